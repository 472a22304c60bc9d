"""The profile's two edges found as edges: where its two sides meet at the ends of the camber
line, whatever the caliper diameter does.

The caliper diameter's ends are the edges of a lightly cambered profile, but on a strongly
turned one (a turbine vane) or one with a long non-circular nose, an end sits on a side's
shoulder: the camber line between sides split there stops short of the nose. So the split is
moved to where the camber line's end tangents, extended, leave the profile, the camber line
worked out again between the new sides, and so on until the split points stop moving. On an
exact circular edge that fixed point is the edge point itself (the tangent through the edge
circle's centre); once a split point is in the nose the camber line no longer depends on
where exactly (its end is set by the edge, medial.py), so the rounds stop as soon as both
split points are in the nose: seen from the camber line's end within NOSE_HALF_ANGLE_DEG of
its outward tangent. On a lightly cambered profile the caliper's ends already are.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .camber import line_end
from .chords import farthest_pair
from .medial import medial_axis, side_samples
from .profile import ray_hit

# A split point is in the nose when, seen from its end of the camber line, it lies within
# this angle of the line's outward end tangent; there the camber line no longer depends on it.
NOSE_HALF_ANGLE_DEG = 20.0
_ROUNDS = 12


@dataclass
class EdgeSplit:
    """The two sides between the edges and the camber line's inscribed circles between them
    (centres ordered from side a's start, at u_a, to its end, at u_b)."""
    u_a: float
    u_b: float
    side_a: object
    side_b: object
    centres: np.ndarray
    radii: np.ndarray
    rounds: int


def edge_split(profile, window_pct):
    """The profile split into its two sides at its edges: from the caliper diameter's ends,
    re-split where the camber line's end tangents (the metal angle rule's, ``window_pct``)
    leave the profile until the split settles. InputError when it does not settle."""
    L = profile.length
    u_a, u_b = sorted(u % L for u in farthest_pair(profile)[:2])
    cos_nose = np.cos(np.radians(NOSE_HALF_ANGLE_DEG))
    for rounds in range(1, _ROUNDS + 1):
        side_a, side_b = side_samples(profile, u_a, u_b), side_samples(profile, u_b, u_a)
        centres, radii = medial_axis(profile, side_a, side_b)
        settled, hits = True, []
        for end, u in ((0, u_a), (-1, u_b)):
            out = line_end(centres, radii, end, window_pct=window_pct)[2]
            seen = profile.eval([u])[0] - centres[end]
            settled &= bool(out @ seen >= cos_nose * np.linalg.norm(seen))
            hits.append(ray_hit(profile, centres[end], out, behind=True)[0][0] % L)
        if settled:
            return EdgeSplit(u_a, u_b, side_a, side_b, centres, radii, rounds)
        u_a, u_b = hits
        if _cyclic_gap(u_a, u_b, L) < 0.05 * L:
            break
    raise InputError("airfoil profile: its edges could not be found (the camber line's ends "
                     "do not settle on two separate edges); not an airfoil-like profile")


def _cyclic_gap(u, v, length):
    d = abs(u - v) % length
    return min(d, length - d)
