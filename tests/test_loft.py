"""Section curve fitting and lofting against known curves and surfaces with sensor-like noise.

Truths are independent of the code under test: a circle arc (closed-form distance), a
scipy B-spline sampled densely, and the demo blade's side faces measured with OCC."""
import unittest

import numpy as np
from scipy.interpolate import BSpline

import FreeCAD
import Part

from BladeInspect.cad.demo_blade import make_demo_blade
from BladeInspect.cad.loft import (FOLLOW_SIGMAS, cluster_angles, fit_section_curve,
                                   fit_section_pass, loft, make_compatible, reconstruct)
from BladeInspect.core.errors import InputError
from BladeInspect.core.pointio import PointSet
from BladeInspect.core.transforms import apply_transform, invert_transform, random_transform

V = FreeCAD.Vector
NOISE = 0.006                      # uniform +-6 um, the paper's sensor error
NOISE_RMS = NOISE / np.sqrt(3.0)


def curve_points(curve, n=3000):
    a, b = curve.FirstParameter, curve.LastParameter
    return np.array([tuple(curve.value(t)) for t in np.linspace(a, b, n)])


def random_frame(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q)), rng.uniform(-50, 50, 3)


class FitSectionCurve(unittest.TestCase):
    def test_circle_arc_in_random_planes(self):
        for seed in range(4):
            rng = np.random.default_rng(seed)
            R, t = random_frame(rng)
            radius = rng.uniform(20, 60)
            ang = np.sort(rng.uniform(-0.6, 0.6, 500))
            local = np.column_stack([radius * np.cos(ang), radius * np.sin(ang), 0 * ang])
            normal_local = local / radius
            noisy = local + rng.uniform(-NOISE, NOISE, len(ang))[:, None] * normal_local
            curve, rms, worst = fit_section_curve(noisy @ R.T + t)
            # Residuals are the noise itself: rms of U(-a, a) is a / sqrt(3).
            self.assertAlmostEqual(rms / NOISE_RMS, 1.0, delta=0.12)
            self.assertLess(worst, 2 * NOISE)  # noise plus the fit's own error
            self.assertEqual(curve.Degree, 3)
            # The fitted curve against the exact circle, closed form |p - c| - R.
            back = (curve_points(curve) - t) @ R
            self.assertLess(np.max(np.abs(back[:, 2])), 0.003)
            # Within the noise band everywhere, a fraction of it on average.
            err = np.abs(np.linalg.norm(back[:, :2], axis=1) - radius)
            self.assertLess(err.max(), NOISE)
            self.assertLess(np.sqrt(np.mean(err ** 2)), 0.4 * NOISE_RMS)

    def test_gross_outliers_do_not_pull_the_curve(self):
        rng = np.random.default_rng(17)
        radius = 40.0
        ang = np.sort(rng.uniform(-0.5, 0.5, 600))
        err = rng.uniform(-NOISE, NOISE, len(ang))
        spikes = rng.choice(len(ang), 12, replace=False)
        err[spikes] = rng.choice([-1, 1], 12) * rng.uniform(0.1, 0.5, 12)
        r = radius + err
        pts = np.column_stack([r * np.cos(ang), r * np.sin(ang), 0 * ang])
        curve, rms, worst = fit_section_curve(pts)
        self.assertAlmostEqual(rms / NOISE_RMS, 1.0, delta=0.15)
        self.assertLess(worst, 2 * NOISE)
        fitted = curve_points(curve)
        self.assertLess(np.abs(np.linalg.norm(fitted[:, :2], axis=1) - radius).max(), NOISE)

    def test_known_bspline_profile_any_input_order(self):
        rng = np.random.default_rng(11)
        # A wavy cubic profile 50 mm long, like one side of a blade section.
        poles = np.column_stack([np.linspace(0, 50, 9),
                                 [0, 3, 5.5, 6.5, 6, 4.5, 3, 1.5, 0], np.zeros(9)])
        knots = np.concatenate([[0] * 4, np.linspace(0, 1, 7)[1:-1], [1] * 4])
        truth = BSpline(knots, poles, 3)
        dense = truth(np.linspace(0, 1, 200001))
        s = np.sort(rng.uniform(0, 1, 700))
        pts = truth(s)
        tangent = truth.derivative()(s)
        normal = np.column_stack([-tangent[:, 1], tangent[:, 0], 0 * s])
        normal /= np.linalg.norm(normal, axis=1)[:, None]
        noisy = pts + rng.uniform(-NOISE, NOISE, len(s))[:, None] * normal
        a = fit_section_curve(noisy)
        b = fit_section_curve(noisy[rng.permutation(len(noisy))])
        self.assertAlmostEqual(a[1] / NOISE_RMS, 1.0, delta=0.12)
        fitted = curve_points(a[0])
        # Distance of the fitted curve to the truth, by brute force on 200k truth points.
        from scipy.spatial import cKDTree
        d, _ = cKDTree(dense).query(fitted)
        self.assertLess(d.max(), NOISE)
        self.assertLess(np.sqrt(np.mean(d ** 2)), 0.4 * NOISE_RMS)
        self.assertEqual(a[0].getPoles(), b[0].getPoles())

    def test_pass_folding_round_an_edge(self):
        # An edge view: two flanks joined by a round edge (radius 0.8 mm), a U whose largest
        # extent runs along the flanks, given in random order.
        rng = np.random.default_rng(9)
        r, flank = 0.8, 4.0
        s = rng.uniform(0, 2 * flank + np.pi * r, 900)
        phi = np.clip((s - flank) / r, 0, np.pi)
        on_round = (s > flank) & (s < flank + np.pi * r)
        upper = s <= flank
        x = np.where(on_round, -r * np.sin(phi), np.where(upper, flank - s,
                                                          s - flank - np.pi * r))
        y = np.where(on_round, r * np.cos(phi), np.where(upper, r, -r))
        pts = np.column_stack([x, y, np.zeros_like(x)])
        # Exact distance: to the circle on the round, to the flank lines elsewhere.
        def distance(p):
            round_d = np.abs(np.hypot(p[:, 0], p[:, 1]) - r)
            flank_d = np.abs(np.abs(p[:, 1]) - r)
            return np.where(p[:, 0] < 0, round_d, flank_d)
        self.assertLess(distance(pts).max(), 1e-12)
        normal = np.where(on_round[:, None], pts / r, np.column_stack([0 * x, np.sign(y), 0 * x]))
        noisy = pts + rng.uniform(-NOISE, NOISE, len(s))[:, None] * normal
        curve, rms, worst = fit_section_curve(noisy[rng.permutation(len(s))])
        fitted = curve_points(curve, 2000)
        self.assertLess(rms, 2 * NOISE_RMS)
        # The round edge has a curvature jump at each flank, where a cubic lags a little.
        self.assertLess(np.percentile(distance(fitted), 95), NOISE)
        self.assertLess(distance(fitted).max(), 0.02)

    def test_coarse_pass_onto_an_edge_follows_every_reading(self):
        """A 1 mm pass along a flank that turns round a 1 mm edge radius at its end, with two
        0.2 mm spikes on the flank: the spikes are left out, and OCC's
        distance from every other reading to the curve is within 4 sigma of the noise. With
        uniform knots the turn was missed by a tenth of a millimetre and more."""
        for seed in range(3):
            rng = np.random.default_rng(seed)
            r, flank = 1.0, 30.0
            s = np.arange(0.0, flank + np.pi * r, 1.0) + rng.uniform(-0.05, 0.05)
            phi = np.clip((s - flank) / r, 0, np.pi)
            on_flank = s <= flank
            x = np.where(on_flank, s, flank + r * np.sin(phi))
            y = np.where(on_flank, 0.0, r - r * np.cos(phi))
            normal = np.where(on_flank[:, None], [[0.0, -1.0]],
                              np.column_stack([np.sin(phi), -np.cos(phi)]))
            e = rng.uniform(-NOISE, NOISE, len(s))
            spikes = rng.choice(np.arange(5, 25), 2, replace=False)
            e[spikes] = 0.2 * rng.choice([-1, 1], 2)
            pts = np.column_stack([x + e * normal[:, 0], y + e * normal[:, 1], 0 * s])
            fit = fit_section_pass(pts)
            self.assertTrue(np.all(fit.rejected[spikes]))
            # At 1 mm a turn onto the edge can look like a spike: at most one good reading
            # of the 32 is left out (and reported).
            self.assertLessEqual(np.count_nonzero(fit.rejected) - 2, 1)
            edge = Part.Edge(fit.curve)
            gaps = np.array([edge.distToShape(Part.Vertex(V(*p)))[0] for p in pts])
            self.assertLess(gaps[fit.kept].max(), FOLLOW_SIGMAS * NOISE_RMS)
            self.assertGreater(gaps[spikes].min(), 0.1)
            self.assertLess(abs(fit.max - gaps[fit.kept].max()), 1e-5)
            self.assertEqual(fit.record()["n_rejected"], np.count_nonzero(fit.rejected))

    def test_too_few_or_bad_points(self):
        with self.assertRaises(InputError):
            fit_section_curve(np.zeros((3, 3)) + np.arange(3)[:, None])
        with self.assertRaises(InputError):
            fit_section_curve(np.ones((10, 3)))
        with self.assertRaises(InputError):
            fit_section_curve(np.full((10, 3), np.nan))


class CompatibleAndLoft(unittest.TestCase):
    def setUp(self):
        self.curves = []
        for k, z in enumerate((0.0, 10.0, 25.0, 30.0)):
            x = np.linspace(0, 40 - 2 * k, 300)
            pts = np.column_stack([x, (3 + k * 0.3) * np.sin(np.pi * x / x[-1]) + k * 0.5,
                                   np.full_like(x, z)])
            self.curves.append(fit_section_curve(pts, n_poles=8 + 3 * k)[0])

    def test_compatible_curves_keep_their_shape_and_are_arc_length(self):
        out = make_compatible(self.curves)
        for c in out:
            self.assertEqual(c.Degree, 3)
            self.assertEqual(c.getKnots(), out[0].getKnots())
            self.assertEqual(c.getMultiplicities(), out[0].getMultiplicities())
        for orig, comp in zip(self.curves, out):
            edge = Part.Edge(orig)
            for p in curve_points(comp, 25):
                # Arc length is not a spline of the old parameter: refit error < 0.2 um.
                self.assertLess(edge.distToShape(Part.Vertex(V(*p)))[0], 2e-4)
            total = comp.length()
            for f in (0.25, 0.5, 0.8):
                self.assertAlmostEqual(comp.length(0, f) / total, f, delta=2e-4)

    def test_loft_passes_through_every_curve(self):
        comp = make_compatible(self.curves)
        z = np.array([0.0, 10.0, 25.0, 30.0])
        for n in (2, 3, 4):
            surface = loft(comp[:n], v_params=z[:n])
            self.assertEqual(surface.VDegree, min(3, n - 1))
            for c, v in zip(comp[:n], z[:n]):
                for u in np.linspace(0, 1, 9):
                    self.assertLess((surface.value(u, v) - c.value(u)).Length, 1e-9)
        # Incompatible curves are made compatible on the way.
        face = Part.Face(loft(self.curves))
        for c in self.curves:
            for p in curve_points(c, 10):
                self.assertLess(face.distToShape(Part.Vertex(V(*p)))[0], 2e-4)
        with self.assertRaises(InputError):
            loft(comp[:1])


def blade_scan(rng, sections, twist_per_section=2.0, n_per_pass=500, drop=()):
    """Section passes over the demo blade's two sides at the given heights, with uniform
    noise along the surface normal, as a PointSet (section, angle_deg columns)."""
    model = make_demo_blade()
    xyz, sec, ang = [], [], []
    for k, z in enumerate(sections):
        for side, base in (("suction", 355.0), ("pressure", 175.0)):
            if (k, side) in drop:
                continue
            srf = model.shape.Faces[model.roles[side][0]].Surface
            u = np.sort(rng.uniform(0.1, 0.9, n_per_pass))
            pts = np.array([tuple(srf.value(x, z)) for x in u])
            nrm = np.array([tuple(srf.normal(x, z)) for x in u])
            xyz.append(pts + rng.uniform(-NOISE, NOISE, len(u))[:, None] * nrm)
            sec += [k] * len(u)
            ang += [(base + twist_per_section * k) % 360.0] * len(u)
    return model, np.vstack(xyz), np.array(sec, float), np.array(ang, float)


class Reconstruct(unittest.TestCase):
    def test_blade_sections_in_an_unknown_frame(self):
        rng = np.random.default_rng(21)
        # The demo blade's own section heights: the truth is cubic across them too.
        model, xyz, sec, ang = blade_scan(rng, np.linspace(0, 70, 9), twist_per_section=9.0)
        sides = Part.Compound([model.shape.Faces[model.roles[r][0]]
                               for r in ("suction", "pressure")])
        # A random pose, and one turning the mid-span chord across X so that the passes'
        # walking directions differ between sections (the curves must be turned to match).
        turn = np.radians(81.2)
        across = np.eye(4)
        across[:2, :2] = [[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]]
        for move in (random_transform(rng, 100.0), across):
            order = rng.permutation(len(xyz))
            ps = PointSet(xyz=apply_transform(move, xyz)[order], snr=None,
                          columns={"section": sec[order], "angle_deg": ang[order],
                                   "phase": np.zeros(len(xyz))})
            recon = reconstruct(ps)
            self.assertEqual(len(recon.curves), 18)
            self.assertEqual(len(recon.surfaces), 2)
            self.assertEqual(recon.notes, [])
            # The angles turn 72 degrees over the span; each side is still one track.
            for side in (0, 1):
                self.assertEqual(len([g for g in recon.groups if g["side"] == side]), 9)
            for e in recon.fit_errors:
                self.assertAlmostEqual(e["rms"] / NOISE_RMS, 1.0, delta=0.15)
            back = invert_transform(move)
            for surface in recon.surfaces:
                u0, u1, v0, v1 = surface.bounds()
                pts = np.array([tuple(surface.value(u, v)) for v in np.linspace(v0, v1, 25)
                                for u in np.linspace(u0, u1, 7)])
                pts = apply_transform(back, pts)
                d = np.array([sides.distToShape(Part.Vertex(V(*p)))[0] for p in pts])
                self.assertLess(np.median(d), 0.002)
                self.assertLess(d.max(), 0.008)
            # Every reading lies on its side's lofted surface within 4 sigma of the noise, by
            # OCC's own distance, and within the gap the reconstruction states.
            faces = Part.Compound([s.toShape() for s in recon.surfaces])
            moved = apply_transform(move, xyz)
            gaps = np.array([faces.distToShape(Part.Vertex(V(*p)))[0] for p in moved[::7]])
            self.assertLess(gaps.max(), 4 * NOISE_RMS)
            self.assertLessEqual(gaps.max(),
                                 max(e["max_gap_mm"] for e in recon.surface_errors) + 1e-6)
            self.assertEqual(sum(e["n_rejected"] for e in recon.fit_errors), 0)
            self.assertEqual(recon.samples.shape[1], 3)
            self.assertGreater(len(recon.samples), 5000)
            # The samples lie on the lofted surfaces: spot-check against OCC.
            for p in recon.samples[:: len(recon.samples) // 15]:
                q = apply_transform(back, p[None])[0]
                self.assertLess(sides.distToShape(Part.Vertex(V(*q)))[0], 0.008)

    def test_degenerate_groups_are_skipped_with_notes(self):
        rng = np.random.default_rng(4)
        model, xyz, sec, ang = blade_scan(rng, [10.0, 30.0, 50.0], n_per_pass=200,
                                          drop=[(2, "pressure")])
        # Three stray points of a third view on section 1, and non-section points.
        xyz = np.vstack([xyz, xyz[:3] + 0.1, xyz[:5]])
        sec = np.concatenate([sec, [1, 1, 1], [-1] * 5])
        ang = np.concatenate([ang, [90.0] * 3, [0.0] * 5])
        recon = reconstruct(PointSet(xyz=xyz, columns={"section": sec, "angle_deg": ang}))
        self.assertEqual(len(recon.curves), 5)
        self.assertEqual(len(recon.surfaces), 2)
        self.assertTrue(any("3 points" in n for n in recon.notes), recon.notes)
        skipped = [g for g in recon.groups if g["curve"] is None]
        self.assertEqual([(g["section"], g["n_points"]) for g in skipped], [(1, 3)])

    def test_views_seeing_different_stretches_give_no_surface(self):
        rng = np.random.default_rng(6)
        model, xyz, sec, ang = blade_scan(rng, [10.0, 30.0, 50.0], n_per_pass=200)
        # A third view that sees a short stretch near the leading edge on one section and
        # most of the side on the others.
        srf = model.shape.Faces[model.roles["suction"][0]].Surface
        extra = []
        for k, (z, hi) in enumerate(((10.0, 0.25), (30.0, 0.8), (50.0, 0.8))):
            u = np.linspace(0.02, hi, 150)
            extra.append(np.array([tuple(srf.value(x, z)) for x in u]))
        recon = reconstruct(PointSet(
            xyz=np.vstack([xyz] + extra),
            columns={"section": np.concatenate([sec, np.repeat([0.0, 1.0, 2.0], 150)]),
                     "angle_deg": np.concatenate([ang, np.full(450, 85.0)])}))
        self.assertEqual((len(recon.curves), len(recon.surfaces)), (9, 2))
        self.assertTrue(any("mm long, no surface" in n for n in recon.notes), recon.notes)

    def test_one_section_gives_curves_without_surfaces(self):
        rng = np.random.default_rng(8)
        _, xyz, sec, ang = blade_scan(rng, [35.0], n_per_pass=150)
        recon = reconstruct(PointSet(xyz=xyz, columns={"section": sec, "angle_deg": ang}))
        self.assertEqual((len(recon.curves), len(recon.surfaces)), (2, 0))
        self.assertTrue(any("no surface" in n for n in recon.notes))
        self.assertGreater(len(recon.samples), 100)

    def test_nothing_to_reconstruct(self):
        xyz = np.random.default_rng(0).normal(size=(30, 3))
        self.assertIsNone(reconstruct(PointSet(xyz=xyz, columns={})))
        self.assertIsNone(reconstruct(PointSet(xyz=xyz, columns={"section": np.zeros(30)})))
        with self.assertRaises(InputError):
            reconstruct(PointSet(xyz=xyz, columns={"section": np.full(30, -1.0),
                                                   "angle_deg": np.zeros(30)}))
        # Every group too small.
        sec = np.repeat(np.arange(10), 3).astype(float)
        with self.assertRaises(InputError) as ctx:
            reconstruct(PointSet(xyz=xyz, columns={"section": sec, "angle_deg": np.zeros(30)},
                                 source="scan.csv"))
        self.assertIn("scan.csv", str(ctx.exception))


class ClusterAngles(unittest.TestCase):
    def test_clusters_wrap_round_360(self):
        labels = cluster_angles([359.0, 1.0, 0.5, 180.0, 181.0, 90.0, 270.0, -2.0])
        groups = {}
        for a, lab in zip(["a", "a", "a", "b", "b", "c", "d", "a"], labels):
            groups.setdefault(a, set()).add(lab)
        self.assertTrue(all(len(v) == 1 for v in groups.values()))
        self.assertEqual(len(set(labels)), 4)
        self.assertEqual(len(set(cluster_angles([10.0, 12.0, 15.0]))), 1)


if __name__ == "__main__":
    unittest.main()
