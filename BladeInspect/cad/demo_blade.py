"""The built-in demo blade: a twisted, tapered, cambered compressor-like blade as a B-rep solid.

Every registration needs a part whose shape pins the pose down. A constant profile under a
linear twist is a helicoid (a screw motion maps it onto itself), so here chord, thickness,
camber and the leading/trailing-edge radii all change along the span, the twist is not linear
and the sections are swept and leaned.

Section profile (chordwise coordinate xi in [0, 1], chord c):
- camber line y_c = m * g(xi) / g(p), g = xi (1 - xi)(1 - q xi), peak m at xi = p;
- half thickness h, applied along the camber-line normal:
  h = phi((c - x) / r_te) (r_te xi + h_body), phi(t) = sqrt(2 t / (1 + 2 t)), where
  h_body = 5 t c (a0 sqrt(xi) + a1 xi + ... + a4 xi^4) is a NACA-like distribution whose a0
  sets the leading-edge radius r_le (h ~ sqrt(2 r_le x) there) and a1..a4 put the maximum
  thickness t c at xi_t and give the usual trailing-edge wedge. r_te xi opens the trailing
  edge to a half thickness r_te and phi, which is 1 a few r_te away from it, closes it with a
  round end of radius r_te (h ~ sqrt(2 r_te (c - x))). Both ends are smooth in sqrt of the
  distance to the edge, so each side continues smoothly into the other round the edges.
The suction side is the convex (+normal) side, the pressure side the other; both run from the
leading edge (xi = 0) to the trailing edge (xi = 1) and share those two points at each section.
Span along +Z from z = 0 (hub) to z = span; the stacking point is at 40 % chord.
"""
from dataclasses import dataclass, fields

import numpy as np

from ..core.errors import InputError

# NACA 4-digit trailing-edge slope of the normalised thickness, kept so the body has the
# familiar wedge angle whatever the leading-edge radius.
_NACA_TE_SLOPE = 0.2969 / 2 - 0.1260 - 2 * 0.3516 + 3 * 0.2843 - 4 * 0.1036
_STACK_FRACTION = 0.4


@dataclass(frozen=True)
class BladeParams:
    span: float = 70.0                 # mm
    chord_root: float = 50.0           # mm
    chord_tip: float = 42.0
    thickness_root: float = 0.12       # maximum thickness / chord
    thickness_tip: float = 0.06
    thickness_position: float = 0.35   # chord fraction of the maximum thickness
    camber_root: float = 0.08          # maximum camber / chord
    camber_tip: float = 0.04
    camber_position: float = 0.4       # chord fraction of the maximum camber
    stagger_root_deg: float = 0.0      # chord angle from +X at the hub
    twist_deg: float = 25.0            # chord angle at the tip minus at the hub
    twist_exponent: float = 1.5        # twist(s) = twist * s**exponent, s = z / span
    sweep: float = 3.0                 # mm, +X shift of the tip stacking point (quadratic in s)
    lean: float = 2.0                  # mm, +Y shift of the tip stacking point (quadratic in s)
    le_radius_root: float = 0.8        # mm
    le_radius_tip: float = 0.17
    te_radius_root: float = 0.35       # mm
    te_radius_tip: float = 0.15
    n_sections: int = 9
    n_profile: int = 61                # points per side and section

    def validate(self):
        def need(ok, name, what):
            if not ok:
                raise InputError("BladeParams.%s = %r: %s" % (name, getattr(self, name), what))
        for f in fields(self):
            value = getattr(self, f.name)
            need(isinstance(value, (int, float, np.integer, np.floating))
                 and not isinstance(value, bool) and np.isfinite(value), f.name,
                 "must be a finite number")
        for name in ("span", "chord_root", "chord_tip", "thickness_root", "thickness_tip",
                     "le_radius_root", "le_radius_tip", "te_radius_root", "te_radius_tip"):
            value = getattr(self, name)
            need(value > 0, name, "must be positive")
        for name in ("camber_root", "camber_tip"):
            need(0 <= getattr(self, name) < 0.2, name, "must be in [0, 0.2)")
        for name in ("thickness_root", "thickness_tip"):
            need(getattr(self, name) < 0.4, name, "must be below 0.4 of the chord")
        need(0.2 <= self.thickness_position <= 0.5, "thickness_position", "must be in [0.2, 0.5]")
        need(0.35 <= self.camber_position <= 0.65, "camber_position", "must be in [0.35, 0.65]")
        need(abs(self.twist_deg) < 90, "twist_deg", "must be within +-90")
        need(0.5 <= self.twist_exponent <= 4, "twist_exponent", "must be in [0.5, 4]")
        need(int(self.n_sections) == self.n_sections and self.n_sections >= 4, "n_sections",
             "must be an integer >= 4")
        need(int(self.n_profile) == self.n_profile and self.n_profile >= 9, "n_profile",
             "must be an integer >= 9")
        for end in ("root", "tip"):
            c = getattr(self, "chord_" + end)
            t = getattr(self, "thickness_" + end)
            for kind in ("le", "te"):
                r = getattr(self, "%s_radius_%s" % (kind, end))
                need(r < 0.25 * t * c, "%s_radius_%s" % (kind, end),
                     "must be below half the half thickness (%.3g mm)" % (t * c / 4))


@dataclass
class BladeModel:
    shape: object          # Part.Solid
    roles: dict            # role -> list of indices into shape.Faces
    params: object         # BladeParams (demo) or a dict describing the source


def _lerp(s, a, b):
    return a + (b - a) * s


def section_properties(params, s):
    """Chord, thickness, camber, radii, chord angle (rad) and stacking point at span fraction s."""
    p = params
    angle = np.radians(p.stagger_root_deg + p.twist_deg * s ** p.twist_exponent)
    return {
        "chord": _lerp(s, p.chord_root, p.chord_tip),
        "thickness": _lerp(s, p.thickness_root, p.thickness_tip),
        "camber": _lerp(s, p.camber_root, p.camber_tip),
        # Interpolating r_le / (t^2 c) rather than r_le keeps the thickness distribution
        # NACA-like (no waviness) between hub and tip.
        "le_radius": _lerp(s, p.le_radius_root / (p.thickness_root ** 2 * p.chord_root),
                           p.le_radius_tip / (p.thickness_tip ** 2 * p.chord_tip))
        * _lerp(s, p.thickness_root, p.thickness_tip) ** 2 * _lerp(s, p.chord_root, p.chord_tip),
        "te_radius": _lerp(s, p.te_radius_root, p.te_radius_tip),
        "angle": angle,
        "stack": np.array([p.sweep * s * s, p.lean * s * s, p.span * s]),
    }


def _thickness_coefficients(t, c, r_le, r_te, xi_t):
    """a0..a4 of the normalised NACA-like half thickness y = h_body / (5 t c)."""
    a0 = np.sqrt(2.0 * r_le / c) / (5.0 * t)
    scale = 5.0 * t * c
    # (r_te xi + h_body) has its maximum t c / 2 at xi_t, h_body closes at the trailing edge
    # with NACA's slope: four conditions, linear in a1..a4.
    rows = np.array([
        [xi_t, xi_t ** 2, xi_t ** 3, xi_t ** 4],
        [1.0, 2 * xi_t, 3 * xi_t ** 2, 4 * xi_t ** 3],
        [1.0, 1.0, 1.0, 1.0],
        [1.0, 2.0, 3.0, 4.0],
    ])
    rhs = np.array([(t * c / 2 - r_te * xi_t) / scale - a0 * np.sqrt(xi_t),
                    -r_te / scale - a0 / (2 * np.sqrt(xi_t)),
                    -a0,
                    _NACA_TE_SLOPE - a0 / 2])
    return np.concatenate([[a0], np.linalg.solve(rows, rhs)])


def half_thickness(xi, chord, thickness, le_radius, te_radius, thickness_position):
    """Half thickness h(xi) of the profile (see the module docstring)."""
    a = _thickness_coefficients(thickness, chord, le_radius, te_radius, thickness_position)
    body = 5 * thickness * chord * (a[0] * np.sqrt(xi) + a[1] * xi + a[2] * xi ** 2
                                   + a[3] * xi ** 3 + a[4] * xi ** 4)
    t_te = chord * (1.0 - xi) / te_radius
    return np.sqrt(2 * t_te / (1 + 2 * t_te)) * (te_radius * xi + body)


def profile_2d(chord, thickness, camber, camber_position, le_radius, te_radius,
               thickness_position, n):
    """(upper (n,2), lower (n,2), u (n,)) in the chord frame, LE at (0,0), TE at (chord,0).

    Points are spaced by xi = (1 - cos(pi u)) / 2 with u uniform, which is linear in sqrt(xi)
    at both edges so the rounded edges are sampled evenly along their arcs."""
    u = np.linspace(0.0, 1.0, n)
    xi = 0.5 * (1.0 - np.cos(np.pi * u))
    fine = np.linspace(0.0, 1.0, 4001)
    h_fine = half_thickness(fine, chord, thickness, le_radius, te_radius, thickness_position)
    curvature = np.diff(h_fine, 2)
    if np.any(h_fine[1:-1] <= 0) or np.any(curvature[1:-1] > 0):
        raise InputError("BladeParams: edge radii %.3g / %.3g mm do not fit a %.3g thick "
                         "%.3g mm chord" % (le_radius, te_radius, thickness, chord))
    half = half_thickness(xi, chord, thickness, le_radius, te_radius, thickness_position)

    p = camber_position
    q = (1 - 2 * p) / (p * (2 - 3 * p))
    g_max = p * (1 - p) * (1 - q * p)
    yc = camber * xi * (1 - xi) * (1 - q * xi) / g_max
    dyc = camber * ((1 - 2 * xi) * (1 - q * xi) - q * xi * (1 - xi)) / g_max
    normal = np.column_stack([-dyc, np.ones_like(xi)]) / np.sqrt(1 + dyc ** 2)[:, None]
    camber_pts = np.column_stack([chord * xi, chord * yc])
    upper = camber_pts + half[:, None] * normal
    lower = camber_pts - half[:, None] * normal
    return upper, lower, u


def section_points(params, s):
    """(suction (n,3), pressure (n,3), u (n,)) of the section at span fraction s."""
    props = section_properties(params, s)
    upper, lower, u = profile_2d(props["chord"], props["thickness"], props["camber"],
                                 params.camber_position, props["le_radius"],
                                 props["te_radius"], params.thickness_position,
                                 params.n_profile)
    ca, sa = np.cos(props["angle"]), np.sin(props["angle"])
    rot = np.array([[ca, -sa], [sa, ca]])
    shift = np.array([_STACK_FRACTION * props["chord"], 0.0])

    def place(pts2):
        xy = (pts2 - shift) @ rot.T + props["stack"][:2]
        return np.column_stack([xy, np.full(len(xy), props["stack"][2])])
    return place(upper), place(lower), u


_CACHE = {}


# The root block of make_demo_blade(root_block=True), mm: a box below the hub with a gap (the
# platform and fillets between are not modelled), its faces the datum faces of a fixture.
ROOT_BLOCK_MIN = (-30.0, -15.0, -25.0)
ROOT_BLOCK_SIZE = (70.0, 35.0, 20.0)


def make_demo_blade(params=None, root_block=False):
    """The demo blade as a ``BladeModel``: a valid closed solid with roles suction, pressure,
    hub (plane z = 0) and tip (plane z = span). ``root_block``: a compound of the blade and a
    root block below it (ROOT_BLOCK_*), with the roles root_block (its six faces) and
    datum_primary (its bottom, z = min), datum_secondary (its side y = min) and
    datum_tertiary (its end x = min)."""
    if root_block:
        return _with_root_block(make_demo_blade(params))
    params = BladeParams() if params is None else params
    if not isinstance(params, BladeParams):
        raise InputError("make_demo_blade: params must be a BladeParams, got %s"
                         % type(params).__name__)
    params.validate()
    if params not in _CACHE:
        _CACHE[params] = _build(params)
    shape, roles = _CACHE[params]
    return BladeModel(shape=shape.copy(), roles={k: list(v) for k, v in roles.items()},
                      params=params)


def _with_root_block(model):
    import Part
    from FreeCAD import Vector
    box = Part.makeBox(*ROOT_BLOCK_SIZE, Vector(*ROOT_BLOCK_MIN))
    shape = Part.makeCompound([model.shape, box])
    first = len(model.shape.Faces)
    lo = np.array(ROOT_BLOCK_MIN)

    def face_at(axis):
        for k, face in enumerate(box.Faces):
            bb = face.BoundBox
            extent = (bb.XLength, bb.YLength, bb.ZLength)[axis]
            low = (bb.XMin, bb.YMin, bb.ZMin)[axis]
            if extent < 1e-9 and abs(low - lo[axis]) < 1e-9:
                return first + k
        raise AssertionError("root block: no face at the low end of axis %d" % axis)
    roles = dict(model.roles, root_block=list(range(first, first + len(box.Faces))),
                 datum_primary=[face_at(2)], datum_secondary=[face_at(1)],
                 datum_tertiary=[face_at(0)])
    return BladeModel(shape=shape, roles=roles, params=model.params)


def _build(params):
    import Part
    from .surface_build import interpolate_grid, close_sides

    fractions = np.linspace(0.0, 1.0, int(params.n_sections))
    suction, pressure = [], []
    for s in fractions:
        up, lo, u = section_points(params, s)
        suction.append(up)
        pressure.append(lo)
    v = fractions * params.span
    faces = [Part.Face(interpolate_grid(np.array(side), u, v))
             for side in (suction, pressure)]
    surfaces = [f.Surface for f in faces]
    hub = [Part.Edge(srf.vIso(v[0])) for srf in surfaces]
    tip = [Part.Edge(srf.vIso(v[-1])) for srf in surfaces]
    solid, (i_s, i_p, i_h, i_t) = close_sides(faces[0], faces[1], hub, tip, planar_caps=True)
    return solid, {"suction": [i_s], "pressure": [i_p], "hub": [i_h], "tip": [i_t]}

