"""The section-line scan strategy on an analytic twisted blade at random fixture poses: every
kept reading meets the standoff criterion, the points lie on the part (an independent implicit
distance), both sides and both edges are covered, the part is turned by the twist, and the
result is deterministic per seed."""
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import InputError
from BladeInspect.rig.kinematics import RigKinematics
from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
from BladeInspect.measurement.strategy import (ScanOptions, ScanStrategy, ViewResult,
                                               fit_stage_profile)
from tests.rig_parts import Sphere, TwistedEllipse

TWIST = 25.0


def scan(seed, **options):
    part = TwistedEllipse(a=25.0, b=3.0, length=70.0, twist_deg=TWIST)
    pose = random_fixture_pose(np.random.default_rng(seed), cad_center=(0, 0, 35.0))
    rig = SimulatedRig(part, pose, seed=seed)
    strategy = ScanStrategy(rig, ScanOptions(**options))
    return part, pose, rig, strategy, strategy.run()


class TestScanOfTwistedBlade(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.runs = [scan(seed, n_sections=3) for seed in (11, 12)]

    def test_every_kept_reading_meets_the_standoff_criterion(self):
        for _, _, _, strategy, sections in self.runs:
            for sec in sections:
                self.assertLessEqual(sec.max_standoff_error_mm, 2.0)
                for view in sec.views:
                    self.assertTrue(np.all(np.abs(view.reading_mm - 44.0) <= 2.0))
                    self.assertEqual(view.passes[-1]["kind"], "final")
                    self.assertEqual(len(view.stage_xyz), len(view.reading_mm))

    def test_points_lie_on_the_part(self):
        for part, pose, _, _, sections in self.runs:
            xyz = np.vstack([s.table_xyz for s in sections])
            snr = np.concatenate([s.snr for s in sections])
            dev = part.signed_distance(tf.apply_transform(pose, xyz))
            bound = 0.006 * np.sqrt(100.0 / snr) + 2e-4
            good = snr >= 25.0
            # Above the gross-error SNR every point is within the noise bound.
            self.assertTrue(np.all(np.abs(dev[good]) <= bound[good]),
                            np.max(np.abs(dev[good]) - bound[good]))
            self.assertLess(np.mean(np.abs(dev) > bound), 0.02)
            self.assertGreater(len(xyz), 3000)

    def test_sections_in_their_planes_and_spread_over_the_span(self):
        for part, pose, _, strategy, sections in self.runs:
            lo, hi = strategy.state.span_range
            # The part's true extent along the table's Y (the rotary axis).
            cad_to_table = np.linalg.inv(pose)
            corners = tf.apply_transform(cad_to_table, part.bbox_corners)
            self.assertGreater(lo, corners[:, 1].min() - 0.6)
            self.assertLess(hi, corners[:, 1].max() + 0.6)
            self.assertGreater(hi - lo, 0.9 * 70.0)
            ys = [s.y for s in sections]
            self.assertTrue(np.all(np.diff(ys) > 0.25 * (hi - lo)))
            for s in sections:
                # Nominal axis along Y: the turn keeps Y, so the table Y is the section's.
                np.testing.assert_allclose(s.table_xyz[:, 1], s.y, atol=1e-9)

    def test_both_sides_and_both_edges_covered(self):
        for part, pose, _, _, sections in self.runs:
            for s in sections:
                cad = tf.apply_transform(pose, s.table_xyz)
                xl, yl, _, _ = part._local(cad)
                u = xl / part.a
                self.assertGreater(np.count_nonzero(yl > 0.5), 300)
                self.assertGreater(np.count_nonzero(yl < -0.5), 300)
                # Round each edge: points on the nose and on both flanks next to it.
                for end in (1.0, -1.0):
                    near = u * end > 0.98
                    self.assertGreater(np.count_nonzero(near & (yl > 0.05)), 3)
                    self.assertGreater(np.count_nonzero(near & (yl < -0.05)), 3)

    def test_turned_by_the_twist(self):
        for part, pose, _, strategy, sections in self.runs:
            inclines = []
            for s in sections:
                z = np.median(tf.apply_transform(pose, s.table_xyz)[:, 2])
                tau = np.radians(TWIST) * z / 70.0
                chord_table = pose[:3, :3].T @ np.array([np.cos(tau), np.sin(tau), 0.0])
                chord_machine = strategy.kinematics.rotation(s.base_angle_deg) @ chord_table
                inclines.append(np.degrees(np.arctan2(abs(chord_machine[2]),
                                                      abs(chord_machine[0]))))
            spacing = sections[1].y - sections[0].y
            step = TWIST * spacing / 70.0
            # The first section is levelled on itself; the second follows the first's level,
            # one twist step off; from the third on the twist rate read so far predicts it.
            self.assertLess(inclines[0], 3.0)
            self.assertLess(abs(inclines[1] - step), 3.0)
            for incline in inclines[2:]:
                self.assertLess(incline, 3.0)
            levels = np.array(strategy.state.level_angles)
            np.testing.assert_allclose(np.abs(np.diff(levels[:, 1])), step, atol=1.0)


class TestSearchStartsWhereTheSurfaceIs(unittest.TestCase):
    def test_later_views_find_the_surface_with_their_first_linear_pass(self):
        """Once a section's first view has read, the others are predicted from its points
        (turned to their angles) or from the previous section: their first linear pass reads,
        and the rescans follow it. Searching from the top of the envelope, the other side's
        first pass found nothing."""
        for seed in (11, 12):
            part = TwistedEllipse(a=25.0, b=3.0, length=70.0, twist_deg=TWIST)
            pose = random_fixture_pose(np.random.default_rng(seed), cad_center=(0, 0, 35.0))
            rig = SimulatedRig(part, pose, seed=seed)
            sections = ScanStrategy(rig, ScanOptions(n_sections=3)).run()
            for sec in sections:
                for view in sec.views[1:]:
                    first = view.passes[0]
                    self.assertEqual(first["kind"], "linear")
                    self.assertGreaterEqual(first["readings"], 5, (sec.index, view.name))
                    # A window centred where the surface was expected is not re-centred: the
                    # rescans follow straight on.
                    self.assertEqual(view.passes[1]["kind"], "rescan", (sec.index, view.name))

    def test_first_section_starts_where_the_span_probe_read(self):
        """The span probe's lines along the axis read the surface heights near the first
        section: its levelling search starts there and its first linear pass reads (from the
        top of the envelope it found nothing)."""
        for seed in (11, 12, 13):
            part = TwistedEllipse(a=25.0, b=3.0, length=70.0, twist_deg=TWIST)
            pose = random_fixture_pose(np.random.default_rng(seed), cad_center=(0, 0, 35.0))
            rig = SimulatedRig(part, pose, seed=seed)
            strategy = ScanStrategy(rig, ScanOptions(n_sections=1, sides=1, edges=False))
            strategy.section_y
            first = rig.pass_index
            readings = []
            scan_path = rig.scan_path
            rig.scan_path = lambda p, a: readings.append(scan_path(p, a)) or readings[-1]
            strategy.run()
            self.assertEqual(readings[0].meta["pass_index"], first)
            self.assertGreaterEqual(np.isfinite(readings[0].reading_mm).sum(), 5, seed)

    def test_first_side_view_starts_from_the_levelling(self):
        """The levelling already followed the first section's side1 to within a few degrees of
        its final angle: that view starts from those points turned on (no search pass) and
        still covers the section's side."""
        for seed in (11, 12):
            part = TwistedEllipse(a=25.0, b=3.0, length=70.0, twist_deg=TWIST)
            pose = random_fixture_pose(np.random.default_rng(seed), cad_center=(0, 0, 35.0))
            rig = SimulatedRig(part, pose, seed=seed)
            sections = ScanStrategy(rig, ScanOptions(n_sections=2)).run()
            side1 = sections[0].views[0]
            self.assertEqual(side1.name, "side1")
            self.assertEqual([p["kind"] for p in side1.passes if p["kind"] == "linear"], [])
            self.assertEqual(side1.passes[-1]["kind"], "final")
            # The side's points reach from one edge region to the other (chord 50 mm).
            x = side1.stage_xyz[:, 0]
            self.assertGreater(x.max() - x.min(), 40.0)
            # The next section searches again (only the first one is levelled).
            self.assertEqual(sections[1].views[0].passes[0]["kind"], "linear")

    def test_side_prediction_is_the_far_side_turned_over(self):
        """A plate's top face read at z = 8 from above at 0 deg (axis at the origin, along Y):
        turned by 180 deg about the axis that face lies at z = -8, under the other face, which
        a plate of a few mm puts within the working range of that height."""
        strategy = ScanStrategy(SimulatedRig(Sphere(10.0), np.eye(4)),
                                ScanOptions(span_range=(0, 1)))
        x = np.linspace(-20.0, 20.0, 81)
        top = 8.0
        reading = np.full(len(x), 44.0)
        stage = np.column_stack([x, np.zeros(len(x)), top + reading])
        view = ViewResult("side1", 0.0, stage, reading, np.full(len(x), 90.0), [])
        self.assertAlmostEqual(strategy._side_prediction([view], 180.0), -top, places=9)
        self.assertAlmostEqual(strategy._side_prediction([view], 0.0), top, places=9)
        self.assertIsNone(strategy._side_prediction([], 180.0))


class TestCalibratedKinematics(unittest.TestCase):
    def test_points_on_the_part_only_with_the_true_axis(self):
        """A rig whose rotary axis and stages are off the nominal ones: with the calibrated
        geometry the points of both sides lie on the part through the rig's true table pose;
        with the nominal geometry they miss it."""
        true = RigKinematics(axis_point=[0.4, 0.0, -0.3], axis_direction=[0.003, 1.0, 0.0],
                             stage_scale=[2e-4, 0, -1e-4])
        part = TwistedEllipse(a=25.0, b=3.0, length=70.0, twist_deg=TWIST)
        pose = random_fixture_pose(np.random.default_rng(31), cad_center=(0, 0, 35.0))
        results = {}
        for name, believed in (("calibrated", true), ("nominal", RigKinematics())):
            rig = SimulatedRig(part, pose, seed=31, kinematics=true)
            sections = ScanStrategy(rig, ScanOptions(n_sections=2, edges=False),
                                    kinematics=believed).run()
            xyz = np.vstack([sec.table_xyz for sec in sections])
            snr = np.concatenate([sec.snr for sec in sections])
            dev = part.signed_distance(tf.apply_transform(pose, xyz))
            results[name] = np.abs(dev) > 0.006 * np.sqrt(100.0 / snr) + 2e-4
        self.assertLess(results["calibrated"].mean(), 0.02)
        self.assertGreater(results["nominal"].mean(), 0.5)


class TestDeterminism(unittest.TestCase):
    def test_same_seed_same_points(self):
        a = scan(5, n_sections=2, edges=False, sides=1)[4]
        b = scan(5, n_sections=2, edges=False, sides=1)[4]
        for sa, sb in zip(a, b):
            np.testing.assert_array_equal(sa.table_xyz, sb.table_xyz)
            np.testing.assert_array_equal(sa.snr, sb.snr)


class TestCurveFit(unittest.TestCase):
    def test_fits_a_known_profile_through_gross_errors(self):
        rng = np.random.default_rng(0)
        x = np.sort(rng.uniform(-20, 20, 400))
        truth = lambda x: 10 * np.sqrt(1 - (x / 22.0) ** 2)
        z = truth(x) + rng.uniform(-0.006, 0.006, 400)
        bad = rng.random(400) < 0.03
        z[bad] += rng.uniform(0.1, 0.5, bad.sum())
        curve, keep = fit_stage_profile(x, z)
        self.assertTrue(np.all(~keep[bad]))
        self.assertGreater(keep[~bad].mean(), 0.97)
        xz = curve(np.linspace(0, curve.length, 500))
        np.testing.assert_allclose(xz[:, 1], truth(xz[:, 0]), atol=0.01)
        self.assertAlmostEqual(xz[0, 0], x.min(), delta=0.05)
        self.assertAlmostEqual(xz[-1, 0], x.max(), delta=0.05)

    def test_extension_never_steeper_than_the_coverage(self):
        x = np.linspace(0, 1, 50)
        z = -30 * x          # steeper than 85 deg would allow
        curve, _ = fit_stage_profile(x, z)
        beyond = curve(np.array([curve.length, curve.length + 3.0]))
        self.assertGreaterEqual(beyond[1, 0] - beyond[0, 0], 3.0 * np.cos(np.radians(85)) - 1e-9)


class TestInputs(unittest.TestCase):
    def test_bad_options(self):
        rig = SimulatedRig(Sphere(10.0), np.eye(4))
        for options in ({"sides": 3}, {"epsilon": 9.0}, {"n_sections": 0},
                        {"span_range": (5, 1)}, {"point_spacing": 0}):
            with self.assertRaises(InputError):
                ScanStrategy(rig, ScanOptions(**options))

    def test_nothing_to_scan(self):
        rig = SimulatedRig(Sphere(5.0, center=[0, 0, 500.0]), np.eye(4))
        with self.assertRaises(InputError):
            ScanStrategy(rig, ScanOptions(n_sections=1, search_radius=20.0)).run()


if __name__ == "__main__":
    unittest.main()
