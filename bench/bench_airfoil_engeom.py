"""Side by side with engeom (PyPI, Rust with Python bindings), issue 15: the same sections
through core/airfoil.py and through engeom's AfGeometry.from_geometric_analysis, values against
the closed forms (tests/airfoil_shapes.py) and CPU time.

    scripts/fcpython bench/bench_airfoil_engeom.py [--no-cad]

engeom is not a dependency: it is installed into a throw-away venv (/tmp/engeom-venv, only if
not already there) and run there by bench/engeom_worker.py as a subprocess; the sections go
as .npy files, its figures come back as JSON. Sections: the double-circular-arc section (exact
circular edges), NACA 0012 and 0006 with circular tails, and (with FreeCAD, unless --no-cad)
the demo blade's cuts at 10/50/90 % span. engeom fits both edges as ``full_round`` (its
``auto`` picks "sharp" for the arc section's LE). Its metal angles are taken here from the
first/last segment of its camber polyline (engeom reports the camber line, not the angles).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from BladeInspect.core import airfoil  # noqa: E402
from tests.airfoil_shapes import ArcSection, NacaSection  # noqa: E402

VENV = "/tmp/engeom-venv"
WORKER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "engeom_worker.py")


def engeom_python():
    py = os.path.join(VENV, "bin", "python")
    if os.path.exists(py) and subprocess.run([py, "-c", "import engeom"],
                                             capture_output=True).returncode == 0:
        return py
    if not os.path.exists(py):
        subprocess.run([sys.executable, "-m", "venv", VENV], check=True)
    r = subprocess.run([os.path.join(VENV, "bin", "pip"), "install", "engeom", "numpy"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        errors = [l for l in r.stderr.splitlines() if "ERROR" in l] or r.stderr.splitlines()[-1:]
        sys.exit("engeom could not be installed: %s" % errors[0])
    return py


def angle_of(v):
    return float(np.degrees(np.arctan2(v[1], v[0])))


def adiff(a, b):
    return (a - b + 180.0) % 360.0 - 180.0


def closed_forms():
    """(name, points, truth dict) with truth the closed forms in the section's own frame."""
    out = []
    arc = ArcSection(x_le=-24.0, x_te=27.0)
    out.append(("double circular arc", arc.points(), {
        "chord": arc.chord(), "le_radius": arc.r_le, "te_radius": arc.r_te,
        "max_thickness": arc.max_thickness(), "inlet": angle_of(arc.inlet_dir()),
        "outlet": angle_of(arc.outlet_dir()), "le_point": arc.le_point(),
        "te_point": arc.te_point()}))
    for digits in ("0012", "0006"):
        sec = NacaSection(digits, c=60.0, x0=0.97)
        out.append(("NACA %s" % digits, sec.points(), {
            "chord": sec.chord(), "le_radius": None, "te_radius": sec.r_te,
            "max_thickness": sec.max_thickness(), "inlet": 0.0, "outlet": 0.0,
            "le_point": sec.to_world([0.0, 0.0])[0],
            "te_point": sec.to_world([sec.chord(), 0.0])[0]}))
    return out


def cad_sections():
    import FreeCAD  # noqa: F401
    from BladeInspect.cad.airfoil_sections import airfoil_section
    from BladeInspect.inspection.pipeline import load_nominal
    from BladeInspect.inspection.sections import span_axis_of
    nominal = load_nominal(None)
    span, (lo, hi) = span_axis_of(nominal)
    bb = nominal.shape.BoundBox
    centre = np.array([bb.Center.x, bb.Center.y, bb.Center.z])
    out = []
    for pct in (10, 50, 90):
        origin = centre + ((lo + pct / 100.0 * (hi - lo)) - centre @ span) * span
        xy, _ = airfoil_section(nominal.shape, origin, span)
        out.append(("demo blade %d %%" % pct, xy, None))
    return out


def ours(points):
    airfoil.characteristics(points)              # first-call set-up, not timed
    t0 = time.process_time()
    ch = airfoil.characteristics(points)
    cpu = time.process_time() - t0
    return ch, cpu


def theirs_figures(e):
    cam = np.array(e["camber"])
    le, te = np.array(e["le_point"]), np.array(e["te_point"])
    return {"chord": float(np.linalg.norm(te - le)), "le_radius": e["le_radius"],
            "te_radius": e["te_radius"], "max_thickness": e["max_thickness"],
            "inlet": angle_of(cam[1] - cam[0]), "outlet": angle_of(cam[-1] - cam[-2]),
            "le_point": le, "te_point": te}


def our_figures(ch):
    return {"chord": ch.nose_tail_chord_mm, "le_radius": ch.le_radius_mm,
            "te_radius": ch.te_radius_mm, "max_thickness": ch.max_thickness_mm,
            "inlet": ch.inlet_angle_deg, "outlet": ch.outlet_angle_deg,
            "le_point": ch.le_point, "te_point": ch.te_point}


def fmt(name, v, truth):
    if v is None:
        return "%-14s %s" % (name, "-")
    if name in ("inlet", "outlet"):
        s = "%10.5f deg" % v
        return s + ("  (%+.4f mdeg)" % (1e3 * adiff(v, truth)) if truth is not None else "")
    if name.endswith("point"):
        s = "(%.5f, %.5f)" % tuple(v)
        return s + ("  (%.4f um)" % (1e3 * np.linalg.norm(v - truth)) if truth is not None
                    else "")
    s = "%10.5f mm" % v
    return s + ("  (%+.4f um)" % (1e3 * (v - truth)) if truth is not None else "")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--no-cad", action="store_true")
    args = ap.parse_args()
    py = engeom_python()
    version = subprocess.run([py, "-c", "import importlib.metadata as m; "
                              "print(m.version('engeom'))"], capture_output=True,
                             text=True).stdout.strip()
    sections = closed_forms() + ([] if args.no_cad else cad_sections())
    tmp = tempfile.mkdtemp(prefix="engeom-bench-")
    job, mine = {}, {}
    for name, pts, _ in sections:
        ch, cpu = ours(pts)
        mine[name] = (ch, cpu)
        path = os.path.join(tmp, "%d.npy" % len(job))
        np.save(path, pts)
        # engeom's orientation from ours (LE end, suction side): only which end is which.
        normal = np.array([-ch.chord_dir[1], ch.chord_dir[0]])
        suction_mid = ch.profile.eval([0.5 * sum(ch.suction_range)])[0]
        upper = normal if (suction_mid - ch.le_point) @ normal > 0 else -normal
        job[name] = {"npy": path, "edge": "full_round", "fwd": (-ch.chord_dir).tolist(),
                     "upper": upper.tolist()}
    with open(os.path.join(tmp, "job.json"), "w") as f:
        json.dump(job, f)
    subprocess.run([py, WORKER, os.path.join(tmp, "job.json"), os.path.join(tmp, "out.json")],
                   check=True)
    theirs = json.load(open(os.path.join(tmp, "out.json")))
    print("engeom %s (venv %s) against BladeInspect core/airfoil.py; in brackets: minus the "
          "closed form" % (version, VENV))
    keys = ("chord", "le_point", "te_point", "le_radius", "te_radius", "max_thickness",
            "inlet", "outlet")
    worse = []
    for name, _, truth in sections:
        ch, cpu = mine[name]
        e = theirs[name]
        print("\n%s (%d points)" % (name, len(ch.profile.points)))
        if "error" in e:
            print("  engeom refused: %s" % e["error"])
            continue
        a, b = our_figures(ch), theirs_figures(e)
        print("  %-14s %-44s %s" % ("", "BladeInspect", "engeom (%s/%s edges)"
                                    % (e["le_kind"], e["te_kind"])))
        for k in keys:
            t = None if truth is None else truth[k]
            print("  %-14s %-44s %s" % (k, fmt(k, a[k], t), fmt(k, b[k], t)))
            if t is not None and a[k] is not None and b[k] is not None:
                ea = abs(adiff(a[k], t)) if k in ("inlet", "outlet") else np.linalg.norm(
                    np.asarray(a[k]) - t)
                eb = abs(adiff(b[k], t)) if k in ("inlet", "outlet") else np.linalg.norm(
                    np.asarray(b[k]) - t)
                if ea > eb:
                    worse.append("%s %s: ours %.3g, engeom %.3g" % (name, k, ea, eb))
        print("  %-14s %10.3f s CPU %24s %10.3f s CPU" % ("time", cpu, "", e["cpu_s"]))
    print("\nOn the closed forms BladeInspect is at least as close as engeom on every figure"
          if not worse else "\nCloser to the closed form in engeom: " + "; ".join(worse))


if __name__ == "__main__":
    main()
