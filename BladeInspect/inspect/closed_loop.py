"""The `inspect` workflow (issue 8, item 1): the paper's whole automated loop on one blade.

1. blind section scan (rig.scan.scan_to_dir: nothing about the pose is known yet);
2. registration of those points (reconstruction, PCA, SNR-weighted ICP) -> pose on the table;
3. paths planned from the CAD at its nominal section planes, brought into the machine by
   that pose (rig.planning), and scanned;
4. ICP on all points from that pose; when the pose moved enough to matter for the planned
   points, one re-plan and re-scan of the nominal sections with the better pose;
5. Table 2 at the nominal sections (inspect.sections, with a CMM's columns when given), the
   verdict, and the report of the `report` command.

With --complete (paper 4.3) steps 3-4 are the whole blade rastered every --pitch mm instead
(rig.complete) and one ICP on all points; Table 2 takes the raster points within 0.25 mm of
each nominal plane, and the `phase` column reads blind or complete.

Files in DIR: points.csv (table frame, with a `phase` column: blind or planned), plan.json,
scan.json (the blind scan's record, the planned passes, the simulator's truth), result.json
(with `sections` and `uncertainty_after_blind_mm`), deviations.csv, report.html/.pdf.
"""

import json
import os
import shutil
import tempfile
import time

import numpy as np

from ..core import transforms as tf
from ..core.errors import InputError
from ..core.pointio import PointSet, read_points, write_points_csv

DEFAULT_HEIGHTS = (10.0, 30.0, 50.0, 70.0, 90.0)
EPSILON_MM = 2.0
# The planned points must lie within 0.01 mm of their nominal planes: a pose that moves them by
# more than a quarter of that budget (5 um, the fraction 1/400 of the 2 mm epsilon) is worth a
# re-plan. The standoff criterion epsilon itself is far looser than the plane budget.
REPLAN_FRACTION = 0.0025
# Below this fraction of planned points read, the part is not where the plan expected it.
MIN_READ_FRACTION = 0.9


def _no_progress(fraction, message):
    pass


def _check_heights(heights):
    values = []
    for h in heights:
        try:
            v = float(h)
        except (TypeError, ValueError):
            raise InputError("--section-heights: %r is not a number" % (h,)) from None
        if not (np.isfinite(v) and 0.0 <= v <= 100.0):
            raise InputError("--section-heights: %g is outside 0-100 %% of the span" % v)
        values.append(v)
    if not values:
        raise InputError("--section-heights: at least one height is needed")
    return values


def scan_plan(rig, plan, kinematics, progress=_no_progress):
    """Scan every planned path on the rig. Returns table-frame points with their SNR, the
    planned section index, rotary angle and the planned point they answer (rows with no
    reading are left out) and a list of per-path records for scan.json."""
    xyz, snr, section, angle, point = [], [], [], [], []
    records = []
    for i, path in enumerate(plan.paths):
        progress(i / max(len(plan.paths), 1), "planned scan: path %d of %d (section %g %%, "
                 "A=%.0f deg)" % (i + 1, len(plan.paths),
                                  plan.sections[path.section].height_pct, path.angle_deg))
        stage = plan.path_stage_xyz(path)
        readings = rig.scan_path(stage, path.angle_deg)
        d = np.asarray(readings.reading_mm, dtype=float)
        ok = np.isfinite(d)
        machine = kinematics.machine_point(np.asarray(readings.stage_xyz)[ok], d[ok])
        xyz.append(kinematics.table_point(machine, path.angle_deg))
        snr.append(np.asarray(readings.snr, dtype=float)[ok])
        section.append(np.full(int(ok.sum()), path.section))
        angle.append(np.full(int(ok.sum()), path.angle_deg))
        point.append(path.points[ok])
        expected = plan.sections[path.section].expected_standoff_mm[path.points]
        records.append({"section": path.section, "angle_deg": path.angle_deg,
                        "points": int(len(d)), "readings": int(ok.sum()),
                        "max_standoff_error_mm": (float(np.max(np.abs(d[ok] - expected[ok])))
                                                  if ok.any() else None),
                        "pass_index": readings.meta.get("pass_index")})
    cat = np.concatenate
    return (np.vstack(xyz) if xyz else np.zeros((0, 3)), cat(snr), cat(section), cat(angle),
            cat(point), records)


def _plan_agreement(plan, planned, epsilon):
    """None when the planned scan read what the plan expected; else a one-line message. The
    plan puts every nominal point at the standoff: readings missing or far off it mean the
    part is not where the blind registration put it (a wrong PCA candidate, a moved part)."""
    n_read = len(planned[0])
    records = planned[5]
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


def _result_from_fit(nominal, pointset, fit, coarse, timing, warnings):
    """A RegistrationResult for points registered by a fine ICP from a known start, built the
    way pipeline.register builds its own."""
    from ..core import icp as icp_mod
    from ..core import stats as stats_mod
    from .result import RegistrationResult
    points_cad = tf.apply_transform(fit.transform, pointset.xyz)
    dist = nominal.signed_distance(points_cad)
    inlier = np.asarray(fit.inlier, dtype=bool)
    rms = float(np.sqrt(np.mean(dist.distance[inlier] ** 2))) if inlier.any() else float("nan")
    uncertainty = icp_mod.pose_uncertainty(fit.covariance, fit.center, nominal.bbox_corners)
    return RegistrationResult(
        measured_to_cad=fit.transform, points_cad=points_cad, deviation=dist.distance,
        inlier=inlier, closest=dist.closest, normal=dist.normal, face=dist.face,
        snr=pointset.snr, columns=dict(pointset.columns), n_rows_skipped=0, rms_mm=rms,
        pose_covariance=fit.covariance, center=fit.center,
        pose_uncertainty_mm=float(uncertainty),
        deviation_stats=stats_mod.deviation_statistics(dist.distance), coarse=coarse,
        timing_s=timing, warnings=warnings, source=pointset.source)


def _subset(result, rows):
    """The result restricted to some rows (the planned points), for the section table."""
    import dataclasses
    from ..core import stats as stats_mod
    rows = np.asarray(rows)
    cols = {k: np.asarray(v)[rows] for k, v in result.columns.items() if k != "section"}
    return dataclasses.replace(
        result, points_cad=result.points_cad[rows], deviation=result.deviation[rows],
        inlier=result.inlier[rows], closest=result.closest[rows], normal=result.normal[rows],
        face=result.face[rows], snr=None if result.snr is None else result.snr[rows],
        columns=cols, deviation_stats=stats_mod.deviation_statistics(result.deviation[rows]))


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


def run_inspect(cad_path, out_dir, rig_spec="sim", section_heights=DEFAULT_HEIGHTS,
                complete=False, pitch=0.1, cmm=None, tolerance=0.04, seed=0, rig_file=None,
                progress=None, rig=None, nominal=None, epsilon=EPSILON_MM, document=True,
                scan_options=None, on_plan=None):
    """The `inspect` command (see the module notes). ``rig`` (an open Rig) and ``nominal``
    replace opening them from ``rig_spec`` and ``cad_path``: tests and the GUI pass their own.
    ``scan_options``: options of the blind scan (rig.scan.scan_to_dir, e.g. n_sections).
    ``on_plan(plan)`` sees each plan before its paths are scanned (the GUI draws them).
    Returns a summary dict. All files appear in out_dir together, or none on an error."""
    from ..rig import scan as scan_mod
    from ..rig.kinematics import RigKinematics
    from ..rig.planning import plan_sections
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
    heights = _check_heights(section_heights)
    tolerance = float(tolerance)
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise InputError("--tolerance: must be a positive number of mm, got %r" % (tolerance,))
    if complete:
        from ..rig.complete import _check_step
        pitch = _check_step(pitch, "--pitch")
    cmm_data = sections_mod.read_cmm(cmm) if cmm is not None else None
    timing = {}
    t0 = time.perf_counter()
    if nominal is None:
        nominal = pipeline.load_nominal(cad_path)
    kinematics = RigKinematics.from_json(rig_file) if rig_file else RigKinematics()
    opened = rig is None
    if opened:
        rig = scan_mod.open_rig(rig_spec, nominal=nominal, seed=seed, kinematics=kinematics)
    timing["load"] = time.perf_counter() - t0
    try:
        with pipeline.AtomicOutput(out_dir) as out:
            work = tempfile.mkdtemp(prefix="blind-", dir=out.tmp)
            try:
                if complete:
                    summary = _complete_loop(nominal, rig, kinematics, heights, seed, epsilon,
                                             cmm_data, tolerance, pitch, out, work, timing,
                                             progress, document, dict(scan_options or {}),
                                             cad_path or "built-in demo blade")
                else:
                    summary = _loop(nominal, rig, kinematics, heights, seed, epsilon, cmm_data,
                                    tolerance, out, work, timing, progress, plan_sections,
                                    scan_mod, pipeline, sections_mod, verdict_mod, write_report,
                                    document, dict(scan_options or {}),
                                    cad_path or "built-in demo blade")
            finally:
                shutil.rmtree(work, ignore_errors=True)
    finally:
        if opened:
            rig.close()
    summary["out_dir"] = os.path.abspath(out_dir)
    return summary


def _blind_stage(nominal, rig, kinematics, seed, epsilon, work, timing, progress, scan_options,
                 scan_mod, pipeline, scan_share, register_share):
    """The blind section scan into ``work`` and its registration: nothing is known of the pose
    yet, so only what the sensor reads is used. Returns (scan summary, points, scan record,
    rig time spent, registration)."""
    t0 = time.perf_counter()
    progress(0.0, "blind section scan")
    scan_options.setdefault("epsilon", epsilon)
    blind_summary = scan_mod.scan_to_dir(work, rig, seed=seed, kinematics=kinematics,
                                         progress=lambda f, m: progress(scan_share * f, m),
                                         **scan_options)
    blind = read_points(os.path.join(work, "points.csv"))
    with open(os.path.join(work, "scan.json")) as fh:
        scan_record = json.load(fh)
    timing["blind_scan"] = time.perf_counter() - t0
    blind_rig_s = float(rig.elapsed_s)
    t0 = time.perf_counter()
    first = pipeline.register(
        nominal, blind, seed=seed,
        progress=lambda f, m: progress(scan_share + register_share * f, m))
    timing["register_blind"] = time.perf_counter() - t0
    return blind_summary, blind, scan_record, blind_rig_s, first


def _loop(nominal, rig, kinematics, heights, seed, epsilon, cmm_data, tolerance, out, work,
          timing, progress, plan_sections, scan_mod, pipeline, sections_mod, verdict_mod,
          write_report, document, scan_options, cad_label):
    # 1-2. blind section scan and its registration
    blind_summary, blind, scan_record, blind_rig_s, first = _blind_stage(
        nominal, rig, kinematics, seed, epsilon, work, timing, progress, scan_options,
        scan_mod, pipeline, scan_share=0.25, register_share=0.2)
    pose = first.measured_to_cad

    # 3-4. plan, scan, ICP on everything; one re-plan if the pose moved enough to matter
    span_axis, _ = sections_mod.span_axis_of(nominal)
    replans = []
    planned = None
    for attempt in range(2):
        t0 = time.perf_counter()
        progress(0.45 + 0.05 * attempt, "planning the nominal sections from the CAD")
        plan = plan_sections(nominal, pose, heights, rig.sensor, rig.limits,
                             span_axis=span_axis, kinematics=kinematics)
        timing["plan" if attempt == 0 else "replan"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        planned = scan_plan(rig, plan, kinematics,
                            lambda f, m: progress(0.5 + 0.1 * attempt + 0.1 * f, m))
        timing["planned_scan" if attempt == 0 else "replanned_scan"] = time.perf_counter() - t0

        agreement = _plan_agreement(plan, planned, epsilon)
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
        replans.append({"pose_change_mm": moved, "threshold_mm": REPLAN_FRACTION * epsilon,
                        "n_planned": plan.n_points, "n_measured": int(len(planned[0]))})
        pose = fit.transform
        if moved <= REPLAN_FRACTION * epsilon:
            break

    # 5. results at the nominal sections
    t0 = time.perf_counter()
    xyz_p, snr_p, section_p, angle_p, _, path_records = planned
    n_blind = len(blind.xyz)
    phase = np.array(["blind"] * n_blind + ["planned"] * len(xyz_p))
    blind_sections = _blind_column(blind, "section", n_blind)
    # Planned sections are numbered after the blind ones, so a `report` of points.csv by its
    # section column keeps them apart.
    first_planned = (np.nanmax(blind_sections) + 1) if np.isfinite(blind_sections).any() else 0
    columns = {"section": np.concatenate([blind_sections, first_planned + section_p]),
               "angle_deg": np.concatenate([_blind_column(blind, "angle_deg", n_blind),
                                            angle_p]),
               "phase": phase}
    everything = _pointset(xyz, snr, columns, "inspect: blind and planned scans")
    result = _result_from_fit(nominal, everything, fit, first.coarse,
                              dict(timing), list(first.warnings))
    result.cad_source = cad_label
    table, verdict = _judge_after_blind(result, nominal, n_blind, len(xyz_p), heights,
                                        span_axis, cmm_data, tolerance, sections_mod,
                                        verdict_mod)
    timing["sections"] = time.perf_counter() - t0

    progress(0.85, "writing the report")
    t0 = time.perf_counter()
    write_points_csv(out.path("points.csv"), xyz, {"snr": snr, **columns})
    plan.to_json(out.path("plan.json"))
    scan_record["phases"] = {
        "blind": {"points": n_blind, "summary": blind_summary, "rig_s": blind_rig_s},
        "planned": {"points": int(len(xyz_p)), "paths": path_records,
                    "rig_s": float(rig.elapsed_s) - blind_rig_s}}
    scan_record["replans"] = replans
    with open(out.path("scan.json"), "w") as fh:
        json.dump(scan_record, fh, indent=1, default=pipeline._json_default)
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
             "n_points_by_phase": {"blind": n_blind, "planned": int(len(xyz_p))},
             "rig_time_s": float(rig.elapsed_s)}
    pipeline.write_register_outputs(None, result, extra=extra, output=out)
    progress(1.0, verdict["summary"])
    return {"result": result, "blind_result": first, "plan": plan, "sections": table,
            "verdict": verdict, "replans": replans, "files": files,
            "uncertainty_after_blind_mm": first.pose_uncertainty_mm,
            "pose_uncertainty_mm": result.pose_uncertainty_mm}


def _judge_after_blind(result, nominal, n_blind, n_rows, heights, span_axis, cmm_data,
                       tolerance, sections_mod, verdict_mod):
    """Table 2 from the rows measured after the blind scan (the nominal sections are theirs),
    indexed back into the whole result, and the verdict on every point."""
    rows = np.arange(n_blind, n_blind + n_rows)
    table = sections_mod.section_table(_subset(result, rows), nominal, heights_pct=heights,
                                       span_axis=span_axis, cmm=cmm_data)
    for sec in table.sections:
        sec.point_index = sec.point_index + n_blind
    return table, verdict_mod.judge(result, table, tolerance=tolerance)


def _blind_column(pointset, name, n):
    values = pointset.columns.get(name)
    if values is None:
        return np.full(n, np.nan)
    return np.asarray(values, dtype=float)


def _complete_loop(nominal, rig, kinematics, heights, seed, epsilon, cmm_data, tolerance, pitch,
                   out, work, timing, progress, document, scan_options, cad_label):
    """`inspect --complete` (paper 4.3): the blind scan and its registration as in _loop, then
    the whole blade rastered every ``pitch`` mm (rig.complete) from that pose, ICP on every
    point, and Table 2 at the nominal planes from the raster points within 0.25 mm of each."""
    from ..rig import scan as scan_mod
    from ..rig.complete import plan_complete, scan_complete
    from . import pipeline
    from . import sections as sections_mod
    from . import verdict as verdict_mod
    from .report import write_report
    blind_summary, blind, scan_record, blind_rig_s, first = _blind_stage(
        nominal, rig, kinematics, seed, epsilon, work, timing, progress, scan_options,
        scan_mod, pipeline, scan_share=0.15, register_share=0.1)

    t0 = time.perf_counter()
    progress(0.25, "planning the complete raster from the CAD")
    plan = plan_complete(nominal, first.measured_to_cad, rig.sensor, rig.limits, pitch=pitch,
                         kinematics=kinematics)
    timing["plan"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    xyz_c, snr_c, line_c, angle_c, _, reading_c, pass_records = scan_complete(
        rig, plan, kinematics, lambda f, m: progress(0.3 + 0.3 * f, m))
    timing["complete_scan"] = time.perf_counter() - t0
    complete_rig_s = float(rig.elapsed_s) - blind_rig_s
    worst = float(np.max(np.abs(reading_c - plan.standoff_mm))) if len(reading_c) else np.inf
    if len(xyz_c) < MIN_READ_FRACTION * plan.n_points or worst > epsilon:
        raise InputError("inspect --complete: the raster does not find the blade where the "
                         "blind scan's registration put it (%d of %d planned points read, "
                         "standoff off by up to %.2f mm)" % (len(xyz_c), plan.n_points, worst))

    t0 = time.perf_counter()
    xyz = np.vstack([blind.xyz, xyz_c])
    snr = np.concatenate([blind.snr, snr_c])
    fit = pipeline.fine_register(xyz, snr, nominal, first.measured_to_cad,
                                 progress=lambda f, m: progress(0.65, m))
    timing["register_all"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    n_blind = len(blind.xyz)
    blind_sections = _blind_column(blind, "section", n_blind)
    first_line = (np.nanmax(blind_sections) + 1) if np.isfinite(blind_sections).any() else 0
    columns = {"section": np.concatenate([blind_sections, first_line + line_c]),
               "angle_deg": np.concatenate([_blind_column(blind, "angle_deg", n_blind),
                                            angle_c]),
               "phase": np.array(["blind"] * n_blind + ["complete"] * len(xyz_c))}
    everything = _pointset(xyz, snr, columns, "inspect --complete: blind and complete scans")
    result = _result_from_fit(nominal, everything, fit, first.coarse, dict(timing),
                              list(first.warnings))
    result.cad_source = cad_label
    span_axis, _ = sections_mod.span_axis_of(nominal)
    # _subset drops the section column (raster lines are not the nominal planes), so the table
    # takes the points within its band of each plane.
    table, verdict = _judge_after_blind(result, nominal, n_blind, len(xyz_c), heights,
                                        span_axis, cmm_data, tolerance, sections_mod,
                                        verdict_mod)
    timing["sections"] = time.perf_counter() - t0

    progress(0.85, "writing the report")
    t0 = time.perf_counter()
    write_points_csv(out.path("points.csv"), xyz, {"snr": snr, **columns})
    plan.to_json(out.path("plan.json"))
    scan_record["phases"] = {
        "blind": {"points": n_blind, "summary": blind_summary, "rig_s": blind_rig_s},
        "complete": {"points": int(len(xyz_c)), "planned_points": plan.n_points,
                     "pitch_mm": plan.pitch_mm, "angles_deg": plan.angles_deg.tolist(),
                     "passes": pass_records, "rig_s": complete_rig_s,
                     "simulated_s": timing["complete_scan"],
                     "sensor_rate_s": len(xyz_c) / float(rig.sensor.rate_hz)}}
    with open(out.path("scan.json"), "w") as fh:
        json.dump(scan_record, fh, indent=1, default=pipeline._json_default)
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
             "n_points_by_phase": {"blind": n_blind, "complete": int(len(xyz_c))},
             "complete": {"pitch_mm": plan.pitch_mm, "rig_s": complete_rig_s,
                          "simulated_s": timing["complete_scan"]},
             "rig_time_s": float(rig.elapsed_s)}
    pipeline.write_register_outputs(None, result, extra=extra, output=out)
    progress(1.0, verdict["summary"])
    return {"result": result, "blind_result": first, "plan": plan, "sections": table,
            "verdict": verdict, "files": files,
            "uncertainty_after_blind_mm": first.pose_uncertainty_mm,
            "pose_uncertainty_mm": result.pose_uncertainty_mm,
            "complete_rig_s": complete_rig_s, "complete_simulated_s": timing["complete_scan"]}
