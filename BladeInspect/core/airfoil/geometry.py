"""Small plane-geometry helpers the airfoil kernel's modules share (numpy only)."""

from dataclasses import dataclass

import numpy as np

def unit(v):
    v = np.asarray(v, dtype=float)
    return v / norms(v)[..., None]


def norms(v):
    """Lengths of vectors along the last axis: np.linalg.norm's sum of squares, without its
    per-call overhead (the hot loops call it tens of thousands of times)."""
    return np.sqrt(np.einsum("...i,...i->...", v, v))


def angle_deg(direction, axis):
    cross = axis[0] * direction[1] - axis[1] * direction[0]
    return float(np.degrees(np.arctan2(cross, np.dot(axis, direction))))


def cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def in_range(u, side, length):
    u = np.mod(u - side.lo, length)
    return u <= side.hi - side.lo


@dataclass
class Range:
    lo: float
    hi: float
