"""A production lot: one report per point file of a folder, and DIR/summary.csv.

Each file gets out_dir/<file stem>/ with the `report` command's files. A file is done when its
folder holds result.json (written last and atomically) made from the same inputs, so a lot
interrupted midway resumes where it stopped; a bad file is reported in the summary and skipped.
"The same inputs" is result.json's ``batch_inputs``, written with it: the point file's and the
CAD file's SHA-256 and every option that changes a result (tolerance, seed, fit, airfoil
options, the measurement model). A lot
run again with another tolerance, RIG.json or fit, or a point file scanned again under the
same name, has those files redone rather than a summary that mixes results made otherwise. Files run in parallel in
worker processes (concurrent.futures), or on a Dask distributed cluster when a scheduler
address is given; either way every worker loads the nominal once and keeps it.

A worker lost mid-file (killed, its machine gone) has the file run again elsewhere (Dask does
that by itself). Each run of a file begins by appending a line (host, process) to
out_dir/.attempts/<stem>, on disk before any work, so the summary's ``attempts`` column says
how many times a file was begun: more than one means it was retried. The folder goes when the
lot is complete.
"""

import csv
import dataclasses
import hashlib
import json
import os
import shutil
import socket
import sys
import threading
import time
from dataclasses import dataclass

from ..core.atomic_file import atomic_write
from ..core.contracts import BUILTIN_CADS, PROFILE_TOLERANCE_MM
from ..core.errors import InputError
from . import airfoil_stage as airfoil_mod
from .pipeline import load_nominal
from .report import run_report
from .run_options import RunOptions

POINT_EXTENSIONS = (".csv", ".xyz", ".asc", ".txt", ".ply", ".pcd")
SUMMARY_FIELDS = ["file", "status", "n_points", "rms_mm", "worst_deviation_mm", "verdict",
                  "pose_uncertainty_mm", "attempts"]
ATTEMPTS_FOLDER = ".attempts"
SECTION_FIELDS = ("n", "max_abs_mm", "rms_mm", "pct_within")

_NOMINALS = {}
_NOMINALS_LOCK = threading.Lock()


def _nominal_for(cad_path):
    """The worker's nominal, loaded on its first file and kept for the rest."""
    with _NOMINALS_LOCK:
        if cad_path not in _NOMINALS:
            _NOMINALS[cad_path] = load_nominal(cad_path)
        return _NOMINALS[cad_path]


def point_files(scans_dir):
    """(stem used as folder name, path) of every point file in the folder, sorted by name; a
    stem shared by two files gets its extension appended so no report overwrites another."""
    if not os.path.isdir(scans_dir):
        raise InputError("%s: no such scans folder" % scans_dir)
    names = sorted(n for n in os.listdir(scans_dir)
                   if n.lower().endswith(POINT_EXTENSIONS)
                   and os.path.isfile(os.path.join(scans_dir, n)))
    if not names:
        raise InputError("%s: no point files (%s) in the folder"
                         % (scans_dir, ", ".join(POINT_EXTENSIONS)))
    stems = [os.path.splitext(n)[0] for n in names]
    out = []
    for name, stem in zip(names, stems):
        if stems.count(stem) > 1:
            stem = "%s_%s" % (stem, os.path.splitext(name)[1].lstrip(".").lower())
        out.append((stem, os.path.join(scans_dir, name)))
    return out


def _row_from_result_json(name, doc):
    verdict = doc.get("verdict") or {}
    dev = doc.get("deviation") or {}
    worst = max((dev.get("min"), dev.get("max")), key=lambda v: abs(v or 0.0))
    row = {"file": name, "status": "ok", "n_points": doc.get("n_points"),
           "rms_mm": doc.get("rms_mm"), "worst_deviation_mm": worst,
           # the decision rule's pass / not proven / fail, else today's pass/fail
           "verdict": verdict.get("verdict") or ("pass" if verdict.get("pass") else "fail"),
           "pose_uncertainty_mm": doc.get("pose_uncertainty_mm"), "error": ""}
    for sec in (doc.get("sections") or {}).get("sections", []):
        for key in SECTION_FIELDS:
            row["section_%s_%s" % (sec["label"], key)] = sec["optical"].get(key)
    return row


def _sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _as_json(value):
    """The options' JSON form for the inputs record (dataclasses as their fields)."""
    return dataclasses.asdict(value) if dataclasses.is_dataclass(value) else value


def lot_options(cad_path, tolerance, seed, allow_mismatch, airfoil, fit_choice,
                measurement_model):
    """What every file of the lot is made from besides its points (inputs_record)."""
    cad = {"cad": cad_path if cad_path in BUILTIN_CADS or cad_path is None
           else os.path.abspath(cad_path)}
    if cad_path is not None and cad_path not in BUILTIN_CADS:
        cad["cad_sha256"] = _sha256(cad_path)
    options = dict(cad, tolerance_mm=float(tolerance), seed=seed,
                   allow_mismatch=bool(allow_mismatch), airfoil=_as_json(airfoil),
                   fit=_as_json(fit_choice), measurement_model=_as_json(measurement_model))
    # one canonical JSON form, so that a record read back compares equal to a fresh one
    return json.loads(json.dumps(options, sort_keys=True, default=repr))


def inputs_record(points_path, options):
    return dict(options, points_file=os.path.basename(points_path),
                points_sha256=_sha256(points_path))


def _read_done(folder, record=None):
    """The folder's result.json, or None when it is not done: absent, unreadable, or (given
    ``record``) made from other inputs than ``record``. A result.json with no record (made by
    `report` into the lot, or by an earlier version) is taken when the tolerance it states is
    the record's: the verdict is against it."""
    path = os.path.join(folder, "result.json")
    if not os.path.exists(path):
        return None
    try:
        with open(path) as fh:
            doc = json.load(fh)
    except (OSError, ValueError):
        return None     # unreadable: the file is simply done again
    if record is None:
        return doc
    if not isinstance(doc, dict):
        return None
    if "batch_inputs" in doc:
        return doc if doc["batch_inputs"] == record else None
    return doc if doc.get("tolerance_mm") == record["tolerance_mm"] else None


def report_one(cad_path, points_path, folder, options, attempt_log=None, document=None,
               record=None):
    """One file of the lot, in whichever process runs it: a summary row, never an exception.
    ``options``: the lot's RunOptions (inspection.run_options), as for run_report (its
    measurement model read from the lot's RIG.json once, by run_batch); ``attempt_log``: the
    file this run is recorded in before it begins; ``document``: as for run_report (a
    module-level function, so that it pickles to a worker process); ``record``: the file's
    inputs (inputs_record), kept in its result.json."""
    # A Dask worker is a plain Python process, perhaps on another machine: FreeCAD is started
    # there as the command line starts it, with its module folders on the path (FreeCAD 1.0's
    # Part needs them, or crashes).
    from ..freecad_library import import_freecad
    import_freecad()
    name = os.path.basename(points_path)
    if attempt_log is not None:
        _record_attempt(attempt_log)
    try:
        run_report(cad_path, points_path, folder, options, nominal=_nominal_for(cad_path),
                   document=document, batch_inputs=record)
    except InputError as exc:
        return {"file": name, "status": "error", "error": str(exc)}
    except Exception as exc:  # a bug on one blade must not stop the line; it is reported
        return {"file": name, "status": "error",
                "error": "internal error: %s: %s" % (type(exc).__name__, exc)}
    return _row_from_result_json(name, _read_done(folder))


def _record_attempt(path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "a") as fh:
        fh.write("%s %d %.3f\n" % (socket.gethostname(), os.getpid(), time.time()))
        fh.flush()
        os.fsync(fh.fileno())


def attempts_of(out_dir, stem):
    """How many times the file ``stem`` of the lot in ``out_dir`` was begun (0: not yet)."""
    try:
        with open(os.path.join(out_dir, ATTEMPTS_FOLDER, stem)) as fh:
            return sum(1 for line in fh if line.strip())
    except FileNotFoundError:
        return 0


def write_summary(path, rows):
    """summary.csv: the fixed columns, per-section columns (union over files), error last;
    replaced atomically so a reader never sees half a file."""
    section_cols = sorted({k for r in rows for k in r if k.startswith("section_")},
                          key=_section_col_key)
    fields = SUMMARY_FIELDS + section_cols + ["error"]
    with atomic_write(path, newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        for r in rows:
            writer.writerow({k: _csv_value(r.get(k)) for k in fields})


def _section_col_key(col):
    """Order section columns by section (numerically when labels are numbers), then field."""
    rest = col[len("section_"):]
    field = next(f for f in SECTION_FIELDS if rest.endswith("_" + f))
    label = rest[:-len(field) - 1]
    try:
        return (0, float(label), "", SECTION_FIELDS.index(field))
    except ValueError:
        return (1, 0.0, label, SECTION_FIELDS.index(field))


def _csv_value(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return "%.6g" % v
    return v


def run_batch(cad_path, scans_dir, out_dir, options=None, workers=None, scheduler=None,
              progress=None, document=None):
    """Report every point file of ``scans_dir`` into ``out_dir``/<stem>/ and write
    ``out_dir``/summary.csv. ``workers`` processes (default: one per CPU; 1 runs here), or the
    Dask cluster at ``scheduler`` ('tcp://HOST:PORT'). Returns {'rows': the summary rows in
    file order, each with 'reused' True when the file was already done, 'summary_csv': path,
    'message': one line for the command line}. ``options``: inspection.run_options.RunOptions
    of every file, as for `report` (its tolerance, seed, allow_mismatch, airfoil, fit and
    measurement model, the rig calibration's term from `--rig-file`, make the inputs record);
    with ``options.airfoil`` also ``out_dir``/summary_airfoil.csv (inspection.airfoil_stage);
    ``document``: the writer of each file's inspection.FCStd, as for report.run_report."""
    options = options or RunOptions()
    progress = progress or (lambda f, m: None)
    tolerance = float(options.tolerance)
    if not tolerance > 0:
        raise InputError("--tolerance: must be a positive number of mm, got %r" % (tolerance,))
    if cad_path is not None and not os.path.exists(cad_path) and cad_path not in BUILTIN_CADS:
        raise InputError("%s: no such CAD file" % cad_path)
    files = point_files(scans_dir)
    os.makedirs(out_dir, exist_ok=True)
    summary_path = os.path.join(out_dir, "summary.csv")

    options = options.replace(tolerance=tolerance)
    lot = _Lot(cad_path, out_dir, options, document, {})
    inputs = lot_options(cad_path, tolerance, options.seed, options.allow_mismatch,
                         options.airfoil, options.fit_choice, options.measurement_model)
    rows = {}
    todo = []
    records = lot.records
    redone = 0
    for stem, path in files:
        records[stem] = inputs_record(path, inputs)
        folder = os.path.join(out_dir, stem)
        doc = _read_done(folder, records[stem])
        if doc is not None:
            rows[stem] = dict(_row_from_result_json(os.path.basename(path), doc), reused=True)
        else:
            redone += os.path.exists(os.path.join(folder, "result.json"))
            todo.append((stem, path))

    def finished(stem, row):
        rows[stem] = dict(row, reused=False, attempts=attempts_of(out_dir, stem))
        # the summary is rewritten as files finish, so an interrupted lot still has one
        write_summary(summary_path, [rows[s] for s, _ in files if s in rows])
        progress(len(rows) / len(files), "%s: %s" % (row["file"], row.get("verdict") or
                                                     row.get("error")))

    t0 = time.perf_counter()
    if todo and scheduler:
        _run_dask(scheduler, lot, todo, finished)
    elif todo:
        _run_local(workers, lot, todo, finished)
    ordered = [rows[s] for s, _ in files]
    write_summary(summary_path, ordered)
    airfoil_mod.write_lot_csv(out_dir, files)   # summary_airfoil.csv
    # Every file is reported: the attempt counts are in the summary.
    shutil.rmtree(os.path.join(out_dir, ATTEMPTS_FOLDER), ignore_errors=True)
    count = {k: sum(1 for r in ordered if r["status"] == "ok" and r["verdict"] == k)
             for k in ("pass", "fail")}
    retried = ["%s (%d attempts)" % (r["file"], r["attempts"]) for r in ordered
               if (r.get("attempts") or 0) > 1]
    not_proven = sum(1 for r in ordered if r["status"] == "ok" and r["verdict"] == "not proven")
    message = ("%d files: %d pass, %d fail, %s%d error (%d already done%s, %.1f s)%s; %s"
               % (len(files), count["pass"], count["fail"],
                  "%d not proven, " % not_proven if not_proven else "",
                  sum(1 for r in ordered if r["status"] == "error"),
                  len(files) - len(todo),
                  "; %d done again: made from other inputs or options" % redone if redone
                  else "", time.perf_counter() - t0,
                  ("; retried after a lost worker: " + ", ".join(retried)) if retried else "",
                  summary_path))
    progress(1.0, message)
    return {"rows": ordered, "summary_csv": summary_path, "message": message}


def _spawn_context():
    """Worker processes started afresh, not forked: this process has threads (the distance and
    ray-cast pools, BLAS), and a child forked from it can wait forever on a lock one of them held
    (seen under FreeCAD 1.0). They run the distribution's Python, not FreeCADCmd, which is
    sys.executable in a batch run from FreeCADCmd; report_one starts FreeCAD in each."""
    import multiprocessing
    context = multiprocessing.get_context("spawn")
    executable = sys.executable
    if not os.path.basename(executable).startswith("python"):
        executable = os.path.join(sys.base_exec_prefix, "bin",
                                  "python%d.%d" % sys.version_info[:2])
    context.set_executable(executable)
    return context


def _attempt_log(out_dir, stem):
    # Absolute: a worker elsewhere runs in another folder (the lot's folder must be shared).
    return os.path.join(os.path.abspath(out_dir), ATTEMPTS_FOLDER, stem)


@dataclass
class _Lot:
    """What every file of a lot is reported with: the CAD, the lot's folder, the RunOptions,
    the document writer and each file's inputs record (by stem)."""
    cad_path: object
    out_dir: str
    options: RunOptions
    document: object
    records: dict


def _run_local(workers, lot, todo, finished):
    """The files ``todo`` of the ``lot`` in ``workers`` processes (1: here), ``finished``
    called with each file's row."""
    cad_path, out_dir, records = lot.cad_path, lot.out_dir, lot.records
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    if workers < 1:
        raise InputError("--workers: must be at least 1, got %d" % workers)
    if workers == 1 or len(todo) == 1:
        for stem, path in todo:
            finished(stem, report_one(cad_path, path, os.path.join(out_dir, stem),
                                      lot.options, _attempt_log(out_dir, stem), lot.document,
                                      records.get(stem)))
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed
    with ProcessPoolExecutor(max_workers=min(workers, len(todo)),
                             mp_context=_spawn_context()) as pool:
        futures = {pool.submit(report_one, cad_path, path, os.path.join(out_dir, stem),
                               lot.options, _attempt_log(out_dir, stem), lot.document,
                               records.get(stem)):
                   stem for stem, path in todo}
        for fut in as_completed(futures):
            finished(futures[fut], fut.result())


def _run_dask(scheduler, lot, todo, finished):
    """The files ``todo`` of the ``lot`` on the Dask cluster at ``scheduler``, ``finished``
    called with each file's row."""
    cad_path, out_dir, records = lot.cad_path, lot.out_dir, lot.records
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise InputError("--scheduler %s: the Dask 'distributed' package is not installed "
                         "(apt-get install python3-distributed)" % scheduler)
    try:
        client = Client(scheduler, timeout=10)
    except (OSError, TimeoutError) as exc:
        raise InputError("--scheduler %s: cannot reach the Dask scheduler (%s)"
                         % (scheduler, exc))
    try:
        stems, futures = {}, []
        # Workers run in other folders, perhaps on other machines (sharing these paths).
        cad = os.path.abspath(cad_path) if cad_path is not None else None
        for stem, path in todo:
            fut = client.submit(report_one, cad, os.path.abspath(path),
                                os.path.join(os.path.abspath(out_dir), stem), lot.options,
                                _attempt_log(out_dir, stem), lot.document, records.get(stem),
                                pure=False)
            stems[fut.key] = stem
            futures.append(fut)
        for fut in as_completed(futures):
            finished(stems[fut.key], fut.result())
    finally:
        client.close()
