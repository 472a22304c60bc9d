"""The airfoil uncertainty task file: the re-fit draws' 1 sigma of each section (and the
task's nominal cuts), made once for a measurement task -- this CAD, these planes and options,
this sensor, fit and calibration (``task_key``) -- and reused by every later blade of the task
whose section still matches the conditions they were made under (MATCH_RULE); a section that
does not is re-fitted afresh and says why. The file is written once, atomically; a file that is
not a task file or was made for another task is refused with a one-line InputError naming it.
"""

import datetime
import hashlib
import json
import os
from dataclasses import asdict, dataclass, field

import numpy as np

from ..core.atomic_file import atomic_write
from ..core.errors import InputError
from . import uncertainty as uncertainty_mod
from .airfoil_measure import on_smooth_fit
from .airfoil_uncertainty import (maxima_bias, point_noise_model, refit_uncertainty,
                                  sensor_of)
from .airfoil_values import flat, unflat

# Raise whenever the re-fit draws' model (inspection.airfoil_uncertainty.refit_uncertainty,
# point_noise_model, inspection.airfoil_measure.measure) or the key's layout changes: files of
# another version are refused, never read as this one's. A changed airfoil definition or
# kernel needs no raise: the key holds the definition and its kernel version.
TASK_MODEL_VERSION = 4
FILE_KIND = "BladeInspect airfoil task uncertainty"
DEFAULT_TASK_DRAWS = 48
# The match rule: relative half-widths about the stored conditions.
MATCH_RULE = {"n_points": 0.10, "noise_mm": 0.20, "pose_translation_mm": 0.50,
              "pose_rotation_rad": 0.50}
# Conditions this small count as zero (a pose covariance of a fixed pose).
CONDITION_FLOOR = {"n_points": 1.0, "noise_mm": 1e-9, "pose_translation_mm": 1e-12,
                   "pose_rotation_rad": 1e-15}
PLANE_LEVEL_MM = 0.05
PLANE_ANGLE_DEG = 0.05
MATCH_RULE_TEXT = ("a section reuses the task's draws when its plane is within %g mm and "
                   "%g deg of the task's, its point count within +-%d %%, its noise sigma "
                   "within +-%d %% and sqrt(trace) of the pose covariance's translation and "
                   "rotation parts each within +-%d %% of the task's; otherwise its u is "
                   "re-fitted afresh" % (PLANE_LEVEL_MM, PLANE_ANGLE_DEG,
                                         100 * MATCH_RULE["n_points"],
                                         100 * MATCH_RULE["noise_mm"],
                                         100 * MATCH_RULE["pose_translation_mm"]))


def cad_fingerprint(nominal):
    """sha256 of the nominal's dense samples (points to 0.1 um, outward normals to 1e-6, with
    their count): the same CAD loads to the same fingerprint in every run, and it changes with
    the CAD, the sample spacing and ``--flip-face``."""
    xyz = np.round(np.asarray(nominal.samples.xyz, dtype=float), 4) + 0.0   # no -0.0
    nrm = np.round(np.asarray(nominal.samples.normal, dtype=float), 6) + 0.0
    h = hashlib.sha256()
    h.update(np.int64(len(xyz)).tobytes())
    h.update(np.ascontiguousarray(xyz).tobytes())
    h.update(np.ascontiguousarray(nrm).tobytes())
    return "samples-sha256:" + h.hexdigest()


def _fit_of(result):
    fit = getattr(result, "fit", None) or {}
    weights = getattr(result, "weights", None) or {}
    return {"objective": fit.get("objective", "least-squares"), "free": fit.get("free", "all"),
            "weights_by_zone": fit.get("weights_by_zone"),
            "datum_faces": fit.get("datum_faces"), "weight_model": weights.get("model")}


def task_key(nominal, opts, result):
    """The task's key, a JSON-able dict of what the draws depend on: the model version, the
    CAD (cad_fingerprint), the airfoil options that change the values, the sensor, the rig
    calibration (only when the run has it), the registration's fit and weight model, and which
    readings carry SNR and beams. Sections are not part of it: a run of fewer or other
    sections is the same task, each section found by its label."""
    key = {"version": TASK_MODEL_VERSION,
           "cad": cad_fingerprint(nominal),
           "engine_axis": [round(float(v), 9) for v in opts.engine_axis],
           "definition": opts.definition.as_dict(),
           "sensor": json.loads(json.dumps(asdict(sensor_of(opts)))),
           "fit": _fit_of(result),
           "readings": {"snr": result.snr is not None,
                        "beams": uncertainty_mod.beam_directions(result) is not None}}
    if opts.calibration_mm:     # only when given: the files of runs without one stay valid
        key["calibration_mm"] = round(float(opts.calibration_mm), 12)
    if opts.calibration_axis is not None:
        key["calibration_axis"] = {name: np.asarray(opts.calibration_axis[name],
                                                     dtype=float).tolist()
                                   for name in ("parameters", "covariance")}
    return key


def digest(key):
    return hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:16]


def conditions(result, n_points, noise):
    """The conditions a section's draws hold for (MATCH_RULE's quantities)."""
    cov = np.asarray(result.pose_covariance, dtype=float)
    cov = np.where(np.isfinite(cov), cov, 0.0)
    return {"n_points": int(n_points), "noise_mm": float(noise),
            "pose_translation_mm": float(np.sqrt(max(np.trace(cov[:3, :3]), 0.0))),
            "pose_rotation_rad": float(np.sqrt(max(np.trace(cov[3:, 3:]), 0.0)))}


def mismatch(stored, now):
    """Why a section's conditions ``now`` are outside the match rule of the ``stored`` ones
    (an empty list when they match)."""
    out = []
    for name, rel in MATCH_RULE.items():
        a, b = float(now[name]), float(stored[name])
        floor = CONDITION_FLOOR[name]
        if abs(a - b) > rel * max(abs(b), floor) and max(abs(a), abs(b)) > floor:
            out.append("%s %.4g against the task's %.4g (+-%d %%)" % (name, a, b, 100 * rel))
    return out


def plane_mismatch(stored, plane):
    n0 = np.asarray(stored["normal"], dtype=float)
    o0 = np.asarray(stored["origin"], dtype=float)
    n1 = np.asarray(plane.normal, dtype=float)
    n1 = n1 / np.linalg.norm(n1)
    angle = float(np.degrees(np.arccos(np.clip(abs(n0 @ n1), -1.0, 1.0))))
    level = float(abs((np.asarray(plane.origin, dtype=float) - o0) @ n0))
    out = []
    if level > PLANE_LEVEL_MM:
        out.append("plane %.4g mm from the task's (%g allowed)" % (level, PLANE_LEVEL_MM))
    if angle > PLANE_ANGLE_DEG:
        out.append("plane normal %.4g deg from the task's (%g allowed)" % (angle, PLANE_ANGLE_DEG))
    return out


def _now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


@dataclass
class TaskUncertainty:
    """A task file's contents (or one being made: ``made`` False until saved)."""
    key: dict
    draws: int
    seed: int
    made_utc: str = None
    made_from: str = ""
    sections: dict = field(default_factory=dict)    # label -> {plane, conditions, sd}
    path: str = None
    made: bool = True
    # the nominal cuts' characteristics (airfoil_stage.nominal_characteristics' key ->
    # kernel.characteristics_state): a task's nominal is the same for every blade of it
    nominal: dict = field(default_factory=dict)

    def describe(self):
        return ("task-specific (file %s, made from %d draws on %s, seed %d%s)"
                % (self.path or "in memory", self.draws, self.made_utc, self.seed,
                   ", blade %s" % self.made_from if self.made_from else ""))

    def to_json(self):
        return {"kind": FILE_KIND, "version": TASK_MODEL_VERSION, "key": self.key,
                "key_digest": digest(self.key), "draws": self.draws, "seed": self.seed,
                "made_utc": self.made_utc, "made_from": self.made_from,
                "match_rule": MATCH_RULE_TEXT, "sections": self.sections,
                "nominal": self.nominal, "nominal_digest": digest(self.nominal)}

    def finish(self):
        """A task just made: written to its file (when a section was measured), or marked
        made in memory."""
        if self.path is None:
            self.made_utc, self.made = _now(), True
        elif self.sections:
            self.save()

    def save(self, path=None):
        """Written atomically: a temporary file beside the target, then os.replace."""
        path = path or self.path
        self.made_utc = self.made_utc or _now()
        with atomic_write(path) as fh:
            json.dump(self.to_json(), fh, indent=1, allow_nan=False)
        self.path, self.made = path, True
        return path


def load(path):
    """The task file at ``path``; a one-line InputError when it is not one (corrupt JSON,
    another kind of file, another model version, a damaged key or nominal cuts)."""
    try:
        with open(path) as fh:
            doc = json.load(fh)
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError("%s: cannot read the uncertainty task file (%s)" % (path, exc))
    except ValueError as exc:
        raise InputError("%s: not an uncertainty task file: corrupt JSON (%s); delete it to "
                         "compute the task afresh" % (path, str(exc).splitlines()[0]))
    if not isinstance(doc, dict) or doc.get("kind") != FILE_KIND:
        raise InputError("%s: not an uncertainty task file (no kind %r)" % (path, FILE_KIND))
    if doc.get("version") != TASK_MODEL_VERSION:
        raise InputError("%s: uncertainty task file of model version %r, this is version %d: "
                         "delete it to compute the task afresh"
                         % (path, doc.get("version"), TASK_MODEL_VERSION))
    try:
        key, sections = doc["key"], doc["sections"]
        draws, seed = int(doc["draws"]), int(doc["seed"])
        if not isinstance(key, dict) or not isinstance(sections, dict):
            raise TypeError("key or sections")
        if doc.get("key_digest") != digest(key):
            raise ValueError("its key does not match its key_digest")
        for label, s in sections.items():
            _ = (np.asarray(s["plane"]["origin"], dtype=float).reshape(3),
                 np.asarray(s["plane"]["normal"], dtype=float).reshape(3),
                 [float(s["conditions"][k]) for k in MATCH_RULE],
                 {k: (None if v is None else float(v)) for k, v in s["sd"].items()})
        # files made before the nominal cuts were kept have none (they are computed)
        nominal = doc.get("nominal") or {}
        if not isinstance(nominal, dict) or (nominal and doc.get("nominal_digest")
                                             != digest(nominal)):
            raise ValueError("its nominal cuts do not match their nominal_digest")
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError("%s: uncertainty task file is damaged (%s); delete it to compute the "
                         "task afresh" % (path, exc))
    return TaskUncertainty(key=key, draws=draws, seed=seed, made_utc=doc.get("made_utc"),
                           made_from=doc.get("made_from") or "", sections=sections, path=path,
                           nominal=nominal)


def check_file(path):
    """--uncertainty-task FILE: a file that exists must be a task file (fails early)."""
    if path is not None and os.path.exists(path):
        load(path)


def open_task(spec, key, opts, result):
    """The task for a run: ``spec`` a path (loaded when it exists, else a new task to make and
    write there) or a TaskUncertainty (in memory; made when empty). A task made for another
    key is refused (InputError naming what differs)."""
    if isinstance(spec, TaskUncertainty):
        task = spec
        if not task.sections and not task.made:
            task.key = key
    elif os.path.exists(spec):
        task = load(spec)
    else:
        return TaskUncertainty(key=key, draws=int(opts.task_draws), seed=int(opts.seed),
                               made_from=getattr(result, "source", "") or "", path=spec,
                               made=False)
    if task.key != key:
        differ = sorted(k for k in set(task.key) | set(key) if task.key.get(k) != key.get(k))
        raise InputError("%s: uncertainty task file made for another task (differs in %s); "
                         "use another file or delete it to compute this task afresh"
                         % (task.path or "task", ", ".join(differ)))
    return task


def section_maxima_bias(m, opts):
    """{form key: bias} of one blade's section ``m`` (an airfoil_measure.SectionMeasurement),
    with the inputs airfoil_uncertainty.refit_uncertainty gives maxima_bias (kept in step with
    it: tests/test_airfoil_task_u.py checks that the task's u of the blade that made it is that
    blade's re-fit u)."""
    pts, _, out_normal = on_smooth_fit(m.result, m.idx, m.frame, m.measured)
    sensor = sensor_of(opts)
    sigma = point_noise_model(m.result, m.idx, sensor, m.noise_mm, out_normal)[0]
    return maxima_bias(m.result, m.idx, pts, m.nominal, m.fit, sigma, sensor)


def section_uncertainty(task, sr, m, opts, rng):
    """The block's ``uncertainty`` of one measured section ``m`` (an
    airfoil_measure.SectionMeasurement, ``sr`` its stage SectionResult) under a task: the
    task's draws when the section matches, else made (a task being made) or re-fitted afresh;
    records how on the block and in ``sr.notes``. Returns ("task" | "made" | "re-fit",
    reason)."""
    result, idx, noise, measured_values = m.result, m.idx, m.noise_mm, m.values
    label = sr.plane.label
    now = conditions(result, len(idx), noise)
    block = sr.block
    if not task.made:
        sd = {}
        u = refit_uncertainty(m, _with_draws(opts, task.draws), rng, draws_sd=sd)
        block["uncertainty"] = u
        if u is not None:
            task.sections[label] = {
                "plane": {"origin": np.asarray(sr.plane.origin, float).tolist(),
                          "normal": (np.asarray(sr.plane.normal, float)
                                     / np.linalg.norm(sr.plane.normal)).tolist()},
                "conditions": now,
                "sd": {k: (None if not np.isfinite(v) else float(v)) for k, v in sd.items()}}
        block["uncertainty_method"] = "task-specific, made on this blade"
        block["uncertainty_draws"] = task.draws
        return "made", None
    stored = task.sections.get(label)
    why = (["section not in the task file"] if stored is None else
           plane_mismatch(stored["plane"], sr.plane) + mismatch(stored["conditions"], now))
    if why:
        sr.notes.append("uncertainty: the task's draws not used (%s): re-fitted afresh, "
                        "%d draws" % ("; ".join(why), opts.draws))
        block["uncertainty"] = refit_uncertainty(m, opts, rng) if opts.draws else None
        block["uncertainty_method"] = "re-fit"
        block["uncertainty_draws"] = int(opts.draws)
        return "re-fit", "; ".join(why)
    sd = {k: (float("nan") if v is None else float(v)) for k, v in stored["sd"].items()}
    for key, bias in section_maxima_bias(m, opts).items():
        if key in sd:
            sd[key] = float(np.hypot(sd[key], bias))
    keys = flat(measured_values).keys()
    block["uncertainty"] = unflat({k: sd[k] for k in keys if k in sd}, measured_values)
    block["uncertainty_method"] = "task-specific"
    block["uncertainty_draws"] = task.draws
    return "task", None


def _with_draws(opts, draws):
    import dataclasses
    return dataclasses.replace(opts, draws=int(draws))


def settings_of(task, used, refit_text):
    """The stage settings' fields of a task run: ``uncertainty_method`` and
    ``uncertainty_task`` (per section how its u was found)."""
    made_now = any(how == "made" for how, _ in used.values())
    head = task.describe() if not made_now else (
        "task-specific, made now (file %s, %d draws, seed %d)"
        % (task.path or "in memory", task.draws, task.seed))
    per = {label: ("task" if how == "task" else "made" if how == "made"
                   else "re-fit: %s" % why) for label, (how, why) in used.items()}
    text = "%s: the draws' 1 sigma of the task, form values add this blade's bias of a " \
           "maximum; sections outside the task's conditions: %s" % (head, refit_text)
    return {"uncertainty_method": text,
            "uncertainty_task": {"file": task.path, "made_utc": task.made_utc,
                                 "draws": task.draws, "seed": task.seed,
                                 "made_from": task.made_from, "key_digest": digest(task.key),
                                 "cad": task.key.get("cad"), "match_rule": MATCH_RULE_TEXT,
                                 "sections": per},
            "uncertainty_relative_accuracy_task": float(1.0 / np.sqrt(2.0 * (task.draws - 1)))}
