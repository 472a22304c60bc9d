"""inspection.airfoil_stage.nominal_characteristics remembers a nominal cut's characteristics (a batch
worker's next blade, issue 15's "five sections in under 1 s") against independent truth: a
profile of exact circular arcs (tests/airfoil_shapes.ArcSection), its edge radii in closed
form, read afresh and from the memory; the same cut scaled by 2 (radii doubled, so not served
the remembered ones); other edge offsets (the offsets asked are the ones reported); a caller
writing into its result's lists does not change the next caller's."""

import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from airfoil_shapes import ArcSection  # noqa: E402

from BladeInspect.core import airfoil as kernel  # noqa: E402
from BladeInspect.core.airfoil import AirfoilDefinition  # noqa: E402
from BladeInspect.inspection import airfoil_stage as stage  # noqa: E402

UM = 1e-3


class RememberedNominal(unittest.TestCase):
    def setUp(self):
        stage.clear_nominal_cache()
        self.sec = ArcSection(x_le=-24.0, x_te=27.0, angle_deg=30.0, shift=(3.0, -2.0))
        self.xy = self.sec.points(0.02)

    def tearDown(self):
        stage.clear_nominal_cache()

    def _read(self, xy, offsets=(0.5, 1.0, 2.0), **definition):
        return stage.nominal_characteristics(
            xy, AirfoilDefinition(edge_offsets_mm=offsets, **definition), None, (-1.0, 0.0))

    def test_remembered_cut_reads_the_closed_form(self):
        first = self._read(self.xy)
        self.assertEqual(len(stage._NOMINAL_CACHE), 1)
        again = self._read(self.xy.copy())
        self.assertEqual(len(stage._NOMINAL_CACHE), 1)
        self.assertIs(again.profile, first.profile)      # served from the memory
        for ch in (first, again):
            self.assertAlmostEqual(ch.le_radius_mm, self.sec.r_le, delta=UM)
            self.assertAlmostEqual(ch.te_radius_mm, self.sec.r_te, delta=UM)

    def test_a_scaled_cut_and_other_offsets_are_read_afresh(self):
        self._read(self.xy)
        big = self._read(2.0 * self.xy)
        self.assertAlmostEqual(big.le_radius_mm, 2.0 * self.sec.r_le, delta=2 * UM)
        self.assertAlmostEqual(big.te_radius_mm, 2.0 * self.sec.r_te, delta=2 * UM)
        other = self._read(self.xy, offsets=(0.25, 0.75))
        self.assertEqual(other.edge_offsets_mm, [0.25, 0.75])
        self.assertEqual(len(other.le_thickness_mm), 2)
        self.assertEqual(len(stage._NOMINAL_CACHE), 3)

    def test_a_cut_of_another_definition_is_read_afresh(self):
        """Every definition field keys the remembered cut: a changed edge zone or metal-angle
        window (not arguments of the cut before the definition held them) gives that
        definition's characteristics, not the remembered ones."""
        first = self._read(self.xy)
        for change in ({"edge_zone_deg": 30.0}, {"metal_angle_window_pct": 30.0},
                       {"le_radius_sigmas": 2.0}, {"chord_method": "caliper"}):
            got = self._read(self.xy, **change)
            want = kernel.characteristics(self.xy, le_upstream=(-1.0, 0.0),
                                          definition=AirfoilDefinition(**change))
            self.assertEqual(kernel.characteristics_state(got),
                             kernel.characteristics_state(want), change)
        zone = self._read(self.xy, edge_zone_deg=30.0)
        self.assertNotEqual(zone.le_radius_mm, first.le_radius_mm)
        self.assertEqual(len(stage._NOMINAL_CACHE), 5)

    def test_a_caller_writing_into_its_lists_does_not_change_the_next(self):
        first = self._read(self.xy)
        n_warnings = len(first.warnings)
        le_thk = list(first.le_thickness_mm)
        first.warnings.append("a caller's note")
        first.le_thickness_mm[0] = -1.0
        again = self._read(self.xy)
        self.assertEqual(len(again.warnings), n_warnings)
        self.assertEqual(again.le_thickness_mm, le_thk)
        self.assertTrue(np.all(np.asarray(again.le_thickness_mm) > 0))

    def test_the_memory_is_bounded(self):
        for k in range(stage.NOMINAL_CACHE_SIZE + 3):
            self._read(self.xy + np.array([0.001 * k, 0.0]))
        self.assertEqual(len(stage._NOMINAL_CACHE), stage.NOMINAL_CACHE_SIZE)


if __name__ == "__main__":
    unittest.main()
