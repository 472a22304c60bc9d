"""Which end of a section is the leading edge (issue 15): by default the pipeline passes the
flow's direction (+engine axis, so the LE is the upstream end) to the kernel. Checked on NASA
Rotor 67 at every planned section against the section file's own LE and TE (points JLE and
JTE of each streamsurface, as NASA numbers them), which no rule of the kernel reads."""
import unittest

import numpy as np

from BladeInspect.core.airfoil import AirfoilDefinition
from BladeInspect.cad import rotor67 as r67
from BladeInspect.inspection import airfoil_stage as stage_mod
from tests.helpers import ROTOR67_SECTIONS
from tests.test_rotor67_loop import rotor67_nominal

HEIGHTS = (10.0, 30.0, 50.0, 70.0, 90.0)


def _distance_to_polyline(p, line):
    a, b = line[:-1], line[1:]
    t = np.clip(np.einsum("ij,ij->i", p - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
    return float(np.min(np.linalg.norm(a + t[:, None] * (b - a) - p, axis=1)))


class Rotor67LeadingEdge(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = rotor67_nominal()
        upper, _ = r67.blade_sections(r67.read_rotor67(ROTOR67_SECTIONS))
        # NASA's LE and TE lines: the first and last blade point of every streamsurface
        cls.le_line, cls.te_line = upper[:, 0, :], upper[:, -1, :]
        planes = stage_mod.nominal_planes(cls.nominal, HEIGHTS)
        cls.by_rule = {rule: stage_mod.run_stage(cls.nominal, planes,
                                                 stage_mod.Options(
                                                     draws=0,
                                                     definition=AirfoilDefinition(le_rule=rule)))
                       for rule in stage_mod.LE_RULES}

    def _ends(self, section):
        return (section.frame.to_3d(section.nominal.le_point)[0],
                section.frame.to_3d(section.nominal.te_point)[0])

    def test_the_le_is_nasas_le_at_every_section(self):
        stage = self.by_rule["engine-axis"]
        self.assertEqual(stage.settings["le_rule"], "engine-axis")
        self.assertIn("upstream", stage.settings["le_rule_meaning"])
        for section in stage.sections:
            if section.plane.height_pct == 90.0:
                # the plane leaves the blade through its tip face (the casing cut reaches
                # down to 80 % span) before NASA's TE: not the airfoil's profile
                self.assertIn("(tip)", section.block["refused"])
                continue
            le, te = self._ends(section)
            self.assertEqual(section.block["le_rule"], "given upstream direction")
            # within an edge radius of NASA's LE line (0.17-0.38 mm), 90 mm from its TE line
            self.assertLess(_distance_to_polyline(le, self.le_line), 0.5, section.plane.label)
            self.assertGreater(_distance_to_polyline(le, self.te_line), 50.0)
            self.assertLess(_distance_to_polyline(te, self.te_line), 0.5, section.plane.label)

    def test_the_larger_radius_rule_picks_the_te_at_10_pct_span(self):
        # the issue's case: at 10 % span Rotor 67's TE is the blunter end
        section = self.by_rule["larger-radius"].sections[0]
        self.assertEqual(section.block["le_rule"], "larger edge radius")
        le, _ = self._ends(section)
        self.assertLess(_distance_to_polyline(le, self.te_line), 2.0)
        right = self.by_rule["engine-axis"].sections[0]
        self.assertAlmostEqual(section.nominal.le_radius_mm, right.nominal.te_radius_mm,
                               places=9)

    def test_a_bad_rule_is_refused(self):
        from BladeInspect.core.errors import InputError
        with self.assertRaises(InputError):
            stage_mod.options_from_args(le_rule="sharper")


class CommandLineDefaults(unittest.TestCase):
    """report, inspect and batch compute the airfoil block unless --no-airfoil."""

    def _options(self, argv):
        from BladeInspect import cli
        return cli._airfoil_options(cli.build_parser().parse_args(argv))

    def test_on_by_default_with_the_engine_axis_rule(self):
        from BladeInspect.core.errors import InputError
        for base in (["report", "--cad", "c.step", "--points", "p.csv", "--out", "o"],
                     ["inspect", "--out", "o"], ["batch", "--cad", "c.step", "--scans", "s",
                                                 "--out", "o"]):
            opts = self._options(base)
            self.assertIsNotNone(opts, base)
            self.assertEqual(opts.definition.le_rule, "engine-axis")
            self.assertEqual(self._options(base + ["--le-rule", "larger-radius"])
                             .definition.le_rule, "larger-radius")
            self.assertIsNone(self._options(base + ["--no-airfoil"]))
            with self.assertRaises(InputError):
                self._options(base + ["--no-airfoil", "--engine-axis", "z"])


if __name__ == "__main__":
    unittest.main()
