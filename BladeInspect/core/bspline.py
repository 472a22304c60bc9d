"""A CAD face's surface as plain arrays: vectorised (rational) B-spline evaluation with first
and second derivatives, and Newton projection of points onto it.

The evaluation is the Cox-de Boor recurrence with derivatives (Piegl & Tiller, "The NURBS
Book", algorithm A2.3) run on N parameter values at once: every scalar of the textbook
algorithm becomes an (N,) array, the loops run over the degree only. Rational surfaces are
evaluated in homogeneous coordinates and divided out with the quotient rule. Newton's
projection, which evaluates one surface many times, runs on the power-basis form instead
(``PowerPatches``, built once per surface by ``SurfaceData.power_patches``).

Periodic surfaces are stored non-periodic (clamped knots over one period); ``closed_u`` /
``closed_v`` tell the projection to wrap around the seam instead of stopping at it.
"""

from dataclasses import dataclass
from typing import Optional

import numpy as np

from .errors import InputError

# Parameters are evaluated in chunks so the (chunk, p+1, q+1, 4) pole gathers stay small.
CHUNK = 32768
# Newton steps shorter than this (mm) are the last: applied to first order, not re-evaluated.
FINAL_STEP = 1e-5


@dataclass
class SurfaceData:
    degree_u: int
    degree_v: int
    knots_u: np.ndarray            # flat, with multiplicity: len = n_poles_u + degree_u + 1
    knots_v: np.ndarray
    poles: np.ndarray              # (nu, nv, 3)
    weights: Optional[np.ndarray]  # (nu, nv) or None when polynomial
    u_range: np.ndarray            # (2,) the parameter box used (a face's bounds)
    v_range: np.ndarray
    closed_u: bool = False         # periodic in u: S(u_range[0], v) == S(u_range[1], v)
    closed_v: bool = False

    def __post_init__(self):
        self.knots_u = np.asarray(self.knots_u, dtype=float)
        self.knots_v = np.asarray(self.knots_v, dtype=float)
        self.poles = np.asarray(self.poles, dtype=float)
        self.u_range = np.asarray(self.u_range, dtype=float)
        self.v_range = np.asarray(self.v_range, dtype=float)
        nu, nv = self.poles.shape[:2]
        if self.poles.ndim != 3 or self.poles.shape[2] != 3:
            raise InputError("B-spline surface: poles must be (nu, nv, 3), got %s"
                             % (self.poles.shape,))
        if len(self.knots_u) != nu + self.degree_u + 1 or len(self.knots_v) != nv + self.degree_v + 1:
            raise InputError("B-spline surface: %d x %d poles of degree %d x %d need %d x %d knots, "
                             "got %d x %d" % (nu, nv, self.degree_u, self.degree_v,
                                              nu + self.degree_u + 1, nv + self.degree_v + 1,
                                              len(self.knots_u), len(self.knots_v)))
        if self.weights is not None:
            self.weights = np.asarray(self.weights, dtype=float)
            if self.weights.shape != (nu, nv):
                raise InputError("B-spline surface: weights must be (%d, %d)" % (nu, nv))
            if np.all(self.weights == self.weights.flat[0]):
                self.weights = None
        self._homogeneous = None
        self._power = None

    @property
    def rational(self):
        return self.weights is not None

    def homogeneous(self):
        """(nu, nv, 4) poles times weight, then the weight (or 3 columns when polynomial)."""
        if self._homogeneous is None:
            if self.weights is None:
                self._homogeneous = self.poles
            else:
                w = self.weights[..., None]
                self._homogeneous = np.concatenate([self.poles * w, w], axis=2)
        return self._homogeneous

    def power_patches(self):
        """The surface's PowerPatches, built on first use: Newton's projection evaluates the
        same surface many times."""
        if self._power is None:
            self._power = PowerPatches(self)
        return self._power


def find_span(knots, degree, t):
    """Index i of the knot span [knots[i], knots[i+1]) holding each t, restricted to the spans
    of the valid range so the end parameter uses the last span."""
    n_poles = len(knots) - degree - 1
    span = np.searchsorted(knots, t, side="right") - 1
    # minimum/maximum, not np.clip: the same values, without numpy 1.24's slow scalar checks
    return np.minimum(np.maximum(span, degree), n_poles - 1)


def basis_derivatives(knots, degree, span, t, n):
    """Non-zero basis functions and their derivatives up to order n at each t.

    Returns (N, n+1, degree+1): [:, k, r] is the k-th derivative of N_{span-degree+r}(t).
    """
    p = degree
    m = len(t)
    ndu = np.empty((p + 1, p + 1, m))
    left = np.empty((p + 1, m))
    right = np.empty((p + 1, m))
    ndu[0, 0] = 1.0
    for j in range(1, p + 1):
        left[j] = t - knots[span + 1 - j]
        right[j] = knots[span + j] - t
        # the textbook's inner loop over r < j, as whole-column operations
        ndu[j, :j] = right[1:j + 1] + left[j:0:-1]
        temp = ndu[:j, j - 1] / ndu[j, :j]
        ndu[:j, j] = right[1:j + 1] * temp
        ndu[j, j] = 0.0
        ndu[1:j + 1, j] += left[j:0:-1] * temp
    ders = np.zeros((m, n + 1, p + 1))
    for j in range(p + 1):
        ders[:, 0, j] = ndu[j, p]
    # The textbook's loop over the basis function r, as whole-column operations: for the k-th
    # derivative, the j-th term is defined for k - j <= r <= p - j (j = 0 and j = k included).
    a = np.empty((2, p + 1, p + 1, m))      # [s, j, r]
    a[0, 0] = 1.0
    s1, s2 = 0, 1
    for k in range(1, min(n, p) + 1):      # derivatives above the degree stay zero
        pk = p - k
        d = np.zeros((p + 1, m))
        a[s2, 0, k:] = a[s1, 0, k:] / ndu[pk + 1, :pk + 1]
        d[k:] += a[s2, 0, k:] * ndu[:pk + 1, pk]
        for j in range(1, k):
            a[s2, j, k - j:p - j + 1] = ((a[s1, j, k - j:p - j + 1] - a[s1, j - 1, k - j:p - j + 1])
                                         / ndu[pk + 1, :pk + 1])
            d[k - j:p - j + 1] += a[s2, j, k - j:p - j + 1] * ndu[:pk + 1, pk]
        a[s2, k, :pk + 1] = -a[s1, k - 1, :pk + 1] / ndu[pk + 1, :pk + 1]
        d[:pk + 1] += a[s2, k, :pk + 1] * ndu[:pk + 1, pk]
        ders[:, k] = d.T
        s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, n + 1):
        ders[:, k] *= factor
        factor *= p - k
    return ders


_COMBOS = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))


def _evaluate_chunk(surf, u, v, order):
    p, q = surf.degree_u, surf.degree_v
    su = find_span(surf.knots_u, p, u)
    sv = find_span(surf.knots_v, q, v)
    Nu = basis_derivatives(surf.knots_u, p, su, u, order)
    Nv = basis_derivatives(surf.knots_v, q, sv, v, order)
    combos = _COMBOS[:(1, 3, 6)[order]]
    ks = [k for k, _ in combos]
    ls = [l for _, l in combos]
    # Tensor-product weights of every derivative (k, l) over the (p+1)(q+1) active poles, then
    # one batched matrix product with the gathered (homogeneous) poles.
    W = (Nu[:, ks, :, None] * Nv[:, ls, None, :]).reshape(len(u), len(combos), -1)
    hom = surf.homogeneous()
    nv = hom.shape[1]
    flat = ((su[:, None] - p + np.arange(p + 1))[:, :, None] * nv
            + (sv[:, None] - q + np.arange(q + 1))[:, None, :]).reshape(len(u), -1)
    block = hom.reshape(-1, hom.shape[2])[flat]                    # (N, (p+1)(q+1), 3|4)
    Dall = np.matmul(W, block)                                      # (N, combos, 3|4)
    return _divide_out(surf, {kl: Dall[:, i] for i, kl in enumerate(combos)}, order)


def _divide_out(surf, D, order):
    """[S, Su, Sv(, Suu, Suv, Svv)] from the derivatives D[k, l] of the (homogeneous) surface:
    the quotient rule for a rational one."""
    combos = _COMBOS[:(1, 3, 6)[order]]
    if not surf.rational:
        return [D[kl] for kl in combos]
    A = {kl: d[:, :3] for kl, d in D.items()}
    w = {kl: d[:, 3:4] for kl, d in D.items()}
    w0 = w[0, 0]
    S = A[0, 0] / w0
    if order == 0:
        return [S]
    Su = (A[1, 0] - w[1, 0] * S) / w0
    Sv = (A[0, 1] - w[0, 1] * S) / w0
    out = [S, Su, Sv]
    if order >= 2:
        Suu = (A[2, 0] - 2 * w[1, 0] * Su - w[2, 0] * S) / w0
        Suv = (A[1, 1] - w[1, 0] * Sv - w[0, 1] * Su - w[1, 1] * S) / w0
        Svv = (A[0, 2] - 2 * w[0, 1] * Sv - w[0, 2] * S) / w0
        out += [Suu, Suv, Svv]
    return out


def evaluate(surf, u, v, order=1):
    """Points and derivatives at N parameter pairs.

    order=0 -> (S,), order=1 -> (S, Su, Sv), order=2 -> (S, Su, Sv, Suu, Suv, Svv); each (N, 3).
    Parameters outside the knot range are extrapolated from the end spans (callers clamp).
    """
    if order not in (0, 1, 2):
        raise ValueError("order must be 0, 1 or 2")
    u = np.atleast_1d(np.asarray(u, dtype=float))
    v = np.atleast_1d(np.asarray(v, dtype=float))
    u, v = np.broadcast_arrays(u, v)
    n_out = 1 if order == 0 else (3 if order == 1 else 6)
    n = len(u)
    if n <= CHUNK:
        out = _evaluate_chunk(surf, u, v, order)
        return tuple(out)
    out = [np.empty((n, 3)) for _ in range(n_out)]
    for s in range(0, n, CHUNK):
        part = _evaluate_chunk(surf, u[s:s + CHUNK], v[s:s + CHUNK], order)
        for o, pv in zip(out, part):
            o[s:s + CHUNK] = pv
    return tuple(out)


def _wrap_or_clamp(t, lo, hi, closed):
    if closed:
        return lo + np.mod(t - lo, hi - lo)
    return np.minimum(np.maximum(t, lo), hi)      # as np.clip, faster on numpy 1.24


def project_points(surf, points, u0, v0, max_iter=40, tol=1e-11):
    """Foot points of `points` (N,3) on the surface patch over u_range x v_range by Newton's
    method from the starts (u0, v0).

    Minimises |S(u,v) - p|^2 / 2: gradient g = ((S-p).Su, (S-p).Sv), full Hessian with the
    second derivatives. Where the Hessian is not positive definite (far on the concave side)
    the Gauss-Newton matrix (first derivatives only, always PSD) takes its place, and steps that
    increase the distance are halved. A parameter at a bound whose gradient points out of the
    box is held there (projected Newton), so the result is the closest point of the box patch,
    possibly on its boundary. Closed directions wrap around the seam instead. Newton is local:
    the start must lie in the foot point's basin.

    Returns (u, v, closest (N,3), converged (N,) bool); converged means the last full Newton
    step moved the point less than FINAL_STEP (applied to first order: the error left is of
    order step^2 x curvature), or less than `tol` for a Gauss-Newton step.
    """
    u, v, S, _, _, converged = project(surf, points, u0, v0, max_iter, tol)
    return u, v, S, converged


def project(surf, points, u0, v0, max_iter=40, tol=1e-11):
    """project_points, also returning the first derivatives at the result:
    (u, v, S, Su, Sv, converged)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    n = len(points)
    patches = surf.power_patches()
    (ulo, uhi), (vlo, vhi) = surf.u_range, surf.v_range
    u = _wrap_or_clamp(np.asarray(u0, dtype=float) * np.ones(n), ulo, uhi, surf.closed_u)
    v = _wrap_or_clamp(np.asarray(v0, dtype=float) * np.ones(n), vlo, vhi, surf.closed_v)
    out_S, out_Su, out_Sv = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
    converged = np.zeros(n, dtype=bool)
    # Last accepted iterate of each point, for backtracking when a step made things worse.
    prev_u, prev_v = u.copy(), v.copy()
    prev_f = np.full(n, np.inf)
    last_du, last_dv = np.zeros(n), np.zeros(n)
    scale = np.ones(n)
    active = np.arange(n)
    eps_u = 1e-14 * (uhi - ulo)
    eps_v = 1e-14 * (vhi - vlo)
    for _ in range(max_iter):
        if len(active) == 0:
            break
        ua, va, pa = u[active], v[active], points[active]
        S, Su, Sv, Suu, Suv, Svv = patches.evaluate(ua, va)
        r = S - pa
        f = np.einsum("ij,ij->i", r, r)
        worse = f > prev_f[active] * (1 + 1e-12) + 1e-24
        if worse.any():
            w = active[worse]
            scale[w] *= 0.5
            stuck = scale[w] < 1.0 / 256
            # Cannot go lower from the last accepted iterate: it is the numerical minimum.
            ws = w[stuck]
            u[ws], v[ws] = prev_u[ws], prev_v[ws]
            converged[ws] = True
            wm = w[~stuck]
            u[wm] = _wrap_or_clamp(prev_u[wm] + scale[wm] * last_du[wm], ulo, uhi, surf.closed_u)
            v[wm] = _wrap_or_clamp(prev_v[wm] + scale[wm] * last_dv[wm], vlo, vhi, surf.closed_v)
            if len(ws):
                out_S[ws], out_Su[ws], out_Sv[ws] = patches.evaluate(u[ws], v[ws], order=1)
            keep = ~worse
            active_next_retry = wm
            active = active[keep]
            ua, va, pa = ua[keep], va[keep], pa[keep]
            S, Su, Sv, Suu, Suv, Svv = S[keep], Su[keep], Sv[keep], Suu[keep], Suv[keep], Svv[keep]
            r, f = r[keep], f[keep]
        else:
            active_next_retry = active[:0]
        gu = np.einsum("ij,ij->i", r, Su)
        gv = np.einsum("ij,ij->i", r, Sv)
        a = np.einsum("ij,ij->i", Su, Su)
        b = np.einsum("ij,ij->i", Su, Sv)
        c = np.einsum("ij,ij->i", Sv, Sv)
        hu = a + np.einsum("ij,ij->i", r, Suu)
        hb = b + np.einsum("ij,ij->i", r, Suv)
        hv = c + np.einsum("ij,ij->i", r, Svv)
        # One-variable steps (the other held at a bound) use their own curvature when positive.
        hu1 = np.where(hu > 0, hu, a)
        hv1 = np.where(hv > 0, hv, c)
        indefinite = (hu <= 0) | (hv <= 0) | (hu * hv - hb * hb <= 1e-12 * a * c)
        hu = np.where(indefinite, a, hu)
        hb = np.where(indefinite, b, hb)
        hv = np.where(indefinite, c, hv)
        hold_u = np.zeros(len(active), bool) if surf.closed_u else \
            ((ua <= ulo + eps_u) & (gu > 0)) | ((ua >= uhi - eps_u) & (gu < 0))
        hold_v = np.zeros(len(active), bool) if surf.closed_v else \
            ((va <= vlo + eps_v) & (gv > 0)) | ((va >= vhi - eps_v) & (gv < 0))
        det = hu * hv - hb * hb
        det = np.where(det == 0, 1e-300, det)
        du = -(hv * gu - hb * gv) / det
        dv = -(hu * gv - hb * gu) / det
        only_v = hold_u & ~hold_v
        only_u = hold_v & ~hold_u
        both = hold_u & hold_v
        du = np.where(only_v | both, 0.0, np.where(only_u, -gu / (hu1 + 1e-300), du))
        dv = np.where(only_u | both, 0.0, np.where(only_v, -gv / (hv1 + 1e-300), dv))
        un = _wrap_or_clamp(ua + du, ulo, uhi, surf.closed_u)
        vn = _wrap_or_clamp(va + dv, vlo, vhi, surf.closed_v)
        # Length in space of the step about to be taken (a seam jump is no step).
        dua, dva = un - ua, vn - va
        if surf.closed_u:
            dua = np.where(np.abs(dua) > 0.5 * (uhi - ulo), 0.0, dua)
        if surf.closed_v:
            dva = np.where(np.abs(dva) > 0.5 * (vhi - vlo), 0.0, dva)
        move = dua[:, None] * Su + dva[:, None] * Sv
        step = np.linalg.norm(move, axis=1)
        # A short full-Newton step is taken to first order instead of another evaluation: with
        # quadratic convergence the error left is of order step^2 x curvature (< 1e-10 mm).
        done = (step <= tol) | (~indefinite & (step <= FINAL_STEP))
        d_idx = active[done]
        converged[d_idx] = True
        u[d_idx], v[d_idx] = un[done], vn[done]
        out_S[d_idx] = S[done] + move[done]
        out_Su[d_idx], out_Sv[d_idx] = Su[done], Sv[done]
        go = ~done
        g_idx = active[go]
        prev_u[g_idx], prev_v[g_idx], prev_f[g_idx] = ua[go], va[go], f[go]
        last_du[g_idx], last_dv[g_idx] = du[go], dv[go]
        scale[g_idx] = 1.0
        u[g_idx], v[g_idx] = un[go], vn[go]
        active = np.concatenate([g_idx, active_next_retry])
    if len(active):
        out_S[active], out_Su[active], out_Sv[active] = patches.evaluate(u[active], v[active],
                                                                          order=1)
    return u, v, out_S, out_Su, out_Sv, converged


class PowerPatches:
    """A surface as one polynomial patch per pair of knot spans, in the span's own parameters
    s = (u - u_i) / (u_{i+1} - u_i) and r likewise: a point and its derivatives are then
    powers of (s, r) and two batched matrix products with the patch's coefficients, without
    the Cox-de Boor recurrence -- eight to ten times faster than ``evaluate`` (order 2) on the
    demo blade's bicubic sides, for code that evaluates one surface many times (Newton's
    projection, the ray cast). Agrees with it to ~1e-13
    relative: the coefficients are the Taylor expansions of the basis functions at each
    span's start (``basis_derivatives`` up to the degree), exact for polynomials.
    Rational surfaces are expanded in homogeneous coordinates and divided out as
    ``evaluate`` does."""

    def __init__(self, surf):
        self.surf = surf
        p, q = surf.degree_u, surf.degree_v
        self._u = _span_taylor(surf.knots_u, p)
        self._v = _span_taylor(surf.knots_v, q)
        (su, _, Au), (sv, _, Av) = self._u, self._v
        hom = surf.homogeneous()                              # (nu, nv, c)
        rows = su[:, None] - p + np.arange(p + 1)             # (Su, p+1)
        cols = sv[:, None] - q + np.arange(q + 1)             # (Sv, q+1)
        block = hom[rows[:, None, :, None], cols[None, :, None, :]]   # (Su, Sv, p+1, q+1, c)
        # coefficient of s^k r^l: sum over the span's poles of both Taylor rows
        coef = np.einsum("ikr,ijrqc,jlq->ijlkc", Au, block, Av)
        self._c = hom.shape[2]
        # (patch, power of r, (power of s, coordinate)): a point's patch is one gathered row
        # block, contracted with the powers of r and then of s by two batched matrix products.
        self._coef = np.ascontiguousarray(
            coef.reshape(len(su) * len(sv), q + 1, (p + 1) * self._c))

    def evaluate(self, u, v, order=2):
        """Points and derivatives at N parameter pairs, as ``evaluate(surf, u, v, order)``:
        (S, Su, Sv, Suu, Suv, Svv) for order 2, (S, Su, Sv) for 1, (S,) for 0; each (N, 3)."""
        surf = self.surf
        p, q = surf.degree_u, surf.degree_v
        u = np.atleast_1d(np.asarray(u, dtype=float))
        v = np.atleast_1d(np.asarray(v, dtype=float))
        u, v = np.broadcast_arrays(u, v)
        if len(u) > CHUNK:
            parts = [self.evaluate(u[s:s + CHUNK], v[s:s + CHUNK], order)
                     for s in range(0, len(u), CHUNK)]
            return tuple(np.concatenate(d) for d in zip(*parts))
        (su, hu, _), (sv, hv, _) = self._u, self._v
        iu = find_span(surf.knots_u, p, u) - su[0]
        iv = find_span(surf.knots_v, q, v) - sv[0]
        Mu = _powers(u - surf.knots_u[su[iu]], hu[iu], p, order)      # (N, order+1, p+1)
        Mv = _powers(v - surf.knots_v[sv[iv]], hv[iv], q, order)
        G = np.matmul(Mv, self._coef[iu * len(sv) + iv])              # (N, order+1, (p+1)c)
        G = G.reshape(len(u), order + 1, p + 1, self._c)
        T = np.matmul(Mu[:, None], G)                    # (N, kv, ku, c): d^ku/du d^kv/dv
        D = {(ku, kv): T[:, kv, ku] for ku, kv in _COMBOS[:(1, 3, 6)[order]]}
        return tuple(_divide_out(surf, D, order))


def _span_taylor(knots, degree):
    """For every span find_span can return: its index, its length, and (span, k, r) the
    coefficient of s^k in basis function N_{span-degree+r}, s in [0, 1] across the span."""
    p = degree
    spans = np.arange(p, len(knots) - p - 1)
    h = knots[spans + 1] - knots[spans]
    # A zero-length span (a repeated knot) is never returned by find_span: its recurrence
    # divides by zero, and its (unused) coefficients are set to zero.
    empty = ~(h > 0)
    h = np.where(empty, 1.0, h)
    with np.errstate(divide="ignore", invalid="ignore"):
        D = basis_derivatives(knots, p, spans, knots[spans].astype(float), p)   # (S, k, r)
    D[empty] = 0.0
    fact = np.cumprod(np.concatenate([[1.0], np.arange(1.0, p + 1)]))
    return spans, h, D * (h[:, None] ** np.arange(p + 1) / fact)[:, :, None]


def _powers(x, h, degree, order):
    """(N, order+1, degree+1): s^k and its derivatives up to `order` in the surface's own
    parameter, for s = x / h."""
    n = len(x)
    inv = 1.0 / h
    k = np.arange(degree + 1.0)
    M = np.zeros((n, order + 1, degree + 1))
    pw = M[:, 0]
    pw[:, 0] = 1.0
    pw[:, 1:] = (x * inv)[:, None]
    np.cumprod(pw, axis=1, out=pw)
    if order >= 1:
        M[:, 1, 1:] = pw[:, :-1] * (k[1:] * inv[:, None])
    if order >= 2:
        M[:, 2, 2:] = pw[:, :-2] * (k[2:] * (k[2:] - 1) * (inv * inv)[:, None])
    return M
