"""Uncertainty of a section's airfoil characteristics by re-fitting perturbed points (the
``uncertainty`` block, 1 sigma, k = 1).

Each draw moves the section's points by a pose drawn from the registration's covariance (its
random part, inspection.uncertainty.random_pose_covariance), lays fresh sensor noise on the
measured profile's smooth fit where each reading's beam meets it (beam_feet; "The draws'
base": the closest point would keep the scan's own error along the surface beneath the draw's,
docs/maintainers.md) -- each reading's own sigma_beam(SNR) along its beam, in the sensor's
distribution (its normal part is inspection.uncertainty.normal_noise; along the normal without
beams, the section's point-to-point scatter only for readings without SNR) -- and adds one
reading bias within the sensor's stated accuracy carried through the registration as
inspection.uncertainty carries it for the deviations; the standard deviation of each
characteristic over the draws is its uncertainty (a parametric bootstrap;
bench/bench_uncertainty_mc.py compares it with the whole chain's scatter). The contour's form
values are maxima: their u adds the maximum's bias (maxima_bias) to the draws' scatter.

A change of this model changes every task file's draws: raise
inspection.airfoil_task.TASK_MODEL_VERSION with it.
"""

import numpy as np

from ..core import airfoil as kernel
from ..core import background
from ..core import transforms as tf
from ..core import uncertainty_model
from ..core.errors import InputError
from ..rig.sensor import SensorModel
from . import airfoil_measure
from . import fitting
from . import uncertainty as uncertainty_mod
from .airfoil_measure import into_plane, on_smooth_fit, slide
from .airfoil_values import char_values, flat, unflat


def sensor_of(opts):
    """The sensor the uncertainty's draws model (the default one, at ``opts.accuracy_mm``)."""
    return (SensorModel() if opts.accuracy_mm is None
            else SensorModel(accuracy=float(opts.accuracy_mm)))


# A reading's foot along its beam is taken only within this many of its beam sigmas of the
# reading (farther, the beam runs nearly along the fit: its closest foot is kept).
BEAM_FOOT_SIGMAS = 10.0
_BEAM_FOOT_ROUNDS = 3


def beam_feet(profile, pts, feet, beams2d, reach):
    """Where each point's beam (in-plane directions ``beams2d``, as into_plane carries a move
    along the beam into the plane) meets ``profile``: the point with its reading's error along
    the beam taken out, the noise-free reading the sensor model assumes. ``feet``, the closest
    points, are kept where the beam misses the profile within ``reach`` (per point) of the
    point or has no direction. A few Newton steps on the signed distance along the beam."""
    t = np.zeros(len(pts))
    ok = np.all(np.isfinite(beams2d), axis=1) & (np.linalg.norm(beams2d, axis=1) > 0)
    b = np.where(ok[:, None], beams2d, 0.0)
    for _ in range(_BEAM_FOOT_ROUNDS):
        u, at = profile.closest(pts - t[:, None] * b)
        n = profile.outward_normal(u)
        cos = np.einsum("ij,ij->i", b, n)
        ok &= np.abs(cos) > 1e-3
        dev = np.einsum("ij,ij->i", pts - t[:, None] * b - at, n)
        t = t + np.where(ok, dev / np.where(ok, cos, 1.0), 0.0)
    ok &= np.abs(t) * np.linalg.norm(b, axis=1) <= reach
    _, on = profile.closest(pts - t[:, None] * b)
    return np.where(ok[:, None], on, feet)


def _beams_in_plane(beams, surface_normal, frame):
    """(n, 2) in-plane displacement that into_plane makes of a unit move along each beam (a
    move out of the plane is slid back along the surface, which turns it in the plane)."""
    pn = np.asarray(frame.normal, dtype=float)
    direction, divisor = slide(surface_normal, pn)
    moved = beams - ((beams @ pn) / divisor)[:, None] * direction
    return np.column_stack([moved @ frame.e1, moved @ frame.e2])


def refit_uncertainty(m, opts, rng, draws_sd=None):
    """1 sigma of each measured characteristic of the section ``m`` (an
    airfoil_measure.SectionMeasurement) by re-fitting perturbed points (module notes);
    ``draws_sd``, a dict, is given the draws' own 1 sigma before the maxima's bias."""
    result, idx, frame, nom, ch, fit = m.result, m.idx, m.frame, m.nominal, m.measured, m.fit
    noise, measured_values = m.noise_mm, m.values
    n0 = result.normal[idx]
    pts, smooth, out_normal = on_smooth_fit(result, idx, frame, ch)
    cov = uncertainty_mod.random_pose_covariance(result)
    cov = np.where(np.isfinite(cov), cov, 0.0)
    try:
        chol = np.linalg.cholesky(cov + 1e-30 * np.eye(6))
    except np.linalg.LinAlgError:
        w, V = np.linalg.eigh(cov)
        chol = V * np.sqrt(np.clip(w, 0, None))
    centre = np.asarray(result.center, dtype=float)
    # The sensor's systematic error: one reading bias b per draw (rectangular within the stated
    # accuracy) moves every point by b along its beam, less the rigid motion by which the
    # registration takes that up (inspection.uncertainty.bias_take_up, whose normal part is
    # the deviations' b s_i); without beams by b along its normal, taken whole. Where the
    # sensor errs, as the noise (point_noise_model). Noise-free, the characteristics' slopes
    # on the bias are those of moving along the normal by b s_i (within 3 % on the demo
    # blade's loop); with the noise, bench_uncertainty_mc (16 trials) found section 2's chord
    # 0.77 and section 1's LE thickness at 2 mm 1.26 of the chain's scatter against 0.58 and
    # 1.67 along the normal (a stated u of 2 x 12 draws is itself ~15 % uncertain).
    sensor = sensor_of(opts)
    accuracy = sensor.accuracy
    sigma, spread, along, unit = point_noise_model(result, idx, sensor, noise, out_normal)
    # The draws' noise-free points: each reading's beam where it meets the measured profile's
    # smooth fit (module notes).
    smooth3 = frame.to_3d(beam_feet(ch.profile, pts, smooth, _beams_in_plane(along, n0, frame),
                                     BEAM_FOOT_SIGMAS * spread))
    take_up = uncertainty_mod.bias_take_up(result, sensor)
    if take_up is None:
        bias_step = n0
    else:
        beams, r = take_up
        bias_step = beams[idx] - r[:3] - np.cross(r[3:], smooth3 - centre)
    axis_fields, axis_chol = _calibration_model(result, idx, opts, sensor)
    draws = []
    for _ in range(max(int(opts.draws), 2)):
        background.check()    # a cancelled job stops between draws
        d = chol @ rng.standard_normal(6)
        R = tf.rotation_from_vector(d[3:])
        moved = (smooth3 - centre) @ R.T + centre + d[:3]
        moved = moved + along * (spread * unit(rng, len(moved)))[:, None]
        moved = moved + rng.uniform(-accuracy, accuracy) * bias_step
        if axis_fields is not None:
            moved = moved + axis_fields @ (axis_chol @ rng.standard_normal(4))
        p2 = frame.to_2d(into_plane(moved, n0, frame.origin, frame.normal))
        if opts.calibration_mm and axis_fields is None:
            # the calibration's error at the part as one in-plane translation of the section
            # (1 sigma per axis): its location part, which the Monte Carlo showed missing
            # (docs/user-guide.md, "Decisions")
            p2 = p2 + float(opts.calibration_mm) * rng.standard_normal(2)
        try:
            c, f, k, _ = airfoil_measure.measure(p2, nom, opts, noise, nom.le_point)
        except InputError:
            continue
        draws.append(flat(char_values(c, frame, f, k)))
    if len(draws) < 2:
        return None
    keys = flat(measured_values).keys()
    sd = {key: _draws_sd([d[key] for d in draws if key in d])
          for key in keys if sum(key in d for d in draws) >= 2}
    if draws_sd is not None:   # inspection.airfoil_task stores these
        draws_sd.update(sd)
    for key, bias in maxima_bias(result, idx, pts, nom, fit, sigma, sensor).items():
        if key in sd:
            sd[key] = float(np.hypot(sd[key], bias))
    return unflat(sd, measured_values)


class SizeTakeUp:
    """The size fit beside a plain rigid least-squares pose (``uncertainty_size_take_up``):
    the estimated uniform size ``size_mm`` (+ oversize), its statistical U (k = 2; the
    sensor's accuracy, which also reads as size, is in the draws' bias already), the size
    fit's motion of the points (``transform``, CAD frame), the largest distance it moves an
    inlier and the seconds the fit took."""

    def __init__(self, run, seconds, result):
        self.size_mm = float(run.size)
        variance = run.size_variance
        self.U_mm = (float(fitting.K * np.sqrt(variance))
                     if variance is not None and np.isfinite(variance) else None)
        self.transform = np.asarray(run.transform, dtype=float)
        inlier = np.asarray(run.inlier, dtype=bool)
        p = np.asarray(result.points_cad, dtype=float)[inlier]
        moved = tf.apply_transform(self.transform, p)
        self.pose_motion_mm = float(np.max(np.linalg.norm(moved - p, axis=1))) if len(p) else 0.0
        self.seconds = float(seconds)

    def scale(self):
        """The factor from the take-up's effect at the estimated size to the systematic term:
        1 + U/|s| (the size's own U through the same sensitivity), at most 2: where the size
        is not resolved (|s| <= U) the effect itself is of the order of the noise; 2 when the
        points leave the size's variance undetermined (a pose direction they do not measure,
        e.g. along the span of a blade without ends), U then taken as |s|."""
        if self.U_mm is None:
            return 2.0
        return 1.0 + min(self.U_mm / max(abs(self.size_mm), 1e-12), 1.0)


def size_take_up_model(result, nominal):
    """SizeTakeUp of a registration whose pose is the plain rigid least-squares one (None for
    any other fit, or when the size fit cannot be made)."""
    import time
    if result is None or not fitting.is_plain_rigid(result):
        return None
    t0 = time.perf_counter()
    try:
        run = fitting.size_fit_from_pose(result, nominal)
    except InputError:
        return None
    if run is None or run.size is None:
        return None
    return SizeTakeUp(run, time.perf_counter() - t0, result)


# A characteristic whose U the take-up term widens by more than this fraction is named in
# the section's note.
TAKE_UP_NOTE_FRACTION = 0.5


def size_take_up_term(m, take_up, opts):
    """{flat key: systematic term, mm or deg, added to the expanded U} of the section ``m``
    (an airfoil_measure.SectionMeasurement) under the plain rigid pose: its characteristics
    measured again at the size fit's pose, |plain - at size fit| (what the pose took up of
    the size ``take_up.size_mm``), times take_up.scale(). None when they cannot be measured
    there."""
    factor = take_up.scale()
    R = take_up.transform[:3, :3]
    moved = tf.apply_transform(take_up.transform, m.result.points_cad[m.idx])
    normals = np.asarray(m.result.normal[m.idx], dtype=float) @ R.T
    try:
        ch, fit, cont, _, _ = airfoil_measure.measure_at(moved, normals, m.frame, m.nominal,
                                                          opts)
    except InputError:
        return None
    at_size = flat(char_values(ch, m.frame, fit, cont))
    plain = flat(m.values)
    return {key: float(abs(plain[key] - at_size[key]) * factor)
            for key in plain if key in at_size
            and np.isfinite(plain[key]) and np.isfinite(at_size[key])}


def add_take_up(uncertainty, term, k):
    """(u with the term folded in, the term as a block like ``uncertainty``, the keys whose
    expanded U grew by more than TAKE_UP_NOTE_FRACTION): the systematic term is added to the
    expanded U linearly (it is a bias), U = k u + term, so u becomes u + term / k."""
    u = flat(uncertainty)
    grown = [key for key in u if key in term and np.isfinite(u[key])
             and term[key] > TAKE_UP_NOTE_FRACTION * k * u[key]]
    widened = {key: (u[key] + term[key] / k if key in term else u[key]) for key in u}
    kept = {key: term[key] for key in u if key in term}
    return unflat(widened, uncertainty), unflat(kept, uncertainty), grown


def _calibration_model(result, idx, opts, sensor):
    """(fields (n, 3, 4), Cholesky factor (4, 4)) of the section's readings' axis errors
    (uncertainty.calibration_fields) when the options carry RIG.json's axis covariance and the
    readings their angles, else (None, None): calibration_mm's in-plane translation serves
    instead (it over-states the shifts and holds no shape part, docs/maintainers.md, "The airfoil draws"). The fields
    of the whole scan cost ~0.04 s (demo loop, 16264 readings), against ~1 s of a section's
    re-fits: not kept between sections."""
    if opts.calibration_axis is None:
        return None, None
    fields = uncertainty_mod.calibration_fields(result, opts.calibration_axis, sensor)
    if fields is None:
        return None, None
    cov = np.asarray(opts.calibration_axis["covariance"], dtype=float)
    w, V = np.linalg.eigh(0.5 * (cov + cov.T))
    return fields[idx], V * np.sqrt(np.clip(w, 0.0, None))


def maxima_bias(result, idx, pts, nom, fit, sigma, sensor):
    """{form key: bias} of the contour's form values, which are maxima over the section's
    readings: the largest of several noisy readings lies above the true largest (as for a
    worst deviation, inspection.uncertainty.maximum_error with the same noise, systematic
    bias and pose). form_location_mm is twice the largest |deviation| before the section's
    fit; form_mm the largest less the smallest deviation after it, both ends biased outwards.
    The draws' scatter of a form value does not hold this bias (their maxima are as biased
    as the measured one); u states both."""
    model = uncertainty_mod.MeasurementModel(sensor=sensor)
    shared = uncertainty_mod.shared_terms(result, idx, model)
    flipped = [uncertainty_model.SharedTerm(t.name, -t.coefficients, t.sample)
               for t in shared]
    before = kernel.signed_deviation(pts, nom.profile)[0]
    theta = -np.radians(fit.twist_deg)
    c, s = np.cos(theta), np.sin(theta)
    turn = np.array([[c, -s], [s, c]])
    after = kernel.signed_deviation((pts - fit.pivot) @ turn.T + fit.pivot
                                    - turn @ fit.shift_mm, nom.profile)[0]
    # the ends of the after-fit range as maxima of readings clear of zero
    span = float(after.max() - after.min()) + 1.0
    # only the biases are used: the terms' extra rounds are not run (the same biases)
    _, location, _ = uncertainty_mod.maximum_error(before, sigma, shared, model, bias_only=True)
    _, top, _ = uncertainty_mod.maximum_error(after - after.min() + span, sigma, shared, model,
                                              bias_only=True)
    _, bottom, _ = uncertainty_mod.maximum_error(after.max() + span - after, sigma, flipped,
                                                 model, bias_only=True)
    return {"form_location_mm": 2.0 * location, "form_mm": top + bottom}


def point_noise_model(result, idx, sensor, scatter, out_normal):
    """(sigma (n,), spread (n,), along (n, 3), unit-variance sampler) of the section's readings'
    noise: sigma along the normal, each reading's own sigma_beam(SNR) cos(theta) in the
    sensor's distribution (inspection.uncertainty.normal_noise, the deviations' model), and
    for the draws the same error where the sensor makes it, sigma_beam along the beam. Its
    part along the surface moves a reading along the profile, which the edges, the thickness
    stations, the metal angles and a flat maximum's position read. On one noise-only scan of
    the demo loop, 48 draws against a 16-scan noise-only chain (sections 1/2), the normal
    part alone -> along the beam: max-thickness position 0.76/2.52 -> 0.89/1.06 of the
    chain's scatter, inlet angle 0.86/0.95 -> 1.12/1.10, stagger 0.52/1.10 -> 0.70/1.06, LE
    thickness at 2 mm 0.77/0.76 -> 0.85/1.00; outlet angle 0.60/0.81 -> 0.77/0.76 and TE
    thickness at 1 mm 0.63/0.84 -> 0.63/0.65 stay short (cause not found). Without beams sigma_beam
    along ``out_normal`` (the profile's normal); for readings without SNR (another sensor's
    points) the section's point-to-point scatter as a normal noise along it."""
    n = len(idx)
    if result.snr is None:
        sigma = np.full(n, scatter)
        return sigma, sigma, out_normal, lambda rng, k: rng.standard_normal(k)
    sigma = uncertainty_mod.normal_noise(result, idx, sensor)
    sigma = np.where(np.isfinite(sigma), sigma, scatter)
    snr = np.asarray(result.snr, dtype=float)[idx]
    with np.errstate(divide="ignore", invalid="ignore"):
        beam_sigma = np.where(snr > 0, sensor.sigma_ref * np.sqrt(sensor.snr_ref / snr), np.nan)
    beams = uncertainty_mod.beam_directions(result)
    along = out_normal.copy()
    spread = sigma.copy()
    if beams is not None:
        read = np.isfinite(beam_sigma)
        along[read] = beams[idx][read]
        spread[read] = beam_sigma[read]
    return sigma, spread, along, uncertainty_mod.unit_noise(sensor)


# A draw farther than this many robust sigmas (1.4826 MAD) from the draws' median is a failure
# of that re-fit (an offset station off the end of a nose), not scatter: 12 normal draws hold
# one so far in a thousand sets (the MAD of 12 is itself loose; 5 would drop one in 35).
DRAW_OUTLIER_SIGMAS = 10.0


def _draws_sd(values):
    """Standard deviation of one characteristic over the re-fit draws, without the draws that
    failed for it (DRAW_OUTLIER_SIGMAS): one draw whose thickness station fell off the nose
    once stated a 13.6 mm uncertainty on Rotor 67."""
    v = np.asarray(values, dtype=float)
    spread = 1.4826 * np.median(np.abs(v - np.median(v)))
    if spread > 0:
        v = v[np.abs(v - np.median(v)) <= DRAW_OUTLIER_SIGMAS * spread]
    return float(np.std(v, ddof=1)) if len(v) >= 2 else float("nan")
