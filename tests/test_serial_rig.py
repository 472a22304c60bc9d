"""SerialRig against the simulated rig served on a real pseudo-terminal: the same readings as
the rig in process for the same seed, positions and limits, and GRBL's receive buffer kept."""
import unittest

import numpy as np

from BladeInspect.core.errors import DeviceError, InputError
from BladeInspect.rig.serial_rig import SerialRig
from BladeInspect.rig.simrig_device import SimRigDevice
from tests.serial_support import FakeSimulatedRig, section_path


def assert_same_readings(test, got, expected):
    np.testing.assert_array_equal(got.stage_xyz, expected.stage_xyz)
    test.assertEqual(got.angle_deg, expected.angle_deg)
    np.testing.assert_array_equal(got.reading_mm, expected.reading_mm)   # NaN == NaN here
    np.testing.assert_array_equal(got.snr, expected.snr)


class SerialRigFakeTest(unittest.TestCase):
    """Protocol behaviour with a stand-in rig whose readings depend on every coordinate,
    the angle and the pass index."""

    def open(self, two_ports=False, **device_options):
        device = SimRigDevice(FakeSimulatedRig(seed=11), two_ports=two_ports, **device_options)
        device.start()
        self.addCleanup(device.stop)
        rig = SerialRig(device.port_url, timeout_s=3)
        self.addCleanup(rig.close)
        return device, rig

    def check_same_as_in_process(self, two_ports):
        device, rig = self.open(two_ports)
        reference = FakeSimulatedRig(seed=11)
        rng = np.random.default_rng(5)
        for k in (1, 2, 17, 400):
            path = section_path(rng, k, y=rng.uniform(0, 200))
            if k == 17:
                path[5] = path[4]       # a repeated point still gets its own reading
            angle = float(rng.uniform(-360, 360))
            assert_same_readings(self, rig.scan_path(path, angle), reference.scan_path(path, angle))
        self.assertEqual(device.passes, 4)
        self.assertEqual(device.overflows, 0)

    def test_same_readings_as_in_process_one_port(self):
        self.check_same_as_in_process(two_ports=False)

    def test_same_readings_as_in_process_two_ports(self):
        self.check_same_as_in_process(two_ports=True)

    def test_home_position_move(self):
        device, rig = self.open()
        self.assertIn("SimProbe", rig.sensor_identity["model"])
        rig.home()
        self.assertEqual(rig.position(), FakeSimulatedRig().position())
        rig.move_to(x=12.345678901234567, a=-33.3)
        rig.move_to(z=0.1 + 0.2)
        self.assertEqual(rig.position(), (12.345678901234567, 150.0, 0.1 + 0.2, -33.3))
        self.assertGreater(rig.elapsed_s, 0.0)

    def test_first_motion_homes(self):
        device, rig = self.open()
        rig.move_to(x=1.0)
        self.assertEqual(rig.position(), (1.0, 150.0, 100.0, 0.0))

    def test_controller_without_homing(self):
        device, rig = self.open(homing=False)
        rig.move_to(x=2.5)         # $H answered error:5: unlocked where it stands, then moved
        self.assertEqual(rig.position(), (2.5, 150.0, 100.0, 0.0))

    def test_host_checks_limits_before_sending(self):
        device, rig = self.open()
        rig.home()
        sent = device.lines_received
        path = section_path(np.random.default_rng(0), 20)
        path[7, 2] = 170.0
        with self.assertRaisesRegex(DeviceError, "soft limit: Z=170.000"):
            rig.scan_path(path, 0.0)
        with self.assertRaisesRegex(DeviceError, "soft limit: X"):
            rig.move_to(x=-500)
        self.assertEqual(device.lines_received, sent)

    def test_bad_path(self):
        device, rig = self.open()
        for path in (np.zeros((0, 3)), np.zeros((4, 2)), [[0, 0, np.nan]]):
            with self.assertRaisesRegex(InputError, "scan_path"):
                rig.scan_path(path, 0.0)

    def test_stream_keeps_grbl_receive_buffer(self):
        # The device counts bytes received but not yet answered; a host ignoring GRBL's
        # 128 bytes must be caught by it, or the zero count proves nothing.
        path = section_path(np.random.default_rng(1), 3000)
        for size in (128, 1024):
            device, rig = self.open(rx_buffer=size)
            self.assertEqual(rig.rx_buffer, size)       # as the controller reports in $I
            rig.scan_path(path, 0.0)
            self.assertEqual(device.overflows, 0)
            rig.rx_buffer = 4 * size
            rig.scan_path(path, 0.0)
            self.assertGreater(device.overflows, 0)

    def test_one_line_of_two_port_urls(self):
        with self.assertRaisesRegex(InputError, "MOTION_PORT,SENSOR_PORT"):
            SerialRig("a,b,c")
        with self.assertRaisesRegex(InputError, "timeout_s"):
            SerialRig("loop://", timeout_s=0)


class SerialRigSimulatedTest(unittest.TestCase):
    """The real SimulatedRig (ray cast onto a part at a random fixture pose, sensor model,
    noise per pass) behind the pty gives what it gives in process, pass for pass."""

    def make_rig(self):
        from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
        from tests.rig_parts import Sphere
        pose = random_fixture_pose(np.random.default_rng(8), cad_center=(0, 60.0, 0))
        return SimulatedRig(Sphere(40.0, center=[0, 60.0, 0]), pose, seed=21)

    def test_scan_passes_identical_to_in_process(self):
        device = SimRigDevice(self.make_rig()).start()
        self.addCleanup(device.stop)
        rig = SerialRig(device.port_url, timeout_s=3)
        self.addCleanup(rig.close)
        reference = self.make_rig()
        self.assertEqual(rig.sensor.standoff, reference.sensor.standoff)
        self.assertEqual(rig.sensor.half_range, reference.sensor.half_range)
        rig.home()
        reference.home()
        self.assertEqual(rig.position(), reference.position())
        rng = np.random.default_rng(2)
        hits = 0
        for angle in (0.0, 37.5, -90.0, 181.25):
            path = np.column_stack([np.linspace(-30, 30, 250) + rng.uniform(-0.1, 0.1),
                                    np.full(250, rng.uniform(40, 80)),
                                    np.full(250, 80.0) + rng.normal(0, 0.5, 250)])
            got, expected = rig.scan_path(path, angle), reference.scan_path(path, angle)
            assert_same_readings(self, got, expected)
            self.assertEqual(got.meta["pass_index"], expected.meta["pass_index"])
            hits += np.isfinite(got.reading_mm).sum()
        self.assertGreater(hits, 300)     # the comparison is about real surface readings
        # A resumed scan numbers its passes as the uninterrupted one did.
        rig.set_pass_index(1)
        reference.set_pass_index(1)
        assert_same_readings(self, rig.scan_path(path, 5.0), reference.scan_path(path, 5.0))


class SerialScanToDirTest(unittest.TestCase):
    def test_scan_folder_identical_to_in_process(self):
        # The whole blind scan (probing, levelling, rescans, final passes) over two ports.
        import os
        import tempfile
        from BladeInspect.measurement.scan import scan_to_dir
        from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
        from tests.rig_parts import TwistedEllipse

        def simulated_rig():
            pose = random_fixture_pose(np.random.default_rng(6), cad_center=(0, 0, 35.0))
            return SimulatedRig(TwistedEllipse(), pose, seed=9)
        options = dict(n_sections=2, point_spacing=0.5, span_range=(30.0, 90.0), edges=False)
        folder = tempfile.TemporaryDirectory()
        self.addCleanup(folder.cleanup)
        expected = scan_to_dir(os.path.join(folder.name, "process"), simulated_rig(), **options)
        device = SimRigDevice(simulated_rig(), two_ports=True).start()
        self.addCleanup(device.stop)
        rig = SerialRig(device.port_url)
        self.addCleanup(rig.close)
        got = scan_to_dir(os.path.join(folder.name, "serial"), rig, **options)
        self.assertEqual((got["points"], got["passes"]), (expected["points"], expected["passes"]))
        self.assertGreater(got["points"], 200)
        texts = []
        for name in ("process", "serial"):
            with open(os.path.join(folder.name, name, "points.csv")) as f:
                texts.append(f.read())
        self.assertEqual(texts[0], texts[1])


class SimrigCommandTest(unittest.TestCase):
    """``simrig_main`` in its own process, as ``./bladeinspect simrig --cad CAD --seed S`` runs
    it: the printed port reaches a rig holding that CAD, measuring as it does in process."""

    def test_served_cad_matches_in_process(self):
        import os
        import signal
        import subprocess
        import tempfile
        import Part
        from BladeInspect.cad.load import load_nominal
        from BladeInspect.rig.simulated import simulated_rig_for
        from tests.helpers import REPO
        folder = tempfile.TemporaryDirectory()
        self.addCleanup(folder.cleanup)
        # A cylinder's ray casts are cheap; the demo blade's first one takes seconds.
        cad = os.path.join(folder.name, "part.step")
        Part.makeCylinder(15.0, 60.0).exportStep(cad)
        server = subprocess.Popen(
            [os.path.join(REPO, "scripts", "fcpython"), "-c", "from BladeInspect.rig."
             "simrig_device import simrig_main; simrig_main(%r, 3)" % cad],
            cwd=REPO, stdout=subprocess.PIPE, text=True)
        self.addCleanup(server.wait, 10)
        self.addCleanup(server.send_signal, signal.SIGTERM)
        reference = simulated_rig_for(load_nominal(cad), 3)     # while the server loads
        first = server.stdout.readline()
        self.assertRegex(first, r"^simulated rig \(seed 3\) on /dev/pts/\d+$")
        rig = SerialRig(first.split()[-1], timeout_s=10)
        self.addCleanup(rig.close)
        rig.home()
        reference.home()
        path = np.column_stack([np.linspace(-40, 40, 80), np.full(80, 60.0), np.full(80, 60.0)])
        for angle in (30.0, 120.0):
            got, expected = rig.scan_path(path, angle), reference.scan_path(path, angle)
            assert_same_readings(self, got, expected)
            self.assertGreater(np.isfinite(got.reading_mm).sum(), 5)


if __name__ == "__main__":
    unittest.main()
