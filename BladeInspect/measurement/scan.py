"""Open a rig and run the blind section scan into a folder: DIR/points.csv (table frame) and
DIR/scan.json (per-section record, times, the simulator's truth, the checkpoint).

Both files grow one COMPLETED section at a time: the points are appended, then scan.json is
replaced atomically (temporary file + os.replace) with a checkpoint holding the strategy's
state, the rig's pass counter, the byte length of points.csv and the number of passes it
holds. Within a section every pass goes to DIR/readings.journal as it ends (measurement.journal), so a
scan cut short - a DeviceError, a cancel, or a kill -9 / power cut mid-section - keeps its
finished sections and the finished passes of the section in flight. ``resume=True`` continues
after the last finished section: points.csv is cut back to the checkpoint (dropping a
section's rows appended just before the interruption), the strategy carries on from its saved
state, and the journal's passes are given back to it in place of the rig's until the rig
takes over at the pass that was in flight; so nothing is measured twice or lost and a
simulated rig reads exactly what it would have.
"""

import json
import os

import numpy as np

from .. import __version__
from ..core.atomic_file import atomic_write
from ..core.contracts import json_ready
from ..core.errors import DeviceError, InputError
from ..rig.kinematics import RigKinematics
from ..rig.serial_rig import SerialRig
from ..rig.simulated import SimulatedRig, simulated_rig_for
from .journal import JOURNAL_FILE, JournaledRig, inner_rig
from .strategy import ScanOptions, ScanStrategy, StrategyState

POINTS_FILE = "points.csv"
RECORD_FILE = "scan.json"
POINTS_HEADER = "x,y,z,snr,section,angle_deg\n"
# Per pass on a real rig, beyond motion and acquisition: stopping, arming the trigger and
# reading the sensor's buffer out (a few hundred ms on a serial line).
PASS_OVERHEAD_S = 0.3


def open_rig(spec, nominal=None, seed=0, kinematics=None, **rig_options):
    """``sim``: a SimulatedRig of ``nominal`` (None: the demo blade) clamped at a random
    fixture pose drawn from ``seed``, with ``kinematics`` as its true geometry (default
    nominal); ``serial:PORT`` (or ``serial:MOTION,SENSOR``): the serial driver."""
    spec = str(spec)
    if spec == "sim":
        if nominal is None:
            nominal = demo_nominal()
        return simulated_rig_for(nominal, seed=seed, kinematics=kinematics, **rig_options)
    if spec.startswith("serial:") and len(spec) > len("serial:"):
        return SerialRig(spec[len("serial:"):], **rig_options)
    raise InputError("--rig %s: expected sim or serial:PORT" % spec)


def demo_nominal():
    """The built-in demo blade as a Nominal (what ``sim`` measures without a CAD)."""
    # cad/ needs FreeCAD; measurement/ imports without it (a scan of a given nominal)
    from ..cad.demo_blade import make_demo_blade
    from ..cad.nominal import nominal_from_shape
    model = make_demo_blade()
    return nominal_from_shape(model.shape, roles=model.roles)


def scan_to_dir(out_dir, rig, n_sections=5, seed=0, resume=False, progress=None, phase=None,
                on_record=None, **strategy_options):
    """Run the blind scan (measurement.strategy.ScanStrategy; ``strategy_options`` are
    ScanOptions' fields and ``kinematics``) and write it to ``out_dir`` section by section.
    Returns the scan record (what scan.json holds, plus ``points``: the number of points). ``progress(fraction, message)`` is called per section.
    ``phase``: a value for a last ``phase`` column of points.csv (``inspect`` appends its
    planned rows to the same file). ``on_record(record)`` may add to each scan.json before it
    is written. ``rig`` may be journaled already (measurement.journal.JournaledRig: the caller keeps
    the journal, as `inspect` does); else the journal is DIR/readings.journal, removed when the
    scan is complete.

    A folder holding a previous scan is an InputError unless ``resume``; on resume the saved
    options are used (the scan continues as it began) and the rig must be the same one."""
    if not out_dir:
        raise InputError("--out: a folder is required")
    points_path = os.path.join(out_dir, POINTS_FILE)
    record_path = os.path.join(out_dir, RECORD_FILE)
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise InputError("--out %s: exists and is not a folder" % out_dir)
    has_record = os.path.exists(record_path)
    if not resume and (has_record or os.path.exists(points_path)):
        raise InputError("--out %s: holds a previous scan (use --resume to continue it, or "
                         "another folder)" % out_dir)
    fresh = not (resume and has_record)
    if fresh:
        if os.path.exists(points_path):
            raise InputError("--out %s: has %s but no %s to resume from"
                             % (out_dir, POINTS_FILE, RECORD_FILE))
        options = dict(strategy_options, n_sections=int(n_sections))
        record = _new_record(rig, seed, options)
        record["phase_column"] = phase
        state = None
    else:
        record = _load_record(record_path)
        check_same_rig(record, rig, seed, record_path)
        options = record["options"]
        state = StrategyState.from_dict(record["checkpoint"]["strategy"])
    scan_options, kinematics = _strategy_options(options)
    if fresh:
        # A bad option fails here, before anything is written.
        ScanStrategy(rig, scan_options, kinematics=kinematics)
        os.makedirs(out_dir, exist_ok=True)
    own_journal = not isinstance(rig, JournaledRig)
    if own_journal:
        rig = JournaledRig(rig, os.path.join(out_dir, JOURNAL_FILE), keep=not fresh)
    if fresh:
        with open(points_path, "w") as f:
            f.write(POINTS_HEADER if phase is None else POINTS_HEADER[:-1] + ",phase\n")
        record["checkpoint"]["points_bytes"] = os.path.getsize(points_path)
        record["checkpoint"]["journal_passes"] = rig.passes
        _write(record_path, record, on_record)
    else:
        _truncate_points(points_path, record["checkpoint"]["points_bytes"])
        rig.resume(record["checkpoint"].get("journal_passes"))
    strategy = ScanStrategy(rig, scan_options, kinematics=kinematics, state=state)
    start_elapsed = rig.elapsed_s
    base_simulated = record["simulated_s"]
    try:
        for section in strategy.sections(progress):
            _append_points(points_path, section, record.get("phase_column"))
            record["sections"].append(_section_record(section))
            record["points"] += int(len(section.snr))
            record["passes"] += section.passes
            record["simulated_s"] = base_simulated + (rig.elapsed_s - start_elapsed)
            record["real_time_s"] = _real_time(rig, record)
            record["section_y"] = [float(v) for v in strategy.section_y]
            record["complete"] = strategy.state.next_section >= len(strategy.section_y)
            record["checkpoint"] = {"strategy": strategy.state.to_dict(),
                                    "points_bytes": os.path.getsize(points_path),
                                    "journal_passes": rig.passes}
            _write(record_path, record, on_record)
            rig.commit()
    except InputError as exc:
        # A device failure leaves the scan to resume; a scan that found nothing to measure
        # leaves nothing that looks like a result.
        if fresh and not record["sections"] and not isinstance(exc, DeviceError):
            for path in (points_path, record_path) + ((rig.path,) if own_journal else ()):
                if os.path.exists(path):
                    os.remove(path)
        raise
    if own_journal and record["complete"]:
        os.remove(rig.path)
    if progress is not None:
        progress(1.0, "scan complete: %d sections, %d points"
                 % (len(record["sections"]), record["points"]))
    return record


# ---------------------------------------------------------------- record

def _write(path, record, on_record):
    if on_record is not None:
        on_record(record)
    write_record(path, record)


def _strategy_options(options):
    """scan.json's ``options`` as ScanStrategy's arguments: (ScanOptions, kinematics)."""
    options = dict(options)
    kinematics = options.pop("kinematics", None)
    if isinstance(kinematics, dict):
        kinematics = RigKinematics.from_dict(kinematics, "scan.json options")
    return ScanOptions.from_dict(options), kinematics


def _new_record(rig, seed, options):
    sensor = rig.sensor
    record = {
        "software": {"name": "BladeInspect", "version": __version__},
        "kind": "blind section scan",
        "rig": type(inner_rig(rig)).__name__,
        "seed": int(seed),
        "options": json_ready(options),
        "sensor": sensor.to_dict() if hasattr(sensor, "to_dict") else None,
        "frame": "rotary table (machine frame turned back by the rotary angle)",
        "complete": False,
        "sections": [],
        "section_y": None,
        "points": 0,
        "passes": 0,
        "simulated_s": 0.0,
        "real_time_s": 0.0,
        "checkpoint": {"strategy": StrategyState().to_dict(), "points_bytes": 0},
    }
    truth = getattr(rig, "table_to_cad", None)
    if truth is not None:
        record["table_to_cad"] = np.asarray(truth, dtype=float).tolist()
        record["rig_seed"] = int(getattr(rig, "seed", seed))
    return record


def check_same_rig(record, rig, seed, path):
    """InputError unless ``rig`` and ``seed`` are those the scan in ``record`` was begun with
    (the rig's kind, and a simulated part's clamping)."""
    if int(record.get("seed", seed)) != int(seed):
        raise InputError("%s: the scan was made with seed %s, not %s"
                         % (path, record.get("seed"), seed))
    kind = type(inner_rig(rig)).__name__
    if record.get("rig") != kind:
        raise InputError("%s: the scan was made on a %s rig, not a %s"
                         % (path, record.get("rig"), kind))
    truth = getattr(rig, "table_to_cad", None)
    if truth is not None and "table_to_cad" in record:
        if not np.allclose(np.asarray(record["table_to_cad"]), truth, atol=1e-9):
            raise InputError("%s: the simulated part is clamped differently from the scan "
                             "being resumed (another CAD or seed?)" % path)


def _load_record(path):
    try:
        with open(path) as f:
            record = json.load(f)
    except (OSError, ValueError) as exc:
        raise InputError("%s: not a readable scan record (%s)" % (path, exc))
    checkpoint = record.get("checkpoint") if isinstance(record, dict) else None
    if (not isinstance(checkpoint, dict) or "strategy" not in checkpoint
            or "points_bytes" not in checkpoint or "options" not in record
            or not isinstance(record.get("sections"), list)):
        raise InputError("%s: not a scan record with a checkpoint" % path)
    return record


def write_record(path, record):
    """Replace the JSON file ``path`` by ``record`` atomically (temporary file, fsync,
    os.replace): a reader, or a resume after a crash, sees the old record or the new one."""
    with atomic_write(path) as f:
        json.dump(record, f, indent=1)
        f.write("\n")


def _truncate_points(path, size):
    if not os.path.exists(path) or os.path.getsize(path) < size:
        raise InputError("%s: shorter than its checkpoint in %s (the scan folder was changed)"
                         % (path, RECORD_FILE))
    with open(path, "r+b") as f:
        f.truncate(size)


def _append_points(path, section, phase=None):
    rows = np.column_stack([section.table_xyz, section.snr])
    end = "\n" if phase is None else ",%s\n" % phase
    lines = [("%.6f,%.6f,%.6f,%.6f,%d,%.6f" % (x, y, z, s, section.index, a)) + end
             for (x, y, z, s), a in zip(rows, section.angle_deg)]
    with open(path, "a") as f:
        f.write("".join(lines))
        f.flush()
        os.fsync(f.fileno())


def _section_record(section):
    return {"index": int(section.index),
            "y": float(section.y),
            "base_angle_deg": float(section.base_angle_deg),
            "points": int(len(section.snr)),
            "passes": int(section.passes),
            "max_standoff_error_mm": float(section.max_standoff_error_mm),
            "simulated_s": float(section.simulated_s),
            "views": [{"name": v.name, "angle_deg": float(v.angle_deg),
                       "points": int(len(v.snr)), "passes": v.passes}
                      for v in section.views]}


def _real_time(rig, record):
    """A simulated rig's time plus the per-pass overhead a real one adds; a real rig's
    elapsed time is already real."""
    if isinstance(inner_rig(rig), SimulatedRig):
        return record["simulated_s"] + PASS_OVERHEAD_S * record["passes"]
    return record["simulated_s"]
