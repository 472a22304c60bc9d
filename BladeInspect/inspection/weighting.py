"""Which weights the fine registration uses (`--weights snr|sensor`) and the
record of that choice in result.json's ``weights`` block.

- ``snr``: the paper's SNR-linear weights (uniform when the points carry no SNR);
- ``sensor``: core.weights.SensorWeights, the efficient weights 1 / (sigma_beam(SNR) cos
  theta)^2 of this project's sensor model, which need each reading's rotary angle
  (``angle_deg``) to know its beam.

The default (None) is ``sensor`` when the points carry both an SNR and an ``angle_deg``
column - readings from this rig (`scan`, `inspect`), whose beam is known, so the efficient
weights are available and their pose is the more accurate one (bench/bench_weights.py) - and
``snr`` otherwise, where there is no beam to weight by; files without ``angle_deg`` therefore
register exactly as before. Either way result.json's ``weights`` says which was used and why.

How they compose with the fit objectives (inspection.fitting, core.fits): the ICP's weights
(these a_i times the robust weight) are the weights every later fit starts from. Least squares
with ``--weights-by-zone`` minimises sum a_i rho_i z_i d_i^2 - the product of the sensor (or
SNR) weight and the region multiplier z_i - and states the sandwich covariance, which with the
sensor weights is exact for the noise and keeps the region multipliers honest; minimax and
fit-to-tolerance are unweighted by definition (every inlier must lie in the zone), so the
weights enter them only through the inliers the ICP kept and their least-squares covariance.
"""

import numpy as np

from ..core.errors import InputError
from ..core.pointio import PointSet
from ..core.weights import WEIGHT_MODELS, SensorWeights, beam_in_table
from ..rig.kinematics import RigKinematics
from ..rig.sensor import SensorModel
from ..rig.simulated import BEAM_MACHINE

DEFAULT_RULE = "sensor when the points carry snr and angle_deg, else snr"


def check_choice(choice, option="--weights"):
    """InputError unless ``choice`` is None or one of WEIGHT_MODELS."""
    if choice is not None and choice not in WEIGHT_MODELS:
        raise InputError("%s: unknown weights '%s' (use %s)"
                         % (option, choice, " or ".join(WEIGHT_MODELS)))
    return choice


def sensor_weights(snr, angle_deg, sensor=None, kinematics=None):
    """SensorWeights of readings with this SNR taken at these rotary angles, their beam the
    rig's machine beam turned back about ``kinematics``' rotary axis (default: the nominal
    rig; an error of the axis direction of e rad changes a weight by a factor cos e)."""
    sensor = sensor if sensor is not None else SensorModel()
    kinematics = kinematics if kinematics is not None else RigKinematics()
    beam = beam_in_table(angle_deg, kinematics.axis_direction, BEAM_MACHINE)
    return SensorWeights(snr, beam, sensor.sigma_ref, sensor.snr_ref, sensor.max_incidence_rad)


def weight_model_for(pointset, choice=None, sensor=None, kinematics=None):
    """(weight model for core.icp, or None for the SNR weights; result.json ``weights``
    record) for this point set and ``choice`` (None, "snr" or "sensor"; module docstring)."""
    check_choice(choice)
    source = pointset.source or "points"
    has_beam = pointset.snr is not None and "angle_deg" in pointset.columns
    if choice is None:
        has_beam = has_beam and bool(np.all(np.isfinite(
            np.asarray(pointset.columns["angle_deg"], dtype=float))))
        choice = "sensor" if has_beam else "snr"
        why = "default (%s): %s" % (DEFAULT_RULE, "the readings carry snr and angle_deg"
                                    if has_beam else _no_beam_reason(pointset))
    else:
        why = "--weights %s" % choice
    if choice == "snr":
        model = "snr" if pointset.snr is not None else "uniform"
        return None, {"model": model, "chosen_by": why,
                      "normal_noise": "sigma_ref sqrt(snr_ref / snr), the paper's"
                      if model == "snr" else "the same for every point"}
    if not has_beam:
        raise InputError("%s: --weights sensor needs snr and angle_deg columns (the beam of "
                         "each reading)" % source)
    angle = np.asarray(pointset.columns["angle_deg"], dtype=float)
    if not np.all(np.isfinite(angle)):
        raise InputError("%s: angle_deg: every row needs a finite rotary angle for --weights "
                         "sensor" % source)
    kinematics = kinematics if kinematics is not None else RigKinematics()
    model = sensor_weights(np.asarray(pointset.snr, dtype=float), angle, sensor, kinematics)
    record = dict(model.describe(), chosen_by=why,
                  beam="machine %s turned back about the rotary axis %s by angle_deg"
                  % (np.asarray(BEAM_MACHINE).tolist(),
                     np.round(kinematics.axis_direction, 9).tolist()))
    return model, record


def _no_beam_reason(pointset):
    """Why the sensor weights are not the default for these readings: what they lack."""
    missing = [name for name, absent in (("snr", pointset.snr is None),
                                         ("angle_deg", "angle_deg" not in pointset.columns))
               if absent]
    if missing:
        return "no beam known (no %s column)" % " and no ".join(missing)
    return "no beam known (angle_deg is not finite in every row)"


def weights_for_rows(xyz, snr, angle_deg, choice=None, kinematics=None, source="points"):
    """weight_model_for of rows held as arrays (the `inspect` loop's blind and later rows),
    their beams turned back by ``kinematics``, the loop's."""
    columns = {} if angle_deg is None else {"angle_deg": np.asarray(angle_deg, dtype=float)}
    return weight_model_for(PointSet(xyz=xyz, snr=snr, columns=columns, source=source), choice,
                            kinematics=kinematics)
