"""A rig whose every pass is written to a journal file as it ends, so that a process killed
outright (kill -9, a power cut) loses at most the pass in flight.

The checkpoints of `scan` and `inspect` are kept per completed section (or raster pass): a
section is many passes, and what a hard kill cuts short cannot be saved at the moment it
happens. So each pass's readings are appended to the journal as soon as the rig returns them
(full precision, flushed and fsync'd), closed by an ``end`` line. The checkpoint records how
many passes of the run it holds (``journal_passes``); on resume the journal's passes from that
number on are given back to the scan in place of the rig's (the scan asks for the same passes
in the same order, since it depends only on the readings), then the rig takes over with the
pass numbering where the journal left it. Nothing is measured twice; a pass without its
``end`` line (the one in flight, or a line cut by the kill) is dropped.

Format, one pass::

    pass {"seq": 12, "k": 3, "angle_deg": 30.0, "rig_s": 0.41, "next_pass_index": 13, "meta": {...}}
    x,y,z,reading_mm,snr        (k lines: the stage position and the reading, nan when none)
    end 12
"""

import collections
import json
import os

import numpy as np

from ..core import background
from ..core.errors import InputError
from ..rig.base import Readings

JOURNAL_FILE = "readings.journal"


def inner_rig(rig):
    """The rig itself when ``rig`` is journaled (its kind, its simulated truth)."""
    return rig.rig if isinstance(rig, JournaledRig) else rig


class JournaledRig:
    """``rig`` with its passes journaled to ``path``: created empty for a new run, or
    ``keep`` for one to resume. Everything other than the passes is the rig's own."""

    def __init__(self, rig, path, keep=False):
        self.rig = rig
        self.path = path
        self.passes = 0         # passes of the whole run: those a checkpoint holds, and since
        self._replay = collections.deque()
        self._replayed_s = 0.0
        self._next_index = None     # the rig's pass numbering after the replayed passes
        with open(path, "a" if keep else "w") as fh:
            _sync(fh)

    def __getattr__(self, name):
        if name == "rig":       # not set yet (a copy being made): no recursion
            raise AttributeError(name)
        return getattr(self.rig, name)

    # -- resume --------------------------------------------------------------------------

    def resume(self, committed):
        """Continue a run whose checkpoint holds its first ``committed`` passes (None: a
        checkpoint from before the journal, which is then ignored). The journal's later
        passes are replayed; a pass cut short by the interruption is cut off the file."""
        entries, good_bytes = read_journal(self.path)
        with open(self.path, "r+b") as fh:
            fh.truncate(good_bytes if committed is not None else 0)
            _sync(fh)
        self.passes = int(committed or 0)
        self._replay.clear()
        if committed is None:
            return 0
        for entry in entries:
            if entry["seq"] < self.passes:
                continue    # already in the checkpoint (saved just before the journal's reset)
            if entry["seq"] != self.passes + len(self._replay):
                break
            self._replay.append(entry)
        return len(self._replay)

    def commit(self):
        """The owner has saved a checkpoint holding every pass so far: the journal restarts."""
        with open(self.path, "r+b") as fh:
            fh.truncate(0)
            _sync(fh)

    # -- the Rig interface ----------------------------------------------------------------

    def scan_path(self, path_xyz, angle_deg):
        if self._replay:
            return self._replayed(path_xyz, angle_deg)
        if self._next_index is not None:
            if hasattr(self.rig, "set_pass_index"):
                self.rig.set_pass_index(self._next_index)
            self._next_index = None
        background.tick()    # a GUI's event loop turns between the passes
        start = float(self.rig.elapsed_s)
        readings = self.rig.scan_path(path_xyz, angle_deg)
        self._append(readings, float(self.rig.elapsed_s) - start)
        self.passes += 1
        return readings

    def set_pass_index(self, index):
        self._next_index = None
        if hasattr(self.rig, "set_pass_index"):
            self.rig.set_pass_index(index)

    @property
    def pass_index(self):
        if self._next_index is not None:
            return self._next_index
        return getattr(self.rig, "pass_index", None)

    @property
    def elapsed_s(self):
        """The rig's time, with that of the replayed passes (spent before the interruption)."""
        return float(self.rig.elapsed_s) + self._replayed_s

    def close(self):
        self.rig.close()

    # -- internals ------------------------------------------------------------------------

    def _replayed(self, path_xyz, angle_deg):
        entry = self._replay.popleft()
        path = np.asarray(path_xyz, dtype=float)
        if (path.shape != entry["stage_xyz"].shape or not np.array_equal(path, entry["stage_xyz"])
                or float(angle_deg) != entry["angle_deg"]):
            raise InputError("%s: pass %d was measured along another path than the resumed scan "
                             "asks for (another rig file or software version?)"
                             % (self.path, entry["seq"]))
        self._replayed_s += entry["rig_s"]
        self._next_index = entry["next_pass_index"]
        self.passes += 1
        return Readings(entry["stage_xyz"].copy(), entry["angle_deg"], entry["reading_mm"].copy(),
                        entry["snr"].copy(), meta=dict(entry["meta"]))

    def _append(self, readings, rig_s):
        stage = np.asarray(readings.stage_xyz, dtype=float)
        reading = np.asarray(readings.reading_mm, dtype=float)
        snr = np.asarray(readings.snr, dtype=float)
        head = {"seq": self.passes, "k": int(len(stage)), "angle_deg": float(readings.angle_deg),
                "rig_s": rig_s, "next_pass_index": getattr(self.rig, "pass_index", None),
                "meta": {k: v for k, v in (readings.meta or {}).items()
                         if isinstance(v, (str, int, float, bool, type(None)))}}
        lines = ["pass " + json.dumps(head) + "\n"]
        lines += ["%r,%r,%r,%r,%r\n" % (x, y, z, d, s)
                  for (x, y, z), d, s in zip(stage.tolist(), reading.tolist(), snr.tolist())]
        lines.append("end %d\n" % self.passes)
        with open(self.path, "a") as fh:
            fh.write("".join(lines))
            _sync(fh)


def read_journal(path):
    """(complete passes in file order, byte length of the file up to the last of them). A
    pass without its end line is the one a kill cut short, and so is a last line without its
    newline; damage followed by another pass is not, and is an InputError."""
    if not os.path.exists(path):
        return [], 0
    with open(path, "rb") as fh:
        data = fh.read()
    entries, good, pos = [], 0, 0
    while pos < len(data):
        try:
            entry, pos = _parse_pass(data, pos)
        except (ValueError, KeyError, TypeError) as exc:
            if data.find(b"\npass ", pos) >= 0:
                raise InputError("%s: damaged at byte %d (%s)" % (path, pos, exc)) from None
            break
        entries.append(entry)
        good = pos
    return entries, good


def _parse_pass(data, pos):
    def line():
        nonlocal pos
        end = data.find(b"\n", pos)
        if end < 0:
            raise ValueError("cut short")
        text = data[pos:end].decode("ascii")
        pos = end + 1
        return text
    head = line()
    if not head.startswith("pass "):
        raise ValueError("a pass must begin with 'pass'")
    entry = json.loads(head[5:])
    k = int(entry["k"])
    rows = np.array([[float(v) for v in line().split(",")] for _ in range(k)],
                    dtype=float).reshape(k, 5)
    if line() != "end %d" % entry["seq"]:
        raise ValueError("pass %s has no end line" % entry["seq"])
    entry.update(stage_xyz=rows[:, :3], reading_mm=rows[:, 3], snr=rows[:, 4],
                 angle_deg=float(entry["angle_deg"]), rig_s=float(entry["rig_s"]),
                 seq=int(entry["seq"]))
    return entry, pos


def _sync(fh):
    fh.flush()
    os.fsync(fh.fileno())
