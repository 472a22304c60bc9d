"""The inspection's checkpoint: what `inspect` has measured so far, kept in DIR/.checkpoint
while it runs (Checkpoint), and how a resumed run checks that it continues the same
inspection (inspection_identity) and puts the points file, the rig's pass numbering and the
journal back to where the interrupted run stood (start_or_resume). docs/maintainers.md
describes the fields.
"""

import json
import os
import shutil

import numpy as np

from ..core import contracts
from ..core.atomic_file import atomic_copy
from ..core.errors import InputError
from ..core.pointio import PointSet, read_points
from ..measurement.journal import JOURNAL_FILE, JournaledRig
from ..measurement.scan import POINTS_FILE, RECORD_FILE, check_same_rig, write_record

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


class Checkpoint:
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
                        atomic_copy(os.path.join(copy_from, name), self.path(name))
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


def inspection_identity(nominal, run_options, kinematics):
    """What a resumed inspection must share with the interrupted one to measure the same
    points (JSON-ready): of ``run_options`` (inspection.run_options.RunOptions, checked) the
    seed, section heights and the loop's options. Its ``loop.scan_options`` None: whatever the
    interrupted run used; ``loop.edge_radius_sigma_mm`` the planned sections' edge-density
    target (None: off)."""
    loop = run_options.loop
    options = None
    if loop.scan_options is not None:
        options = contracts.json_ready(loop.scan_options)
    sigma = loop.edge_radius_sigma_mm
    return {"cad_bbox": np.asarray(nominal.bbox_corners, dtype=float).tolist(),
            "seed": int(run_options.seed),
            "section_heights": [float(h) for h in run_options.section_heights],
            "complete": bool(loop.complete),
            "pitch_mm": float(loop.pitch) if loop.complete else None,
            "epsilon_mm": float(loop.epsilon), "kinematics": kinematics.to_dict(),
            "scan_options": options,
            "edge_radius_sigma_mm": None if sigma is None else float(sigma)}


IDENTITY_FLAGS = (("cad_bbox", "the CAD (its bounding box)"), ("seed", "--seed"),
                  ("section_heights", "--section-heights"), ("complete", "--complete"),
                  ("pitch_mm", "--pitch"), ("epsilon_mm", "epsilon"),
                  ("kinematics", "--rig-file"), ("scan_options", "the blind scan's options"),
                  ("edge_radius_sigma_mm", "--edge-radius-sigma"))


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


def start_or_resume(checkpoint, rig, resumed, fresh):
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


def save_plan(plan, checkpoint):
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
