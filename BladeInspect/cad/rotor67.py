"""A blade from a section table: NASA Rotor 67's streamsurface file lofted into a solid.

File format (self-documented in its header, see data/blades/nasa_rotor67/PROVENANCE.txt):
a line "JM NS NB JLE JTE" followed by their values, then for each of the NS streamsurfaces
(1 = hub ... NS = casing) a "Surface number k" line and four blocks of JM values, each a name
line, a scale-factor line and the values (8 a line, FEET): axial distance, radius*theta of the
upper surface, tangential thickness (lower = upper - thickness, as r*dtheta) and radius.
The blade is J = JLE..JTE (1-based); the thickness is 0 there, so both sides share their
leading and trailing points.

Which sections: the file's text calls section 13 "the blade tip section" and puts the tip a
0.024 in clearance inside the casing (surface 14), but section 13 lies about 12 mm (in
radius) inside section 14, and the independent surface cloud of the same blade
(MoveSurface_NASA_R67_parablade.txt) runs right up to the casing. So by default all
sections 1..NS are lofted, hub to casing with no tip gap, as that cloud has it; pass
``sections=range(1, 14)`` for the file's own reading.

Frame: X = r cos(theta), Y = r sin(theta), Z = axial, millimetres; the rotation axis is Z.
The upper (larger theta) side is the convex one: the suction side.
"""
import os
import re

import numpy as np

from ..core.errors import InputError
from .demo_blade import BladeModel

FOOT_MM = 304.8
BLOCKS = ("axial", "r_theta", "thickness", "radius")


def read_rotor67(path):
    """The file's streamsurfaces: dict with jm, ns, jle, jte (1-based) and for each block name
    an (ns, jm) array in feet (scale factors applied)."""
    try:
        with open(path, "r", errors="replace") as fh:
            lines = fh.read().splitlines()
    except FileNotFoundError:
        raise InputError("%s: no such section file" % path) from None
    except OSError as exc:
        raise InputError("%s: cannot be read (%s)" % (path, exc.strerror)) from None

    def fail(lineno, what):
        raise InputError("%s: line %d: %s" % (path, lineno + 1, what))

    header = None
    for i, line in enumerate(lines):
        if re.match(r"^\s*JM\s+NS\s+NB\s+JLE\s+JTE\s*$", line):
            header = i
    if header is None or header + 1 >= len(lines):
        raise InputError("%s: no 'JM NS NB JLE JTE' line: not a Rotor 67 style section file"
                         % path)
    try:
        jm, ns, _nb, jle, jte = (int(v) for v in lines[header + 1].split())
    except ValueError:
        fail(header + 1, "expected five integers JM NS NB JLE JTE")
    if not (1 <= jle < jte <= jm and ns >= 2):
        fail(header + 1, "inconsistent JM=%d NS=%d JLE=%d JTE=%d" % (jm, ns, jle, jte))

    data = {name: np.empty((ns, jm)) for name in BLOCKS}
    i = header + 2
    for surface in range(ns):
        while i < len(lines) and not re.match(r"^\s*Surface number\s+%d\b" % (surface + 1),
                                              lines[i]):
            i += 1
        if i >= len(lines):
            raise InputError("%s: surface %d of %d missing" % (path, surface + 1, ns))
        i += 1
        for name in BLOCKS:
            i += 1  # block name line
            try:
                scale = float(lines[i])
            except (IndexError, ValueError):
                fail(min(i, len(lines) - 1), "expected the scale factor of the %s block of "
                     "surface %d" % (name, surface + 1))
            i += 1
            values = []
            while len(values) < jm:
                if i >= len(lines):
                    raise InputError("%s: surface %d: %s block ends after %d of %d values"
                                     % (path, surface + 1, name, len(values), jm))
                try:
                    values.extend(float(v) for v in lines[i].split())
                except ValueError:
                    fail(i, "a non-number in the %s block of surface %d" % (name, surface + 1))
                i += 1
            if len(values) != jm:
                fail(i - 1, "%s block of surface %d has %d values, expected %d"
                     % (name, surface + 1, len(values), jm))
            data[name][surface] = scale * np.array(values)
    if not np.all(np.isfinite(np.concatenate([d.ravel() for d in data.values()]))):
        raise InputError("%s: non-finite values" % path)
    if np.any(data["radius"] <= 0):
        raise InputError("%s: radius must be positive" % path)
    return {"jm": jm, "ns": ns, "jle": jle, "jte": jte, **data}


def blade_sections(table, sections=None):
    """(upper (S, J, 3), lower (S, J, 3)) in mm, J = JLE..JTE, for the 1-based ``sections``
    (default all)."""
    sections = range(1, table["ns"] + 1) if sections is None else sections
    rows = np.array(list(sections)) - 1
    if len(rows) < 2 or rows.min() < 0 or rows.max() >= table["ns"] \
            or np.any(np.diff(rows) <= 0):
        raise InputError("sections %s: need at least 2 increasing section numbers of 1..%d"
                         % (list(sections), table["ns"]))
    cols = slice(table["jle"] - 1, table["jte"])
    z = table["axial"][rows, cols] * FOOT_MM
    r = table["radius"][rows, cols] * FOOT_MM
    r_theta = table["r_theta"][rows, cols] * FOOT_MM
    thick = table["thickness"][rows, cols] * FOOT_MM
    if np.any(thick < -1e-9):
        raise InputError("negative tangential thickness in the section file")

    def to_xyz(theta):
        return np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=-1)
    return to_xyz(r_theta / r), to_xyz((r_theta - thick) / r)


def _chord_params(rows):
    """Chord-length parameters of each row (…, n, 3), averaged over rows, in [0, 1]."""
    seg = np.linalg.norm(np.diff(rows, axis=-2), axis=-1)
    cum = np.concatenate([np.zeros(seg.shape[:-1] + (1,)), np.cumsum(seg, axis=-1)], axis=-1)
    return np.mean(cum / cum[..., -1:], axis=0)


def make_rotor67_blade(dat_path, sections=None):
    """Rotor 67 as a ``BladeModel``: a solid of suction and pressure B-spline faces through
    the 1-based ``sections`` (default all: hub to casing) closed by ruled hub and tip faces;
    roles suction, pressure, hub, tip."""
    # Rebuilt only when the file changes: the pipeline and the document objects both load it.
    try:
        stat = os.stat(dat_path)
    except OSError:
        raise InputError("%s: no such section file" % dat_path) from None
    key = (os.path.abspath(dat_path), stat.st_mtime_ns, stat.st_size,
           None if sections is None else tuple(sections))
    if key not in _CACHE:
        _CACHE[key] = _build(dat_path, sections)
    model = _CACHE[key]
    return BladeModel(shape=model.shape.copy(),
                      roles={k: list(v) for k, v in model.roles.items()},
                      params=dict(model.params))

_CACHE = {}


def side_faces(table, sections):
    """([suction, pressure] open B-spline faces, their common spanwise parameters) through the
    1-based ``sections`` of a read_rotor67 table; each face's normal is its Su x Sv, u along
    the chord from the leading edge, v along the span."""
    import Part
    from .surface_build import interpolate_grid

    upper, lower = blade_sections(table, sections)
    # Both sides use one spanwise parameter so their shared LE/TE boundary curves coincide.
    v = _chord_params(np.concatenate([upper, lower], axis=1).transpose(1, 0, 2))
    faces = []
    for side in (upper, lower):
        # A side's u parameter: chord length along each section, averaged over sections.
        faces.append(Part.Face(interpolate_grid(side, _chord_params(side), v)))
    return faces, v


def _build(dat_path, sections):
    import Part
    from .surface_build import close_sides

    table = read_rotor67(dat_path)
    sections = list(range(1, table["ns"] + 1) if sections is None else sections)
    faces, v = side_faces(table, sections)
    hub = [Part.Edge(f.Surface.vIso(v[0])) for f in faces]
    tip = [Part.Edge(f.Surface.vIso(v[-1])) for f in faces]
    solid, (i_s, i_p, i_h, i_t) = close_sides(faces[0], faces[1], hub, tip, planar_caps=False)
    return BladeModel(shape=solid,
                      roles={"suction": [i_s], "pressure": [i_p], "hub": [i_h], "tip": [i_t]},
                      params={"source": str(dat_path), "sections": sections})
