"""What the GUI holds between commands that is not document data: the connected rig."""


class RigSession:
    def __init__(self):
        self.rig = None
        self.spec = None

    def connect(self, rig, spec):
        self.disconnect()
        self.rig, self.spec = rig, spec

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
