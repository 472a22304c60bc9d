"""core.contracts: the one place for the contracts' defaults, checks and JSON form, and the
callers that used to keep their own copies agreeing with it."""
import json
import unittest

import numpy as np

from BladeInspect.core import contracts, stats
from BladeInspect.core.errors import InputError


class SectionHeights(unittest.TestCase):
    def test_parsed_as_typed(self):
        self.assertEqual(contracts.parse_section_heights("10, 30;50 70"), [10.0, 30.0, 50.0, 70.0])
        self.assertEqual(contracts.parse_section_heights("", allow_empty=True), [])

    def test_refusals_name_the_flag(self):
        for text, words in (("10,130", "130 is outside 0-100"), ("10,x", "not a comma-separated"),
                            ("", "at least one height"), ("nan", "outside 0-100")):
            with self.assertRaises(InputError) as ctx:
                contracts.parse_section_heights(text, "--section-heights")
            self.assertIn("--section-heights", str(ctx.exception))
            self.assertIn(words, str(ctx.exception))
        with self.assertRaises(InputError):
            contracts.section_heights([50, None])

    def test_one_check_behind_every_caller(self):
        from BladeInspect import cli
        import argparse
        with self.assertRaises(argparse.ArgumentTypeError) as ctx:
            cli._heights("10,101")
        self.assertIn("101 is outside 0-100", str(ctx.exception))
        self.assertEqual(cli._heights("20,80"), [20.0, 80.0])


class Tolerance(unittest.TestCase):
    def test_default_is_table_3(self):
        # Table 3's bands are +-0.04, +-0.06, +-0.08 mm: the default tolerance and its bands
        self.assertEqual(stats.tolerance_bands(contracts.PROFILE_TOLERANCE_MM),
                         (-0.08, -0.06, -0.04, 0.04, 0.06, 0.08))
        self.assertEqual(stats.DEFAULT_BAND_EDGES, (-0.08, -0.06, -0.04, 0.04, 0.06, 0.08))

    def test_refused_unless_positive(self):
        self.assertEqual(contracts.profile_tolerance("0.02"), 0.02)
        for bad in (0, -1, float("nan"), float("inf"), "x", None):
            with self.assertRaises(InputError):
                contracts.profile_tolerance(bad)


class Json(unittest.TestCase):
    def test_numpy_and_to_dict_round_trip(self):
        class Kinematics:
            def to_dict(self):
                return {"axis": [0.0, 1.0, 0.0]}
        value = {"a": np.arange(3.0), "b": np.float32(0.5), "c": np.int64(7),
                 "d": np.bool_(True), "e": (1, 2), "k": Kinematics()}
        self.assertEqual(contracts.json_ready(value),
                         {"a": [0.0, 1.0, 2.0], "b": 0.5, "c": 7, "d": True, "e": [1, 2],
                          "k": {"axis": [0.0, 1.0, 0.0]}})
        with self.assertRaises(TypeError):
            json.dumps({"x": object()}, default=contracts.json_default)


if __name__ == "__main__":
    unittest.main()
