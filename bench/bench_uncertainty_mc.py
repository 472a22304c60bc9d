"""Monte Carlo over the whole measurement chain against the stated expanded uncertainty U (issue
16 item 5): does inspection/uncertainty.py's model (and inspection/airfoil_uncertainty.py's airfoil u) state
the scatter that the chain really has?

One `inspect` loop on the blade (simulated rig, default sensor, a 30 um bump on the suction side
at the first section, sections at 30 and 70 % span) is recorded once, reading by reading: the
stage position, rotary angle, true distance along the beam and incidence of every reading of the
blind scan and of the planned one. Each trial then measures those readings again with every error
the model states, drawn from its distribution:

- the sensor's noise, gross errors, rounding and gating (rig.sensor.SensorModel.read on the
  recorded true distances and incidences, a fresh stream per trial);
- the sensor's stated accuracy as a systematic term: one bias per trial, uniform in
  +-accuracy, added to every reading; the trials' biases are stratified (core.mc_sampling), so
  that a few trials cover the whole range;
- the rig calibration's error: the rotary axis the rig really has differs from the believed one
  by an error drawn from `calibrate`'s own covariance (one simulated calibration run here);

and goes on as the loop does: believed kinematics -> table-frame points -> ICP with the loop's
default weights (the sensor model's, inspection.weighting) of the blind and planned points
together (started at the true pose: the coarse stage finds the basin, not the answer) ->
Table 2 from the planned rows -> verdict on the whole result (each section's worst deviation
and the part's worst, with U) -> airfoil characteristics (no re-fits in the trials). The
stated u (k = 1) is U / 2 of the verdict, averaged over every trial (each verdict states it),
and the airfoil stage's own u (its default re-fits), averaged over the first STATED trials.

The worst deviation is a maximum over points: where several points compete for it the maximum
is biased up and scatters less than one reading. The table therefore gives, beside the
scatter (1 sd), the RMS error against the truth (the injected field's largest |value| over the
same points; for an airfoil characteristic, the noise-free chain's value); the verdict's U is
that of the error of a maximum (uncertainty.worst_terms). A value's scatter and RMS error take
the part that follows the trial's bias from the bias's known spread and only the rest from the
trials (core.mc_sampling.scatter_and_rms): a value the bias drives (a thickness, a chord) would
otherwise be judged on a handful of draws of one uniform variable. Column "judged" compares a
maximum (a worst deviation, form_mm, form_location_mm; marked *) with its RMS error, any other
value with its scatter. Trials more than 5 robust sigmas from the median are counted (column
"out"), not averaged in. `--sensitivity` prints instead what the systematic term really does
to each value through the chain (noise-free scans with a bias of +-accuracy).

    scripts/fcpython bench/bench_uncertainty_mc.py [--blade demo|rotor67|both] [--trials 40]
        [--seed 2026] [--stated 2] [--errors noise,systematic,calibration] [--sensitivity]
        [--reanalyse]

Each ratio comes with its bootstrap interval (the trials and the stated trials resampled): a
row outside +-30 % is "resolved" only when its whole interval is outside, else "unresolved"
(the run cannot tell it from a correct u). `--reanalyse` prints the table again from the
last run's saved trials, without running them.
"""
import argparse
import os
import pickle
import shutil
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from BladeInspect.core import mc_sampling  # noqa: E402
from BladeInspect.core import stats as stats_mod  # noqa: E402
from BladeInspect.core import transforms as tf  # noqa: E402
from BladeInspect.inspection import airfoil_stage as airfoil_mod  # noqa: E402
from BladeInspect.inspection import airfoil_values as values  # noqa: E402
from BladeInspect.inspection import pipeline  # noqa: E402
from BladeInspect.inspection import sections as sections_mod  # noqa: E402
from BladeInspect.inspection import uncertainty as uncertainty_mod  # noqa: E402
from BladeInspect.inspection import verdict as verdict_mod  # noqa: E402
from BladeInspect.inspection import weighting  # noqa: E402
from BladeInspect.inspection.result import RegistrationResult  # noqa: E402
from tests.helpers import suction_bump_at  # noqa: E402
from BladeInspect.measurement import calibration as calibration_mod  # noqa: E402
from BladeInspect.rig.kinematics import RigKinematics  # noqa: E402
from BladeInspect.rig.sensor import SensorModel  # noqa: E402
from BladeInspect.inspection.run_options import RunOptions  # noqa: E402

BEAM = np.array([0.0, 0.0, -1.0])
BUMP_HEIGHT = 0.03
BUMP_RADIUS = 6.0
OUTLIER_SIGMAS = 5.0
ERRORS = ("noise", "systematic", "calibration")
CACHE = os.path.join(tempfile.gettempdir(), "bi-mc-record-%s.pkl")


def code_version():
    """A digest of the package's sources: a recording is reused only by the code that made it
    (a loop planned by older code, e.g. before the edge-density rule, is another scan)."""
    import hashlib
    digest = hashlib.sha1()
    root = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        "BladeInspect")
    for folder, _, files in sorted(os.walk(root)):
        for name in sorted(files):
            if name.endswith(".py"):
                with open(os.path.join(folder, name), "rb") as fh:
                    digest.update(name.encode() + fh.read())
    return digest.hexdigest()[:12]


def blade(name):
    if name == "demo":
        return pipeline.load_nominal(None), (30.0, 70.0)
    from BladeInspect.cad.load import load_nominal
    from tests.helpers import ROTOR67_SECTIONS
    return load_nominal(ROTOR67_SECTIONS), (30.0, 70.0)


def bump_at(nominal, height_pct):
    """A bump on the suction side where the plane at ``height_pct`` crosses it (as
    tests/test_rotor67_loop.py builds it)."""
    return suction_bump_at(nominal, height_pct, BUMP_RADIUS, BUMP_HEIGHT)


def by_angle(fn, points, angles):
    """fn(points, angle) applied to the points of each rotary angle."""
    out = np.empty_like(points)
    for a in np.unique(angles):
        sel = angles == a
        out[sel] = fn(points[sel], a)
    return out


def record(name, seed):
    """The planned scan's readings as the rig made them: per reading the stage, angle, true
    distance (bump included), incidence, and the true table-frame point; plus the truth."""
    path = CACHE % ("%s-%d-%s" % (name, seed, code_version()))
    if os.path.exists(path):
        with open(path, "rb") as fh:
            return pickle.load(fh)
    from BladeInspect.inspection.closed_loop import run_inspect
    from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose_of
    import json
    nominal, heights = blade(name)
    axis, bump = bump_at(nominal, heights[0])
    truth = random_fixture_pose_of(nominal, np.random.default_rng(seed), axis)
    log = {}
    context = {}

    class RecordingSensor(SensorModel):
        def read(self, true_distance, incidence_rad, rng):
            log[context["index"]] = (context["stage"], context["angle"],
                                     np.array(true_distance, float),
                                     np.array(incidence_rad, float))
            return SensorModel.read(self, true_distance, incidence_rad, rng)

    rig = SimulatedRig(nominal, truth, sensor=RecordingSensor(), error_field=bump, seed=seed)
    measure = rig.measure

    def recording(stage_xyz, angle_deg, pass_index):
        context.update(index=int(pass_index), stage=np.atleast_2d(stage_xyz).astype(float),
                       angle=float(angle_deg))
        return measure(stage_xyz, angle_deg, pass_index)
    rig.measure = recording
    tmp = tempfile.mkdtemp(prefix="bi-mc-")
    try:
        run_inspect(None, tmp + "/out",
                    RunOptions.of(section_heights=heights, seed=seed,
                                  scan_options={"n_sections": 3}), rig=rig, nominal=nominal,
                    document=False)
        with open(os.path.join(tmp, "out", "scan.json")) as fh:
            scan = json.load(fh)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    # The loop's final fit takes the blind scan's points with the planned ones (closed_loop):
    # the passes before the first planned one are the blind scan's.
    planned = sorted({p["pass_index"] for p in scan["phases"]["planned"]["paths"]})
    blind = [i for i in sorted(log) if i < planned[0]]
    stage, angle, dist, inc, phase = [], [], [], [], []
    for i in blind + planned:
        s, a, d, c = log[i]
        stage.append(s)
        angle.append(np.full(len(s), a))
        dist.append(d)
        inc.append(c)
        phase.append(np.full(len(s), i in planned))
    rec = {"stage": np.vstack(stage), "angle": np.concatenate(angle),
           "distance": np.concatenate(dist), "incidence": np.concatenate(inc),
           "planned": np.concatenate(phase), "table_to_cad": truth, "heights": heights}
    nominal_k = RigKinematics()
    hit = np.isfinite(rec["distance"])
    for key in ("stage", "angle", "distance", "incidence", "planned"):
        rec[key] = rec[key][hit]
    machine = nominal_k.machine_point(rec["stage"], rec["distance"])
    rec["table"] = by_angle(nominal_k.table_point, machine, rec["angle"])
    with open(path, "wb") as fh:
        pickle.dump(rec, fh)
    return rec



def registered(nominal, xyz, snr, init, rng, angles, kinematics):
    """The loop's fine registration and its result (pipeline.register after the coarse
    stage, which only finds the basin the true pose starts in), with the loop's default
    weights (inspection.weighting: the sensor model's 1 / sigma_n^2, the readings carrying
    SNR and angle_deg) and its beams turned back by the believed ``kinematics``. The paper's
    SNR weights, which this bench used before, take up a reading bias of 6 um on Rotor 67
    as a 37 um shift along the span, the sensor weights as 4 um."""
    weight_model, _ = weighting.weights_for_rows(xyz, snr, angles, None, kinematics)
    fit = pipeline.fine_register(xyz, snr, nominal, init, rng=rng, weight_model=weight_model)
    points_cad = tf.apply_transform(fit.transform, xyz)
    dist = nominal.signed_distance(points_cad)
    inlier = np.asarray(fit.inlier, dtype=bool)
    covariance, statistical, _ = pipeline.pose_summary(fit, nominal)
    return RegistrationResult(
        measured_to_cad=fit.transform, points_cad=points_cad, deviation=dist.distance,
        inlier=inlier, closest=dist.closest, normal=dist.normal, face=dist.face, snr=snr,
        columns={"angle_deg": np.asarray(angles, dtype=float)}, n_rows_skipped=0,
        icp_weights=fit.weights, inlier_cut=fit.cut,
        rms_mm=float(np.sqrt(np.mean(dist.distance[inlier] ** 2))),
        pose_covariance=covariance, center=fit.center, pose_uncertainty_mm=float(statistical),
        deviation_stats=stats_mod.deviation_statistics(dist.distance), coarse={})


class Chain:
    """One blade's recorded scan, the rig's calibration (its covariance) and the model."""

    def __init__(self, name, seed, record_seed):
        self.name = name
        self.nominal, self.heights = blade(name)
        self.rec = record(name, record_seed)
        _, self.bump = bump_at(self.nominal, self.heights[0])
        self.sensor = SensorModel()
        self.believed = RigKinematics()
        calib = calibration_mod.run_calibration(None, seed=seed, axis_offset_mm=0.2,
                                                axis_tilt_deg=0.1)["uncertainty"]
        self.calibration = calib
        self.axis_cov = np.asarray(calib["calibration_covariance"])
        self.model = uncertainty_mod.MeasurementModel(
            sensor=self.sensor, calibration_mm=calib["calibration_uncertainty_mm"],
            calibration_source="simulated calibration",
            calibration_axis=uncertainty_mod.calibration_axis_of(calib, "simulated calibration"))
        truth_cad = tf.apply_transform(self.rec["table_to_cad"], self.rec["table"])
        self.field = np.asarray(self.bump(self.nominal.signed_distance(truth_cad).closest))

    def stage_sections(self, rng, **trial_args):
        """One trial (``trial``'s arguments) and the airfoil stage's SectionResults it made:
        the sections' points in their planes, noise, nominal and blocks."""
        kept = {}
        run_stage = airfoil_mod.run_stage

        def keeping(*a, **k):
            kept["stage"] = run_stage(*a, **k)
            return kept["stage"]
        airfoil_mod.run_stage = keeping
        try:
            self.trial(rng, **trial_args)
        finally:
            airfoil_mod.run_stage = run_stage
        return kept["stage"].sections

    def trial(self, rng, draws=0, errors=ERRORS, bias_mm=None):
        """One measurement of the recorded scan with the model's errors drawn afresh: the
        judged values {name: value}, their stated u (k = 1) {name: u} and the truth.
        ``bias_mm``: this trial's reading bias (run() draws the trials' biases stratified,
        core.mc_sampling); None draws one here when "systematic" is in ``errors``."""
        from BladeInspect.measurement.calibration_uncertainty import kinematics_with
        rec = self.rec
        reading, snr = self.sensor.read(rec["distance"], rec["incidence"], rng)
        ok = np.isfinite(reading)
        error = np.where(ok, reading - rec["distance"], 0.0)
        if "noise" not in errors:
            error[:] = 0.0
            snr = self.sensor.snr(rec["distance"], rec["incidence"])
            ok = snr > 0
        if bias_mm is not None:
            error = error + bias_mm
        elif "systematic" in errors:
            error = error + rng.uniform(-self.sensor.accuracy, self.sensor.accuracy)
        true_axis = self.believed
        if "calibration" in errors:
            d = np.linalg.cholesky(self.axis_cov + 1e-30 * np.eye(4)) @ rng.standard_normal(4)
            true_axis = kinematics_with(self.believed, np.zeros(4) + d)
        machine = by_angle(true_axis.machine_point_of_table, rec["table"], rec["angle"])
        machine[:, 2] -= error
        xyz = by_angle(self.believed.table_point, machine, rec["angle"])[ok]
        result = registered(self.nominal, xyz, snr[ok], rec["table_to_cad"],
                            np.random.default_rng(rng.integers(1 << 31)), rec["angle"][ok],
                            self.believed)
        field = self.field[ok]
        # As the loop judges (closed_loop._judge_after_blind): Table 2 from the planned rows,
        # indexed back into the whole result, which the verdict and the airfoil stage read.
        rows = np.flatnonzero(rec["planned"][ok])
        table = sections_mod.section_table(result.planned_rows(rows), self.nominal,
                                           heights_pct=self.heights)
        for sec in table.sections:
            sec.point_index = rows[sec.point_index]
        verdict = verdict_mod.judge(result, table, measurement_model=self.model)
        values, stated, truth = {}, {}, {}
        for sec, entry in zip(table.sections, verdict["sections"]):
            key = "worst deviation %s" % sec.label
            # Judged against +-T, the worst deviation's size is what decides; its sign flips
            # between trials where two opposite points compete.
            values[key] = abs(entry["worst_deviation_mm"])
            stated[key] = 0.5 * entry["U_mm"]
            truth[key] = float(np.max(np.abs(field[sec.point_index])))
        values["worst deviation part"] = abs(verdict["part"]["worst_deviation_mm"])
        stated["worst deviation part"] = 0.5 * verdict["part"]["U_mm"]
        truth["worst deviation part"] = float(np.max(np.abs(field[result.inlier])))
        # the stage states u as the product does: with the rig calibration's term when the
        # trials draw a calibration error (report/inspect take it from RIG.json)
        opts = airfoil_mod.Options(draws=draws, seed=int(rng.integers(1 << 31)),
                                   calibration_mm=(self.model.calibration_mm
                                                   if "calibration" in errors else None),
                                   calibration_axis=(self.model.calibration_axis
                                                     if "calibration" in errors else None))
        stage = airfoil_mod.run_stage(self.nominal, airfoil_mod.planes_of_table(table), opts,
                                      result, table.span_axis)
        for b in stage.blocks:
            for k, v in values.flat(b["measured"] or {}).items():
                values["%s %s" % (b["label"], k)] = v
            for k, v in values.flat(b["uncertainty"] or {}).items():
                stated["%s %s" % (b["label"], k)] = v
        return values, stated, truth, result


def is_maximum(key):
    """A judged value that is a maximum over points: a worst deviation, a contour's form."""
    return key.startswith("worst deviation") or any(
        key.endswith(" " + m) for m in values.MAXIMA)


def run(name, trials, seed, n_stated, errors=ERRORS, record_seed=31):
    t0 = time.perf_counter()
    chain = Chain(name, seed, record_seed)
    rng = np.random.default_rng(seed)
    reference, _, _, _ = chain.trial(np.random.default_rng(0), errors=())
    accuracy = chain.sensor.accuracy
    # the trials' reading biases stratified, and their share of each value's variance from
    # their known spread (core.mc_sampling: a few trials of a uniform term otherwise decide)
    biases = (mc_sampling.stratified_uniform(np.random.default_rng([seed, 1]), trials,
                                             accuracy) if "systematic" in errors else None)
    values, stated, truth = {}, {}, {}
    pose = []
    for k in range(trials):
        v, s, t, result = chain.trial(rng, draws=airfoil_mod.DEFAULT_DRAWS if k < n_stated
                                      else 0, errors=errors,
                                      bias_mm=None if biases is None else biases[k])
        pose.append(result.pose_uncertainty_mm)
        for key, x in v.items():
            values.setdefault(key, []).append(x)
        # the worst deviations' u comes with every trial's verdict; the airfoil stage's costs
        # its draws, so only the first n_stated trials state theirs
        for key, x in s.items():
            if k < n_stated or key.startswith("worst deviation"):
                stated.setdefault(key, []).append(x)
        for key, x in t.items():
            truth.setdefault(key, []).append(x)
    seconds = time.perf_counter() - t0
    with open(os.path.join(tempfile.gettempdir(), "bi-mc-%s-%s.pkl" % (name, "+".join(errors))),
              "wb") as fh:       # the trials' raw values, for a second look (--reanalyse)
        pickle.dump({"values": values, "stated": stated, "truth": truth,
                     "reference": reference, "biases": biases, "accuracy": accuracy,
                     "n_stated": n_stated, "trials": trials}, fh)
    print("\n%s (errors: %s): %d trials, seed %d, %.0f s wall; %d readings a scan; sensor accuracy %.1f um; "
          "calibration 1 sigma at the part %.2f um; pose 1 sigma (worst corner) %.2f um"
          % (name, ", ".join(errors), trials, seed, seconds, len(chain.rec["distance"]),
             1e3 * chain.sensor.accuracy, 1e3 * chain.model.calibration_mm,
             1e3 * np.mean(pose)))
    return judge(values, stated, truth, reference, biases, accuracy)


# The ratio u / scatter of one row is itself a random variable: u is a mean over the stated
# trials (each its own draws), the scatter a sample over the trials. A row is counted outside
# +-30 % as "resolved" only when its whole bootstrap interval is (resampling the trials and,
# apart, the stated trials); a row whose point ratio is outside but whose interval reaches
# into [0.7, 1.3] is "unresolved": the run cannot tell it from a correct u.
BOOTSTRAP = 2000
INTERVAL = (5.0, 95.0)


def _ratio_interval(u_values, err, bias, bias_sd, use_rms, rng):
    u_values = np.asarray(u_values, dtype=float)
    n, m = len(err), len(u_values)
    out = []
    for _ in range(BOOTSTRAP):
        i = rng.integers(0, n, n)
        sd, rms = mc_sampling.scatter_and_rms(err[i], None if bias is None else bias[i],
                                              bias_sd)
        spread = rms if use_rms else sd
        if spread > 0:
            out.append(np.mean(u_values[rng.integers(0, m, m)]) / spread)
    return tuple(np.percentile(out, INTERVAL)) if out else (np.nan, np.nan)


def judge(values, stated, truth, reference, biases, accuracy, seed=7):
    """The table: per judged value its stated u against the trials' scatter (a maximum: its
    RMS error against the truth), the ratio with its bootstrap interval, and the counts."""
    rng = np.random.default_rng(seed)
    lo, hi = INTERVAL
    print("%-30s %9s %9s %6s %5s %9s %6s %5s %9s %4s %6s %15s %10s"
          % ("characteristic", "stated u", "MC 1sd", "ratio", "30%", "MC rmserr", "ratio",
             "30%", "bias", "out", "judged", "%g-%g %% interval" % (lo, hi), "outside"))
    rows = []
    for key in sorted(values, key=lambda k: (not k.startswith("worst"), k)):
        if key.endswith("centroid_mm[2]") or key not in stated:
            continue
        v = np.asarray(values[key], dtype=float)
        u = float(np.mean(stated[key]))
        ref = np.asarray(truth[key]) if key in truth else reference.get(key, np.nan)
        err = v - ref
        # Trials beyond OUTLIER_SIGMAS robust sigmas of the median are counted, not averaged
        # in: a gross failure of one trial (an edge not found) is not the chain's scatter.
        mad = 1.4826 * np.median(np.abs(err - np.median(err)))
        keep = np.abs(err - np.median(err)) <= OUTLIER_SIGMAS * max(mad, 1e-12)
        bias = None if biases is None else np.asarray(biases)[keep]
        sd, rms = mc_sampling.scatter_and_rms(err[keep], bias, accuracy / np.sqrt(3.0))
        ratio, ratio_rms = u / sd if sd > 0 else np.nan, u / rms if rms > 0 else np.nan
        ok, ok_rms = 0.7 <= ratio <= 1.3, 0.7 <= ratio_rms <= 1.3
        # A maximum's U states its error against the truth (bias included), not its scatter.
        maximum = is_maximum(key)
        judged = ok_rms if maximum else ok
        a, b = _ratio_interval(stated[key], err[keep], bias, accuracy / np.sqrt(3.0),
                               maximum, rng)
        resolved = (not judged) and (b < 0.7 or a > 1.3)
        rows.append((key, u, sd, ratio, ok, rms, ratio_rms, ok_rms, judged, resolved))
        print("%-30s %9.5f %9.5f %6.2f %5s %9.5f %6.2f %5s %+9.5f %4d %6s %7.2f-%-7.2f %10s"
              % (key, u, sd, ratio, "yes" if ok else "NO", rms, ratio_rms,
                 "yes" if ok_rms else "NO", float(np.mean(err[keep])), int((~keep).sum()),
                 ("yes" if judged else "NO") + ("*" if maximum else ""), a, b,
                 "" if judged else ("resolved" if resolved else "unresolved")))
    print("%d of %d within +-30 %% of the scatter, %d of %d of the RMS error against the truth; "
          "judged (* maxima against the RMS error, the rest against the scatter): %d of %d; "
          "outside with the whole %g-%g %% interval outside: %d"
          % (sum(r[4] for r in rows), len(rows), sum(r[7] for r in rows), len(rows),
             sum(r[8] for r in rows), len(rows), lo, hi, sum(r[9] for r in rows)))
    return rows


def reanalyse(name, errors):
    """The table again from a run's saved trials (run() pickles them)."""
    path = os.path.join(tempfile.gettempdir(), "bi-mc-%s-%s.pkl" % (name, "+".join(errors)))
    with open(path, "rb") as fh:
        saved = pickle.load(fh)
    accuracy = saved.get("accuracy", SensorModel().accuracy)
    n = len(next(iter(saved["values"].values())))
    print("\n%s (errors: %s): %d trials re-analysed from %s"
          % (name, ", ".join(errors), n, path))
    return judge(saved["values"], saved["stated"], saved["truth"], saved["reference"],
                 saved["biases"], accuracy)


def systematic_sensitivity(name, seed, record_seed=31):
    """What the sensor's systematic term really does to each judged value through the whole
    chain: noise-free scans with a reading bias of +-accuracy, the registration included. For
    a rectangular bias the standard uncertainty is |d value / d bias| * accuracy / sqrt(3);
    the model states accuracy / sqrt(3) for a deviation (sensitivity 1) and nothing for an
    airfoil characteristic."""
    chain = Chain(name, seed, record_seed)
    a = chain.sensor.accuracy
    up, _, _, _ = chain.trial(np.random.default_rng(0), errors=(), bias_mm=a)
    down, _, _, _ = chain.trial(np.random.default_rng(0), errors=(), bias_mm=-a)
    print("\n%s: the systematic term through the chain (noise-free scans, bias +-%.1f um)"
          % (name, 1e3 * a))
    print("%-34s %12s %12s" % ("characteristic", "d value/d b", "u_sys (mm)"))
    for key in sorted(up, key=lambda k: (not k.startswith("worst"), k)):
        if key in down and not key.endswith("centroid_mm[2]"):
            c = (up[key] - down[key]) / (2.0 * a)
            print("%-34s %12.3f %12.5f" % (key, c, abs(c) * a / np.sqrt(3.0)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--blade", choices=("demo", "rotor67", "both"), default="both")
    ap.add_argument("--trials", type=int, default=40)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--record-seed", type=int, default=31)
    ap.add_argument("--stated", type=int, default=2,
                    help="trials whose airfoil u is averaged (its re-fits are slow); the worst "
                    "deviations' u is every trial's")
    ap.add_argument("--errors", default=",".join(ERRORS),
                    help="which of %s to draw (the others left out), to attribute a scatter"
                    % ",".join(ERRORS))
    ap.add_argument("--sensitivity", action="store_true",
                    help="print the systematic term's sensitivities through the chain instead")
    ap.add_argument("--reanalyse", action="store_true",
                    help="print the table again from the last run's saved trials")
    args = ap.parse_args()
    if args.sensitivity:
        for name in (("demo", "rotor67") if args.blade == "both" else (args.blade,)):
            systematic_sensitivity(name, args.seed, args.record_seed)
        return
    errors = tuple(e for e in args.errors.split(",") if e)
    for name in (("demo", "rotor67") if args.blade == "both" else (args.blade,)):
        if args.reanalyse:
            reanalyse(name, errors)
            continue
        run(name, args.trials, args.seed, args.stated, errors, args.record_seed)


if __name__ == "__main__":
    main()
