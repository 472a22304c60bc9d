"""The expanded uncertainty U (k = 2) of a judged deviation, from a stated measurement model.

A judged value is the signed deviation of one measured point (a section's worst, the part's
worst). Its standard uncertainty combines, as independent terms (GUM, root sum of squares):

- noise: the sensor's random error of that reading along the surface normal,
  sigma(SNR) cos(theta) (normal_noise: sigma(SNR) of rig.sensor.SensorModel runs along the
  beam, theta the incidence from the point's rotary angle; cos theta 1 without angle_deg);
  sigma_ref when the point has no SNR;
- systematic: the sensor's stated accuracy taken as a bias of unknown sign common to every
  reading, a rectangular distribution of half-width ``accuracy``: s_i * accuracy / sqrt(3).
  The bias lengthens every reading alike, moving each point along its beam; the registration
  then takes up part of it, so a deviation moves by s_i = beta_i - J_i (J^T W J)^-1 J^T W beta
  per unit bias, beta = beam . n of each point and W the fit's weights (systematic_coefficients).
  The beams follow from the points' rotary angles (the ``angle_deg`` column an inspection and
  points.csv carry); without them s_i = 1, the bias taken whole (an upper estimate: on the demo
  blade's loop the fit takes up more than half of it, bench/bench_uncertainty_mc.py);
- pose: the registration's pose covariance Sigma (result.pose_covariance, 6x6 [t mm, w rad]
  about result.center) propagated to the point along its normal: J Sigma J^T with
  J = [n, (p - c) x n] (the deviation's change under a twist (t, w) about c). Sigma's
  residual scale is cut to the residuals' random part (random_pose_covariance): the bias's
  left-over misfit is the systematic term's, not the pose's;
- calibration: the rig calibration's own uncertainty at the part, when a RIG.json stating one
  is given (``calibration_uncertainty_mm``, an average over directions at the calibration
  sphere, the registration's take-up not subtracted); otherwise the term is not included and
  the model says so. The airfoil draws use the axis covariance itself through each reading's
  angle when the RIG.json states it (calibration_fields);
- fit: the pose covariance above is that of the least-squares fit of the same points; under a
  Chebyshev objective (minimax, tolerance) it states what the measurement determines, not that
  estimator's own, larger scatter, which is not included (core.fits, "Covariance").

A worst deviation (a section's, a spot's, the part's: verdict.judge) is a maximum over points:
its U is that of the error of a maximum (worst_terms, core.uncertainty_model), the upward bias
of the largest of several noisy readings included in U rather than corrected. The part's worst
inlier, where the fit left out a defect's top beside it, is a censored maximum
(censored_worst_terms).
"""

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..core import background
from ..core import bias_take_up as core_take_up
from ..core import icp as core_icp
from ..core import uncertainty_model
from ..core.errors import InputError
from ..core.weights import SensorWeights, beam_in_table
from ..rig.kinematics import read_rig_file
from ..rig.sensor import SensorModel
from ..rig.simulated import BEAM_MACHINE

COVERAGE_FACTOR = 2.0


@dataclass
class MeasurementModel:
    sensor: SensorModel = field(default_factory=SensorModel)
    calibration_mm: Optional[float] = None     # 1 sigma at the part, from RIG.json
    calibration_source: Optional[str] = None
    # RIG.json's axis parameters (4,) and their covariance (4, 4), when it states them: the
    # airfoil draws propagate these through each reading's angle (calibration_fields)
    calibration_axis: Optional[dict] = None

    def to_json(self):
        return {
            "k": COVERAGE_FACTOR,
            "noise": "sensor sigma(SNR) along the normal: %.4g mm at SNR %g, times "
                     "sqrt(SNR_ref / SNR) cos(incidence)"
                     % (self.sensor.sigma_ref, self.sensor.snr_ref),
            "worst": "a worst deviation's U is the error of the largest of the readings that "
                     "compete for it (within %g combined noise sigmas), its upward bias "
                     "included in U, not corrected" % COMPETING_SIGMAS,
            "systematic_mm": self.systematic_mm,
            "systematic": "stated accuracy %.4g mm as a rectangular bias of every reading: "
                          "s * accuracy / sqrt(3), s the deviation's change per unit bias "
                          "after the registration (1 when the beams are not known)"
                          % self.sensor.accuracy,
            "pose": "pose covariance propagated along the normal, J S J^T, J = [n, (p-c) x n]",
            "calibration_mm": self.calibration_mm,
            "calibration_axis": self.calibration_axis,
            "calibration": ("from %s" % self.calibration_source if self.calibration_mm
                            is not None else "not included (no RIG.json stating the "
                            "calibration's uncertainty)"),
            "fit": "the least-squares pose covariance of the same free degrees of freedom; a "
                   "Chebyshev fit's own scatter is not included",
        }

    @property
    def systematic_mm(self):
        return float(self.sensor.accuracy / np.sqrt(3.0))


def model_from_rig_file(path, sensor=None):
    """The measurement model with the calibration term of a RIG.json (None: not included)."""
    sensor = sensor or SensorModel()
    if path is None:
        return MeasurementModel(sensor=sensor)
    data = read_rig_file(path)
    value = data.get("calibration_uncertainty_mm") if isinstance(data, dict) else None
    if value is not None:
        value = float(value)
        if not np.isfinite(value) or value < 0:
            raise InputError("%s: calibration_uncertainty_mm must be a finite number >= 0"
                             % path)
    return MeasurementModel(sensor=sensor, calibration_mm=value,
                            calibration_source=path if value is not None else None,
                            calibration_axis=(calibration_axis_of(data, path)
                                              if value is not None else None))


def calibration_axis_of(data, source):
    """{"parameters": (4,), "covariance": (4, 4)} of a RIG.json's axis calibration
    (measurement.calibration_uncertainty), None when the file does not state them (a RIG.json
    written before they were); InputError when it states them wrongly."""
    values, cov = data.get("calibration_parameter_values"), data.get("calibration_covariance")
    if values is None and cov is None:
        return None
    try:
        values = np.asarray(values, dtype=float)
        cov = np.asarray(cov, dtype=float)
    except (TypeError, ValueError):
        values = cov = None
    ok = (values is not None and values.shape == (4,) and cov.shape == (4, 4)
          and np.all(np.isfinite(values)) and np.all(np.isfinite(cov)))
    if ok:
        ok = (np.allclose(cov, cov.T, rtol=1e-9, atol=1e-30)
              and np.linalg.eigvalsh(0.5 * (cov + cov.T)).min()
              >= -1e-9 * max(np.abs(cov).max(), 1e-300))
    if not ok:
        raise InputError("%s: calibration_parameter_values must be 4 finite numbers and "
                         "calibration_covariance a symmetric positive semi-definite 4 x 4 "
                         "matrix" % source)
    return {"parameters": values.tolist(), "covariance": cov.tolist()}


def calibration_fields(result, axis, sensor=None):
    """(N, 3, 4) of each point's error in the CAD frame per unit error of each axis parameter
    of ``axis`` (calibration_axis_of's), less the rigid motion by which the registration takes
    that error up (core.bias_take_up.take_up_of, the fit's weights and points as bias_take_up's);
    None without the points' rotary angles.

    A reading at angle a through an axis off by d lands at K(K'^-1(q, a), a) instead of q
    (measurement.calibration_uncertainty.error_fields): the views see the part through
    differently wrong axes, so the error is not one translation; the part common to all the
    readings, a rigid motion, is what the registration removes."""
    from ..measurement.calibration_uncertainty import error_fields
    from ..rig.kinematics import RigKinematics
    angles = reading_angles(result)
    if axis is None or angles is None:
        return None
    to_cad = np.asarray(result.measured_to_cad, dtype=float)
    points = np.asarray(result.points_cad, dtype=float)
    table = (points - to_cad[:3, 3]) @ to_cad[:3, :3]
    fields = error_fields(RigKinematics(), axis["parameters"], table, angles)
    fields = np.einsum("ij,njk->nik", to_cad[:3, :3], fields)
    beams = beam_directions(result)
    weights = _fit_weights(result)
    keep = core_take_up.takes_part(points, result.normal, beams, weights,
                                   (sensor or SensorModel()).max_incidence_rad)
    centre = np.asarray(result.center, dtype=float)
    for k in range(4):
        r = core_take_up.take_up_of(points, result.normal, fields[:, :, k], weights, centre,
                                    keep)
        fields[:, :, k] -= r[:3] + np.cross(r[3:], points - centre)
    return fields


def standard_terms(result, index, model=None):
    """{term: (n,) standard uncertainty in mm} of the deviations of the points ``index``."""
    model = model or MeasurementModel()
    index = np.atleast_1d(np.asarray(index, dtype=int))
    n = len(index)
    noise = normal_noise(result, index, model.sensor)
    normal = np.asarray(result.normal, dtype=float)[index]
    arm = np.asarray(result.points_cad, dtype=float)[index] - np.asarray(result.center)
    J = np.hstack([normal, np.cross(arm, normal)])
    cov = random_pose_covariance(result)
    with np.errstate(invalid="ignore"):
        pose_var = np.einsum("ij,jk,ik->i", J, cov, J) if np.all(np.isfinite(cov)) \
            else np.full(n, np.inf)
    coefficient = systematic_coefficients(result, model.sensor)
    coefficient = np.ones(n) if coefficient is None else np.abs(coefficient[index])
    terms = {"noise_mm": noise, "systematic_mm": coefficient * model.systematic_mm,
             "pose_mm": np.sqrt(np.maximum(pose_var, 0.0))}
    if model.calibration_mm is not None:
        terms["calibration_mm"] = np.full(n, model.calibration_mm)
    return terms


def normal_noise(result, index=None, sensor=None):
    """(n,) 1 sigma of the readings' errors along the surface normal, what a deviation sees:
    the noise runs along the beam, so it is sigma_beam(SNR) cos(theta), theta the incidence
    between the beam and the normal (core.weights.SensorWeights, the same model the sensor
    weights of the fit use); sigma_beam alone when the beams are not known (no angle_deg),
    sigma_ref at SNR_ref when the readings have no SNR; inf where the SNR is not positive."""
    sensor = sensor or SensorModel()
    n_all = len(result.points_cad)
    index = np.arange(n_all) if index is None else np.atleast_1d(np.asarray(index, dtype=int))
    snr = (np.full(len(index), sensor.snr_ref) if result.snr is None
           else np.asarray(result.snr, dtype=float)[index])
    beams = _beams_measured(result)
    if beams is None:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(snr > 0, sensor.sigma_ref * np.sqrt(sensor.snr_ref / snr), np.inf)
    model = SensorWeights(snr, beams[index], sensor.sigma_ref, sensor.snr_ref,
                          sensor.max_incidence_rad)
    return model.normal_sigma(result.measured_to_cad, np.asarray(result.normal)[index])


def reading_angles(result):
    """(N,) each point's rotary angle (the ``angle_deg`` column), or None when the points do
    not carry one finite angle each."""
    angles = (result.columns or {}).get("angle_deg")
    if angles is None:
        return None
    angles = np.asarray(angles, dtype=float)
    if angles.shape != (len(result.points_cad),) or not np.all(np.isfinite(angles)):
        return None
    return angles


def _beams_measured(result):
    """(N, 3) unit beam directions in the measured frame from the rotary angles, or None."""
    from ..rig.kinematics import RigKinematics
    angles = reading_angles(result)
    if angles is None:
        return None
    return beam_in_table(angles, RigKinematics().axis_direction, BEAM_MACHINE)


def beam_directions(result):
    """(N, 3) unit beam directions of the points in the CAD frame, from their rotary angles
    (the nominal axis: a calibrated axis is within a fraction of a degree of it, which moves
    these directions by as little), or None without an ``angle_deg`` column."""
    beams = _beams_measured(result)
    if beams is None:
        return None
    return beams @ np.asarray(result.measured_to_cad, dtype=float)[:3, :3].T


def systematic_coefficients(result, sensor=None):
    """(N,) change of each point's deviation per unit reading bias, after the registration has
    taken up what a rigid motion can (module notes): s_i = beta_i - J_i r,
    core.bias_take_up.left_over of bias_take_up's r; None when the beams are not known.
    ``sensor``: the rig.sensor.SensorModel whose largest incidence tells a reading's normal
    from an edge's (None: the default sensor)."""
    take_up = bias_take_up(result, sensor)
    if take_up is None:
        return None
    beams, response = take_up
    return core_take_up.left_over(result.points_cad, result.normal, beams, response,
                                  result.center)


def bias_take_up(result, sensor=None):
    """(beams (N, 3) in the CAD frame, r (6,)) of a unit reading bias: each point moves by its
    beam and the registration takes that up by the rigid motion -r ([t mm, w rad] about
    result.center), systematic_coefficients' s_i = beta_i - J_i r being its normal part; None
    when the beams are not known. r is core.bias_take_up.take_up with the fit's final weights
    (result.icp_weights, else the SNR, else 1) of the inliers; an edge foot, a point whose beam
    meets its CAD normal more obliquely than the sensor reads at all, takes up nothing (there
    the defect test's take-up in core.icp does the same; one such point past the demo blade's
    hub end once made the span screw's take-up 3.7 where the fit's is 11.5 mm per mm of bias,
    and the airfoil draws state a section's twist 5 times too small, bench_uncertainty_mc)."""
    beams = beam_directions(result)
    if beams is None:
        return None
    max_incidence = (sensor or SensorModel()).max_incidence_rad
    return beams, core_take_up.take_up(result.points_cad, result.normal, beams,
                                       _fit_weights(result), result.center, max_incidence)


def random_pose_covariance(result):
    """result.pose_covariance with its unit-weight variance s^2 cut to the residuals' random
    part (core.icp.random_residual_share of the fine fit's weights and residuals, in the
    readings' order): what the noise makes the pose scatter by. The misfit the registration
    leaves (the reading bias's left-over, a defect, form) inflates s^2 but moves the pose by a
    fixed amount, which the systematic term already carries. As given when the result does not
    hold the fit's own weights (a covariance from elsewhere)."""
    cov = np.asarray(result.pose_covariance, dtype=float)
    if result.icp_weights is None or not np.all(np.isfinite(cov)):
        return cov
    share = core_icp.random_residual_share(_fit_weights(result), result.deviation)
    return share * cov


def _fit_weights(result):
    """(N,) the fine fit's final weights (result.icp_weights, else the SNR, else 1) of its
    inliers, 0 elsewhere: what a take-up of the registration weighs its points by."""
    weights = result.icp_weights if result.icp_weights is not None else result.snr
    weights = (np.ones(len(result.points_cad)) if weights is None else
               np.clip(np.nan_to_num(np.asarray(weights, dtype=float)), 0.0, None))
    return weights * np.asarray(result.inlier, dtype=bool)


def expanded_uncertainty(result, index, model=None):
    """(n,) U = k * the combined standard uncertainty of the points' deviations (mm)."""
    terms = standard_terms(result, index, model)
    return COVERAGE_FACTOR * np.sqrt(sum(t ** 2 for t in terms.values()))


# ---------------------------------------------------------------- the worst of several points

# Points whose deviations lie within this many combined noise sigmas of the worst cannot be told
# from it: any of them could have been the worst, and the reported one is the largest of their
# noisy readings.
COMPETING_SIGMAS = uncertainty_model.COMPETING_SIGMAS


def max_of_draws(n, noise="uniform"):
    """(mean, standard deviation) of the largest of ``n`` independent draws of the sensor's
    noise distribution scaled to unit variance (rig.sensor: uniform, or normal clipped at
    NORMAL_CLIP_SIGMAS), from its order statistic's distribution F(x)^n on a fine grid: the
    closed form of worst_terms' sampled error for n readings of one sigma on a plateau well
    away from zero (tests/test_worst_uncertainty.py holds the two together)."""
    from scipy.stats import norm
    from ..rig.sensor import NORMAL_CLIP_SIGMAS, clipped_normal_std
    n = max(int(n), 1)
    if noise == "uniform":
        # max of n U(-1, 1): mean (n-1)/(n+1), variance 4n / ((n+1)^2 (n+2)); U(-1,1)*sqrt(3)
        # has unit variance.
        mean = (n - 1.0) / (n + 1.0)
        var = 4.0 * n / ((n + 1.0) ** 2 * (n + 2.0))
        return float(np.sqrt(3.0) * mean), float(np.sqrt(3.0 * var))
    c = NORMAL_CLIP_SIGMAS
    z = np.linspace(-c, c, 4001)
    cdf = norm.cdf(z) ** n
    cdf[-1] = 1.0                     # the clipped tail piles up at +c
    p = np.diff(np.concatenate([[0.0], cdf]))
    s = clipped_normal_std(c)
    mean = float(p @ z)
    return mean / s, float(np.sqrt(max(p @ (z - mean) ** 2, 0.0))) / s


def unit_noise(sensor):
    """The sensor's noise distribution at unit variance, as core.uncertainty_model draws it:
    uniform, or normal clipped at NORMAL_CLIP_SIGMAS (rig.sensor)."""
    from ..rig.sensor import NORMAL_CLIP_SIGMAS, clipped_normal_std
    if sensor.noise == "uniform":
        return uncertainty_model.uniform_unit_noise
    c = NORMAL_CLIP_SIGMAS
    s = clipped_normal_std(c)
    return lambda rng, shape: np.clip(rng.standard_normal(shape), -c, c) / s


def worst_terms(result, candidates, model=None, left_out=None):
    """The worst |deviation| among the points ``candidates`` and its standard uncertainty
    terms as the error of a maximum: (worst index, {term: mm}, number of competing points).
    ``left_out``: readings a selection left out of ``candidates`` by their measured values
    (the robust fit's zero weights, for the part's worst inlier): where any of them could
    have been kept, the worst is a censored maximum (censored_worst_terms).

    core.uncertainty_model.max_error: the competitors are the readings within
    COMPETING_SIGMAS combined sigmas of the worst (their own noise along the normal,
    normal_noise, and what the systematic bias and the pose can move them against it); the
    terms' root sum of squares is the RMS error of their largest reading against the true
    largest deviation, bias included. Noise is sampled in the sensor's distribution; the
    systematic bias (b s_i, b uniform in +-accuracy) and the pose (J_i d, d from the pose
    covariance) with it where they move the competitors differently (a bias the fit has taken
    up at one point and not at its neighbour pushes one of them up), else they add their
    variance at the worst as for a single reading; the calibration term is the single
    reading's. The bias of the maximum is included in U, not corrected: the reported worst
    deviation stays the measured one (docs/maintainers.md). A lone worst is a single reading."""
    model = model or MeasurementModel()
    candidates = np.atleast_1d(np.asarray(candidates, dtype=int))
    dev = np.asarray(result.deviation, dtype=float)[candidates]
    noise = normal_noise(result, candidates, model.sensor)
    usable = np.isfinite(noise)
    if not usable.any():
        usable[:] = True
    candidates, dev, noise = candidates[usable], dev[usable], noise[usable]
    worst = int(candidates[np.argmax(np.abs(dev))])
    background.tick()    # a GUI's event loop turns between the sections' worst points
    terms = {k: float(v[0]) for k, v in standard_terms(result, worst, model).items()}
    censored = (None if left_out is None or not len(left_out) else
                censored_worst_terms(result, worst, candidates, left_out, model))
    sampled, _, n = censored or maximum_error(dev, noise, shared_terms(result, candidates,
                                                                       model), model)
    terms.update(sampled)
    return worst, terms, n


# Each reading's true level is estimated as the mean measured deviation over this many nearest
# readings (itself included): the size of core.icp's defect-test neighbourhoods, enough to put a
# level's noise at a quarter of one reading's while a defect's flank stays resolved.
LEVEL_NEIGHBOURS = 16
# Draws of the shared terms from which each reading's largest push is taken
_PUSH_PROBES = 64


def censored_worst_terms(result, worst, candidates, left_out, model):
    """The error terms of the worst among ``candidates`` (index ``worst``) where a selection
    kept them and left out ``left_out`` by their measured values: (terms, bias, n) of
    core.uncertainty_model.censored_max_error, or None when none of the left-out readings
    could have been kept (the plain maximum's model applies).

    Where a defect straddles the robust fit's cut-off, the fit keeps its flanks and gives its
    top no weight, and which flank readings it keeps follows their measured deviations; the
    worst inlier's truth then follows the noise too (docs/maintainers.md, "The part's worst inlier: a
    censored maximum"). Each reading's true level is the mean of the measured deviations of
    its LEVEL_NEIGHBOURS nearest readings (kept or left out), turned to the worst's side. The
    competitors are the readings whose level lies within COMPETING_SIGMAS combined noise sigmas
    under the reported worst, and at most the reach of the noise and the shared terms above
    the fit's per-reading cut (above the reported worst when the cut is not known); the model
    applies when a left-out competitor's level lies above the reported worst. The systematic
    bias and the pose are sampled with the noise, since they move which readings are kept.
    Which are kept: with ``result.inlier_cut`` (core.icp.InlierCut) the fit's own two tests
    replayed in every draw, a reading against its cut and its neighbourhood's mean (the fit's
    own window where known, else its nearest readings; drawn with it) against the defect
    test's; without it, a cut-off at the reported worst on each reading's own value."""
    from scipy.spatial import cKDTree
    dev = np.asarray(result.deviation, dtype=float)
    side = -1.0 if dev[worst] < 0 else 1.0
    # the noise and the shared terms of every reading at once: the pool's, and then the
    # readings drawn with its competitors, are taken from them
    noise_all = normal_noise(result, None, model.sensor)
    shared_all = shared_terms(result, np.arange(len(dev)), model)
    pool = np.union1d(candidates, np.asarray(left_out, dtype=int))
    pool = pool[np.isfinite(noise_all[pool])]
    noise = noise_all[pool]
    cutoff = side * dev[worst]
    sigma_worst = float(noise[pool == worst][0])
    below = COMPETING_SIGMAS * np.sqrt(sigma_worst ** 2 + noise ** 2)
    cut = getattr(result, "inlier_cut", None)
    # Above the cut-off, a reading competes when its noise, or its noise and the shared
    # terms' push (a bias that lowers every reading keeps a higher band of the defect), could
    # bring it under the cut-off -- under the fit's own per-reading cut, when known, which
    # may lie above the reported worst where the neighbourhoods decided.
    shared = [t.take(pool) for t in shared_all]
    rng = np.random.default_rng(0)
    above = _noise_bound_sigmas(model.sensor) * noise + sum(
        np.abs(t.moves(t.sample(rng, _PUSH_PROBES))).max(axis=0) for t in shared)
    ceiling = (cutoff if cut is None
               else np.maximum(cutoff, cut.point_cut / cut.root[pool]))
    # a level is a mean over neighbours: a reading whose own value lies further from the
    # cut-off than the band plus its own noise's reach is not worth a neighbour search
    near = side * dev[pool] >= cutoff - below - 2.0 * above
    points = np.asarray(result.points_cad, dtype=float)
    tree = cKDTree(points[pool])
    k = min(LEVEL_NEIGHBOURS, len(pool))

    def levels_at(index):
        """Each reading's (of result's ``index``) level: the mean of its k nearest in pool."""
        _, hood = tree.query(points[index], k)
        return (side * dev[pool])[np.asarray(hood).reshape(len(index), k)].mean(axis=1)
    levels = np.full(len(pool), -np.inf)
    levels[near] = levels_at(pool[near])
    competes = (levels >= cutoff - below) & (levels <= ceiling + above)
    competes |= pool == worst
    # the cut-off decided where the fit left out a competitor whose level lies above it (the
    # defect's top beyond the kept flank); a worst inlier with no such reading beside it (the
    # part in its noise, a rejected gross error) is a plain maximum
    if not (competes & np.isin(pool, left_out) & (levels >= cutoff)).any():
        return None
    if cut is None:
        return uncertainty_model.censored_max_error(
            levels[competes], noise[competes], cutoff, unit_noise(model.sensor),
            [t.take(competes) for t in shared])
    # the fit's two tests replayed: each competitor's neighbourhood is drawn with it, the
    # fit's own window along its space-filling curve where known, else its nearest readings
    rivals = pool[competes]
    if cut.neighbourhoods is not None and len(cut.neighbourhoods.order) == len(dev):
        hood = cut.neighbourhoods.members(rivals)
    else:
        size = min(core_icp.ICPOptions().defect_neighbours, len(pool))
        _, hood = tree.query(points[rivals], size)
        hood = pool[np.asarray(hood).reshape(len(rivals), size)]
    drawn = np.union1d(rivals, hood.ravel())
    sigma = noise_all[drawn]
    # a window may hold a reading without a noise figure (no usable normal): the typical one
    sigma = np.where(np.isfinite(sigma), sigma, np.median(noise))
    judged = np.searchsorted(drawn, rivals)
    neighbours = np.searchsorted(drawn, hood)
    # the shared terms' draws are symmetric about zero: their pushes need no turning to the side
    return uncertainty_model.censored_max_error(
        levels_at(drawn), sigma, cutoff, unit_noise(model.sensor),
        [t.take(drawn) for t in shared_all], judged=judged,
        kept=lambda measured: cut.kept(measured, drawn, judged, neighbours))


def _noise_bound_sigmas(sensor):
    """The largest a reading's noise can be, in its sigmas: sqrt 3 for uniform noise, the
    clip over the clipped normal's sigma otherwise (rig.sensor)."""
    from ..rig.sensor import NORMAL_CLIP_SIGMAS, clipped_normal_std
    return (np.sqrt(3.0) if sensor.noise == "uniform"
            else NORMAL_CLIP_SIGMAS / clipped_normal_std(NORMAL_CLIP_SIGMAS))


def maximum_error(values, noise, shared, model, bias_only=False):
    """core.uncertainty_model.max_error of these readings in the model's sensor noise
    (``bias_only``: its bias alone, the terms not worked out)."""
    return uncertainty_model.max_error(
        values, noise, unit_noise(model.sensor), shared,
        equal_sigma_max=lambda k: max_of_draws(k, model.sensor.noise),
        noise_bound_sigmas=_noise_bound_sigmas(model.sensor), bias_only=bias_only)


def shared_terms(result, index, model):
    """The errors common to the readings ``index`` as core.uncertainty_model.SharedTerm: the
    systematic bias (b s_i, b uniform in +-accuracy) and, when finite, the pose (J_i d, d
    drawn from the pose covariance)."""
    shared = []
    coefficient = systematic_coefficients(result, model.sensor)
    a = model.sensor.accuracy
    shared.append(uncertainty_model.SharedTerm(
        "systematic_mm", np.ones(len(index)) if coefficient is None
        else coefficient[index], lambda rng, k: rng.uniform(-a, a, (k, 1))))
    cov = random_pose_covariance(result)
    if np.all(np.isfinite(cov)):
        normal = np.asarray(result.normal, dtype=float)[index]
        arm = np.asarray(result.points_cad, dtype=float)[index] - np.asarray(result.center)
        w, V = np.linalg.eigh(0.5 * (cov + cov.T))
        root = V * np.sqrt(np.clip(w, 0.0, None))
        shared.append(uncertainty_model.SharedTerm(
            "pose_mm", np.hstack([normal, np.cross(arm, normal)]),
            lambda rng, k: rng.standard_normal((k, 6)) @ root.T))
    return shared


def worst_expanded_uncertainty(result, candidates, model=None, left_out=None):
    """(worst index, U = k * the combined worst_terms, competing points)."""
    worst, terms, n = worst_terms(result, candidates, model, left_out)
    return worst, COVERAGE_FACTOR * float(np.sqrt(sum(t ** 2 for t in terms.values()))), n
