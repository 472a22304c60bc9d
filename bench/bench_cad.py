"""CAD building figures: build times, Rotor 67 loft against its independent cloud (every
point), section cut time and accuracy of the reconstruction from noisy section passes.

Run: scripts/fcpython bench/bench_cad.py [--quick]
(--quick uses 400 cloud points instead of all 2057)."""
import os
import sys
import time

import numpy as np

import FreeCAD
import Part

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from BladeInspect.cad import demo_blade  # noqa: E402
from BladeInspect.cad.loft import reconstruct  # noqa: E402
from BladeInspect.cad.rotor67 import make_rotor67_blade  # noqa: E402
from BladeInspect.cad.sections import cut  # noqa: E402
from BladeInspect.core.pointio import PointSet  # noqa: E402
from tests.helpers import ROTOR67_CLOUD, ROTOR67_SECTIONS, have_rotor67  # noqa: E402

V = FreeCAD.Vector


def timed(fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t0


def main(quick):
    demo_blade._CACHE.clear()
    model, t = timed(demo_blade.make_demo_blade)
    bb = model.shape.BoundBox
    print("demo blade: build %.3f s, volume %.1f mm3, box %.1f x %.1f x %.1f mm, valid %s"
          % (t, model.shape.Volume, bb.XLength, bb.YLength, bb.ZLength, model.shape.isValid()))
    _, t = timed(demo_blade.make_demo_blade)
    print("demo blade: cached copy %.4f s" % t)

    lines, t = timed(cut, model.shape, [0, 0, 35.0], [0, 0, 1])
    print("section cut z=35: %.3f s, %d polyline(s), %d points"
          % (t, len(lines), sum(len(l) for l in lines)))

    if have_rotor67():
        r67, t = timed(make_rotor67_blade, ROTOR67_SECTIONS)
        print("rotor67 (sections 1..14): build %.3f s, volume %.0f mm3, valid %s"
              % (t, r67.shape.Volume, r67.shape.isValid()))
        cloud = np.loadtxt(ROTOR67_CLOUD)[:, 1:4] * 1000.0
        if quick:
            cloud = cloud[np.random.default_rng(0).choice(len(cloud), 400, replace=False)]
        t0 = time.perf_counter()
        d = np.array([r67.shape.distToShape(Part.Vertex(V(*p)))[0] for p in cloud])
        print("rotor67 cloud vs loft (%d points, %.0f s): median %.4f, p99 %.4f, max %.4f mm"
              % (len(d), time.perf_counter() - t0, np.median(d), np.percentile(d, 99), d.max()))
        r13 = make_rotor67_blade(ROTOR67_SECTIONS, sections=range(1, 14))
        d13 = np.array([r13.shape.distToShape(Part.Vertex(V(*p)))[0] for p in cloud[::10]])
        print("rotor67 sections 1..13 only (%d points): median %.4f, p99 %.3f, max %.3f mm"
              % (len(d13), np.median(d13), np.percentile(d13, 99), d13.max()))

    rng = np.random.default_rng(3)
    xyz, sec, ang = [], [], []
    for k, z in enumerate(np.linspace(5.0, 65.0, 7)):
        for side, base in (("suction", 0.0), ("pressure", 180.0)):
            srf = model.shape.Faces[model.roles[side][0]].Surface
            u = np.sort(rng.uniform(0.1, 0.9, 1500))
            pts = np.array([tuple(srf.value(x, z)) for x in u])
            nrm = np.array([tuple(srf.normal(x, z)) for x in u])
            xyz.append(pts + rng.uniform(-0.006, 0.006, len(u))[:, None] * nrm)
            sec += [k] * len(u)
            ang += [base + 4.0 * k] * len(u)
    ps = PointSet(xyz=np.vstack(xyz), columns={"section": np.array(sec, float),
                                               "angle_deg": np.array(ang)})
    recon, t = timed(reconstruct, ps)
    rms = [e["rms"] for e in recon.fit_errors]
    faces = [model.shape.Faces[model.roles[r][0]] for r in ("suction", "pressure")]
    probe = recon.samples[:: max(1, len(recon.samples) // 300)]
    d = np.array([min(f.distToShape(Part.Vertex(V(*p)))[0] for f in faces) for p in probe])
    print("reconstruct %d points, 7 sections x 2 sides, uniform +-6 um: %.2f s; fit RMS "
          "%.2f-%.2f um (noise RMS 3.46 um); lofted surfaces vs truth (sections 10 mm apart, "
          "%d samples): median %.2f, max %.2f um"
          % (len(ps.xyz), t, 1e3 * min(rms), 1e3 * max(rms), len(d), 1e3 * np.median(d),
             1e3 * d.max()))


if __name__ == "__main__":
    main("--quick" in sys.argv)
