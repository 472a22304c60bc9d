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
and scan.json marked incomplete with the loop's state under "inspection" (no result files). ``resume=True`` (the
CLI's --resume) continues it on a fresh rig and ends as the uninterrupted run would have:
measured data is kept section by section in DIR/.checkpoint while the loop runs
(_Checkpoint), every pass in between journaled (measurement.journal), so a kill -9 or a power cut
loses at most the pass in flight and --resume continues that folder; a simulated rig's noise
depends only on the pass number, which the checkpoint carries. See docs/internals.md for the
checkpoint's fields.
"""

import json
import os
import shutil
import time

import numpy as np

from ..core import contracts
from ..core import transforms as tf
from ..core.errors import Cancelled, DeviceError, InputError
from ..core.pointio import PointSet, read_points, write_points_csv
from ..measurement.journal import JOURNAL_FILE, JournaledRig
from ..measurement.scan import POINTS_FILE, RECORD_FILE, check_same_rig, write_record
from . import airfoil as airfoil_mod

EPSILON_MM = 2.0
# The planned points must lie within 0.01 mm of their nominal planes: a pose that moves them by
# more than a quarter of that budget (5 um, the fraction 1/400 of the 2 mm epsilon) is worth a
# re-plan. The standoff criterion epsilon itself is far looser than the plane budget.
REPLAN_FRACTION = 0.0025
# Below this fraction of planned points read, the part is not where the plan expected it.
MIN_READ_FRACTION = 0.9
# A resumed inspection registers its blind points again; they must land where they did
# (the same numbers give the same pose, up to rounding far below this).
RESUME_POSE_TOLERANCE_MM = 1e-6
# While an inspection is unfinished, scan.json holds the loop's state under this key.
CHECKPOINT = "inspection"
# What a checkpoint is made of; scan.json last, since it marks the folder as one.
CHECKPOINT_FILES = ("plan.json", POINTS_FILE, RECORD_FILE)
# While an inspection runs, its checkpoint grows in this folder inside DIR: what a kill -9 or a
# power cut leaves, and what --resume continues in place.
LIVE_FOLDER = ".checkpoint"
# What a finished inspection adds; none of them may stand beside a checkpoint.
RESULT_FILES = ("result.json", "deviations.csv", "report.html", "report.pdf",
                "inspection.FCStd")


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


def _result_of_all(nominal, blind, blind_sections, later, phase, xyz, snr, fit, first, timing,
                   cad_label, source):
    """points.csv's extra columns and the RegistrationResult of the blind rows followed by
    those measured after them (``later``: xyz, snr, section, angle_deg; tagged ``phase``)."""
    n_blind = len(blind.xyz)
    columns = {"section": np.concatenate([blind_sections, later[2]]),
               "angle_deg": np.concatenate([_blind_column(blind, "angle_deg", n_blind),
                                            later[3]]),
               "phase": np.array(["blind"] * n_blind + [phase] * len(later[0]))}
    result = _result_from_fit(nominal, _pointset(xyz, snr, columns, source), fit, first.coarse,
                              dict(timing), list(first.warnings))
    result.cad_source = cad_label
    return columns, result


def _result_from_fit(nominal, pointset, fit, coarse, timing, warnings):
    """A RegistrationResult for points registered by a fine ICP from a known start, built the
    way pipeline.register builds its own."""
    from ..core import stats as stats_mod
    from .pipeline import uncertainty_with_rival
    from .result import RegistrationResult
    points_cad = tf.apply_transform(fit.transform, pointset.xyz)
    dist = nominal.signed_distance(points_cad)
    inlier = np.asarray(fit.inlier, dtype=bool)
    rms = float(np.sqrt(np.mean(dist.distance[inlier] ** 2))) if inlier.any() else float("nan")
    from .pipeline import pose_summary
    from .checks import unmeasured_warning
    covariance, statistical, unmeasured = pose_summary(fit, nominal)
    if unmeasured:
        warnings = [w for w in warnings if w != unmeasured_warning(unmeasured)]
        warnings.append(unmeasured_warning(unmeasured))
    uncertainty, includes_rival = uncertainty_with_rival(statistical, fit.transform, coarse,
                                                         nominal.bbox_corners)
    return RegistrationResult(
        measured_to_cad=fit.transform, points_cad=points_cad, deviation=dist.distance,
        inlier=inlier, closest=dist.closest, normal=dist.normal, face=dist.face,
        snr=pointset.snr, columns=dict(pointset.columns), n_rows_skipped=0, rms_mm=rms,
        pose_covariance=covariance, center=fit.center,
        pose_uncertainty_mm=float(uncertainty),
        deviation_stats=stats_mod.deviation_statistics(dist.distance), coarse=coarse,
        timing_s=timing, warnings=warnings, source=pointset.source, cad_faces=nominal.cad_faces,
        pose_unmeasured=unmeasured, pose_uncertainty_statistical_mm=float(statistical),
        pose_uncertainty_includes_rival=includes_rival, icp_weights=fit.weights)


def _sections_json(table, plan):
    """result.json `sections`: per nominal section its height, plane (CAD frame), the Table 2
    figures and the CMM's, and how many points were planned and measured there."""
    out = []
    for sec, planned in zip(table.sections, plan.sections):
        doc = sec.to_json()
        doc["plane"] = {"point": planned.plane_point.tolist(),
                        "normal": planned.plane_normal.tolist()}
        doc["height_pct"] = planned.height_pct
        doc["n_planned"] = planned.n_points
        out.append(doc)
    return out


def _pointset(xyz, snr, columns, source):
    return PointSet(xyz=np.asarray(xyz, dtype=float), snr=np.asarray(snr, dtype=float),
                    columns=columns, n_rows_skipped=0, source=source)


def run_inspect(cad_path, out_dir, rig_spec="sim", section_heights=contracts.SECTION_HEIGHTS_PCT,
                complete=False, pitch=0.1, cmm=None, tolerance=contracts.PROFILE_TOLERANCE_MM,
                seed=0, rig_file=None,
                progress=None, rig=None, nominal=None, epsilon=EPSILON_MM, document=True,
                scan_options=None, on_plan=None, resume=False, flip_faces=(),
                allow_mismatch=False, airfoil=None, fit_choice=None, measurement_model=None):
    """The `inspect` command (see the module notes). ``rig`` (an open Rig) and ``nominal``
    replace opening them from ``rig_spec`` and ``cad_path``: tests and the GUI pass their own.
    ``scan_options``: options of the blind scan (measurement.scan.scan_to_dir, e.g. n_sections).
    ``on_plan(plan)`` sees each plan before its paths are scanned (the GUI draws them).
    ``resume``: continue the interrupted inspection in out_dir (same CAD, seed and options;
    ``scan_options`` None takes the interrupted run's). ``flip_faces``: CAD faces whose
    outward side is reversed (``--flip-face``, cad.orient). ``allow_mismatch``: go on with a
    blind scan that does not fit the CAD, with the warning (pipeline.register). ``airfoil``: an
    inspection.airfoil.Options to add the airfoil characteristics (issue 15; None: none).
    ``fit_choice``, ``measurement_model``: the fit and the decision, as for `report`.
    Returns a summary dict. The result files appear in out_dir together, or none: on a
    DeviceError, a cancel or a KeyboardInterrupt out_dir holds the checkpoint instead
    (points.csv, plan.json, scan.json)."""
    from ..measurement import scan as scan_mod
    from ..rig.kinematics import RigKinematics
    from ..measurement.planning import plan_sections
    if on_plan is not None:
        plan_only = plan_sections

        def plan_sections(*args, **kwargs):
            plan = plan_only(*args, **kwargs)
            on_plan(plan)
            return plan
    from . import pipeline
    from . import sections as sections_mod
    from . import verdict as verdict_mod
    from .report import write_report
    progress = progress or _no_progress
    if not out_dir:
        raise InputError("--out: a folder is required")
    heights = contracts.section_heights(section_heights)
    tolerance = contracts.profile_tolerance(tolerance)
    if complete:
        from ..measurement.complete import _check_step
        pitch = _check_step(pitch, "--pitch")
    cmm_data = sections_mod.read_cmm(cmm) if cmm is not None else None
    if scan_options is not None or not resume:
        scan_options = dict(scan_options or {})
        scan_options.setdefault("epsilon", epsilon)
    timing = {}
    t0 = time.perf_counter()
    if nominal is None:
        nominal = pipeline.load_nominal(cad_path, flip_faces=flip_faces)
    kinematics = RigKinematics.from_json(rig_file) if rig_file else RigKinematics()
    identity = _identity(nominal, seed, heights, complete, pitch, epsilon, kinematics,
                         scan_options)
    opened = rig is None
    if opened:
        rig = scan_mod.open_rig(rig_spec, nominal=nominal, seed=seed, kinematics=kinematics)
    timing["load"] = time.perf_counter() - t0
    try:
        with pipeline.AtomicOutput(out_dir) as out:
            checkpoint = _Checkpoint(os.path.join(os.path.abspath(out_dir), LIVE_FOLDER),
                                     out_dir, identity, rig, resume)
            scan_options = dict(checkpoint.identity["scan_options"] or {})
            register_options = {"allow_mismatch": allow_mismatch, "tolerance": tolerance,
                                "cad_source": cad_path or "the demo blade"}
            judge_options = {"fit_choice": fit_choice,   # hook: issue 16
                             "measurement_model": measurement_model}
            try:
                if complete:
                    summary = _complete_loop(nominal, checkpoint.rig, kinematics, heights,
                                             seed, epsilon, cmm_data, tolerance, pitch, out,
                                             checkpoint, timing, progress, document,
                                             scan_options, cad_path or "built-in demo blade",
                                             register_options, judge_options,
                                             airfoil=airfoil)
                else:
                    summary = _loop(nominal, checkpoint.rig, kinematics, heights, seed, epsilon,
                                    cmm_data, tolerance, out, checkpoint, timing, progress,
                                    plan_sections, scan_mod, pipeline, sections_mod,
                                    verdict_mod, write_report, document, scan_options,
                                    cad_path or "built-in demo blade", register_options,
                                    judge_options, airfoil=airfoil)
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


def _blind_stage(nominal, rig, kinematics, seed, checkpoint, timing, progress, scan_options,
                 scan_mod, pipeline, scan_share, register_share, **register_options):
    """The blind section scan into the checkpoint and its registration: nothing is known of
    the pose yet, so only what the sensor reads is used. A resumed inspection continues an
    interrupted blind scan (scan_to_dir's own resume) or reads the finished one back.
    ``register_options``: pipeline.register's allow_mismatch, tolerance and cad_source.
    Returns (the blind scan's record, points, rig time spent, registration)."""
    t0 = time.perf_counter()
    state = checkpoint.state
    if state is None or state["phase"] == "blind":
        progress(0.0, "blind section scan" + (" (resumed)" if state else ""))
        scan_mod.scan_to_dir(checkpoint.folder, rig, seed=seed, kinematics=kinematics,
                             resume=state is not None, phase="blind",
                             progress=lambda f, m: progress(scan_share * f, m),
                             on_record=checkpoint.mark_blind, **scan_options)
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
        nominal, blind, seed=seed,
        progress=lambda f, m: progress(scan_share + register_share * f, m), **register_options)
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


def _loop(nominal, rig, kinematics, heights, seed, epsilon, cmm_data, tolerance, out,
          checkpoint, timing, progress, plan_sections, scan_mod, pipeline, sections_mod,
          verdict_mod, write_report, document, scan_options, cad_label, register_options,
          judge_options=None, airfoil=None):
    # 1-2. blind section scan and its registration
    resumed = checkpoint.state if (checkpoint.state or {}).get("phase") == "planned" else None
    scan_record, blind, blind_rig_s, first = _blind_stage(
        nominal, rig, kinematics, seed, checkpoint, timing, progress, scan_options,
        scan_mod, pipeline, scan_share=0.25, register_share=0.2, **register_options)
    n_blind = len(blind.xyz)
    blind_sections = _blind_column(blind, "section", n_blind)
    # Planned sections are numbered after the blind ones, so a `report` of points.csv by its
    # section column keeps them apart.
    first_planned = int(np.nanmax(blind_sections) + 1) if np.isfinite(blind_sections).any() \
        else 0
    state = _start_or_resume(checkpoint, rig, resumed, {
        "phase": "planned", "attempt": 0, "plan_pose": first.measured_to_cad.tolist(),
        "paths_done": 0, "sections_done": [], "paths": [], "replans": []})
    state.update(blind_measured_to_cad=np.asarray(first.measured_to_cad).tolist(),
                 blind_points=n_blind, blind_rig_s=blind_rig_s,
                 blind_points_bytes=state.get("blind_points_bytes", state["points_bytes"]))
    checkpoint.save(state, scan_record)

    # 3-4. plan, scan, ICP on everything; one re-plan if the pose moved enough to matter
    span_axis, _ = sections_mod.span_axis_of(nominal)
    for attempt in range(int(state["attempt"]), 2):
        pose = np.asarray(state["plan_pose"], dtype=float)
        t0 = time.perf_counter()
        progress(0.45 + 0.05 * attempt, "planning the nominal sections from the CAD")
        plan = plan_sections(nominal, pose, heights, rig.sensor, rig.limits,
                             span_axis=span_axis, kinematics=kinematics)
        timing["plan" if attempt == 0 else "replan"] = time.perf_counter() - t0
        _save_plan(plan, checkpoint)
        # Sections measured before an interruption are read back; this run's are kept too.
        earlier = checkpoint.rows("planned") if state["paths_done"] else None
        session = []

        def section_done(n_paths, rows, records):
            xyz, snr, section, angle, _ = rows
            session.append((xyz, snr, first_planned + section, angle))
            checkpoint.append_rows(*session[-1], "planned")
            state["paths_done"] = n_paths
            state["sections_done"] = state["sections_done"] + [int(records[-1]["section"])]
            state["paths"] = state["paths"] + records
            state["points_bytes"] = checkpoint.points_bytes()
            state["pass_index"] = getattr(rig, "pass_index", None)
            checkpoint.save(state, scan_record)

        t0 = time.perf_counter()
        scan_plan(rig, plan, kinematics,
                  lambda f, m: progress(0.5 + 0.1 * attempt + 0.1 * f, m),
                  first_path=int(state["paths_done"]), on_section=section_done)
        timing["planned_scan" if attempt == 0 else "replanned_scan"] = time.perf_counter() - t0
        planned = _measured_rows(earlier, session)
        n_planned = len(planned[0])
        agreement = _plan_agreement(plan, n_planned, state["paths"], epsilon)
        if agreement:
            raise InputError(agreement)
        t0 = time.perf_counter()
        xyz = np.vstack([blind.xyz, planned[0]])
        snr = np.concatenate([blind.snr, planned[1]])
        fit = pipeline.fine_register(xyz, snr, nominal, pose,
                                     progress=lambda f, m: progress(0.75, m))
        timing["register_all" if attempt == 0 else "register_all_again"] = \
            time.perf_counter() - t0
        targets = np.vstack([s.target_cad for s in plan.sections])
        moved = pose_change_mm(pose, fit.transform, targets)
        state["replans"] = state["replans"] + [
            {"pose_change_mm": moved, "threshold_mm": REPLAN_FRACTION * epsilon,
             "n_planned": plan.n_points, "n_measured": n_planned}]
        if moved <= REPLAN_FRACTION * epsilon or attempt == 1:
            break
        # The re-plan measures the nominal sections again from the better pose; the first
        # pass's rows are replaced, as the uninterrupted loop replaces them.
        checkpoint.truncate_points(state["blind_points_bytes"])
        os.remove(checkpoint.path("plan.json"))
        state.update(attempt=attempt + 1, plan_pose=np.asarray(fit.transform).tolist(),
                     paths_done=0, sections_done=[], paths=[],
                     points_bytes=state["blind_points_bytes"])
        checkpoint.save(state, scan_record)
    replans = state["replans"]
    path_records = state["paths"]

    # 5. results at the nominal sections
    t0 = time.perf_counter()
    columns, result = _result_of_all(nominal, blind, blind_sections, planned, "planned", xyz,
                                     snr, fit, first, timing, cad_label,
                                     "inspect: blind and planned scans")
    table, verdict = _judge_after_blind(result, nominal, n_blind, n_planned, heights,
                                        span_axis, cmm_data, tolerance, sections_mod,
                                        verdict_mod, **(judge_options or {}))
    if airfoil is not None:  # issue 15 hook: airfoil characteristics, into the verdict
        airfoil_mod.attach(result, nominal, table, verdict, airfoil)
    timing["sections"] = time.perf_counter() - t0

    progress(0.85, "writing the report")
    t0 = time.perf_counter()
    rig_s = checkpoint.rig_s()
    write_points_csv(out.path("points.csv"), xyz, {"snr": snr, **columns})
    plan.to_json(out.path("plan.json"))
    scan_record["phases"] = {
        "blind": {"points": n_blind, "summary": dict(scan_record),
                  "rig_s": blind_rig_s},
        "planned": {"points": n_planned, "paths": path_records, "rig_s": rig_s - blind_rig_s}}
    scan_record["replans"] = replans
    with open(out.path("scan.json"), "w") as fh:
        json.dump(scan_record, fh, indent=1, default=contracts.json_default)
    files = write_report(None, result, nominal, table, verdict, tolerance, output=out,
                         title="BladeInspect inspection (CAD-planned sections)")
    if document:
        from .document import write_inspection_document
        write_inspection_document(out.path("inspection.FCStd"), nominal, result, table,
                                  tolerance=tolerance)
    timing["write"] = time.perf_counter() - t0
    result.timing_s = timing
    extra = {"sections": _sections_json(table, plan),
             "section_table": table.to_json(),
             "verdict": verdict, "tolerance_mm": tolerance,
             "uncertainty_after_blind_mm": first.pose_uncertainty_mm,
             "blind_measured_to_cad": np.asarray(first.measured_to_cad).tolist(),
             "replans": replans,
             "n_points_by_phase": {"blind": n_blind, "planned": n_planned},
             "rig_time_s": rig_s, **airfoil_mod.extras_of(table)}  # issue 15 hook
    pipeline.write_register_outputs(None, result, extra=extra, output=out)
    progress(1.0, verdict["summary"])
    return {"result": result, "blind_result": first, "plan": plan, "sections": table,
            "verdict": verdict, "replans": replans, "files": files,
            "uncertainty_after_blind_mm": first.pose_uncertainty_mm,
            "pose_uncertainty_mm": result.pose_uncertainty_mm}


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


def _start_or_resume(checkpoint, rig, resumed, fresh):
    """The phase's state: ``fresh`` with where the points file and the rig's pass numbering
    stand now, or the checkpoint's ``resumed`` state with both put back to where it stood."""
    if resumed is None:
        return dict(fresh, points_bytes=checkpoint.points_bytes(),
                    pass_index=getattr(rig, "pass_index", None))
    state = dict(resumed)
    checkpoint.truncate_points(state["points_bytes"])
    _continue_pass_numbering(rig, state)
    checkpoint.rig.resume(state.get("journal_passes"))
    return state


def _continue_pass_numbering(rig, state):
    """The next pass is numbered as in the interrupted run: a simulated rig's noise stream per
    pass, so a resumed run measures what the uninterrupted one would have."""
    if state.get("pass_index") is not None and hasattr(rig, "set_pass_index"):
        rig.set_pass_index(state["pass_index"])


def _save_plan(plan, checkpoint):
    """plan.json of the checkpoint. One already there is the plan being scanned when the run
    was interrupted (a re-plan removes the first): the plan made again from the saved pose
    must be that one, so the rest of its sections is scanned as the interrupted run would."""
    text = plan.to_json()
    path = checkpoint.path("plan.json")
    if os.path.exists(path):
        with open(path) as fh:
            if fh.read() != text:
                raise InputError("--resume: the plan made again from the saved pose differs "
                                 "from the checkpoint's plan.json (another rig or software)")
        return
    with open(path, "w") as fh:
        fh.write(text)


def _judge_after_blind(result, nominal, n_blind, n_rows, heights, span_axis, cmm_data,
                       tolerance, sections_mod, verdict_mod, fit_choice=None,
                       measurement_model=None):
    """Table 2 from the rows measured after the blind scan (the nominal sections are theirs),
    indexed back into the whole result, and the verdict on every point; the result moved to
    the pose of ``fit_choice`` first (inspection.fitting), its fit sensitivity recorded."""
    from . import fitting   # hook: issue 16
    fit_choice = fit_choice or fitting.FitChoice()
    runs = fitting.apply(result, nominal, fit_choice, tolerance, all_objectives=True)
    rows = np.arange(n_blind, n_blind + n_rows)
    table = sections_mod.section_table(result.planned_rows(rows), nominal, heights_pct=heights,
                                       span_axis=span_axis, cmm=cmm_data)
    for sec in table.sections:
        sec.point_index = sec.point_index + n_blind
    judge_options = {"measurement_model": measurement_model}
    verdict = verdict_mod.judge(result, table, tolerance=tolerance,
                                decision_rule=fit_choice.decision_rule, **judge_options)
    result.fit_sensitivity = fitting.sensitivity(runs, result, table, tolerance, fit_choice,
                                                 judge_options)
    return table, verdict


def _blind_column(pointset, name, n):
    values = pointset.columns.get(name)
    if values is None:
        return np.full(n, np.nan)
    return np.asarray(values, dtype=float)


def _complete_loop(nominal, rig, kinematics, heights, seed, epsilon, cmm_data, tolerance, pitch,
                   out, checkpoint, timing, progress, document, scan_options, cad_label,
                   register_options, judge_options=None, airfoil=None):
    """`inspect --complete` (paper 4.3): the blind scan and its registration as in _loop, then
    the whole blade rastered every ``pitch`` mm (measurement.complete) from that pose, ICP on every
    point, and Table 2 at the nominal planes from the raster points within 0.25 mm of each."""
    from ..measurement import scan as scan_mod
    from ..measurement.complete import plan_complete, scan_complete
    from . import pipeline
    from . import sections as sections_mod
    from . import verdict as verdict_mod
    from .report import write_report
    resumed = checkpoint.state if (checkpoint.state or {}).get("phase") == "complete" else None
    scan_record, blind, blind_rig_s, first = _blind_stage(
        nominal, rig, kinematics, seed, checkpoint, timing, progress, scan_options,
        scan_mod, pipeline, scan_share=0.15, register_share=0.1, **register_options)
    n_blind = len(blind.xyz)
    blind_sections = _blind_column(blind, "section", n_blind)
    first_line = int(np.nanmax(blind_sections) + 1) if np.isfinite(blind_sections).any() else 0
    state = _start_or_resume(checkpoint, rig, resumed, {
        "phase": "complete", "plan_pose": first.measured_to_cad.tolist(),
        "passes_done": 0, "passes": []})
    state.update(blind_measured_to_cad=np.asarray(first.measured_to_cad).tolist(),
                 blind_points=n_blind, blind_rig_s=blind_rig_s)
    checkpoint.save(state, scan_record)

    t0 = time.perf_counter()
    progress(0.25, "planning the complete raster from the CAD")
    pose = np.asarray(state["plan_pose"], dtype=float)
    plan = plan_complete(nominal, pose, rig.sensor, rig.limits, pitch=pitch,
                         kinematics=kinematics)
    timing["plan"] = time.perf_counter() - t0
    _save_plan(plan, checkpoint)
    # Passes measured before an interruption are read back; this run's are kept too.
    earlier = checkpoint.rows("complete") if state["passes_done"] else None
    session = []

    def pass_done(n_passes, rows, record):
        xyz, snr, line, angle = rows
        session.append((xyz, snr, first_line + line, angle))
        checkpoint.append_rows(*session[-1], "complete")
        state["passes_done"] = n_passes
        state["passes"] = state["passes"] + [record]
        state["points_bytes"] = checkpoint.points_bytes()
        state["pass_index"] = getattr(rig, "pass_index", None)
        checkpoint.save(state, scan_record)

    t0 = time.perf_counter()
    scan_complete(rig, plan, kinematics, lambda f, m: progress(0.3 + 0.3 * f, m),
                  first_pass=int(state["passes_done"]), on_pass=pass_done)
    timing["complete_scan"] = time.perf_counter() - t0
    complete_rig_s = checkpoint.rig_s() - blind_rig_s
    pass_records = state["passes"]
    raster = _measured_rows(earlier, session)
    n_read = len(raster[0])
    worst = max((r["max_standoff_error_mm"] or 0.0) for r in pass_records) if n_read else np.inf
    if n_read < MIN_READ_FRACTION * plan.n_points or worst > epsilon:
        raise InputError("inspect --complete: the raster does not find the blade where the "
                         "blind scan's registration put it (%d of %d planned points read, "
                         "standoff off by up to %.2f mm)" % (n_read, plan.n_points, worst))

    t0 = time.perf_counter()
    xyz = np.vstack([blind.xyz, raster[0]])
    snr = np.concatenate([blind.snr, raster[1]])
    fit = pipeline.fine_register(xyz, snr, nominal, pose,
                                 progress=lambda f, m: progress(0.65, m))
    timing["register_all"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    columns, result = _result_of_all(nominal, blind, blind_sections, raster, "complete", xyz,
                                     snr, fit, first, timing, cad_label,
                                     "inspect --complete: blind and complete scans")
    span_axis, _ = sections_mod.span_axis_of(nominal)
    # planned_rows drops the section column (raster lines are not the nominal planes), so the
    # table takes the points within its band of each plane.
    table, verdict = _judge_after_blind(result, nominal, n_blind, n_read, heights,
                                        span_axis, cmm_data, tolerance, sections_mod,
                                        verdict_mod, **(judge_options or {}))
    if airfoil is not None:  # issue 15 hook: airfoil characteristics, into the verdict
        airfoil_mod.attach(result, nominal, table, verdict, airfoil)
    timing["sections"] = time.perf_counter() - t0

    progress(0.85, "writing the report")
    t0 = time.perf_counter()
    write_points_csv(out.path("points.csv"), xyz, {"snr": snr, **columns})
    plan.to_json(out.path("plan.json"))
    scan_record["phases"] = {
        "blind": {"points": n_blind, "summary": dict(scan_record), "rig_s": blind_rig_s},
        "complete": {"points": n_read, "planned_points": plan.n_points,
                     "pitch_mm": plan.pitch_mm, "angles_deg": plan.angles_deg.tolist(),
                     "passes": pass_records, "rig_s": complete_rig_s,
                     "simulated_s": timing["complete_scan"],
                     "sensor_rate_s": n_read / float(rig.sensor.rate_hz)}}
    with open(out.path("scan.json"), "w") as fh:
        json.dump(scan_record, fh, indent=1, default=contracts.json_default)
    files = write_report(None, result, nominal, table, verdict, tolerance, output=out,
                         title="BladeInspect inspection (complete scan, pitch %g mm)" % pitch)
    if document:
        from .document import write_inspection_document
        write_inspection_document(out.path("inspection.FCStd"), nominal, result, table,
                                  tolerance=tolerance)
    timing["write"] = time.perf_counter() - t0
    result.timing_s = timing
    sections_doc = [dict(sec.to_json(), height_pct=sec.height_pct,
                         plane={"point": sec.origin.tolist(), "normal": sec.normal.tolist()})
                    for sec in table.sections]
    extra = {"sections": sections_doc, "section_table": table.to_json(), "verdict": verdict,
             "tolerance_mm": tolerance,
             "uncertainty_after_blind_mm": first.pose_uncertainty_mm,
             "blind_measured_to_cad": np.asarray(first.measured_to_cad).tolist(),
             "n_points_by_phase": {"blind": n_blind, "complete": n_read},
             "complete": {"pitch_mm": plan.pitch_mm, "rig_s": complete_rig_s,
                          "simulated_s": timing["complete_scan"]},
             "rig_time_s": checkpoint.rig_s(), **airfoil_mod.extras_of(table)}  # issue 15 hook
    pipeline.write_register_outputs(None, result, extra=extra, output=out)
    progress(1.0, verdict["summary"])
    return {"result": result, "blind_result": first, "plan": plan, "sections": table,
            "verdict": verdict, "files": files,
            "uncertainty_after_blind_mm": first.pose_uncertainty_mm,
            "pose_uncertainty_mm": result.pose_uncertainty_mm,
            "complete_rig_s": complete_rig_s, "complete_simulated_s": timing["complete_scan"]}


# ---------------------------------------------------------------- checkpoint and resume

class _Checkpoint:
    """What an inspection has measured so far, kept in DIR/LIVE_FOLDER while it runs:
    points.csv and scan.json grow one completed blind section at a time (measurement.scan.scan_to_dir's
    own checkpoint), then one completed planned section or raster pass at a time; plan.json is
    the plan being scanned; readings.journal holds every pass since (``rig``: the rig,
    journaled). scan.json's CHECKPOINT entry says where the loop stands from the first write
    on, so whatever a kill leaves can be resumed. A DeviceError or a cancel moves the three
    files into DIR (keep); ``resume`` continues the live folder in place when a kill left one,
    else starts from a copy of the files in DIR."""

    def __init__(self, folder, out_dir, identity, rig, resume):
        self.folder = folder
        self.out_dir = os.path.abspath(out_dir)
        self.state = None
        self.in_place = False
        self._created_dir = not os.path.exists(self.out_dir)
        self._earlier_rig_s = 0.0
        live = _live_checkpoint(self.path(RECORD_FILE))
        record_path = os.path.join(self.out_dir, RECORD_FILE)
        if not resume:
            try:
                saved = live or _saved_checkpoint(record_path)
            except InputError:
                saved = None    # not a checkpoint: a fresh run replaces it, as any old file
            if saved is not None:
                raise InputError("--out %s: holds an interrupted inspection (use --resume to "
                                 "continue it, or another folder)" % out_dir)
            self.identity = identity
            self._start(rig, copy_from=None)
            return
        saved = live if live is not None else _saved_checkpoint(record_path)
        if saved is None:
            raise InputError("--resume: %s holds no interrupted inspection to continue"
                             % out_dir)
        self.identity = _same_identity(saved.get("options"), identity, out_dir)
        source = self.path(RECORD_FILE) if live is not None else record_path
        with open(source) as fh:
            check_same_rig(json.load(fh), rig, identity["seed"], source)
        self.state = saved
        self._earlier_rig_s = float(saved.get("rig_s", 0.0))
        self.in_place = live is not None
        self._start(rig, copy_from=None if self.in_place else self.out_dir)

    def _start(self, rig, copy_from):
        """The live folder (a fresh one, the files of ``copy_from`` copied in, or the one a
        kill left) and the journaled rig writing into it."""
        if not self.in_place:
            shutil.rmtree(self.folder, ignore_errors=True)   # a kill before its first record
            os.makedirs(self.folder)
            if copy_from is not None:
                # scan.json last and whole: it is what makes the folder a checkpoint.
                for name in CHECKPOINT_FILES:
                    if os.path.exists(os.path.join(copy_from, name)):
                        _durable_copy(os.path.join(copy_from, name), self.path(name))
        self.rig = JournaledRig(rig, self.path(JOURNAL_FILE), keep=self.in_place)
        self._session_start = float(self.rig.elapsed_s)

    def path(self, name):
        return os.path.join(self.folder, name)

    def rig_s(self):
        """Rig time of the whole inspection: earlier sessions and this one."""
        return self._earlier_rig_s + float(self.rig.elapsed_s) - self._session_start

    def record(self):
        """scan.json as it stands, without the loop's own state."""
        with open(self.path(RECORD_FILE)) as fh:
            record = json.load(fh)
        record.pop(CHECKPOINT, None)
        return record

    def save(self, state, record=None, journal=True):
        """Records where the loop stands (after a completed section: the rows on disk are
        exactly those the state counts, and so are the journal's passes, which then start
        afresh). ``journal`` False leaves the journal's count as ``state`` has it."""
        record = self.record() if record is None else dict(record)
        self.state = dict(state, options=self.identity, complete=False, rig_s=self.rig_s())
        if journal:
            self.state["journal_passes"] = self.rig.passes
        record[CHECKPOINT] = self.state
        record["complete"] = False
        write_record(self.path(RECORD_FILE), record)
        if journal:
            self.rig.commit()

    def mark_blind(self, record):
        """The blind scan's scan.json, as scan_to_dir writes it: marked as this inspection's
        checkpoint from the first write on (the journal's count is scan_to_dir's own)."""
        record[CHECKPOINT] = dict(self.state if self.state is not None else {},
                                  phase="blind", options=self.identity, complete=False,
                                  rig_s=self.rig_s())

    def keep(self):
        """After a DeviceError or a cancel: the measured data goes to DIR as a checkpoint to resume, in
        place of any earlier result there (a result beside a checkpoint would not be one)."""
        if not os.path.exists(self.path(RECORD_FILE)):
            return
        state = self.state if self.state is not None else {"phase": "blind"}
        # The journal stays behind: the kept checkpoint is the completed sections, as before.
        self.save(state, journal=False)
        for name in RESULT_FILES:
            if os.path.exists(os.path.join(self.out_dir, name)):
                os.remove(os.path.join(self.out_dir, name))
        # scan.json last: it is what marks the folder as a checkpoint.
        for name in CHECKPOINT_FILES:
            if os.path.exists(self.path(name)):
                os.replace(self.path(name), os.path.join(self.out_dir, name))
            elif os.path.exists(os.path.join(self.out_dir, name)):
                os.remove(os.path.join(self.out_dir, name))

    def discard(self):
        """The live folder goes: the result, or the kept checkpoint, is in DIR."""
        shutil.rmtree(self.folder, ignore_errors=True)

    def abandon(self):
        """After an InputError: nothing of this run is left, except a live folder that a kill
        left, which stays resumable (it holds measurements made before this run)."""
        if self.in_place:
            return
        self.discard()
        if self._created_dir and os.path.isdir(self.out_dir) and not os.listdir(self.out_dir):
            os.rmdir(self.out_dir)

    def truncate_points(self, size):
        path = self.path(POINTS_FILE)
        if os.path.getsize(path) < size:
            raise InputError("%s: shorter than its checkpoint in %s (the folder was changed)"
                             % (os.path.join(self.out_dir, POINTS_FILE), RECORD_FILE))
        with open(path, "r+b") as fh:
            fh.truncate(size)

    def points_bytes(self):
        return os.path.getsize(self.path(POINTS_FILE))

    def rows(self, phase):
        """The rows of one phase in points.csv (a PointSet; None when there are none)."""
        pointset = read_points(self.path(POINTS_FILE))
        keep = pointset.columns["phase"] == phase
        if not keep.any():
            return None
        return PointSet(xyz=pointset.xyz[keep], snr=pointset.snr[keep],
                        columns={k: np.asarray(v)[keep] for k, v in pointset.columns.items()},
                        n_rows_skipped=0, source=pointset.source)

    def append_rows(self, xyz, snr, section, angle, phase):
        """Rows measured after the blind scan, at full precision: a resumed run reads back the
        very numbers an uninterrupted one keeps in memory."""
        lines = ["%r,%r,%r,%r,%d,%r,%s\n" % (x, y, z, s, k, a, phase)
                 for (x, y, z), s, k, a in zip(np.asarray(xyz, dtype=float).tolist(),
                                               np.asarray(snr, dtype=float).tolist(),
                                               np.asarray(section).tolist(),
                                               np.asarray(angle, dtype=float).tolist())]
        with open(self.path(POINTS_FILE), "a") as fh:
            fh.write("".join(lines))
            fh.flush()
            os.fsync(fh.fileno())


def _live_checkpoint(record_path):
    """The loop's state in the live folder's scan.json, or None when there is none to resume
    (no folder, or one killed before its first record)."""
    try:
        return _saved_checkpoint(record_path)
    except InputError:
        return None


def _durable_copy(source, target):
    """Copy ``source`` to ``target`` all at once and on disk (a temporary file replaced)."""
    tmp = target + ".part"
    shutil.copyfile(source, tmp)
    with open(tmp, "rb+") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, target)


def _saved_checkpoint(record_path):
    """The loop's state in DIR/scan.json when DIR holds an interrupted inspection, else None."""
    if not os.path.exists(record_path):
        return None
    try:
        with open(record_path) as fh:
            record = json.load(fh)
    except (OSError, ValueError) as exc:
        raise InputError("%s: not a readable scan record (%s)" % (record_path, exc))
    state = record.get(CHECKPOINT) if isinstance(record, dict) else None
    if not isinstance(state, dict) or state.get("complete", True):
        return None
    if state.get("phase") not in ("blind", "planned", "complete") or \
            not isinstance(state.get("options"), dict):
        raise InputError("%s: malformed inspection checkpoint" % record_path)
    return state


def _identity(nominal, seed, heights, complete, pitch, epsilon, kinematics, scan_options):
    """What a resumed inspection must share with the interrupted one to measure the same
    points (JSON-ready). ``scan_options`` None: whatever the interrupted run used."""
    options = None
    if scan_options is not None:
        options = contracts.json_ready(scan_options)
    return {"cad_bbox": np.asarray(nominal.bbox_corners, dtype=float).tolist(),
            "seed": int(seed), "section_heights": [float(h) for h in heights],
            "complete": bool(complete), "pitch_mm": float(pitch) if complete else None,
            "epsilon_mm": float(epsilon), "kinematics": kinematics.to_dict(),
            "scan_options": options}


IDENTITY_FLAGS = (("cad_bbox", "the CAD (its bounding box)"), ("seed", "--seed"),
                  ("section_heights", "--section-heights"), ("complete", "--complete"),
                  ("pitch_mm", "--pitch"), ("epsilon_mm", "epsilon"),
                  ("kinematics", "--rig-file"), ("scan_options", "the blind scan's options"))


def _same_identity(saved, given, out_dir):
    """The identity the resumed run continues with; InputError naming the first difference."""
    if not isinstance(saved, dict):
        raise InputError("--resume %s: the checkpoint does not say how it was begun" % out_dir)
    if given["scan_options"] is None:
        given = dict(given, scan_options=saved.get("scan_options"))
    for key, flag in IDENTITY_FLAGS:
        a, b = saved.get(key), given[key]
        same = (np.allclose(a, b, rtol=0.0, atol=1e-9) if key == "cad_bbox" and a is not None
                else a == b)
        if not same:
            shown = ("another part" if key == "cad_bbox" else
                     "another rig file" if key == "kinematics" else "%s, not %s" % (a, b))
            raise InputError("--resume %s: the interrupted inspection was begun with other %s "
                             "(%s); resume with the same options" % (out_dir, flag, shown))
    return given
