"""Section profiles of the validation corpus, in mm, in the section plane (x along the engine
axis, the flow along +x, so the LE is the upstream, -x, end), with their closed-form truths.

Two constructions, neither using any code of BladeInspect:

- ``EnvelopeProfile``: the profile is the boundary of the union of circles of radius r(s)
  centred on a camber line c(s) (s its arc length), |r'| < 1 and r*curvature < 1. Its mean
  camber line (the locus of inscribed-circle centres) IS c(s), its inscribed radii are r(s),
  and its ends are exact circular arcs of radius r(0), r(L) spanning more than +-90 deg about
  the camber line's end tangents. So the edge radii, LE/TE points (c(0) - r(0) t(0),
  c(L) + r(L) t(L)), nose-tail chord and stagger, metal angles (the camber's end tangents) and
  maximum thickness (2 max r) are closed forms. A uniform outward offset d is the same camber
  with r + d, exactly (the union of circles grown by d).
- ``ElliptNoseProfile``: a thickness h(x) laid off normal to a camber line, with an elliptic
  nose (h = H sqrt(1 - (1 - x/a)^2) near the LE: the edge is not a circle) and a circular TE cap
  where h' = 0: the TE radius is exact, the rest of its truth is computed on the CAD (truth.py).
"""
import numpy as np

# ---- camber lines: callables x in [0, 1] -> (N, 2) points, chord 1 along x before scaling


def circular_camber(turning_deg):
    """A circular arc from (0, 0) to (1, 0) turning by ``turning_deg``, symmetric."""
    th = np.radians(turning_deg)

    def f(u):
        if abs(th) < 1e-9:
            return np.column_stack([u, 0 * u])
        R = 0.5 / np.sin(th / 2)
        phi = -th / 2 + th * u          # angle along the arc from the inlet tangent
        x = 0.5 + R * np.sin(phi)
        y = R * np.cos(phi) - R * np.cos(th / 2)
        return np.column_stack([x, y])
    return f


def two_arc_camber(turning1_deg, turning2_deg, split=0.4):
    """A multiple-circular-arc camber: two tangent circular arcs, the first turning
    ``turning1_deg`` over the fraction ``split`` of its length, the second the rest."""
    t1, t2 = np.radians(turning1_deg), np.radians(turning2_deg)

    def f(u):
        # angle of the tangent along arc length s in [0, 1]; piecewise linear (two arcs)
        s = np.asarray(u, float)
        ang = np.where(s < split, t1 * s / split, t1 + t2 * (s - split) / (1 - split))
        ang = ang - (t1 + t2) / 2           # symmetric about the chord
        ss = np.linspace(0, 1, 20001)
        aa = np.where(ss < split, t1 * ss / split, t1 + t2 * (ss - split) / (1 - split)) \
            - (t1 + t2) / 2
        # exact integral of the piecewise-constant-curvature tangent: integrate finely
        x = np.concatenate([[0], np.cumsum((np.cos(-aa[1:]) + np.cos(-aa[:-1])) / 2 * np.diff(ss))])
        y = np.concatenate([[0], np.cumsum((np.sin(-aa[1:]) + np.sin(-aa[:-1])) / 2 * np.diff(ss))])
        return np.column_stack([np.interp(s, ss, x), np.interp(s, ss, y)])
    return f


def naca65_camber(cl):
    """NACA a = 1.0 mean line of design lift ``cl`` (the NACA 65 series' camber)."""
    # Its end slopes are logarithmically infinite: the line is used over x in [e, 1 - e] of
    # the original chord, rescaled to chord 1, so that the metal angles are finite.
    e = 0.005

    def f(u):
        x = e + (1 - 2 * e) * np.asarray(u, float)
        y = -cl / (4 * np.pi) * ((1 - x) * np.log(1 - x) + x * np.log(x))
        y0 = -cl / (4 * np.pi) * ((1 - e) * np.log(1 - e) + e * np.log(e))
        return np.column_stack([np.asarray(u, float), (y - y0) / (1 - 2 * e)])
    return f


def _arclength_resample(f, n=20001):
    u = np.linspace(0.0, 1.0, 200001)
    p = f(u)
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    si = np.linspace(0, s[-1], n)
    return np.column_stack([np.interp(si, s, p[:, 0]), np.interp(si, s, p[:, 1])]), si


class EnvelopeProfile:
    """Union of circles r(s) along a camber line of chord ``chord`` (mm), rotated by
    ``stagger_deg`` (counter-clockwise from +x), shifted by ``shift``. ``radius(q)`` gives r at
    the fraction q in [0, 1] of the camber's length, in mm."""

    def __init__(self, camber, radius, chord=50.0, stagger_deg=0.0, shift=(0.0, 0.0)):
        self.camber_fn, self.radius_fn = camber, radius
        self.chord, self.stagger_deg = chord, stagger_deg
        self.shift = np.asarray(shift, float)
        c, s = _arclength_resample(camber)
        c = c * chord
        s = s * chord
        a = np.radians(stagger_deg)
        R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        self.c = (c - c[0]) @ R.T + self.shift
        self.s = s
        self.L = s[-1]
        t = np.gradient(self.c, s, axis=0, edge_order=2)
        self.t = t / np.linalg.norm(t, axis=1)[:, None]
        self.n = np.column_stack([-self.t[:, 1], self.t[:, 0]])
        self.r = np.array([radius(q) for q in s / self.L])
        self.dr = np.gradient(self.r, s, edge_order=2)

    def grown(self, d):
        """The profile offset outward by d (mm), exactly."""
        return EnvelopeProfile(self.camber_fn, lambda q: self.radius_fn(q) + d, self.chord,
                               self.stagger_deg, self.shift)

    def thickened(self, k):
        """Every inscribed radius times k (a thickness error, edges included)."""
        return EnvelopeProfile(self.camber_fn, lambda q: k * self.radius_fn(q), self.chord,
                               self.stagger_deg, self.shift)

    def le_reshaped(self, dr_le, reach=0.08):
        """The LE radius changed by dr_le, blended smoothly to nothing at ``reach`` of the
        camber's length (an LE re-profiled in manufacture)."""
        f = self.radius_fn

        def r(q):
            w = np.cos(0.5 * np.pi * min(q / reach, 1.0)) ** 2
            return f(q) + dr_le * w
        return EnvelopeProfile(self.camber_fn, r, self.chord, self.stagger_deg, self.shift)

    def points(self):
        """Dense closed loop, counter-clockwise, without the repeated closing point."""
        c, t, n, r, dr = self.c, self.t, self.n, self.r, self.dr
        q = np.sqrt(1 - dr ** 2)
        upper = c + r[:, None] * (-dr[:, None] * t + q[:, None] * n)
        lower = c + r[:, None] * (-dr[:, None] * t - q[:, None] * n)

        def cap(centre, radius, a0, a1, m=400):
            a = np.linspace(a0, a1, m)[1:-1]
            return centre + radius * np.column_stack([np.cos(a), np.sin(a)])
        ang = lambda v: np.arctan2(v[1], v[0])
        # TE cap from the lower side's end to the upper side's end, counter-clockwise
        a0, a1 = ang(lower[-1] - c[-1]), ang(upper[-1] - c[-1])
        a1 += 2 * np.pi * (a1 < a0)
        te = cap(c[-1], r[-1], a0, a1)
        a0, a1 = ang(upper[0] - c[0]), ang(lower[0] - c[0])
        a1 += 2 * np.pi * (a1 < a0)
        le = cap(c[0], r[0], a0, a1)
        loop = np.vstack([lower, te, upper[::-1], le])
        keep = np.concatenate([[True], np.linalg.norm(np.diff(loop, axis=0), axis=1) > 1e-9])
        return loop[keep]

    def closed_form(self):
        """The characteristics that are closed forms of the construction (mm, deg)."""
        le = self.c[0] - self.r[0] * self.t[0]
        te = self.c[-1] + self.r[-1] * self.t[-1]
        ch = te - le
        deg = lambda v: float(np.degrees(np.arctan2(v[1], v[0])))
        return {"le_radius_mm": float(self.r[0]), "te_radius_mm": float(self.r[-1]),
                "max_thickness_mm": float(2 * self.r.max()),
                "chord_mm": float(np.linalg.norm(ch)), "stagger_deg": deg(ch),
                "inlet_angle_deg": deg(self.t[0]), "outlet_angle_deg": deg(self.t[-1])}


def smooth_half_thickness(t_max, r_le, r_te, x_max=0.4):
    """r(q) (mm): r_le at the LE, t_max/2 at q = x_max (r' = 0), r_te at the TE, joined by
    cosine blends (|r'| stays well under 1 for chords of tens of mm)."""
    h = t_max / 2.0

    def r(q):
        if q <= x_max:
            w = np.sin(0.5 * np.pi * q / x_max)
            return float(r_le + (h - r_le) * w)
        w = np.cos(0.5 * np.pi * (q - x_max) / (1 - x_max)) ** 2
        return float(r_te + (h - r_te) * w)
    return r


class ElliptNoseProfile:
    """Thickness h(x) laid off along the camber's normal, chord ``chord``; an elliptic nose of
    length a (fraction of chord) and half-thickness H, a cos^2 fall to the TE half-thickness
    r_te with h' = 0 there, closed by a circular cap of radius r_te (the exact TE radius)."""

    def __init__(self, camber, H, a, r_te, chord=50.0, stagger_deg=0.0):
        self.args = (camber, H, a, r_te, chord, stagger_deg)
        u = np.linspace(0, 1, 20001)
        # cosine spacing: dense at the nose, where the ellipse turns fast
        x = 0.5 * (1 - np.cos(np.pi * u))
        c = camber(x) * chord
        t = np.gradient(c, x, axis=0)
        t /= np.linalg.norm(t, axis=1)[:, None]
        n = np.column_stack([-t[:, 1], t[:, 0]])
        h = np.where(x < a, H * np.sqrt(np.clip(1 - (1 - x / a) ** 2, 0, 1)),
                     r_te + (H - r_te) * np.cos(0.5 * np.pi * (x - a) / (1 - a)) ** 2)
        ang = np.radians(stagger_deg)
        R = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
        self.c, self.t = c @ R.T, t @ R.T
        self.n = n @ R.T
        self.h, self.r_te = h, r_te
        self.upper = self.c + h[:, None] * self.n
        self.lower = self.c - h[:, None] * self.n

    def points(self):
        c, r = self.c[-1], self.r_te
        a0 = np.arctan2(*(self.lower[-1] - c)[::-1])
        a1 = np.arctan2(*(self.upper[-1] - c)[::-1])
        a1 += 2 * np.pi * (a1 < a0)
        a = np.linspace(a0, a1, 400)[1:-1]
        te = c + r * np.column_stack([np.cos(a), np.sin(a)])
        loop = np.vstack([self.lower[1:], te, self.upper[::-1]])
        keep = np.concatenate([[True], np.linalg.norm(np.diff(loop, axis=0), axis=1) > 1e-9])
        return loop[keep]

    def closed_form(self):
        return {"te_radius_mm": float(self.r_te)}


class DenseLoop:
    """A profile known only as a dense counter-clockwise loop (a public geometry, or a
    profile offset numerically); ``closed`` the closed forms that still hold."""

    def __init__(self, loop, closed=None):
        self.loop, self.closed = np.asarray(loop, float), dict(closed or {})

    def points(self):
        return self.loop

    def closed_form(self):
        return dict(self.closed)


class ArcProfile:
    """The double circular arc of tests/airfoil_shapes.py (suction and pressure arcs, exact
    edge circles tangent to both): every characteristic a closed form."""

    def __init__(self, **params):
        import os
        import sys
        sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(
            os.path.abspath(__file__)))))
        from tests.airfoil_shapes import ArcSection
        self.params = params
        self.s = ArcSection(**params)

    def _with(self, **change):
        return ArcProfile(**dict(self.params, **change))

    def grown(self, d):
        return self._with(offset=self.params.get("offset", 0.0) + d)

    def thickened(self, k):
        # the pressure arc lowered: thickness grows by (k - 1) of the maximum thickness
        t = self.s.max_thickness()
        return self._with(yp=self.params.get("yp", 4.0) - (k - 1) * t)

    def le_reshaped(self, dx):
        return self._with(x_le=self.params.get("x_le", -24.0) + dx)

    def points(self):
        return self.s.points(spacing=0.002)

    def closed_form(self):
        s = self.s
        deg = lambda v: float(np.degrees(np.arctan2(v[1], v[0])))
        return {"le_radius_mm": float(s.r_le), "te_radius_mm": float(s.r_te),
                "max_thickness_mm": float(s.max_thickness()), "chord_mm": s.chord(),
                "stagger_deg": deg(s.chord_dir()), "inlet_angle_deg": deg(s.inlet_dir()),
                "outlet_angle_deg": deg(s.outlet_dir())}
