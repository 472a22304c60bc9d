"""What the GUI holds between commands that is not document data: the connected rig."""


class RigSession:
    def __init__(self):
        self.rig = None
        self.spec = None
        self.seed = 0      # the simulated rig's: a replayed Scan line opens the same one

    def connect(self, rig, spec, seed=0):
        self.disconnect()
        self.rig, self.spec, self.seed = rig, spec, seed

    def disconnect(self):
        if self.rig is not None:
            try:
                self.rig.close()
            finally:
                self.rig, self.spec = None, None

    @property
    def connected(self):
        return self.rig is not None


RIG = RigSession()
