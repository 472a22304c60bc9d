"""core.bspline.basis_derivatives against OpenCASCADE at degrees 1 to 9: random polynomial
B-spline curves (uneven knots, a repeated interior knot), their derivatives up to the third
(above the degree: zero) from the basis derivatives, compared with
Part.BSplineCurve.value/getDN at random parameters, every knot and the ends, to 1e-9
relative."""
import unittest

import numpy as np

import FreeCAD
import Part

from BladeInspect.core import bspline

V = FreeCAD.Vector


class BasisDerivativesAgainstOCC(unittest.TestCase):
    def test_random_curves(self):
        rng = np.random.default_rng(151)
        for p in range(1, 10):
            n_poles = p + 6
            inner = np.sort(rng.uniform(0.05, 0.95, n_poles - p - 1))
            if p >= 2:
                inner[2] = inner[1]
            knots, mults = np.unique(np.round(inner, 12), return_counts=True)
            knots = np.concatenate([[0.0], knots, [1.0]])
            mults = np.concatenate([[p + 1], mults, [p + 1]]).astype(int)
            poles = np.cumsum(rng.normal(0, 1, (n_poles, 3)), axis=0)
            curve = Part.BSplineCurve()
            curve.buildFromPolesMultsKnots([V(*q) for q in poles], mults.tolist(),
                                           knots.tolist(), False, p)
            flat = np.repeat(knots, mults)
            t = np.concatenate([rng.uniform(0, 1, 40), knots])
            span = bspline.find_span(flat, p, t)
            ders = bspline.basis_derivatives(flat, p, span, t, 3)
            rows = span[:, None] - p + np.arange(p + 1)
            ours = np.einsum("nkr,nrd->knd", ders, poles[rows])
            for k in range(4):
                ref = np.array([[c.x, c.y, c.z] for c in
                                (curve.value(x) if k == 0 else curve.getDN(x, k) for x in t)])
                mag = max(1.0, np.abs(ref).max())
                err = np.abs(ours[k] - ref).max() / mag
                self.assertLess(err, 1e-9, "degree %d, derivative %d: %.3g off" % (p, k, err))


if __name__ == "__main__":
    unittest.main()
