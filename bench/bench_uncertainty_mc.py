"""Monte Carlo over the whole measurement chain against the stated expanded uncertainty U (issue
16 item 5): does inspection/uncertainty.py's model (and inspection/airfoil.py's airfoil u) state
the scatter that the chain really has?

One planned section scan of the blade (the `inspect` loop on the simulated rig, default sensor,
a 30 um bump on the suction side at the first section) is recorded once, reading by reading: the
stage position, rotary angle, the true distance along the beam and the incidence. Each trial
then measures that scan again with every error the model states, drawn from its distribution:

- the sensor's noise, gross errors, rounding and gating (rig.sensor.SensorModel.read on the
  recorded true distances and incidences, a fresh stream per trial);
- the sensor's stated accuracy as a systematic term: one bias per trial, uniform in
  +-accuracy, added to every reading;
- the rig calibration's error: the rotary axis the rig really has differs from the believed
  (RIG.json) one by an error drawn from `calibrate`'s own covariance (measurement/calibration.py,
  one simulated calibration run here);

and goes on as the pipeline does: believed kinematics -> table-frame points -> SNR-weighted ICP
(started at the true pose: the coarse stage finds the basin, not the answer) -> Table 2 ->
verdict (each section's worst deviation and the part's worst, with U) -> airfoil
characteristics (draws 0 in the trials). The stated u (k = 1) is U / 2 of the verdict, and the
airfoil stage's own u (its default re-fits), both from the first STATED trials' results.

The worst deviation is a maximum over points. Its scatter is not a single point's: where many
points compete for the maximum (a flat bump top, a part inside its noise) the max is biased up
and scatters less. The table therefore prints, beside the scatter, the RMS error against the
truth (the injected field's largest |value| over the section's points), which is what U must
cover.

    scripts/fcpython bench/bench_uncertainty_mc.py [--blade demo|rotor67|both] [--trials 40]
        [--seed 2026] [--stated 2]
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

from BladeInspect.core import stats as stats_mod  # noqa: E402
from BladeInspect.core import transforms as tf  # noqa: E402
from BladeInspect.inspection import airfoil as airfoil_mod  # noqa: E402
from BladeInspect.inspection import pipeline  # noqa: E402
from BladeInspect.inspection import sections as sections_mod  # noqa: E402
from BladeInspect.inspection import uncertainty as uncertainty_mod  # noqa: E402
from BladeInspect.inspection import verdict as verdict_mod  # noqa: E402
from BladeInspect.inspection.result import RegistrationResult  # noqa: E402
from BladeInspect.measurement import calibration as calibration_mod  # noqa: E402
from BladeInspect.rig.kinematics import RigKinematics  # noqa: E402
from BladeInspect.rig.sensor import SensorModel  # noqa: E402

BEAM = np.array([0.0, 0.0, -1.0])
BUMP_HEIGHT = 0.03
BUMP_RADIUS = 6.0
CACHE = os.path.join(tempfile.gettempdir(), "bi-mc-record-%s.pkl")


def blade(name):
    if name == "demo":
        return pipeline.load_nominal(None), (30.0, 70.0)
    from BladeInspect.cad.load import load_nominal
    from tests.helpers import ROTOR67_SECTIONS
    return load_nominal(ROTOR67_SECTIONS), (30.0, 70.0)


def bump_at(nominal, height_pct):
    """A bump on the suction side where the plane at ``height_pct`` crosses it (as
    tests/test_rotor67_loop.py builds it)."""
    from BladeInspect.rig.simulated import make_bump
    axis, (lo, hi) = sections_mod.span_axis_of(nominal)
    s = nominal.samples
    level = lo + (hi - lo) * height_pct / 100.0
    near = np.isin(s.face, nominal.roles["suction"]) & (np.abs(s.xyz @ axis - level) < 0.5)
    pts = s.xyz[near]
    centre = pts[np.argmin(np.linalg.norm(pts - pts.mean(axis=0), axis=1))]
    return axis, make_bump(centre, BUMP_RADIUS, BUMP_HEIGHT)


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
    path = CACHE % name
    if os.path.exists(path):
        with open(path, "rb") as fh:
            return pickle.load(fh)
    from BladeInspect.inspection.closed_loop import run_inspect
    from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
    import json
    nominal, heights = blade(name)
    axis, bump = bump_at(nominal, heights[0])
    corners = nominal.bbox_corners
    truth = random_fixture_pose(np.random.default_rng(seed), blade_span_axis=axis,
                                cad_center=0.5 * (corners.min(0) + corners.max(0)))
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
        run_inspect(None, tmp + "/out", rig=rig, nominal=nominal, section_heights=heights,
                    seed=seed, document=False, scan_options={"n_sections": 3})
        with open(os.path.join(tmp, "out", "scan.json")) as fh:
            scan = json.load(fh)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    planned = sorted({p["pass_index"] for p in scan["phases"]["planned"]["paths"]})
    stage, angle, dist, inc = [], [], [], []
    for i in planned:
        s, a, d, c = log[i]
        stage.append(s)
        angle.append(np.full(len(s), a))
        dist.append(d)
        inc.append(c)
    rec = {"stage": np.vstack(stage), "angle": np.concatenate(angle),
           "distance": np.concatenate(dist), "incidence": np.concatenate(inc),
           "table_to_cad": truth, "heights": heights}
    nominal_k = RigKinematics()
    hit = np.isfinite(rec["distance"])
    for key in ("stage", "angle", "distance", "incidence"):
        rec[key] = rec[key][hit]
    machine = nominal_k.machine_point(rec["stage"], rec["distance"])
    rec["table"] = by_angle(nominal_k.table_point, machine, rec["angle"])
    with open(path, "wb") as fh:
        pickle.dump(rec, fh)
    return rec


if __name__ == "__main__" and sys.argv[1:2] == ["--record-only"]:
    t0 = time.perf_counter()
    r = record(sys.argv[2], int(sys.argv[3]))
    print(sys.argv[2], len(r["distance"]), "readings", time.perf_counter() - t0, "s")
