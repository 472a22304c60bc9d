"""Stage times of the whole `register` command (load CAD, load points, coarse, fine, deviations,
write) at the paper's 269,158 points on three blades in one run (issue 14's speed target):

- the built-in demo blade;
- NASA Rotor 67 lofted from its section table (../shared/data/blades/nasa_rotor67);
- a third-party-like STEP: the demo blade's B-spline sides, run past hub and tip, cut by a
  hub that is a trimmed surface of revolution (a revolved arc) and a tip that is a trimmed
  cylinder about the same engine axis, written to STEP and read back (built here, not kept).

    scripts/fcpython bench/bench_register_stages.py [--points 269158] [--seed 14]
        [--only demo rotor67 step] [--repeat N]
        [--save FILE.npz] [--compare FILE.npz]

After the stage times: how many point evaluations the exact distance handed to OpenCASCADE
(over all its calls). ``--save`` keeps each blade's pose and deviations; ``--compare`` prints the largest pose
difference (mm at the CAD's bounding-box corners) and deviation difference against such a
file (a revision before a change against one after it). ``--converged`` (after the timed
run) iterates the fine ICP on every point from the returned pose until its steps are below
1e-7 mm and prints how far the returned pose (and, with ``--compare``, the file's) is from
that optimum in units of the pose's 1 sigma, and how far the written deviations are from an
exact evaluation at the returned pose.

Each stage is printed as wall seconds and, in brackets, the process's CPU seconds (all its
threads): on a shared machine the wall time measures the neighbours too, the CPU time less so.
"""
import argparse
import os
import shutil
import sys
import tempfile
import time

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.blas_threads import limit_blas_threads
from BladeInspect.core.pointio import write_points_csv
from BladeInspect.cad.nominal import Nominal
from BladeInspect.inspection import pipeline
from BladeInspect.inspection.simulate import simulate_measurement
from BladeInspect.inspection.run_options import RunOptions

HERE = os.path.dirname(os.path.abspath(__file__))
ROTOR67 = os.path.join(HERE, "..", "..", "shared", "data", "blades", "nasa_rotor67",
                       "rotor67geometry.dat")
PAPER_POINTS = 269158
# The third-party blade: engine axis along x, this far below the demo blade's hub (mm).
HUB_RADIUS = 120.0
# How far the sides run past the caps before they are cut (mm).
OVERRUN = 4.0


def write_revolved_cap_step(path):
    """The demo blade cut by a revolved hub and a cylindrical tip, as a STEP file."""
    import Part
    import FreeCAD
    from BladeInspect.cad.demo_blade import BladeParams, make_demo_blade

    span = BladeParams().span
    long_params = BladeParams(span=span + 2 * OVERRUN)
    blade = make_demo_blade(long_params).shape
    blade.translate(FreeCAD.Vector(0, 0, -OVERRUN))
    # The annulus between hub and tip in the (x, r) half-plane, revolved about the x axis
    # through (0, 0, -HUB_RADIUS): the hub line is an arc (a surface of revolution that is no
    # cylinder or cone), the tip a straight line (a cylinder).
    lo = blade.BoundBox
    x0, x1 = lo.XMin - 10.0, lo.XMax + 10.0
    axis_z = -HUB_RADIUS
    r_hub, r_tip = HUB_RADIUS, HUB_RADIUS + span
    sag = 1.5
    p = lambda x, r: FreeCAD.Vector(x, 0.0, axis_z + r)
    hub = Part.Arc(p(x0, r_hub), p(0.5 * (x0 + x1), r_hub - sag), p(x1, r_hub)).toShape()
    wire = Part.Wire([hub, Part.LineSegment(p(x1, r_hub), p(x1, r_tip)).toShape(),
                      Part.LineSegment(p(x1, r_tip), p(x0, r_tip)).toShape(),
                      Part.LineSegment(p(x0, r_tip), p(x0, r_hub)).toShape()])
    annulus = Part.Face(wire).revolve(FreeCAD.Vector(0, 0, axis_z), FreeCAD.Vector(1, 0, 0), 360)
    cut = blade.common(Part.Solid(annulus) if annulus.ShapeType != "Solid" else annulus)
    solids = cut.Solids
    if len(solids) != 1:
        raise RuntimeError("third-party blade: the cut gave %d solids" % len(solids))
    solids[0].exportStep(path)
    return path


class FallbackCount:
    """Counts the points the exact distance hands to OpenCASCADE (Nominal._occ_into) while
    it is installed."""

    def __init__(self):
        self.points = 0
        self.calls = 0

    def __enter__(self):
        self._occ_into = Nominal._occ_into
        count = self

        def counted(nominal, points, out, rows, solid_test=True):
            count.points += len(rows)
            count.calls += 1
            return count._occ_into(nominal, points, out, rows, solid_test)
        Nominal._occ_into = counted
        return self

    def __exit__(self, *exc):
        Nominal._occ_into = self._occ_into


class StageClock:
    """Stands in for the pipeline's ``time`` module: its perf_counter is the wall clock, and
    each reading also notes the process's CPU time, so that a stage the pipeline timed as
    ``perf_counter() - t0`` can be given its CPU seconds too (the pair of readings whose wall
    times differ by exactly that figure)."""

    def __init__(self):
        self.readings = []

    def __getattr__(self, name):
        return getattr(time, name)

    def perf_counter(self):
        wall = time.perf_counter()
        self.readings.append((wall, time.process_time()))
        return wall

    def cpu_seconds(self, wall_seconds):
        for j, (wall_j, cpu_j) in enumerate(self.readings):
            for wall_i, cpu_i in self.readings[:j]:
                if wall_j - wall_i == wall_seconds:
                    return cpu_j - cpu_i
        return float("nan")


def report_convergence(name, nominal, points_path, result, other_pose=None):
    """How far the returned pose is from the fine fit's optimum iterated to its tight default
    step tolerances on every point (and ``other_pose`` too), in units of the pose's 1 sigma,
    and the written deviations from an exact evaluation at the returned pose."""
    from BladeInspect.core import icp
    from BladeInspect.core.pointio import read_points
    ps = read_points(points_path)
    pose = result.measured_to_cad
    exact = nominal.signed_distance(tf.apply_transform(pose, ps.xyz)).distance
    optimum = icp.icp(ps.xyz, ps.snr, pipeline.TrackedDistance(nominal), pose,
                      icp.ICPOptions(horn_iters=0, uncertainty_fraction=0.0, max_iter=10))
    sigma = result.pose_uncertainty_statistical_mm
    corners = nominal.bbox_corners
    line = ("%-17s converged in %d more steps: the returned pose is %.2g sigma from it (sigma "
            "%.3g mm)" % (name, optimum.iterations, tf.corner_displacement(
                pose, optimum.transform, corners) / sigma, sigma))
    if other_pose is not None:
        line += ", the compared file's %.2g sigma" % (
            tf.corner_displacement(other_pose, optimum.transform, corners) / sigma)
    print(line + "; deviations at most %.3g mm from an exact evaluation at the returned pose"
          % float(np.max(np.abs(exact - result.deviation))), flush=True)


def blades(tmp, only=None):
    """(name, CAD path or None) of the blades to time; ``only``: a subset of demo, rotor67,
    step."""
    only = set(only or ("demo", "rotor67", "step"))
    out = [("demo blade", None)] if "demo" in only else []
    if "rotor67" in only:
        if os.path.exists(ROTOR67):
            out.append(("Rotor 67", ROTOR67))
        else:
            print("Rotor 67 skipped: %s not found" % ROTOR67)
    if "step" in only:
        out.append(("third-party STEP",
                    write_revolved_cap_step(os.path.join(tmp, "blade.step"))))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=PAPER_POINTS)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--save")
    ap.add_argument("--compare")
    ap.add_argument("--converged", action="store_true")
    ap.add_argument("--only", nargs="+", choices=("demo", "rotor67", "step"),
                    help="time these blades only (default: all three)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="register each blade this many times (the stage times of each run)")
    args = ap.parse_args(argv)
    limited = limit_blas_threads()   # as the CLI does (core.blas_threads)
    print("BLAS threads limited to 1 in %s" % (", ".join(limited) or "no library"))
    print("load average %.2f %.2f %.2f on %d cores" % (os.getloadavg() + (os.cpu_count(),)))
    tmp = tempfile.mkdtemp(prefix="bench-stages-")
    saved, reference = {}, (dict(np.load(args.compare)) if args.compare else None)
    try:
        for k, (name, cad) in enumerate(blades(tmp, args.only)):
            nominal = pipeline.load_nominal(cad)
            if cad is not None and cad.endswith(".step"):
                kinds = sorted({type(f.Surface).__name__ for f in
                                __import__("Part").read(cad).Faces})
                print("%s: faces %s" % (name, ", ".join(kinds)))
            ps, _, _, _ = simulate_measurement(nominal, n_points=args.points, section_heights=(),
                                               outlier_fraction=0.02, seed=args.seed)
            points = os.path.join(tmp, "points%d.csv" % k)
            write_points_csv(points, ps.xyz, {"snr": ps.snr})
            for run in range(args.repeat):
                out = os.path.join(tmp, "out%d-%d" % (k, run))
                clock = StageClock()
                pipeline.time = clock
                try:
                    with FallbackCount() as fallback:
                        t0, c0 = time.perf_counter(), time.process_time()
                        result = pipeline.run_register(cad, points, out,
                                                       RunOptions.of(seed=args.seed))
                        total, total_cpu = time.perf_counter() - t0, time.process_time() - c0
                finally:
                    pipeline.time = time
                print("%-17s %d points: register %.2f s [cpu %.2f] (%s); OCC fallback %d "
                      "points in %d calls"
                      % (name, len(ps.xyz), total, total_cpu,
                         ", ".join("%s %.2f [%.2f]" % (k, v, clock.cpu_seconds(v))
                                   for k, v in result.timing_s.items()),
                         fallback.points, fallback.calls), flush=True)
            key = "b%d" % k
            saved[key + "_pose"] = result.measured_to_cad
            saved[key + "_dev"] = result.deviation
            saved[key + "_corners"] = nominal.bbox_corners
            if reference is not None and key + "_pose" in reference:
                pose_diff = tf.corner_displacement(result.measured_to_cad,
                                                   reference[key + "_pose"],
                                                   nominal.bbox_corners)
                dev = reference[key + "_dev"]
                dev_diff = (float(np.max(np.abs(result.deviation - dev)))
                            if dev.shape == result.deviation.shape else float("nan"))
                print("%-17s against %s: pose differs by %.3g mm at the worst corner, "
                      "deviations by at most %.3g mm" % (name, args.compare, pose_diff, dev_diff))
            if args.converged:
                report_convergence(name, nominal, points, result,
                                   None if reference is None else reference.get(key + "_pose"))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if args.save:
        np.savez(args.save, **saved)
    return 0


if __name__ == "__main__":
    sys.exit(main())
