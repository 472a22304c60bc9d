"""Inputs that gave a traceback, a hang or garbage (issue 13, item 3), through the real
command line: exit status, seconds, and the one line each ends with; then the surface-fit
rule's margin, the fraction of points within its distance, on right and wrong scans.

    scripts/fcpython bench/bench_bad_inputs.py [DIR]
"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import FreeCAD  # noqa: F401  (before Part)
from BladeInspect.cad.demo_blade import BladeParams, make_demo_blade
from BladeInspect.cad.nominal import nominal_from_shape
from BladeInspect.core.pointio import PointSet, write_points_csv
from BladeInspect.inspection import pipeline
from BladeInspect.inspection.simulate import simulate_measurement

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROTOR67 = os.path.join(REPO, "..", "shared", "data", "blades", "nasa_rotor67")
OTHER_BLADES = (dict(twist_deg=40.0, camber_root=0.11, chord_root=46.0),
                dict(twist_deg=15.0, thickness_root=0.09, sweep=6.0),
                dict(chord_root=47.0, chord_tip=40.0))


def cli(*args):
    t0 = time.perf_counter()
    proc = subprocess.run([os.path.join(REPO, "bladeinspect")] + list(args), cwd=REPO,
                          capture_output=True, text=True)
    last = [l for l in proc.stderr.splitlines() + proc.stdout.splitlines()
            if l.startswith("bladeinspect: error:") or "Traceback" in l or "Error" in l]
    return proc.returncode, time.perf_counter() - t0, (last or ["(no error line)"])[0]


def main(folder):
    cad = os.path.join(folder, "blade.step")
    make_demo_blade().shape.exportStep(cad)
    nominal = pipeline.load_nominal(None)
    scan, _, _, _ = simulate_measurement(nominal, n_points=3000, seed=7, outlier_fraction=0.02)
    good = os.path.join(folder, "scan.csv")
    write_points_csv(good, scan.xyz, {"snr": scan.snr})
    rows = open(good).read().splitlines()
    files = {}

    def put(name, xyz=None, text=None):
        path = os.path.join(folder, name)
        if text is not None:
            with open(path, "w") as fh:
                fh.write(text)
        else:
            write_points_csv(path, xyz)
        files[name] = path

    put("huge_row.csv", text="\n".join(rows[:5] + ["1e300,1,2,50"] + rows[5:]) + "\n")
    put("inf_row.csv", text="\n".join(rows[:5] + ["inf,1,2,50"] + rows[5:]) + "\n")
    put("metres.csv", scan.xyz / 1000.0)
    put("one_point.csv", np.tile([[1.0, 2.0, 3.0]], (500, 1)))
    t = np.linspace(0.0, 50.0, 500)[:, None]
    put("line.csv", np.hstack([t, 2 * t + 1, -t]))
    other_nominal = nominal_from_shape(make_demo_blade(BladeParams(**OTHER_BLADES[0])).shape)
    other, _, _, _ = simulate_measurement(other_nominal, n_points=3000, seed=3,
                                          outlier_fraction=0.02)
    put("other_blade.csv", other.xyz)
    print("| input | exit | s | message |\n|---|---|---|---|")
    for name, path in files.items():
        code, seconds, line = cli("register", "--cad", cad, "--points", path,
                                  "--out", os.path.join(folder, "out-" + name))
        print("| %s | %d | %.1f | %s |" % (name, code, seconds, line))
    taken = os.path.join(folder, "taken.txt")
    open(taken, "w").close()
    code, seconds, line = cli("register", "--cad", cad, "--points", good, "--out", taken)
    print("| --out is a file | %d | %.1f | %s |" % (code, seconds, line))

    print("\nsurface-fit rule: fraction of points within the fit distance after registration")
    cases = [("demo blade, its own scan", nominal, scan)]
    for params in OTHER_BLADES:
        other_nominal = nominal_from_shape(make_demo_blade(BladeParams(**params)).shape)
        other, _, _, _ = simulate_measurement(other_nominal, n_points=3000, seed=3,
                                              outlier_fraction=0.02)
        cases.append(("demo CAD, blade with " + ", ".join("%s=%g" % kv for kv in params.items()),
                      nominal, other))
    if os.path.exists(ROTOR67):
        r67 = pipeline.load_nominal(os.path.join(ROTOR67, "rotor67geometry.dat"))
        cloud = np.loadtxt(os.path.join(ROTOR67, "MoveSurface_NASA_R67_parablade.txt"))
        cases.append(("Rotor 67 CAD, its independent CFD cloud", r67,
                      PointSet(xyz=cloud[:, 1:4] * 1000.0, source="r67 cloud")))
    for label, nom, points in cases:
        result = pipeline.register(nom, points, allow_mismatch=True)
        fit = result.surface_fit
        print("  %-62s %.3f within %.3f mm (needs %.2f) -> %s"
              % (label, fit["fraction_within"], fit["distance_mm"], fit["min_fraction"],
                 "fits" if fit["fits"] else "refused"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="bench-bad-"))
