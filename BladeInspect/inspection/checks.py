"""What a registration refuses, and what it reports it could not measure.

A metrology result must be right or say it cannot be trusted, so a registration is refused,
with one line naming the file and the problem, when

* the points are too degenerate to fix a pose (one point, a line, a plane: their spread has
  fewer than three directions above the sensor's accuracy) - checked before any fitting;
* the cloud's size does not match the CAD's (a scan in metres, inches, micrometres) - checked
  before any fitting, with the factor found;
* the scan does not fit the CAD after the best candidate (another blade's scan): fewer than
  FIT_MIN_FRACTION of its points within the fit distance of the surface; ``allow_mismatch``
  writes the result anyway, with the warning in it.

A pose direction the points do not constrain (sections across a prismatic vane leave its span
position free) is not refused: it is named in words, the pose uncertainty is that of the
directions that are measured (core.icp.split_information states the rule), and the deviations,
which do not depend on it to first order, are reported as usual.
"""

import os

import numpy as np

from ..core.errors import InputError
from ..core import pca as pca_mod
from ..rig.sensor import SensorModel
from ..core.contracts import PROFILE_TOLERANCE_MM
from .sections import span_axis_of

# The sensor's error bound at the reference SNR (docs/contracts.md: accuracy < 6 um). A cloud whose
# spread (standard deviation) in some direction is within it has no extent there, only noise:
# noise of that bound spreads a flat patch by 3.5 um (uniform) or 2 um (clipped normal).
SENSOR_ACCURACY_MM = SensorModel().accuracy

# Unit factors a scan in the wrong unit shows as its extent over the CAD's. Each is judged
# within a factor UNIT_BAND either side, half the (logarithmic) distance between the two
# closest factors, centimetres and inches (2.54 apart), so the bands do not overlap.
UNIT_FACTORS = (("metres", 1e-3), ("inches", 1.0 / 25.4), ("centimetres", 0.1),
                ("micrometres", 1e3))
UNIT_BAND = np.sqrt(2.54)
# A scan cannot be larger than the part it measures (beyond the millimetre band's edge), and
# a scan smaller than the centimetre band's upper edge (a sixth of the part) is either in
# centimetres or a patch too small for a blind registration to place.
MAX_EXTENT_RATIO = UNIT_BAND
MIN_EXTENT_RATIO = 0.1 * UNIT_BAND
# Percentiles of the cloud's extent: 1 % of garbage rows at either end does not count.
EXTENT_PERCENTILES = (1.0, 99.0)

# The surface-fit rule. A point of the right part lies within the profile tolerance of the CAD
# (if the part is good) plus the sensor's error; the robust fit keeps at least half of the
# points at full weight (core.icp._robust_deviation) and its breakdown point is one half, and
# the sensor's gross errors are at most SensorModel.gross_probability (10 %) of even its worst
# readings. So a scan of the right part has far more than half of its points within that
# distance, and one of which fewer than half are has a pose that is set by what does not fit:
# the wrong part, or a part so far out of tolerance that its best fit means nothing.
FIT_MIN_FRACTION = 0.5


def fit_distance_mm(tolerance=PROFILE_TOLERANCE_MM):
    return float(tolerance) + SENSOR_ACCURACY_MM


def check_out_dir(out_dir):
    """--out must be a folder (or not exist yet): refused before any work is done."""
    if out_dir and os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise InputError("%s: --out is an existing file, not a folder" % out_dir)


def check_spread(xyz, source, coincide_only=False):
    """Refuse a cloud whose spread has fewer than three directions above the sensor's accuracy:
    one point, a line or a plane cannot fix a rigid pose against any CAD, and the message
    names the motions it leaves free. ``coincide_only``: the single-point test alone (which
    the unit check must come after, a point having no size; the line and plane tests are in
    millimetres, so they come after the unit check)."""
    centred = xyz - xyz.mean(axis=0)
    values, vectors = np.linalg.eigh(centred.T @ centred / len(xyz))
    spread = np.sqrt(np.maximum(values[::-1], 0.0))
    vectors = vectors[:, ::-1]
    thin = spread <= SENSOR_ACCURACY_MM
    if not thin.any():
        return
    noise = "the sensor's accuracy, %.3g um" % (1e3 * SENSOR_ACCURACY_MM)
    if thin[0]:
        raise InputError(
            "%s: all %d points coincide (spread %.3g mm, below %s): a single point cannot fix "
            "a pose - rotation about every axis and translation along the surface are not "
            "determined" % (source, len(xyz), spread[0], noise))
    if coincide_only:
        return
    if thin[1]:
        raise InputError(
            "%s: the %d points lie on a straight line along %s (spread across it %.3g mm, "
            "below %s): rotation about that line is not determined by any surface, and "
            "a line fixes at most five of the six motions" % (
                source, len(xyz), _vector_text(vectors[:, 0]), spread[1], noise))
    raise InputError(
        "%s: the %d points lie in one plane, normal %s (thickness %.3g mm, below %s): "
        "translation along that normal and tilt about the plane's two axes are not measured "
        "by points that never leave it (a flat patch leaves the motions within the plane free "
        "as well); scan at least two sections or a surface" % (
            source, len(xyz), _vector_text(vectors[:, 2]), spread[2], noise))


def _robust_extent(points, weights=None, percentiles=EXTENT_PERCENTILES):
    """Diagonal of the points' box in their own principal axes (independent of their pose),
    between the given percentiles along each axis."""
    axes = pca_mod.principal_axes(points, weights).axes
    along = (points - points.mean(axis=0)) @ axes
    lo, hi = np.percentile(along, percentiles, axis=0)
    return float(np.linalg.norm(hi - lo))


def check_scale(xyz, nominal, source, cad_source):
    """Refuse a cloud whose size does not match the CAD's, naming the unit it looks like.
    Returns the extent ratio (cloud / CAD) for the record."""
    cad_extent = _robust_extent(nominal.samples.xyz, nominal.samples.weight, (0.0, 100.0))
    ratio = _robust_extent(xyz) / cad_extent
    if MIN_EXTENT_RATIO <= ratio <= MAX_EXTENT_RATIO:
        return ratio
    for unit, factor in UNIT_FACTORS:
        if factor / UNIT_BAND <= ratio <= factor * UNIT_BAND:
            raise InputError(
                "%s: looks like %s, not millimetres: extent ratio %.3g against %s (the cloud "
                "spans %.4g, the CAD %.4g mm); convert the points to millimetres"
                % (source, unit, ratio, cad_source, ratio * cad_extent, cad_extent))
    if ratio > MAX_EXTENT_RATIO:
        problem = "is %.3g times the size of" % ratio
    else:
        problem = "spans only %.3g of" % ratio
    raise InputError("%s: unit or scale mismatch: the cloud %s %s (extent ratio %.3g; "
                     "%.4g against %.4g mm)" % (source, problem, cad_source, ratio,
                                                ratio * cad_extent, cad_extent))


def surface_fit(deviation, tolerance=PROFILE_TOLERANCE_MM):
    """The surface-fit record of result.json: which fraction of the points lies within the fit
    distance of the CAD, against the rule's minimum."""
    distance = fit_distance_mm(tolerance)
    deviation = np.asarray(deviation, dtype=float)
    fraction = float(np.mean(np.abs(deviation) <= distance)) if len(deviation) else 0.0
    return {"fraction_within": fraction, "distance_mm": distance,
            "min_fraction": FIT_MIN_FRACTION, "fits": fraction >= FIT_MIN_FRACTION,
            "rule": "at least %g of the points within the profile tolerance plus the sensor's "
                    "accuracy (%.3g + %.3g mm) of the CAD" % (
                        FIT_MIN_FRACTION, distance - SENSOR_ACCURACY_MM, SENSOR_ACCURACY_MM)}


def mismatch_message(fit, source, cad_source):
    return ("%s: does not fit %s: only %.1f %% of the points lie within %.3g mm of its surface "
            "after the best candidate (at least %.0f %% needed) - another part's scan, or a "
            "part far out of tolerance; --allow-mismatch writes the result anyway"
            % (source, cad_source, 100 * fit["fraction_within"], fit["distance_mm"],
               100 * fit["min_fraction"]))


# ---------------------------------------------------------------- unmeasured directions

# Rounding level of the rotation content of a null direction: an exact translation has none
# but for the eigen-solver's error (~sqrt(eps) of a unit vector at worst).
_ROTATION_CONTENT_TOL = 1e-6
# A named axis is "the" direction of an unmeasured motion when this much of it (cosine) lies
# in the unmeasured subspace, i.e. within about 18 degrees.
_NAMED_AXIS_COSINE = 0.95


def part_axes(nominal):
    """Named axes of the part in the CAD frame: its span (sections.span_axis_of), then the
    other two principal axes of its surface, chord-wise and across the chord."""
    span = span_axis_of(nominal)[0]
    axes = pca_mod.principal_axes(nominal.samples.xyz, nominal.samples.weight).axes
    others = [a - (a @ span) * span for a in axes.T]
    others.sort(key=lambda a: -np.linalg.norm(a))
    chord = others[0] / np.linalg.norm(others[0])
    across = np.cross(span, chord)
    return (({"translation": "position along the span",
              "rotation": "rotation about the span axis"}, span),
            ({"translation": "position along the chord",
              "rotation": "rotation about the chord axis"}, chord),
            ({"translation": "position across the chord",
              "rotation": "rotation about the axis across the chord"}, across))


def describe_unmeasured(split, nominal):
    """The unmeasured directions of a core.icp.PoseSplit in words and as vectors, for
    result.json `pose_unmeasured`: translations ("position along the span") and rotations
    ("rotation about the span axis", possibly about a line off the centre)."""
    if split is None or split.complete:
        return []
    U = split.unmeasured                      # (6, k), y = [t mm, length * w]
    named = part_axes(nominal)
    out = []
    # The rotation parts' singular vectors: the axis directions the subspace turns about
    # (with whatever shift puts the axis where it is), and the combinations of its basis whose
    # rotation part vanishes, its pure translations.
    A, s, Vt = np.linalg.svd(U[3:])
    rank = int(np.count_nonzero(s > _ROTATION_CONTENT_TOL))
    rot = A[:, :rank]
    trans = U[:3] @ Vt[rank:].T
    if trans.shape[1]:
        trans = np.linalg.qr(trans)[0]
    for kind, basis in (("translation", trans), ("rotation", rot)):
        remaining = basis
        for texts, axis in named:
            if remaining.shape[1] and np.linalg.norm(remaining.T @ axis) >= _NAMED_AXIS_COSINE:
                out.append(_motion(kind, texts[kind], axis))
                remaining = _remove(remaining, axis)
        for k in range(remaining.shape[1]):
            v = remaining[:, k]
            out.append(_motion(kind, ("position along %s" if kind == "translation"
                                      else "rotation about %s") % _vector_text(v), v))
    return out


def _remove(basis, axis):
    """The basis of the subspace left after taking out (the projection of) ``axis``."""
    p = basis @ (basis.T @ axis)
    p /= np.linalg.norm(p)
    rest = basis - np.outer(p, p @ basis)
    u, s, _ = np.linalg.svd(rest, full_matrices=False)
    return u[:, s > 1e-6]


def _motion(kind, text, direction):
    return {"motion": text + " is not measured", "kind": kind,
            "direction": [float(x) for x in direction / np.linalg.norm(direction)]}


def unmeasured_warning(unmeasured):
    if not unmeasured:
        return None
    return ("; ".join(u["motion"] for u in unmeasured)
            + ": the pose uncertainty covers only the directions the points measure; the "
              "deviations do not depend on the others")


def _vector_text(v):
    v = np.asarray(v, dtype=float)
    v = v / np.linalg.norm(v)
    if v[np.argmax(np.abs(v))] < 0:
        v = -v
    return "(%.3f, %.3f, %.3f)" % tuple(v)
