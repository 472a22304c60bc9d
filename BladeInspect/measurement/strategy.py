"""The blind section-line scan (paper 3.1.1, steps 1-5), driven only by what the sensor reads.

Per section plane Y = y_k and per view (rotary angle):
  1. find the surface: linear passes at fixed Z until the sensor reads, first at the height
     where it is expected (this section's views already measured, turned to this angle; else
     the previous section's; for the first section, what the span probe read near it), then
     through the search envelope outward from there (top down when nothing is known);
  2. that linear scan at fixed Z gives the first points, only those within the working range;
  3. fit a cubic uniform B-spline to the valid points (parametric by chord length, so the
     steep flanks near the edges are as easy as the flat middle);
  4. rescan along the fitted curve raised by the standoff, judge |d - z_s| <= epsilon, and
     extend the path past both ends along the curve's tangent while readings continue;
     refit with everything read so far and repeat;
  5. when a pass meets the criterion over the whole section and neither end grows, scan the
     curve once more at the final point spacing; only readings meeting the criterion are kept.
Views of a section: the first side at the section's base angle, the edges at +-90 deg (edge up,
as far as the angular coverage reaches; a thin edge shows only its nose, looked for finely
where the side views' ends predict it) and the other side at +180 deg. The next section's
base angle is the one that levelled this section's first side (its chord read from the points)
carried on by the twist rate read between the last two sections, so every section is scanned
nearly level. The first section levels itself the same way before it counts, and its first
side's view then starts from the last levelling points turned on by the residual twist.

Everything is in stage coordinates while planning (surface height = Z - d); the kinematics
(RIG.json) turns the kept readings into machine and then table-frame points.
"""

from dataclasses import dataclass, field, fields, replace

import numpy as np
from scipy.interpolate import BSpline

from ..core import background
from ..core.errors import InputError
from ..rig.kinematics import RigKinematics

# Views of one section as (name, angle offset from the section's base angle in deg).
SIDE_VIEWS = (("side1", 0.0), ("side2", 180.0))
EDGE_VIEWS = (("edge1", 90.0), ("edge2", 270.0))
MIN_VIEW_POINTS = 5
MIN_EDGE_POINTS = 3
EDGE_WINDOW_MM = 5.0
EDGE_PROBE_SPACING_MM = 0.05
SPAN_PROBE_OFFSETS = (-15.0, 15.0)
# An end that keeps reading doubles its extension up to this many times extension_mm: a long
# blade's side seen from an edge view runs on for tens of mm past the first find, and a cap of
# a few extensions crept along it 12 mm a pass (Rotor 67: up to 8 rescans for one view).
MAX_EXTENSION_FACTOR = 16.0
# Where the re-centred first window puts the highest surface point found, in half ranges
# above the window's centre.
RECENTRE_TOP = 0.6
# A search window is skipped when it lies within this many half ranges of one that read
# nothing: more than half of it was seen empty already.
SKIP_OVERLAP = 0.8
# The span probe's readings this close to a section (along the axis) predict where its first
# search finds the surface.
PROBE_HINT_MM = 3.0
# The levelling view's points that start the first section's side1 view stay below this
# slope once turned to the section's angle.
START_MAX_SLOPE_DEG = 60.0
LEVEL_TOLERANCE_DEG = 10.0
MAX_LEVELLING = 3
KNOT_SPACING_MM = 1.5
# Second-difference penalty relative to the data term: small enough not to bias the fit where
# data are dense, enough to bridge gaps (a straight line across them) and the end intervals.
SMOOTHING = 1e-3
OUTLIER_SIGMAS = 6.0
OUTLIER_FLOOR_MM = 0.03
MAX_FIT_ROUNDS = 5
# Sampling of the fitted curve for point-to-curve distances: its chord error at the curvature
# of a blade's edge (radius ~0.2 mm and up) stays below a micrometre.
DENSE_STEP_MM = 0.02


# ---------------------------------------------------------------- section curve (step 3)

class SectionCurve:
    """Cubic uniform B-spline (x(s), z(s)) fitted to section points, s ~ arc length on
    [0, length], x increasing with s; beyond the ends it continues along the end tangents (the
    path extension), kept at least ``min_dx`` outward in x per unit length: a surface seen
    from above is never steeper than the sensor's coverage, and a vertical extension would
    probe the same spot over and over."""

    def __init__(self, x_spline, z_spline, length, min_dx=np.cos(np.radians(85.0))):
        self._x, self._z = x_spline, z_spline
        self._dx, self._dz = x_spline.derivative(), z_spline.derivative()
        self.length = float(length)
        self.min_dx = float(min_dx)

    def tangent(self, s):
        """Unit tangent in the direction of increasing s (and x), at most as steep as
        min_dx allows."""
        t = np.array([float(self._dx(s)), float(self._dz(s))])
        n = np.linalg.norm(t)
        t = t / n if n > 0 else np.array([1.0, 0.0])
        if t[0] < self.min_dx:
            t = np.array([self.min_dx, np.copysign(np.sqrt(1.0 - self.min_dx ** 2), t[1])])
        return t

    def __call__(self, s):
        s = np.atleast_1d(np.asarray(s, dtype=float))
        inner = np.clip(s, 0.0, self.length)
        out = np.column_stack([self._x(inner), self._z(inner)])
        for end, mask in ((0.0, s < 0.0), (self.length, s > self.length)):
            if np.any(mask):
                start = np.array([float(self._x(end)), float(self._z(end))])
                out[mask] = start + np.outer(s[mask] - end, self.tangent(end))
        return out


def _chord_parameter(x, z):
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(z)))])
    return s


def _penalised_fit(s, values, length, knot_spacing):
    """Cubic spline with uniform knots, least squares plus a second-difference penalty."""
    intervals = max(1, int(np.ceil(length / knot_spacing)))
    inner = np.linspace(0.0, length, intervals + 1)
    knots = np.concatenate([[0.0] * 3, inner, [length] * 3])
    B = BSpline.design_matrix(np.clip(s, 0.0, length), knots, 3).toarray()
    n = B.shape[1]
    D = np.diff(np.eye(n), 2, axis=0)
    BtB = B.T @ B
    lam = SMOOTHING * max(np.mean(np.diag(BtB)), 1e-12)
    coef = np.linalg.solve(BtB + lam * D.T @ D + 1e-12 * np.eye(n), B.T @ values)
    return BSpline(knots, coef, 3, extrapolate=False)


def fit_stage_profile(x, z, knot_spacing=KNOT_SPACING_MM, max_incidence_deg=85.0):
    """The surface profile one view reads along a section line, in stage coordinates: a cubic
    uniform B-spline through the points seen from above (a graph z(x); the path the rescan
    follows, not cad.loft's curve of a whole measured section line). Gross
    errors are removed by a robust scale of the point-to-curve distances (of every point, so
    a point wrongly dropped while an outlier still bent the curve comes back) and the fit is
    repeated until the kept set settles. Returns (SectionCurve, kept mask in input order)."""
    from scipy.spatial import cKDTree
    x = np.asarray(x, dtype=float)
    z = np.asarray(z, dtype=float)
    order = np.argsort(x, kind="stable")
    points = np.column_stack([x, z])
    keep = np.ones(len(x), bool)
    min_dx = np.cos(np.radians(max_incidence_deg))
    for _ in range(MAX_FIT_ROUNDS):
        idx = order[keep[order]]
        s = _chord_parameter(x[idx], z[idx])
        length = max(s[-1], 1e-6)
        curve = SectionCurve(_penalised_fit(s, x[idx], length, knot_spacing),
                             _penalised_fit(s, z[idx], length, knot_spacing), length, min_dx)
        dense = curve(np.linspace(0.0, length, max(2, int(length / DENSE_STEP_MM) + 1)))
        r, _ = cKDTree(dense).query(points)
        # Half-normal distances: sigma = 1.4826 * median.
        limit = max(OUTLIER_SIGMAS * 1.4826 * np.median(r[keep]), OUTLIER_FLOOR_MM)
        new_keep = r <= limit
        if np.count_nonzero(new_keep) < MIN_VIEW_POINTS or np.array_equal(new_keep, keep):
            break
        keep = new_keep
    return curve, keep


# ---------------------------------------------------------------- results and state

@dataclass
class ViewResult:
    name: str
    angle_deg: float
    stage_xyz: np.ndarray          # (N,3) final-pass triggers kept
    reading_mm: np.ndarray         # (N,)
    snr: np.ndarray                # (N,)
    passes: list                   # per pass: kind, points, readings, max_standoff_error_mm, ...
    surface_z: float = None        # median surface height in stage Z (the next section's hint)


@dataclass
class SectionResult:
    index: int
    y: float
    base_angle_deg: float
    table_xyz: np.ndarray          # (N,3) table-frame points
    snr: np.ndarray
    angle_deg: np.ndarray          # (N,) rotary angle of each point
    views: list                    # ViewResult
    simulated_s: float
    max_standoff_error_mm: float

    @property
    def passes(self):
        return sum(len(v.passes) for v in self.views)


@dataclass
class StrategyState:
    """Everything a resumed scan needs to measure the remaining sections exactly as an
    uninterrupted one would (JSON-ready through to_dict)."""
    section_y: list = None
    next_section: int = 0
    base_angle_deg: float = 0.0
    levelled: bool = False
    surface_z: dict = field(default_factory=dict)     # view name -> stage-Z surface height
    level_angles: list = field(default_factory=list)  # [y, angle levelling side 1] per section
    pass_index: int = None
    span_range: list = None

    def to_dict(self):
        return {"section_y": None if self.section_y is None else [float(v) for v in self.section_y],
                "next_section": int(self.next_section),
                "base_angle_deg": float(self.base_angle_deg),
                "levelled": bool(self.levelled),
                "surface_z": {k: float(v) for k, v in self.surface_z.items()},
                "level_angles": [[float(a), float(b)] for a, b in self.level_angles],
                "pass_index": self.pass_index,
                "span_range": self.span_range}

    @classmethod
    def from_dict(cls, data):
        try:
            return cls(section_y=data["section_y"], next_section=int(data["next_section"]),
                       base_angle_deg=float(data["base_angle_deg"]),
                       levelled=bool(data["levelled"]), surface_z=dict(data["surface_z"]),
                       level_angles=[list(v) for v in data.get("level_angles", [])],
                       pass_index=data.get("pass_index"), span_range=data.get("span_range"))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError("scan checkpoint: malformed strategy state (%s)" % exc)


# ---------------------------------------------------------------- the strategy

@dataclass(frozen=True)
class ScanOptions:
    """What the blind scan measures and how finely (``ScanStrategy``'s options; scan.json's
    ``options`` hold them by these names).

    ``span_range`` (lo, hi): the blade's extent along the rotary axis (machine Y); None probes
    it. Sections are evenly spread inside it, ``end_margin`` (fraction of the span, at least
    1 mm) from its ends, or ``section_spacing`` mm apart centred on it. ``point_spacing``: final
    pass, along the section; ``probe_spacing``: probes and intermediate passes. ``epsilon``:
    the standoff criterion |d - z_s|. ``sides`` 1 or 2, ``edges``: the extra edge views.
    ``search_radius``: the part lies within this distance of the rotary axis."""
    n_sections: int = 5
    span_range: tuple = None
    section_spacing: float = None
    point_spacing: float = 0.1
    probe_spacing: float = 0.5
    epsilon: float = 2.0
    sides: int = 2
    edges: bool = True
    max_passes: int = 8
    search_radius: float = 45.0
    end_margin: float = 0.05
    extension_mm: float = 3.0

    @classmethod
    def from_dict(cls, options):
        """The options named in ``options`` (the rest at their defaults); an unknown name is an
        InputError."""
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(options) - names)
        if unknown:
            raise InputError("scan: unknown option %s" % ", ".join(unknown))
        return cls(**options)

    def validated(self, sensor):
        """These options with numbers as numbers; InputError for a value the scan cannot use
        with ``sensor``."""
        if int(self.n_sections) != self.n_sections or self.n_sections < 1:
            raise InputError("--sections: must be a positive integer, got %r"
                             % (self.n_sections,))
        if self.sides not in (1, 2):
            raise InputError("--sides: must be 1 or 2, got %r" % (self.sides,))
        if not 0 < self.epsilon <= sensor.half_range:
            raise InputError("--epsilon: must be in (0, %g] mm (the half range), got %r"
                             % (sensor.half_range, self.epsilon))
        for name, value in (("point spacing", self.point_spacing),
                            ("probe spacing", self.probe_spacing),
                            ("search radius", self.search_radius),
                            ("extension", self.extension_mm)):
            if not (np.isfinite(value) and value > 0):
                raise InputError("scan %s: must be a positive number of mm, got %r"
                                 % (name, value))
        if int(self.max_passes) != self.max_passes or self.max_passes < 1:
            raise InputError("scan max_passes: must be a positive integer, got %r"
                             % (self.max_passes,))
        span_range = self.span_range
        if span_range is not None:
            span_range = tuple(float(v) for v in span_range)
            if len(span_range) != 2 or not span_range[1] > span_range[0]:
                raise InputError("scan span range: expected (lo, hi) with lo < hi, got %r"
                                 % (self.span_range,))
        return replace(self, n_sections=int(self.n_sections), span_range=span_range,
                       point_spacing=float(self.point_spacing),
                       probe_spacing=float(self.probe_spacing), epsilon=float(self.epsilon),
                       max_passes=int(self.max_passes),
                       search_radius=float(self.search_radius),
                       end_margin=float(self.end_margin),
                       extension_mm=float(self.extension_mm))


class ScanStrategy:
    """The paper's section-line scan on any Rig, with ``options`` (ScanOptions; default
    ScanOptions()). ``kinematics``: the rig geometry believed (RIG.json); default nominal.
    ``state``: a checkpoint to continue from (StrategyState)."""

    def __init__(self, rig, options=None, kinematics=None, state=None):
        sensor = rig.sensor
        if sensor is None:
            raise InputError("scan: the rig has no sensor model")
        self.options = (options if options is not None else ScanOptions()).validated(sensor)
        self.rig = rig
        self.sensor = sensor
        self.views = SIDE_VIEWS[:self.options.sides] + (EDGE_VIEWS if self.options.edges else ())
        self.kinematics = kinematics if kinematics is not None else RigKinematics()
        d = self.kinematics.axis_direction
        # Turning the table by +phi lowers a chord inclined by phi when the axis runs along +Y.
        self._twist_sign = 1.0 if d[1] >= 0 else -1.0
        self.state = (state if state is not None
                      else StrategyState(span_range=None if self.options.span_range is None
                                         else list(self.options.span_range)))
        # (angle, y, surface height) of the span probe's readings; not part of the checkpoint,
        # which is only taken once the first section (and its levelling) is done.
        self._probed = []
        # The first section's last levelling view, when it met the tolerance (not part of the
        # checkpoint either: it is used within that section).
        self._levelled_view = None
        if state is not None and state.pass_index is not None and hasattr(rig, "set_pass_index"):
            rig.set_pass_index(state.pass_index)

    # -- public --------------------------------------------------------------------------------

    @property
    def section_y(self):
        if self.state.section_y is None:
            self.state.section_y = self._plan_sections()
        return self.state.section_y

    def sections(self, progress=None):
        """Measure the remaining sections one by one, yielding SectionResult; self.state is
        the checkpoint after each (what scan.py saves)."""
        ys = self.section_y
        while self.state.next_section < len(ys):
            k = self.state.next_section
            if progress is not None:
                progress(k / len(ys), "section %d of %d at Y=%.2f" % (k + 1, len(ys), ys[k]))
            result = self._scan_section(k, ys[k], ys[k + 1] if k + 1 < len(ys) else None)
            self.state.next_section = k + 1
            self.state.pass_index = getattr(self.rig, "pass_index", None)
            yield result

    def run(self, progress=None):
        return list(self.sections(progress))

    # -- sections ------------------------------------------------------------------------------

    def _plan_sections(self):
        if self.state.span_range is None:
            self.state.span_range = self._probe_span()
        lo, hi = self.state.span_range
        span = hi - lo
        margin = max(1.0, self.options.end_margin * span)
        if self.options.n_sections == 1:
            return [0.5 * (lo + hi)]
        if self.options.section_spacing is not None:
            total = self.options.section_spacing * (self.options.n_sections - 1)
            if not (self.options.section_spacing > 0 and total <= span - 2 * margin):
                raise InputError("--section-spacing %r: %d sections do not fit in the %.1f mm "
                                 "span" % (self.options.section_spacing,
                                           self.options.n_sections, span))
            mid = 0.5 * (lo + hi)
            return list(mid - 0.5 * total
                        + self.options.section_spacing * np.arange(self.options.n_sections))
        return list(np.linspace(lo + margin, hi - margin, self.options.n_sections))

    def _probe_span(self):
        """The blade's extent along the rotary axis: passes along Y over the axis, stepping
        down in Z, at the current angle and a quarter turn on. At one of the two the chord is
        at least 45 deg from edge-on, so even 10 mm off the axis it lies under the line all
        along the span despite the twist. Where the line reads, two more lines either side
        (the other edge of a narrow view, a line leaving the chord) add to it; everything
        read gives the span. Lines are long, so empty heights cost one line, not three."""
        lim = self.rig.limits
        ax = self.kinematics.axis_point[0]
        ys = self._samples(lim.y[0], lim.y[1], 1.0)
        centre = np.column_stack([np.full(len(ys), ax), ys])
        sides = np.vstack([np.column_stack([np.full(len(ys), ax + dx), ys[::(-1) ** i]])
                           for i, dx in enumerate(SPAN_PROBE_OFFSETS)])
        found = []
        for angle in (self.state.base_angle_deg, self.state.base_angle_deg + 90.0):
            seen = False
            for level in self._levels():
                z_stage = level + self.sensor.standoff
                if not lim.z[0] <= z_stage <= lim.z[1]:
                    continue
                y_read = self._read_along(centre, z_stage, angle)
                if len(y_read) < MIN_VIEW_POINTS:
                    if seen:
                        break       # below the surface already seen: nothing more to find
                    continue
                seen = True
                found += [y_read, self._read_along(sides, z_stage, angle)]
        if found:
            found = np.concatenate(found)
            return [float(found.min()), float(found.max())]
        raise InputError("scan: the sensor found no surface within %g mm of the rotary axis "
                         "(check the part is mounted and the search radius)"
                         % self.options.search_radius)

    def _read_along(self, xy, z_stage, angle):
        """Y of the readings of one pass over the (x, y) points at height z_stage. The surface
        heights read are kept: they tell the first section's search where to start."""
        stage = np.column_stack([xy, np.full(len(xy), z_stage)])
        d = np.asarray(self.rig.scan_path(stage, angle).reading_mm, dtype=float)
        ok = np.isfinite(d)
        self._probed.append((float(angle), xy[ok, 1], z_stage - d[ok]))
        return xy[ok, 1]

    def _probed_height(self, y, angle):
        """Median surface height the span probe read within PROBE_HINT_MM of Y = y at this
        rotary angle, or None."""
        near = [z[np.abs(ys - y) <= PROBE_HINT_MM] for a, ys, z in self._probed
                if abs(a - angle) < 1e-9]
        near = np.concatenate(near) if near else np.zeros(0)
        return float(np.median(near)) if len(near) else None

    def _levels(self):
        """Surface heights (stage Z - standoff) to probe at, from the top of the search
        envelope down; consecutive working windows overlap by a fifth of the range."""
        az = self.kinematics.axis_point[2]
        half = self.sensor.half_range
        return list(np.arange(az + self.options.search_radius - 0.8 * half,
                              az - self.options.search_radius - half, -1.6 * half))

    def _predict_level(self, next_y):
        """The angle that should put the next section's chord level: the last level angle
        carried on by the twist rate read between the last two sections."""
        (y1, a1) = self.state.level_angles[-1]
        if next_y is None or len(self.state.level_angles) < 2:
            return a1
        (y0, a0) = self.state.level_angles[-2]
        return a1 + (a1 - a0) * (next_y - y1) / (y1 - y0)

    def _scan_section(self, k, y, next_y=None):
        start = self.rig.elapsed_s
        base = self.state.base_angle_deg
        if not self.state.levelled:
            base = self._level(y, base)
        levelled, self._levelled_view = self._levelled_view, None
        results = []
        for name, offset in self._view_order(k):
            angle = base + offset
            known = None
            if name.startswith("edge"):
                near, predicted = self._edge_prediction(results, angle), None
            else:
                near, predicted = None, self._side_prediction(results, angle)
                if name == "side1" and levelled is not None:
                    known = self._levelled_start(levelled, angle)
            results.append(self._scan_view(name, y, angle, near=near, predicted=predicted,
                                           start=known))
        first = next(v for v in results if v.name == "side1")
        twist = self._chord_angle(first)
        level = base + (0.0 if twist is None else self._twist_sign * twist)
        self.state.level_angles.append([float(y), float(level)])
        self.state.base_angle_deg = self._predict_level(next_y)
        for v in results:
            if v.surface_z is not None:
                self.state.surface_z[v.name] = v.surface_z
        pts, snr, ang = [], [], []
        errors = [0.0]
        for v in results:
            machine = self.kinematics.machine_point(v.stage_xyz, v.reading_mm)
            pts.append(self.kinematics.table_point(machine, v.angle_deg))
            snr.append(v.snr)
            ang.append(np.full(len(v.snr), v.angle_deg))
            if len(v.reading_mm):
                errors.append(float(np.max(np.abs(v.reading_mm - self.sensor.standoff))))
        return SectionResult(index=k, y=float(y), base_angle_deg=float(base),
                             table_xyz=np.vstack(pts) if pts else np.zeros((0, 3)),
                             snr=np.concatenate(snr), angle_deg=np.concatenate(ang),
                             views=results, simulated_s=self.rig.elapsed_s - start,
                             max_standoff_error_mm=max(errors))

    def _view_order(self, k):
        """Even sections turn up through 0, 90, 180, 270 deg, odd ones back down through
        180, 90, 0, -90: the rotary goes to and fro, and every edge view comes after a side
        view of the same section that shows where the edge is."""
        if k % 2 == 0:
            return sorted(self.views, key=lambda v: v[1])
        back = [(n, o - 360.0 if o > 180.0 else o) for n, o in self.views]
        return sorted(back, key=lambda v: -v[1])

    def _edge_prediction(self, side_views, angle):
        """Where an edge should show at this angle, from the ends of the side views measured
        (stage coordinates, turned about the axis): the end that comes out on top, or None."""
        k = self.kinematics
        ends = []
        for v in side_views:
            if not v.name.startswith("side") or len(v.reading_mm) < MIN_VIEW_POINTS:
                continue
            surface = v.stage_xyz - np.column_stack([np.zeros((len(v.reading_mm), 2)),
                                                     v.reading_mm])
            for i in (np.argmin(surface[:, 0]), np.argmax(surface[:, 0])):
                table = k.table_point(surface[i:i + 1], v.angle_deg)
                ends.append(k.machine_point_of_table(table, angle)[0])
        if not ends:
            return None
        top = max(ends, key=lambda p: p[2])
        return float(top[0]), float(top[2])

    def _turned_surface(self, views, angle):
        """The surface points of the views measured so far, in stage coordinates as they will
        lie once the table is turned to ``angle``."""
        k = self.kinematics
        out = []
        for v in views:
            if len(v.reading_mm) < MIN_VIEW_POINTS:
                continue
            surface = v.stage_xyz - np.column_stack([np.zeros((len(v.reading_mm), 2)),
                                                     v.reading_mm])
            out.append(k.machine_point_of_table(k.table_point(surface, v.angle_deg), angle))
        return np.vstack(out) if out else np.zeros((0, 3))

    def _side_prediction(self, views, angle):
        """Surface height (stage Z - standoff) a side view at this angle should find, from the
        views of this section already measured: their points turned to this angle lie on or
        under the surface seen from above (a thin blade's far side lies a thickness below
        it), so the median over the section of the highest turned point per millimetre of X
        lands within the working range. None before any view of the section read."""
        pts = self._turned_surface(views, angle)
        if len(pts) < MIN_VIEW_POINTS:
            return None
        cells = np.floor(pts[:, 0]).astype(int)
        order = np.lexsort((-pts[:, 2], cells))
        first = np.r_[True, cells[order][1:] != cells[order][:-1]]
        return float(np.median(pts[order][first, 2]))

    def _levelled_start(self, view, angle):
        """Where the first section's side1 view starts instead of searching: the last levelling
        view's points (the same section, turned by less than LEVEL_TOLERANCE_DEG since) turned
        to ``angle``, as (x, z). Points whose neighbours turn steeper than START_MAX_SLOPE_DEG
        are left to the rescans: near the silhouette the turn may tuck them under the surface.
        None with too few points."""
        order = np.argsort(view.stage_xyz[:, 0], kind="stable")
        pts = self._turned_surface([view], angle)
        if len(pts) < MIN_VIEW_POINTS:
            return None
        pts = pts[order]
        dx, dz = np.diff(pts[:, 0]), np.diff(pts[:, 2])
        gentle = (dx > 0) & (np.abs(dz) < np.tan(np.radians(START_MAX_SLOPE_DEG)) * dx)
        keep = np.r_[False, gentle] & np.r_[gentle, False]
        if np.count_nonzero(keep) < MIN_VIEW_POINTS:
            return None
        return pts[keep, 0], pts[keep, 2]

    def _level(self, y, base):
        """Step 1 for the first section: turn the part until the first side's chord is level
        (an edge-on blade shows only an edge, its points stand steeply)."""
        for _ in range(MAX_LEVELLING):
            view = self._scan_view("side1", y, base, final=False,
                                   predicted=self._probed_height(y, base))
            twist = self._chord_angle(view)
            if twist is None:
                base += 90.0
                continue
            if view.surface_z is not None:
                self.state.surface_z["side1"] = view.surface_z
            base += self._twist_sign * twist
            if abs(twist) < LEVEL_TOLERANCE_DEG:
                self._levelled_view = view
                break
        self.state.levelled = True
        self.state.base_angle_deg = base
        return base

    def _chord_angle(self, view):
        """Inclination (deg, -90..90, from +X towards +Z) of the principal direction of the
        view's surface points in the section plane; None without enough points."""
        if len(view.reading_mm) < MIN_VIEW_POINTS:
            return None
        x = view.stage_xyz[:, 0]
        z = view.stage_xyz[:, 2] - view.reading_mm
        c = np.cov(np.vstack([x, z]))
        w, v = np.linalg.eigh(c)
        d = v[:, np.argmax(w)]
        if d[0] < 0:
            d = -d
        return float(np.degrees(np.arctan2(d[1], d[0])))

    # -- one view: steps 1-5 -------------------------------------------------------------------

    def _scan_view(self, name, y, angle, final=True, near=None, predicted=None, start=None):
        """Steps 1-5 for one view; ``start`` (x, z): surface points of this section already
        known at this angle, followed at once instead of searching."""
        passes = []
        found = start if start is not None else self._find_surface(name, y, angle, passes,
                                                                     near, predicted)
        if found is None:
            return ViewResult(name, angle, np.zeros((0, 3)), np.zeros(0), np.zeros(0), passes)
        x_all, z_all = found
        max_incidence = 0.5 * self.sensor.coverage_deg
        open_ends = [True, True]
        extension = [self.options.extension_mm, self.options.extension_mm]
        for _ in range(self.options.max_passes):
            background.tick()    # a GUI's event loop turns between the passes
            curve, _ = fit_stage_profile(x_all, z_all, max_incidence_deg=max_incidence)  # step 3
            lo = -extension[0] if open_ends[0] else 0.0
            hi = curve.length + (extension[1] if open_ends[1] else 0.0)
            s = self._samples(lo, hi, self.options.probe_spacing)
            stage, s = self._stage_path(curve(s), y, s)
            if len(stage) < MIN_VIEW_POINTS:
                break       # the curve left the stages' travel
            readings = self.rig.scan_path(stage, angle)  # step 4
            d = np.asarray(readings.reading_mm, dtype=float)
            valid = np.isfinite(d)
            passes.append(self._pass_info("rescan", readings, d))
            # The criterion is judged on the section itself; the extensions are probes.
            body = valid & (s >= 0.0) & (s <= curve.length)
            err = np.abs(d[body] - self.sensor.standoff)
            surface = np.column_stack([stage[:, 0], stage[:, 2] - d])
            grew = [self._grows(surface[valid & (s < 0.0)], x_all, z_all, -1),
                    self._grows(surface[valid & (s > curve.length)], x_all, z_all, 1)]
            x_all = np.concatenate([x_all, surface[valid, 0]])
            z_all = np.concatenate([z_all, surface[valid, 1]])
            open_ends = [open_ends[0] and grew[0], open_ends[1] and grew[1]]
            # While an end keeps reading, reach further: the working range often hides much
            # of the section from the first linear scan.
            most = MAX_EXTENSION_FACTOR * self.options.extension_mm
            extension = [min(2.0 * e, most) if g else e for e, g in zip(extension, grew)]
            if not any(open_ends) and np.all(err <= self.options.epsilon):
                break
        curve, _ = fit_stage_profile(x_all, z_all, max_incidence_deg=max_incidence)
        surface_z = float(np.median(z_all))
        if final:
            s = self._samples(0.0, curve.length, self.options.point_spacing)  # step 5
            stage, s = self._stage_path(curve(s), y, s)
        if len(stage) < MIN_VIEW_POINTS:
            return ViewResult(name, angle, np.zeros((0, 3)), np.zeros(0), np.zeros(0), passes,
                              surface_z)
        if not final:
            # Levelling only needs the points of the last rescan, not a final pass.
            keep = np.isfinite(d) & (np.abs(d - self.sensor.standoff) <= self.options.epsilon)
            return ViewResult(name, angle, stage[keep], d[keep],
                              np.asarray(readings.snr, dtype=float)[keep], passes, surface_z)
        readings = self.rig.scan_path(stage, angle)
        d = np.asarray(readings.reading_mm, dtype=float)
        passes.append(self._pass_info("final", readings, d))
        keep = np.isfinite(d) & (np.abs(d - self.sensor.standoff) <= self.options.epsilon)
        return ViewResult(name, angle, stage[keep], d[keep],
                          np.asarray(readings.snr, dtype=float)[keep], passes, surface_z)

    def _grows(self, new_points, x_all, z_all, side):
        """Whether readings in an end's extension add surface beyond the known end: by at least
        a probe step, so that creeping towards grazing incidence near an edge stops."""
        if len(new_points) == 0:
            return False
        end = np.argmin(x_all) if side < 0 else np.argmax(x_all)
        beyond = new_points[(new_points[:, 0] - x_all[end]) * side > 0]
        if len(beyond) == 0:
            return False
        reach = np.hypot(beyond[:, 0] - x_all[end], beyond[:, 1] - z_all[end])
        return bool(reach.max() >= self.options.probe_spacing)

    def _find_surface(self, name, y, angle, passes, near=None, predicted=None):
        """Steps 1-2: linear passes along X at fixed Z until the sensor reads: first at the
        ``predicted`` surface height (from this section's other views), then at the height
        this view found on the previous section, then through the search envelope nearest
        those first (from the top down when nothing is known), skipping windows mostly covered
        by one already found empty. Returns the surface points (x, z) of that pass, or None.

        ``near`` (x, z): where an edge is expected. A thin edge turned up shows only its nose
        to the sensor (the flanks lie beyond the coverage), a fraction of a millimetre that
        coarse probes step over: it is looked for first with a fine pass around there."""
        lim = self.rig.limits
        if near is not None:
            z_stage = near[1] + self.sensor.standoff
            xs = self._samples(near[0] - EDGE_WINDOW_MM, near[0] + EDGE_WINDOW_MM,
                               min(self.options.point_spacing, EDGE_PROBE_SPACING_MM))
            xs = xs[(xs >= lim.x[0]) & (xs <= lim.x[1])]
            if lim.z[0] <= z_stage <= lim.z[1] and len(xs):
                stage = np.column_stack([xs, np.full(len(xs), y), np.full(len(xs), z_stage)])
                readings = self.rig.scan_path(stage, angle)
                d = np.asarray(readings.reading_mm, dtype=float)
                passes.append(self._pass_info("linear", readings, d))
                valid = np.isfinite(d)
                if np.count_nonzero(valid) >= MIN_EDGE_POINTS:
                    return stage[valid, 0], z_stage - d[valid]
        ax = self.kinematics.axis_point[0]
        x0 = max(ax - self.options.search_radius, lim.x[0])
        x1 = min(ax + self.options.search_radius, lim.x[1])
        xs = self._samples(x0, x1, self.options.probe_spacing)
        known = [v for v in (predicted, self.state.surface_z.get(name)) if v is not None]
        levels = self._levels()
        if known:
            # The surface lies most likely near where it was expected: a wrong guess (the
            # part turned far, off-centre) is usually one window away, not at the top.
            levels.sort(key=lambda level: abs(level - known[0]))
        gross_snr = getattr(self.sensor, "gross_snr", 0.0)
        empty = []
        for i, level in enumerate(known + levels):
            expected = i < len(known)
            z_stage = level + self.sensor.standoff
            if not lim.z[0] <= z_stage <= lim.z[1]:
                continue
            if any(abs(level - e) < SKIP_OVERLAP * self.sensor.half_range for e in empty):
                continue
            stage = np.column_stack([xs, np.full(len(xs), y), np.full(len(xs), z_stage)])
            readings = self.rig.scan_path(stage, angle)
            d = np.asarray(readings.reading_mm, dtype=float)
            passes.append(self._pass_info("linear", readings, d))
            valid = np.isfinite(d)
            if np.count_nonzero(valid) < MIN_VIEW_POINTS:
                empty.append(level)
                continue
            x, z, snr = stage[valid, 0], z_stage - d[valid], np.asarray(readings.snr)[valid]
            top = z.max()
            if not expected and top - level > -RECENTRE_TOP * self.sensor.half_range:
                # Step 1's adjustment of a surface found blind: lower the window so that the
                # highest point found sits near its top; the steeper parts below the first find
                # come into range. A window centred on the expected height needs none: the
                # rescans' extensions reach the rest (Rotor 67: 6 passes of ~100 saved).
                z_stage = top - RECENTRE_TOP * self.sensor.half_range + self.sensor.standoff
                if lim.z[0] <= z_stage <= lim.z[1]:
                    stage[:, 2] = z_stage
                    readings = self.rig.scan_path(stage, angle)
                    d = np.asarray(readings.reading_mm, dtype=float)
                    passes.append(self._pass_info("linear", readings, d))
                    more = np.isfinite(d)
                    x = np.concatenate([x, stage[more, 0]])
                    z = np.concatenate([z, z_stage - d[more]])
                    snr = np.concatenate([snr, np.asarray(readings.snr)[more]])
            # The first path starts from the well-read part of the section, away from the
            # grazing spots at high curvature that carry the gross errors.
            good = snr >= gross_snr
            if np.count_nonzero(good) >= MIN_VIEW_POINTS:
                return x[good], z[good]
            return x, z
        return None

    def _stage_path(self, xz, y, s):
        """Sensor positions above the curve points at the standoff, inside the soft limits."""
        stage = np.column_stack([xz[:, 0], np.full(len(xz), y), xz[:, 1] + self.sensor.standoff])
        lim = self.rig.limits
        inside = ((stage[:, 0] >= lim.x[0]) & (stage[:, 0] <= lim.x[1])
                  & (stage[:, 2] >= lim.z[0]) & (stage[:, 2] <= lim.z[1]))
        return stage[inside], s[inside]

    @staticmethod
    def _samples(lo, hi, spacing):
        n = max(2, int(np.ceil((hi - lo) / spacing)) + 1)
        return np.linspace(lo, hi, n)

    def _pass_info(self, kind, readings, d):
        valid = np.isfinite(d)
        err = np.abs(d[valid] - self.sensor.standoff)
        return {"kind": kind, "angle_deg": float(readings.angle_deg), "points": int(len(d)),
                "readings": int(np.count_nonzero(valid)),
                "max_standoff_error_mm": float(err.max()) if len(err) else None,
                "pass_index": readings.meta.get("pass_index")}
