"""CAD of the corpus, built with FreeCAD Part: each station's profile an interpolating periodic
B-spline through points of the exact profile, the blade an extrusion (prismatic) or a loft
through the stations (twisted, leaned), optionally on a hub block with fillets, or only its
side faces (open surfaces, no solid). Written as STEP. The truth of a station is read on the
same B-spline curve (``station_loop``): the loft and the extrusion pass through it exactly."""
import os

import numpy as np


def select_points(loop, max_step=0.5, max_turn_deg=3.0):
    """Points of a dense closed loop for interpolation: at most ``max_step`` mm apart and at
    most ``max_turn_deg`` of turning between neighbours (dense round the edges)."""
    loop = np.asarray(loop, float)
    return loop[select_indices(loop, max_step, max_turn_deg)]


def select_indices(loop, max_step=0.5, max_turn_deg=3.0):
    """The indices ``select_points`` keeps."""
    loop = np.asarray(loop, float)
    d = np.roll(loop, -1, axis=0) - loop
    seg = np.linalg.norm(d, axis=1)
    ang = np.arctan2(d[:, 1], d[:, 0])
    turn = np.abs(np.angle(np.exp(1j * (np.roll(ang, -1) - ang))))
    keep, acc_l, acc_t = [0], 0.0, 0.0
    for i in range(1, len(loop)):
        acc_l += seg[i - 1]
        acc_t += np.degrees(turn[i - 1])
        if acc_l >= max_step or acc_t >= max_turn_deg:
            keep.append(i)
            acc_l = acc_t = 0.0
    return np.asarray(keep)


def _curve(points2d, z):
    import FreeCAD
    import Part
    V = FreeCAD.Vector
    c = Part.BSplineCurve()
    c.interpolate(Points=[V(float(x), float(y), float(z)) for x, y in points2d],
                  PeriodicFlag=True)
    return c


def station_loop(curve, n=40000):
    """Dense points of a station's B-spline (x, y): the exact CAD profile there."""
    pts = curve.discretize(Number=n)
    return np.array([[p.x, p.y] for p in pts[:-1]])


def build(stations, mode="solid", hub=None):
    """(shape, [curve per station]) from ``stations``: [(z, dense 2D loop)], in increasing z.
    One station: an extrusion from z = 0 to that station's z * 2. ``mode``: "solid" or
    "surfaces" (the side faces only). ``hub``: None or dict(depth, fillet) — a block under
    z = 0 fused to the blade, its junction filleted."""
    import FreeCAD
    import Part
    V = FreeCAD.Vector
    # Every station interpolates the same points of its loop (the stations are one profile
    # turned and shifted): a loft through curves of different point counts twists its surface
    # between the stations by millimetres.
    sizes = {len(loop) for _, loop in stations}
    if len(sizes) != 1:
        raise ValueError("the stations' loops differ in length: %s" % sorted(sizes))
    keep = select_indices(stations[0][1])
    curves = [_curve(np.asarray(loop, float)[keep], z) for z, loop in stations]
    if len(stations) == 1:
        z, _ = stations[0]
        z0 = -1.0 if hub else 0.0
        c0 = _curve(np.asarray(stations[0][1], float)[keep], z0)
        solid = Part.Face(Part.Wire(c0.toShape())).extrude(V(0, 0, 2 * z - z0))
    else:
        solid = _skinned(curves, [z for z, _ in stations])
    if hub:
        bb = solid.BoundBox
        m = 8.0
        block = Part.makeBox(bb.XLength + 2 * m, bb.YLength + 2 * m, hub["depth"],
                             V(bb.XMin - m, bb.YMin - m, -hub["depth"]))
        solid = solid.fuse(block).removeSplitter()
        edges = [e for e in solid.Edges
                 if abs(e.BoundBox.ZMin) < 1e-6 and abs(e.BoundBox.ZMax) < 1e-6
                 and e.BoundBox.XMin > bb.XMin - 1 and e.BoundBox.XMax < bb.XMax + 1
                 and e.BoundBox.YMin > bb.YMin - 1 and e.BoundBox.YMax < bb.YMax + 1]
        solid = solid.makeFillet(hub["fillet"], edges)
    if mode == "surfaces":
        faces = [f for f in solid.Faces if f.Surface.__class__.__name__ != "Plane"]
        return Part.Shell(faces), curves
    return solid, curves


def _skinned(curves, zs):
    """The solid through station curves that share their knots (one profile turned and
    shifted): each pole's path across the stations is a cubic interpolation of that pole's
    positions, so the surface passes through every station curve exactly and turns smoothly
    between them. (Part.makeLoft's approximation of the same curves strays by millimetres
    between the stations.)"""
    import Part
    first = curves[0]
    knots, mults = first.getKnots(), first.getMultiplicities()
    for c in curves[1:]:
        if c.getMultiplicities() != mults or \
                np.max(np.abs(np.subtract(c.getKnots(), knots))) > 1e-9 * knots[-1]:
            raise ValueError("the station curves differ in their knots")
    q = [(z - zs[0]) / (zs[-1] - zs[0]) for z in zs]
    columns = []
    for j in range(first.NbPoles):
        path = Part.BSplineCurve()
        path.interpolate(Points=[c.getPole(j + 1) for c in curves], Parameters=q)
        columns.append(path)
    surface = Part.BSplineSurface()
    surface.buildFromPolesMultsKnots(
        [c.getPoles() for c in columns], mults, columns[0].getMultiplicities(), knots,
        columns[0].getKnots(), True, False, first.Degree, columns[0].Degree)
    side = surface.toShape()
    ends = [e for e in side.Edges if abs(e.BoundBox.ZMax - e.BoundBox.ZMin) < 1e-9]
    caps = [Part.Face(Part.Wire([e])) for e in ends]
    shell = Part.Shell([side] + caps)
    shell.sewShape()        # orients the faces consistently (else the solid is invalid)
    solid = Part.Solid(shell)
    if solid.Volume < 0:
        solid.reverse()
    if not solid.isValid():
        raise ValueError("the skinned blade is not a valid solid")
    return solid


def write_step(shape, path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".part.step"
    shape.exportStep(tmp)
    os.replace(tmp, path)
