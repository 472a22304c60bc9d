"""The real pair: NASA Rotor 67's independent surface cloud (a CFD mesh of the blade, metres)
registered from a random pose to the blade lofted from NASA's section table. Both are in one
frame by their provenance (X = r cos th, Y = r sin th, Z = axial), so the recovered pose is
judged against it; the two geometries differ by up to 0.3 mm (PROVENANCE.txt).

    scripts/fcpython bench/bench_rotor67_cloud.py
"""
import os
import sys
import time

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.pointio import PointSet
from BladeInspect.inspection import pipeline

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data",
                    "blades", "nasa_rotor67")


def main(seed=67):
    nominal = pipeline.load_nominal(os.path.join(DATA, "rotor67geometry.dat"))
    cloud = np.loadtxt(os.path.join(DATA, "MoveSurface_NASA_R67_parablade.txt"),
                       usecols=(1, 2, 3)) * 1000.0
    move = tf.random_transform(np.random.default_rng(seed), 150.0)
    ps = PointSet(xyz=tf.apply_transform(move, cloud), snr=None, columns={}, n_rows_skipped=0,
                  source="Rotor 67 cloud")
    t0 = time.perf_counter()
    result = pipeline.register(nominal, ps, seed=seed)
    elapsed = time.perf_counter() - t0
    lo, hi = cloud.min(axis=0), cloud.max(axis=0)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    err = tf.corner_displacement(result.measured_to_cad, tf.invert_transform(move), corners)
    fallback = nominal.signed_distance(result.points_cad).fallback_fraction
    print("Rotor 67 cloud, %d points from a random pose: registered in %.1f s (%s)"
          % (len(cloud), elapsed, ", ".join("%s %.1f" % kv for kv in result.timing_s.items())))
    print("pose vs the provenance frame: %.4f mm at the worst corner; median |deviation| "
          "%.4f mm, max %.4f mm; OCC fallback %.1f %% of points"
          % (err, np.median(np.abs(result.deviation)), np.abs(result.deviation).max(),
             100 * fallback))


if __name__ == "__main__":
    sys.exit(main())
