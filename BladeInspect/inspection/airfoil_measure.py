"""A section's measured points into its characteristics: the points slid into the section
plane, their noise, and core.airfoil's measurement against the nominal cut.

Measured points are brought into their section plane by sliding each along the CAD surface
(its tangent nearest the plane normal) rather than straight along the normal: a point of a
raster band 0.25 mm off the plane moves along the part, not off it. A planned scan's points lie
within ~1 um of the plane, where the two agree.
"""

from dataclasses import dataclass

import numpy as np

from ..core import airfoil as kernel


def slide(surface_normal, plane_normal):
    """(direction (n, 3), divisor (n,)) of the slide into the plane: a point h above it moves
    by -h / divisor along direction -- the surface's tangent nearest the plane normal, or the
    plane normal itself where the surface lies nearly in the plane."""
    s = plane_normal - (surface_normal @ plane_normal)[:, None] * surface_normal
    along = s @ plane_normal
    ok = along > 0.2
    return np.where(ok[:, None], s, plane_normal), np.where(ok, along, 1.0)


def into_plane(xyz, surface_normal, origin, plane_normal):
    """Points slid along the CAD surface into the plane (see the module notes)."""
    direction, divisor = slide(surface_normal, plane_normal)
    h = (xyz - origin) @ plane_normal
    return xyz - (h / divisor)[:, None] * direction


def point_noise(pts2d, nominal_profile):
    """Sensor noise of a section's ordered points: the scatter of consecutive points'
    deviations (a smooth form error cancels in the difference), MAD-robust."""
    dev, u = kernel.signed_deviation(pts2d, nominal_profile)
    d = np.diff(dev[np.argsort(np.mod(u, nominal_profile.length))])
    mad = np.median(np.abs(d - np.median(d)))
    return float(1.4826 * mad / np.sqrt(2.0))


def measure(pts2d, nominal_chars, opts, noise, le_hint):
    ordered = kernel.order_by_nominal(pts2d, nominal_chars.profile)
    measured = kernel.Profile(ordered, noise, nominal=nominal_chars.profile)
    ch = kernel.characteristics(measured, engine_axis=(1.0, 0.0), le_hint=le_hint,
                                noise_mm=noise, definition=opts.definition)
    ch = kernel.withhold_corner_edges(ch, nominal_chars)      # metal-angle hook: sharp edges
    # the twist's pivot, the nominal's centroid, is known: not integrated again for each draw
    fit = kernel.fit_section(ordered, nominal_chars.profile, pivot=nominal_chars.centroid_mm)
    cont = kernel.contour(ordered, nominal_chars, fit)
    return ch, fit, cont, ordered


def measure_at(xyz, normals, frame, nom, opts):
    """The measured characteristics of a section's points (CAD frame): slid into the plane,
    given their noise, measured against the nominal."""
    pts = frame.to_2d(into_plane(xyz, normals, frame.origin, frame.normal))
    noise = point_noise(pts, nom.profile)
    ch, fit, cont, ordered = measure(pts, nom, opts, noise, nom.le_point)
    return ch, fit, cont, ordered, noise


def section_points(plane, counted):
    """Indices of the section's points that are measured surface (``counted``, a mask of
    measured_surface)."""
    idx = np.asarray(plane.point_index if plane.point_index is not None else [], dtype=int)
    return idx[counted[idx]] if len(idx) else idx


def on_smooth_fit(result, idx, frame, ch):
    """(points in the plane frame, their feet on the measured profile's smooth fit, the feet's
    outward normals in the CAD frame) of a section's points ``idx``."""
    n0 = result.normal[idx]
    pts = frame.to_2d(into_plane(result.points_cad[idx], n0, frame.origin, frame.normal))
    u, smooth = ch.profile.closest(pts)
    return pts, smooth, frame.vector_to_3d(ch.profile.outward_normal(u))


@dataclass
class SectionMeasurement:
    """One measured section as its uncertainty reads it: the registration ``result``, the
    section's point indices ``idx``, its plane ``frame``, the nominal and measured
    characteristics, the section's fit (core.airfoil.fit_section), the points' noise sigma and
    the block's measured values."""
    result: object
    idx: np.ndarray
    frame: object
    nominal: object                  # core.airfoil.Characteristics
    measured: object                 # core.airfoil.Characteristics
    fit: object
    noise_mm: float
    values: dict
