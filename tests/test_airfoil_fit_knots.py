"""A planned section's edge thicknesses where its points thin out (core.airfoil.refit
._knots_from_nominal).

The planner takes a section's points a few micrometres apart round each edge and 0.1 mm apart
beyond, so the stations 1 and 2 mm from the edges lie where the points thin out. The demo
blade's planned 70 % section, read in the rig's true pose by the simulated rig's own sensor
(its stated noise: a perfect part, no registration), several noise draws: the mean of each
edge thickness must be the CAD's -- the nominal cut's, independent of any measured fit. The
smoothing spline alone read them 3-10 um off, scan after scan (docs/validation.md:
-7.6, +8.1, -9.7 um at 1 and 2 mm, 15-45 standard errors over 24 scans).
"""
import unittest

import numpy as np

from BladeInspect.core import airfoil as kernel
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import sections as sections_mod
from BladeInspect.measurement import planning
from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose_of
from tests.airfoil_shapes import ArcSection
from tests.helpers import demo_nominal, planned_readings_result

HEIGHT = 70.0
SCANS = 8
POSE_SEED = 3
# The mean of SCANS scans of a perfect part: the scans' own scatter (1.0-1.9 um for one scan
# at 1 and 2 mm) over sqrt(SCANS) is 0.4-0.7 um; the smoothing spline alone was 3-10 um off.
MEAN_WITHIN_MM = 0.0025


class EdgeThicknessWhereThePointsThinOut(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        nominal = demo_nominal()
        axis, _ = sections_mod.span_axis_of(nominal)
        truth = random_fixture_pose_of(nominal, np.random.default_rng(POSE_SEED), axis)
        cls.scans = []
        for seed in range(SCANS):
            rig = SimulatedRig(nominal, truth, seed=100 + seed)
            if not seed:
                plan = planning.plan_sections(
                    nominal, truth, (HEIGHT,), rig.sensor, rig.limits, span_axis=axis,
                    kinematics=rig.kinematics,
                    edge_radius_sigma_mm=planning.DEFAULT_EDGE_RADIUS_SIGMA_MM)
            result, _ = planned_readings_result(nominal, rig, plan)
            table = sections_mod.section_table(result, nominal, heights_pct=(HEIGHT,),
                                               span_axis=axis)
            stage = stage_mod.run_stage(nominal, stage_mod.planes_of_table(table),
                                        stage_mod.Options(draws=0), result, table.span_axis)
            cls.scans.append(stage.sections[0])

    def test_the_points_thin_out_beyond_the_edges(self):
        sr = self.scans[0]
        u, _ = sr.nominal.profile.closest(sr.points_2d)
        gaps = np.diff(np.sort(np.mod(u, sr.nominal.profile.length)))
        self.assertLess(np.percentile(gaps, 25), 0.005)
        self.assertGreater(gaps.max(), 0.08)
        self.assertGreater(sr.noise_mm, 0.003)      # the rig's sensor, not a quiet one

    def test_edge_thicknesses_read_the_cad_on_average(self):
        nominal = self.scans[0].nominal
        for side in ("le_thickness_mm", "te_thickness_mm"):
            for i, offset in enumerate(nominal.edge_offsets_mm):
                if offset < 1.0:
                    continue        # 0.5 mm lies where the points are dense
                read = [getattr(sr.measured, side)[i] for sr in self.scans]
                self.assertLess(abs(np.mean(read) - getattr(nominal, side)[i]), MEAN_WITHIN_MM,
                                "%s at %g mm: %s" % (side, offset,
                                                     np.round(1e3 * (np.array(read) - getattr(
                                                         nominal, side)[i]), 2)))

    def test_the_smoothing_spline_alone_misses_them(self):
        """The case discriminates: without the nominal's knots the same points read the
        thickness 1 mm from the TE off by more than the limit."""
        nominal = self.scans[0].nominal
        read = []
        for sr in self.scans:
            ordered = kernel.order_by_nominal(sr.points_2d, nominal.profile)
            ch = kernel.characteristics(kernel.Profile(ordered, sr.noise_mm),
                                        noise_mm=sr.noise_mm, le_hint=nominal.le_point)
            read.append(ch.te_thickness_mm[1])
        self.assertGreater(abs(np.mean(read) - nominal.te_thickness_mm[1]), 2 * MEAN_WITHIN_MM)


class PointsWithoutARunOfThinning(unittest.TestCase):
    """Points that do not thin out in runs keep FITPACK's smoothing spline, to the bit: a
    cloud's band about the plane (points at random along the profile, single gaps from nothing
    to many times their median) and evenly spaced points."""

    @classmethod
    def setUpClass(cls):
        cls.sec = ArcSection(x_le=-71.3, x_te=69.8, angle_deg=17.0, shift=(2.0, -3.0))
        cls.nominal = kernel.Profile(cls.sec.points(0.02))
        cls.dense = cls.sec.points(0.0005)

    def assert_smoothing_alone(self, pts, sigma, seed):
        normal = self.nominal.outward_normal(self.nominal.closest(pts)[0])
        noisy = pts + np.random.default_rng(seed).normal(0.0, sigma, len(pts))[:, None] * normal
        with_nominal = kernel.Profile(noisy, sigma, nominal=self.nominal)
        alone = kernel.Profile(noisy, sigma)
        np.testing.assert_array_equal(with_nominal._tck[0], alone._tck[0])
        for a, b in zip(with_nominal._tck[1], alone._tck[1]):
            np.testing.assert_array_equal(a, b)

    def test_points_at_random(self):
        for seed in range(4):
            rng = np.random.default_rng(seed)
            pts = self.dense[np.sort(rng.choice(len(self.dense), 3000, replace=False))]
            gaps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
            self.assertGreater(gaps.max(), 5 * np.median(gaps))    # single gaps do vary
            self.assert_smoothing_alone(pts, 0.0039, seed)

    def test_points_evenly_spaced(self):
        self.assert_smoothing_alone(self.sec.points(0.02), 0.002, 7)


if __name__ == "__main__":
    unittest.main()
