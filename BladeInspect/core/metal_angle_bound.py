"""Cramer-Rao lower bound of the inlet and outlet metal angles on a given set of measured
points (the 0.005 deg target), numpy/scipy only.

Model: near each edge the measured profile is the nominal one moved along its normal by a
deviation field e that is, on each side, a polynomial of degree ``degree`` (Legendre, in the
arc length from the edge point along that side) over ``span_mm`` of arc (by default the arc
the definition's window reads, window_span_mm), and nothing elsewhere. The points are the given (x, y) positions, each seen along the normal with Gaussian
noise of its 1 sigma. The field's coefficients' Fisher information is
F = sum_i phi(s_i) phi(s_i)^T / sigma_i^2 (phi the basis at each point's foot on the nominal);
the metal angle is the kernel's own rule (core.airfoil.characteristics) on the noise-free
nominal + field, its gradient g in the coefficients taken by central differences; the bound on
the variance of any unbiased estimator of the angle is g^T F^-1 g (delta method).

The bound is relative to the model: an estimator that may assume a lower-degree deviation
(e.g. one that knows the part deviates from its CAD only as a parabola over the window) is held
to the lower figure that degree gives; one that must follow any part to the degree-4 figure:
the definition is a quartic fit over the window, so degree 4 and up give the same bound (the
definition's own variance; degree 6 is within 1 % of it on the DCA section). docs/validation.md
states both.
"""
import numpy as np

from . import airfoil

# Normal displacement of the nominal's points for the angle's gradient (mm): a micrometre, in
# the angle's linear regime (5e-5 and 1e-3 mm agree to 1e-2 in every component) and wide
# enough that the rule's sub-mdeg discrete steps (a centre more or less) do not show.
GRADIENT_STEP_MM = 1e-3
TARGET_DEG = 0.005          # the target: measured - nominal within 0.005 deg for angles


def _end_points(chars):
    """(edge point parameter on the nominal profile, inlet or outlet attribute) per end."""
    prof = chars.profile
    return {"inlet": prof.closest(chars.le_point)[0][0],
            "outlet": prof.closest(chars.te_point)[0][0]}


def window_span_mm(chars, end, window_pct=airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT):
    """(start, end) of arc along each side from the edge point that the definition's window
    reads: past a quarter turn round the edge and the skipped half edge radius, then the
    window's share of the camber line."""
    # the fitted circle (a corner edge reports no radius, but the window is still laid off)
    r = (chars.le_circle if end == "inlet" else chars.te_circle).radius
    start = 0.5 * np.pi * r + airfoil.END_SKIP * r
    return start, start + window_pct / 100.0 * chars.mcl.inner_length


def _signed_arc(prof, u, u_edge):
    """Arc length (spline parameter) from the edge point to feet u, signed: + forwards."""
    d = np.mod(np.asarray(u) - u_edge + prof.length / 2.0, prof.length) - prof.length / 2.0
    return d


def basis(sigma, span_mm, degree):
    """(n, 2 (degree + 1)) deviation basis at signed arc lengths sigma: a Legendre series of
    the given degree on each side, over arc span_mm = (start, end) from the edge point, zero
    elsewhere."""
    sigma = np.asarray(sigma, dtype=float)
    a, b = span_mm
    out = np.zeros((len(sigma), 2 * (degree + 1)))
    for k, sign in enumerate((1.0, -1.0)):
        t = (sign * sigma - a) / (b - a)
        inside = (t >= 0.0) & (t <= 1.0)
        v = np.polynomial.legendre.legvander(2.0 * t[inside] - 1.0, degree)
        out[np.flatnonzero(inside), k * (degree + 1):(k + 1) * (degree + 1)] = v
    return out


def angle_gradient(nominal_points, chars, end, span_mm, degree, engine_axis=(1.0, 0.0),
                   window_pct=airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT, **kw):
    """d(angle)/d(coefficient) in rad per mm of the field's coefficients, for end 'inlet' or
    'outlet', by central differences of the kernel on the nominal's own points displaced along
    the nominal's normal."""
    prof = chars.profile
    pts = np.asarray(nominal_points, dtype=float)
    u, _ = prof.closest(pts)
    normal = prof.outward_normal(u)
    phi = basis(_signed_arc(prof, u, _end_points(chars)[end]), span_mm, degree)
    key = "inlet_angle_deg" if end == "inlet" else "outlet_angle_deg"
    grad = np.zeros(phi.shape[1])
    for k in range(phi.shape[1]):
        if not phi[:, k].any():
            continue
        step = GRADIENT_STEP_MM * phi[:, k][:, None] * normal
        ang = [getattr(airfoil.characteristics(pts + sgn * step, engine_axis=engine_axis,
                                               metal_angle_window_pct=window_pct, **kw), key)
               for sgn in (1.0, -1.0)]
        grad[k] = np.radians(ang[0] - ang[1]) / (2.0 * GRADIENT_STEP_MM)
    return grad


def fisher(points, sigma_mm, chars, end, span_mm, degree):
    """Fisher information of the field's coefficients from measured points (x, y) with normal
    noise sigma_mm (a number or one per point), their feet on the nominal."""
    prof = chars.profile
    u, _ = prof.closest(np.asarray(points, dtype=float))
    phi = basis(_signed_arc(prof, u, _end_points(chars)[end]), span_mm, degree)
    w = 1.0 / np.broadcast_to(np.asarray(sigma_mm, dtype=float), (len(phi),)) ** 2
    return (phi * w[:, None]).T @ phi, int((np.abs(phi).sum(axis=1) > 0).sum())


def metal_angle_bound(nominal_points, chars, points, sigma_mm, degree=4, span_mm=None,
                      engine_axis=(1.0, 0.0), window_pct=airfoil.DEFAULT_METAL_ANGLE_WINDOW_PCT,
                      target_deg=TARGET_DEG, **kw):
    """Per end ('inlet', 'outlet'): the bound's 1 sigma (deg), the points that inform it, and
    what would reach ``target_deg`` at the bound: the points needed in the same layout (the
    bound goes as 1/sqrt(n)), the spacing that gives them and the noise that would do at
    today's points. ``nominal_points``/``chars``: the nominal section's points and
    characteristics (noise-free); ``points``: the measured positions (their layout is what
    counts, not their noise); extra keywords go to characteristics (le_hint, ...)."""
    pts = np.asarray(points, dtype=float)
    out = {}
    for end in ("inlet", "outlet"):
        span = window_span_mm(chars, end, window_pct) if span_mm is None else span_mm
        g = angle_gradient(nominal_points, chars, end, span, degree, engine_axis, window_pct,
                           **kw)
        F, n = fisher(pts, sigma_mm, chars, end, span, degree)
        used = np.flatnonzero(np.abs(g) > 0)
        Fu = F[np.ix_(used, used)]
        var = float(g[used] @ np.linalg.solve(Fu, g[used]))
        crb = float(np.degrees(np.sqrt(var)))
        ratio = (crb / target_deg) ** 2
        spacing = 2.0 * (span[1] - span[0]) / max(n, 1)
        out[end] = {"crb_deg": crb, "n_points": n, "span_mm": tuple(map(float, span)),
                    "degree": int(degree), "mean_spacing_mm": spacing,
                    "points_for_target": int(np.ceil(n * ratio)),
                    "spacing_for_target_mm": spacing / ratio,
                    "sigma_for_target_mm": float(np.mean(sigma_mm)) / np.sqrt(ratio)}
    return out
