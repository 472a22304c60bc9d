"""The rig's line protocols: number formatting, G-code words, status reports and sensor lines,
checked against hand-written GRBL 1.1 lines and round trips over random values."""
import math
import unittest

import numpy as np

from BladeInspect.rig import protocol as pr


class NumberFormatTest(unittest.TestCase):
    def test_round_trips_exactly_without_exponent(self):
        rng = np.random.default_rng(7)
        values = np.concatenate([rng.uniform(-250, 250, 2000),
                                 rng.normal(0, 1, 500) * 10.0 ** rng.integers(-4, 3, 500),
                                 [0.0, -0.0, 1e-5, 0.1, 1 / 3, 219.99999999999997]])
        for v in values:
            text = pr.format_number(v)
            self.assertNotIn("e", text.lower())
            self.assertLessEqual(len(text), 24)
            self.assertEqual(float(text), v, text)

    def test_tiny_values_round_to_picometres(self):
        v = -1.2345678901234567e-7
        text = pr.format_number(v)
        self.assertLessEqual(len(text), 24)
        self.assertAlmostEqual(float(text), v, delta=1e-12)

    def test_rejects_non_finite(self):
        for v in (math.nan, math.inf):
            with self.assertRaises(pr.ProtocolError):
                pr.format_number(v)


class GcodeTest(unittest.TestCase):
    def test_move_leaves_out_unset_axes(self):
        self.assertEqual(pr.gcode_move("G0", a=90), "G0A90")
        self.assertEqual(pr.gcode_move("G1", 1.5, None, -0.25, feed=600), "G1X1.5Z-0.25F600")

    def test_worst_case_block_fits_grbl_line(self):
        v = -0.0012345678901234567
        line = pr.gcode_move("G1", v - 100, v - 10, v - 1)
        self.assertLessEqual(len(line), pr.GRBL_MAX_LINE)
        words = dict(pr.parse_gcode(line))
        self.assertEqual(words["X"], v - 100)

    def test_parse_words_comments_and_spaces(self):
        self.assertEqual(pr.parse_gcode("g1 x1.5 (move) y-2 ; trailing"),
                         [("G", 1.0), ("X", 1.5), ("Y", -2.0)])
        self.assertEqual(pr.parse_gcode("M62P0"), [("M", 62.0), ("P", 0.0)])

    def test_parse_errors_carry_grbl_codes(self):
        with self.assertRaises(pr.ProtocolError) as ctx:
            pr.parse_gcode("G1 X1..2")
        self.assertEqual(ctx.exception.args[0], 2)
        with self.assertRaises(pr.ProtocolError) as ctx:
            pr.parse_gcode("1X2")
        self.assertEqual(ctx.exception.args[0], 1)


class MotionLineTest(unittest.TestCase):
    def test_grbl_status_reports(self):
        # As GRBL 1.1 prints them (3 decimals, extra fields), and as the simulator does.
        s = pr.parse_status("<Idle|MPos:1.000,-2.500,30.125,90.000|FS:0,0|WCO:0.000,0.000,0.000,0.000>")
        self.assertEqual((s.state, s.position), ("Idle", (1.0, -2.5, 30.125, 90.0)))
        self.assertTrue(s.idle)
        s = pr.parse_status("<Run|WPos:0.1,0.2,0.3,0.4|Bf:15,128|FS:500,0>")
        self.assertEqual((s.state, s.position), ("Run", (0.1, 0.2, 0.3, 0.4)))
        self.assertEqual(pr.parse_status("<Alarm:1|MPos:0,0,0,0>").state, "Alarm")
        position = (1 / 3, -0.0015334710205484863, 44.0, 123.456)
        self.assertEqual(pr.parse_status(pr.format_status("Idle", position)).position, position)

    def test_bad_status_reports(self):
        for line in ("<Idle|MPos:1,2,3>", "<Dancing|MPos:0,0,0,0>", "<Idle|FS:0,0>",
                     "Idle|MPos:0,0,0,0", "<Idle|MPos:a,b,c,d>"):
            with self.assertRaises(pr.ProtocolError, msg=line):
                pr.parse_status(line)

    def test_line_kinds(self):
        self.assertEqual(pr.parse_motion_line("ok"), (pr.OK, None))
        self.assertEqual(pr.parse_motion_line("error:9"), (pr.ERROR, 9))
        self.assertEqual(pr.parse_motion_line("ALARM:1"), (pr.ALARM, 1))
        self.assertEqual(pr.parse_motion_line("[MSG:Caution: Unlocked]"), (pr.INFO, "MSG:Caution: Unlocked"))
        self.assertEqual(pr.parse_motion_line("Grbl 1.1h ['$' for help]")[0], pr.BANNER)
        self.assertEqual(pr.parse_motion_line("GrblHAL 1.1f ['$' or '$HELP' for help]")[0],
                         pr.BANNER)
        self.assertEqual(pr.parse_build_options("OPT:V,15,128"), 128)
        self.assertEqual(pr.parse_build_options("OPT:VNMSL,35,1024,3,0"), 1024)
        self.assertIsNone(pr.parse_build_options("OPT:V"))
        self.assertIsNone(pr.parse_build_options("VER:1.1h.20190825:"))
        self.assertEqual(pr.parse_motion_line("<Idle|MPos:0,0,0,0>")[0], pr.STATUS)
        for line in ("okay", "error:x", "%%~ garbage", "ALARM:"):
            with self.assertRaises(pr.ProtocolError, msg=line):
                pr.parse_motion_line(line)

    def test_descriptions_name_limits(self):
        self.assertIn("hard limit", pr.describe_alarm(1))
        self.assertIn("soft limit", pr.describe_alarm(2))
        self.assertIn("travel exceeded", pr.describe_error(15))
        self.assertIn("unknown", pr.describe_error(99))


class SensorLineTest(unittest.TestCase):
    def test_reading_round_trip(self):
        rng = np.random.default_rng(3)
        for i in range(300):
            d = rng.uniform(36, 52) if i % 7 else math.nan
            snr = rng.uniform(0, 100)
            kind, (index, distance, s) = pr.parse_sensor_line(pr.format_reading(i, d, snr))
            self.assertEqual((kind, index, s), (pr.READING, i, snr))
            self.assertTrue(distance == d or (math.isnan(d) and math.isnan(distance)))
        self.assertEqual(pr.format_reading(4, math.nan, 0.0), "R 4 NaN 0")

    def test_other_lines(self):
        self.assertEqual(pr.parse_sensor_line("OK START 12"), (pr.SENSOR_OK, "START 12"))
        self.assertEqual(pr.parse_sensor_line("END 12"), (pr.SENSOR_END, 12))
        self.assertEqual(pr.parse_sensor_line("E OUT_OF_RANGE 0 readings"),
                         (pr.SENSOR_ERROR, ("OUT_OF_RANGE", "0 readings")))
        self.assertEqual(pr.parse_sensor_line("E LASER_FAULT"),
                         (pr.SENSOR_ERROR, ("LASER_FAULT", "laser fault")))
        kind, info = pr.parse_sensor_line(pr.format_identity("Probe", standoff_mm=44, rate_hz=9000))
        self.assertEqual((kind, info), (pr.SENSOR_ID, {"model": "Probe", "standoff_mm": "44",
                                                       "rate_hz": "9000"}))
        for line in ("R 1 2", "R x 44 50", "END", "END x", "E", "Q 1", "ID"):
            with self.assertRaises(pr.ProtocolError, msg=line):
                pr.parse_sensor_line(line)
        self.assertIn("LASER_FAULT", pr.describe_sensor_error("LASER_FAULT"))


if __name__ == "__main__":
    unittest.main()
