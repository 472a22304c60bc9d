"""The metal angle's scatter on noisy points against its Cramer-Rao lower bound (issue 15).

The independent bound is a closed form of the definition's own model: the double-circular-arc
section (tests/airfoil_shapes.py, sides exact circles, camber line an ellipse), each side a
quartic in x over the kernel's window (x along the exact end tangent from the exact edge
centre; the window from the skipped half edge radius over its share of the exact camber
ellipse), its points those the section is built from, normal noise sigma (sigma / cos(slope)
in y); the camber line's slope at the edge (x = 0) is the mean of the two sides' slopes (the
inscribed circle's tangent bisects its contacts' tangents). CRB = 1/4 sum over the sides of
g^T F^-1 g. No code of BladeInspect is used to compute it.
"""
import unittest

import numpy as np

from BladeInspect.core import airfoil, metal_angle_bound
from tests.airfoil_shapes import ArcSection

# The kernel's 1 sigma over SCANS seeded scans lies within [LOW, HIGH] times the bound: at
# least the bound less the sampling error of a 1 sigma from SCANS scans (about
# 1/sqrt(2 SCANS) = 11 %), at most 1.35x. Measured over these scans: 1.04x / 1.13x (inlet /
# outlet) at the default 50 % window, 1.14x / 1.04x at 90 % (the former estimator alike on
# these scans; its excess was the rare scan with a centre off the locus,
# test_centre_off_the_locus_ignored).
SCANS = 40
LOW = 0.8
HIGH = {airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT: 1.35, 90.0: 1.35}


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
    x_near = 0.5 * r
    x_far = x_near + window_pct / 100.0 * locus
    var = 0.0
    for origin, radius in ((sec.Os, sec.Rs), (sec.Op, sec.Rp)):
        on = np.abs(np.linalg.norm(pts - origin, axis=1) - radius) < 1e-9
        q = pts[on] - centre
        x = q @ t
        keep = (x >= x_near) & (x <= x_far)
        radial = pts[on][keep] - origin
        radial /= np.linalg.norm(radial, axis=1)[:, None]
        tangent = np.column_stack([-radial[:, 1], radial[:, 0]])
        slope = np.arctan((tangent @ n) / (tangent @ t))
        sigma_y = sigma / np.cos(slope)
        V = np.vander(x[keep] / x_far, degree + 1, increasing=True)
        F = (V / sigma_y[:, None] ** 2).T @ V
        g = np.zeros(degree + 1)
        # d(angle)/d(coefficient of x/x_far) at x = 0, half of it (the mean of two sides); the
        # side's slope there about its slope at the window's start
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

    def test_bound_module_agrees_with_the_closed_form(self):
        """core.metal_angle_bound's bound (the kernel's own rule differentiated on the
        nominal, a degree-4 deviation per side over the window's arc) is the closed form's
        within 10 % (0.05 mm spacing, the inlet)."""
        pts = self.sec.points(0.05)
        ch = airfoil.characteristics(pts)
        end = "inlet"
        span = metal_angle_bound.window_span_mm(ch, end)
        g = metal_angle_bound.angle_gradient(pts, ch, end, span, 4)
        F, n = metal_angle_bound.fisher(pts, self.SIGMA, ch, end, span, 4)
        used = np.abs(g) > 0
        crb = np.degrees(np.sqrt(g[used] @ np.linalg.solve(F[np.ix_(used, used)], g[used])))
        closed = closed_form_crb(self.sec, 0.05, self.SIGMA,
                                 airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT, end=end)
        self.assertAlmostEqual(crb / closed, 1.0, delta=0.10)
        self.assertGreater(n, 100)


class MetalAngleSmoothOnTheDemoBlade(unittest.TestCase):
    """The inlet angle of the demo blade's 90 % section under a growing deviation of one side
    over the window (0.05 um steps up to 0.4 um, the bound's own kind of perturbation) moves
    smoothly: a lone failed circle mid-locus once cut the camber line in two there (at -0.2 um:
    28 mdeg, 137 of 267 centres)."""

    def test_no_jump(self):
        from BladeInspect.cad.airfoil_sections import airfoil_section
        from BladeInspect.cad.load import load_nominal
        from BladeInspect.inspection.sections import span_axis_of
        nominal = load_nominal(None)
        span, (lo, hi) = span_axis_of(nominal)
        bb = nominal.shape.BoundBox
        centre = np.array([bb.Center.x, bb.Center.y, bb.Center.z])
        origin = centre + ((lo + 0.9 * (hi - lo)) - centre @ span) * span
        xy, _ = airfoil_section(nominal.shape, origin, span)
        ch = airfoil.characteristics(xy)
        prof = ch.profile
        u, _ = prof.closest(xy)
        arc = metal_angle_bound._signed_arc(prof, u, prof.closest(ch.le_point)[0][0])
        mode = metal_angle_bound.basis(arc, metal_angle_bound.window_span_mm(ch, "inlet"), 4)
        push = mode[:, 5][:, None] * prof.outward_normal(u)
        steps = np.arange(-8, 9) * 5e-5
        angles = np.array([airfoil.characteristics(xy + t * push, le_hint=ch.le_point)
                           .inlet_angle_deg for t in steps])
        slope = np.polyfit(steps, angles, 1)[0]
        # off the straight line by less than 0.5 mdeg (a jump was 28 mdeg)
        self.assertLess(np.max(np.abs(angles - ch.inlet_angle_deg - slope * steps)), 5e-4)


if __name__ == "__main__":
    unittest.main()
