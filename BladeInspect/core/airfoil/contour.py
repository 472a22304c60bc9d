"""Measured against nominal: ordering and signed deviation of measured points, the section's
2D fit, contour errors per zone, and the blade's lean and bow."""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .geometry import Range, in_range
from .profile import area_centroid

# Contour zones: a point is at an edge when its foot on the nominal lies within this fraction
# of the chord from that end along the chord (as inspection/sections.py).
CONTOUR_EDGE_FRACTION = 0.03


ZONES = ("LE", "TE", "suction", "pressure")


def order_by_nominal(points, nominal):
    """Unordered measured points of a section, ordered by their foot on the nominal."""
    pts = np.asarray(points, dtype=float)
    u, _ = nominal.closest(pts)
    return pts[np.argsort(np.mod(u, nominal.length))]


def signed_deviation(points, nominal):
    """Signed normal distance of each point from the nominal profile (+ outside, material
    excess) and the feet's parameters."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    u, foot = nominal.closest(pts)
    return np.einsum("ij,ij->i", pts - foot, nominal.outward_normal(u)), u


@dataclass
class SectionFit:
    """The measured section's position against the nominal: measured = R(twist) (nominal -
    pivot) + pivot + shift."""
    shift_mm: np.ndarray
    twist_deg: float
    pivot: np.ndarray
    rms_before_mm: float
    rms_after_mm: float
    iterations: int


def _rot(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def fit_section(points, nominal, pivot=None):
    """2D least-squares fit (shift 2 + twist) of measured points onto the nominal profile by
    point-to-curve Gauss-Newton; twist about ``pivot`` (default the nominal's centroid)."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
        raise InputError("section fit: need an (N, 2) array of at least 3 points")
    pivot = area_centroid(nominal)[1] if pivot is None else np.asarray(pivot, float).reshape(2)
    theta, t = 0.0, np.zeros(2)
    before = signed_deviation(pts, nominal)[0]
    it = 0
    for it in range(1, 60):
        moved = (pts - pivot) @ _rot(theta).T + pivot + t
        dev, u = signed_deviation(moved, nominal)
        n = nominal.outward_normal(u)
        arm = moved - pivot - t
        # d(moved)/d(theta) is arm turned by +90 degrees.
        J = np.column_stack([n, n[:, 1] * arm[:, 0] - n[:, 0] * arm[:, 1]])
        step, *_ = np.linalg.lstsq(J, -dev, rcond=None)
        t, theta = t + step[:2], theta + step[2]
        if np.linalg.norm(step) < 1e-13:
            break
    after = signed_deviation((pts - pivot) @ _rot(theta).T + pivot + t, nominal)[0]
    # The fit maps measured onto nominal; the section's own pose is its inverse.
    twist = -theta
    shift = -_rot(twist) @ t
    return SectionFit(shift, float(np.degrees(twist)), pivot, float(np.sqrt(np.mean(before ** 2))),
                      float(np.sqrt(np.mean(after ** 2))), it)


def contour(points, nominal_chars, fit=None):
    """Contour error per zone (LE, TE, suction, pressure, all). form_location_mm: twice the
    largest |deviation| before any fit (the width of a zone centred on the nominal that holds
    the points); form_mm: max - min deviation after the section's own 2D fit (least squares,
    not minimum zone)."""
    nominal = nominal_chars.profile
    pts = np.asarray(points, dtype=float)
    if fit is None:
        fit = fit_section(pts, nominal)
    before, u = signed_deviation(pts, nominal)
    theta = -np.radians(fit.twist_deg)
    t = -_rot(theta) @ fit.shift_mm
    after = signed_deviation((pts - fit.pivot) @ _rot(theta).T + fit.pivot + t, nominal)[0]
    zone = contour_zones(nominal_chars, u)
    out = {}
    for name in ZONES + ("all",):
        sel = np.ones(len(pts), bool) if name == "all" else zone == name
        if not sel.any():
            out[name] = {"n": 0, "form_mm": None, "form_location_mm": None}
            continue
        out[name] = {"n": int(sel.sum()),
                     "form_mm": float(after[sel].max() - after[sel].min()),
                     "form_location_mm": float(2.0 * np.abs(before[sel]).max()),
                     "min_mm": float(before[sel].min()), "max_mm": float(before[sel].max())}
    return out


def contour_zones(chars, u):
    """'LE', 'TE', 'suction' or 'pressure' for feet at parameters u on the nominal."""
    p = chars.profile.eval(u)
    x = (p - chars.le_point) @ chars.chord_dir / chars.nose_tail_chord_mm
    on_suction = in_range(u, Range(*chars.suction_range), chars.profile.length)
    zone = np.where(on_suction, "suction", "pressure").astype(object)
    zone[x <= CONTOUR_EDGE_FRACTION] = "LE"
    zone[x >= 1.0 - CONTOUR_EDGE_FRACTION] = "TE"
    return zone


def lean_bow(heights_mm, shifts_mm):
    """Per blade: lean is the line through the innermost and outermost sections' shifts
    (its slope per mm of span and its angle), bow each section's shift from that line."""
    h = np.asarray(heights_mm, dtype=float).reshape(-1)
    s = np.asarray(shifts_mm, dtype=float).reshape(len(h), 2)
    if len(h) < 2 or np.ptp(h) <= 0:
        raise InputError("lean/bow: need at least two sections at different heights")
    i, o = int(np.argmin(h)), int(np.argmax(h))
    slope = (s[o] - s[i]) / (h[o] - h[i])
    line = s[i] + (h - h[i])[:, None] * slope
    bow = s - line
    mag = np.linalg.norm(bow, axis=1)
    return {"lean_mm_per_mm": slope.tolist(),
            "lean_deg": float(np.degrees(np.arctan(np.linalg.norm(slope)))),
            "bow_mm": bow.tolist(), "bow_magnitude_mm": mag.tolist(),
            "largest_bow_section": int(np.argmax(mag))}
