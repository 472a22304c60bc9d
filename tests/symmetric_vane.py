"""A prismatic vane whose profile is a cambered double circular arc (issue 13, item 1): nearly
symmetric under a half turn about its thickness axis, told apart only by its two edge fillets.

Built with FreeCAD Part (two arcs closed into a face, extruded along the span, the two sharp
edges filleted by OCC), sampled on every face by area, given uniform noise along the exact
normal and gross outliers, and moved by a known random pose. Shared by
tests/test_symmetric_vane.py and bench/bench_symmetric_vane.py.
"""
import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.pointio import PointSet
from BladeInspect.inspection.simulate import GOOD_SNR, OUTLIER_SNR, sample_faces

# The issue's vane: suction arc through (-25,0),(0,6),(25,0), pressure arc through
# (-25,0),(0,2),(25,0), edge radii 0.8 (x = -25) and 0.4 (x = +25), span 100 mm.
ISSUE_VANE = dict(half_chord=25.0, suction_rise=6.0, pressure_rise=2.0,
                  radius_minus=0.8, radius_plus=0.4, span=100.0)
# A second vane with other arcs and radii (bench only).
OTHER_VANE = dict(half_chord=30.0, suction_rise=8.0, pressure_rise=3.5,
                  radius_minus=1.2, radius_plus=0.5, span=80.0)


def make_vane(half_chord, suction_rise, pressure_rise, radius_minus, radius_plus, span):
    """The vane solid: profile in the x-y plane, span along +z from 0."""
    import FreeCAD
    import Part
    V = FreeCAD.Vector
    a, b = V(-half_chord, 0, 0), V(half_chord, 0, 0)
    suction = Part.Arc(a, V(0, suction_rise, 0), b).toShape()
    pressure = Part.Arc(a, V(0, pressure_rise, 0), b).toShape()
    face = Part.Face(Part.Wire([suction, pressure]))
    solid = face.extrude(V(0, 0, span))
    for x, radius in ((-half_chord, radius_minus), (half_chord, radius_plus)):
        edge = [e for e in solid.Edges
                if abs(e.Vertexes[0].X - x) < 1e-6 and abs(e.Vertexes[-1].X - x) < 1e-6
                and abs(e.Vertexes[0].Z - e.Vertexes[-1].Z) > 0.5 * span]
        solid = solid.makeFillet(radius, edge)
    return solid


def vane_nominal(**params):
    from BladeInspect.cad.nominal import nominal_from_shape
    return nominal_from_shape(make_vane(**params))


def scan_vane(nominal, seed, n_points=5000, amplitude=0.006, outlier_fraction=0.02,
              max_translation=100.0):
    """Every face sampled by area, uniform error on [-a, a] along the normal, gross outliers
    (0.1-0.5 mm off, low SNR), a random pose. Returns (PointSet, measured_to_cad truth, good)."""
    rng = np.random.default_rng(seed)
    pts, nrm = sample_faces(nominal, list(range(len(nominal.faces))), n_points, rng)
    err = rng.uniform(-amplitude, amplitude, n_points)
    snr = rng.uniform(*GOOD_SNR, n_points)
    n_out = int(round(outlier_fraction * n_points))
    outliers = rng.choice(n_points, size=n_out, replace=False)
    err[outliers] = rng.choice([-1.0, 1.0], n_out) * rng.uniform(0.1, 0.5, n_out)
    snr[outliers] = rng.uniform(*OUTLIER_SNR, n_out)
    move = tf.random_transform(rng, max_translation)
    measured = tf.apply_transform(move, pts + err[:, None] * nrm)
    good = np.ones(n_points, bool)
    good[outliers] = False
    ps = PointSet(xyz=measured, snr=snr, columns={}, n_rows_skipped=0,
                  source="simulated vane scan (seed %d)" % seed)
    return ps, tf.invert_transform(move), good
