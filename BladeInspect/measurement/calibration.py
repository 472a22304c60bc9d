"""Rotary-axis calibration with a reference sphere (docs/contracts.md loop 4).

A sphere of calibrated diameter sits on the rotary table off the axis. At each of several
rotary angles the sensor rasters the sphere's upper cap; each cap gives the sphere's centre in
the MACHINE frame (stage positions and readings only, no table transform, so nothing assumed
about the axis enters the centres). Turning the table moves the centre on a circle about the
true axis: the circle's centre is a point of the axis, its normal the axis direction. The
result is written as RIG.json through the kinematics, which every later scan reads.

Why a sphere: its centre is the one point of a part that every viewing angle measures alike,
and with the diameter known the centre follows from a cap seen from above alone.
"""

import numpy as np

from ..core import fitting
from ..core import transforms as tf
from ..core.errors import InputError
from ..rig.kinematics import RigKinematics
from ..rig.serial_rig import SerialRig
from ..rig.simulated import SimulatedRig
from .calibration_uncertainty import calibration_uncertainty

DEFAULT_DIAMETER = 25.0
# Twelve angles round the full turn: the centres then span the whole circle, which makes the
# circle's normal (the axis direction) as well determined as a fixed sphere offset allows.
DEFAULT_ANGLES = tuple(float(a) for a in range(0, 360, 30))
# Where the sphere is mounted in the table frame: off the axis (the circle's radius sets how
# well its normal is known) and along it, within a few mm; the first raster finds it exactly.
DEFAULT_SPHERE_POSITION = (60.0, 30.0, 0.0)
MIN_CAP_POINTS = 20
# Raster half-width as a fraction of the radius: incidence up to about 35 deg keeps the SNR
# high and the cap deep enough (about 2 mm) to separate centre depth from radius.
CAP_FRACTION = 0.6
RASTER_LINES = 21
# Residuals beyond this many robust sigmas are gross sensor errors, not the sphere.
OUTLIER_SIGMAS = 5.0
MAX_RECENTRE_PASSES = 3
RECENTRE_TOLERANCE_MM = 0.02


class SpherePart:
    """A sphere with an exact ray intersection, the part a SimulatedRig measures for
    calibration (same raycast contract as cad.nominal.Nominal)."""

    def __init__(self, radius, center=(0.0, 0.0, 0.0)):
        if not radius > 0:
            raise InputError("sphere: radius must be positive, got %r" % (radius,))
        self.radius = float(radius)
        self.center = np.asarray(center, dtype=float)
        r = self.radius
        self.bbox_corners = self.center + r * np.array(
            [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)

    def raycast(self, origins, directions):
        """First intersection of each ray o + t d (t >= 0) with the sphere; NaN on a miss.
        Directions need not be unit: t is in units of |d| like any ray parameter."""
        o = np.atleast_2d(np.asarray(origins, dtype=float)) - self.center
        d = np.atleast_2d(np.asarray(directions, dtype=float))
        a = np.einsum("ij,ij->i", d, d)
        b = np.einsum("ij,ij->i", o, d)
        c = np.einsum("ij,ij->i", o, o) - self.radius ** 2
        disc = b * b - a * c
        hit = disc >= 0
        sq = np.sqrt(np.where(hit, disc, 0.0))
        near = (-b - sq) / a
        far = (-b + sq) / a
        # From outside the near root is the entry; from inside only the far root is ahead.
        t = np.where(near >= 0, near, far)
        t = np.where(hit & (t >= 0), t, np.nan)
        points = o + t[:, None] * d
        normal = points / self.radius
        return t, np.zeros(len(t), dtype=int), normal


def raster_path(center_xy, half_width, z, lines=RASTER_LINES):
    """Serpentine raster of lines along X at fixed Y (the rig's scan direction): (K, 3)."""
    offsets = np.linspace(-half_width, half_width, lines)
    rows = []
    for i, dy in enumerate(offsets):
        xs = center_xy[0] + (offsets if i % 2 == 0 else offsets[::-1])
        rows.append(np.column_stack([xs, np.full(lines, center_xy[1] + dy), np.full(lines, z)]))
    return np.vstack(rows)


def _fit_cap(points, snr, radius):
    """Known-radius sphere fit with SNR weights, gross errors removed by a robust residual
    scale (median absolute deviation) and the fit repeated on the rest."""
    weights = None if snr is None else np.clip(snr, 1e-6, None)
    fit = fitting.fit_sphere(points, radius=radius, weights=weights)
    mad = np.median(np.abs(fit.residuals - np.median(fit.residuals)))
    keep = np.abs(fit.residuals) <= OUTLIER_SIGMAS * max(1.4826 * mad, 1e-4)
    if not keep.all() and keep.sum() >= MIN_CAP_POINTS:
        fit = fitting.fit_sphere(points[keep], radius=radius,
                                 weights=None if weights is None else weights[keep])
    return fit, keep


def measure_sphere_centre(rig, angle_deg, predicted_centre, radius, standoff,
                          machine_point=None):
    """Raster the cap above the predicted centre, fit the centre, re-centre the raster on it and
    repeat until it stays put. Returns (centre (3,), SphereFit, cap points (K,3), info dict).

    ``machine_point(stage_xyz, reading)`` maps readings to machine points (default: nominal
    stages, (X, Y, Z - d))."""
    if machine_point is None:
        machine_point = RigKinematics().machine_point
    centre = np.asarray(predicted_centre, dtype=float)
    half = CAP_FRACTION * radius
    passes = []
    for _ in range(MAX_RECENTRE_PASSES):
        path = raster_path(centre[:2], half, centre[2] + radius + standoff)
        readings = rig.scan_path(path, angle_deg)
        valid = np.isfinite(readings.reading_mm)
        if np.count_nonzero(valid) < MIN_CAP_POINTS:
            raise InputError(
                "calibration: sphere not found at A=%.1f deg: %d readings in a %.1f mm raster "
                "around machine (%.2f, %.2f, %.2f) (check --sphere-diameter and its position)"
                % (angle_deg, int(np.count_nonzero(valid)), 2 * half,
                   centre[0], centre[1], centre[2]))
        pts = machine_point(np.asarray(readings.stage_xyz, float)[valid],
                            np.asarray(readings.reading_mm, float)[valid])
        snr = np.asarray(readings.snr, float)[valid]
        fit, keep = _fit_cap(pts, snr, radius)
        shift = float(np.linalg.norm(fit.center[:2] - centre[:2]))
        passes.append({"points": int(len(pts)), "rejected": int(np.count_nonzero(~keep)),
                       "shift_mm": shift})
        centre = fit.center
        if shift < RECENTRE_TOLERANCE_MM:
            break
    rms = float(np.sqrt(np.mean(fit.residuals ** 2)))
    return centre, fit, pts, {"passes": passes, "residual_rms_mm": rms}


def axis_from_centres(centres, angles_deg):
    """The rotary axis from the sphere centres measured at the given angles.

    Returns a dict: ``point`` (where the axis crosses the machine plane y = 0, like the
    nominal axis through the origin), ``direction`` (unit, oriented so that the measured
    angles turn right-handed about it), ``circle`` (CircleFit of the centres), and
    ``angle_model_residual_mm``: per angle, the distance between the measured centre and where
    a rigid turn by that angle about the fitted axis puts the mean table position — the
    circle fit ignores the angle values, so this checks the rotary's angles as well."""
    centres = np.asarray(centres, dtype=float)
    angles = np.asarray(angles_deg, dtype=float)
    if len(centres) < 3 or len(np.unique(np.round(angles % 360.0, 6))) < 3:
        raise InputError("calibration: at least 3 distinct rotary angles are needed, got %d"
                         % len(np.unique(np.round(angles % 360.0, 6))))
    circle = fitting.fit_circle_3d(centres)
    o, n = circle.center, circle.normal
    rel = centres - o
    # Orientation: a right-handed turn by (a_j - a_i) about n takes centre i towards centre j.
    sense = 0.0
    for i in range(len(angles)):
        for j in range(i + 1, len(angles)):
            sense += np.sin(np.radians(angles[j] - angles[i])) * (np.cross(rel[i], rel[j]) @ n)
    if sense < 0:
        n = -n
    if abs(n[1]) < 1e-6:
        raise InputError("calibration: the fitted axis is not along Y (direction %s)"
                         % np.array2string(n, precision=4))
    point = o - (o[1] / n[1]) * n
    fitted = RigKinematics(axis_point=point, axis_direction=n)
    table = np.array([fitted.table_point(c, a)[0] for c, a in zip(centres, angles)])
    mean_table = table.mean(axis=0)
    predicted = np.array([fitted.machine_point_of_table(mean_table, a)[0] for a in angles])
    return {"point": point, "direction": n, "circle": circle,
            "angle_model_residual_mm": np.linalg.norm(predicted - centres, axis=1)}


def axis_angles_deg(direction):
    """Tilts of an axis direction from +Y: about machine Z (towards X) and about X (towards Z),
    in degrees — the figures a machine tool's axis alignment is stated in."""
    d = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    return float(np.degrees(np.arctan2(d[0], d[1]))), float(np.degrees(np.arctan2(d[2], d[1])))


# Largest difference between the given and the measured diameter: a wrong diameter moves every
# fitted centre along the beam by the radius error, which shifts the axis by as much.
DIAMETER_TOLERANCE_MM = 0.05


def calibrate(rig, sphere_diameter=DEFAULT_DIAMETER, angles=DEFAULT_ANGLES, out_path=None,
              sphere_position=DEFAULT_SPHERE_POSITION, kinematics=None, progress=None):
    """Measure the reference sphere at each rotary angle, find the axis, write RIG.json.

    ``kinematics`` is what is believed before calibration (default: the nominal RigKinematics);
    it only predicts where to look for the sphere, and the result is a copy of it with the
    measured axis. ``sphere_position`` is the sphere's approximate centre in the table frame.
    Returns a dict of results (JSON-ready) with the new kinematics under ``kinematics``."""
    if not (np.isfinite(sphere_diameter) and sphere_diameter > 0):
        raise InputError("--sphere-diameter: must be a positive number of mm, got %r"
                         % (sphere_diameter,))
    angles = [float(a) for a in angles]
    if len(angles) < 6:
        raise InputError("calibration: at least 6 rotary angles are needed, got %d" % len(angles))
    progress = progress or (lambda fraction, message: None)
    prior = kinematics if kinematics is not None else RigKinematics()
    radius = 0.5 * float(sphere_diameter)
    standoff = float(rig.sensor.standoff)
    centres, per_angle, diameters, centre_covariances = [], [], [], []
    for i, a in enumerate(angles):
        progress(i / len(angles), "calibration: sphere at A=%.1f deg" % a)
        predicted = prior.machine_point_of_table(np.asarray(sphere_position, float), a)[0]
        centre, fit, pts, info = measure_sphere_centre(rig, a, predicted, radius, standoff,
                                                       machine_point=prior.machine_point)
        free = fitting.fit_sphere(pts)
        diameters.append(2.0 * free.radius)
        centres.append(centre)
        centre_covariances.append(fit.covariance)
        per_angle.append({"angle_deg": a, "centre": centre.tolist(),
                          "points": info["passes"][-1]["points"],
                          "passes": len(info["passes"]),
                          "residual_rms_mm": info["residual_rms_mm"],
                          "free_fit_diameter_mm": 2.0 * free.radius})
    measured_d = float(np.median(diameters))
    if abs(measured_d - sphere_diameter) > DIAMETER_TOLERANCE_MM:
        raise InputError("--sphere-diameter %g: the sphere measures %.3f mm across"
                         % (sphere_diameter, measured_d))
    axis = axis_from_centres(centres, angles)
    calibrated = _with_axis(prior, axis["point"], axis["direction"])
    # the calibration's own uncertainty, written into RIG.json beside the axis
    own = calibration_uncertainty(centres, centre_covariances, angles, calibrated,
                                  sphere_position)
    if out_path is not None:
        _write_atomically(out_path, calibrated, own.to_json())
    progress(1.0, "calibration: axis through (%.4f, 0, %.4f), %.4f deg from +Y"
             % (axis["point"][0], axis["point"][2],
                np.degrees(np.arccos(np.clip(axis["direction"][1], -1, 1)))))
    tilt_z, tilt_x = axis_angles_deg(axis["direction"])
    return {
        "axis_point": axis["point"].tolist(),
        "axis_direction": axis["direction"].tolist(),
        "axis_tilt_about_z_deg": tilt_z,
        "axis_tilt_about_x_deg": tilt_x,
        "circle_radius_mm": axis["circle"].radius,
        "circle_residual_rms_mm": float(np.sqrt(np.mean(axis["circle"].residuals ** 2))),
        "angle_model_residual_mm": axis["angle_model_residual_mm"].tolist(),
        "sphere_diameter_mm": float(sphere_diameter),
        "measured_diameter_mm": measured_d,
        "angles": per_angle,
        "simulated_s": float(rig.elapsed_s),
        "rig_file": out_path,
        "kinematics": calibrated,
        "uncertainty": own.to_json(),
        "calibration_uncertainty_mm": own.at_part_mm,
    }


def _with_axis(kinematics, point, direction):
    import copy
    out = copy.deepcopy(kinematics)
    out.axis_point = np.asarray(point, dtype=float)
    out.axis_direction = np.asarray(direction, dtype=float)
    return out


def _write_atomically(path, kinematics, extra=None):
    import os
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError("--out %s: folder %s does not exist" % (path, folder))
    kinematics.to_json(path, extra)


def sphere_residual(rig, kinematics, sphere_diameter=DEFAULT_DIAMETER, angles=DEFAULT_ANGLES,
                    sphere_position=DEFAULT_SPHERE_POSITION):
    """How well a kinematics joins readings from several rotary angles: the sphere's cap is
    scanned at each angle, all points are turned into the table frame by ``kinematics`` and one
    sphere of the known diameter is fitted to them together. With the true axis the caps
    coincide and the residual is the sensor's noise; with a wrong axis each angle's cap sits
    elsewhere and the residual grows. Returns {rms_mm, n_points, centre_table}."""
    radius = 0.5 * float(sphere_diameter)
    standoff = float(rig.sensor.standoff)
    table_pts, weights = [], []
    for a in angles:
        predicted = kinematics.machine_point_of_table(np.asarray(sphere_position, float), a)[0]
        centre, _, _, _ = measure_sphere_centre(rig, a, predicted, radius, standoff,
                                                machine_point=kinematics.machine_point)
        path = raster_path(centre[:2], CAP_FRACTION * radius, centre[2] + radius + standoff)
        readings = rig.scan_path(path, a)
        valid = np.isfinite(readings.reading_mm)
        machine = kinematics.machine_point(np.asarray(readings.stage_xyz)[valid],
                                           np.asarray(readings.reading_mm)[valid])
        table_pts.append(kinematics.table_point(machine, a))
        weights.append(np.asarray(readings.snr)[valid])
    pts, snr = np.vstack(table_pts), np.concatenate(weights)
    # No outlier rejection here: it would hide exactly the misfit this figure is meant to show
    # (the raster stays below 35 deg incidence, where the sensor gives no gross errors).
    fit = fitting.fit_sphere(pts, radius=radius, weights=snr)
    return {"rms_mm": float(np.sqrt(np.mean(fit.residuals ** 2))),
            "n_points": int(len(pts)), "centre_table": fit.center.tolist()}


def simulated_calibration_rig(sphere_diameter=DEFAULT_DIAMETER, seed=0, axis_offset_mm=0.0,
                              axis_tilt_deg=0.0, stage_scale=(0.0, 0.0, 0.0), sensor=None,
                              sphere_position=DEFAULT_SPHERE_POSITION):
    """A SimulatedRig measuring a reference sphere, its TRUE kinematics off the nominal by the
    given axis offset and tilt (in seeded random directions across +Y) and stage scale errors:
    what `calibrate --rig sim` measures, and what tests judge calibration against.
    Returns (rig, true kinematics)."""
    rng = np.random.default_rng(seed)
    lean, shift = rng.uniform(0.0, 2.0 * np.pi, 2)
    tilt = np.radians(axis_tilt_deg)
    direction = np.array([np.sin(tilt) * np.cos(lean), np.cos(tilt), np.sin(tilt) * np.sin(lean)])
    point = axis_offset_mm * np.array([np.cos(shift), 0.0, np.sin(shift)])
    truth = RigKinematics(axis_point=point, axis_direction=direction, stage_scale=stage_scale)
    mount = np.asarray(sphere_position, dtype=float) + rng.uniform(-1.0, 1.0, 3)
    rig = SimulatedRig(SpherePart(0.5 * float(sphere_diameter)),
                       tf.make_transform(np.eye(3), -mount), sensor=sensor, kinematics=truth,
                       seed=seed)
    return rig, truth


def run_calibration(out_path, rig_spec="sim", sphere_diameter=DEFAULT_DIAMETER, seed=0,
                    rig_file=None, progress=None, **simulated_errors):
    """The `calibrate` command: open the rig ('sim' -> simulated_calibration_rig with
    ``simulated_errors``; 'serial:PATH' -> the serial driver), calibrate, write RIG.json.
    ``rig_file``: the kinematics believed so far (default nominal). Returns calibrate()'s dict,
    with the simulator's truth under ``truth`` for a simulated rig."""
    prior = RigKinematics.from_json(rig_file) if rig_file else RigKinematics()
    truth = None
    if rig_spec == "sim":
        rig, truth = simulated_calibration_rig(sphere_diameter, seed=seed, **simulated_errors)
    elif str(rig_spec).startswith("serial:"):
        rig = SerialRig(rig_spec[len("serial:"):])
    else:
        raise InputError("--rig: expected sim or serial:PORT, got %r" % (rig_spec,))
    try:
        result = calibrate(rig, sphere_diameter, out_path=out_path, kinematics=prior,
                           progress=progress)
    finally:
        rig.close()
    if truth is not None:
        result["truth"] = {"axis_point": truth.axis_point.tolist(),
                           "axis_direction": truth.axis_direction.tolist()}
        result["truth_error"] = axis_error(result["axis_point"], result["axis_direction"],
                                           truth.axis_point, truth.axis_direction)
    return result


def axis_error(point, direction, true_point, true_direction):
    """How far a found axis is from the true one: the true axis' offset across itself (mm) and
    the angle between the directions (degrees)."""
    p, d = np.asarray(point, float), np.asarray(direction, float)
    tp, td = np.asarray(true_point, float), np.asarray(true_direction, float)
    off = (p - tp) - np.dot(p - tp, td) * td
    angle = np.degrees(np.arccos(np.clip(abs(np.dot(d, td)), -1.0, 1.0)))
    return {"position_mm": float(np.linalg.norm(off)), "direction_deg": float(angle)}
