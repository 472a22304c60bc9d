"""Measurement paths planned from the CAD once the part's pose on the table is known
(docs/contracts.md; paper 3.2 and 5: registration unifies the part and machine frames "to plan
the measurement path and find the section curve accurately").

A nominal section is the CAD cut by a plane across the span. Its points are brought into the
machine by the registration pose (table -> CAD, inverted) and the rotary angle; each point gets
the rotary angle that turns its surface normal towards the beam (+Z of the machine) well inside
the sensor's angular coverage, and stage setpoints that put the surface at the standoff on the
beam (X, Y = the point's x, y; Z = z + standoff, since a reading d gives the point (X, Y, Z - d)).
Points share a few angles per section (each rotation costs time and repeatability), chosen by a
greedy cover, and every planned point is checked for line of sight (exact ray cast on the CAD),
clearance of the sensor body, and the stages' soft limits.
"""

import json
from dataclasses import dataclass, field

import numpy as np

from ..core import background
from ..core import span as span_mod
from ..core import transforms as tf
from ..core.errors import DeviceError, InputError
from ..rig.kinematics import RigKinematics

# Planned incidence stays within this angle of the beam where any angle allows it: the SNR
# falls with incidence, and the coverage's 85 deg limit is where readings stop, not where they
# are good. Points whose normal leans along the axis more than this get their best angle.
MAX_INCIDENCE_DEG = 40.0
# The last few degrees of the coverage are left as margin for the pose's own uncertainty.
COVERAGE_MARGIN_DEG = 10.0
ANGLE_STEP_DEG = 5.0
ANGLES = np.arange(0.0, 360.0, ANGLE_STEP_DEG)
# Sensor body: a cylinder about the beam from this far below the lens upwards.
BODY_RADIUS_MM = 20.0
BODY_CLEARANCE_MM = 3.0
BODY_CELL_MM = 2.0
# A ray that hits the CAD this much before the target is blocked by another part of the blade.
LINE_OF_SIGHT_TOLERANCE_MM = 0.01
# Alternating projections onto the surface and the plane put each section point on both;
# the angle between a blade surface and a cross-section plane makes them converge in a few.
SECTION_PROJECTIONS = 8
SECTION_TOLERANCE_MM = 1e-6
NORMAL_PROBE_MM = 0.01
# Consecutive section points farther apart than this many spacings start a new path.
PATH_GAP_SPACINGS = 3.0
# A section needs at least this many points to define its plane (inspection.sections fits
# one to them) and a profile; fewer are left out of the plan with a note.
MIN_SECTION_POINTS = 3


@dataclass
class PlannedSection:
    """One nominal section and its planned readings (arrays of length K, contour order)."""
    index: int
    height_pct: float
    plane_point: np.ndarray          # (3,) CAD frame
    plane_normal: np.ndarray         # (3,) CAD frame, the span axis
    target_cad: np.ndarray           # (K, 3) on the CAD surface and the plane
    normal_cad: np.ndarray           # (K, 3) outward surface normals
    angle_deg: np.ndarray            # (K,) rotary angle for each reading
    stage_xyz: np.ndarray            # (K, 3) X, Y, Z setpoints
    expected_standoff_mm: np.ndarray  # (K,) distance along the beam to the nominal surface
    incidence_deg: np.ndarray        # (K,) between the beam and the surface normal
    expected_snr: np.ndarray         # (K,) the sensor model's SNR at that standoff and incidence

    @property
    def n_points(self):
        return int(len(self.target_cad))

    def to_dict(self):
        return {"index": self.index, "height_pct": self.height_pct,
                "plane": {"point": self.plane_point.tolist(),
                          "normal": self.plane_normal.tolist()},
                "n_points": self.n_points,
                "target_cad": np.round(self.target_cad, 6).tolist(),
                "normal_cad": np.round(self.normal_cad, 6).tolist(),
                "angle_deg": np.round(self.angle_deg, 6).tolist(),
                "stage_xyz": np.round(self.stage_xyz, 6).tolist(),
                "expected_standoff_mm": np.round(self.expected_standoff_mm, 6).tolist(),
                "incidence_deg": np.round(self.incidence_deg, 3).tolist(),
                "expected_snr": np.round(self.expected_snr, 3).tolist()}


@dataclass
class PlannedPath:
    """One pass of the rig: a rotary angle and the stage positions read along it in order."""
    section: int                     # index into Plan.sections
    angle_deg: float
    points: np.ndarray               # (K,) indices into that section's arrays, in path order

    def to_dict(self):
        return {"section": self.section, "angle_deg": self.angle_deg,
                "points": self.points.tolist()}


def plan_json(plan, path=None):
    """A plan (anything with ``to_dict``) as JSON text (DIR/plan.json); written to ``path``
    when given."""
    text = json.dumps(plan.to_dict(), indent=1)
    if path is not None:
        with open(path, "w") as fh:
            fh.write(text)
    return text


@dataclass
class Plan:
    sections: list                   # PlannedSection per requested height, in height order
    paths: list                      # PlannedPath in execution order
    table_to_cad: np.ndarray         # (4, 4) the pose planned with
    span_axis: np.ndarray            # (3,) CAD frame, hub to tip
    span_range: tuple                # (lo, hi) of the blade faces along the span axis
    axis_point: np.ndarray           # rotary axis the angles turn about, machine frame
    axis_direction: np.ndarray
    standoff_mm: float
    spacing_mm: float
    info: dict = field(default_factory=dict)

    @property
    def n_points(self):
        return int(sum(s.n_points for s in self.sections))

    def path_stage_xyz(self, path):
        return self.sections[path.section].stage_xyz[path.points]

    def to_dict(self):
        return {"n_points": self.n_points, "n_paths": len(self.paths),
                "table_to_cad": np.asarray(self.table_to_cad).tolist(),
                "span_axis": self.span_axis.tolist(), "span_range": list(self.span_range),
                "rotary_axis": {"point": self.axis_point.tolist(),
                                "direction": self.axis_direction.tolist()},
                "standoff_mm": self.standoff_mm, "spacing_mm": self.spacing_mm,
                "info": self.info,
                "sections": [s.to_dict() for s in self.sections],
                "paths": [p.to_dict() for p in self.paths]}

    to_json = plan_json


# ---------------------------------------------------------------- geometry helpers

def face_count_and_planes(nominal):
    """(number of faces, indices of the planar ones); samples alone (no faces) count as one
    non-planar face each index."""
    faces = getattr(nominal, "faces", None)
    if faces is None:
        return int(np.max(nominal.samples.face)) + 1, []
    return len(faces), [i for i, f in enumerate(faces) if _is_planar(f)]


def _is_planar(face):
    """A plane, or a B-spline face that is one (a STEP writer's or toNurbs's planar cap)."""
    surf = face.Surface
    if "Plane" in type(surf).__name__:
        return True
    try:
        return bool(surf.isPlanar())
    except Exception:
        return False


def blade_faces(nominal):
    """Faces that make the airfoil (core.span.airfoil_faces): the roles when known, else every
    non-planar face."""
    return span_mod.airfoil_faces(nominal.roles, *face_count_and_planes(nominal))


def span_frame(nominal, span_axis=None):
    """core.span.Span of the nominal: the one span rule of the planner and the analysis."""
    s = nominal.samples
    n_faces, planar = face_count_and_planes(nominal)
    return span_mod.span(s.xyz, s.weight, s.face, nominal.roles, planar, n_faces, span_axis,
                         s.normal)


def span_axis_of(nominal, span_axis=None):
    """(axis (3,) unit, origin (3,), lo, hi): span_frame's axis, the airfoil faces' centroid,
    and the extent along the axis measured from that centroid."""
    frame = span_frame(nominal, span_axis)
    offset = float(frame.origin @ frame.axis)
    return frame.axis, frame.origin, frame.lo - offset, frame.hi - offset


def _resample(chain, closed, spacing):
    pts = np.vstack([chain, chain[:1]]) if closed else chain
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    if arc[-1] < spacing:
        return pts[:1]
    n = int(np.floor(arc[-1] / spacing)) + (0 if closed else 1)
    # Even spacing that fits the length exactly, so a closed contour has no short last step.
    t = np.linspace(0.0, arc[-1], n, endpoint=not closed)
    return np.column_stack([np.interp(t, arc, pts[:, k]) for k in range(3)])


# Issue 15 item 7: round each edge circle the planned points are closer, out to this many edge
# radii from its centre (the +-45 degree fit zone ends at one radius; the rest is margin for
# the pose and the edge's own form).
EDGE_DENSIFY_REACH = 2.0
# The rule's count assumes points even in angle over a circular arc; a real edge's curvature
# varies along it (points even in arc length are not even in angle) and the zone is placed on
# the fitted circle: this many times the rule's points (measured on the demo blade: 1.0 gave
# sigma_R 2.23 um for a 2 um target).
EDGE_DENSIFY_MARGIN = 1.25
# `inspect` plans its sections with this edge-radius 1-sigma target (its
# --edge-radius-sigma changes it, 0 or off turns the rule off).
DEFAULT_EDGE_RADIUS_SIGMA_MM = 0.002
# An edge whose radius is under this many spot diameters is averaged away by the spot (the
# simulated sensor has none, so its figures cannot show it).
EDGE_MIN_SPOTS = 2.0


def _edge_spacing(loop, plane_point, plane_normal, spacing, noise_mm, radius_sigma_mm,
                  record=None):
    """Spacing wanted at each vertex of a closed loop: ``spacing``, or within
    EDGE_DENSIFY_REACH radii of an edge circle (core.airfoil's LE/TE fit on the cut) the
    spacing that gives its +-45 degree zone edge_points_needed(noise, sigma_R) points.
    ``record``: a list that gets each edge's circle and spacing (the plan's info)."""
    from ..cad.airfoil_sections import plane_frame
    from ..core import airfoil
    frame = plane_frame(plane_point, plane_normal)
    xy = frame.to_2d(loop)
    ch = airfoil.characteristics(xy)
    h = np.full(len(loop), float(spacing))
    for name, circle in (("LE", ch.le_circle), ("TE", ch.te_circle)):
        near = np.linalg.norm(xy - circle.center, axis=1) <= EDGE_DENSIFY_REACH * circle.radius
        edge_h = airfoil.edge_spacing_mm(circle.radius, noise_mm,
                                         radius_sigma_mm) / EDGE_DENSIFY_MARGIN
        h[near] = np.minimum(h[near], edge_h)
        if record is not None:
            record.append({"edge": name, "radius_mm": float(circle.radius),
                           "center_cad": frame.to_3d(circle.center)[0].tolist(),
                           "spacing_mm": float(min(edge_h, spacing))})
    return h


def _resample_graded(loop, h):
    """A closed loop resampled with spacing h (given at its vertices, linear between): points
    evenly spread in the count n(s) = integral of ds / h."""
    pts = np.vstack([loop, loop[:1]])
    h = np.concatenate([h, h[:1]])
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    count = np.concatenate([[0.0], np.cumsum(seg * 0.5 * (1.0 / h[:-1] + 1.0 / h[1:]))])
    n = max(3, int(np.round(count[-1])))
    t = np.interp(np.linspace(0.0, count[-1], n, endpoint=False), count, arc)
    return np.column_stack([np.interp(t, arc, pts[:, k]) for k in range(3)])


def nominal_section(nominal, plane_point, plane_normal, spacing, edge_densify=None,
                    edge_record=None):
    """Points every ``spacing`` mm along the CAD's cut by the plane, each exactly on the CAD and
    on the plane, with outward normals, in contour order. Returns (points, normals, contours),
    contours a list of (first index, end index, closed). InputError when the plane misses.
    ``edge_densify`` = (noise_mm, radius_sigma_mm): closed contours get points closer round
    their LE and TE (``_edge_spacing``, which adds each edge to the list ``edge_record``); a
    contour whose edges the airfoil kernel cannot find keeps the even spacing and adds
    {"edge": None, "failed": why} to ``edge_record``."""
    from ..cad.sections import cut   # cad/ needs FreeCAD; measurement/ imports without it
    n = np.asarray(plane_normal, dtype=float)
    n = n / np.linalg.norm(n)
    o = np.asarray(plane_point, dtype=float)
    pts, contours, start = [], [], 0
    for line in cut(nominal.shape, o, n):
        closed = len(line) > 2 and np.linalg.norm(line[0] - line[-1]) < 1e-9
        h = None
        if closed and edge_densify is not None:
            try:
                h = _edge_spacing(line[:-1], o, n, spacing, *edge_densify, record=edge_record)
            except InputError as exc:
                # A loop the airfoil kernel cannot read (a tip cap, a hub fillet's ring, a
                # profile too coarse for it) keeps the even spacing; the plan says so.
                if edge_record is not None:
                    edge_record.append({"edge": None, "failed": str(exc)})
        if h is not None:
            p = _resample_graded(line[:-1], h)
        else:
            p = _resample(line[:-1] if closed else line, closed, spacing)
        contours.append((start, start + len(p), closed))
        start += len(p)
        pts.append(p)
    if start < 2:
        raise InputError("section plane through %s: the cut of the CAD is shorter than the "
                         "point spacing" % np.round(o, 3).tolist())
    p = np.vstack(pts)
    for _ in range(SECTION_PROJECTIONS):
        background.tick()    # a GUI's event loop turns between the projections
        res = nominal.signed_distance(p)
        off_plane = (res.closest - o) @ n
        if np.max(np.abs(off_plane)) < SECTION_TOLERANCE_MM:
            break
        p = res.closest - np.outer(off_plane, n)
    return res.closest, _surface_normals(nominal, res.closest), contours


def _surface_normals(nominal, points):
    """Outward normals at points on the CAD. The distance query's normal of a point lying on
    the surface is the direction to it, undefined at that distance (on a face's edge it comes
    out arbitrary): ask instead about points lifted off the surface along the nearest sample's
    normal, whose closest points are the same and whose direction is the surface normal."""
    from scipy.spatial import cKDTree
    _, idx = cKDTree(nominal.samples.xyz).query(points)
    lifted = points + NORMAL_PROBE_MM * nominal.samples.normal[idx]
    return nominal.signed_distance(lifted).normal


# ---------------------------------------------------------------- angles

def incidence_table(normals_table, angles_deg, kinematics):
    """cos(incidence) of every normal at every candidate angle, (A, K): the machine normal's
    Z component after turning the table by the angle."""
    cosines = np.empty((len(angles_deg), len(normals_table)))
    for i, a in enumerate(angles_deg):
        cosines[i] = normals_table @ kinematics.rotation(a)[2]
    return cosines


def _choose_angles(cosines, max_incidence_deg):
    """Greedy cover: the candidate angle that brings most remaining points within the planned
    incidence, repeatedly; points no angle brings within it get the one nearest. Returns the
    chosen candidate row per point."""
    good = cosines >= np.cos(np.radians(max_incidence_deg))
    todo = good.any(axis=0)
    chosen = []
    while todo.any():
        best = int(np.argmax((good & todo).sum(axis=1)))
        chosen.append(best)
        todo &= ~good[best]
    best_any = np.argmax(cosines, axis=0)
    unreachable = ~good.any(axis=0)
    chosen = sorted(set(chosen) | set(best_any[unreachable].tolist()))
    sub = cosines[chosen]
    return np.asarray(chosen)[np.argmax(sub, axis=0)], chosen


# ---------------------------------------------------------------- checks

def _beam_rays(table_to_cad, kinematics, angle_deg, spot_machine, standoff):
    """Rays in the CAD frame down the beam from the lens (standoff above each spot)."""
    cad_from_machine = _cad_from_machine(table_to_cad, kinematics, angle_deg)
    origins = tf.apply_transform(cad_from_machine, spot_machine + np.array([0.0, 0.0, standoff]))
    down = cad_from_machine[:3, :3] @ np.array([0.0, 0.0, -1.0])
    return origins, np.tile(down, (len(origins), 1))


def body_clear(samples_machine, spot_machine, standoff):
    """The sensor body, a cylinder about the beam from just below the lens upwards, must hold
    none of the blade's samples. The samples' highest z per cell of a 2D grid, spread over a
    disc of the body's radius (grown by a cell's diagonal, so the test errs on the safe side),
    gives at each spot the highest blade point under the body."""
    from scipy.ndimage import maximum_filter
    cell = BODY_CELL_MM
    reach = BODY_RADIUS_MM + cell * np.sqrt(2.0)
    pad = int(np.ceil(reach / cell))
    lo = np.minimum(samples_machine[:, :2].min(axis=0), spot_machine[:, :2].min(axis=0))
    idx = np.floor((samples_machine[:, :2] - lo) / cell).astype(int) + pad
    shape = idx.max(axis=0) + pad + 1
    spot_idx = np.floor((spot_machine[:, :2] - lo) / cell).astype(int) + pad
    shape = np.maximum(shape, spot_idx.max(axis=0) + pad + 1)
    height = np.full(tuple(shape), -np.inf)
    np.maximum.at(height, (idx[:, 0], idx[:, 1]), samples_machine[:, 2])
    r = np.arange(-pad, pad + 1) * cell
    disc = (r[:, None] ** 2 + r[None, :] ** 2) <= reach ** 2
    under_body = maximum_filter(height, footprint=disc, mode="constant", cval=-np.inf)
    highest = under_body[spot_idx[:, 0], spot_idx[:, 1]]
    return highest < spot_machine[:, 2] + standoff - BODY_CLEARANCE_MM


def expected_snr(sensor, incidence_rad):
    """The sensor model's noise-free SNR at the range centre and the planned incidence."""
    return np.asarray(sensor.snr(np.full(len(incidence_rad), sensor.standoff), incidence_rad),
                      dtype=float)


# ---------------------------------------------------------------- the plan

def _runs(angle_rows, contours, reverse):
    """Split each contour into runs of consecutive points that share an angle; order runs by
    angle (reversed on alternate sections so the rotary goes back and forth)."""
    runs = []
    for first, end, closed in contours:
        idx = np.arange(first, end)
        cuts = np.flatnonzero(np.diff(angle_rows[idx]) != 0) + 1
        pieces = [list(r) for r in np.split(idx, cuts)]
        # On a closed contour the last and first runs meet when they share an angle.
        if closed and len(pieces) > 1 and angle_rows[idx[0]] == angle_rows[idx[-1]]:
            pieces[0] = pieces.pop() + pieces[0]
        runs += pieces
    runs.sort(key=lambda r: (angle_rows[r[0]], r[0]), reverse=reverse)
    return runs


class _SectionWork:
    """One section between choosing its candidate angles and checking them."""

    def __init__(self, index, height, plane_point, axis, target, normal, contours,
                 table_to_cad, kinematics):
        self.index, self.height, self.plane_point, self.axis = index, height, plane_point, axis
        self.target, self.normal, self.contours = target, normal, contours
        cad_to_table = tf.invert_transform(table_to_cad)
        self.target_t = tf.apply_transform(cad_to_table, target)
        self.cosines = incidence_table(normal @ cad_to_table[:3, :3].T, ANGLES, kinematics)
        self.chosen = []
        self.score = np.full(self.cosines.shape, -np.inf)
        self.beam_length = np.full(self.cosines.shape, np.nan)


def _check_views(works, nominal, table_to_cad, kinematics, sensor, samples_table):
    """Line of sight (one exact ray cast for every section and angle together: the cast's cost
    is mostly per beam direction, and sections share their angles) and body clearance at each
    section's chosen angles, for the points each angle could serve at all. Fills each
    section's score (cos incidence where the view is clear) and beam length."""
    standoff = float(sensor.standoff)
    usable = np.cos(np.radians(0.5 * float(sensor.coverage_deg) - COVERAGE_MARGIN_DEG))
    requests, origins, directions = [], [], []
    samples_m = {}
    for work in works:
        for row in work.chosen:
            background.tick()    # a GUI's event loop turns between the views
            cand = np.flatnonzero(work.cosines[row] >= usable)
            if len(cand) == 0:
                continue
            a = ANGLES[row]
            spot = kinematics.machine_point_of_table(work.target_t[cand], a)
            o, d = _beam_rays(table_to_cad, kinematics, a, spot, standoff)
            if row not in samples_m:
                samples_m[row] = kinematics.machine_point_of_table(samples_table, a)
            clear = body_clear(samples_m[row], spot, standoff)
            requests.append((work, row, cand, clear))
            origins.append(o)
            directions.append(d)
    if not requests:
        return
    t, _, _ = nominal.raycast(np.vstack(origins), np.vstack(directions))
    start = 0
    for work, row, cand, clear in requests:
        tt = t[start:start + len(cand)]
        start += len(cand)
        ok = clear & np.isfinite(tt) & (tt > standoff - LINE_OF_SIGHT_TOLERANCE_MM)
        work.score[row, cand[ok]] = work.cosines[row, cand[ok]]
        work.beam_length[row, cand] = tt


def _finish_section(work, kinematics, sensor, limits):
    """Each point's angle (the clear chosen one nearest head-on, or the next one where the
    stages' soft limits forbid it), setpoints and limit checks. Points no chosen angle can serve
    are left out, and all of them when fewer than MIN_SECTION_POINTS would remain; returns
    (PlannedSection of the rest, the boolean mask of the points kept, {reason: boolean mask
    over the section's points} of those left out, with "soft_limit_example" the first
    refusal's message when the limits left any out)."""
    standoff = float(sensor.standoff)
    score = work.score.copy()
    idx = np.arange(len(work.target))
    blocked = ~np.isfinite(score.max(axis=0))
    off_limits = np.zeros(len(idx), bool)
    limit_errors = []
    while True:
        rows = np.argmax(score, axis=0)
        live = np.isfinite(score[rows, idx])
        angle = ANGLES[rows]
        spot = np.empty_like(work.target_t)
        for a in np.unique(angle[live]):
            sel = live & (angle == a)
            spot[sel] = kinematics.machine_point_of_table(work.target_t[sel], a)
        stage = spot + np.array([0.0, 0.0, standoff])
        refused = _outside_limits(limits, stage, angle, live, limit_errors)
        if not refused.any():
            break
        # the next clear angle may bring the point within the limits
        score[rows[refused], idx[refused]] = -np.inf
        off_limits |= refused & ~np.isfinite(score.max(axis=0))
    keep = live.copy()
    too_few = np.zeros(len(idx), bool)
    if 0 < keep.sum() < MIN_SECTION_POINTS:
        too_few, keep = keep, np.zeros(len(idx), bool)
    incidence = np.degrees(np.arccos(np.clip(work.cosines[rows, idx], -1.0, 1.0)))
    section = PlannedSection(
        index=work.index, height_pct=work.height, plane_point=work.plane_point,
        plane_normal=work.axis.copy(), target_cad=work.target[keep],
        normal_cad=work.normal[keep], angle_deg=angle[keep], stage_xyz=stage[keep],
        expected_standoff_mm=work.beam_length[rows, idx][keep], incidence_deg=incidence[keep],
        expected_snr=expected_snr(sensor, np.radians(incidence[keep])))
    dropped = {}
    if blocked.any():
        dropped["view"] = blocked
    if off_limits.any():
        dropped["soft_limits"] = off_limits
        dropped["soft_limit_example"] = limit_errors[0]
    if too_few.any():
        dropped["too_few"] = too_few
    return section, keep, dropped


def _outside_limits(limits, stage, angle, live, errors):
    """Mask of the live points whose setpoint at their angle lies outside the soft limits
    (``errors`` gets each refusal's message); one check per angle while all pass."""
    refused = np.zeros(len(stage), bool)
    for a in np.unique(angle[live]):
        sel = np.flatnonzero(live & (angle == a))
        try:
            limits.check(stage[sel, 0], stage[sel, 1], stage[sel, 2], a)
            continue
        except DeviceError as exc:
            errors.append(str(exc))
        for i in sel:
            try:
                limits.check(stage[i, 0], stage[i, 1], stage[i, 2], a)
            except DeviceError:
                refused[i] = True
    return refused


def _kept_contours(contours, keep):
    """Contours (first, end, closed) of the kept points, renumbered: a contour that lost points
    is cut into open stretches at each gap, so no path runs across points left out."""
    if keep.all():
        return list(contours)
    new_index = np.cumsum(keep) - 1
    out = []
    for first, end, closed in contours:
        kept = np.flatnonzero(keep[first:end]) + first
        if len(kept) == end - first:
            out.append((int(new_index[first]), int(new_index[first]) + len(kept), closed))
            continue
        for stretch in np.split(kept, np.flatnonzero(np.diff(kept) != 1) + 1):
            if len(stretch):
                out.append((int(new_index[stretch[0]]),
                            int(new_index[stretch[0]]) + len(stretch), False))
    return out


# Why points are left out of a plan, as the notes say it.
_DROP_REASONS = {
    "view": "cannot be seen within the sensor's coverage (less %g deg margin) without the "
            "sensor meeting the blade" % COVERAGE_MARGIN_DEG,
    "soft_limits": "are outside the stages' soft limits at every clear angle",
    "too_few": "were too few to measure the section once the rest were left out (%d "
               "needed)" % MIN_SECTION_POINTS}


def _places(points, frame_edges):
    """How many of ``points`` (CAD frame) lie round the LE, round the TE (within
    EDGE_DENSIFY_REACH radii of the edge circle, where the edge rule adds points) and
    elsewhere on the profile (the edges' circles ``frame_edges`` as _edge_spacing records
    them)."""
    counts, rest = {}, np.ones(len(points), bool)
    for e in frame_edges:
        near = rest & (np.linalg.norm(points - np.asarray(e["center_cad"]), axis=1)
                       <= EDGE_DENSIFY_REACH * e["radius_mm"])
        counts[e["edge"]] = counts.get(e["edge"], 0) + int(near.sum())
        rest &= ~near
    # without the edge rule's circles the plan does not know where its edges are
    counts["elsewhere" if frame_edges else "on the profile"] = int(rest.sum())
    return counts


def unreachable_info(records):
    """plan.json's and result.json's record of the planned points left out (None when none
    was): per section the count, why and where, and one warning line each."""
    sections, warnings = [], []
    for rec in records:
        if rec.get("no_cut"):
            sections.append(rec)
            warnings.append("section at %g %%: not measured, the plane does not cut the "
                            "CAD's blade (%s)" % (rec["height_pct"], rec["no_cut"]))
            continue
        if not rec["n_dropped"]:
            continue
        sections.append(rec)
        why = "; ".join("%d %s" % (n, _DROP_REASONS[r]) for r, n in rec["by_reason"].items())
        where = ", ".join("%s %d" % (k, v) for k, v in rec["by_place"].items() if v)
        if rec["n_planned"] == 0:
            warnings.append("section at %g %%: not measured, none of its %d points can be "
                            "planned (%s; %s)" % (rec["height_pct"], rec["n_dropped"], why,
                                                  where))
        else:
            warnings.append("section at %g %%: %d of %d points left out of the plan (%s; "
                            "where: %s)" % (rec["height_pct"], rec["n_dropped"],
                                            rec["n_dropped"] + rec["n_planned"], why, where))
    if not sections:
        return None
    return {"warnings": warnings, "sections": sections}


def _dropped_record(work, section, dropped, edges):
    gone = np.zeros(len(work.target), bool)
    by_reason = {}
    for reason in ("view", "soft_limits", "too_few"):
        if reason in dropped:
            gone |= dropped[reason]
            by_reason[reason] = int(dropped[reason].sum())
    rec = {"height_pct": work.height, "n_planned": section.n_points,
           "n_dropped": int(gone.sum()), "by_reason": by_reason,
           "by_place": _places(work.target[gone], edges)}
    if "soft_limit_example" in dropped:
        rec["soft_limit_example"] = dropped["soft_limit_example"]
    return rec


def plan_sections(nominal, table_to_cad, heights_pct, sensor, limits, span_axis=None,
                  spacing=0.1, kinematics=None, max_incidence_deg=MAX_INCIDENCE_DEG,
                  edge_radius_sigma_mm=None):
    """Plan readings along the nominal sections at ``heights_pct`` (% of the span).

    ``table_to_cad`` maps rotary-table points into the CAD frame (the registration's
    measured_to_cad for points in the table frame); ``kinematics`` supplies the rotary axis
    (None: the nominal axis through the origin along +Y); ``limits`` an AxisLimits.
    Returns a Plan. Raises InputError for heights outside 0-100. What a blade or the rig
    cannot allow (a plane that misses the CAD, points out of view or beyond the soft limits,
    too few points left, edges the edge rule cannot find) leaves those points or sections out
    with a note in ``info`` ("unreachable", "edge_density"); only a plan left with no point
    at all is refused (DeviceError when the soft limits are why, else InputError).
    ``edge_radius_sigma_mm`` (None: off): points round each section's LE and
    TE closer, so that its fitted edge radius's 1-sigma at the sensor's reference noise
    (sensor.sigma_ref) is at most this (docs/user-guide.md, "Edges measured densely enough")."""
    heights = [float(h) for h in np.atleast_1d(heights_pct)]
    if not heights:
        raise InputError("--section-heights: at least one height is needed")
    for h in heights:
        if not (np.isfinite(h) and 0.0 <= h <= 100.0):
            raise InputError("--section-heights: %g is outside 0-100 %% of the span" % h)
    if not (np.isfinite(spacing) and spacing > 0):
        raise InputError("plan: point spacing must be positive, got %r" % (spacing,))
    table_to_cad = np.asarray(table_to_cad, dtype=float)
    cad_to_table = tf.invert_transform(table_to_cad)
    axis, origin, lo, hi = span_axis_of(nominal, span_axis)
    kinematics = kinematics if kinematics is not None else RigKinematics()
    samples_table = tf.apply_transform(cad_to_table, nominal.samples.xyz)

    edge_radius_sigma_mm = edge_radius_sigma(edge_radius_sigma_mm)
    densify = (None if edge_radius_sigma_mm is None
               else (float(sensor.sigma_ref), edge_radius_sigma_mm))
    works, edges, edge_failures, no_cut = [], [], [], {}
    for k, h in enumerate(heights):
        plane_point = origin + axis * (lo + (hi - lo) * h / 100.0)
        edges.append([])
        try:
            target, normal, contours = nominal_section(nominal, plane_point, axis, spacing,
                                                       densify, edges[-1])
        except InputError as exc:
            # A height where this blade has no section to measure (past a tip, through a
            # gap): that section is not measured, the others are.
            no_cut[k] = str(exc)
            target, normal, contours = np.zeros((0, 3)), np.zeros((0, 3)), []
        edge_failures.append([e["failed"] for e in edges[-1] if e["edge"] is None])
        edges[-1] = [e for e in edges[-1] if e["edge"] is not None]
        works.append(_SectionWork(k, h, plane_point, axis, target, normal, contours,
                                  table_to_cad, kinematics))
    if not any(len(w.target) for w in works):
        raise InputError("plan: no section can be measured; the planes at %s %% do not cut "
                         "the CAD's blade (%s)" % (", ".join("%g" % h for h in heights),
                                                  no_cut[0]))
    # One set of angles for all sections: fewer rotations between sections, and the exact ray
    # cast's cost is mostly per beam direction.
    _, shared = _choose_angles(np.hstack([w.cosines for w in works]), max_incidence_deg)
    for work in works:
        work.chosen = shared
    _check_views(works, nominal, table_to_cad, kinematics, sensor, samples_table)
    sections, paths = [], []
    last_stage = None
    records = []
    for work, section_edges in zip(works, edges):
        section, keep, dropped = _finish_section(work, kinematics, sensor, limits)
        records.append(_dropped_record(work, section, dropped, section_edges))
        if work.index in no_cut:
            records[-1]["no_cut"] = no_cut[work.index]
        sections.append(section)
        rows = np.searchsorted(ANGLES, section.angle_deg)
        for run in _runs(rows, _kept_contours(work.contours, keep),
                         reverse=bool(work.index % 2)):
            run = np.asarray(run, dtype=int)
            # Enter each run from the end nearer to where the stages are.
            stage = section.stage_xyz
            if last_stage is not None and (np.linalg.norm(stage[run[-1]] - last_stage)
                                           < np.linalg.norm(stage[run[0]] - last_stage)):
                run = run[::-1]
            paths.append(PlannedPath(section=work.index,
                                     angle_deg=float(section.angle_deg[run[0]]), points=run))
            last_stage = stage[run[-1]]
    info = {"max_incidence_deg": max_incidence_deg, "angle_step_deg": ANGLE_STEP_DEG,
            "body_radius_mm": BODY_RADIUS_MM,
            "angles_per_section": [len(np.unique(s.angle_deg)) for s in sections],
            "edge_density": edge_density_info(densify, edges, heights,
                                              float(getattr(sensor, "spot", 0.0)),
                                              edge_failures)}
    _refuse_empty(sections, records)
    left_out = unreachable_info(records)
    if left_out is not None:
        info["unreachable"] = left_out
    return Plan(sections=sections, paths=paths, table_to_cad=table_to_cad, span_axis=axis,
                span_range=(lo, hi), axis_point=kinematics.axis_point.copy(),
                axis_direction=kinematics.axis_direction.copy(),
                standoff_mm=float(sensor.standoff), spacing_mm=float(spacing), info=info)


def _refuse_empty(sections, records):
    """A plan with no point at all is no plan: InputError (the blade cannot be seen), or
    DeviceError when the stages' soft limits are what left its points out."""
    if any(s.n_points for s in sections):
        return
    limited = [r for r in records if r["by_reason"].get("soft_limits")]
    if limited:
        raise DeviceError("plan: section at %g %% unreachable within soft limits (%s)"
                          % (limited[0]["height_pct"], limited[0]["soft_limit_example"]))
    info = unreachable_info(records)
    raise InputError("plan: no section can be measured; %s"
                     % (info["warnings"][0] if info else "no section has a point to plan"))


def edge_radius_sigma(value):
    """The edge rule's target sigma_R in mm from a caller's or the command line's value: None,
    0 or "off" turn the rule off (None returned); InputError for anything else not positive."""
    if value is None or (isinstance(value, str) and value.strip().lower() == "off"):
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    if v == 0:
        return None
    if not (np.isfinite(v) and v > 0):
        raise InputError("--edge-radius-sigma: expected a positive 1-sigma in mm, 0 or off, "
                         "got %r" % (value,))
    return v


def edge_density_info(densify, edges, heights, spot_mm, failures=None):
    """plan.json's and result.json's record of the edge rule a plan used (None: off), with a
    warning for each edge whose radius is under EDGE_MIN_SPOTS sensor spots (the rule counts
    readings as independent points, a real reading averages the surface over its spot) and
    for each section whose edges could not be found (``failures``: per section the reasons),
    which keeps its even spacing."""
    if densify is None:
        return None
    from ..core import airfoil
    noise, target = densify
    failures = failures or [[] for _ in heights]
    warnings = ["section at %g %%: no extra edge points planned on a loop of its cut whose "
                "edges could not be found (%s); edge radii there are not measured to the "
                "rule's sigma"
                % (h, "; ".join(why)) for h, why in zip(heights, failures) if why]
    warnings += ["section at %g %%: %s radius %.3f mm is under %g sensor spots (%.3f mm): a "
                "reading averages the edge over its spot, so this edge's radius, edge point "
                "and the chord through it are not measured by this sensor, however dense "
                "the points"
                % (h, e["edge"], e["radius_mm"], EDGE_MIN_SPOTS, spot_mm)
                for h, section in zip(heights, edges) for e in section
                if e["radius_mm"] < EDGE_MIN_SPOTS * spot_mm]
    return {"radius_sigma_mm": target, "noise_mm": noise, "warnings": warnings,
            "zone_deg": airfoil.DEFAULT_EDGE_ZONE_DEG,
            "points_per_zone": airfoil.edge_points_needed(noise, target),
            "margin": EDGE_DENSIFY_MARGIN, "reach_radii": EDGE_DENSIFY_REACH,
            "rule": "n = ceil((noise / radius_sigma * f(zone))^2) points in each +-zone edge "
                    "zone, times margin, spread within reach_radii edge radii of the edge "
                    "circle's centre (docs/user-guide.md)",
            "sections": edges,
            "sections_without_edges": [h for h, why in zip(heights, failures) if why]}


def _cad_from_machine(table_to_cad, kinematics, angle_deg):
    return table_to_cad @ tf.invert_transform(kinematics.table_to_machine_transform(angle_deg))
