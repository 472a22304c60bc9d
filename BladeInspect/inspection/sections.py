"""Profile sections' errors (paper 4.2, Table 2, Figs 9-10): the registered points of each
profile section against the CAD's section curve in the same plane, optionally beside a CMM's
points of the same sections (docs/maintainers.md "Words").

Where the profile sections are:
- with a ``section`` column, each section line's own points (CAD frame) define its plane
  (least squares) and all of that line's points belong to it;
- otherwise planes across the CAD's span at ``heights_pct`` of its length, each taking the
  points within +-``band`` mm of the plane.

Leading and trailing edge: the two ends of the nominal profile along its chord, the chord being
the profile's longest diameter (for an airfoil, the line from nose to tail). A point lies at an
edge when its chordwise position is within ``edge_fraction`` (3 %) of the chord from that end.
The leading edge is the end whose faces the CAD calls ``leading_edge`` when it names faces, or
else the blunter end (the profile is thicker just behind it): airfoils have a round nose and a
thin tail. Between the edges a point is on the suction or pressure side, the two halves of the
profile between its ends; the suction side is the one on the ``suction`` faces when named, or
else the longer (convex) half.
"""

import csv
import os
from dataclasses import dataclass, field
from typing import Optional

import numpy as np
from scipy.spatial import cKDTree

from ..core.contracts import SECTION_HEIGHTS_PCT, section_heights
from ..core.errors import InputError
from ..core.fitting import fit_plane, orthonormal_pair
from ..measurement.planning import span_frame

EDGE_FRACTION = 0.03
# Profile thickness is compared this far behind each end to tell the round nose from the tail.
_THICKNESS_PROBE = 0.05
# Profile halves are resampled at about this spacing (mm) for nearest-side look-ups.
_SIDE_SPACING = 0.05

ZONES = ("LE", "TE", "suction", "pressure")

CMM_COMPENSATION_NOTE = (
    "A CMM touches the part with a ball and reports its centre moved back by the probe radius "
    "along an estimated surface normal; at the leading and trailing edges the curvature is "
    "high and that normal, and the triggering, are least reliable, so a CMM's largest errors "
    "usually lie there (paper 4.2). The optical sensor needs no radius compensation.")


# ---------------------------------------------------------------- data

@dataclass
class Profile:
    """A section's nominal profile in its plane and the chord frame that names places on it."""
    polylines: list                # list of (K, 3) CAD-frame polylines of the cut
    le: np.ndarray                 # (3,) leading-edge end of the chord
    te: np.ndarray                 # (3,) trailing-edge end
    chord_dir: np.ndarray          # (3,) unit, LE -> TE
    cross_dir: np.ndarray          # (3,) unit, plane normal x chord_dir
    chord: float                   # mm
    le_rule: str                   # how the leading edge was told from the trailing edge
    side_tree: Optional[cKDTree] = None    # resampled profile halves, 2D chord coordinates
    side_label: Optional[np.ndarray] = None  # 'suction' / 'pressure' per tree point
    faces: Optional[list] = None   # (K,) face index per polyline point (the exact cut's)


@dataclass
class Section:
    label: str
    source: str                    # "section column" or "span height"
    origin: np.ndarray             # (3,) a point of the plane, CAD frame
    normal: np.ndarray             # (3,) unit plane normal, pointing hub -> tip
    height_pct: float              # position of the plane along the span, % hub -> tip
    point_index: np.ndarray        # indices of this section's points in the result
    zone: np.ndarray               # (n,) 'LE', 'TE', 'suction', 'pressure' per point
    profile: Optional[Profile]
    optical: dict
    cmm: Optional[dict] = None
    cmm_xyz: Optional[np.ndarray] = None
    cmm_deviation: Optional[np.ndarray] = None
    cmm_zone: Optional[np.ndarray] = None
    cmm_closest: Optional[np.ndarray] = None
    cmm_normal: Optional[np.ndarray] = None

    def plane_coords(self, xyz):
        """(n, 2) chord coordinates in mm: along the chord from the leading edge, and across."""
        xyz = np.atleast_2d(np.asarray(xyz, dtype=float))
        if self.profile is None:
            e1, e2 = orthonormal_pair(self.normal)
            d = xyz - self.origin
            return np.column_stack([d @ e1, d @ e2])
        d = xyz - self.profile.le
        return np.column_stack([d @ self.profile.chord_dir, d @ self.profile.cross_dir])

    def vectors_in_plane(self, vec):
        """(n, 2) directions (e.g. normals) in the same chord coordinates."""
        vec = np.atleast_2d(np.asarray(vec, dtype=float))
        if self.profile is None:
            e1, e2 = orthonormal_pair(self.normal)
        else:
            e1, e2 = self.profile.chord_dir, self.profile.cross_dir
        return np.column_stack([vec @ e1, vec @ e2])

    def to_json(self):
        p = self.profile
        return {
            "label": self.label,
            "source": self.source,
            "height_pct": self.height_pct,
            "origin": self.origin.tolist(),
            "normal": self.normal.tolist(),
            "chord_mm": None if p is None else p.chord,
            "leading_edge_point": None if p is None else p.le.tolist(),
            "trailing_edge_point": None if p is None else p.te.tolist(),
            "leading_edge_rule": None if p is None else p.le_rule,
            "optical": self.optical,
            "cmm": self.cmm,
        }


@dataclass
class SectionTable:
    sections: list
    span_axis: np.ndarray          # (3,) unit, hub -> tip
    span_range: tuple              # (lo, hi) of the CAD along span_axis, mm
    band: float
    within: float
    edge_fraction: float
    cmm_source: Optional[str] = None
    warnings: list = field(default_factory=list)

    def to_json(self):
        return {
            "within_mm": self.within,
            "band_mm": self.band,
            "edge_fraction": self.edge_fraction,
            "span_axis": self.span_axis.tolist(),
            "span_range_mm": list(self.span_range),
            "cmm_file": self.cmm_source,
            "cmm_note": CMM_COMPENSATION_NOTE if self.cmm_source else None,
            "warnings": list(self.warnings),
            "sections": [s.to_json() for s in self.sections],
        }

    def span_pct(self, xyz):
        lo, hi = self.span_range
        return 100.0 * (np.atleast_2d(xyz) @ self.span_axis - lo) / (hi - lo)


@dataclass
class CmmData:
    xyz: np.ndarray                # (N, 3) CAD frame, probe-compensated
    section: list                  # (N,) section label (str) or None per row
    source: str


# ---------------------------------------------------------------- statistics

def deviation_figures(dev, within):
    """Table 2's figures for one set of signed deviations (mm): count, max |dev|, RMS (about
    zero, as the paper's), mean, min, max, and the % with |dev| <= within."""
    dev = np.asarray(dev, dtype=float)
    dev = dev[np.isfinite(dev)]
    if len(dev) == 0:
        return {"n": 0, "max_abs_mm": None, "rms_mm": None, "mean_mm": None,
                "min_mm": None, "max_mm": None, "pct_within": None}
    return {
        "n": int(len(dev)),
        "max_abs_mm": float(np.max(np.abs(dev))),
        "rms_mm": float(np.sqrt(np.mean(dev ** 2))),
        "mean_mm": float(np.mean(dev)),
        "min_mm": float(np.min(dev)),
        "max_mm": float(np.max(dev)),
        "pct_within": 100.0 * np.count_nonzero(np.abs(dev) <= within) / len(dev),
    }


def _zone_figures(dev, zone, within):
    out = deviation_figures(dev, within)
    for key, name in (("le", "LE"), ("te", "TE"), ("suction", "suction"),
                      ("pressure", "pressure")):
        f = deviation_figures(dev[zone == name], within)
        out[key] = {k: f[k] for k in ("n", "max_abs_mm", "rms_mm")}
    return out


# ---------------------------------------------------------------- geometry helpers

def _role_faces(nominal, role):
    roles = getattr(nominal, "roles", None) or {}
    return set(int(i) for i in roles.get(role, ()))


def span_axis_of(nominal, span_axis=None):
    """(axis (3,) unit hub -> tip, (lo, hi) extent along it) of the CAD: core.span's rule."""
    frame = span_frame(nominal, span_axis)
    return frame.axis, (frame.lo, frame.hi)


def _farthest_pair(xy):
    """The profile's two mutually farthest points, by alternating farthest-point searches from
    the point farthest from the centroid: for an elongated, airfoil-like outline this settles
    on the diameter in two or three linear passes (an exact all-pairs search over a dense
    convex outline's hull is quadratic and takes seconds)."""
    a = xy[np.argmax(np.sum((xy - xy.mean(axis=0)) ** 2, axis=1))]
    best = -1.0
    for _ in range(8):
        d2 = np.sum((xy - a) ** 2, axis=1)
        b = xy[np.argmax(d2)]
        if d2.max() <= best:
            break
        best = d2.max()
        a, b = b, a
    return a, b


def _width_at(polylines_2d, t0):
    """Extent across the chord of the profile at chordwise position t0 (mm from the first end):
    where the profile's segments cross the line t = t0."""
    crossings = []
    for poly in polylines_2d:
        a, b = poly[:-1], poly[1:]
        da, db = a[:, 0] - t0, b[:, 0] - t0
        hit = (da * db <= 0) & (da != db)
        f = da[hit] / (da[hit] - db[hit])
        crossings.append(a[hit, 1] + f * (b[hit, 1] - a[hit, 1]))
    c = np.concatenate(crossings) if crossings else np.zeros(0)
    return float(c.max() - c.min()) if len(c) >= 2 else 0.0


def _resample(poly, spacing):
    seg = np.linalg.norm(np.diff(poly, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return poly[:1]
    n = max(2, int(np.ceil(s[-1] / spacing)) + 1)
    t = np.linspace(0.0, s[-1], n)
    return np.column_stack([np.interp(t, s, poly[:, k]) for k in range(poly.shape[1])])


def _halves(poly2d, i_le, i_te):
    """The two halves of a profile polyline between vertices i_le and i_te, each as a list of
    pieces (an open polyline's second half is its two outer ends)."""
    closed = len(poly2d) > 2 and np.allclose(poly2d[0], poly2d[-1])
    ring = poly2d[:-1] if closed else poly2d
    a, b = sorted((i_le % len(ring), i_te % len(ring)))
    first = [ring[a:b + 1]]
    if closed:
        second = [np.concatenate([ring[b:], ring[:a + 1]])]
    else:
        second = [piece for piece in (ring[:a + 1], ring[b:]) if len(piece) >= 2]
    return first, second


def build_profile(nominal, polylines, normal, fallback_xyz, origin):
    """Chord, leading edge and sides of a section from the CAD's cut (or, when the plane
    misses the CAD, from the section's own points: chord only)."""
    verts = [np.asarray(p, dtype=float) for p in polylines if len(p) >= 2]
    cloud = np.concatenate(verts) if verts else np.asarray(fallback_xyz, dtype=float)
    if len(cloud) < 2:
        return None
    e1, e2 = orthonormal_pair(normal)
    rel = cloud - origin
    xy = np.column_stack([rel @ e1, rel @ e2])
    a2, b2 = _farthest_pair(xy)
    chord = float(np.linalg.norm(b2 - a2))
    if chord <= 0:
        return None

    def lift(p2):
        return origin + p2[0] * e1 + p2[1] * e2
    a, b = lift(a2), lift(b2)

    def chord_coords(pts, end, d):
        return np.column_stack([(pts - end) @ d, (pts - end) @ np.cross(normal, d)])

    d_ab = (b - a) / chord
    le_rule = None
    le_faces = _role_faces(nominal, "leading_edge")
    te_faces = _role_faces(nominal, "trailing_edge")
    if le_faces or te_faces:
        probe = nominal.signed_distance(np.vstack([a, b]))
        fa, fb = int(probe.face[0]), int(probe.face[1])
        if fa in le_faces or fb in te_faces:
            le_rule = "CAD face roles"
        elif fb in le_faces or fa in te_faces:
            a, b, d_ab = b, a, -d_ab
            le_rule = "CAD face roles"
    if le_rule is None and verts:
        polys_ab = [chord_coords(p, a, d_ab) for p in verts]
        width_a = _width_at(polys_ab, _THICKNESS_PROBE * chord)
        width_b = _width_at(polys_ab, (1.0 - _THICKNESS_PROBE) * chord)
        if width_b > width_a:
            a, b, d_ab = b, a, -d_ab
        le_rule = "blunter end"
    elif le_rule is None:
        le_rule = "undetermined (no CAD profile)"
    cross = np.cross(normal, d_ab)
    profile = Profile(polylines=verts, le=a, te=b, chord_dir=d_ab, cross_dir=cross,
                      chord=chord, le_rule=le_rule)
    if verts:
        _attach_sides(nominal, profile, verts)
    return profile


def _attach_sides(nominal, profile, verts):
    """Split the profile's longest polyline at its chord ends into two halves, labelled suction
    and pressure; the nearest half names the side of any point."""
    main = max(verts, key=len)
    p2 = np.column_stack([(main - profile.le) @ profile.chord_dir,
                          (main - profile.le) @ profile.cross_dir])
    i_le = int(np.argmin(np.linalg.norm(p2 - [0.0, 0.0], axis=1)))
    i_te = int(np.argmin(np.linalg.norm(p2 - [profile.chord, 0.0], axis=1)))
    if i_le == i_te:
        return
    h1, h2 = _halves(p2, i_le, i_te)
    if not h2:
        return

    def length(pieces):
        return sum(float(np.sum(np.linalg.norm(np.diff(h, axis=0), axis=1))) for h in pieces)
    suction_first = length(h1) >= length(h2)
    suction_faces = _role_faces(nominal, "suction")
    pressure_faces = _role_faces(nominal, "pressure")
    if suction_faces or pressure_faces:
        mids = np.vstack([max(h, key=len)[len(max(h, key=len)) // 2] for h in (h1, h2)])
        mids3 = (profile.le + mids[:, :1] * profile.chord_dir
                 + mids[:, 1:] * profile.cross_dir)
        faces = nominal.signed_distance(mids3).face
        if int(faces[0]) in suction_faces or int(faces[1]) in pressure_faces:
            suction_first = True
        elif int(faces[1]) in suction_faces or int(faces[0]) in pressure_faces:
            suction_first = False
    r1 = np.vstack([_resample(h, _SIDE_SPACING) for h in h1])
    r2 = np.vstack([_resample(h, _SIDE_SPACING) for h in h2])
    names = ("suction", "pressure") if suction_first else ("pressure", "suction")
    profile.side_tree = cKDTree(np.vstack([r1, r2]))
    profile.side_label = np.array([names[0]] * len(r1) + [names[1]] * len(r2))


def classify(profile, xyz, edge_fraction=EDGE_FRACTION):
    """Zone of each point ('LE', 'TE', 'suction', 'pressure') in a section's chord frame;
    '' where the section has no profile to say."""
    xyz = np.atleast_2d(np.asarray(xyz, dtype=float))
    zone = np.full(len(xyz), "", dtype=object)
    if profile is None or len(xyz) == 0:
        return zone
    d = xyz - profile.le
    t = d @ profile.chord_dir
    s = d @ profile.cross_dir
    if profile.side_tree is not None:
        _, idx = profile.side_tree.query(np.column_stack([t, s]))
        zone[:] = profile.side_label[idx]
    zone[t <= edge_fraction * profile.chord] = "LE"
    zone[t >= (1.0 - edge_fraction) * profile.chord] = "TE"
    return zone


# ---------------------------------------------------------------- CMM

def section_label(value):
    """Section ids as text: 2, 2.0 and '2' are the same section."""
    if value is None:
        return None
    text = str(value).strip()
    if text == "" or text.lower() == "nan":
        return None
    try:
        f = float(text)
        return str(int(f)) if f == int(f) else repr(f)
    except (ValueError, OverflowError):
        return text


def read_cmm(path):
    """A CMM report's points: CSV with header x,y,z[,section] or whitespace columns
    x y z [section]; CAD frame, probe compensated. Rows with an empty section go to the
    nearest plane later."""
    if not os.path.exists(path):
        raise InputError("%s: no such CMM file" % path)
    try:
        with open(path, newline="") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError("%s: cannot read CMM file (%s)" % (path, exc))
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError("%s: CMM file is empty" % path)
    if "," in lines[0] or ";" in lines[0]:
        delim = ";" if lines[0].count(";") > lines[0].count(",") else ","
        rows = list(csv.reader(lines, delimiter=delim))
    else:
        rows = [ln.split() for ln in lines]
    header = [c.strip().lower() for c in rows[0]]
    if {"x", "y", "z"} <= set(header):
        ix, iy, iz = header.index("x"), header.index("y"), header.index("z")
        isec = header.index("section") if "section" in header else None
        body, first_line = rows[1:], 2
    else:
        ix, iy, iz = 0, 1, 2
        isec = 3 if len(rows[0]) >= 4 else None
        body, first_line = rows, 1
    xyz, section = [], []
    for k, row in enumerate(body):
        try:
            p = [float(row[ix]), float(row[iy]), float(row[iz])]
        except (ValueError, IndexError):
            raise InputError("%s: line %d: x, y, z must be numbers, got %r"
                             % (path, first_line + k, ",".join(row)))
        if not np.all(np.isfinite(p)):
            raise InputError("%s: line %d: coordinates not finite" % (path, first_line + k))
        xyz.append(p)
        section.append(section_label(row[isec]) if isec is not None and isec < len(row)
                       else None)
    if not xyz:
        raise InputError("%s: CMM file has no points" % path)
    return CmmData(xyz=np.asarray(xyz, dtype=float), section=section, source=path)


def _assign_cmm(cmm, sections):
    """Index of the section each CMM row belongs to: its named section, or the nearest plane."""
    labels = {s.label: k for k, s in enumerate(sections)}
    origins = np.array([s.origin for s in sections])
    normals = np.array([s.normal for s in sections])
    plane_dist = np.abs(np.einsum("nkj,kj->nk", cmm.xyz[:, None, :] - origins[None], normals))
    nearest = np.argmin(plane_dist, axis=1)
    out = np.empty(len(cmm.xyz), dtype=int)
    for i, lab in enumerate(cmm.section):
        if lab is None:
            out[i] = nearest[i]
        elif lab in labels:
            out[i] = labels[lab]
        else:
            raise InputError("%s: section %r is not one of the measured sections (%s)"
                             % (cmm.source, lab, ", ".join(labels)))
    return out


# ---------------------------------------------------------------- the table

def _column_sections(result, span_axis, span_range):
    values = np.asarray(result.columns["section"])
    labels = np.array([section_label(v) for v in values], dtype=object)
    out = []
    for lab in sorted(set(x for x in labels if x is not None), key=_sort_key):
        idx = np.flatnonzero(labels == lab)
        if len(idx) < 3:
            continue
        use = idx[result.inlier[idx]] if np.count_nonzero(result.inlier[idx]) >= 3 else idx
        try:
            plane = fit_plane(result.points_cad[use])
        except InputError:
            raise InputError("points: section %s has collinear points, its plane is undefined"
                             % lab)
        normal = plane.normal if plane.normal @ span_axis >= 0 else -plane.normal
        lo, hi = span_range
        height = 100.0 * (plane.point @ span_axis - lo) / (hi - lo)
        out.append(("section column", lab, plane.point, normal, height, idx))
    return out


def _sort_key(label):
    try:
        return (0, float(label), "")
    except ValueError:
        return (1, 0.0, label)


def _height_sections(result, nominal, span_axis, span_range, heights_pct, band):
    lo, hi = span_range
    s = result.points_cad @ span_axis
    centre = nominal.samples.xyz.mean(axis=0)
    out = []
    for k, h in enumerate(heights_pct):
        level = lo + float(h) / 100.0 * (hi - lo)
        idx = np.flatnonzero(np.abs(s - level) <= band)
        origin = centre + (level - centre @ span_axis) * span_axis
        out.append(("span height", str(k + 1), origin, span_axis.copy(), float(h), idx))
    return out


def section_table(result, nominal, heights_pct=SECTION_HEIGHTS_PCT, band=0.25, within=0.02,
                  cmm=None, span_axis=None, edge_fraction=EDGE_FRACTION):
    """Table 2 for a registration: one Section per section plane with the optical figures (and
    the CMM's beside them when ``cmm`` — a path or CmmData — is given). See the module notes
    for where sections, edges and sides are."""
    # cad/ needs FreeCAD; inspection/ imports without it
    from ..cad.airfoil_sections import AIRFOIL_SPACING
    from ..cad.sections import exact_cut
    for name, value in (("band", band), ("within", within), ("edge_fraction", edge_fraction)):
        if not np.isfinite(value) or value <= 0:
            raise InputError("section table: %s must be positive, got %r" % (name, value))
    heights = section_heights(heights_pct, "section heights", allow_empty=True)
    axis, span_range = span_axis_of(nominal, span_axis)
    warnings = []
    if "section" in result.columns:
        specs = _column_sections(result, axis, span_range)
        if not specs:
            warnings.append("the section column names no section with 3 points or more; "
                            "using planes at span heights")
    else:
        specs = []
    if not specs:
        specs = _height_sections(result, nominal, axis, span_range, heights, band)

    sections = []
    for source, label, origin, normal, height, idx in specs:
        try:
            polylines, faces = exact_cut(nominal.shape, origin, normal, AIRFOIL_SPACING)
        except InputError:
            polylines, faces = [], None
            warnings.append("section %s: the plane misses the CAD" % label)
        profile = build_profile(nominal, polylines, normal, result.points_cad[idx], origin)
        if profile is not None and faces is not None and all(len(p) >= 2 for p in polylines):
            profile.faces = faces
        zone = classify(profile, result.points_cad[idx], edge_fraction)
        sec = Section(label=label, source=source, origin=np.asarray(origin, dtype=float),
                      normal=np.asarray(normal, dtype=float), height_pct=float(height),
                      point_index=idx, zone=zone, profile=profile,
                      optical=_zone_figures(result.deviation[idx], zone, within))
        sec.optical["n_outliers"] = int(np.count_nonzero(~result.inlier[idx]))
        if len(idx) == 0:
            warnings.append("section %s: no measured points" % label)
        sections.append(sec)

    table = SectionTable(sections=sections, span_axis=axis, span_range=span_range, band=band,
                         within=within, edge_fraction=edge_fraction, warnings=warnings)
    if cmm is not None:
        _add_cmm(table, nominal, cmm if isinstance(cmm, CmmData) else read_cmm(cmm))
    return table


def _add_cmm(table, nominal, cmm):
    which = _assign_cmm(cmm, table.sections)
    dist = nominal.signed_distance(cmm.xyz)
    deviation = np.asarray(dist.distance, dtype=float)
    table.cmm_source = cmm.source
    for k, sec in enumerate(table.sections):
        rows = which == k
        sec.cmm_xyz = cmm.xyz[rows]
        sec.cmm_deviation = deviation[rows]
        sec.cmm_closest = np.asarray(dist.closest, dtype=float)[rows]
        sec.cmm_normal = np.asarray(dist.normal, dtype=float)[rows]
        sec.cmm_zone = classify(sec.profile, sec.cmm_xyz, table.edge_fraction)
        sec.cmm = _zone_figures(sec.cmm_deviation, sec.cmm_zone, table.within)
