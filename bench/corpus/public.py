"""Real public geometries, read from ../shared/data/blades/ (never copied into the
repository): the ParaBlade STD10 compressor section (2D, extruded)
and NASA Rotor 67 (its section table, which the project lofts itself). Their truths are brute
force on the exact CAD profile (truth.py); Rotor 67 is scanned as made (every true deviation
zero)."""
import os

import numpy as np

from . import Case
from .profiles import DenseLoop

HERE = os.path.dirname(os.path.abspath(__file__))
BLADES = os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared", "data", "blades"))


def read_move_surface(path):
    """A 2D SU2 MoveSurface file's nodes (metres, mesh order) as one counter-clockwise loop in
    mm: repeats dropped, ordered by a nearest-neighbour chain."""
    xy = np.unique(np.round(np.loadtxt(path)[:, 1:3] * 1000.0, 9), axis=0)
    left = list(range(1, len(xy)))
    order = [0]
    while left:
        d = np.linalg.norm(xy[left] - xy[order[-1]], axis=1)
        order.append(left.pop(int(np.argmin(d))))
    loop = xy[order]
    x, y = loop.T
    if np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) < 0:
        loop = loop[::-1]
    return loop - loop.mean(axis=0)


def cases():
    pb = os.path.join(BLADES, "parablade")
    out = []
    if os.path.isdir(pb):
        out.append(Case("parablade_std10", "public",
                        DenseLoop(read_move_surface(os.path.join(pb, "STD10_2D_MoveSurface.txt"))),
                        span=100.0, source="ParaBlade STD10_2D (../shared/data/blades)"))
    r67 = os.path.join(BLADES, "nasa_rotor67", "rotor67geometry.dat")
    if os.path.exists(r67):
        out.append(Case("nasa_rotor67", "public", None, cad_path=r67, errors=("none",),
                        source="NASA Rotor 67 section table (../shared/data/blades)"))
    return out
