"""Airfoil characteristics per section (issue 15): nominal from the CAD's exact cut, measured
from that section's registered points, deviation, standard uncertainty, tolerance and verdict,
and the blade's lean and bow. The numerics are core.airfoil's; the definitions docs/airfoil.md.

Measured points are brought into their section plane by sliding each along the CAD surface
(its tangent nearest the plane normal) rather than straight along the normal: a point of a
raster band 0.25 mm off the plane moves along the part, not off it. A planned scan's points lie
within ~1 um of the plane, where the two agree.

Uncertainty (``uncertainty`` block, 1 sigma, k = 1) is by re-fitting perturbed points: each
draw moves the section's points by a pose drawn from the registration's covariance (its random
part, inspection.uncertainty.random_pose_covariance), lays
fresh sensor noise on the measured profile's smooth fit where each reading's beam meets it
(beam_feet; "The draws' base": the closest point would keep the scan's own error along the
surface beneath the draw's, docs/fits.md) -- each reading's
own sigma_beam(SNR) along its beam, in the sensor's distribution (its normal part is
inspection.uncertainty.normal_noise; along the normal without beams, the section's
point-to-point scatter only for readings without SNR) -- and adds one reading bias within
the sensor's stated accuracy carried through the registration as inspection.uncertainty
carries it for the deviations; the standard deviation of each characteristic over the draws
is its uncertainty (a parametric bootstrap; bench/bench_uncertainty_mc.py compares it with
the whole chain's scatter). The contour's form
values are maxima: their u adds the maximum's bias (_maxima_bias) to the draws' scatter.
"""

import csv
import dataclasses
import hashlib
import os
from dataclasses import dataclass, field

import numpy as np

from ..core import airfoil as kernel
from ..core import contracts
from ..core import decision as decision_mod
from ..core import transforms as tf
from ..core import uncertainty_model
from ..core.atomic_file import atomic_write
from ..core.errors import InputError
from ..rig.sensor import SensorModel
from . import uncertainty as uncertainty_mod

# Scalar characteristics, list-valued ones, and which of them have no CAD value (the section's
# position and contour against the nominal: zero on the nominal by definition).
SCALARS = ("chord_mm", "axial_chord_mm", "stagger_deg", "max_thickness_mm",
           "max_thickness_pos_pct", "le_radius_mm", "te_radius_mm", "inlet_angle_deg",
           "outlet_angle_deg", "area_mm2", "twist_deg", "form_mm", "form_location_mm")
LISTS = ("le_thickness_mm", "te_thickness_mm", "centroid_mm", "shift_mm")
POSITION = ("twist_deg", "form_mm", "form_location_mm", "shift_mm")
# Characteristics that are maxima over the points (their u includes the maximum's bias)
MAXIMA = ("form_mm", "form_location_mm")
CHARACTERISTICS = SCALARS + LISTS
DEFAULT_DRAWS = 12
# Fewer measured points than this in a section: no measured characteristics (a profile needs
# both edges and both sides).
MIN_SECTION_POINTS = 60
# A measured point is round an edge within this many edge radii of the edge circle's centre.
EDGE_NEIGHBOURHOOD = 1.5
CSV_HEADER = ("section", "characteristic", "nominal", "measured", "deviation", "uncertainty",
              "lower", "upper", "U_k2", "decision_rule", "verdict")


@dataclass
class Options:
    engine_axis: tuple = (1.0, 0.0, 0.0)
    chord_method: str = "nose-tail"
    edge_offsets_mm: tuple = kernel.DEFAULT_EDGE_OFFSETS_MM
    tolerances: list = field(default_factory=list)     # of Tolerance
    characteristics_file: str = None
    draws: int = DEFAULT_DRAWS      # re-fits for the uncertainty; 0: none
    # the sensor's stated accuracy, a reading bias of unknown sign (half-width, mm); None: the
    # sensor model's, as inspection.uncertainty takes it for the deviations
    accuracy_mm: float = None
    # the rig calibration's 1 sigma at the part (RIG.json's calibration_uncertainty_mm, the
    # deviations' calibration term); attach takes it from the verdict's measurement model.
    # None: not in the draws, and the settings say so
    calibration_mm: float = None
    # RIG.json's axis parameters and covariance (inspection.uncertainty.calibration_axis_of):
    # with the readings' angles the draws move each reading by its own axis error, less the
    # registration's take-up (calibration_fields), instead of calibration_mm's translation
    calibration_axis: dict = None
    seed: int = 0
    le_rule: str = "engine-axis"    # one of LE_RULES: which end of the nominal is the LE
    decision_rule: str = "iso14253"  # core.decision's rule; report/inspect pass theirs
    # task-specific uncertainty (inspection.airfoil_task_u): a task file's path (reused when
    # it exists and matches, made there when absent) or an airfoil_task_u.TaskUncertainty;
    # None: every section's u from its own re-fit (``draws``)
    task_uncertainty: object = None
    task_draws: int = 48            # re-fits when a task is made (airfoil_task_u)


@dataclass
class Tolerance:
    characteristic: str          # a field name, or name[i] for element i of a list field
    section: str                 # a section label or "all"
    lower: float                 # limits on the deviation (measured - nominal); None = open
    upper: float
    nominal: float = None        # overrides the CAD's value when given
    row: int = 0


# Which end of the nominal profile is the LE when the CAD's faces do not name it:
# "engine-axis" -- the flow runs along +engine axis, so the LE is the upstream end (the end
# furthest along -engine axis in the plane); "larger-radius" -- the blunter end (the kernel's
# rule without a direction; it picks Rotor 67's TE at 10 % span, whose radius is the larger).
LE_RULES = ("engine-axis", "larger-radius")
LE_RULE_TEXT = {"engine-axis": "the upstream end: the flow runs along +engine axis",
                "larger-radius": "the end with the larger edge radius (the engine axis when "
                                 "the radii agree within their uncertainty)"}
# The plane frame's x axis is the engine axis (cad/airfoil_sections.py): upstream is -x.
UPSTREAM_2D = (-1.0, 0.0)


# ---------------------------------------------------------------- options from the CLI

_AXIS_LETTERS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def parse_engine_axis(text):
    """--engine-axis: a letter x, y, z with an optional sign (-x), or a vector "1,0,0"."""
    t = str(text).strip().lower()
    sign = -1.0 if t.startswith("-") else 1.0
    letter = t.lstrip("+-")
    if letter in _AXIS_LETTERS:
        return tuple(sign * v for v in _AXIS_LETTERS[letter])
    try:
        v = np.array([float(c) for c in t.split(",")])
    except ValueError:
        v = np.zeros(0)
    if v.shape != (3,) or not np.all(np.isfinite(v)) or np.linalg.norm(v) == 0:
        raise InputError("--engine-axis: expected x, y, z, -x, ... or three numbers "
                         "\"1,0,0\", got %r" % text)
    return tuple((v / np.linalg.norm(v)).tolist())


def parse_offsets(text):
    try:
        v = [float(c) for c in str(text).split(",") if c.strip()]
    except ValueError:
        v = []
    if not v or not all(np.isfinite(x) and x > 0 for x in v):
        raise InputError("--edge-offsets: expected positive distances in mm \"0.5,1,2\", got %r"
                         % text)
    return tuple(v)


def _base_name(name):
    return name.split("[", 1)[0]


def read_characteristics(path):
    """--characteristics FILE: CSV with header characteristic,section,lower,upper[,nominal].
    ``section`` a label or ``all``; lower/upper limits on the deviation, empty for none; an
    InputError naming the file and row otherwise."""
    if not os.path.exists(path):
        raise InputError("%s: no such characteristics file" % path)
    try:
        with open(path, newline="") as fh:
            rows = [r for r in csv.reader(fh)]
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError("%s: cannot read characteristics file (%s)" % (path, exc))
    rows = [(k + 1, r) for k, r in enumerate(rows)
            if r and any(c.strip() for c in r) and not r[0].lstrip().startswith("#")]
    if not rows:
        raise InputError("%s: characteristics file is empty" % path)
    header = [c.strip().lower() for c in rows[0][1]]
    need = ("characteristic", "section", "lower", "upper")
    if any(n not in header for n in need):
        raise InputError("%s: row %d: header must be characteristic,section,lower,upper"
                         "[,nominal], got %r" % (path, rows[0][0], ",".join(rows[0][1])))
    col = {n: header.index(n) for n in need + ("nominal",) if n in header}
    out = []
    for line, r in rows[1:]:
        cells = {n: (r[i].strip() if i < len(r) else "") for n, i in col.items()}
        name = cells["characteristic"]
        base = _base_name(name)
        if base not in CHARACTERISTICS:
            raise InputError("%s: row %d: unknown characteristic %r (one of %s)"
                             % (path, line, name, ", ".join(CHARACTERISTICS)))
        if "[" in name:
            try:
                idx = int(name[len(base) + 1:-1])
            except ValueError:
                idx = -1
            if not name.endswith("]") or base not in LISTS or idx < 0:
                raise InputError("%s: row %d: %r: an element is named name[i], i >= 0, of a "
                                 "list characteristic" % (path, line, name))
        if not cells["section"]:
            raise InputError("%s: row %d: section is empty (a label or all)" % (path, line))
        values = {}
        for key in ("lower", "upper", "nominal"):
            text = cells.get(key, "")
            if text == "":
                values[key] = None
                continue
            try:
                values[key] = float(text)
            except ValueError:
                values[key] = float("nan")
            if not np.isfinite(values[key]):
                raise InputError("%s: row %d: %s must be a number, got %r"
                                 % (path, line, key, text))
        if values["lower"] is not None and values["upper"] is not None \
                and values["lower"] > values["upper"]:
            raise InputError("%s: row %d: lower %g is above upper %g"
                             % (path, line, values["lower"], values["upper"]))
        if values["nominal"] is not None and base in LISTS and "[" not in name:
            raise InputError("%s: row %d: a nominal of %s needs one element, name[i]"
                             % (path, line, name))
        out.append(Tolerance(name, cells["section"], values["lower"], values["upper"],
                             values["nominal"], line))
    return out


def options_from_args(engine_axis=None, characteristics=None, chord_method=None,
                      edge_offsets=None, le_rule=None, uncertainty_task=None):
    """Options from the command line's text values (None: the default)."""
    opts = Options()
    if uncertainty_task is not None:
        from . import airfoil_task_u
        airfoil_task_u.check_file(uncertainty_task)   # an existing file must be a task file
        opts.task_uncertainty = uncertainty_task
    if le_rule is not None:
        if le_rule not in LE_RULES:
            raise InputError("--le-rule: %r is not one of %s" % (le_rule, ", ".join(LE_RULES)))
        opts.le_rule = le_rule
    if engine_axis is not None:
        opts.engine_axis = parse_engine_axis(engine_axis)
    if characteristics is not None:
        opts.tolerances = read_characteristics(characteristics)
        opts.characteristics_file = characteristics
    if chord_method is not None:
        if chord_method not in kernel.CHORD_METHODS:
            raise InputError("--chord-method: %r is not one of %s"
                             % (chord_method, ", ".join(kernel.CHORD_METHODS)))
        opts.chord_method = chord_method
    if edge_offsets is not None:
        opts.edge_offsets_mm = parse_offsets(edge_offsets)
    return opts


# ---------------------------------------------------------------- section planes

@dataclass
class Plane:
    label: str
    origin: np.ndarray
    normal: np.ndarray
    height_pct: float
    le_hint_3d: np.ndarray = None     # the CAD's LE when its faces name it
    point_index: np.ndarray = None
    # the CAD's cut in this plane when the section table made it (cad.sections.cut at the
    # airfoil spacing); None: the stage cuts the CAD itself
    cut_polylines: list = None


def planes_of_table(table):
    out = []
    for s in table.sections:
        hint = s.profile.le if (s.profile is not None
                                and s.profile.le_rule == "CAD face roles") else None
        polylines = s.profile.polylines if s.profile is not None else None
        out.append(Plane(s.label, s.origin, s.normal, s.height_pct, hint, s.point_index,
                         polylines or None))
    return out


def nominal_planes(nominal, heights_pct):
    """Planes at span heights of the CAD alone (the nominal-only `airfoil` command), placed as
    inspection.sections places them."""
    from . import sections
    axis, (lo, hi) = sections.span_axis_of(nominal)
    centre = nominal.samples.xyz.mean(axis=0)
    out = []
    for k, h in enumerate(heights_pct):
        level = lo + float(h) / 100.0 * (hi - lo)
        origin = centre + (level - centre @ axis) * axis
        out.append(Plane(str(k + 1), origin, axis.copy(), float(h)))
    return out


# ---------------------------------------------------------------- per section

def _slide(surface_normal, plane_normal):
    """(direction (n, 3), divisor (n,)) of the slide into the plane: a point h above it moves
    by -h / divisor along direction -- the surface's tangent nearest the plane normal, or the
    plane normal itself where the surface lies nearly in the plane."""
    s = plane_normal - (surface_normal @ plane_normal)[:, None] * surface_normal
    along = s @ plane_normal
    ok = along > 0.2
    return np.where(ok[:, None], s, plane_normal), np.where(ok, along, 1.0)


def _into_plane(xyz, surface_normal, origin, plane_normal):
    """Points slid along the CAD surface into the plane (see the module notes)."""
    direction, divisor = _slide(surface_normal, plane_normal)
    h = (xyz - origin) @ plane_normal
    return xyz - (h / divisor)[:, None] * direction


def _point_noise(pts2d, nominal_profile):
    """Sensor noise of a section's ordered points: the scatter of consecutive points'
    deviations (a smooth form error cancels in the difference), MAD-robust."""
    dev, u = kernel.signed_deviation(pts2d, nominal_profile)
    d = np.diff(dev[np.argsort(np.mod(u, nominal_profile.length))])
    mad = np.median(np.abs(d - np.median(d)))
    return float(1.4826 * mad / np.sqrt(2.0))


def _sparse_edges(pts, nom):
    """Notes for an edge with fewer measured points round it than the kernel fits a circle
    to directly: the smoothing spline then rounds the edge off, a bias of the edge radius,
    edge point, chord and metal angle that the stated uncertainty does not cover."""
    notes = []
    for name, circle in (("LE", nom.le_circle), ("TE", nom.te_circle)):
        n = int(np.count_nonzero(np.linalg.norm(pts - circle.center, axis=1)
                                 <= circle.radius * EDGE_NEIGHBOURHOOD))
        if n < kernel._ZONE_MIN_POINTS:
            notes.append("measured: %d points within %.1f edge radii of the %s circle's "
                         "centre (%d wanted): the %s radius, edge point, chord and metal "
                         "angle are biased by the smoothing, beyond the stated uncertainty"
                         % (n, EDGE_NEIGHBOURHOOD, name, kernel._ZONE_MIN_POINTS, name))
    return notes


def _char_values(ch, frame, fit=None, contour=None):
    """The block's values of one Characteristics (nominal: fit None)."""
    v = {"chord_mm": ch.chord_mm, "chord_method": ch.chord_method,
         "axial_chord_mm": ch.axial_chord_mm, "stagger_deg": ch.stagger_deg,
         "max_thickness_mm": ch.max_thickness_mm,
         "max_thickness_pos_pct": ch.max_thickness_pos_pct,
         "le_radius_mm": ch.le_radius_mm, "te_radius_mm": ch.te_radius_mm,
         "edge_offsets_mm": list(ch.edge_offsets_mm),
         "le_thickness_mm": list(ch.le_thickness_mm),
         "te_thickness_mm": list(ch.te_thickness_mm),
         "inlet_angle_deg": ch.inlet_angle_deg, "outlet_angle_deg": ch.outlet_angle_deg,
         "area_mm2": ch.area_mm2,
         "centroid_mm": frame.to_3d(ch.centroid_mm)[0].tolist(),
         "shift_mm": [0.0, 0.0] if fit is None else fit.shift_mm.tolist(),
         "twist_deg": 0.0 if fit is None else fit.twist_deg,
         "form_mm": 0.0 if contour is None else contour["all"]["form_mm"],
         "form_location_mm": 0.0 if contour is None else contour["all"]["form_location_mm"]}
    return v


def _measure(pts2d, nominal_chars, opts, noise, le_hint):
    ordered = kernel.order_by_nominal(pts2d, nominal_chars.profile)
    measured = kernel.Profile(ordered, noise, nominal=nominal_chars.profile)
    ch = kernel.characteristics(measured, engine_axis=(1.0, 0.0), chord_method=opts.chord_method,
                                edge_offsets_mm=opts.edge_offsets_mm, le_hint=le_hint,
                                noise_mm=noise)
    ch = kernel.withhold_corner_edges(ch, nominal_chars)      # metal-angle hook: sharp edges
    # the twist's pivot, the nominal's centroid, is known: not integrated again for each draw
    fit = kernel.fit_section(ordered, nominal_chars.profile, pivot=nominal_chars.centroid_mm)
    cont = kernel.contour(ordered, nominal_chars, fit)
    return ch, fit, cont, ordered


def _flat(values):
    """{name or name[i]: number} of a block's numeric characteristics."""
    out = {}
    for name in SCALARS:
        if values.get(name) is not None:
            out[name] = float(values[name])
    for name in LISTS:
        for i, x in enumerate(values.get(name) or []):
            if x is not None:
                out["%s[%d]" % (name, i)] = float(x)
    return out


def _unflat(flat, like):
    out = {}
    for name in SCALARS:
        out[name] = flat.get(name)
    for name in LISTS:
        out[name] = [flat.get("%s[%d]" % (name, i)) for i in range(len(like.get(name) or []))]
    return out


@dataclass
class SectionResult:
    plane: Plane
    frame: object
    nominal: object                  # core.airfoil.Characteristics
    measured: object = None
    fit: object = None
    contour: dict = None
    points_2d: np.ndarray = None
    noise_mm: float = None
    block: dict = None
    notes: list = field(default_factory=list)
    task_u: tuple = None             # (how, why) under a task uncertainty (airfoil_task_u)


# The nominal's characteristics of a cut, remembered by the cut's points and the arguments
# (NOMINAL_CACHE_SIZE cuts): a process that measures blade after blade of one CAD (a batch
# worker keeps its nominal, the workbench re-runs a section) cuts the same profiles and need
# not read them again -- the kernel is deterministic, so the same points and arguments give
# the same characteristics. A one-blade run (report, inspect) gains nothing from it.
NOMINAL_CACHE_SIZE = 16
_NOMINAL_CACHE = {}


def nominal_characteristics(xy, chord_method, edge_offsets_mm, le_hint, le_upstream,
                            states=None):
    """kernel.characteristics of a nominal cut (engine axis +x of its frame), remembered
    (above); each call has its own Characteristics (its own warnings list), the numbers and
    the profile shared. ``states``: a dict of computed cuts by the same key
    (kernel.characteristics_state; an uncertainty task file keeps its nominal cuts so): a cut
    found there is read back instead of computed (the same bits), one computed is added."""
    xy = np.ascontiguousarray(xy, dtype=float)
    h = hashlib.sha256(xy.tobytes())
    h.update(repr((xy.shape, chord_method, [float(v) for v in edge_offsets_mm],
                   None if le_hint is None else np.asarray(le_hint, float).tolist(),
                   None if le_upstream is None else np.asarray(le_upstream, float).tolist()))
             .encode())
    key = h.hexdigest()
    ch = _NOMINAL_CACHE.pop(key, None)
    if ch is None and states is not None and key in states:
        try:
            ch = kernel.characteristics_from_state(states[key], kernel.Profile(xy))
        except InputError:
            # a kept cut that no longer fits Characteristics (made by another version of
            # it) is computed afresh, not taken for a section the kernel cannot read
            del states[key]
    if ch is None:
        ch = kernel.characteristics(xy, engine_axis=(1.0, 0.0), chord_method=chord_method,
                                    edge_offsets_mm=edge_offsets_mm, le_hint=le_hint,
                                    le_upstream=le_upstream)
    if states is not None and key not in states:
        states[key] = kernel.characteristics_state(ch)
    _NOMINAL_CACHE[key] = ch            # the most recent last
    while len(_NOMINAL_CACHE) > NOMINAL_CACHE_SIZE:
        del _NOMINAL_CACHE[next(iter(_NOMINAL_CACHE))]
    return dataclasses.replace(ch, warnings=list(ch.warnings),
                               edge_offsets_mm=list(ch.edge_offsets_mm),
                               thickness_stations_pct=list(ch.thickness_stations_pct),
                               thickness_mm=list(ch.thickness_mm),
                               le_thickness_mm=list(ch.le_thickness_mm),
                               te_thickness_mm=list(ch.te_thickness_mm))


def clear_nominal_cache():
    """Forget the remembered nominal cuts (a benchmark of a one-blade run)."""
    _NOMINAL_CACHE.clear()


def _section(nominal, plane, opts, result, rng, counted=None, task=None):
    from ..cad.airfoil_sections import airfoil_section
    try:
        xy, frame = airfoil_section(nominal.shape, plane.origin, plane.normal, opts.engine_axis,
                                    polylines=plane.cut_polylines)
        hint = None if plane.le_hint_3d is None else frame.to_2d(plane.le_hint_3d)[0]
        upstream = UPSTREAM_2D if opts.le_rule == "engine-axis" else None
        nom = nominal_characteristics(xy, opts.chord_method, opts.edge_offsets_mm, hint,
                                      upstream, None if task is None else task.nominal)
    except InputError as exc:
        # A plane past the blade's end, or a profile the kernel cannot read: said, not fatal.
        sr = SectionResult(plane=plane, frame=None, nominal=None, notes=["nominal: %s" % exc])
        sr.block = {"label": plane.label, "height_pct": plane.height_pct, "le_rule": None,
                    "nominal": None, "measured": None, "deviation": None, "uncertainty": None}
        return sr
    sr = SectionResult(plane=plane, frame=frame, nominal=nom)
    sr.notes += ["nominal: %s" % w for w in nom.warnings]
    nominal_values = _char_values(nom, frame)
    block = {"label": plane.label, "height_pct": plane.height_pct,
             "le_rule": nom.le_rule, "nominal": nominal_values, "measured": None,
             "deviation": None, "uncertainty": None}
    sr.block = block
    if result is None:
        return sr
    idx = _section_points(plane, counted)
    if len(idx) < MIN_SECTION_POINTS:
        sr.notes.append("measured: %d points in the section, %d needed"
                        % (len(idx), MIN_SECTION_POINTS))
        return sr
    try:
        ch, fit, cont, ordered, noise = _measure_at(result.points_cad[idx], result.normal[idx],
                                                    frame, nom, opts)
    except InputError as exc:
        sr.notes.append("measured: %s" % exc)
        return sr
    sr.measured, sr.fit, sr.contour, sr.points_2d, sr.noise_mm = ch, fit, cont, ordered, noise
    sr.notes += ["measured: %s" % w for w in ch.warnings]
    sr.notes += _sparse_edges(ordered, nom)
    measured_values = _char_values(ch, frame, fit, cont)
    measured_values["noise_mm"] = noise
    measured_values["n_points"] = int(len(idx))
    measured_values["zones"] = cont
    block["measured"] = measured_values
    if task is not None:    # task-specific uncertainty (inspection.airfoil_task_u)
        from . import airfoil_task_u
        sr.task_u = airfoil_task_u.section_uncertainty(task, sr, result, idx, frame, nom, ch,
                                                       fit, opts, noise, rng, measured_values)
    elif opts.draws:
        block["uncertainty"] = _uncertainty(result, idx, frame, nom, ch, fit, opts, noise,
                                            rng, measured_values)
    return sr


def _section_points(plane, counted):
    """Indices of the section's points that are measured surface (``counted``, a mask of
    measured_surface)."""
    idx = np.asarray(plane.point_index if plane.point_index is not None else [], dtype=int)
    return idx[counted[idx]] if len(idx) else idx


def measured_surface(result):
    """Mask of the points the characteristics are measured from: the fit's inliers and every
    point the robust fit rejected that lies in a group (verdict.MIN_SPOT_POINTS or more linked
    among their verdict.SPOT_NEIGHBOURS nearest), as Table 2's verdict counts a spot. The fit
    rejects a defect as readily as a sensor outlier: a 30 um bump on the demo blade's suction
    side lost all of its 55 points above 15 um, and the section's form read 16 um. Only the
    isolated rejected readings are left out, as the verdict leaves out isolated points."""
    from .verdict import MIN_SPOT_POINTS, SPOT_NEIGHBOURS, linked_groups
    counted = np.asarray(result.inlier, dtype=bool).copy()
    rejected = np.flatnonzero(~counted)
    if len(rejected):
        labels, sizes = linked_groups(result.points_cad, rejected, SPOT_NEIGHBOURS)
        counted[rejected[sizes[labels] >= MIN_SPOT_POINTS]] = True
    return counted


def _measure_at(xyz, normals, frame, nom, opts):
    """The measured characteristics of a section's points (CAD frame): slid into the plane,
    given their noise, measured against the nominal."""
    pts = frame.to_2d(_into_plane(xyz, normals, frame.origin, frame.normal))
    noise = _point_noise(pts, nom.profile)
    ch, fit, cont, ordered = _measure(pts, nom, opts, noise, nom.le_point)
    return ch, fit, cont, ordered, noise


def sensor_of(opts):
    """The sensor the uncertainty's draws model (the default one, at ``opts.accuracy_mm``)."""
    return (SensorModel() if opts.accuracy_mm is None
            else SensorModel(accuracy=float(opts.accuracy_mm)))


def on_smooth_fit(result, idx, frame, ch):
    """(points in the plane frame, their feet on the measured profile's smooth fit, the feet's
    outward normals in the CAD frame) of a section's points ``idx``."""
    n0 = result.normal[idx]
    pts = frame.to_2d(_into_plane(result.points_cad[idx], n0, frame.origin, frame.normal))
    u, smooth = ch.profile.closest(pts)
    return pts, smooth, frame.vector_to_3d(ch.profile.outward_normal(u))


# A reading's foot along its beam is taken only within this many of its beam sigmas of the
# reading (farther, the beam runs nearly along the fit: its closest foot is kept).
BEAM_FOOT_SIGMAS = 10.0
_BEAM_FOOT_ROUNDS = 3


def beam_feet(profile, pts, feet, beams2d, reach):
    """Where each point's beam (in-plane directions ``beams2d``, as _into_plane carries a move
    along the beam into the plane) meets ``profile``: the point with its reading's error along
    the beam taken out, the noise-free reading the sensor model assumes. ``feet``, the closest
    points, are kept where the beam misses the profile within ``reach`` (per point) of the
    point or has no direction. A few Newton steps on the signed distance along the beam."""
    t = np.zeros(len(pts))
    ok = np.all(np.isfinite(beams2d), axis=1) & (np.linalg.norm(beams2d, axis=1) > 0)
    b = np.where(ok[:, None], beams2d, 0.0)
    for _ in range(_BEAM_FOOT_ROUNDS):
        u, at = profile.closest(pts - t[:, None] * b)
        n = profile.outward_normal(u)
        cos = np.einsum("ij,ij->i", b, n)
        ok &= np.abs(cos) > 1e-3
        dev = np.einsum("ij,ij->i", pts - t[:, None] * b - at, n)
        t = t + np.where(ok, dev / np.where(ok, cos, 1.0), 0.0)
    ok &= np.abs(t) * np.linalg.norm(b, axis=1) <= reach
    _, on = profile.closest(pts - t[:, None] * b)
    return np.where(ok[:, None], on, feet)


def _beams_in_plane(beams, surface_normal, frame):
    """(n, 2) in-plane displacement that _into_plane makes of a unit move along each beam (a
    move out of the plane is slid back along the surface, which turns it in the plane)."""
    pn = np.asarray(frame.normal, dtype=float)
    direction, divisor = _slide(surface_normal, pn)
    moved = beams - ((beams @ pn) / divisor)[:, None] * direction
    return np.column_stack([moved @ frame.e1, moved @ frame.e2])


def _uncertainty(result, idx, frame, nom, ch, fit, opts, noise, rng, measured_values,
                 draws_sd=None):
    """1 sigma of each measured characteristic by re-fitting perturbed points (module notes);
    ``draws_sd``, a dict, is given the draws' own 1 sigma before the maxima's bias."""
    n0 = result.normal[idx]
    pts, smooth, out_normal = on_smooth_fit(result, idx, frame, ch)
    cov = uncertainty_mod.random_pose_covariance(result)
    cov = np.where(np.isfinite(cov), cov, 0.0)
    try:
        chol = np.linalg.cholesky(cov + 1e-30 * np.eye(6))
    except np.linalg.LinAlgError:
        w, V = np.linalg.eigh(cov)
        chol = V * np.sqrt(np.clip(w, 0, None))
    centre = np.asarray(result.center, dtype=float)
    # The sensor's systematic error: one reading bias b per draw (rectangular within the stated
    # accuracy) moves every point by b along its beam, less the rigid motion by which the
    # registration takes that up (inspection.uncertainty.bias_take_up, whose normal part is
    # the deviations' b s_i); without beams by b along its normal, taken whole. Where the
    # sensor errs, as the noise (_point_noise_model). Noise-free, the characteristics' slopes
    # on the bias are those of moving along the normal by b s_i (within 3 % on the demo
    # blade's loop); with the noise, bench_uncertainty_mc (16 trials) found section 2's chord
    # 0.77 and section 1's LE thickness at 2 mm 1.26 of the chain's scatter against 0.58 and
    # 1.67 along the normal (a stated u of 2 x 12 draws is itself ~15 % uncertain).
    sensor = sensor_of(opts)
    accuracy = sensor.accuracy
    sigma, spread, along, unit = _point_noise_model(result, idx, sensor, noise, out_normal)
    # The draws' noise-free points: each reading's beam where it meets the measured profile's
    # smooth fit (module notes).
    smooth3 = frame.to_3d(beam_feet(ch.profile, pts, smooth, _beams_in_plane(along, n0, frame),
                                     BEAM_FOOT_SIGMAS * spread))
    take_up = uncertainty_mod.bias_take_up(result, sensor)
    if take_up is None:
        bias_step = n0
    else:
        beams, r = take_up
        bias_step = beams[idx] - r[:3] - np.cross(r[3:], smooth3 - centre)
    axis_fields, axis_chol = _calibration_model(result, idx, opts, sensor)
    draws = []
    for _ in range(max(int(opts.draws), 2)):
        d = chol @ rng.standard_normal(6)
        R = tf.rotation_from_vector(d[3:])
        moved = (smooth3 - centre) @ R.T + centre + d[:3]
        moved = moved + along * (spread * unit(rng, len(moved)))[:, None]
        moved = moved + rng.uniform(-accuracy, accuracy) * bias_step
        if axis_fields is not None:
            moved = moved + axis_fields @ (axis_chol @ rng.standard_normal(4))
        p2 = frame.to_2d(_into_plane(moved, n0, frame.origin, frame.normal))
        if opts.calibration_mm and axis_fields is None:
            # the calibration's error at the part as one in-plane translation of the section
            # (1 sigma per axis): its location part, which the Monte Carlo showed missing
            # (docs/airfoil.md, "Decisions")
            p2 = p2 + float(opts.calibration_mm) * rng.standard_normal(2)
        try:
            c, f, k, _ = _measure(p2, nom, opts, noise, nom.le_point)
        except InputError:
            continue
        draws.append(_flat(_char_values(c, frame, f, k)))
    if len(draws) < 2:
        return None
    keys = _flat(measured_values).keys()
    sd = {key: _draws_sd([d[key] for d in draws if key in d])
          for key in keys if sum(key in d for d in draws) >= 2}
    if draws_sd is not None:   # inspection.airfoil_task_u stores these
        draws_sd.update(sd)
    for key, bias in _maxima_bias(result, idx, pts, nom, fit, sigma, sensor).items():
        if key in sd:
            sd[key] = float(np.hypot(sd[key], bias))
    return _unflat(sd, measured_values)


def _calibration_model(result, idx, opts, sensor):
    """(fields (n, 3, 4), Cholesky factor (4, 4)) of the section's readings' axis errors
    (uncertainty.calibration_fields) when the options carry RIG.json's axis covariance and the
    readings their angles, else (None, None): calibration_mm's in-plane translation serves
    instead (it over-states the shifts and holds no shape part, docs/airfoil.md). The fields
    of the whole scan cost ~0.04 s (demo loop, 16264 readings), against ~1 s of a section's
    re-fits: not kept between sections."""
    if opts.calibration_axis is None:
        return None, None
    fields = uncertainty_mod.calibration_fields(result, opts.calibration_axis, sensor)
    if fields is None:
        return None, None
    cov = np.asarray(opts.calibration_axis["covariance"], dtype=float)
    w, V = np.linalg.eigh(0.5 * (cov + cov.T))
    return fields[idx], V * np.sqrt(np.clip(w, 0.0, None))


def _maxima_bias(result, idx, pts, nom, fit, sigma, sensor):
    """{form key: bias} of the contour's form values, which are maxima over the section's
    readings: the largest of several noisy readings lies above the true largest (as for a
    worst deviation, inspection.uncertainty.maximum_error with the same noise, systematic
    bias and pose). form_location_mm is twice the largest |deviation| before the section's
    fit; form_mm the largest less the smallest deviation after it, both ends biased outwards.
    The draws' scatter of a form value does not hold this bias (their maxima are as biased
    as the measured one); u states both."""
    model = uncertainty_mod.MeasurementModel(sensor=sensor)
    shared = uncertainty_mod.shared_terms(result, idx, model)
    flipped = [uncertainty_model.SharedTerm(t.name, -t.coefficients, t.sample)
               for t in shared]
    before = kernel.signed_deviation(pts, nom.profile)[0]
    theta = -np.radians(fit.twist_deg)
    c, s = np.cos(theta), np.sin(theta)
    turn = np.array([[c, -s], [s, c]])
    after = kernel.signed_deviation((pts - fit.pivot) @ turn.T + fit.pivot
                                    - turn @ fit.shift_mm, nom.profile)[0]
    # the ends of the after-fit range as maxima of readings clear of zero
    span = float(after.max() - after.min()) + 1.0
    # only the biases are used: the terms' extra rounds are not run (the same biases)
    _, location, _ = uncertainty_mod.maximum_error(before, sigma, shared, model, bias_only=True)
    _, top, _ = uncertainty_mod.maximum_error(after - after.min() + span, sigma, shared, model,
                                              bias_only=True)
    _, bottom, _ = uncertainty_mod.maximum_error(after.max() + span - after, sigma, flipped,
                                                 model, bias_only=True)
    return {"form_location_mm": 2.0 * location, "form_mm": top + bottom}


def _point_noise_model(result, idx, sensor, scatter, out_normal):
    """(sigma (n,), spread (n,), along (n, 3), unit-variance sampler) of the section's readings'
    noise: sigma along the normal, each reading's own sigma_beam(SNR) cos(theta) in the
    sensor's distribution (inspection.uncertainty.normal_noise, the deviations' model), and
    for the draws the same error where the sensor makes it, sigma_beam along the beam. Its
    part along the surface moves a reading along the profile, which the edges, the thickness
    stations, the metal angles and a flat maximum's position read. On one noise-only scan of
    the demo loop, 48 draws against a 16-scan noise-only chain (sections 1/2), the normal
    part alone -> along the beam: max-thickness position 0.76/2.52 -> 0.89/1.06 of the
    chain's scatter, inlet angle 0.86/0.95 -> 1.12/1.10, stagger 0.52/1.10 -> 0.70/1.06, LE
    thickness at 2 mm 0.77/0.76 -> 0.85/1.00; outlet angle 0.60/0.81 -> 0.77/0.76 and TE
    thickness at 1 mm 0.63/0.84 -> 0.63/0.65 stay short (cause not found). Without beams sigma_beam
    along ``out_normal`` (the profile's normal); for readings without SNR (another sensor's
    points) the section's point-to-point scatter as a normal noise along it."""
    n = len(idx)
    if result.snr is None:
        sigma = np.full(n, scatter)
        return sigma, sigma, out_normal, lambda rng, k: rng.standard_normal(k)
    sigma = uncertainty_mod.normal_noise(result, idx, sensor)
    sigma = np.where(np.isfinite(sigma), sigma, scatter)
    snr = np.asarray(result.snr, dtype=float)[idx]
    with np.errstate(divide="ignore", invalid="ignore"):
        beam_sigma = np.where(snr > 0, sensor.sigma_ref * np.sqrt(sensor.snr_ref / snr), np.nan)
    beams = uncertainty_mod.beam_directions(result)
    along = out_normal.copy()
    spread = sigma.copy()
    if beams is not None:
        read = np.isfinite(beam_sigma)
        along[read] = beams[idx][read]
        spread[read] = beam_sigma[read]
    return sigma, spread, along, uncertainty_mod.unit_noise(sensor)


# A draw farther than this many robust sigmas (1.4826 MAD) from the draws' median is a failure
# of that re-fit (an offset station off the end of a nose), not scatter: 12 normal draws hold
# one so far in a thousand sets (the MAD of 12 is itself loose; 5 would drop one in 35).
DRAW_OUTLIER_SIGMAS = 10.0


def _draws_sd(values):
    """Standard deviation of one characteristic over the re-fit draws, without the draws that
    failed for it (DRAW_OUTLIER_SIGMAS): one draw whose thickness station fell off the nose
    once stated a 13.6 mm uncertainty on Rotor 67."""
    v = np.asarray(values, dtype=float)
    spread = 1.4826 * np.median(np.abs(v - np.median(v)))
    if spread > 0:
        v = v[np.abs(v - np.median(v)) <= DRAW_OUTLIER_SIGMAS * spread]
    return float(np.std(v, ddof=1)) if len(v) >= 2 else float("nan")


# ---------------------------------------------------------------- tolerances and verdicts

def _tolerance_for(tolerances, label, key):
    """The most specific row for (section, characteristic): a named section before all, an
    element name[i] before the whole list."""
    base = _base_name(key)
    best, rank = None, -1
    for t in tolerances:
        if t.section != label and t.section.lower() != "all":
            continue
        if t.characteristic != key and t.characteristic != base:
            continue
        r = (2 if t.section == label else 0) + (1 if t.characteristic == key else 0)
        if r > rank:
            best, rank = t, r
    return best


# Expanded uncertainty of a judged characteristic: k times its standard uncertainty (the
# ``uncertainty`` block, by re-fitting perturbed points).
COVERAGE_FACTOR = 2.0
# A characteristic judged with no stated uncertainty (Options.draws = 0) is decided by simple
# acceptance, and says so: the ISO rule needs a U.
NO_U_RULE = "simple"
JUDGED = (decision_mod.PASS, decision_mod.FAIL, decision_mod.NOT_PROVEN, "not measured")


def _decision(deviation, u, t, rule):
    """The decision on one characteristic's deviation against its tolerance row: U = k u under
    ``rule``; without u, simple acceptance (NO_U_RULE), named in the result."""
    if u is not None and np.isfinite(u):
        U, used = COVERAGE_FACTOR * float(u), rule
    else:
        U, used = None, NO_U_RULE
    d = decision_mod.decide(deviation, 0.0 if U is None else U, t.lower, t.upper, rule=used)
    tur = d.test_uncertainty_ratio
    return {"verdict": d.verdict, "rule": used, "U": U, "k": COVERAGE_FACTOR,
            "tur": None if tur is None or not np.isfinite(tur) else float(tur)}


def _judge(block, tolerances, measured_part=True, rule="iso14253"):
    """Deviation, tolerance and verdict of each characteristic of one section block (the
    decision rule ``rule`` with U = k u, core.decision); returns (the keys that failed, the
    keys not proven)."""
    if block["nominal"] is None:
        block.update(tolerance={}, verdicts={}, decisions={}, verdict="not measured")
        return [], []
    nominal = _flat(block["nominal"])
    measured = _flat(block["measured"]) if block["measured"] else {}
    sd = _flat(block["uncertainty"]) if block.get("uncertainty") else {}
    deviation, tol_out, verdicts, decisions, failed, unproven = {}, {}, {}, {}, [], []
    # A toleranced characteristic the CAD has no value for (a corner's edge radius) is judged
    # against the drawing's nominal if the row gives one, else cannot be signed off.
    keys = list(nominal) + [k for k in SCALARS if k not in nominal
                            and _tolerance_for(tolerances, block["label"], k) is not None]
    for key in keys:
        t = _tolerance_for(tolerances, block["label"], key)
        if t is not None and t.nominal is not None:
            nominal[key] = t.nominal
        elif key not in nominal:
            judged = measured_part and (t.lower is not None or t.upper is not None)
            tol_out[key] = {"lower": t.lower, "upper": t.upper, "row": t.row}
            verdicts[key] = "not measured" if judged else "not judged"
            if judged:
                failed.append(key + " (no nominal: not a rounded edge on the CAD)")
            continue
        if key in measured:
            deviation[key] = measured[key] - nominal[key]
        if t is None or (t.lower is None and t.upper is None):
            verdicts[key] = "not judged"
            continue
        tol_out[key] = {"lower": t.lower, "upper": t.upper, "row": t.row}
        if not measured_part:
            verdicts[key] = "not judged"
            continue
        if key not in deviation:
            # A toleranced characteristic that could not be measured cannot be signed off.
            verdicts[key] = "not measured"
            failed.append(key + " (not measured)")
            continue
        decisions[key] = _decision(deviation[key], sd.get(key), t, rule)
        verdicts[key] = decisions[key]["verdict"]
        if verdicts[key] == decision_mod.FAIL:
            failed.append(key)
        elif verdicts[key] == decision_mod.NOT_PROVEN:
            unproven.append(key)
    like = block["nominal"]
    block["nominal"] = dict(like, **{k: v for k, v in _unflat(nominal, like).items()})
    block["deviation"] = _unflat(deviation, like) if measured else None
    block["tolerance"] = tol_out
    block["verdicts"] = verdicts
    block["decisions"] = decisions
    judged = [v for v in verdicts.values() if v in JUDGED]
    block["verdict"] = (decision_mod.combine([decision_mod.FAIL if v == "not measured" else v
                                              for v in judged]) if judged else "not judged")
    return failed, unproven


@dataclass
class Stage:
    sections: list                   # of SectionResult
    blocks: list                     # result.json `airfoil`
    lean_bow: dict
    verdict: dict
    settings: dict
    counted: np.ndarray = None       # measured_surface of the result (None: nominal only)

    def extras(self):
        """result.json's fields of the stage."""
        return {"airfoil": self.blocks, "lean_bow": self.lean_bow,
                "airfoil_verdict": self.verdict, "airfoil_settings": self.settings}


def _lean_bow(results, span_axis):
    measured = [r for r in results if r.fit is not None]
    if len(measured) < 2:
        return None
    heights = [float(r.plane.origin @ span_axis) for r in measured]
    if np.ptp(heights) <= 0:
        return None
    lb = kernel.lean_bow(heights, [r.fit.shift_mm for r in measured])
    lb["largest_bow_section"] = measured[lb["largest_bow_section"]].plane.label
    lb["sections"] = [r.plane.label for r in measured]
    lb["heights_mm"] = heights
    return lb


def stage_verdict(results, failed, unproven):
    """airfoil_verdict: pass only when every judged characteristic passed (None when nothing
    is judged); ``verdict`` core.decision's combined pass / not proven / fail."""
    n_judged = sum(v in JUDGED for r in results for v in r.block["verdicts"].values())
    combined = (None if n_judged == 0 else decision_mod.FAIL if failed else
                decision_mod.NOT_PROVEN if unproven else decision_mod.PASS)
    if n_judged == 0:
        summary = "airfoil: no characteristic toleranced"
    elif failed:
        summary = "airfoil: FAIL %d of %d: %s" % (len(failed), n_judged, "; ".join(failed))
    elif unproven:
        summary = "airfoil: NOT PROVEN %d of %d: %s" % (len(unproven), n_judged,
                                                        "; ".join(unproven))
    else:
        summary = "airfoil: PASS (%d characteristics)" % n_judged
    return {"pass": None if n_judged == 0 else combined == decision_mod.PASS,
            "verdict": combined, "n_judged": n_judged, "failed": failed,
            "not_proven": unproven, "summary": summary}


def check_sections(opts, planes):
    """A tolerance row's section must be one of the planes' labels (or all)."""
    labels = {p.label for p in planes}
    for t in opts.tolerances:
        if t.section.lower() != "all" and t.section not in labels:
            raise InputError("%s: row %d: section %r is not one of the sections (%s)"
                             % (opts.characteristics_file, t.row, t.section,
                                ", ".join(sorted(labels))))


def run_stage(nominal, planes, opts=None, result=None, span_axis=None):
    """The characteristics of every plane (measured too when ``result``, a
    RegistrationResult, is given), judged against ``opts.tolerances``."""
    from . import sections
    opts = opts or Options()
    if span_axis is None:
        span_axis, _ = sections.span_axis_of(nominal)
    check_sections(opts, planes)
    rng = np.random.default_rng(opts.seed)
    counted = None if result is None else measured_surface(result)
    task = None
    if opts.task_uncertainty is not None and result is not None:
        from . import airfoil_task_u
        task = airfoil_task_u.open_task(
            opts.task_uncertainty, airfoil_task_u.task_key(nominal, opts, result),
            opts, result)
    results = [_section(nominal, p, opts, result, rng, counted, task) for p in planes]
    if task is not None and not task.made:
        task.finish()    # written (atomically) to its file, or kept in memory
    if opts.decision_rule not in decision_mod.RULES:
        raise InputError("--decision-rule: unknown rule '%s' (use %s)"
                         % (opts.decision_rule, ", ".join(decision_mod.RULES)))
    failed, unproven = [], []
    for r in results:
        f, n = _judge(r.block, opts.tolerances, result is not None, opts.decision_rule)
        failed += ["section %s: %s" % (r.plane.label, k) for k in f]
        unproven += ["section %s: %s" % (r.plane.label, k) for k in n]
        r.block["notes"] = list(r.notes)
    verdict = stage_verdict(results, failed, unproven)
    if result is not None and opts.calibration_axis is not None and \
            uncertainty_mod.reading_angles(result) is not None:
        calibration = ("the rig calibration's axis covariance (RIG.json) through each "
                       "reading's rotary angle, less the registration's take-up")
    elif opts.calibration_mm:
        calibration = ("the rig calibration's %.4g mm (1 sigma at the part) as an in-plane "
                       "shift of each section" % opts.calibration_mm)
    else:
        calibration = "the rig calibration not included (no RIG.json stating its uncertainty)"
    settings = {"engine_axis": list(map(float, opts.engine_axis)),
                "chord_method": opts.chord_method,
                "le_rule": opts.le_rule,
                "le_rule_meaning": LE_RULE_TEXT[opts.le_rule] + " (unless the CAD's faces "
                                   "name the LE: the block's le_rule says \"given\")",
                "edge_offsets_mm": list(map(float, opts.edge_offsets_mm)),
                "characteristics_file": opts.characteristics_file,
                "tolerance_meaning": "lower/upper limit the deviation measured - nominal",
                "uncertainty_method": "re-fit of perturbed points: pose from the registration "
                                      "covariance, each reading's sensor noise along its "
                                      "beam (sigma_beam, the sensor's distribution) on the "
                                      "measured profile's smooth fit and "
                                      "the sensor's bias, %d draws; %s; form values add the "
                                      "bias of a maximum" % (opts.draws, calibration),
                # a standard deviation of n draws is itself uncertain by 1 / sqrt(2 (n - 1))
                "uncertainty_relative_accuracy": (None if opts.draws < 2 else
                                                  float(1.0 / np.sqrt(2.0 * (opts.draws - 1)))),
                "uncertainty_coverage": "standard uncertainty, 1 sigma (k = 1); a judged "
                                        "characteristic's U = %g u (its `decisions`)"
                                        % COVERAGE_FACTOR,
                "decision_rule": opts.decision_rule,
                "decision_rule_text": decision_mod.RULE_TEXT[opts.decision_rule],
                "decision_without_u": "a characteristic with no stated u (draws 0) is "
                                      "decided by %s: %s" % (NO_U_RULE,
                                                             decision_mod.RULE_TEXT[NO_U_RULE])}
    if task is not None:
        settings.update(airfoil_task_u.settings_of(
            task, {r.plane.label: r.task_u for r in results if r.task_u is not None},
            settings["uncertainty_method"]))
    return Stage(results, [r.block for r in results], _lean_bow(results, span_axis), verdict,
                 settings, counted)


def attach(result, nominal, table, verdict, opts=None):
    """The stage for a report or an inspection: the section table's sections measured from
    the result, the part's verdict taking in every judged characteristic (it fails, naming
    them, when one does). The stage is kept on the table for the report's figures."""
    opts = opts or Options()
    model = verdict.get("measurement_model") or {}
    opts = dataclasses.replace(
        opts, decision_rule=verdict.get("decision_rule", "iso14253"),
        calibration_mm=(model.get("calibration_mm") if opts.calibration_mm is None
                        else opts.calibration_mm),
        calibration_axis=(model.get("calibration_axis") if opts.calibration_axis is None
                          else opts.calibration_axis))
    stage = run_stage(nominal, planes_of_table(table), opts, result, table.span_axis)
    table.airfoil = stage
    if stage.verdict["verdict"] == decision_mod.FAIL:
        verdict["summary"] = ("FAIL: %s; profile %s" % (stage.verdict["summary"],
                                                         verdict["summary"])
                              if verdict["pass"] else
                              "%s; %s" % (verdict["summary"], stage.verdict["summary"]))
        verdict["pass"] = False
        if "verdict" in verdict:   # the part's decision (core.decision) takes the failure in
            verdict["verdict"] = decision_mod.FAIL
    elif stage.verdict["verdict"] == decision_mod.NOT_PROVEN:
        verdict["summary"] = "%s; %s" % (verdict["summary"], stage.verdict["summary"])
        verdict["pass"] = False    # not proven is never rounded to pass
        if verdict.get("verdict") in (decision_mod.PASS, None):
            verdict["verdict"] = decision_mod.NOT_PROVEN
    verdict["airfoil"] = stage.verdict
    if getattr(result, "fit_sensitivity", None):   # issue 16 item 2: the airfoil rows
        add_to_sensitivity(result.fit_sensitivity, stage, result, opts)
    return stage


UNITS = {"deg": "deg", "pct": "%", "mm2": "mm2", "mm": "mm"}


def _unit_of(key):
    base = _base_name(key)
    return next(UNITS[u] for u in ("deg", "pct", "mm2", "mm") if base.endswith("_" + u))


def add_to_sensitivity(doc, stage, result, opts):
    """The airfoil characteristics as rows of ``fit_sensitivity`` (inspection.fitting): every
    measured characteristic's deviation and verdict under each fit objective, re-measured from
    the points moved by that objective's motion (``cad_motion_by_fit``, from the least-squares
    start; the result stands at the chosen one's). U is the chosen fit's (the measurement's,
    about the same under every pose). ``largest_change_airfoil`` names the row whose change
    across the fits is largest in units of its U (k = 2), and ``airfoil_verdict_by_fit`` the
    airfoil verdict under each fit."""
    motions = doc.get("cad_motion_by_fit")
    if not motions:
        return
    chosen = np.asarray(motions[doc["chosen"]], dtype=float)
    back = np.linalg.inv(chosen)
    per_fit = {}
    quiet = dataclasses.replace(opts, draws=0)
    for objective in doc["objectives"]:
        if objective == doc["chosen"]:
            per_fit[objective] = {r.plane.label: r.block for r in stage.sections}
            continue
        move = np.asarray(motions[objective], dtype=float) @ back
        if np.allclose(move, np.eye(4), atol=1e-15):
            per_fit[objective] = {r.plane.label: r.block for r in stage.sections}
            continue
        view = dataclasses.replace(result, points_cad=tf.apply_transform(move, result.points_cad))
        blocks = {}
        for r in stage.sections:
            if r.measured is None:
                continue
            idx = _section_points(r.plane, stage.counted)
            try:
                ch, fit, cont, _, _ = _measure_at(view.points_cad[idx], view.normal[idx],
                                                  r.frame, r.nominal, quiet)
            except InputError:
                continue
            b = {"label": r.block["label"], "nominal": dict(r.block["nominal"]),
                 "measured": _char_values(ch, r.frame, fit, cont),
                 "uncertainty": r.block.get("uncertainty")}
            _judge(b, opts.tolerances, True, opts.decision_rule)
            blocks[r.plane.label] = b
        per_fit[objective] = blocks
    rows, largest = [], None
    for r in stage.sections:
        label = r.plane.label
        base = per_fit[doc["chosen"]].get(label)
        if base is None or not base.get("deviation"):
            continue
        for key in _flat(base["deviation"]):
            cells = {}
            for objective in doc["objectives"]:
                b = per_fit[objective].get(label)
                dev = _flat(b["deviation"]).get(key) if b and b.get("deviation") else None
                d = (b or {}).get("decisions", {}).get(key, {})
                cells[objective] = {"value": dev, "U": d.get("U"),
                                    "verdict": (b or {}).get("verdicts", {}).get(key)}
            values = [c["value"] for c in cells.values() if c["value"] is not None]
            change = float(max(values) - min(values)) if values else 0.0
            row = {"characteristic": "section %s %s" % (label, key), "unit": _unit_of(key),
                   "by_fit": cells, "change": change, "airfoil": True}
            rows.append(row)
            u = _flat(base.get("uncertainty") or {}).get(key)
            if u:
                score = change / (COVERAGE_FACTOR * u)
                if largest is None or score > largest["change_over_U"]:
                    largest = {"characteristic": row["characteristic"], "change": change,
                               "unit": row["unit"], "change_over_U": float(score)}
    doc["rows"] = doc["rows"] + rows
    # issue 15 item 5 hook: what completes these rows' display names (chord method, edge
    # offsets; inspection.characteristic_names)
    doc["airfoil_definitions"] = {"chord_method": opts.chord_method,
                                  "edge_offsets_mm": [float(x) for x in opts.edge_offsets_mm]}
    doc["largest_change_airfoil"] = largest
    doc["largest_change_airfoil_rule"] = ("the airfoil row whose change across the fits is "
                                          "largest in units of its U (k = 2); none when no "
                                          "u is stated")
    by_fit = {}
    for objective, blocks in per_fit.items():
        verdicts = [v for b in blocks.values() for v in b.get("verdicts", {}).values()
                    if v in JUDGED]
        by_fit[objective] = decision_mod.combine(
            [decision_mod.FAIL if v == "not measured" else v for v in verdicts])
    doc["airfoil_verdict_by_fit"] = by_fit


def extras_of(table):
    """result.json's airfoil fields of a table the stage was attached to (none otherwise)."""
    stage = getattr(table, "airfoil", None)
    return {} if stage is None else stage.extras()


# ---------------------------------------------------------------- files

def csv_rows(blocks):
    rows = []
    for b in blocks:
        if b["nominal"] is None:
            continue
        nom = _flat(b["nominal"])
        mea = _flat(b["measured"]) if b["measured"] else {}
        dev = _flat(b["deviation"]) if b.get("deviation") else {}
        unc = _flat(b["uncertainty"]) if b.get("uncertainty") else {}
        # a toleranced key the CAD has no value for (a corner's radius) keeps its row
        for key in list(nom) + [k for k in b["verdicts"] if k not in nom]:
            t = b["tolerance"].get(key, {})
            d = (b.get("decisions") or {}).get(key, {})
            rows.append([b["label"], key, nom.get(key), mea.get(key), dev.get(key), unc.get(key),
                         t.get("lower"), t.get("upper"), d.get("U"), d.get("rule"),
                         b["verdicts"][key]])
    return rows


def write_csv(path, blocks):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(CSV_HEADER)
        for row in csv_rows(blocks):
            w.writerow(["" if v is None else ("%.9g" % v if isinstance(v, float) else v)
                        for v in row])


def run_airfoil(cad_path, out_dir, points_path=None, heights_pct=None, opts=None, seed=0,
                progress=None, nominal=None):
    """The `airfoil` command: DIR/airfoil.json and DIR/airfoil.csv, atomically. Without
    ``points_path`` the CAD's characteristics alone; with it the points are registered first
    (their frame is unknown, as for `register`) and measured per section."""
    import json
    from . import pipeline
    from . import sections as sections_mod
    from .checks import check_out_dir
    check_out_dir(out_dir)
    progress = progress or (lambda f, m: None)
    opts = opts or Options()
    heights = list(contracts.SECTION_HEIGHTS_PCT if heights_pct is None else heights_pct)
    if nominal is None:
        nominal = pipeline.load_nominal(cad_path)
    doc = {"cad_file": cad_path or "built-in demo blade", "points_file": points_path}
    result = table = None
    if points_path is not None:
        points = pipeline.load_points(points_path)
        result = pipeline.register(nominal, points, seed=seed,
                                   progress=lambda f, m: progress(0.6 * f, m),
                                   cad_source=cad_path or "the demo blade")
        table = sections_mod.section_table(result, nominal, heights_pct=heights)
        planes, span_axis = planes_of_table(table), table.span_axis
        doc.update(measured_to_cad=np.asarray(result.measured_to_cad).tolist(),
                   pose_uncertainty_mm=result.pose_uncertainty_mm, rms_mm=result.rms_mm)
    else:
        planes, span_axis = nominal_planes(nominal, heights), None
    check_sections(opts, planes)
    progress(0.7, "airfoil characteristics of %d sections" % len(planes))
    stage = run_stage(nominal, planes, opts, result, span_axis)
    doc.update(stage.extras())
    with pipeline.AtomicOutput(out_dir) as out:
        with open(out.path("airfoil.json"), "w") as fh:
            json.dump(doc, fh, indent=1, default=contracts.json_default)
        write_csv(out.path("airfoil.csv"), stage.blocks)
    progress(1.0, stage.verdict["summary"])
    return {"stage": stage, "result": result, "sections": table, "doc": doc}


LOT_CSV = "summary_airfoil.csv"


def write_lot_csv(out_dir, files):
    """A lot's DIR/summary_airfoil.csv: one row per blade, section and characteristic (the
    blade's airfoil.csv rows with the file first), from each blade's result.json, so that a
    lot can be charted; none when no blade has airfoil characteristics. ``files``: (stem,
    path) of the lot in order."""
    import json
    rows = []
    for stem, path in files:
        try:
            with open(os.path.join(out_dir, stem, "result.json")) as fh:
                blocks = json.load(fh).get("airfoil")
        except (OSError, ValueError):
            continue
        rows += [[os.path.basename(path)] + r for r in csv_rows(blocks or [])]
    if not rows:
        return None
    target = os.path.join(out_dir, LOT_CSV)
    with atomic_write(target, newline="") as fh:
        w = csv.writer(fh)
        w.writerow(("file",) + CSV_HEADER)
        for row in rows:
            w.writerow(["" if v is None else ("%.9g" % v if isinstance(v, float) else v)
                        for v in row])
    return target
