"""The airfoil stage: per section plane the nominal characteristics from the CAD's
exact cut, the measured ones from that section's registered points, their deviation, standard
uncertainty, tolerance and verdict, and the blade's lean and bow; its options, its section
planes, the nominal cuts it remembers, and its files (airfoil.json, airfoil.csv, a lot's
summary_airfoil.csv). The numerics are core.airfoil's, the definitions docs/user-guide.md; the
measuring of a section's points is airfoil_measure's, their uncertainty airfoil_uncertainty's
(or an uncertainty task file's, airfoil_task), the verdicts airfoil_verdicts'.
"""


import csv
import dataclasses
import hashlib
import json
import os
from dataclasses import dataclass, field

import numpy as np

from ..core import airfoil as kernel
from ..core import background
from ..core import contracts
from ..core import decision as decision_mod
from ..core.atomic_file import atomic_write
from ..core.errors import InputError
from ..measurement.planning import blade_faces
from . import airfoil_frame, airfoil_task
from . import uncertainty as uncertainty_mod
from .airfoil_measure import SectionMeasurement, measure_at, section_points
from . import airfoil_uncertainty
from .airfoil_uncertainty import refit_uncertainty
from .airfoil_values import (CHARACTERISTICS, LISTS, base_name, char_values, flat,
                             ordered_notes, section_summary, withheld_values)
from .airfoil_verdicts import (COVERAGE_FACTOR, NO_U_RULE, add_to_sensitivity,
                               check_sections, judge, stage_verdict)


DEFAULT_DRAWS = 12
# Fewer measured points than this in a section: no measured characteristics (a profile needs
# both edges and both sides).
MIN_SECTION_POINTS = 60
# A section whose measured points leave a stretch of the nominal profile longer than this
# share of its perimeter without a point is refused: the profile fitted to them would close
# the stretch by a guess (a scan of the blade alone where the cut is closed by a hub, or of one
# side only), so every characteristic across it would be measured against another loop.
MAX_COVERAGE_GAP = 0.15
CSV_HEADER = ("section", "characteristic", "nominal", "measured", "deviation", "uncertainty",
              "lower", "upper", "U_k2", "decision_rule", "verdict")


# Which end of the nominal profile is the LE when the CAD's faces do not name it:
# "engine-axis" -- the flow runs along +engine axis, so the LE is the upstream end (the end
# furthest along -engine axis in the plane); "larger-radius" -- the blunter end (the kernel's
# rule without a direction; it picks Rotor 67's TE at 10 % span, whose radius is the larger).
# (the kernel's AirfoilDefinition.LE rules, the stage's default first)
LE_RULE_TEXT = {"engine-axis": "the upstream end: the flow runs along +engine axis",
                "larger-radius": "the end with the larger edge radius (the engine axis when "
                                 "the radii agree within their uncertainty)"}
LE_RULES = tuple(LE_RULE_TEXT)
assert set(LE_RULES) == set(kernel.LE_RULES)
# The stage's definition unless one is given: the kernel's, the LE upstream.
DEFAULT_DEFINITION = kernel.AirfoilDefinition(le_rule="engine-axis")


@dataclass
class Options:
    engine_axis: tuple = (1.0, 0.0, 0.0)
    # what each characteristic means (chord method, edge offsets, LE rule, edge zone,
    # metal-angle window): one value, whose digest keys the nominal cuts and task files
    definition: kernel.AirfoilDefinition = DEFAULT_DEFINITION
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
    decision_rule: str = "iso14253"  # core.decision's rule; report/inspect pass theirs
    # task-specific uncertainty (inspection.airfoil_task): a task file's path (reused when
    # it exists and matches, made there when absent) or an airfoil_task.TaskUncertainty;
    # None: every section's u from its own re-fit (``draws``)
    task_uncertainty: object = None
    task_draws: int = 48            # re-fits when a task is made (airfoil_task)
    # the `airfoil` command's fit of its measured points (inspection.fitting.FitChoice; None:
    # the ICP's pose); report, inspect and batch fit before the stage, by their own choice
    fit_choice: object = None


@dataclass
class Tolerance:
    characteristic: str          # a field name, or name[i] for element i of a list field
    section: str                 # a section label or "all"
    lower: float                 # limits on the deviation (measured - nominal); None = open
    upper: float
    nominal: float = None        # overrides the CAD's value when given
    row: int = 0


# The plane frame's x axis is the engine axis (cad/airfoil_sections.py): upstream is -x.
UPSTREAM_2D = (-1.0, 0.0)


# ---------------------------------------------------------------- options from text

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
        base = base_name(name)
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
    definition = {}
    if uncertainty_task is not None:
        airfoil_task.check_file(uncertainty_task)   # an existing file must be a task file
        opts.task_uncertainty = uncertainty_task
    if le_rule is not None:
        if le_rule not in LE_RULES:
            raise InputError("--le-rule: %r is not one of %s" % (le_rule, ", ".join(LE_RULES)))
        definition["le_rule"] = le_rule
    if engine_axis is not None:
        opts.engine_axis = parse_engine_axis(engine_axis)
    if characteristics is not None:
        opts.tolerances = read_characteristics(characteristics)
        opts.characteristics_file = characteristics
    if chord_method is not None:
        if chord_method not in kernel.CHORD_METHODS:
            raise InputError("--chord-method: %r is not one of %s"
                             % (chord_method, ", ".join(kernel.CHORD_METHODS)))
        definition["chord_method"] = chord_method
    if edge_offsets is not None:
        definition["edge_offsets_mm"] = parse_offsets(edge_offsets)
    opts.definition = dataclasses.replace(opts.definition, **definition)
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
    # the CAD's exact cut in this plane when the section table made it (cad.sections.exact_cut
    # at the airfoil spacing) and its points' faces; None: the stage cuts the CAD itself
    cut_polylines: list = None
    cut_faces: list = None


def planes_of_table(table):
    out = []
    for s in table.sections:
        hint = s.profile.le if (s.profile is not None
                                and s.profile.le_rule == "CAD face roles") else None
        polylines = s.profile.polylines if s.profile is not None else None
        faces = s.profile.faces if s.profile is not None else None
        out.append(Plane(s.label, s.origin, s.normal, s.height_pct, hint, s.point_index,
                         polylines or None, faces if polylines else None))
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
    task_u: tuple = None             # (how, why) under a task uncertainty (airfoil_task)


# The nominal's characteristics of a cut, remembered by the cut's points and the arguments
# (NOMINAL_CACHE_SIZE cuts): a process that measures blade after blade of one CAD (a batch
# worker keeps its nominal, the workbench re-runs a section) cuts the same profiles and need
# not read them again -- the kernel is deterministic, so the same points and arguments give
# the same characteristics. A one-blade run (report, inspect) gains nothing from it.
NOMINAL_CACHE_SIZE = 16
_NOMINAL_CACHE = {}


def nominal_characteristics(xy, definition, le_hint, le_upstream, states=None):
    """kernel.characteristics of a nominal cut (engine axis +x of its frame), remembered
    (above); each call has its own Characteristics (its own warnings list), the numbers and
    the profile shared. ``states``: a dict of computed cuts by the same key
    (kernel.characteristics_state; an uncertainty task file keeps its nominal cuts so): a cut
    found there is read back instead of computed (the same bits), one computed is added."""
    xy = np.ascontiguousarray(xy, dtype=float)
    h = hashlib.sha256(xy.tobytes())
    h.update(repr((xy.shape, definition.digest(),
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
        ch = kernel.characteristics(xy, engine_axis=(1.0, 0.0), le_hint=le_hint,
                                    le_upstream=le_upstream, definition=definition)
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


def coverage_gap(pts, loop):
    """(longest stretch of the closed ``loop`` (N, 2) with none of ``pts`` (M, 2) nearest to
    it, the loop's perimeter), mm."""
    from scipy.spatial import cKDTree
    seg = np.linalg.norm(np.diff(np.vstack([loop, loop[:1]]), axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    perimeter = float(arc[-1])
    if len(pts) == 0:
        return perimeter, perimeter
    at = np.unique(arc[cKDTree(loop).query(pts)[1]])
    gaps = np.diff(np.concatenate([at, [at[0] + perimeter]]))
    return float(gaps.max()), perimeter


def _blade_faces(nominal):
    """(indices of the faces that make the airfoil, {index: role} of the others)."""
    blade = set(blade_faces(nominal))
    roles = {int(i): name for name, idx in (getattr(nominal, "roles", None) or {}).items()
             for i in idx if int(i) not in blade}
    return blade, roles


def _refused(plane, reason, nominal_values=None, le_rule=None):
    """A section the stage will not measure: its block says why, the run goes on."""
    sr = SectionResult(plane=plane, frame=None, nominal=None,
                       notes=["section refused: %s" % reason])
    sr.block = {"label": plane.label, "height_pct": plane.height_pct, "le_rule": le_rule,
                "nominal": nominal_values, "measured": None, "deviation": None,
                "uncertainty": None, "refused": reason}
    return sr


def _section(nominal, plane, opts, result, rng, counted=None, task=None, take_up=None):
    from ..cad.airfoil_sections import NotAirfoilSection, airfoil_section
    background.tick()    # a GUI's event loop turns between the sections
    blade, roles = _blade_faces(nominal)
    try:
        xy, frame = airfoil_section(nominal.shape, plane.origin, plane.normal, opts.engine_axis,
                                    polylines=plane.cut_polylines, faces=plane.cut_faces,
                                    blade_faces=blade, face_roles=roles)
        hint = None if plane.le_hint_3d is None else frame.to_2d(plane.le_hint_3d)[0]
        upstream = UPSTREAM_2D if opts.definition.le_rule == "engine-axis" else None
        # The kernel's work (numpy and scipy only) runs beside the GUI's event loop; the cut
        # above, an OpenCASCADE call, stays in this thread.
        nom = background.run(lambda: nominal_characteristics(
            xy, opts.definition, hint, upstream, None if task is None else task.nominal))
    except NotAirfoilSection as exc:
        return _refused(plane, str(exc))
    except InputError as exc:
        # A plane past the blade's end, or a profile the kernel cannot read: said, not fatal.
        sr = SectionResult(plane=plane, frame=None, nominal=None, notes=["nominal: %s" % exc])
        sr.block = {"label": plane.label, "height_pct": plane.height_pct, "le_rule": None,
                    "nominal": None, "measured": None, "deviation": None, "uncertainty": None,
                    "withheld": {}}
        return sr
    sr = SectionResult(plane=plane, frame=frame, nominal=nom)
    sr.notes += ["nominal: %s" % w for w in nom.warnings]
    nominal_values = char_values(nom, frame)
    block = {"label": plane.label, "height_pct": plane.height_pct,
             "le_rule": nom.le_rule, "nominal": nominal_values, "measured": None,
             "deviation": None, "uncertainty": None, "withheld": {}}
    sr.block = block
    if result is None:
        return sr
    idx = section_points(plane, counted)
    if len(idx) < MIN_SECTION_POINTS:
        sr.notes.append("measured: %d points in the section, %d needed"
                        % (len(idx), MIN_SECTION_POINTS))
        return sr
    gap = coverage_gap(frame.to_2d(result.points_cad[idx]), xy)
    if gap[0] > MAX_COVERAGE_GAP * gap[1]:
        refused = _refused(plane, "the measured points cover only part of the profile: none "
                           "along %.1f mm of its %.1f mm perimeter (%.0f %%, at most %.0f %% "
                           "allowed)" % (gap[0], gap[1], 100.0 * gap[0] / gap[1],
                                         100.0 * MAX_COVERAGE_GAP),
                           nominal_values, nom.le_rule)
        refused.frame, refused.nominal = frame, nom
        refused.notes = sr.notes + refused.notes
        return refused
    try:
        ch, fit, cont, ordered, noise = background.run(lambda: measure_at(
            result.points_cad[idx], result.normal[idx], frame, nom, opts))
    except InputError as exc:
        sr.notes.append("measured: %s" % exc)
        return sr
    sr.measured, sr.fit, sr.contour, sr.points_2d, sr.noise_mm = ch, fit, cont, ordered, noise
    sr.notes += ["measured: %s" % w for w in ch.warnings]
    block["withheld"] = withheld_values(ch, noise)
    measured_values = char_values(ch, frame, fit, cont)
    measured_values["noise_mm"] = noise
    measured_values["n_points"] = int(len(idx))
    measured_values["zones"] = cont
    block["measured"] = measured_values
    measurement = SectionMeasurement(result, idx, frame, nom, ch, fit, noise, measured_values)
    if task is not None:    # task-specific uncertainty (inspection.airfoil_task)
        sr.task_u = background.run(
            lambda: airfoil_task.section_uncertainty(task, sr, measurement, opts, rng))
    elif opts.draws:
        block["uncertainty"] = background.run(
            lambda: refit_uncertainty(measurement, opts, rng))
        if take_up is not None and block["uncertainty"] is not None:
            background.run(lambda: _add_size_take_up(sr, measurement, take_up, opts))
    return sr


def _add_size_take_up(sr, measurement, take_up, opts):
    """The plain rigid pose's take-up of the part's size as a systematic term of the section's
    U (airfoil_uncertainty.size_take_up_term), stated in ``uncertainty_size_take_up`` and a
    note."""
    term = airfoil_uncertainty.size_take_up_term(measurement, take_up, opts)
    if term is None:
        sr.notes.append("measured: the pose's take-up of the part's size could not be "
                        "measured at the size fit's pose; U does not include it")
        return
    block = sr.block
    block["uncertainty"], block["uncertainty_size_take_up"], grown = \
        airfoil_uncertainty.add_take_up(block["uncertainty"], term, COVERAGE_FACTOR)
    if grown:   # a part made to size takes nothing up: no note
        sr.notes.append(
            "measured: the least-squares pose takes up the part's size (estimated %+.4f mm, "
            "U %s) by moving the points up to %.4f mm; U holds that take-up as a systematic "
            "term (uncertainty_size_take_up), which widens it by more than half for %s "
            "(--fit least-squares-size keeps size out of the pose)"
            % (take_up.size_mm, "n/a" if take_up.U_mm is None else "%.5f mm" % take_up.U_mm,
               take_up.pose_motion_mm, ", ".join(grown)))


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


# ---------------------------------------------------------------- the stage

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
        task = airfoil_task.open_task(
            opts.task_uncertainty, airfoil_task.task_key(nominal, opts, result),
            opts, result)
    take_up = None if opts.draws == 0 or task is not None else \
        airfoil_uncertainty.size_take_up_model(result, nominal)
    results = [_section(nominal, p, opts, result, rng, counted, task, take_up) for p in planes]
    frame = airfoil_frame.fit_frame(result, counted, span_axis)
    if frame is not None:
        rates = airfoil_frame.twist_rates(results, span_axis)
        for r, rate in zip(results, rates):
            if r.measured is not None:
                airfoil_frame.add_fit_frame(r, frame, rate, span_axis)
    if task is not None and not task.made:
        task.finish()    # written (atomically) to its file, or kept in memory
    if opts.decision_rule not in decision_mod.RULES:
        raise InputError("--decision-rule: unknown rule '%s' (use %s)"
                         % (opts.decision_rule, ", ".join(decision_mod.RULES)))
    failed, unproven = [], []
    for r in results:
        f, n = judge(r.block, opts.tolerances, result is not None, opts.decision_rule)
        failed += ["section %s: %s" % (r.plane.label, k) for k in f]
        unproven += ["section %s: %s" % (r.plane.label, k) for k in n]
        r.block["notes"] = ordered_notes(r.notes)
        r.block["summary"] = section_summary(r.block)
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
                "chord_method": opts.definition.chord_method,
                "le_rule": opts.definition.le_rule,
                "le_rule_meaning": LE_RULE_TEXT[opts.definition.le_rule] + " (unless the "
                                   "CAD's faces name the LE: the block's le_rule says "
                                   "\"given\")",
                "edge_offsets_mm": list(map(float, opts.definition.edge_offsets_mm)),
                "definition": opts.definition.as_dict(),
                "definition_digest": opts.definition.digest(),
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
    if take_up is not None:
        settings["size_take_up"] = {
            "size_mm": take_up.size_mm, "U_mm": take_up.U_mm,
            "pose_motion_mm": take_up.pose_motion_mm, "fit_seconds": take_up.seconds,
            "rule": "plain least-squares pose: each characteristic measured again at the "
                    "least-squares-size fit's pose; |difference| x (1 + U/|size|, at most 2) "
                    "added to its expanded U (uncertainty_size_take_up)"}
    if task is not None:
        settings.update(airfoil_task.settings_of(
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
    if getattr(result, "fit_sensitivity", None):   # the airfoil rows
        add_to_sensitivity(result.fit_sensitivity, stage, result, opts)
    return stage


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
        nom = flat(b["nominal"])
        mea = flat(b["measured"]) if b["measured"] else {}
        dev = flat(b["deviation"]) if b.get("deviation") else {}
        unc = flat(b["uncertainty"]) if b.get("uncertainty") else {}
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
    (their frame is unknown, as for `register`), moved to the pose of ``opts.fit_choice``
    and measured per section."""
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
                                   cad_source=cad_path or "the demo blade",
                                   fit_choice=opts.fit_choice)
        table = sections_mod.section_table(result, nominal, heights_pct=heights)
        planes, span_axis = planes_of_table(table), table.span_axis
        doc.update(measured_to_cad=np.asarray(result.measured_to_cad).tolist(),
                   pose_uncertainty_mm=result.pose_uncertainty_mm, rms_mm=result.rms_mm,
                   fit=getattr(result, "fit", None))
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
