"""Exact signed distance of the paper's full cloud size (269,158 points) to a blade solid: time,
OCC fallback fraction, agreement with OCC on a random sample, FreeCAD's per-point route for
comparison, and the ray cast on 100,000 sensor-like rays.

Run: scripts/fcpython bench/bench_distance.py [--rotor67]
"""
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import FreeCAD  # noqa: E402
import Part  # noqa: E402

from BladeInspect.cad.nominal import nominal_from_shape  # noqa: E402

N_POINTS = 269158
N_CHECK = 300
N_OCC_TIMED = 50
N_RAYS = 100000


def blade():
    if "--rotor67" in sys.argv:
        from BladeInspect.cad.rotor67 import make_rotor67_blade
        from tests.helpers import ROTOR67_SECTIONS
        return "NASA Rotor 67", make_rotor67_blade(ROTOR67_SECTIONS)
    from BladeInspect.cad.demo_blade import make_demo_blade
    return "demo blade", make_demo_blade()


def main():
    rng = np.random.default_rng(0)
    name, model = blade()
    t = time.perf_counter()
    nominal = nominal_from_shape(model.shape, roles=model.roles)
    t_build = time.perf_counter() - t
    s = nominal.samples
    # A scan-like cloud: points on the faces (jittered parameters) moved up to +-0.1 mm along
    # the normal, plus 2 % farther off (0.1-5 mm).
    i = rng.integers(0, len(s.xyz), N_POINTS)
    off = rng.uniform(-0.1, 0.1, N_POINTS)
    far = rng.random(N_POINTS) < 0.02
    off[far] = rng.choice([-1, 1], far.sum()) * rng.uniform(0.1, 5.0, far.sum())
    pts = s.xyz[i] + off[:, None] * s.normal[i] + rng.normal(0, 0.05, (N_POINTS, 3))

    nominal.signed_distance(pts[:1000])         # warm up (k-d tree pages, numpy)
    t = time.perf_counter()
    res = nominal.signed_distance(pts)
    t_fast = time.perf_counter() - t

    pick = rng.choice(N_POINTS, N_CHECK, replace=False)
    t = time.perf_counter()
    ref = nominal.signed_distance_occ(pts[pick])
    t_ref = time.perf_counter() - t
    d_err = np.abs(res.distance[pick] - ref.distance)
    c_err = np.linalg.norm(res.closest[pick] - ref.closest, axis=1)

    # FreeCAD's own per-point route (what the Inspection workbench does): distToShape.
    t = time.perf_counter()
    for p in pts[:N_OCC_TIMED]:
        model.shape.distToShape(Part.Vertex(FreeCAD.Vector(*p)))
    per_point = (time.perf_counter() - t) / N_OCC_TIMED

    # Rays: sensor passes along -Z at a few rotary angles about +Y (the rig's convention).
    lo, hi = nominal.bbox_corners.min(axis=0), nominal.bbox_corners.max(axis=0)
    n_pass = 8
    origins, dirs = [], []
    for k in range(n_pass):
        a = 2 * np.pi * k / n_pass
        d = np.array([np.sin(a), 0.0, -np.cos(a)])
        e1 = np.array([np.cos(a), 0.0, np.sin(a)])
        m = N_RAYS // n_pass
        c = 0.5 * (lo + hi)
        u = rng.uniform(-0.3, 0.3, m) * np.linalg.norm(hi - lo)
        y = rng.uniform(lo[1], hi[1], m)
        o = c - 100 * d + u[:, None] * e1 + (y - c[1])[:, None] * np.array([0, 1.0, 0])
        origins.append(o)
        dirs.append(np.tile(d, (m, 1)))
    origins, dirs = np.concatenate(origins), np.concatenate(dirs)
    # First cast: the tessellation and one bucket grid per direction are built; the same
    # directions again reuse the grids (a scan's rotary angles recur for every line).
    t = time.perf_counter()
    nominal.raycast(origins, dirs)
    t_cold = time.perf_counter() - t
    t_ray = np.inf
    for _ in range(2):          # the better of two: other jobs share the machine
        t = time.perf_counter()
        t_hit, face, nrm = nominal.raycast(origins, dirs)
        t_ray = min(t_ray, time.perf_counter() - t)
    hit = np.flatnonzero(~np.isnan(t_hit))
    chk = rng.choice(hit, min(100, len(hit)), replace=False)
    x = origins[chk] + t_hit[chk, None] * dirs[chk]
    ray_err = nominal.signed_distance_occ(x).distance

    print("blade: %s, %d faces, %d samples, nominal built in %.2f s"
          % (name, len(nominal.faces), len(s.xyz), t_build))
    print("signed_distance: %d points in %.2f s (%.2f us/point), OCC fallback %d points (%.3f %%)"
          % (N_POINTS, t_fast, 1e6 * t_fast / N_POINTS, np.count_nonzero(res.fallback),
             100 * res.fallback_fraction))
    print("vs OCC reference on %d random points: max |d - d_occ| = %.2e mm, max |c - c_occ| = "
          "%.2e mm, signs agree: %s (reference took %.1f ms/point)"
          % (N_CHECK, d_err.max(), c_err.max(),
             bool(np.all(np.sign(res.distance[pick]) == np.sign(ref.distance))), 1e3 * t_ref / N_CHECK))
    print("FreeCAD distToShape on the solid: %.2f ms/point -> %.0f s for the full cloud "
          "(%.0f x slower)" % (1e3 * per_point, per_point * N_POINTS, per_point * N_POINTS / t_fast))
    print("raycast: %d rays (%d directions) in %.2f s (%.1f us/ray; first cast with the "
          "tessellation and grids %.2f s), %d hits; hit points' OCC distance max %.2e mm"
          % (len(origins), n_pass, t_ray, 1e6 * t_ray / len(origins), t_cold, len(hit),
             np.abs(ray_err).max()))


if __name__ == "__main__":
    main()
