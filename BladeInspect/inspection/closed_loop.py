"""The `inspect` workflow (docs/contracts.md loop 1): the paper's whole automated loop on one blade.

1. blind section scan (measurement.scan.scan_to_dir: nothing about the pose is known yet);
2. registration of those points (reconstruction, PCA, SNR-weighted ICP) -> pose on the table;
3. paths planned from the CAD at its nominal section planes, brought into the machine by
   that pose (measurement.planning), and scanned;
4. ICP on all points from that pose; when the pose moved enough to matter for the planned
   points, one re-plan and re-scan of the nominal sections with the better pose;
5. Table 2 at the nominal sections (inspection.sections, with a CMM's columns when given), the
   verdict, and the report of the `report` command.

With --complete (paper 4.3) steps 3-4 are the whole blade rastered every --pitch mm instead
(measurement.complete) and one ICP on all points; Table 2 takes the raster points within 0.25 mm of
each nominal plane, and the `phase` column reads blind or complete.

Files in DIR: points.csv (table frame, with a `phase` column: blind or planned), plan.json,
scan.json (the blind scan's record, the planned passes, the simulator's truth), result.json
(with `sections` and `uncertainty_after_blind_mm`), deviations.csv, report.html/.pdf.

A rig failure (DeviceError), a cancel or Ctrl-C mid-loop leaves DIR a checkpoint instead:
points.csv up to the last completed blind section, planned section or raster pass, plan.json,
and scan.json marked incomplete with the loop's state under "inspection" (no result files).
``options.loop.resume`` (the CLI's --resume) continues it on a fresh rig and ends as the uninterrupted run would have:
measured data is kept section by section in DIR/.checkpoint while the loop runs
(inspection.checkpoint), every pass in between journaled (measurement.journal), so a kill -9 or a power cut
loses at most the pass in flight and --resume continues that folder; a simulated rig's noise
depends only on the pass number, which the checkpoint carries. See docs/maintainers.md ("The closed loop and its checkpoint") for the
checkpoint's fields.
"""

import json
import os
import time
from dataclasses import dataclass

import numpy as np

from ..core import contracts
from ..core import transforms as tf
from ..core.errors import Cancelled, DeviceError, InputError
from ..core import stats as stats_mod
from ..core.pointio import PointSet, write_points_csv
from ..measurement import scan as scan_mod
from ..measurement.complete import check_step, plan_complete, scan_complete
from ..measurement.planning import edge_radius_sigma, plan_sections
from ..rig.kinematics import RigKinematics
from . import airfoil_stage as airfoil_mod
from . import pipeline
from . import sections as sections_mod
from . import weighting
from .judging import fit_and_judge
from .planned_sections import PlannedSections
from .checkpoint import LIVE_FOLDER, Checkpoint, inspection_identity, save_plan, start_or_resume
from .checks import unmeasured_warning
from .report import write_report
from .result import RegistrationResult
from .run_options import RegisterOptions, RunOptions

# The planned points must lie within 0.01 mm of their nominal planes: a pose that moves them by
# more than a quarter of that budget (5 um, the fraction 1/400 of the 2 mm epsilon) is worth a
# re-plan. The standoff criterion epsilon itself is far looser than the plane budget.
REPLAN_FRACTION = 0.0025
# Below this fraction of planned points read, the part is not where the plan expected it.
MIN_READ_FRACTION = 0.9
# A resumed inspection registers its blind points again; they must land where they did
# (the same numbers give the same pose, up to rounding far below this).
RESUME_POSE_TOLERANCE_MM = 1e-6


def _no_progress(fraction, message):
    pass


def scan_plan(rig, plan, kinematics, progress=_no_progress, first_path=0, on_section=None):
    """Scan the planned paths on the rig from path ``first_path`` on (those before it were
    measured before an interruption). Returns table-frame points with their SNR, the planned
    section index, rotary angle and the planned point they answer (rows with no reading are
    left out) and a list of per-path records for scan.json. ``on_section(n_paths_done,
    rows, records)`` is called as the last path of each section has run, with that section's
    rows (xyz, snr, section, angle, point) and path records: the loop's checkpoint."""
    rows, records = [], []
    section_start = 0
    for i in range(first_path, len(plan.paths)):
        path = plan.paths[i]
        progress(i / max(len(plan.paths), 1), "planned scan: path %d of %d (section %g %%, "
                 "A=%.0f deg)" % (i + 1, len(plan.paths),
                                  plan.sections[path.section].height_pct, path.angle_deg))
        stage = plan.path_stage_xyz(path)
        readings = rig.scan_path(stage, path.angle_deg)
        d = np.asarray(readings.reading_mm, dtype=float)
        ok = np.isfinite(d)
        machine = kinematics.machine_point(np.asarray(readings.stage_xyz)[ok], d[ok])
        n = int(ok.sum())
        rows.append((kinematics.table_point(machine, path.angle_deg),
                     np.asarray(readings.snr, dtype=float)[ok], np.full(n, path.section),
                     np.full(n, path.angle_deg), path.points[ok]))
        expected = plan.sections[path.section].expected_standoff_mm[path.points]
        records.append({"section": path.section, "angle_deg": path.angle_deg,
                        "points": int(len(d)), "readings": n,
                        "max_standoff_error_mm": (float(np.max(np.abs(d[ok] - expected[ok])))
                                                  if ok.any() else None),
                        "pass_index": readings.meta.get("pass_index")})
        if i + 1 == len(plan.paths) or plan.paths[i + 1].section != path.section:
            if on_section is not None:
                on_section(i + 1, _stack_rows(rows[section_start:]), records[section_start:])
            section_start = len(rows)
    return _stack_rows(rows) + (records,)


def _stack_rows(rows):
    """(xyz, snr, section, angle, point) of several paths as one set of arrays."""
    if not rows:
        return (np.zeros((0, 3)), np.zeros(0), np.zeros(0, int), np.zeros(0), np.zeros(0, int))
    return (np.vstack([r[0] for r in rows]),) + tuple(np.concatenate([r[k] for r in rows])
                                                     for k in range(1, 5))


def _plan_agreement(plan, n_read, records, epsilon):
    """None when the planned scan read what the plan expected; else a one-line message. The
    plan puts every nominal point at the standoff: readings missing or far off it mean the
    part is not where the blind registration put it (a wrong PCA candidate, a moved part)."""
    worst = max((r["max_standoff_error_mm"] or 0.0) for r in records) if records else 0.0
    if n_read < MIN_READ_FRACTION * plan.n_points or worst > epsilon:
        return ("inspect: the planned scan does not find the blade where the blind scan's "
                "registration put it (%d of %d planned points read, standoff off by up to "
                "%.2f mm); the blind registration is wrong or the part moved"
                % (n_read, plan.n_points, worst))
    return None


def pose_change_mm(old_table_to_cad, new_table_to_cad, cad_points):
    """How far the table-frame positions of CAD points move between two poses (max, mm):
    what a plan made with the old pose gets wrong under the new one."""
    old = tf.apply_transform(tf.invert_transform(old_table_to_cad), cad_points)
    new = tf.apply_transform(tf.invert_transform(new_table_to_cad), cad_points)
    return float(np.max(np.linalg.norm(old - new, axis=1)))


def _result_of_all(run, phase, blind, blind_sections, later, points, fit, first):
    """points.csv's extra columns and the RegistrationResult of the blind rows followed by
    those measured after them (``later``: xyz, snr, section, angle_deg; tagged with the
    ``phase``'s name), ``points`` (xyz, snr) all of them, registered by ``fit``."""
    n_blind = len(blind.xyz)
    xyz, snr = points
    columns = {"section": np.concatenate([blind_sections, later[2]]),
               "angle_deg": np.concatenate([_blind_column(blind, "angle_deg", n_blind),
                                            later[3]]),
               "phase": np.array(["blind"] * n_blind + [phase.name] * len(later[0]))}
    result = _result_from_fit(run.nominal, _pointset(xyz, snr, columns, phase.source), fit,
                              first.coarse, dict(run.timing), list(first.warnings))
    result.cad_source = run.cad_label
    return columns, result


def _fit_all_points(run, phase, points, pose):
    """The fine ICP of every point (``points``: xyz, snr, rotary angle) from ``pose``,
    weighted by the run's weight model (inspection.weighting), its beams turned back by the
    run's kinematics. Returns (the fit, the weights' record)."""
    xyz, snr, angles = points
    weight_model, weights_record = weighting.weights_for_rows(
        xyz, snr, angles, run.register_options.weights, run.kinematics, phase.source)
    fit = pipeline.fine_register(xyz, snr, run.nominal, pose,
                                 progress=lambda f, m: run.progress(phase.fit_progress, m),
                                 weight_model=weight_model,
                                 systematic_mm=run.rig.sensor.accuracy)
    return fit, weights_record


def _add_airfoil(run, result, table, verdict):
    """The airfoil characteristics into the table and the verdict, when the run asks."""
    if run.options.airfoil is not None:
        airfoil_mod.attach(result, run.nominal, table, verdict, run.options.airfoil)


def _result_from_fit(nominal, pointset, fit, coarse, timing, warnings):
    """A RegistrationResult for points registered by a fine ICP from a known start, built the
    way pipeline.register builds its own."""
    points_cad = tf.apply_transform(fit.transform, pointset.xyz)
    dist = nominal.signed_distance(points_cad)
    inlier = np.asarray(fit.inlier, dtype=bool)
    rms = float(np.sqrt(np.mean(dist.distance[inlier] ** 2))) if inlier.any() else float("nan")
    covariance, statistical, unmeasured = pipeline.pose_summary(fit, nominal)
    if unmeasured:
        warnings = [w for w in warnings if w != unmeasured_warning(unmeasured)]
        warnings.append(unmeasured_warning(unmeasured))
    uncertainty, includes_rival = pipeline.uncertainty_with_rival(statistical, fit.transform,
                                                                  coarse, nominal.bbox_corners)
    return RegistrationResult(
        measured_to_cad=fit.transform, points_cad=points_cad, deviation=dist.distance,
        inlier=inlier, closest=dist.closest, normal=dist.normal, face=dist.face,
        snr=pointset.snr, columns=dict(pointset.columns), n_rows_skipped=0, rms_mm=rms,
        pose_covariance=covariance, center=fit.center,
        pose_uncertainty_mm=float(uncertainty),
        deviation_stats=stats_mod.deviation_statistics(dist.distance), coarse=coarse,
        timing_s=timing, warnings=warnings, source=pointset.source, cad_faces=nominal.cad_faces,
        pose_unmeasured=unmeasured, pose_uncertainty_statistical_mm=float(statistical),
        pose_uncertainty_includes_rival=includes_rival, icp_weights=fit.weights,
        inlier_cut=fit.cut)


def _sections_json(table, plan):
    """result.json `sections`: per nominal section its height, plane (CAD frame), the Table 2
    figures and the CMM's, and how many points were planned and measured there."""
    if all(sec.source == "section column" for sec in table.sections):
        # a section none of whose points could be planned or read has no row in the table
        by_label = {sec.label: sec for sec in table.sections}
        pairs = [(by_label.get(sections_mod.section_label(k)), planned)
                 for k, planned in enumerate(plan.sections)]
    else:
        pairs = list(zip(table.sections, plan.sections))
    # the plan's note on a section left wholly out is why it has no row (one line each)
    left_out = (getattr(plan, "info", None) or {}).get("unreachable") or {}
    notes = dict(zip([rec["height_pct"] for rec in left_out.get("sections", [])],
                     left_out.get("warnings", [])))
    out = []
    for sec, planned in pairs:
        doc = {} if sec is None else sec.to_json()
        doc["plane"] = {"point": planned.plane_point.tolist(),
                        "normal": planned.plane_normal.tolist()}
        doc["height_pct"] = planned.height_pct
        doc["n_planned"] = planned.n_points
        if sec is None or len(sec.point_index) == 0:
            doc["measured"] = False
            doc["reason"] = (notes.get(planned.height_pct) if not planned.n_points
                             else "section at %g %%: none of its %d planned points was read"
                             % (planned.height_pct, planned.n_points))
        out.append(doc)
    return out


def _pointset(xyz, snr, columns, source):
    return PointSet(xyz=np.asarray(xyz, dtype=float), snr=np.asarray(snr, dtype=float),
                    columns=columns, n_rows_skipped=0, source=source)


@dataclass
class _Inspection:
    """One inspection once opened: the nominal, the rig and its kinematics, the options
    (checked, RunOptions), those of its registrations, the CMM's table, the CAD's name in the
    result, the output and checkpoint, the timings, and the caller's progress, document
    writer and plan viewer."""
    nominal: object
    rig: object
    kinematics: RigKinematics
    options: RunOptions
    register_options: RegisterOptions
    cmm_data: object
    cad_label: str
    out: object
    checkpoint: Checkpoint
    timing: dict
    progress: object
    document: object
    on_plan: object


def run_inspect(cad_path, out_dir, options=None, rig=None, nominal=None, progress=None,
                document=None, on_plan=None):
    """The `inspect` command (see the module notes) with ``options`` (RunOptions; its
    ``loop`` the loop's own, LoopOptions). ``rig`` (an open Rig) and ``nominal`` replace
    opening them from ``options.loop.rig_spec`` and ``cad_path``: tests and the GUI pass their
    own. ``on_plan(plan)`` sees each plan before its paths are scanned (the GUI draws them).
    ``options.loop.resume``: continue the interrupted inspection in out_dir (same CAD, seed
    and options). ``options.allow_mismatch``: go on with a blind scan that does not fit the
    CAD, with the warning (pipeline.register). ``options.airfoil``: adds the airfoil
    characteristics (None: none). ``options.fit_choice``, ``options.measurement_model``: the
    fit and the decision, as for `report`.
    ``document``: the writer of inspection.FCStd (app.document.write_inspection_document, which
    this layer cannot import), or None for no document. Returns a summary dict.
    The result files appear in out_dir together, or none: on a
    DeviceError, a cancel or a KeyboardInterrupt out_dir holds the checkpoint instead
    (points.csv, plan.json, scan.json)."""
    progress = progress or _no_progress
    if not out_dir:
        raise InputError("--out: a folder is required")
    options, cmm_data = _checked(options or RunOptions())
    timing = {}
    t0 = time.perf_counter()
    if nominal is None:
        nominal = pipeline.load_nominal(cad_path, flip_faces=options.flip_faces)
    kinematics = (RigKinematics.from_json(options.rig_file) if options.rig_file
                  else RigKinematics())
    identity = inspection_identity(nominal, options, kinematics)
    opened = rig is None
    if opened:
        rig = scan_mod.open_rig(options.loop.rig_spec, nominal=nominal, seed=options.seed,
                                kinematics=kinematics)
    timing["load"] = time.perf_counter() - t0
    try:
        with pipeline.AtomicOutput(out_dir) as out:
            checkpoint = Checkpoint(os.path.join(os.path.abspath(out_dir), LIVE_FOLDER),
                                    out_dir, identity, rig, options.loop.resume)
            options = options.replace(
                scan_options=dict(checkpoint.identity["scan_options"] or {}))
            run = _Inspection(nominal, checkpoint.rig, kinematics, options,
                              options.register_options(cad_path or "the demo blade"), cmm_data,
                              cad_path or "built-in demo blade", out, checkpoint, timing,
                              progress, document, on_plan)
            try:
                summary = _loop(_phase_of(run), run)
            except (DeviceError, Cancelled, KeyboardInterrupt):
                # An inspection interrupted midway keeps what it measured.
                checkpoint.keep()
                checkpoint.discard()
                raise
            except BaseException:
                checkpoint.abandon()
                raise
        # Only once the result is in DIR: a kill before leaves the checkpoint to resume.
        checkpoint.discard()
    finally:
        if opened:
            rig.close()
    summary["out_dir"] = os.path.abspath(out_dir)
    return summary


def _checked(options):
    """(``options`` with the heights, tolerance, pitch and edge rule checked (InputError naming
    the flag) and the blind scan's epsilon set, the CMM's table or None)."""
    loop = options.loop
    heights = contracts.section_heights(options.section_heights)
    tolerance = contracts.profile_tolerance(options.tolerance)
    pitch = check_step(loop.pitch, "--pitch") if loop.complete else loop.pitch
    cmm_data = sections_mod.read_cmm(options.cmm) if options.cmm is not None else None
    sigma = edge_radius_sigma(loop.edge_radius_sigma_mm)
    scan_options = loop.scan_options
    if scan_options is not None or not loop.resume:
        scan_options = dict(scan_options or {})
        scan_options.setdefault("epsilon", loop.epsilon)
    checked = options.replace(section_heights=heights, tolerance=tolerance, pitch=pitch,
                              edge_radius_sigma_mm=sigma, scan_options=scan_options)
    return checked, cmm_data


def _phase_of(run):
    """The phase after the blind scan: the complete raster or the planned sections."""
    loop = run.options.loop
    if loop.complete:
        return _RasterPhase(run.nominal, run.rig, run.kinematics, loop.epsilon, loop.pitch)
    return _SectionsPhase(run.nominal, run.rig, run.kinematics, loop.epsilon, loop.pitch,
                          loop.edge_radius_sigma_mm)


def _blind_stage(run, scan_share, register_share):
    """The blind section scan into the checkpoint and its registration: nothing is known of
    the pose yet, so only what the sensor reads is used. A resumed inspection continues an
    interrupted blind scan (scan_to_dir's own resume) or reads the finished one back. The
    registration's weights have their beams turned back by the run's kinematics; the scan and
    the registration take ``scan_share`` and ``register_share`` of the progress.
    Returns (the blind scan's record, points, rig time spent, registration)."""
    nominal, checkpoint, timing, progress = run.nominal, run.checkpoint, run.timing, run.progress
    t0 = time.perf_counter()
    state = checkpoint.state
    if state is None or state["phase"] == "blind":
        progress(0.0, "blind section scan" + (" (resumed)" if state else ""))
        scan_mod.scan_to_dir(checkpoint.folder, run.rig, seed=run.options.seed,
                             kinematics=run.kinematics, resume=state is not None,
                             phase="blind", progress=lambda f, m: progress(scan_share * f, m),
                             on_record=checkpoint.mark_blind, **run.options.loop.scan_options)
        blind_rig_s = checkpoint.rig_s()
    else:
        blind_rig_s = float(state["blind_rig_s"])
    record = checkpoint.record()
    record["complete"] = True
    blind = checkpoint.rows("blind")
    if blind is None:
        raise InputError("inspect: the blind scan measured no point of the part")
    timing["blind_scan"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    first = pipeline.register(
        nominal, blind, seed=run.options.seed,
        progress=lambda f, m: progress(scan_share + register_share * f, m),
        options=run.register_options, rig_kinematics=run.kinematics)
    timing["register_blind"] = time.perf_counter() - t0
    if state is not None and state["phase"] != "blind":
        # The saved pose plans the rest; a registration that no longer lands there means the
        # points or the CAD are not those of the interrupted run.
        saved = np.asarray(state["blind_measured_to_cad"], dtype=float)
        moved = pose_change_mm(saved, first.measured_to_cad, nominal.bbox_corners)
        if moved > RESUME_POSE_TOLERANCE_MM:
            raise InputError("--resume: the blind points register %.3g mm away from where "
                             "they did before the interruption (points.csv or the CAD "
                             "changed)" % moved)
    return record, blind, blind_rig_s, first


# ---------------------------------------------------------------- the phases after the blind scan
# The loop (_loop) measures one phase after the blind scan: it plans from the blind pose, scans
# the plan unit by unit (a path's section, a raster pass), each completed unit appended to the
# checkpoint, registers everything, and may plan again from the better pose. A phase says how
# to plan, how to scan and judge its units, and what it adds to scan.json and result.json.

class _SectionsPhase:
    """Steps 3-4: the nominal sections planned from the CAD and scanned; one re-plan when the
    pose moved enough to matter for the planned points."""
    name = "planned"                # points.csv's phase column and the checkpoint's phase
    done_key = "paths_done"         # the checkpoint's count of units scanned
    scan_share, register_share = 0.25, 0.2
    attempts = 2
    plan_timing = ("plan", "replan")
    scan_timing = ("planned_scan", "replanned_scan")
    fit_timing = ("register_all", "register_all_again")
    fit_progress = 0.75
    source = "inspect: blind and planned scans"
    title = "BladeInspect inspection (CAD-planned sections)"

    def __init__(self, nominal, rig, kinematics, epsilon, pitch, edge_radius_sigma_mm=None):
        self.nominal, self.rig, self.kinematics, self.epsilon = nominal, rig, kinematics, epsilon
        self.edge_radius_sigma_mm = edge_radius_sigma_mm

    def fresh_state(self, pose):
        return {"phase": self.name, "attempt": 0, "plan_pose": pose.tolist(),
                "paths_done": 0, "sections_done": [], "paths": [], "replans": []}

    def started(self, state):
        # A re-plan drops the planned rows: points.csv goes back to its blind rows.
        state.update(blind_points_bytes=state.get("blind_points_bytes", state["points_bytes"]))

    def plan(self, pose, attempt, heights, span_axis, progress):
        progress(0.45 + 0.05 * attempt, "planning the nominal sections from the CAD")
        return plan_sections(self.nominal, pose, heights, self.rig.sensor, self.rig.limits,
                             span_axis=span_axis, kinematics=self.kinematics,
                             edge_radius_sigma_mm=self.edge_radius_sigma_mm)

    def scan(self, plan, attempt, first, on_unit, progress):
        scan_plan(self.rig, plan, self.kinematics,
                  lambda f, m: progress(0.5 + 0.1 * attempt + 0.1 * f, m), first_path=first,
                  on_section=lambda n, rows, records: on_unit(n, rows[:4], records))

    @staticmethod
    def record_unit(state, records):
        state["sections_done"] = state["sections_done"] + [int(records[-1]["section"])]
        state["paths"] = state["paths"] + records

    def agreement(self, plan, n_read, state):
        return _plan_agreement(plan, n_read, state["paths"], self.epsilon)

    def again(self, state, plan, pose, fit, n_read, attempt, checkpoint):
        """Whether to plan again from the pose ``fit`` found (the state made ready for it)."""
        targets = np.vstack([s.target_cad for s in plan.sections])
        moved = pose_change_mm(pose, fit.transform, targets)
        state["replans"] = state["replans"] + [
            {"pose_change_mm": moved, "threshold_mm": REPLAN_FRACTION * self.epsilon,
             "n_planned": plan.n_points, "n_measured": n_read}]
        if moved <= REPLAN_FRACTION * self.epsilon or attempt == self.attempts - 1:
            return False
        # The re-plan measures the nominal sections again from the better pose; the first
        # pass's rows are replaced, as the uninterrupted loop replaces them.
        checkpoint.truncate_points(state["blind_points_bytes"])
        os.remove(checkpoint.path("plan.json"))
        state.update(attempt=attempt + 1, plan_pose=np.asarray(fit.transform).tolist(),
                     paths_done=0, sections_done=[], paths=[],
                     points_bytes=state["blind_points_bytes"])
        return True

    @staticmethod
    def sections_json(table, plan):
        return _sections_json(table, plan)

    def scan_json(self, plan, n_read, state, rig_s, timing):
        return {"points": n_read, "paths": state["paths"], "rig_s": rig_s}

    @staticmethod
    def add_to_record(record, state):
        record["replans"] = state["replans"]

    def result_json(self, plan, n_read, state, rig_s, timing):
        out = {"replans": state["replans"], "n_points_by_phase": {"blind": None,
                                                                   self.name: n_read},
               "edge_density": plan.info.get("edge_density")}
        if plan.info.get("unreachable"):
            out["unreachable_points"] = plan.info["unreachable"]
        return out

    def summary(self, plan, state, rig_s, timing):
        return {"replans": state["replans"]}


class _RasterPhase:
    """`inspect --complete` (paper 4.3): the whole blade rastered every ``pitch`` mm
    (measurement.complete) from the blind pose; Table 2 at the nominal planes takes the raster
    points within its band of each."""
    name = "complete"
    done_key = "passes_done"
    scan_share, register_share = 0.15, 0.1
    attempts = 1
    plan_timing = ("plan",)
    scan_timing = ("complete_scan",)
    fit_timing = ("register_all",)
    fit_progress = 0.65
    source = "inspect --complete: blind and complete scans"

    def __init__(self, nominal, rig, kinematics, epsilon, pitch):
        self.nominal, self.rig, self.kinematics, self.epsilon = nominal, rig, kinematics, epsilon
        self.pitch = pitch
        self.title = "BladeInspect inspection (complete scan, pitch %g mm)" % pitch

    def fresh_state(self, pose):
        return {"phase": self.name, "plan_pose": pose.tolist(), "passes_done": 0, "passes": []}

    def started(self, state):
        pass

    def plan(self, pose, attempt, heights, span_axis, progress):
        progress(0.25, "planning the complete raster from the CAD")
        return plan_complete(self.nominal, pose, self.rig.sensor, self.rig.limits,
                             pitch=self.pitch, kinematics=self.kinematics)

    def scan(self, plan, attempt, first, on_unit, progress):
        scan_complete(self.rig, plan, self.kinematics, lambda f, m: progress(0.3 + 0.3 * f, m),
                      first_pass=first,
                      on_pass=lambda n, rows, record: on_unit(n, rows, [record]))

    @staticmethod
    def record_unit(state, records):
        state["passes"] = state["passes"] + records

    def agreement(self, plan, n_read, state):
        worst = (max((r["max_standoff_error_mm"] or 0.0) for r in state["passes"]) if n_read
                 else np.inf)
        if n_read < MIN_READ_FRACTION * plan.n_points or worst > self.epsilon:
            return ("inspect --complete: the raster does not find the blade where the "
                    "blind scan's registration put it (%d of %d planned points read, "
                    "standoff off by up to %.2f mm)" % (n_read, plan.n_points, worst))
        return None

    def again(self, state, plan, pose, fit, n_read, attempt, checkpoint):
        return False

    @staticmethod
    def sections_json(table, plan):
        out = []
        for sec in table.sections:
            doc = dict(sec.to_json(), height_pct=sec.height_pct,
                       plane={"point": sec.origin.tolist(), "normal": sec.normal.tolist()})
            if len(sec.point_index) == 0:
                doc.update(measured=False, reason="section at %g %%: no raster point lies "
                           "within %g mm of its plane" % (sec.height_pct, table.band))
            out.append(doc)
        return out

    def scan_json(self, plan, n_read, state, rig_s, timing):
        return {"points": n_read, "planned_points": plan.n_points,
                "pitch_mm": plan.pitch_mm, "angles_deg": plan.angles_deg.tolist(),
                "passes": state["passes"], "rig_s": rig_s,
                "simulated_s": timing["complete_scan"],
                "sensor_rate_s": n_read / float(self.rig.sensor.rate_hz)}

    @staticmethod
    def add_to_record(record, state):
        pass

    def result_json(self, plan, n_read, state, rig_s, timing):
        out = {"n_points_by_phase": {"blind": None, self.name: n_read},
               "complete": {"pitch_mm": plan.pitch_mm, "rig_s": rig_s,
                            "simulated_s": timing["complete_scan"]}}
        if plan.info.get("unreachable"):
            out["unreachable_points"] = plan.info["unreachable"]
        return out

    def summary(self, plan, state, rig_s, timing):
        return {"complete_rig_s": rig_s, "complete_simulated_s": timing["complete_scan"]}


def _loop(phase, run):
    """The inspection ``run`` after opening: the blind stage, then ``phase`` planned from its
    pose, scanned unit by unit into the checkpoint, ICP on every point (and the phase's
    re-plan), Table 2 at the nominal sections, the verdict and the result files in its
    output."""
    nominal, rig, checkpoint, timing, progress = (run.nominal, run.rig, run.checkpoint,
                                                  run.timing, run.progress)
    out, tolerance = run.out, run.options.tolerance
    # 1-2. blind section scan and its registration
    resumed = checkpoint.state if (checkpoint.state or {}).get("phase") == phase.name else None
    scan_record, blind, blind_rig_s, first = _blind_stage(run, phase.scan_share,
                                                          phase.register_share)
    n_blind = len(blind.xyz)
    blind_sections = _blind_column(blind, "section", n_blind)
    # The units measured after the blind scan are numbered after its sections, so a `report`
    # of points.csv by its section column keeps them apart.
    first_unit = int(np.nanmax(blind_sections) + 1) if np.isfinite(blind_sections).any() \
        else 0
    state = start_or_resume(checkpoint, rig, resumed, phase.fresh_state(first.measured_to_cad))
    state.update(blind_measured_to_cad=np.asarray(first.measured_to_cad).tolist(),
                 blind_points=n_blind, blind_rig_s=blind_rig_s)
    phase.started(state)
    checkpoint.save(state, scan_record)

    # 3-4. plan, scan, ICP on everything; again from the better pose if the phase says so
    span_axis, _ = sections_mod.span_axis_of(nominal)
    for attempt in range(int(state.get("attempt", 0)), phase.attempts):
        pose = np.asarray(state["plan_pose"], dtype=float)
        t0 = time.perf_counter()
        plan = phase.plan(pose, attempt, run.options.section_heights, span_axis, progress)
        timing[phase.plan_timing[attempt]] = time.perf_counter() - t0
        if run.on_plan is not None:
            run.on_plan(plan)
        save_plan(plan, checkpoint)
        # Units measured before an interruption are read back; this run's are kept too.
        earlier = checkpoint.rows(phase.name) if state[phase.done_key] else None
        session = []

        def unit_done(n_units, rows, records):
            xyz, snr, unit, angle = rows
            session.append((xyz, snr, first_unit + unit, angle))
            checkpoint.append_rows(*session[-1], phase.name)
            state[phase.done_key] = n_units
            phase.record_unit(state, records)
            state["points_bytes"] = checkpoint.points_bytes()
            state["pass_index"] = getattr(rig, "pass_index", None)
            checkpoint.save(state, scan_record)

        t0 = time.perf_counter()
        phase.scan(plan, attempt, int(state[phase.done_key]), unit_done, progress)
        timing[phase.scan_timing[attempt]] = time.perf_counter() - t0
        measured = _measured_rows(earlier, session)
        n_measured = len(measured[0])
        agreement = phase.agreement(plan, n_measured, state)
        if agreement:
            raise InputError(agreement)
        t0 = time.perf_counter()
        xyz = np.vstack([blind.xyz, measured[0]])
        snr = np.concatenate([blind.snr, measured[1]])
        angles = np.concatenate([_blind_column(blind, "angle_deg", n_blind), measured[3]])
        fit, weights_record = _fit_all_points(run, phase, (xyz, snr, angles), pose)
        timing[phase.fit_timing[attempt]] = time.perf_counter() - t0
        if not phase.again(state, plan, pose, fit, n_measured, attempt, checkpoint):
            break
        checkpoint.save(state, scan_record)
    rig_s = checkpoint.rig_s()

    # 5. results at the nominal sections
    t0 = time.perf_counter()
    columns, result = _result_of_all(run, phase, blind, blind_sections, measured, (xyz, snr),
                                     fit, first)
    result.weights = weights_record
    # the plan's edges a sensor spot averages away are said, not hidden
    plan_info = getattr(plan, "info", None) or {}
    edge_rule = plan_info.get("edge_density")
    if edge_rule:
        result.planning_notes += edge_rule["warnings"]
    # so are the planned points the rig could not reach, left out of the plan
    if plan_info.get("unreachable"):
        result.planning_notes += plan_info["unreachable"]["warnings"]
    result.warnings += result.planning_notes
    # planned_rows drops the section column (raster lines are not the nominal planes), so the
    # table takes the points within its band of each plane.
    progress(0.8, "section table and verdict")
    table, verdict = _judge_after_blind(run, result, n_blind, n_measured, span_axis)
    if run.options.airfoil is not None:
        progress(0.82, "airfoil characteristics")
    _add_airfoil(run, result, table, verdict)
    timing["sections"] = time.perf_counter() - t0

    progress(0.85, "writing the report")
    t0 = time.perf_counter()
    write_points_csv(out.path("points.csv"), xyz, {"snr": snr, **columns})
    plan.to_json(out.path("plan.json"))
    scan_record["phases"] = {
        "blind": {"points": n_blind, "summary": dict(scan_record), "rig_s": blind_rig_s},
        phase.name: phase.scan_json(plan, n_measured, state, rig_s - blind_rig_s, timing)}
    phase.add_to_record(scan_record, state)
    with open(out.path("scan.json"), "w") as fh:
        json.dump(scan_record, fh, indent=1, default=contracts.json_default)
    files = write_report(out, result, nominal, table, verdict, tolerance, title=phase.title)
    if run.document:
        run.document(out.path("inspection.FCStd"), nominal, result, table, tolerance=tolerance)
    timing["write"] = time.perf_counter() - t0
    result.timing_s = timing
    extra = {"sections": phase.sections_json(table, plan), "section_table": table.to_json(),
             "verdict": verdict, "tolerance_mm": tolerance,
             "uncertainty_after_blind_mm": first.pose_uncertainty_mm,
             "blind_measured_to_cad": np.asarray(first.measured_to_cad).tolist()}
    extra.update(phase.result_json(plan, n_measured, state, rig_s - blind_rig_s, timing))
    extra["n_points_by_phase"]["blind"] = n_blind
    extra["rig_time_s"] = rig_s
    extra.update(airfoil_mod.extras_of(table))
    pipeline.write_register_outputs(None, result, extra=extra, output=out)
    progress(1.0, verdict["summary"])
    summary = {"result": result, "blind_result": first, "plan": plan, "sections": table,
               "verdict": verdict}
    summary.update(phase.summary(plan, state, rig_s - blind_rig_s, timing))
    summary.update(files=files, uncertainty_after_blind_mm=first.pose_uncertainty_mm,
                   pose_uncertainty_mm=result.pose_uncertainty_mm)
    return summary


def _measured_rows(earlier, session):
    """(xyz, snr, section, angle_deg) of the rows measured after the blind scan: those of
    earlier runs (a PointSet read back from the checkpoint, or None) then this run's (tuples
    of arrays). The checkpoint holds them at full precision, so both are the same numbers."""
    parts = list(session)
    if earlier is not None:
        parts.insert(0, (earlier.xyz, earlier.snr, earlier.columns["section"],
                         earlier.columns["angle_deg"]))
    if not parts:
        return np.zeros((0, 3)), np.zeros(0), np.zeros(0), np.zeros(0)
    return (np.vstack([p[0] for p in parts]),) + tuple(
        np.concatenate([np.asarray(p[k], dtype=float) for p in parts]) for k in (1, 2, 3))


def _judge_after_blind(run, result, n_blind, n_rows, span_axis):
    """Table 2 from the rows measured after the blind scan (the nominal sections are theirs),
    indexed back into the whole result, and the verdict on every point; the result moved to
    the pose of the run's fit first (inspection.fitting), its fit sensitivity recorded."""
    nominal, options = run.nominal, run.options
    planned = PlannedSections(tuple(options.section_heights), n_blind, n_rows)

    def planned_table(fitted):
        return planned.table(fitted, nominal, span_axis=span_axis, cmm=run.cmm_data)
    return fit_and_judge(result, nominal, options.fit_choice, options.tolerance, planned_table,
                         measurement_model=options.measurement_model)


def _blind_column(pointset, name, n):
    values = pointset.columns.get(name)
    if values is None:
        return np.full(n, np.nan)
    return np.asarray(values, dtype=float)
