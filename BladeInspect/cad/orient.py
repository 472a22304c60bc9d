"""Which side of each CAD face is outside the material: the sign of every deviation.

A solid says it by itself: its faces' orientations point out of it. A compound of open faces
(an IGES or STEP of a blade's suction and pressure surfaces, no caps) says nothing: each
face's normal Su x Sv follows the parameterisation its CAD system happened to choose, so one
side of a blade may read every bump as a dent. The rule, per face, in this order:

1. A face of a closed solid in the shape keeps the solid's orientation ("closed solid").
2. Otherwise a ray-parity vote ("ray parity"). At sample points p inside the face (away from
   its boundary) two test points p + e n and p - e n straddle it along its own normal n. From
   each, a ray leaves the face along one of 13 fixed lines (3 axes, 4 body and 6 face
   diagonals; lines within MIN_COSINE of the tangent plane sit out) and its crossings with a
   mesh of all the faces are counted: an odd count means inside. Where exactly one of the two
   test points is inside, the pair votes that n points away from it ("outward") or into it
   ("flipped"); both or neither inside (a ray out through an open end, a lone sheet) abstains.
   The vote needs no consistent orientation anywhere, no sewing tolerance and no closed
   shell: faces that nearly enclose a volume, or two sides facing each other, decide it.
   confidence = |outward - flipped| / (outward + flipped + abstained); at DECIDE_CONFIDENCE
   or more the majority sets the face's side. Below it (a single open face, a flat sheet) the
   face keeps its file normal and is reported "undecided".
3. ``--flip-face`` reverses the side the rule chose (or the file's, when undecided) for the
   listed faces; what the rule found is kept in the record.

The mesh is a grid in each face's parameters (the face's own sampling density, cells kept
when their corners are inside a trimmed domain); the test points' offset e is a few times the
mesh's sag there, so a test point lies on the same side of the mesh as of the exact surface.
"""

from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.spatial import cKDTree

from ..core import bspline
from ..core.errors import InputError

# Vote points per face (random interior cells of its mesh, fixed seed).
VOTE_POINTS = 64
# A ray line this close to a face's tangent plane (|cos| with its normal below) does not vote.
MIN_COSINE = 0.2
# Confidence at or above which the vote decides a face's side.
DECIDE_CONFIDENCE = 0.5
# Mesh cells over all faces together, and at least this many per face and direction.
MESH_CELLS = 12000
MIN_CELLS_PER_SIDE = 16
# Test points lie this many mesh sags off the face, plus this fraction of the mesh spacing.
OFFSET_SAGS = 3.0
OFFSET_SPACING = 0.01


def _ray_lines():
    lines = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
    lines += [(1, sy, sz) for sy in (1, -1) for sz in (1, -1)]
    lines += [(1, 1, 0), (1, -1, 0), (1, 0, 1), (1, 0, -1), (0, 1, 1), (0, 1, -1)]
    lines = np.array(lines, dtype=float)
    return lines / np.linalg.norm(lines, axis=1, keepdims=True)


RAY_LINES = _ray_lines()


@dataclass
class FaceSide:
    """How one face's outward side was decided."""
    index: int
    flip: bool                    # the outward normal is the opposite of the file's
    orientation: str              # "outward" (file normal), "flipped", "undecided"
    rule: str                     # "closed solid", "ray parity", "--flip-face"
    confidence: float             # of the rule that decided (1 for a closed solid)
    votes: Optional[dict] = None  # ray parity: outward, flipped, abstained
    automatic: Optional[dict] = None   # with --flip-face: what the rule alone found

    def to_json(self):
        doc = {"index": self.index, "orientation": self.orientation, "rule": self.rule,
               "confidence": round(float(self.confidence), 4)}
        if self.votes is not None:
            doc["votes"] = dict(self.votes)
        if self.automatic is not None:
            doc["automatic"] = dict(self.automatic)
        return doc


def face_sides(shape, faces, surfaces, domains, reversed_, flip_faces=()):
    """A FaceSide per face of ``faces`` (= shape.Faces; ``surfaces``, ``domains`` and
    ``reversed_`` as in the Nominal, reversed_ from the file). ``flip_faces``: indices the
    user reverses."""
    flip_faces = sorted({int(i) for i in flip_faces})
    for i in flip_faces:
        if not 0 <= i < len(faces):
            raise InputError("--flip-face %d: the CAD has %d faces (0-%d)"
                             % (i, len(faces), len(faces) - 1))
    in_solid = _faces_of_closed_solids(shape, faces)
    for i in flip_faces:
        if in_solid[i]:
            raise InputError("--flip-face %d: face %d bounds a closed solid, whose outside is "
                             "known" % (i, i))
    sides = [FaceSide(i, False, "outward", "closed solid", 1.0) if in_solid[i] else None
             for i in range(len(faces))]
    loose = [i for i in range(len(faces)) if not in_solid[i]]
    if loose:
        votes = _parity_votes(surfaces, domains, reversed_, loose)
        for i in loose:
            sides[i] = _side_from_votes(i, votes[i])
    for i in flip_faces:
        s = sides[i]
        auto = {"orientation": s.orientation, "rule": s.rule,
                "confidence": round(float(s.confidence), 4)}
        flip = not s.flip
        sides[i] = FaceSide(i, flip, "flipped" if flip else "outward", "--flip-face", 1.0,
                            s.votes, auto)
    return sides


def side_warnings(sides):
    """Lines for result.json's warnings and the terminal: undecided faces, and user flips
    against a decided rule."""
    out = []
    undecided = [s.index for s in sides if s.orientation == "undecided"]
    if undecided:
        listed = ",".join(str(i) for i in undecided)
        out.append("CAD face%s %s: which side is outside the material could not be decided "
                   "(open face%s that enclose%s no volume); %s deviations are signed by the "
                   "file's face normal, which may be inverted: check, and pass --flip-face %s "
                   "if they read the wrong way"
                   % ("s" if len(undecided) > 1 else "", listed,
                      "s" if len(undecided) > 1 else "", "" if len(undecided) > 1 else "s",
                      "their" if len(undecided) > 1 else "its", listed))
    for s in sides:
        if s.automatic is not None and s.automatic["orientation"] != "undecided":
            out.append("CAD face %d: --flip-face overrides the %s rule (confidence %.2f), which "
                       "found it %s" % (s.index, s.automatic["rule"], s.automatic["confidence"],
                                        s.automatic["orientation"]))
    return out


def _faces_of_closed_solids(shape, faces):
    """(F,) bool: the face bounds a solid of the shape whose shells are all closed."""
    closed = np.zeros(len(faces), bool)
    members = {}
    for solid in shape.Solids:
        if not solid.Shells or not all(sh.isClosed() for sh in solid.Shells):
            continue
        for g in solid.Faces:
            members.setdefault(g.hashCode(), []).append(g)
    for i, f in enumerate(faces):
        closed[i] = any(f.isSame(g) for g in members.get(f.hashCode(), ()))
    return closed


def _side_from_votes(index, votes):
    total = votes["outward"] + votes["flipped"] + votes["abstained"]
    confidence = abs(votes["outward"] - votes["flipped"]) / total if total else 0.0
    if confidence < DECIDE_CONFIDENCE:
        return FaceSide(index, False, "undecided", "ray parity", confidence, votes)
    flip = votes["flipped"] > votes["outward"]
    return FaceSide(index, flip, "flipped" if flip else "outward", "ray parity", confidence,
                    votes)


# ---------------------------------------------------------------- the vote

def _inside_domain(domain, uv):
    if domain.index is None:
        return np.ones(len(uv), bool)
    return domain.index.query(uv)[0]


def _face_mesh(surf, domain, spacing):
    """(triangles (T, 3, 3), cell centres' (u, v) (C, 2) inside the domain and off the
    boundary ring, the mesh's points there (C, 3): the midpoint of the diagonal both
    triangles of the cell share) of a grid mesh of the face."""
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    probe_u, probe_v = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 9), indexing="ij")
    (P,) = bspline.evaluate(surf, probe_u.ravel(), probe_v.ravel(), order=0)
    P = P.reshape(9, 9, 3)
    lu = np.linalg.norm(np.diff(P, axis=0), axis=2).sum(axis=0).max()
    lv = np.linalg.norm(np.diff(P, axis=1), axis=2).sum(axis=1).max()
    nu = max(MIN_CELLS_PER_SIDE, int(np.ceil(lu / spacing)))
    nv = max(MIN_CELLS_PER_SIDE, int(np.ceil(lv / spacing)))
    u = np.linspace(u0, u1, nu + 1)
    v = np.linspace(v0, v1, nv + 1)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    corner_uv = np.column_stack([uu.ravel(), vv.ravel()])
    (C,) = bspline.evaluate(surf, corner_uv[:, 0], corner_uv[:, 1], order=0)
    C = C.reshape(nu + 1, nv + 1, 3)
    inside = _inside_domain(domain, corner_uv).reshape(nu + 1, nv + 1)
    a, b, c, d = C[:-1, :-1], C[1:, :-1], C[1:, 1:], C[:-1, 1:]
    kept = inside[:-1, :-1] & inside[1:, :-1] & inside[1:, 1:] & inside[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], axis=2)[kept], np.stack([a, c, d], axis=2)[kept]])
    interior = kept.copy()
    interior[[0, -1], :] = False
    interior[:, [0, -1]] = False
    iu, iv = np.nonzero(interior)
    centre_uv = np.column_stack([0.5 * (u[iu] + u[iu + 1]), 0.5 * (v[iv] + v[iv + 1])])
    return tris, centre_uv, 0.5 * (a + c)[iu, iv]


def _parity_votes(surfaces, domains, reversed_, voters):
    """Per face index in ``voters``: {outward, flipped, abstained} counts of the vote."""
    areas = []
    for surf in surfaces:
        (u0, u1), (v0, v1) = surf.u_range, surf.v_range
        g = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 9), indexing="ij")
        _, Su, Sv = bspline.evaluate(surf, g[0].ravel(), g[1].ravel(), order=1)
        areas.append(np.mean(np.linalg.norm(np.cross(Su, Sv), axis=1)) * (u1 - u0) * (v1 - v0))
    spacing = max(np.sqrt(sum(areas) / MESH_CELLS), 1e-9)
    rng = np.random.default_rng(0)
    triangles, tests, owners = [], [], []
    for f, (surf, domain) in enumerate(zip(surfaces, domains)):
        tris, centre_uv, on_mesh = _face_mesh(surf, domain, spacing)
        triangles.append(tris)
        if f not in voters or len(centre_uv) == 0:
            continue
        pick = rng.choice(len(centre_uv), size=min(VOTE_POINTS, len(centre_uv)), replace=False)
        S, Su, Sv = bspline.evaluate(surf, centre_uv[pick, 0], centre_uv[pick, 1], order=1)
        n = np.cross(Su, Sv)
        length = np.linalg.norm(n, axis=1)
        good = length > 0
        n = n[good] / length[good, None]
        if reversed_[f]:
            n = -n
        sag = np.abs(np.einsum("ij,ij->i", S[good] - on_mesh[pick][good], n))
        tests.append((S[good], n, sag))
        owners.append(np.full(int(good.sum()), f))
    mesh = np.concatenate(triangles) if triangles else np.zeros((0, 3, 3))
    counts = {f: {"outward": 0, "flipped": 0, "abstained": 0} for f in voters}
    if not tests or len(mesh) == 0:
        return counts
    p = np.concatenate([t[0] for t in tests])
    n = np.concatenate([t[1] for t in tests])
    e = OFFSET_SAGS * np.concatenate([t[2] for t in tests]) + OFFSET_SPACING * spacing
    owner = np.concatenate(owners)
    plus, minus = p + e[:, None] * n, p - e[:, None] * n
    for line in RAY_LINES:
        cos = n @ line
        use = np.abs(cos) >= MIN_COSINE
        if not use.any():
            continue
        ahead, behind = _crossings(mesh, np.concatenate([plus[use], minus[use]]), line)
        k = int(use.sum())
        away = cos[use] > 0
        # Each test point's ray leaves the face: p+ along +n's side of the line, p- along -n's.
        odd_plus = np.where(away, ahead[:k], behind[:k]) % 2 == 1
        odd_minus = np.where(away, behind[k:], ahead[k:]) % 2 == 1
        who = owner[use]
        for f in np.unique(who):
            mine = who == f
            out_votes = int(np.count_nonzero(mine & odd_minus & ~odd_plus))
            in_votes = int(np.count_nonzero(mine & odd_plus & ~odd_minus))
            counts[f]["outward"] += out_votes
            counts[f]["flipped"] += in_votes
            counts[f]["abstained"] += int(np.count_nonzero(mine)) - out_votes - in_votes
    return counts


def _crossings(triangles, points, direction):
    """(ahead, behind) (N,) int: triangles the line through each point along ``direction``
    crosses beyond it and before it."""
    a = np.array([1.0, 0, 0]) if abs(direction[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(direction, a)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(direction, e1)
    basis = np.column_stack([e1, e2])
    tri2 = triangles @ basis                     # (T, 3, 2)
    depth = triangles @ direction                # (T, 3)
    centre = tri2.mean(axis=1)
    reach = float(np.linalg.norm(tri2 - centre[:, None, :], axis=2).max())
    q2 = points @ basis
    qd = points @ direction
    near = cKDTree(centre).query_ball_point(q2, reach * (1 + 1e-9))
    qi = np.repeat(np.arange(len(points)), [len(x) for x in near])
    ti = np.fromiter((t for x in near for t in x), dtype=int, count=len(qi))
    n = len(points)
    if len(qi) == 0:
        return np.zeros(n, int), np.zeros(n, int)
    o = tri2[ti, 0]
    ab = tri2[ti, 1] - o
    ac = tri2[ti, 2] - o
    w = q2[qi] - o
    det = ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]
    ok = det != 0
    det = np.where(ok, det, 1.0)
    s = (w[:, 0] * ac[:, 1] - w[:, 1] * ac[:, 0]) / det
    t = (ab[:, 0] * w[:, 1] - ab[:, 1] * w[:, 0]) / det
    hit = ok & (s >= 0) & (t >= 0) & (s + t <= 1)
    z = depth[ti, 0] + s * (depth[ti, 1] - depth[ti, 0]) + t * (depth[ti, 2] - depth[ti, 0])
    ahead = np.bincount(qi[hit & (z > qd[qi])], minlength=n)
    behind = np.bincount(qi[hit & (z < qd[qi])], minlength=n)
    return ahead, behind
