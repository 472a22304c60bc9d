"""One section's characteristics: the Characteristics record and characteristics(), which
puts the kernel's parts together."""

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import InputError
from .camber import CamberLine, DEFAULT_METAL_ANGLE_WINDOW_PCT, closed_end, line_end
from .chords import CHORD_METHODS, extent, farthest_pair, pressure_bitangent
from .edges import (CircleFit2D, DEFAULT_EDGE_ZONE_DEG, LE_RADIUS_SIGMAS, corner_edges,
                    corner_warnings, edge_circle, edge_point, leading_end,
                    withhold_sparse_edges)
from .geometry import angle_deg, norms, unit
from .medial import refine_centres, side_range
from .nose import edge_split
from .profile import Profile, area_centroid, ray_hit
from .thickness import (MAX_POS_WINDOW, max_thickness_position, stations_to_arc,
                        thickness_normal)

DEFAULT_EDGE_OFFSETS_MM = (0.5, 1.0, 2.0)


@dataclass
class Characteristics:
    """One section's characteristics (field names as result.json's ``airfoil`` block)."""
    chord_mm: float
    chord_method: str
    nose_tail_chord_mm: float
    caliper_chord_mm: float
    tangent_chord_mm: Optional[float]
    axial_chord_mm: float
    stagger_deg: float
    max_thickness_mm: float
    max_thickness_pos_pct: float
    max_thickness_center: np.ndarray
    thickness_stations_pct: list
    thickness_mm: list
    le_radius_mm: float
    te_radius_mm: float
    le_circle: CircleFit2D
    te_circle: CircleFit2D
    edge_offsets_mm: list
    le_thickness_mm: list
    te_thickness_mm: list
    inlet_angle_deg: float
    outlet_angle_deg: float
    area_mm2: float
    centroid_mm: np.ndarray
    le_point: np.ndarray
    te_point: np.ndarray
    chord_dir: np.ndarray
    engine_axis: np.ndarray
    le_rule: str
    mcl: CamberLine
    inscribed_centres: np.ndarray
    inscribed_radii: np.ndarray
    profile: Profile = field(repr=False)
    suction_range: tuple = ()     # unwrapped parameter ranges of the two sides
    pressure_range: tuple = ()
    warnings: list = field(default_factory=list)

    def edge_circles(self):
        """[("LE" or "TE", CircleFit2D)] of the edges whose radius is reported: an edge
        withheld by withhold_corner_edges (radius None) keeps its fit on the record, but a
        circle drawn for it would show a radius the result says is not measurable."""
        return [(name, circle) for name, circle, radius in
                (("LE", self.le_circle, self.le_radius_mm),
                 ("TE", self.te_circle, self.te_radius_mm)) if radius is not None]

    def as_dict(self):
        return {
            "chord_mm": self.chord_mm, "chord_method": self.chord_method,
            "nose_tail_chord_mm": self.nose_tail_chord_mm,
            "caliper_chord_mm": self.caliper_chord_mm,
            "tangent_chord_mm": self.tangent_chord_mm,
            "axial_chord_mm": self.axial_chord_mm, "stagger_deg": self.stagger_deg,
            "max_thickness_mm": self.max_thickness_mm,
            "max_thickness_pos_pct": self.max_thickness_pos_pct,
            "thickness_stations_pct": list(self.thickness_stations_pct),
            "thickness_mm": list(self.thickness_mm),
            "le_radius_mm": self.le_radius_mm, "te_radius_mm": self.te_radius_mm,
            "edge_zone_deg": self.le_circle.zone_deg,
            "edge_offsets_mm": list(self.edge_offsets_mm),
            "le_thickness_mm": list(self.le_thickness_mm),
            "te_thickness_mm": list(self.te_thickness_mm),
            "inlet_angle_deg": self.inlet_angle_deg, "outlet_angle_deg": self.outlet_angle_deg,
            "area_mm2": self.area_mm2, "centroid_mm": self.centroid_mm.tolist(),
            "le_point_mm": self.le_point.tolist(), "te_point_mm": self.te_point.tolist(),
            "le_rule": self.le_rule, "warnings": list(self.warnings),
        }


def characteristics(profile, engine_axis=(1.0, 0.0), chord_method="nose-tail",
                    stations_pct=(), edge_offsets_mm=DEFAULT_EDGE_OFFSETS_MM,
                    edge_zone_deg=DEFAULT_EDGE_ZONE_DEG, le_hint=None, noise_mm=0.0,
                    le_upstream=None, metal_angle_window_pct=DEFAULT_METAL_ANGLE_WINDOW_PCT,
                    definition=None):
    """All characteristics of one section. ``profile``: a Profile or an ordered (N, 2) array;
    ``engine_axis``: a 2D direction in the section plane, pointing downstream; ``le_hint``: a
    point near the leading edge (e.g. on the CAD's named LE face); ``le_upstream``: a 2D
    direction pointing upstream (the LE is the end furthest along it); with neither, the LE is
    the blunter end, or the end upstream along the engine axis when the two edge radii agree
    within their uncertainty (``le_rule`` says which rule decided, docs/user-guide.md).
    ``definition``: an AirfoilDefinition whose fields take the place of chord_method,
    stations_pct, edge_offsets_mm, edge_zone_deg and metal_angle_window_pct (given with it,
    those must keep their defaults), and set the LE rule used when neither le_hint nor
    le_upstream is given and the radii's sigmas of the blunter-end rule."""
    le_radius_sigmas = LE_RADIUS_SIGMAS
    if definition is not None:
        _check_no_parameter_beside(chord_method, stations_pct, edge_offsets_mm, edge_zone_deg,
                                   metal_angle_window_pct)
        chord_method, stations_pct = definition.chord_method, definition.stations_pct
        edge_offsets_mm, edge_zone_deg = definition.edge_offsets_mm, definition.edge_zone_deg
        metal_angle_window_pct = definition.metal_angle_window_pct
        le_radius_sigmas = definition.le_radius_sigmas
    if not isinstance(profile, Profile):
        profile = Profile(profile, noise_mm)
    if chord_method not in CHORD_METHODS:
        raise InputError("chord method: %r is not one of %s" % (chord_method,
                                                                 ", ".join(CHORD_METHODS)))
    axis = np.asarray(engine_axis, dtype=float).reshape(2)
    if not np.all(np.isfinite(axis)) or np.linalg.norm(axis) < 1e-12:
        raise InputError("engine axis: %s must be a finite non-zero 2D direction" % axis)
    axis = unit(axis)
    if definition is not None and definition.le_rule == "engine-axis" \
            and le_hint is None and le_upstream is None:
        le_upstream = -axis
    L = profile.length
    if not (np.isfinite(metal_angle_window_pct) and 0 < metal_angle_window_pct <= 100):
        raise InputError("metal angle window: %r %% of the camber line must be in (0, 100]"
                         % (metal_angle_window_pct,))

    # The caliper chord is the caliper diameter; the sides are split at the edges (nose.py),
    # not at its ends, which sit on a shoulder of a strongly turned profile.
    _, _, cal_p1, cal_p2 = farthest_pair(profile)
    caliper = float(np.linalg.norm(cal_p2 - cal_p1))
    split = edge_split(profile, metal_angle_window_pct)
    side_a, side_b = split.side_a, split.side_b
    centres, radii = split.centres, split.radii

    # Camber line end tangents, extended to the profile: the two edge points.
    # First the edge circles about the locus's ends, then the ends closed onto circular edges.
    out_a = line_end(centres, radii, 0, window_pct=metal_angle_window_pct)[2]
    out_b = line_end(centres, radii, -1, window_pct=metal_angle_window_pct)[2]
    circle_a = edge_circle(profile, centres[0], out_a,
                            ray_hit(profile, centres[0], out_a, behind=True)[0][0],
                            edge_zone_deg)
    circle_b = edge_circle(profile, centres[-1], out_b,
                            ray_hit(profile, centres[-1], out_b, behind=True)[0][0],
                            edge_zone_deg)
    notes = []
    centres, radii, out_a, ua_end, end_a = closed_end(profile, centres, radii, 0, circle_a,
                                                       notes, metal_angle_window_pct)
    centres, radii, out_b, ub_end, end_b = closed_end(profile, centres, radii, -1, circle_b,
                                                       notes, metal_angle_window_pct)
    circle_a = edge_circle(profile, circle_a.center, out_a, ua_end[0], edge_zone_deg)
    circle_b = edge_circle(profile, circle_b.center, out_b, ub_end[0], edge_zone_deg)
    # The edge points: from each edge circle's centre along the camber line's end direction.
    ua_end, end_a = edge_point(profile, circle_a, out_a, noise_mm, ua_end, end_a)
    ub_end, end_b = edge_point(profile, circle_b, out_b, noise_mm, ub_end, end_b)
    t0, t1 = -out_a, out_b
    a_is_le, le_rule = leading_end(end_a[0], end_b[0], circle_a, circle_b, axis, le_hint,
                                   le_upstream, noise_mm, le_radius_sigmas)
    if a_is_le:
        le, te, le_u, te_u = end_a[0], end_b[0], ua_end[0], ub_end[0]
        le_circle, te_circle = circle_a, circle_b
    else:
        centres, radii = centres[::-1], radii[::-1]
        le, te, le_u, te_u = end_b[0], end_a[0], ub_end[0], ua_end[0]
        le_circle, te_circle = circle_b, circle_a
    mcl = CamberLine(le, centres, te, t0 if a_is_le else -t1, t1 if a_is_le else -t0)

    nose_tail = float(np.linalg.norm(te - le))
    chord_dir = (te - le) / nose_tail
    # The two sides between the edge points; the suction side is the longer one (convex).
    # (their parameter ranges only: no samples or tree of them is wanted)
    s1, s2 = side_range(profile, le_u % L, te_u % L), side_range(profile, te_u % L,
                                                                   le_u % L + L)
    suction, pressure = (s1, s2) if (s1.hi - s1.lo) >= (s2.hi - s2.lo) else (s2, s1)

    bitangent = pressure_bitangent(profile, pressure, le_u, te_u)
    tangent_chord = None if bitangent is None else extent(profile, bitangent[1] - bitangent[0])
    chord = {"nose-tail": nose_tail, "caliper": caliper, "tangent": tangent_chord}[chord_method]
    if chord is None:
        raise InputError("chord method tangent: the pressure side is not concave, no line "
                         "touches the profile at both edges across it")
    # The stagger is the angle of the chord asked for, pointing from the LE towards the TE: a
    # chord's length and its angle describe one line.
    line = {"nose-tail": chord_dir, "caliper": cal_p2 - cal_p1,
            "tangent": None if bitangent is None else bitangent[1] - bitangent[0]}[chord_method]
    stagger_dir = unit(line) * (1.0 if np.dot(line, chord_dir) >= 0 else -1.0)

    # Largest inscribed circle: the radius along the camber line is flat at its maximum, so
    # it is zoomed in on twice by exact circles at 9 arc lengths and a parabola through them.
    k = int(np.clip(np.argmax(radii), 1, len(radii) - 2))
    s_c = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(centres, axis=0), axis=1))])
    lo_s, hi_s = s_c[k - 1], s_c[k + 1]
    for _ in range(2):
        s_try = np.linspace(lo_s, hi_s, 9)
        seeds, _ = mcl.at(mcl.le_extension + s_try)
        cs, _, _, fs, _ = refine_centres(profile, side_a, side_b, seeds)
        r_try = norms(fs - cs)
        a2, a1, _ = np.polyfit(s_try - s_try[4], r_try, 2)
        s_max = s_try[4] + (-a1 / (2 * a2) if a2 < 0 else 0.0)
        s_max = float(np.clip(s_max, lo_s, hi_s))
        half = (hi_s - lo_s) / 8.0
        lo_s, hi_s = s_max - half, s_max + half
    seed, _ = mcl.at(mcl.le_extension + s_max)
    c_max, _, _, fa, _ = refine_centres(profile, side_a, side_b, seed)
    max_thickness = 2.0 * float(np.linalg.norm(fa[0] - c_max[0]))
    # Its position: the vertex of the radius's local quartic (continuous in the points).
    x_pos, c_pos = max_thickness_position(profile, side_a, side_b, mcl,
                                           mcl.le_extension + s_max, c_max[0],
                                           MAX_POS_WINDOW * nose_tail, le, chord_dir)
    max_pos = 100.0 * x_pos / nose_tail

    stations = [float(p) for p in stations_pct]
    offsets = [float(d) for d in edge_offsets_mm]
    # the stations' and both edges' thicknesses in one call (each its own crossings)
    s_all = np.concatenate([stations_to_arc(mcl, le, chord_dir, nose_tail, stations),
                            np.array(offsets), mcl.length - np.array(offsets)])
    thk = thickness_normal(profile, mcl, s_all).tolist()
    n_st, n_off = len(stations), len(offsets)
    thickness = thk[:n_st]
    le_thk, te_thk = thk[n_st:n_st + n_off], thk[n_st + n_off:]

    area, centroid = area_centroid(profile)
    circles = (le_circle, te_circle)
    warnings = corner_warnings(profile, le, te, nose_tail, circles) + notes
    le_radius, te_radius = le_circle.radius, te_circle.radius
    for name in corner_edges(profile, le, te, nose_tail, circles):
        # A corner's radius is zero: the circle fitted about the camber line's end (kept, for
        # a scan plan's edge spacing) is the window's, not the part's.
        warnings.append("%s is a corner, not a rounded edge: its radius is not reported (the "
                        "circle fitted there, %.4f mm, is not the part's)"
                        % (name, (le_circle if name == "LE" else te_circle).radius))
        if name == "LE":
            le_radius = None
        else:
            te_radius = None
    # an edge whose zone holds too few measured points: its values withheld (edges.py)
    return withhold_sparse_edges(Characteristics(
        chord_mm=float(chord), chord_method=chord_method, nose_tail_chord_mm=nose_tail,
        caliper_chord_mm=caliper, tangent_chord_mm=tangent_chord,
        axial_chord_mm=extent(profile, axis), stagger_deg=angle_deg(stagger_dir, axis),
        max_thickness_mm=max_thickness, max_thickness_pos_pct=max_pos,
        max_thickness_center=c_pos, thickness_stations_pct=stations, thickness_mm=thickness,
        le_radius_mm=le_radius, te_radius_mm=te_radius, le_circle=le_circle,
        te_circle=te_circle, edge_offsets_mm=offsets, le_thickness_mm=le_thk,
        te_thickness_mm=te_thk, inlet_angle_deg=angle_deg(mcl.le_tangent, axis),
        outlet_angle_deg=angle_deg(mcl.te_tangent, axis), area_mm2=area,
        centroid_mm=centroid, le_point=le, te_point=te, chord_dir=chord_dir, engine_axis=axis,
        le_rule=le_rule, mcl=mcl, inscribed_centres=centres, inscribed_radii=radii,
        profile=profile, suction_range=(suction.lo, suction.hi),
        pressure_range=(pressure.lo, pressure.hi), warnings=warnings), noise_mm)


def _check_no_parameter_beside(chord_method, stations_pct, edge_offsets_mm, edge_zone_deg,
                               metal_angle_window_pct):
    """InputError when a definition parameter is given beside the definition (one of the two
    would be silently ignored)."""
    given = [name for name, value, default in (
        ("chord_method", chord_method, "nose-tail"),
        ("stations_pct", tuple(stations_pct), ()),
        ("edge_offsets_mm", tuple(edge_offsets_mm), DEFAULT_EDGE_OFFSETS_MM),
        ("edge_zone_deg", edge_zone_deg, DEFAULT_EDGE_ZONE_DEG),
        ("metal_angle_window_pct", metal_angle_window_pct, DEFAULT_METAL_ANGLE_WINDOW_PCT))
        if value != default]
    if given:
        raise InputError("airfoil characteristics: %s given beside a definition; give them "
                         "in the definition" % ", ".join(given))
