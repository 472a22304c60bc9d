"""Every way the serial rig can fail ends in one DeviceError whose one-line message names the
port and the failure: a missing port, the port vanishing mid-scan, silence, garbage, alarms,
limits and sensor errors, injected by the simulated device over a real pseudo-terminal."""
import time
import unittest

import numpy as np

from BladeInspect.core.errors import DeviceError
from BladeInspect.rig.base import AxisLimits
from BladeInspect.rig.serial_rig import SerialRig
from BladeInspect.rig.simrig_device import Fault, SimRigDevice
from tests.serial_support import FakeSimulatedRig, section_path

# Lines the driver sends before the first pass ($I, ID; $H, G90G21) and around a pass's G1
# blocks (START, G0 A, G0 XYZ, F, M62, ..., M63, G4): a fault at CONNECT + HOME + 10 is mid-scan.
CONNECT, HOME, MID_SCAN = 2, 2, 10


class SerialFaultTest(unittest.TestCase):
    def device(self, fault=None, **options):
        device = SimRigDevice(FakeSimulatedRig(seed=2), fault=fault, **options).start()
        self.addCleanup(device.stop)
        return device

    def scan_fails(self, device, pattern, timeout_s=2.0, k=60):
        rig = SerialRig(device.port_url, timeout_s=timeout_s)
        self.addCleanup(rig.close)
        rig.home()
        path = section_path(np.random.default_rng(4), k)
        with self.assertRaises(DeviceError) as ctx:
            rig.scan_path(path, 15.0)
        message = str(ctx.exception)
        self.assertRegex(message, pattern)
        # The message names the port that failed: with two ports, whichever the closed
        # device's loss reached first.
        self.assertTrue(any(port in message for port in device.port_url.split(",")), message)
        self.assertNotIn("\n", message)
        with self.assertRaisesRegex(DeviceError, "unusable after an earlier failure"):
            rig.scan_path(path, 15.0)
        rig.close()     # closing after a failure must not raise
        return message

    def test_missing_port(self):
        with self.assertRaisesRegex(DeviceError, r"serial:/dev/no-such-rig: cannot open the "
                                                 r"motion port \(No such file or directory\)"):
            SerialRig("/dev/no-such-rig")

    def test_missing_sensor_port(self):
        device = self.device()
        with self.assertRaisesRegex(DeviceError, "cannot open the sensor port"):
            SerialRig(device.port_url + ",/dev/no-such-sensor")

    def test_port_vanishes_mid_scan(self):
        self.scan_fails(self.device(Fault("close", CONNECT + HOME + MID_SCAN)), "motion port lost")

    def test_sensor_port_vanishes(self):
        device = self.device(Fault("close", CONNECT + 1 + HOME + MID_SCAN), two_ports=True)
        self.scan_fails(device, "port lost")

    def test_device_stops_answering(self):
        message = self.scan_fails(self.device(Fault("silent", CONNECT + HOME + MID_SCAN)),
                                  "timeout, no answer within 0.3 s", timeout_s=0.3)
        self.assertIn("waiting for", message)

    def test_long_move_is_not_a_timeout(self):
        # The sync after a move is answered only after 1 s, 3x the timeout; the controller
        # reports Run to the driver's status polls meanwhile, which is progress.
        device = self.device(Fault("busy", CONNECT + HOME + 1, busy_s=1.0))
        rig = SerialRig(device.port_url, timeout_s=0.3)
        self.addCleanup(rig.close)
        rig.home()
        start = time.monotonic()
        rig.move_to(x=5.0)
        self.assertGreaterEqual(time.monotonic() - start, 1.0)
        self.assertEqual(rig.position()[0], 5.0)

    def test_slow_measurement_is_not_a_timeout(self):
        # Ray casting a large pass may outlast the timeout; the device reports Run meanwhile.
        class SlowRig(FakeSimulatedRig):
            def measure(self, *args):
                time.sleep(1.0)
                return super().measure(*args)
        device = SimRigDevice(SlowRig(seed=2)).start()
        self.addCleanup(device.stop)
        rig = SerialRig(device.port_url, timeout_s=0.3)
        self.addCleanup(rig.close)
        path = section_path(np.random.default_rng(4), 30)
        readings = rig.scan_path(path, 15.0)
        expected = FakeSimulatedRig(seed=2).scan_path(path, 15.0)
        np.testing.assert_array_equal(readings.reading_mm, expected.reading_mm)

    def test_simulation_failure_is_a_sensor_error(self):
        class BrokenRig(FakeSimulatedRig):
            def measure(self, *args):
                raise ValueError("no part on the table")
        device = SimRigDevice(BrokenRig(seed=2)).start()
        self.scan_fails(device, r"sensor error SIMULATION_FAILED \(ValueError: no part on "
                                r"the table\)")

    def test_nothing_answers_at_open(self):
        # loop:// echoes the reset byte back: no controller greets.
        with self.assertRaisesRegex(DeviceError, "timeout.*greeting"):
            SerialRig("loop://", timeout_s=0.2)

    def test_garbage(self):
        self.scan_fails(self.device(Fault("garbage", CONNECT + HOME + MID_SCAN)),
                        "garbage from the controller: '%%~ 0x3f garbage ~%%'")

    def test_garbage_from_sensor(self):
        # The START command (first line of the pass) is answered with noise.
        self.scan_fails(self.device(Fault("garbage", CONNECT + HOME)), "garbage")

    def test_hard_limit_alarm(self):
        self.scan_fails(self.device(Fault("alarm", CONNECT + HOME + MID_SCAN, alarm=1)),
                        r"hard limit: controller raised ALARM:1 \(hard limit triggered\)")

    def test_controller_soft_limit(self):
        # The controller's travel is shorter than the host believes: GRBL raises ALARM:2.
        device = self.device(limits=AxisLimits(x=(-10.0, 10.0)))
        self.scan_fails(device, r"soft limit: controller raised ALARM:2")

    def test_sensor_error(self):
        self.scan_fails(self.device(Fault("sensor_error", CONNECT + HOME + MID_SCAN)),
                        r"sensor error LASER_FAULT \(laser fault\)")

    def test_lost_reading(self):
        self.scan_fails(self.device(Fault("lose_reading", CONNECT + HOME)),
                        "sensor ended the pass with 59 of 60 readings")

    def test_sensor_out_of_range_request(self):
        device = self.device()
        rig = SerialRig(device.port_url, timeout_s=2)
        self.addCleanup(rig.close)
        with self.assertRaisesRegex(DeviceError, "sensor error OUT_OF_RANGE"):
            rig._sensor_command("START 0")

    def test_motion_after_alarm_is_refused(self):
        device = self.device(Fault("alarm", CONNECT + HOME + MID_SCAN))
        self.scan_fails(device, "ALARM:1")
        rig = SerialRig(device.port_url, timeout_s=2)
        self.addCleanup(rig.close)
        self.assertEqual(rig._query_status().state, "Alarm")    # a reset keeps a limit alarm
        # Public motion would home first; a bare block meets the controller's lock-out.
        with self.assertRaisesRegex(DeviceError, r"controller answered error:9 \(G-code locked "
                                                 r"out during alarm\) to G0X1"):
            rig._stream(["G0X1"])


class ScanResumeTest(unittest.TestCase):
    """scan_to_dir over the serial rig: the pty vanishes in the middle of a section; the
    sections finished before stay on disk, and a resumed scan on a fresh device completes
    it exactly as one uninterrupted scan of the same rig in process: nothing measured twice,
    nothing lost."""

    OPTIONS = dict(n_sections=2, point_spacing=0.5, span_range=(30.0, 90.0), edges=False)

    @staticmethod
    def simulated_rig():
        from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
        from tests.rig_parts import TwistedEllipse
        pose = random_fixture_pose(np.random.default_rng(4), cad_center=(0, 0, 35.0))
        return SimulatedRig(TwistedEllipse(), pose, seed=5)

    def serial_rig(self, fault=None):
        device = SimRigDevice(self.simulated_rig(), fault=fault).start()
        self.addCleanup(device.stop)
        rig = SerialRig(device.port_url, timeout_s=5)
        self.addCleanup(rig.close)
        return rig

    def test_fault_mid_section_then_resume(self):
        import json
        import os
        import tempfile
        from BladeInspect.measurement.scan import scan_to_dir
        folder = tempfile.TemporaryDirectory()
        self.addCleanup(folder.cleanup)
        reference_dir = os.path.join(folder.name, "reference")
        rig = self.simulated_rig()
        section_first_pass = []     # progress is called as each section starts
        reference = scan_to_dir(reference_dir, rig, progress=lambda fraction, message:
                                section_first_pass.append(rig.pass_index), **self.OPTIONS)
        with open(os.path.join(reference_dir, "points.csv")) as f:
            expected_rows = f.read().splitlines()
        self.assertTrue(reference["complete"])
        rows = [s["points"] for s in reference["sections"]]

        out = os.path.join(folder.name, "scan")
        fault = Fault("close", after_passes=section_first_pass[1] + 2)   # inside section 1
        with self.assertRaisesRegex(DeviceError, "motion port lost"):
            scan_to_dir(out, self.serial_rig(fault), **self.OPTIONS)
        with open(os.path.join(out, "scan.json")) as f:
            record = json.load(f)
        self.assertFalse(record["complete"])
        self.assertEqual([s["index"] for s in record["sections"]], [0])
        with open(os.path.join(out, "points.csv")) as f:
            kept = f.read().splitlines()
        self.assertEqual(kept, expected_rows[:1 + rows[0]])

        record = scan_to_dir(out, self.serial_rig(), resume=True, **self.OPTIONS)
        self.assertTrue(record["complete"])
        self.assertEqual([s["index"] for s in record["sections"]], [0, 1])
        self.assertEqual(record["passes"], reference["passes"])
        with open(os.path.join(out, "points.csv")) as f:
            self.assertEqual(f.read().splitlines(), expected_rows)


if __name__ == "__main__":
    unittest.main()
