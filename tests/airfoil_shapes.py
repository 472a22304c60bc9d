"""Section profiles with closed-form characteristics, for tests/test_airfoil.py and
bench/bench_airfoil.py (no code of BladeInspect is used to build or measure them).

- ArcSection: a cambered "double circular arc" section, suction side on a circle (Os, Rs),
  pressure side on a circle (Op, Rp) that the section lies outside, the edges exact circles
  tangent to both. Its inscribed-circle centres are equidistant from the two circles,
  Rs - |P - Os| = |P - Op| - Rp, i.e. |P - Os| + |P - Op| = Rs + Rp: an ellipse with foci Os
  and Op, so the mean camber line, the edge points, the metal angles and the maximum thickness
  are all closed forms.
- NacaSection: NACA 4-digit thickness (and camber) from its formula up to x0, the trailing
  edge closed by the circle tangent there with its centre on the camber line's chord (for the
  symmetric section: on the chord line, which is then its exact mean camber line).
"""
import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq


def rigid(points, angle_deg, shift):
    a = np.radians(angle_deg)
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    return np.asarray(points) @ R.T + np.asarray(shift, float)


def _rotate(v, angle_deg):
    return rigid(np.atleast_2d(v), angle_deg, (0.0, 0.0))[0]


def _arc_points(centre, radius, a0, a1, spacing):
    n = max(8, int(np.ceil(abs(a1 - a0) * radius / spacing)))
    a = np.linspace(a0, a1, n, endpoint=False)
    return centre + radius * np.column_stack([np.cos(a), np.sin(a)])


def _gauss(f, a, b, n=200):
    x, w = np.polynomial.legendre.leggauss(n)
    t = (a + b) / 2 + (b - a) / 2 * x
    return float(np.sum((b - a) / 2 * w * f(t)))


class ArcSection:
    """All figures in its own frame, then moved by ``angle_deg`` and ``shift``."""

    def __init__(self, Rs=100.0, ys=8.0, Rp=110.0, yp=4.0, x_le=-24.0, x_te=25.0,
                 offset=0.0, angle_deg=0.0, shift=(0.0, 0.0)):
        self.angle_deg, self.shift = angle_deg, np.asarray(shift, float)
        self.Os, self.Op = np.array([0.0, ys - Rs]), np.array([0.0, yp - Rp])
        # An outward offset keeps every arc concentric: the camber ellipse does not move.
        self.Rs0, self.Rp0 = Rs, Rp
        self.Rs, self.Rp = Rs + offset, Rp - offset
        self.a = (Rs + Rp) / 2.0
        self.c = abs(self.Os[1] - self.Op[1]) / 2.0
        self.centre_y = (self.Os[1] + self.Op[1]) / 2.0
        self.b = np.sqrt(self.a ** 2 - self.c ** 2)
        self.C_le, self.C_te = self.ellipse(x_le), self.ellipse(x_te)
        self.r_le = Rs - np.linalg.norm(self.C_le - self.Os) + offset
        self.r_te = Rs - np.linalg.norm(self.C_te - self.Os) + offset

    # camber ellipse (upper branch), x in its own frame
    def ellipse(self, x):
        return np.array([x, self.centre_y + self.a * np.sqrt(1 - x ** 2 / self.b ** 2)])

    def ellipse_tangent(self, x):
        dy = -self.a * x / (self.b ** 2 * np.sqrt(1 - x ** 2 / self.b ** 2))
        t = np.array([1.0, dy])
        return t / np.linalg.norm(t)

    def ellipse_distance(self, P):
        """Distance of points (own frame) from the camber ellipse, to first order (exact to
        far below a nanometre at the micrometre level)."""
        P = np.atleast_2d(P)
        d1, d2 = P - self.Os, P - self.Op
        n1, n2 = np.linalg.norm(d1, axis=1), np.linalg.norm(d2, axis=1)
        g = d1 / n1[:, None] + d2 / n2[:, None]
        return (n1 + n2 - 2 * self.a) / np.linalg.norm(g, axis=1)

    def _pieces(self):
        """(centre, radius, start angle, end angle) counter-clockwise around the section."""
        def ang(v):
            return np.arctan2(v[1], v[0])
        us_le = (self.C_le - self.Os) / np.linalg.norm(self.C_le - self.Os)
        us_te = (self.C_te - self.Os) / np.linalg.norm(self.C_te - self.Os)
        up_le = (self.C_le - self.Op) / np.linalg.norm(self.C_le - self.Op)
        up_te = (self.C_te - self.Op) / np.linalg.norm(self.C_te - self.Op)
        suction = (self.Os, self.Rs, ang(us_te), ang(us_le))
        a0, a1 = ang(us_le), ang(-up_le)
        le = (self.C_le, self.r_le, a0, a1 + 2 * np.pi * (a1 < a0))
        pressure = (self.Op, self.Rp, ang(up_le), ang(up_te))          # clockwise about Op
        a0, a1 = ang(-up_te), ang(us_te)
        te = (self.C_te, self.r_te, a0, a1 + 2 * np.pi * (a1 < a0))
        return [suction, le, pressure, te]

    def points(self, spacing=0.02):
        pts = np.vstack([_arc_points(c, r, a0, a1, spacing) for c, r, a0, a1 in self._pieces()])
        return rigid(pts, self.angle_deg, self.shift)

    def to_world(self, p):
        return rigid(np.atleast_2d(p), self.angle_deg, self.shift)

    # ---- closed forms (world frame unless noted)
    def le_point(self):
        return self.to_world(self.C_le - self.r_le * self.ellipse_tangent(self.C_le[0]))[0]

    def te_point(self):
        return self.to_world(self.C_te + self.r_te * self.ellipse_tangent(self.C_te[0]))[0]

    def chord(self):
        return float(np.linalg.norm(self.te_point() - self.le_point()))

    def chord_dir(self):
        return (self.te_point() - self.le_point()) / self.chord()

    def inlet_dir(self):
        return _rotate(self.ellipse_tangent(self.C_le[0]), self.angle_deg)

    def outlet_dir(self):
        return _rotate(self.ellipse_tangent(self.C_te[0]), self.angle_deg)

    def max_thickness(self):
        # Nearest point of the ellipse to the focus Os: the vertex on its side, x = 0.
        return 2.0 * (self.Rs - (self.a - self.c))

    def max_thickness_pos_pct(self):
        vertex = self.to_world(self.ellipse(0.0))[0]
        return 100.0 * float((vertex - self.le_point()) @ self.chord_dir()) / self.chord()

    def support(self, direction):
        """max over the section of p . d (world direction)."""
        d = _rotate(direction, -self.angle_deg)
        best = -np.inf
        for c, r, a0, a1 in self._pieces():
            lo, hi = min(a0, a1), max(a0, a1)
            th = np.arctan2(d[1], d[0])
            th = lo + np.mod(th - lo, 2 * np.pi)
            cands = [c @ d + r * np.cos(a - np.arctan2(d[1], d[0])) for a in (a0, a1)]
            if th <= hi:
                cands.append(c @ d + r)
            best = max(best, max(cands))
        return best + float(self.shift @ np.asarray(direction))

    def extent(self, direction):
        d = np.asarray(direction, float) / np.linalg.norm(direction)
        return self.support(d) + self.support(-d)

    def caliper(self):
        return float(np.linalg.norm(self.C_te - self.C_le) + self.r_le + self.r_te)

    def pressure_tangent_dir(self):
        """Direction of the line touching both edge circles on the pressure side."""
        D = self.C_te - self.C_le
        L = np.linalg.norm(D)
        up = np.array([-D[1], D[0]]) / L
        phi = np.arcsin((self.r_te - self.r_le) / L)
        nu = np.cos(phi) * up + np.sin(phi) * D / L
        return _rotate(np.array([nu[1], -nu[0]]), self.angle_deg)

    def area_centroid(self):
        A = Mx = My = 0.0
        for c, r, a0, a1 in self._pieces():
            def xy(t):
                return c[0] + r * np.cos(t), c[1] + r * np.sin(t)
            A += _gauss(lambda t: 0.5 * (xy(t)[0] * r * np.cos(t) + xy(t)[1] * r * np.sin(t)),
                        a0, a1)
            Mx += _gauss(lambda t: 0.5 * xy(t)[0] ** 2 * r * np.cos(t), a0, a1)
            My += _gauss(lambda t: 0.5 * xy(t)[1] ** 2 * r * np.sin(t), a0, a1)
        centroid = np.array([Mx / A, My / A])
        return A, self.to_world(centroid)[0]

    def _side_crossings(self, m, n):
        """Thickness along the line m + tau n (own frame) through the section."""
        hits = []
        for c, r, a0, a1 in self._pieces():
            w = m - c
            bq = w @ n
            disc = bq ** 2 - (w @ w - r ** 2)
            if disc < 0:
                continue
            for tau in (-bq - np.sqrt(disc), -bq + np.sqrt(disc)):
                p = m + tau * n - c
                th = np.arctan2(p[1], p[0])
                lo, hi = min(a0, a1), max(a0, a1)
                if lo + np.mod(th - lo, 2 * np.pi) <= hi + 1e-12:
                    hits.append(tau)
        hits = np.array(hits)
        return hits[hits > 0].min() - hits[hits < 0].max()

    def _ellipse_arc(self, x0, x1):
        def speed(x):
            t = np.array([1.0, -self.a * x / (self.b ** 2 * np.sqrt(1 - x ** 2 / self.b ** 2))])
            return np.linalg.norm(t)
        return quad(speed, x0, x1, epsabs=1e-13, epsrel=1e-13)[0]

    def camber_point(self, s):
        """Point and unit tangent of the mean camber line at arc length s from the LE point
        (own frame): straight through the LE circle, the ellipse, straight through the TE."""
        x_le, x_te = self.C_le[0], self.C_te[0]
        inner = self._ellipse_arc(x_le, x_te)
        if s <= self.r_le:
            t = self.ellipse_tangent(x_le)
            return self.C_le - (self.r_le - s) * t, t
        if s >= self.r_le + inner:
            t = self.ellipse_tangent(x_te)
            return self.C_te + (s - self.r_le - inner) * t, t
        x = brentq(lambda x: self._ellipse_arc(x_le, x) - (s - self.r_le), x_le, x_te,
                   xtol=1e-14)
        return self.ellipse(x), self.ellipse_tangent(x)

    def mcl_length(self):
        return self.r_le + self._ellipse_arc(self.C_le[0], self.C_te[0]) + self.r_te

    def thickness_at_arc(self, s):
        m, t = self.camber_point(s)
        return self._side_crossings(m, np.array([-t[1], t[0]]))

    def thickness_at_station(self, pct):
        le = self.C_le - self.r_le * self.ellipse_tangent(self.C_le[0])
        te = self.C_te + self.r_te * self.ellipse_tangent(self.C_te[0])
        d = (te - le) / np.linalg.norm(te - le)
        target = pct / 100.0 * np.linalg.norm(te - le)
        s = brentq(lambda s: (self.camber_point(s)[0] - le) @ d - target, 0.0,
                   self.mcl_length(), xtol=1e-13)
        return self.thickness_at_arc(s)


# ---------------------------------------------------------------- NACA 4-digit

def naca_thickness(x, t):
    return 5 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x ** 2 + 0.2843 * x ** 3
                    - 0.1015 * x ** 4)


def naca_thickness_slope(x, t):
    return 5 * t * (0.2969 / (2 * np.sqrt(x)) - 0.1260 - 0.7032 * x + 0.8529 * x ** 2
                    - 0.4060 * x ** 3)


def naca_camber(x, m, p):
    x = np.asarray(x, float)
    yc = np.where(x < p, m / p ** 2 * (2 * p * x - x ** 2),
                  m / (1 - p) ** 2 * (1 - 2 * p + 2 * p * x - x ** 2)) if m else 0 * x
    dy = np.where(x < p, 2 * m / p ** 2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x)) if m else 0 * x
    return yc, dy


class NacaSection:
    """NACA mpxx of chord ``c`` (mm) up to x0 (fraction), the tail a circle tangent to the
    thickness there (symmetric section: centred on the chord line)."""

    def __init__(self, digits="0012", c=50.0, x0=0.95, angle_deg=0.0, shift=(0.0, 0.0)):
        self.m = int(digits[0]) / 100.0
        self.p = int(digits[1]) / 10.0
        self.t = int(digits[2:]) / 100.0
        self.c, self.x0 = c, x0
        self.angle_deg, self.shift = angle_deg, np.asarray(shift, float)
        yt, dyt = naca_thickness(x0, self.t) * c, naca_thickness_slope(x0, self.t)
        self.r_te = yt * np.sqrt(1 + dyt ** 2)
        self.xc_te = x0 * c + yt * dyt

    def surface(self, xi, upper):
        """Points at x = xi**2 (fraction of c); thickness normal to the camber line."""
        x = xi ** 2
        yt = naca_thickness(x, self.t)
        yc, dyc = naca_camber(x, self.m, self.p)
        th = np.arctan(dyc)
        sgn = 1.0 if upper else -1.0
        return self.c * np.column_stack([x - sgn * yt * np.sin(th), yc + sgn * yt * np.cos(th)])

    def points(self, n_side=2500, spacing=0.02):
        if self.m:
            raise ValueError("the round tail is built for symmetric sections only")
        xi = np.linspace(0.0, np.sqrt(self.x0), n_side)
        upper = self.surface(xi, True)
        lower = self.surface(xi, False)
        a0 = np.arctan2(upper[-1, 1], upper[-1, 0] - self.xc_te)
        tail = _arc_points(np.array([self.xc_te, 0.0]), self.r_te, -a0, a0, spacing)
        # Lower side nose to tail, the tail arc, upper side tail to nose: counter-clockwise.
        pts = np.vstack([lower, tail[1:], upper[::-1][:-1]])
        return rigid(pts, self.angle_deg, self.shift)

    def to_world(self, p):
        return rigid(np.atleast_2d(p), self.angle_deg, self.shift)

    def chord(self):
        return self.xc_te + self.r_te

    def le_radius(self):
        return 1.1019 * self.t ** 2 * self.c

    def x_max_thickness(self):
        return brentq(lambda x: naca_thickness_slope(x, self.t), 0.05, 0.6, xtol=1e-15)

    def max_thickness(self):
        return 2 * naca_thickness(self.x_max_thickness(), self.t) * self.c

    def max_thickness_pos_pct(self):
        return 100.0 * self.x_max_thickness() * self.c / self.chord()

    def thickness_at_x(self, x_mm):
        """Thickness normal to the chord line (the camber line) at x mm from the nose."""
        if x_mm <= self.x0 * self.c:
            return 2 * naca_thickness(x_mm / self.c, self.t) * self.c
        return 2 * np.sqrt(self.r_te ** 2 - (x_mm - self.xc_te) ** 2)

    def area_centroid(self):
        # Nose to x0 by x = xi^2 (smooth integrands), plus the tail's circular segment.
        X0 = np.sqrt(self.x0)
        A = _gauss(lambda xi: 2 * naca_thickness(xi ** 2, self.t) * 2 * xi, 0, X0) * self.c ** 2
        Mx = _gauss(lambda xi: 2 * naca_thickness(xi ** 2, self.t) * xi ** 2 * 2 * xi,
                    0, X0) * self.c ** 3
        e = self.x0 * self.c - self.xc_te
        r = self.r_te
        seg = r ** 2 * np.arccos(e / r) - e * np.sqrt(r ** 2 - e ** 2)
        seg_x = self.xc_te + (2.0 / 3.0) * (r ** 2 - e ** 2) ** 1.5 / seg
        area = A + seg
        return area, self.to_world([(Mx + seg * seg_x) / area, 0.0])[0]
