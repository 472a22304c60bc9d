"""The complete scan (paper 4.3): raster lines every ``pitch`` mm across the
span at a few rotary angles, so that suction and pressure sides and both edges are measured.

Planned from the CAD once the pose is known. The span runs along the rotary axis (machine Y),
so a raster line is a pass along X at fixed Y. For each angle, rays down the beam (-Z) are
cast on the CAD from above the blade on a grid of X steps by lines: the first hit is the
surface height z(x) on that line and is in the sensor's line of sight by construction; the
stage goes to Z = z + standoff. Each surface point is kept only at the angle of the set that
sees it most nearly head-on, so the angles share the surface instead of measuring it twice.
Rays are cast only where the CAD's samples say the angle can be the best one, which keeps the
cast near the number of points kept (no per-line OCC cuts: 700 lines would take minutes).
"""

from dataclasses import dataclass, field

import numpy as np
from scipy.ndimage import binary_dilation

from ..core import transforms as tf
from ..core.errors import DeviceError, InputError
from ..rig.kinematics import RigKinematics
from .planning import (ANGLES, COVERAGE_MARGIN_DEG, blade_faces, body_clear,
                       expected_snr, incidence_table, plan_json)

DEFAULT_PITCH_MM = 0.1
# Along a line: 0.25 mm steps give the paper's ~269,000 points on a 70 x 50 x 20 mm blade at
# 0.1 mm pitch (about 380 points per section around a ~100 mm contour).
DEFAULT_SPACING_MM = 0.25
# Evenly spaced angles: six put every normal across the span within 30 deg of one of them,
# whatever the twist (a greedy cover at 40 deg picks 20 angles on the twisted Rotor 67 blade,
# each a whole raster pass and a rotation).
DEFAULT_N_ANGLES = 6
# The lens starts this far above the blade's highest point at each angle.
CAST_CLEARANCE_MM = 1.0
# Where a ray may be worth casting: grid cells within this distance (mm) of a CAD sample whose
# best angle is the one being planned. Wider than the samples' own spacing, so no cell between
# samples is missed.
CAST_REACH_MM = 1.5
# One pass of the rig holds whole lines up to about this many points: a serial device's
# message stays bounded, while the simulator's cost per pass stays negligible.
MAX_PASS_POINTS = 100000


@dataclass
class CompletePass:
    """One pass of the rig: a rotary angle and rows of CompletePlan, in execution order."""
    angle_deg: float
    rows: np.ndarray


@dataclass
class CompletePlan:
    """The raster: per planned reading (N rows) its line, angle, setpoint and CAD target."""
    pitch_mm: float
    spacing_mm: float
    angles_deg: np.ndarray           # (A,) the rotary angles used
    line_y: np.ndarray               # (L,) machine Y of each raster line
    line: np.ndarray                 # (N,) index into line_y
    angle_deg: np.ndarray            # (N,)
    stage_xyz: np.ndarray            # (N, 3) setpoints
    target_cad: np.ndarray           # (N, 3) the nominal surface point on the beam
    normal_cad: np.ndarray           # (N, 3)
    face: np.ndarray                 # (N,) CAD face index
    incidence_deg: np.ndarray        # (N,)
    expected_snr: np.ndarray         # (N,)
    passes: list                     # CompletePass in execution order
    table_to_cad: np.ndarray
    standoff_mm: float
    info: dict = field(default_factory=dict)

    @property
    def n_points(self):
        return int(len(self.line))

    def to_dict(self):
        """A summary for DIR/plan.json: the per-point arrays of a 0.1 mm raster (hundreds of
        thousands of rows) belong in points.csv, not in JSON."""
        per_angle = {("%g" % a): int(np.count_nonzero(self.angle_deg == a))
                     for a in self.angles_deg}
        return {"kind": "complete raster", "n_points": self.n_points,
                "n_passes": len(self.passes), "n_lines": int(len(self.line_y)),
                "pitch_mm": self.pitch_mm, "spacing_mm": self.spacing_mm,
                "angles_deg": self.angles_deg.tolist(), "points_per_angle": per_angle,
                "line_y_range": [float(self.line_y[0]), float(self.line_y[-1])],
                "table_to_cad": np.asarray(self.table_to_cad).tolist(),
                "standoff_mm": self.standoff_mm,
                "max_incidence_deg": float(np.max(self.incidence_deg)),
                "info": self.info}

    to_json = plan_json


def check_step(value, name):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError("%s: %r is not a number" % (name, value)) from None
    if not (np.isfinite(v) and 0.01 <= v <= 10.0):
        raise InputError("%s: %g mm is outside 0.01-10 mm" % (name, v))
    return v


def _cad_from_machine(table_to_cad, kinematics, angle_deg):
    return table_to_cad @ tf.invert_transform(kinematics.table_to_machine_transform(angle_deg))


def _cast_mask(samples_m, best_here, line_y, x0, nx, spacing, pitch):
    """(L, nx) cells worth a ray at this angle: near samples whose best angle this is."""
    mask = np.zeros((len(line_y), nx), dtype=bool)
    p = samples_m[best_here]
    li = np.rint((p[:, 1] - line_y[0]) / pitch).astype(int)
    xi = np.rint((p[:, 0] - x0) / spacing).astype(int)
    inside = (li >= 0) & (li < len(line_y)) & (xi >= 0) & (xi < nx)
    mask[li[inside], xi[inside]] = True
    ry = int(np.ceil(CAST_REACH_MM / pitch))
    rx = int(np.ceil(CAST_REACH_MM / spacing))
    # Dilating by a rectangle along each axis separately is the same as by the full box.
    mask = binary_dilation(mask, structure=np.ones((2 * ry + 1, 1), dtype=bool))
    return binary_dilation(mask, structure=np.ones((1, 2 * rx + 1), dtype=bool))


def _even_angles(cos_all, n_angles):
    """``n_angles`` angles evenly around the axis from the candidate grid, turned so that the
    worst-served blade sample is served best. ``cos_all``: (candidates, samples)."""
    if n_angles < 1 or len(ANGLES) % n_angles:
        raise InputError("complete scan: %r angles do not divide the %g deg grid evenly"
                         % (n_angles, 360.0 / len(ANGLES)))
    per_turn = len(ANGLES) // n_angles
    best = cos_all.reshape(n_angles, per_turn, -1).max(axis=0)
    phase = int(np.argmax(best.min(axis=1)))
    return ANGLES[phase::per_turn]


def plan_complete(nominal, table_to_cad, sensor, limits, pitch=DEFAULT_PITCH_MM,
                  spacing=DEFAULT_SPACING_MM, kinematics=None, angles_deg=None,
                  n_angles=DEFAULT_N_ANGLES):
    """Plan the complete raster of the blade faces at pose ``table_to_cad`` (table -> CAD).

    ``pitch``: mm between raster lines along the rotary axis; ``spacing``: mm between readings
    along a line; ``angles_deg``: the rotary angles (default: ``n_angles`` evenly spaced, turned
    to serve the blade faces' worst normal best).
    Returns a CompletePlan. InputError for bad steps. Setpoints outside the soft limits are
    left out with a note (``info["unreachable"]``); DeviceError only when that leaves none."""
    pitch = check_step(pitch, "--pitch")
    spacing = check_step(spacing, "complete scan spacing")
    kinematics = kinematics if kinematics is not None else RigKinematics()
    table_to_cad = np.asarray(table_to_cad, dtype=float)
    cad_to_table = tf.invert_transform(table_to_cad)
    standoff = float(sensor.standoff)
    usable = np.cos(np.radians(0.5 * float(sensor.coverage_deg) - COVERAGE_MARGIN_DEG))

    s = nominal.samples
    faces = np.asarray(blade_faces(nominal))
    on_blade = np.isin(s.face, faces)
    samples_t = tf.apply_transform(cad_to_table, s.xyz)
    normals_t = s.normal[on_blade] @ cad_to_table[:3, :3].T
    if angles_deg is None:
        angles = _even_angles(incidence_table(normals_t, ANGLES, kinematics), int(n_angles))
    else:
        angles = np.unique(np.mod(np.asarray(angles_deg, dtype=float), 360.0))
        if len(angles) == 0 or not np.all(np.isfinite(angles)):
            raise InputError("complete scan angles: expected finite rotary angles")
    cos_samples = incidence_table(normals_t, angles, kinematics)
    best_sample = np.argmax(cos_samples, axis=0)

    # Lines span the blade faces along machine Y at every angle (the axis may lean off Y).
    blade_m = [kinematics.machine_point_of_table(samples_t[on_blade], a) for a in angles]
    y_lo = min(m[:, 1].min() for m in blade_m)
    y_hi = max(m[:, 1].max() for m in blade_m)
    line_y = y_lo + pitch * np.arange(int(np.floor((y_hi - y_lo) / pitch)) + 1)
    stage_inverse = np.linalg.inv(kinematics.stage_matrix)

    cols = {k: [] for k in ("line", "angle", "stage", "target", "normal", "face", "cos")}
    passes, left_out = [], []
    info = {"rays_cast": 0, "dropped_not_best": 0, "dropped_off_blade": 0,
            "dropped_coverage": 0, "dropped_body": 0}
    for ai, a in enumerate(angles):
        all_m = kinematics.machine_point_of_table(samples_t, a)
        bm = blade_m[ai]
        x0 = bm[:, 0].min() - CAST_REACH_MM
        nx = int(np.ceil((bm[:, 0].max() + CAST_REACH_MM - x0) / spacing)) + 1
        mask = _cast_mask(bm, best_sample == ai, line_y, x0, nx, spacing, pitch)
        li, xi = np.nonzero(mask)
        if len(li) == 0:
            continue
        z_top = all_m[:, 2].max() + CAST_CLEARANCE_MM
        lens_m = np.column_stack([x0 + spacing * xi, line_y[li], np.full(len(li), z_top)])
        T = _cad_from_machine(table_to_cad, kinematics, a)
        beam = T[:3, :3] @ np.array([0.0, 0.0, -1.0])
        t, face, normal = nominal.raycast(tf.apply_transform(T, lens_m),
                                          np.tile(beam, (len(li), 1)))
        info["rays_cast"] += int(len(li))
        hit = np.isfinite(t)
        blade_hit = hit & np.isin(face, faces)
        info["dropped_off_blade"] += int(np.count_nonzero(hit & ~blade_hit))
        n_t = np.asarray(normal, dtype=float) @ cad_to_table[:3, :3].T
        cos_here = incidence_table(n_t, angles, kinematics)
        best = blade_hit & (np.argmax(cos_here, axis=0) == ai)
        info["dropped_not_best"] += int(np.count_nonzero(blade_hit & ~best))
        seen = best & (cos_here[ai] >= usable)
        info["dropped_coverage"] += int(np.count_nonzero(best & ~seen))
        spot = lens_m[seen] - np.outer(t[seen], [0.0, 0.0, 1.0])
        clear = body_clear(all_m, spot, standoff)
        info["dropped_body"] += int(np.count_nonzero(~clear))
        keep = np.flatnonzero(seen)[clear]
        spot = spot[clear]
        stage = (spot + np.array([0.0, 0.0, standoff])) @ stage_inverse.T
        # Setpoints beyond the soft limits are left out with a note; the rest are measured.
        beyond, example = outside_soft_limits(limits, stage, a)
        if beyond.any():
            left_out.append({"angle_deg": float(a), "n_dropped": int(beyond.sum()),
                             "soft_limit_example": example,
                             "target_cad": tf.apply_transform(T, spot[beyond])})
            keep, stage, spot = keep[~beyond], stage[~beyond], spot[~beyond]
        if len(keep) == 0:
            continue
        start = sum(len(c) for c in cols["line"])
        # Boustrophedon: the grid is line-major with X increasing; every other line reversed.
        order = np.lexsort((np.where(li[keep] % 2 == 1, -xi[keep], xi[keep]), li[keep]))
        keep, stage, spot = keep[order], stage[order], spot[order]
        cols["line"].append(li[keep])
        cols["angle"].append(np.full(len(keep), float(a)))
        cols["stage"].append(stage)
        cols["target"].append(tf.apply_transform(T, spot))
        cols["normal"].append(np.asarray(normal, dtype=float)[keep])
        cols["face"].append(np.asarray(face)[keep])
        cols["cos"].append(cos_here[ai, keep])
        passes += _passes(float(a), li[keep], start)
    if not passes:
        if left_out:
            raise DeviceError("complete scan: every raster point is outside the soft limits "
                              "(%s)" % left_out[0]["soft_limit_example"])
        raise InputError("complete scan: no point of the CAD's blade faces is in view")
    cat = {k: np.concatenate(v) for k, v in cols.items()}
    incidence = np.degrees(np.arccos(np.clip(cat["cos"], -1.0, 1.0)))
    info["cast_reach_mm"] = CAST_REACH_MM
    if left_out:
        info["unreachable"] = unreachable_raster_info(left_out, nominal, len(cat["line"]))
    return CompletePlan(
        pitch_mm=pitch, spacing_mm=spacing, angles_deg=np.asarray(angles, dtype=float),
        line_y=line_y, line=cat["line"], angle_deg=cat["angle"], stage_xyz=cat["stage"],
        target_cad=cat["target"], normal_cad=cat["normal"], face=cat["face"],
        incidence_deg=incidence, expected_snr=expected_snr(sensor, np.radians(incidence)),
        passes=passes, table_to_cad=table_to_cad, standoff_mm=standoff, info=info)


def outside_soft_limits(limits, stage, angle_deg):
    """(mask of the setpoints (N, 3) at rotary angle ``angle_deg`` outside the soft limits,
    the first refusal's message or None). The limits' own check decides; its bounds are read
    per point only once the whole set fails it."""
    try:
        limits.check(stage[:, 0], stage[:, 1], stage[:, 2], angle_deg)
        return np.zeros(len(stage), bool), None
    except DeviceError as exc:
        message = str(exc)
    a_range = getattr(limits, "a", None)
    if a_range is not None and not a_range[0] <= angle_deg <= a_range[1]:
        return np.ones(len(stage), bool), message
    beyond = np.zeros(len(stage), bool)
    for k, name in enumerate("xyz"):
        lo, hi = getattr(limits, name)
        beyond |= (stage[:, k] < lo - 1e-9) | (stage[:, k] > hi + 1e-9)
    return beyond, message


def unreachable_raster_info(left_out, nominal, n_planned):
    """plan.json's and result.json's record of the raster points left out (the soft limits):
    per angle how many and between which span heights (% of the blade faces' span), and one
    warning line."""
    from .planning import span_axis_of
    axis, origin, lo, hi = span_axis_of(nominal)
    angles, total = [], 0
    for rec in left_out:
        height = 100.0 * (((rec["target_cad"] - origin) @ axis) - lo) / (hi - lo)
        total += rec["n_dropped"]
        angles.append({"angle_deg": rec["angle_deg"], "n_dropped": rec["n_dropped"],
                       "span_pct": [round(float(height.min()), 1),
                                    round(float(height.max()), 1)],
                       "soft_limit_example": rec["soft_limit_example"]})
    where = ", ".join("%d at A=%g deg between %g and %g %% span"
                      % (r["n_dropped"], r["angle_deg"], r["span_pct"][0], r["span_pct"][1])
                      for r in angles)
    warning = ("complete scan: %d of %d raster points left out of the plan (outside the "
               "stages' soft limits, e.g. %s; where: %s)"
               % (total, total + n_planned, angles[0]["soft_limit_example"], where))
    return {"warnings": [warning], "n_dropped": total, "angles": angles}


def _passes(angle, lines, start, max_points=MAX_PASS_POINTS):
    """Cut one angle's ordered rows into passes of whole lines of at most ``max_points``."""
    bounds = np.flatnonzero(np.diff(lines) != 0) + 1
    line_starts = np.concatenate([[0], bounds])
    out, first = [], 0
    for b in np.concatenate([line_starts[1:], [len(lines)]]):
        if b - first > max_points:
            # Close the pass at the last line start before it overflows (one long line alone
            # still makes a pass).
            cut = line_starts[(line_starts > first) & (line_starts < b)]
            end = int(cut[-1]) if len(cut) else int(b)
            out.append(CompletePass(angle, np.arange(start + first, start + end)))
            first = end
    if first < len(lines):
        out.append(CompletePass(angle, np.arange(start + first, start + len(lines))))
    return out


def _no_progress(fraction, message):
    pass


def scan_complete(rig, plan, kinematics=None, progress=_no_progress, first_pass=0,
                  on_pass=None):
    """Run the passes of ``plan`` on the rig from pass ``first_pass`` on (those before it were
    measured before an interruption). Returns (table-frame points (M, 3), snr (M,), line (M,),
    angle_deg (M,), plan row (M,), reading_mm (M,), per-pass records); rows with no reading
    are left out. ``on_pass(n_passes_done, (xyz, snr, line, angle_deg), record)`` is called as
    each pass ends: the inspection's checkpoint."""
    kinematics = kinematics if kinematics is not None else RigKinematics()
    xyz, snr, rows, readings_mm, records = [], [], [], [], []
    for i in range(first_pass, len(plan.passes)):
        p = plan.passes[i]
        progress(i / len(plan.passes), "complete scan: pass %d of %d (A=%g deg, %d points)"
                 % (i + 1, len(plan.passes), p.angle_deg, len(p.rows)))
        readings = rig.scan_path(plan.stage_xyz[p.rows], p.angle_deg)
        d = np.asarray(readings.reading_mm, dtype=float)
        ok = np.isfinite(d)
        machine = kinematics.machine_point(np.asarray(readings.stage_xyz)[ok], d[ok])
        xyz.append(kinematics.table_point(machine, p.angle_deg))
        snr.append(np.asarray(readings.snr, dtype=float)[ok])
        rows.append(p.rows[ok])
        readings_mm.append(d[ok])
        records.append({"angle_deg": p.angle_deg, "points": int(len(d)),
                        "readings": int(ok.sum()),
                        "lines": [int(plan.line[p.rows[0]]), int(plan.line[p.rows[-1]])],
                        "max_standoff_error_mm": (float(np.max(np.abs(d[ok] - plan.standoff_mm)))
                                                  if ok.any() else None),
                        "pass_index": readings.meta.get("pass_index")})
        if on_pass is not None:
            on_pass(i + 1, (xyz[-1], snr[-1], plan.line[rows[-1]], plan.angle_deg[rows[-1]]),
                    records[-1])
    if not rows:
        return (np.zeros((0, 3)), np.zeros(0), np.zeros(0, int), np.zeros(0),
                np.zeros(0, int), np.zeros(0), records)
    rows = np.concatenate(rows)
    return (np.vstack(xyz), np.concatenate(snr), plan.line[rows], plan.angle_deg[rows], rows,
            np.concatenate(readings_mm), records)
