"""High-turning turbine profiles whose characteristics are known in closed form.

The camber line is a circular arc of the given turning. The profile is the envelope of the
circles centred on it with radius r(s) (s: arc length along it), so every one of those circles
is inscribed and the inscribed-circle locus is the arc itself: the largest inscribed circle is
max r, the metal angles are the arc's end tangents. The LE is capped by the end circle (radius
r(0), tangent to both flanks, its centre the camber line's end) or by a half ellipse (the
radius flat at the LE, so the flanks there run parallel to the end tangent and the ellipse's
co-vertices meet them tangentially; the nose is the ellipse's vertex on the end tangent, and
inside the ellipse the inscribed-circle locus runs straight along that tangent). The TE is
capped by the end circle.

r(s) is r_max - k (x - x_max)^2 (x = s / S), fixed by r(0) = r_le and r(1) = r_te; with an
elliptic nose the LE side is a smoothstep from r_le (flat at the LE) whose curvature at x_max
matches the TE side's, so r is twice differentiable and largest at x_max.
"""

import math

import numpy as np

_SPACING_MM = 0.04
_CAP_STEP_DEG = 1.5


def _rot(v, angle_deg):
    a = math.radians(angle_deg)
    c, s = math.cos(a), math.sin(a)
    v = np.asarray(v, dtype=float)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


class TurbineSection:
    """A turbine profile on a circular-arc camber line of ``turning_deg``, camber length
    ``camber_mm``, inscribed radius r_le at the LE end, r_te at the TE end, largest
    ``r_max``; ``nose_mm``: the elliptic nose's semi-axis along the end tangent (None: a
    circular LE of radius r_le). The whole is rotated by ``pose_deg`` about the origin and
    shifted by ``shift``; the engine axis is +x."""

    def __init__(self, turning_deg, camber_mm, r_le, r_te, r_max, nose_mm=None,
                 pose_deg=0.0, shift=(0.0, 0.0)):
        if not (r_max > r_le and r_max > r_te > 0 and r_le > 0):
            raise ValueError("need r_max > r_le, r_te > 0")
        self.turning = math.radians(turning_deg)
        self.S = float(camber_mm)
        self.Rc = self.S / self.turning
        self.r_le, self.r_te, self.r_max = float(r_le), float(r_te), float(r_max)
        self.nose = nose_mm
        self.pose, self.shift = float(pose_deg), np.asarray(shift, dtype=float)
        dl, dt = r_max - r_le, r_max - r_te
        if nose_mm is None:
            # one parabola through r_le at 0 and r_te at 1 with its vertex r_max at x_max
            q = math.sqrt(dl / dt)
            self.x_max = q / (1.0 + q)
        else:
            # smoothstep on the LE side: curvature -6 dl / x^2; parabola on the TE side:
            # -2 dt / (1 - x)^2; equal at x_max
            q = math.sqrt(3.0 * dl / dt)
            self.x_max = q / (1.0 + q)
        self.k_te = dt / (1.0 - self.x_max) ** 2
        self.phi0 = math.pi / 2 + self.turning / 2

    # ---- the local frame (before the pose): camber arc about the origin, run clockwise
    def _r(self, x):
        x = np.asarray(x, dtype=float)
        xm = self.x_max
        te_side = self.r_max - self.k_te * (x - xm) ** 2
        if self.nose is None:
            return te_side
        u = np.clip(x / xm, 0.0, 1.0)
        le_side = self.r_le + (self.r_max - self.r_le) * (3 * u ** 2 - 2 * u ** 3)
        return np.where(x < xm, le_side, te_side)

    def _dr_ds(self, x):
        x = np.asarray(x, dtype=float)
        xm = self.x_max
        te_side = -2.0 * self.k_te * (x - xm)
        if self.nose is not None:
            u = np.clip(x / xm, 0.0, 1.0)
            le_side = (self.r_max - self.r_le) * (6 * u - 6 * u ** 2) / xm
            te_side = np.where(x < xm, le_side, te_side)
        return te_side / self.S

    def _camber(self, s):
        phi = self.phi0 - np.asarray(s, dtype=float) / self.Rc
        c = self.Rc * np.stack([np.cos(phi), np.sin(phi)], axis=-1)
        t = np.stack([np.sin(phi), -np.cos(phi)], axis=-1)
        n = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
        return c, t, n

    def _place(self, p):
        return _rot(p, self.pose) + self.shift

    def _dir(self, v):
        return _rot(v, self.pose)

    # ---- the profile
    def points(self, spacing=_SPACING_MM):
        n_s = int(math.ceil(self.S * (self.Rc + self.r_max) / self.Rc / spacing)) + 1
        x = np.linspace(0.0, 1.0, n_s)
        s = x * self.S
        c, t, n = self._camber(s)
        r, rho = self._r(x), self._dr_ds(x)
        root = np.sqrt(1.0 - rho ** 2)
        outer = c + r[:, None] * (-rho[:, None] * t + root[:, None] * n)
        inner = c + r[:, None] * (-rho[:, None] * t - root[:, None] * n)
        te_cap = self._cap(c[-1], t[-1], n[-1], r[-1], rho[-1], front=+1)
        if self.nose is None:
            le_cap = self._cap(c[0], t[0], n[0], r[0], rho[0], front=-1)
        else:
            le_cap = self._ellipse_cap(c[0], t[0], n[0])
        # outer flank LE -> TE, TE cap, inner flank TE -> LE, LE cap (inner side to outer)
        loop = np.vstack([outer, te_cap, inner[::-1], le_cap])
        return self._place(loop)

    @staticmethod
    def _cap(centre, t, n, r, rho, front):
        """The end circle's arc outside the envelope, from the outer flank's contact round the
        front (+t at the TE, -t at the LE) to the inner flank's (TE) or back (LE)."""
        root = math.sqrt(1.0 - rho ** 2)
        a_out = math.atan2(*(-rho * t + root * n)[::-1])
        a_in = math.atan2(*(-rho * t - root * n)[::-1])
        if front > 0:       # outer -> inner, clockwise through +t
            sweep = (a_out - a_in) % (2 * math.pi)
            a = a_out - np.linspace(0.0, sweep, max(8, int(math.degrees(sweep)
                                                          / _CAP_STEP_DEG)))[1:-1]
        else:               # inner -> outer, clockwise through -t
            sweep = (a_in - a_out) % (2 * math.pi)
            a = a_in - np.linspace(0.0, sweep, max(8, int(math.degrees(sweep)
                                                         / _CAP_STEP_DEG)))[1:-1]
        return centre + r * np.stack([np.cos(a), np.sin(a)], axis=-1)

    def _ellipse_cap(self, centre, t, n):
        """Half ellipse: semi-axis nose along -t, r_le along n; inner co-vertex to outer."""
        a = np.linspace(-math.pi / 2, math.pi / 2, int(180 / _CAP_STEP_DEG) + 1)[1:-1]
        # from -n (inner) through -t to +n (outer)
        return (centre - np.cos(a)[:, None] * self.nose * t
                + np.sin(a)[:, None] * self.r_le * n)

    # ---- the closed-form truth
    def truth(self):
        c, t, _ = self._camber(np.array([0.0, self.S]))
        le_ext = self.r_le if self.nose is None else self.nose
        le = c[0] - le_ext * t[0]
        te = c[1] + self.r_te * t[1]
        cm, _, _ = self._camber(self.x_max * self.S)
        le, te = self._place(le), self._place(te)
        chord = te - le
        axis = np.array([1.0, 0.0])

        def angle(v):
            return math.degrees(math.atan2(axis[0] * v[1] - axis[1] * v[0], axis @ v))

        nose_tail = float(np.linalg.norm(chord))
        centre = self._place(cm)
        return {
            "le_point": le, "te_point": te, "nose_tail_chord_mm": nose_tail,
            "stagger_deg": angle(chord),
            "inlet_angle_deg": angle(self._dir(t[0])),
            "outlet_angle_deg": angle(self._dir(t[1])),
            "le_radius_mm": self.r_le if self.nose is None else None,
            "te_radius_mm": self.r_te, "max_thickness_mm": 2.0 * self.r_max,
            "max_thickness_pos_pct": 100.0 * float((centre - le) @ chord) / nose_tail ** 2,
            "max_thickness_center": centre,
        }
