"""NASA Rotor 67 given as surface-only CAD: its suction and pressure sides lofted from the
section table as two open B-spline faces (no hub or tip cap), written to STEP and read back,
each face with the normal its lofting gave it (Su x Sv: u along the chord, v along the span).

For points scattered on both sides at random offsets along the true outward normal, and for a
+0.05 mm bump band across both sides, the deviation's sign is compared with OCC's
Solid.isInside on the closed Rotor 67 solid (the same sides with ruled caps, as
cad.rotor67 builds it): "before" signs each face by its file normal (what the code did
before faces were oriented; reproduced here by flipping back every face the rule flipped),
"after" by the orientation rule of cad.orient.

    scripts/fcpython bench/bench_open_faces.py
"""
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import FreeCAD  # noqa: E402
import Part  # noqa: E402

from BladeInspect.cad import orient  # noqa: E402
from BladeInspect.cad.load import load_nominal  # noqa: E402
from BladeInspect.cad.rotor67 import make_rotor67_blade, read_rotor67, side_faces  # noqa: E402
from tests.helpers import ROTOR67_SECTIONS, face_points  # noqa: E402

POINTS_PER_SIDE = 200
OFFSET_MM = (0.005, 0.2)
BUMP_MM = 0.05
BAND = (0.4, 0.6)          # span fractions of the bump band


def main(seed=67):
    rng = np.random.default_rng(seed)
    model = make_rotor67_blade(ROTOR67_SECTIONS)
    solid = model.shape
    truth_faces = [solid.Faces[model.roles["suction"][0]], solid.Faces[model.roles["pressure"][0]]]
    table = read_rotor67(ROTOR67_SECTIONS)
    faces, _ = side_faces(table, range(1, table["ns"] + 1))
    tmp = tempfile.mkdtemp(prefix="bench-open-faces-")
    step = os.path.join(tmp, "rotor67-sides.step")
    Part.makeCompound(faces).exportStep(step)

    t0 = time.perf_counter()
    after = load_nominal(step)
    t_load = time.perf_counter() - t0
    t0 = time.perf_counter()
    orient.face_sides(after.shape, after.faces, after.surfaces, after.domains,
                      after.reversed)
    t_rule = time.perf_counter() - t0
    undo = [s.index for s in after.face_sides if s.flip]
    before = load_nominal(step, flip_faces=undo)

    print("Rotor 67 as two open faces (STEP), each with its lofting's normal; rule %.2f s of "
          "the %.2f s load" % (t_rule, t_load))
    for record in after.cad_faces:
        print("  face %(index)d: %(orientation)s by %(rule)s, confidence %(confidence).3f, "
              "votes %(votes)s" % record)

    points, inside, side, bump, band = [], [], [], [], []
    for k, face in enumerate(truth_faces):
        p, n, uv = face_points(face, POINTS_PER_SIDE, rng, margin=0.02)
        v = uv[:, 1]
        offset = rng.choice([-1.0, 1.0], len(p)) * rng.uniform(*OFFSET_MM, len(p))
        q = p + offset[:, None] * n
        points.append(q)
        inside.append([solid.isInside(FreeCAD.Vector(*x), 1e-9, True) for x in q])
        side.append(np.full(len(p), k))
        v0, v1 = face.ParameterRange[2:]
        in_band = (v > v0 + BAND[0] * (v1 - v0)) & (v < v0 + BAND[1] * (v1 - v0))
        bump.append(p[in_band] + BUMP_MM * n[in_band])
        band.append(np.full(int(in_band.sum()), k))
    points, inside, side = np.concatenate(points), np.concatenate(inside), np.concatenate(side)
    bump, band = np.concatenate(bump), np.concatenate(band)
    truth_negative = inside.astype(bool)

    print("sign of the deviation against OCC's isInside on the closed solid, %d points per "
          "side at %.3f-%.1f mm off it:" % (POINTS_PER_SIDE, *OFFSET_MM))
    for label, nominal in (("before", before), ("after", after)):
        d = nominal.signed_distance(points).distance
        agree = (d < 0) == truth_negative
        per_side = ", ".join("side %d (%s) %d of %d" % (k, name, int(agree[side == k].sum()),
                                                          int((side == k).sum()))
                             for k, name in enumerate(("suction", "pressure")))
        b = nominal.signed_distance(bump).distance
        means = ", ".join("%+.4f" % b[band == k].mean() for k in (0, 1))
        print("  %-6s agree: %s; total %d of %d. +%.2f mm bump band reads %s mm "
              "(suction, pressure), mean %+.4f mm"
              % (label, per_side, int(agree.sum()), len(agree), BUMP_MM, means, b.mean()))
    os.remove(step)
    os.rmdir(tmp)


if __name__ == "__main__":
    sys.exit(main())
