"""Metal angles on a thin-edged section measured as the plan samples Rotor 67's 10 % section,
when the noise given to the kernel over-states the points' own scatter (issue 15).

Independent truth: a double-circular-arc section (tests/airfoil_shapes.py; its camber line an
exact ellipse, the metal angles the ellipse's tangents at the edge circles' centres) shaped
like Rotor 67's 10 % section: edge radii 0.48 / 0.57 mm, 126 mm chord, the kernel's rule on
the exact profile within 0.25 mdeg of those tangents. Sampled as measurement.planning plans
it: 0.1 mm along the flanks, 2 um within two edge radii of each edge circle's centre (where
points lie closer than their noise). Uniform noise along the normal.

The kernel's smoothing spline used to take its residual budget from the noise given
(N sigma^2): when the points scatter less than that (a sensor's stated noise, a noise
estimate a little high), the fit spent the excess on not following the edges, and the metal
angles read the rounded edges: +64 / +72 mdeg over these scans at 1 um scatter given 3.9 um
(the old kernel), against a bound of a few mdeg.
"""
import unittest

import numpy as np

from BladeInspect.core import airfoil
from tests.airfoil_shapes import ArcSection

EDGE_SPACING_MM, FLANK_SPACING_MM, EDGE_REACH = 0.002, 0.1, 2.0
SCANS = 12
HALF_WIDTH_MM = 0.0017          # uniform noise: sigma = 0.98 um
STATED_NOISE_MM = 0.0039        # the noise given (the rig's planned Rotor 67 sections read 3.9 um)
RULE_SLACK_DEG = 0.5e-3         # the kernel's rule against the exact tangent on this section


def thin_section():
    """Rotor 67 10 %-like section: edge radii 0.48 (LE, x < 0) and 0.57 mm (TE)."""
    return ArcSection(Rs=150.0, ys=4.0, Rp=165.0, yp=1.5, x_le=-64.50495, x_te=60.78111)


def planned_points(sec):
    fine = sec.points(EDGE_SPACING_MM)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(fine, axis=0), axis=1))])
    near = np.zeros(len(fine), bool)
    for centre, radius in ((sec.C_le, sec.r_le), (sec.C_te, sec.r_te)):
        near |= np.linalg.norm(fine - sec.to_world(centre)[0], axis=1) < EDGE_REACH * radius
    keep, last = near.copy(), -np.inf
    for i in range(len(fine)):
        if near[i]:
            last = arc[i]
        elif arc[i] - last >= FLANK_SPACING_MM:
            keep[i], last = True, arc[i]
    return fine[keep]


def angle_of(v):
    return float(np.degrees(np.arctan2(v[1], v[0])))


def normals(sec, pts):
    """Exact outward normals of the section's arcs at its points."""
    out = np.zeros_like(pts)
    assigned = np.zeros(len(pts), bool)
    for centre, radius, sign in ((sec.C_le, sec.r_le, 1), (sec.C_te, sec.r_te, 1),
                                 (sec.Os, sec.Rs, 1), (sec.Op, sec.Rp, -1)):
        c = sec.to_world(centre)[0]
        d = pts - c
        on = ~assigned & (np.abs(np.linalg.norm(d, axis=1) - radius) < 1e-9)
        out[on] = sign * d[on] / np.linalg.norm(d[on], axis=1)[:, None]
        assigned |= on
    assert assigned.all()
    return out


class ThinEdgeMetalAngles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.sec = thin_section()
        cls.pts = planned_points(cls.sec)
        cls.normal = normals(cls.sec, cls.pts)
        rng = np.random.default_rng(20261202)
        cls.err = {"inlet": [], "outlet": []}
        for _ in range(SCANS):
            noisy = cls.pts + rng.uniform(-HALF_WIDTH_MM, HALF_WIDTH_MM,
                                          len(cls.pts))[:, None] * cls.normal
            ch = airfoil.characteristics(noisy, noise_mm=STATED_NOISE_MM,
                                         le_upstream=(-1.0, 0.0))
            cls.err["inlet"].append(ch.inlet_angle_deg - angle_of(cls.sec.inlet_dir()))
            cls.err["outlet"].append(ch.outlet_angle_deg - angle_of(cls.sec.outlet_dir()))

    def test_the_case_is_what_it_claims(self):
        self.assertAlmostEqual(self.sec.r_le, 0.48, delta=1e-4)
        self.assertAlmostEqual(self.sec.r_te, 0.57, delta=1e-4)
        spacing = np.linalg.norm(np.diff(self.pts, axis=0), axis=1)
        self.assertGreater(np.mean(spacing < 3 * EDGE_SPACING_MM), 0.5)   # most points dense
        # the normals are the arcs' (the noise is laid along the true normal)
        prof = airfoil.Profile(self.pts)
        n = prof.outward_normal(prof.point_params)
        self.assertGreater(np.min(np.einsum("ij,ij->i", n, self.normal)), 0.999)

    def test_mean_metal_angles_within_the_scatter_of_their_mean(self):
        """Over the seeded scans the mean error is within 3 standard errors of the mean (and
        the rule's own 0.5 mdeg on this section): no bias from the over-stated noise."""
        for end, e in self.err.items():
            e = np.asarray(e)
            sem = e.std(ddof=1) / np.sqrt(len(e))
            with self.subTest(end=end, mean_mdeg=1e3 * e.mean(), sem_mdeg=1e3 * sem):
                self.assertLess(abs(e.mean()), 3.0 * sem + RULE_SLACK_DEG)
                # and the scatter is that of a 1 um scan, not of a rounded edge's
                self.assertLess(e.std(ddof=1), 0.01)


if __name__ == "__main__":
    unittest.main()
