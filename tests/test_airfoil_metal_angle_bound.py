"""The metal angle's scatter on noisy points against its Cramer-Rao lower bound (issue 15).

The independent bound is a closed form of the definition's own model: the double-circular-arc
section (tests/airfoil_shapes.py, sides exact circles, camber line an ellipse), each side a
quartic in x over the kernel's window (x along the exact end tangent from the exact edge
centre, over the window's share of the exact camber ellipse plus the skipped half edge
radius), its points those the section is built from, normal noise sigma (sigma / cos(slope)
in y); the camber line's slope at the edge is the mean of the two sides' slopes (the
inscribed circle's tangent bisects its contacts' tangents). CRB = 1/4 sum over the sides of
g^T F^-1 g. No code of BladeInspect is used to compute it.
"""
import unittest

import numpy as np

from BladeInspect.core import airfoil, metal_angle_bound
from tests.airfoil_shapes import ArcSection

# The kernel's 1 sigma over SCANS seeded scans lies within a factor of the bound: at least the
# bound (less the sampling error of a 1 sigma from SCANS scans, about 1/sqrt(2 SCANS) = 11 %,
# and the kernel's window leaving out the last half edge radius, a few %), at most HIGH times
# it per window. Measured over these scans: at the default 50 % window 1.42x / 1.54x (inlet /
# outlet; the former estimator, a quartic fitted to the centres as sampled: 1.45x / 1.54x --
# the 50 % window is not yet efficient, its error heavy-tailed); at a 90 % window 1.0x / 1.1x
# (the former estimator alike on these scans: its excess was one scan in 20 with a centre off
# the locus, test_centre_off_the_locus_ignored).
SCANS = 40
LOW = 0.75
HIGH = {airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT: 1.7, 90.0: 1.6}


def closed_form_crb(sec, spacing, sigma, window_pct, degree=4, end="inlet"):
    """1 sigma bound (deg) of the inlet or outlet metal angle of an ArcSection in its own frame
    (module notes)."""
    pts = sec.points(spacing)
    if end == "inlet":
        centre, t, r = sec.C_le, np.asarray(sec.inlet_dir(), float), sec.r_le
    else:
        centre, t, r = sec.C_te, -np.asarray(sec.outlet_dir(), float), sec.r_te
    t = t / np.linalg.norm(t)
    n = np.array([-t[1], t[0]])
    xe = np.linspace(sec.C_le[0], sec.C_te[0], 20001)
    ellipse = np.array([sec.ellipse(x) for x in xe])
    locus = np.sum(np.linalg.norm(np.diff(ellipse, axis=0), axis=1))
    x_far = 0.5 * r + window_pct / 100.0 * locus
    var = 0.0
    for origin, radius in ((sec.Os, sec.Rs), (sec.Op, sec.Rp)):
        on = np.abs(np.linalg.norm(pts - origin, axis=1) - radius) < 1e-9
        q = pts[on] - centre
        x = q @ t
        keep = (x >= 0.0) & (x <= x_far)
        radial = pts[on][keep] - origin
        radial /= np.linalg.norm(radial, axis=1)[:, None]
        tangent = np.column_stack([-radial[:, 1], radial[:, 0]])
        slope = np.arctan((tangent @ n) / (tangent @ t))
        sigma_y = sigma / np.cos(slope)
        V = np.vander(x[keep] / x_far, degree + 1, increasing=True)
        F = (V / sigma_y[:, None] ** 2).T @ V
        g = np.zeros(degree + 1)
        # d(angle)/d(coefficient of x/x_far) at x = 0, half of it (the mean of two sides)
        g[1] = 0.5 * np.cos(slope[np.argmin(x[keep])]) ** 2 / x_far
        var += g @ np.linalg.solve(F, g)
    return float(np.degrees(np.sqrt(var)))


def angle_of(v):
    return float(np.degrees(np.arctan2(v[1], v[0])))


class MetalAngleAgainstItsBound(unittest.TestCase):
    SIGMA, SPACING = 0.002, 0.02

    @classmethod
    def setUpClass(cls):
        cls.sec = ArcSection(x_le=-24.0, x_te=27.0)
        cls.pts = cls.sec.points(cls.SPACING)
        prof = airfoil.Profile(cls.pts)
        cls.truth = airfoil.characteristics(prof)
        normal = prof.outward_normal(prof.point_params)
        rng = np.random.default_rng(20261202)
        scans = [cls.pts + rng.normal(0.0, cls.SIGMA, len(cls.pts))[:, None] * normal
                 for _ in range(SCANS)]
        cls.errors = {}
        for window in HIGH:
            truth = airfoil.characteristics(prof, metal_angle_window_pct=window)
            err = cls.errors[window] = {"inlet": [], "outlet": []}
            for noisy in scans:
                ch = airfoil.characteristics(noisy, noise_mm=cls.SIGMA,
                                             metal_angle_window_pct=window)
                err["inlet"].append(ch.inlet_angle_deg - truth.inlet_angle_deg)
                err["outlet"].append(ch.outlet_angle_deg - truth.outlet_angle_deg)
        cls.err = cls.errors[airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT]

    def test_exact_nominal_is_the_exact_tangent(self):
        self.assertAlmostEqual(self.truth.inlet_angle_deg, angle_of(self.sec.inlet_dir()),
                               delta=1e-3)
        self.assertAlmostEqual(self.truth.outlet_angle_deg, angle_of(self.sec.outlet_dir()),
                               delta=1e-3)

    def test_scatter_within_a_factor_of_the_bound(self):
        for window, high in HIGH.items():
            for end in ("inlet", "outlet"):
                crb = closed_form_crb(self.sec, self.SPACING, self.SIGMA, window, end=end)
                e = np.asarray(self.errors[window][end])
                sd = e.std(ddof=1)
                with self.subTest(window=window, end=end, sd_mdeg=1e3 * sd,
                                  crb_mdeg=1e3 * crb):
                    self.assertGreater(sd, LOW * crb)
                    self.assertLess(sd, high * crb)
                    # no bias beyond the mean's sampling error
                    self.assertLess(abs(e.mean()), 3.5 * sd / np.sqrt(len(e)))

    def test_centre_off_the_locus_ignored(self):
        """Scan 14 of seed 11 (bench/bench_airfoil_metal_angle.py's first figures) has an
        inscribed circle refined onto a wrong foot mid-locus, 0.13 mm off it: the former fit
        read the inlet angle 49 mdeg off (8.5 x the bound); now within 3 x the bound."""
        rng = np.random.default_rng(11)
        prof = airfoil.Profile(self.pts)
        normal = prof.outward_normal(prof.point_params)
        for _ in range(15):
            noisy = self.pts + rng.normal(0.0, self.SIGMA, len(self.pts))[:, None] * normal
        ch = airfoil.characteristics(noisy, noise_mm=self.SIGMA)
        window = airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT
        for end, key in (("inlet", "inlet_angle_deg"), ("outlet", "outlet_angle_deg")):
            crb = closed_form_crb(self.sec, self.SPACING, self.SIGMA, window, end=end)
            self.assertLess(abs(getattr(ch, key) - getattr(self.truth, key)), 3.0 * crb)

    def test_bound_module_below_the_scatter(self):
        """core.metal_angle_bound's bound (a sub-model: a parabola deviation per side) is
        below the estimator's scatter and scales as sigma / sqrt(n)."""
        pts = self.sec.points(0.05)
        ch = airfoil.characteristics(pts)
        b2 = metal_angle_bound.metal_angle_bound(pts, ch, pts, self.SIGMA, degree=2)
        b2s = metal_angle_bound.metal_angle_bound(pts, ch, pts[::2], 2 * self.SIGMA, degree=2)
        for end in ("inlet", "outlet"):
            sd = np.std(self.err[end], ddof=1) * np.sqrt(0.05 / self.SPACING)
            self.assertLess(b2[end]["crb_deg"], sd)
            self.assertAlmostEqual(b2s[end]["crb_deg"] / b2[end]["crb_deg"],
                                   2.0 * np.sqrt(2.0), delta=0.15)
            self.assertGreater(b2[end]["spacing_for_target_mm"], 0.0)


if __name__ == "__main__":
    unittest.main()
