"""Re-measuring a measured section's perturbed points from the measured section's own state
(issue 15 item 6: the uncertainty of every characteristic by re-measuring perturbed points),
numpy/scipy only.

The stage's uncertainty draws move each measured point by a few micrometres and measure the
section again. From scratch (core.airfoil.characteristics) a re-measure costs as much as the
measurement itself, and twelve of them per section took the five sections' stage from 1.1 s to
5.2 s. Here a perturbation ``dp`` of the ordered points is carried to first order through every
step the kernel takes, with every discrete choice the measurement made kept:

- the smoothing spline: the measured fit's knots and the smoothing weight FITPACK settled on
  (identified from its coefficients: the jumps of the third derivative at the interior knots,
  weighted, added to the sum of squares) make a linear smoother; its factorisation is made
  once, a draw's spline coefficients are one product;
- each inscribed circle of the camber line moves with the curve's normal displacement at its
  two contacts (centre along the difference of the contact normals, radius by what is left),
  the maximum thickness by the sum of the two (its circle is the largest: the envelope
  theorem), its position by the shift of the radius's maximum along the line;
- the edge circles are the least-squares circles of their zone's points, the zones kept (the
  first-order change of a geometric circle fit, its own Hessian);
- the camber line's ends are closed by the kernel's own estimator (core.airfoil._line_end) on
  the moved centres and circles -- whatever that estimator is, the draws use it;
- the edge points, the thicknesses at the edge offsets and the chord are crossings of lines
  with the curve, moved by the line's change and the curve's normal displacement there;
- area and centroid by Green's theorem on the displacement (exact quadrature);
- the section's 2D fit (twist, shift) by its Gauss-Newton step at the measured solution, and
  the contour's deviations moved with it (their maxima taken again per draw).

What it leaves out, by construction: a fresh fit's own choices per draw -- FITPACK's knots
(a re-fit of a 0.1 mm section's points takes 31 to 166 knots where the measurement took 34 to
89), the points entering or leaving an edge zone, the camber line's resampled centres. Where
those move a characteristic more than the points' noise does through the kept choices (edge
radii and max-thickness position on sparse edges), the u stated is smaller than the draws'
from scratch (docs/airfoil.md "Warm re-measure").

Tests (tests/test_airfoil_fast_u.py) compare a draw's figures with the kernel measuring the
same perturbed profile (this smoother's) from scratch. ``SectionPropagation.of`` returns None where it cannot
stand in for the kernel (a tangent chord, a profile whose spline it cannot identify, a state
that does not reproduce the measurement): the caller then re-measures from scratch.
"""

import numpy as np
from scipy.interpolate import BSpline
from scipy.optimize import minimize_scalar

from . import airfoil as kernel
from .errors import InputError

_DEGREE = 3
# The identified smoothing weight reproduces the measured spline's coefficients to this (mm):
# FITPACK's own arithmetic, far below any characteristic's resolution.
_SPLINE_MATCH_MM = 1e-8
# The state at zero perturbation reproduces the measured characteristics to this (mm, deg).
_REPLAY_MM = 1e-8
_REPLAY_DEG = 1e-6
# Arc length either side of the largest inscribed circle over which the radius's curvature
# along the camber line is taken (the kernel's own zoom settles within a few hundredths of
# a millimetre; the smooth fit's radius is a parabola over this).
_MAX_STEP_MM = 0.05
_ZONE_SEARCH_ROUNDS = 4
# The largest circle has jumped to another local maximum when the moved circles' largest lies
# more than this many circles from the measured one.
_MAX_JUMP_CIRCLES = 3


def warm_remeasure(ch, points, nominal_chars, fit):
    """A function of point moves (n, N, 2), in the order of ``points`` (a section's
    unordered measured points), giving each draw's characteristics; None where the state
    cannot stand in for the kernel."""
    nom = nominal_chars.profile
    order = np.argsort(np.mod(nom.closest(points)[0], nom.length))
    state = SectionPropagation.of(ch, np.asarray(points)[order], nominal_chars, fit)
    if state is None:
        return None
    return lambda moves: state.remeasure(np.asarray(moves)[:, order])


class SmoothFit:
    """A Profile's periodic smoothing spline as a linear smoother of its input points."""

    def __init__(self, profile, weight, system):
        self.profile = profile
        self.weight = weight
        self._system = system          # (n_free, n_points): free coefficients per point

    @classmethod
    def of(cls, profile):
        t, c = kernel.spline_of(profile)[:2]
        c = np.asarray(c)
        n_free = len(t) - 2 * _DEGREE - 1
        if n_free < 2 * _DEGREE or c.shape[1] < n_free + _DEGREE:
            return None
        basis = _free_basis(t, n_free, profile.point_params)
        # third-derivative jumps at the interior knots, as FITPACK's closed-curve smoothing
        # penalises them (fpclos/fpdisc: the periodic knot itself is not one)
        knots = t[_DEGREE:len(t) - _DEGREE]
        mids = 0.5 * (knots[:-1] + knots[1:])
        third = _free_basis(t, n_free, mids, der=3)
        jumps = (third - np.roll(third, 1, axis=0))[1:]
        btb, dtd = basis.T @ basis, jumps.T @ jumps
        rhs = basis.T @ profile.points
        target = c[:, :n_free].T

        def mismatch(log_w):
            w = 0.0 if log_w is None else np.exp(log_w)
            return float(np.abs(np.linalg.solve(btb + w * dtd, rhs) - target).max())

        if mismatch(None) <= _SPLINE_MATCH_MM:
            weight = 0.0
        else:
            best = minimize_scalar(mismatch, bounds=(-60.0, 30.0), method="bounded",
                                   options={"xatol": 1e-9})
            if best.fun > _SPLINE_MATCH_MM:
                return None
            weight = float(np.exp(best.x))
        system = np.linalg.solve(btb + weight * dtd, basis.T)
        return cls(profile, weight, system)

    def coefficients(self, dp):
        """Free coefficients' change (n, n_free, 2) for point moves dp (n, n_points, 2) in the
        profile's own point order (the measured fit's knots and smoothing weight kept)."""
        return np.einsum("fp,npk->nfk", self._system, dp)

    def profile_of(self, points, dcoef):
        """The kernel's Profile of moved points (profile order) whose spline is the measured
        one moved by dcoef (n_free, 2): what this smoother makes of them."""
        t, c = kernel.spline_of(self.profile)[:2]
        c = np.array(c, dtype=float)
        n_free = len(t) - 2 * _DEGREE - 1
        wrapped = np.vstack([dcoef, dcoef[:_DEGREE]]).T
        c[:, :n_free + _DEGREE] += wrapped
        return kernel.Profile(points, tck=(t, [c[0], c[1]], _DEGREE))

    def rows(self, u, der=0):
        """Basis rows (len(u), n_free): the curve's change at u is rows @ coefficients."""
        t = kernel.spline_of(self.profile)[0]
        return _free_basis(t, len(t) - 2 * _DEGREE - 1,
                           np.mod(np.asarray(u, dtype=float), self.profile.length), der)


def _free_basis(t, n_free, x, der=0):
    """B-spline basis of the periodic spline's free coefficients at x (the last _DEGREE
    coefficients repeat the first)."""
    n_coef = len(t) - _DEGREE - 1
    x = np.asarray(x, dtype=float)
    if der == 0:
        full = BSpline.design_matrix(x, t, _DEGREE).toarray()
    else:
        full = BSpline(t, np.eye(n_coef), _DEGREE, extrapolate="periodic")(x, der)
    free = full[:, :n_free].copy()
    free[:, :_DEGREE] += full[:, n_free:n_free + _DEGREE]
    return free


def _circle_response(points, centre, radius):
    """(3, n, 2): the first-order change of a geometric least-squares circle's (centre,
    radius) per move of each of its points (the optimum's own Hessian)."""
    v = points - centre
    rho = np.sqrt(np.einsum("ij,ij->i", v, v))
    w = v / rho[:, None]
    q = (rho - radius) / rho
    outer = w[:, :, None] * w[:, None, :]
    per_point = outer + q[:, None, None] * (np.eye(2)[None] - outer)     # (n, 2, 2)
    hess = np.zeros((3, 3))
    hess[:2, :2] = per_point.sum(axis=0)
    hess[:2, 2] = hess[2, :2] = w.sum(axis=0)
    hess[2, 2] = len(points)
    cross = np.concatenate([per_point.transpose(1, 0, 2), w[None]], axis=0)   # (3, n, 2)
    return np.einsum("ab,bnk->ank", np.linalg.inv(hess), cross)


class _Zone:
    """An edge circle's zone: its input points (indices, a set kept) or the curve resampled
    between the bounds its own circle sees (bounds that move with the curve, the circle's
    centre and the outward direction: the fixed point the kernel iterates to)."""

    def __init__(self, smooth, circle, outward, edge_u):
        prof = smooth.profile
        # The zone whose own fit is the circle: the one seen from its centre, or -- when the
        # kernel cycled between two point sets and kept the larger -- the one seen from the
        # other set's fit (a round or two of the kernel's own iteration).
        seen_from = circle.center
        for _ in range(_ZONE_SEARCH_ROUNDS):
            lo, hi = kernel.zone_range(prof, seen_from, outward, edge_u, circle.zone_deg)
            xy, key = kernel.zone_points(prof, lo, hi)
            centre, radius, _ = kernel.fit_circle_2d(xy)
            # a resampled zone moves with its circle's centre and is settled to the kernel's
            # own tolerance, not to the bit
            tol = _REPLAY_MM if key is not None else 10.0 * kernel.ZONE_SETTLED_MM
            self.reproduced = (np.linalg.norm(centre - circle.center) < tol
                               and abs(radius - circle.radius) < tol)
            if self.reproduced:
                break
            seen_from = centre
        self.circle = circle
        self.response = _circle_response(xy, circle.center, circle.radius)
        if key is not None:
            self.index = np.frombuffer(key, dtype=np.intp)
            return
        self.index = None
        u = np.linspace(lo, hi, kernel.ZONE_SAMPLES)
        self.rows = smooth.rows(u)
        frac = np.linspace(0.0, 1.0, kernel.ZONE_SAMPLES)
        tangent = prof.eval(u, 1)
        # each bound: g(u) = unit(S(u) - c) . outward - cos(zone) = 0
        self.bound_rows, self.bound_q, self.bound_e, pulls = [], [], [], []
        for bound, weight in ((lo, 1.0 - frac), (hi, frac)):
            v = prof.eval([bound])[0] - circle.center
            rho = np.linalg.norm(v)
            e = v / rho
            q = (outward - (e @ outward) * e) / rho
            den = float(q @ prof.eval([bound], 1)[0])
            pull = np.einsum("ank,nk->a", self.response, tangent * weight[:, None]) / den
            self.bound_rows.append(smooth.rows([bound])[0])
            self.bound_q.append(q)
            self.bound_e.append(e)
            pulls.append(pull)
        self.pulls = pulls
        coupling = np.zeros((3, 3))
        for pull, q in zip(pulls, self.bound_q):
            coupling[:, :2] += np.outer(pull, q)
        self.settle = np.linalg.inv(np.eye(3) - coupling)

    def moved(self, dp, dcoef, d_outward):
        """The circle for one draw (point moves dp in profile order, coefficients dcoef, the
        outward direction's change)."""
        if self.index is not None:
            change = np.einsum("ank,nk->a", self.response, dp[self.index])
        else:
            b = np.einsum("ank,nk->a", self.response, self.rows @ dcoef)
            for pull, rows, q, e in zip(self.pulls, self.bound_rows, self.bound_q,
                                        self.bound_e):
                b = b - pull * (q @ (rows @ dcoef) + e @ d_outward)
            change = self.settle @ b
        c = self.circle
        return kernel.CircleFit2D(c.center + change[:2], c.radius + change[2], c.rms,
                                  c.n_points, c.zone_deg)


class _Crossing:
    """Where a line m + tau nu crosses the curve (parameter, point, outward normal, tau)."""

    def __init__(self, smooth, origin, direction, u0):
        prof = smooth.profile
        self.direction = direction
        u, xy = kernel.line_hit(prof, origin, direction, u0)
        self.u, self.point = u, xy
        self.normal = prof.outward_normal(u)
        self.tau = np.einsum("ij,ij->i", xy - origin, direction)
        self.rows = smooth.rows(u)

    def tau_moved(self, dcoef, d_origin, d_direction):
        """tau of the moved line on the moved curve, to first order."""
        ds = self.rows @ dcoef
        n = self.normal
        num = (np.einsum("ij,ij->i", n, ds) - np.einsum("ij,ij->i", n, d_origin)
               - self.tau * np.einsum("ij,ij->i", n, d_direction))
        return self.tau + num / np.einsum("ij,ij->i", n, self.direction)


class SectionPropagation:
    """A measured section's state, re-measured under point moves (module notes)."""

    @classmethod
    def of(cls, ch, ordered, nominal_chars, fit):
        """The state of measured characteristics ``ch`` of the ordered points ``ordered`` with
        their section fit ``fit`` against ``nominal_chars``; None where it cannot stand in for
        the kernel (module notes)."""
        if ch.medial is None or ch.chord_method == "tangent":
            return None
        prof = ch.profile
        pts = np.asarray(ordered, dtype=float)
        if len(prof.points) != len(pts):
            return None
        if np.array_equal(prof.points, pts):
            to_profile = np.arange(len(pts))
        elif np.array_equal(prof.points, pts[::-1]):
            to_profile = np.arange(len(pts))[::-1]
        else:
            return None
        smooth = SmoothFit.of(prof)
        if smooth is None:
            return None
        self = cls()
        self.ch, self.smooth, self.to_profile = ch, smooth, to_profile
        try:
            self._setup(pts, nominal_chars, fit)
        except (InputError, np.linalg.LinAlgError):
            return None
        if not self._replays(fit):
            return None
        return self

    # ------------------------------------------------------------ set-up

    def _setup(self, pts, nominal_chars, fit):
        ch, smooth, prof, m = self.ch, self.smooth, self.ch.profile, self.ch.medial
        # inscribed circles: contacts and their normals
        ua, ub, fa, fb = kernel.feet(prof, m.side_a, m.side_b, m.centres)
        self.contacts = _Contacts(smooth, m.centres, ua, ub, fa, fb)
        # first edge circles (about the unclosed ends) and their zones
        zones, self.first_outs = [], []
        for end, circle in ((0, m.circle_a), (-1, m.circle_b)):
            out = kernel.line_end(m.centres, m.radii, end, window_pct=m.window_pct)[2]
            u_hit = kernel.ray_hit(prof, m.centres[end], out)[0][0]
            zones.append(_Zone(smooth, circle, out, u_hit))
            self.first_outs.append(out)
        self.first_zones = zones
        # the closed ends at zero perturbation: tips, tangents, edge points
        closed = self._close(m.centres, m.radii, m.circle_a, m.circle_b)
        (c_closed, r_closed, out_a, out_b) = closed
        self.tips0 = (c_closed[0], c_closed[-1])
        self.outs0 = (out_a, out_b)
        self.hits = []
        for tip, out in zip(self.tips0, self.outs0):
            u_hit = kernel.ray_hit(prof, tip, out)[0]
            self.hits.append(_Crossing(smooth, tip[None], out[None], u_hit))
        ends = [h.point[0] for h in self.hits]
        self.a_is_le = bool(np.linalg.norm(ends[0] - ch.le_point)
                            <= np.linalg.norm(ends[1] - ch.le_point))
        # the final edge circles' zones (seen from the closed ends)
        finals = (ch.le_circle, ch.te_circle) if self.a_is_le else (ch.te_circle, ch.le_circle)
        self.final_zones = [_Zone(smooth, circle, out, hit.u[0])
                            for circle, out, hit in zip(finals, self.outs0, self.hits)]
        # the camber line and the thickness crossings at the edge offsets
        mcl0 = self._camber(c_closed, ends[0], ends[1], out_a, out_b)
        self.mcl0 = mcl0
        offsets = np.asarray(ch.edge_offsets_mm, dtype=float)
        self.stations = np.concatenate([offsets, mcl0.length - offsets])
        mid, tangent = mcl0.at(self.stations)
        nu = np.column_stack([-tangent[:, 1], tangent[:, 0]])
        thickness = np.concatenate([ch.le_thickness_mm, ch.te_thickness_mm])
        if not np.all(np.isfinite(thickness)):
            raise InputError("a thickness at an edge offset was not measured")
        sides = []
        for sign in (1.0, -1.0):
            guess = prof.closest(mid + sign * 0.5 * thickness[:, None] * nu)[0]
            sides.append(_Crossing(smooth, mid, nu, guess))
        self.thickness_sides = sides
        self.mid0, self.nu0 = mid, nu
        # the largest inscribed circle and its neighbours along the line
        c_max = ch.max_thickness_center
        ua, ub, fa, fb = kernel.feet(prof, m.side_a, m.side_b, c_max[None])
        at_max = _Contacts(smooth, c_max[None], ua, ub, fa, fb)
        along = np.array([-at_max.normal_dir[0, 1], at_max.normal_dir[0, 0]])
        along = along if along @ ch.chord_dir >= 0 else -along
        seeds = c_max + np.outer([-_MAX_STEP_MM, _MAX_STEP_MM], along)
        cs, ua, ub, fa, fb = kernel.refine_centres(prof, m.side_a, m.side_b, seeds)
        self.max_contacts = at_max
        self.max_side = _Contacts(smooth, cs, ua, ub, fa, fb)
        s_side = (cs - c_max) @ along
        r_side = np.linalg.norm(fa - cs, axis=1)
        r0 = 0.5 * ch.max_thickness_mm
        # r(s) through the three circles: its slope's change per unit slope of the radius
        h1, h2 = s_side
        self.max_curvature = 2.0 * ((r_side[1] - r0) / h2 - (r_side[0] - r0) / h1) / (h2 - h1)
        self.max_along, self.max_steps = along, s_side
        self.max_index = int(np.argmin(np.linalg.norm(m.centres - c_max, axis=1)))
        # chords along the axis and, for the caliper, the farthest pair
        axis = ch.engine_axis
        ends_axis = [kernel.support(prof, axis, sign) for sign in (1, -1)]
        self.axial_rows = smooth.rows(prof.closest(np.array(ends_axis))[0])
        if ch.chord_method == "caliper":
            u1, u2, p1, p2 = kernel.farthest_pair(prof)
            self.caliper_rows = smooth.rows([u2, u1])
            self.caliper_dir = (p2 - p1) / np.linalg.norm(p2 - p1)
        # area and centroid: Green's theorem on the displacement
        uq, wq = prof.knot_quadrature(5)
        self.quad_w, self.quad_rows = wq, smooth.rows(uq)
        self.quad_p, self.quad_d = prof.eval(uq), prof.eval(uq, 1)
        # the section fit and the contour (points in ordered order)
        nom = nominal_chars.profile
        self.before, ub_nom = kernel.signed_deviation(pts, nom)
        self.before_normal = nom.outward_normal(ub_nom)
        theta = -np.radians(fit.twist_deg)
        self.turn = kernel.rotation_2d(theta)
        t = -self.turn @ fit.shift_mm
        moved = (pts - fit.pivot) @ self.turn.T + fit.pivot + t
        self.after, u_after = kernel.signed_deviation(moved, nom)
        n = nom.outward_normal(u_after)
        arm = moved - fit.pivot - t
        jac = np.column_stack([n, n[:, 1] * arm[:, 0] - n[:, 0] * arm[:, 1]])
        self.fit_jac = jac
        self.fit_step = np.linalg.solve(jac.T @ jac, jac.T)
        self.after_normal = n
        self.theta, self.t = theta, t

    def _close(self, centres, radii, circle_a, circle_b):
        """The camber line's ends closed as the kernel closes them (end a, then end b)."""
        w = self.ch.medial.window_pct
        c, r, out_a, _ = kernel.line_end(centres, radii, 0, circle_a, w)
        c, r, out_b, _ = kernel.line_end(c, r, -1, circle_b, w)
        return c, r, out_a, out_b

    def _camber(self, centres, end_a, end_b, out_a, out_b):
        if self.a_is_le:
            return kernel.CamberLine(end_a, centres, end_b, -out_a, out_b)
        return kernel.CamberLine(end_b, centres[::-1], end_a, -out_b, out_a)

    def _replays(self, fit):
        """The state at zero perturbation gives the measured characteristics."""
        ch = self.ch
        zero = np.zeros((1, len(ch.profile.points), 2))
        got = self.remeasure(zero)[0]
        want = {"chord_mm": ch.chord_mm, "axial_chord_mm": ch.axial_chord_mm,
                "max_thickness_mm": ch.max_thickness_mm, "le_radius_mm": ch.le_radius_mm,
                "te_radius_mm": ch.te_radius_mm, "area_mm2": ch.area_mm2}
        ok = all(abs(got[k] - v) < _REPLAY_MM for k, v in want.items())
        ok &= all(abs(got[k] - v) < _REPLAY_DEG for k, v in
                  (("stagger_deg", ch.stagger_deg), ("inlet_angle_deg", ch.inlet_angle_deg),
                   ("outlet_angle_deg", ch.outlet_angle_deg), ("twist_deg", fit.twist_deg)))
        ok &= bool(np.all(np.abs(np.subtract(got["le_thickness_mm"], ch.le_thickness_mm))
                          < _REPLAY_MM))
        ok &= bool(np.all(np.abs(np.subtract(got["te_thickness_mm"], ch.te_thickness_mm))
                          < _REPLAY_MM))
        ok &= bool(np.linalg.norm(got["centroid_mm"] - ch.centroid_mm) < _REPLAY_MM)
        ok &= abs(got["max_thickness_pos_pct"] - ch.max_thickness_pos_pct) < 1e-6
        # the reported radii's zones must be the kernel's; a first circle only places the
        # line's end, and may be the larger of two zones the kernel cycled between
        ok &= all(z.reproduced for z in self.final_zones)
        return bool(ok)

    # ------------------------------------------------------------ one draw

    def remeasure(self, dp_ordered):
        """The characteristics of the ordered points moved by dp_ordered (n, N, 2), one dict
        per draw: the kernel's fields (centroid in the plane) and the section fit's."""
        smooth = self.smooth
        dp_ordered = np.asarray(dp_ordered, dtype=float)
        dp = dp_ordered[:, self.to_profile]
        dcoef = smooth.coefficients(dp)
        fit_part = self._fit_and_contour(dp_ordered)
        area_part = self._area_centroid(dcoef)
        out = []
        for k in range(len(dp)):
            v = self._one(dp[k], dcoef[k])
            v.update({name: values[k] for name, values in fit_part.items()})
            v["shift_mm"] = v["shift_mm"].tolist()
            v.update({name: values[k] for name, values in area_part.items()})
            out.append(v)
        return out

    def _one(self, dp, dcoef):
        ch, m = self.ch, self.ch.medial
        dc, dr = self.contacts.moves(dcoef)
        centres, radii = m.centres + dc, m.radii + dr
        first = []
        for end, zone, out0 in zip((0, -1), self.first_zones, self.first_outs):
            out = kernel.line_end(centres, radii, end, window_pct=m.window_pct)[2]
            first.append(zone.moved(dp, dcoef, out - out0))
        c, r, out_a, out_b = self._close(centres, radii, *first)
        ends = []
        for hit, tip0, out0, tip, out in zip(self.hits, self.tips0, self.outs0,
                                             (c[0], c[-1]), (out_a, out_b)):
            tau = hit.tau_moved(dcoef, (tip - tip0)[None], (out - out0)[None])[0]
            ends.append(tip + tau * out)
        fa, fb = (z.moved(dp, dcoef, out - out0) for z, out, out0 in
                  zip(self.final_zones, (out_a, out_b), self.outs0))
        if self.a_is_le:
            le, te, le_circle, te_circle = ends[0], ends[1], fa, fb
        else:
            le, te, le_circle, te_circle = ends[1], ends[0], fb, fa
        mcl = self._camber(c, ends[0], ends[1], out_a, out_b)
        nose_tail = float(np.linalg.norm(te - le))
        chord_dir = (te - le) / nose_tail
        axis = ch.engine_axis
        # thickness at the edge offsets: the moved line's crossings with the moved curve
        stations = np.concatenate([self.stations[:len(self.stations) // 2],
                                   mcl.length - self.stations[:len(self.stations) // 2]])
        mid, tangent = mcl.at(stations)
        nu = np.column_stack([-tangent[:, 1], tangent[:, 0]])
        tau_plus, tau_minus = (s.tau_moved(dcoef, mid - self.mid0, nu - self.nu0)
                               for s in self.thickness_sides)
        thickness = tau_plus - tau_minus
        half = len(stations) // 2
        # the largest inscribed circle: radius by the envelope, position by its maximum's shift
        dn_max = self.max_contacts.normal_moves(dcoef)
        max_thickness = ch.max_thickness_mm + float(dn_max[0, 0] + dn_max[0, 1])
        dn_side = self.max_side.normal_moves(dcoef)
        dr_side = 0.5 * (dn_side[:, 0] + dn_side[:, 1])
        dr_max = 0.5 * float(dn_max[0, 0] + dn_max[0, 1])
        h1, h2 = self.max_steps
        # the slope at the largest circle of the parabola through the three radii's changes
        slope = ((dr_side[0] - dr_max) * h2 ** 2 - (dr_side[1] - dr_max) * h1 ** 2) \
            / (h1 * h2 * (h2 - h1))
        ds = -slope / self.max_curvature if self.max_curvature < 0 else 0.0
        # the radius's maximum is flat: its shift by ds raises it by slope ds / 2 (second
        # order, but of the size of the first where the thickness hardly varies)
        max_thickness += slope * ds
        dc_max = self.max_contacts.moves(dcoef)[0][0]
        c_max = ch.max_thickness_center + dc_max + ds * self.max_along
        # On a flat maximum another local maximum of the radius along the line may become the
        # larger one (the kernel's search then jumps there): taken from the moved circles.
        k = int(np.clip(np.argmax(radii), 1, len(radii) - 2))
        if abs(k - self.max_index) > _MAX_JUMP_CIRCLES:
            r_jump, c_jump = _vertex(centres[k - 1:k + 2], radii[k - 1:k + 2])
            if 2.0 * r_jump > max_thickness:
                max_thickness, c_max = 2.0 * r_jump, c_jump
        if ch.chord_method == "caliper":
            d = self.caliper_rows @ dcoef
            chord = ch.caliper_chord_mm + float((d[0] - d[1]) @ self.caliper_dir)
        else:
            chord = nose_tail
        d_axis = self.axial_rows @ dcoef
        return {"chord_mm": chord,
                "axial_chord_mm": ch.axial_chord_mm + float((d_axis[0] - d_axis[1]) @ axis),
                "stagger_deg": kernel.angle_deg(chord_dir, axis),
                "max_thickness_mm": max_thickness,
                "max_thickness_pos_pct": 100.0 * float((c_max - le) @ chord_dir) / nose_tail,
                "le_radius_mm": le_circle.radius, "te_radius_mm": te_circle.radius,
                "le_thickness_mm": thickness[:half].tolist(),
                "te_thickness_mm": thickness[half:].tolist(),
                "inlet_angle_deg": kernel.angle_deg(mcl.le_tangent, axis),
                "outlet_angle_deg": kernel.angle_deg(mcl.te_tangent, axis)}

    def _area_centroid(self, dcoef):
        """Area and centroid of each draw's curve (Green's theorem, first order)."""
        ch = self.ch
        ds = np.einsum("qf,nfk->nqk", self.quad_rows, dcoef)
        w, p, d = self.quad_w, self.quad_p, self.quad_d
        x, y, dx, dy = p[:, 0], p[:, 1], d[:, 0], d[:, 1]
        sx, sy = ds[..., 0], ds[..., 1]
        area0 = ch.area_mm2
        d_area = (w * (sx * dy - sy * dx)).sum(axis=1)
        nx = np.sum(w * x * x * dy)
        ny = np.sum(w * y * y * dx)
        d_nx = (w * (2 * x * dy * sx - 2 * x * dx * sy)).sum(axis=1)
        d_ny = (w * (2 * y * dx * sy - 2 * y * dy * sx)).sum(axis=1)
        area = area0 + d_area
        centroid = np.column_stack([(nx + d_nx) / (2 * area), -(ny + d_ny) / (2 * area)])
        return {"area_mm2": area, "centroid_mm": centroid}

    def _fit_and_contour(self, dp):
        """Twist, shift and the contour's form values of each draw: the section fit's
        Gauss-Newton step from the measured solution, deviations moved with it."""
        turned = np.einsum("ij,npj->npi", self.turn, dp)
        d_dev = np.einsum("pi,npi->np", self.after_normal, turned)
        step = -np.einsum("ap,np->na", self.fit_step, d_dev)
        after = self.after + d_dev + step @ self.fit_jac.T
        before = self.before + np.einsum("pi,npi->np", self.before_normal, dp)
        theta = self.theta + step[:, 2]
        t = self.t + step[:, :2]
        twist = -theta
        c, s = np.cos(twist), np.sin(twist)
        shift = -np.column_stack([c * t[:, 0] - s * t[:, 1], s * t[:, 0] + c * t[:, 1]])
        return {"twist_deg": np.degrees(twist), "shift_mm": shift,
                "form_mm": after.max(axis=1) - after.min(axis=1),
                "form_location_mm": 2.0 * np.abs(before).max(axis=1)}


def _vertex(centres, radii):
    """(radius, centre) at the top of the parabola of radius in arc length through three
    circles along the line."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(centres, axis=0), axis=1))])
    a2, a1, a0 = np.polyfit(s, radii, 2)
    top = float(np.clip(-a1 / (2.0 * a2), s[0], s[-1])) if a2 < 0 else s[1]
    along = np.array([np.polyval(np.polyfit(s, centres[:, j], 2), top) for j in range(2)])
    return float(np.polyval([a2, a1, a0], top)), along


class _Contacts:
    """Inscribed circles' two contacts: the circles move with the curve's normal displacement
    there (centre along the difference of the contact normals, radius by what is left)."""

    def __init__(self, smooth, centres, ua, ub, fa, fb):
        self.na = (fa - centres) / np.linalg.norm(fa - centres, axis=1)[:, None]
        self.nb = (fb - centres) / np.linalg.norm(fb - centres, axis=1)[:, None]
        diff = self.na - self.nb
        self.gap = np.linalg.norm(diff, axis=1)
        self.normal_dir = diff / self.gap[:, None]
        self.rows_a, self.rows_b = smooth.rows(ua), smooth.rows(ub)

    def normal_moves(self, dcoef):
        """(k, 2): the curve's outward displacement at each circle's two contacts."""
        da, db = self.rows_a @ dcoef, self.rows_b @ dcoef
        return np.column_stack([np.einsum("ij,ij->i", self.na, da),
                                np.einsum("ij,ij->i", self.nb, db)])

    def moves(self, dcoef):
        """(centre moves (k, 2), radius moves (k,))."""
        dn = self.normal_moves(dcoef)
        along = (dn[:, 0] - dn[:, 1]) / self.gap
        dc = self.normal_dir * along[:, None]
        return dc, dn[:, 0] - np.einsum("ij,ij->i", self.na, dc)
