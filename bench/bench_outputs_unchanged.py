"""Every CLI command on the demo blade, run by two checkouts, and their outputs compared: a
refactoring must leave them identical (issue 14, "What must hold").

    /usr/bin/python3 bench/bench_outputs_unchanged.py REFERENCE_CHECKOUT [CHECKOUT] [--quick]

REFERENCE_CHECKOUT is e.g. ``git worktree add /tmp/ref <commit>``; CHECKOUT defaults to this
one. Both get the same inputs (the demo blade as STEP, the same point files) and write into
folders of the same names, so paths inside the outputs differ only by their root.

Compared: every CSV numerically (points, deviations, summaries), every JSON value (the pose
and all other numbers within 1e-12 of the value's size, in mm for lengths), the report's
tables (the HTML <table>s, text exact), the set of files written, and stdout's result lines.
Not compared: stage times (timing_s, the wall clock), the PDF's bytes (its creation date) and
the FCStd's bytes (its save date; it is compared as the list of files it holds). ``simrig``
serves a pseudo-terminal and writes nothing; it is not run. --quick leaves out demo and
inspect --complete (the two slowest). Prints one line per command and the differences; exit
status 1 if any.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOLERANCE = 1e-12
# Wall-clock figures, different on every run of the same code.
IGNORED_KEYS = {"timing_s", "simulated_s", "wall_s", "elapsed_s", "created", "date", "made_utc"}


def commands(quick):
    """(name, argv after the command name); paths relative to the run's folder."""
    runs = [
        ("simulate", ["simulate", "--out", "sim", "--points", "3000", "--seed", "3"]),
        ("register", ["register", "--cad", "../blade.step", "--points", "sim/points.csv",
                      "--out", "reg", "--seed", "1"]),
        ("report", ["report", "--cad", "../blade.step", "--points", "sim/points.csv",
                    "--out", "rep", "--tolerance", "0.05"]),
        ("batch", ["batch", "--cad", "../blade.step", "--scans", "../lot", "--out", "lot",
                   "--workers", "1"]),
        ("scan", ["scan", "--out", "scan", "--sections", "2", "--seed", "5"]),
        ("calibrate", ["calibrate", "--out", "rig.json", "--seed", "2"]),
        ("inspect", ["inspect", "--out", "insp", "--seed", "4"]),
        ("airfoil nominal", ["airfoil", "--out", "af_nominal", "--cad", "../blade.step",
                             "--chord-method", "caliper", "--engine-axis", "z"]),
        # The first writes the task's draws, the second reads them back.
        ("airfoil", ["airfoil", "--out", "af", "--cad", "../blade.step", "--points",
                     "sim/points.csv", "--uncertainty-task", "task.json", "--chord-method",
                     "tangent", "--le-rule", "larger-radius", "--edge-offsets", "0.3,1"]),
        ("airfoil again", ["airfoil", "--out", "af_again", "--cad", "../blade.step",
                           "--points", "sim/points.csv", "--uncertainty-task", "task.json",
                           "--chord-method", "tangent", "--le-rule", "larger-radius",
                           "--edge-offsets", "0.3,1"]),
    ]
    if not quick:
        runs += [("inspect --complete", ["inspect", "--out", "insp_complete", "--complete",
                                         "--pitch", "1.0", "--seed", "6"]),
                 ("demo", ["demo", "--out", "demo"])]
    return runs


def prepare_inputs(work):
    """The demo blade as STEP and a lot of two point files, made once for both checkouts."""
    code = ("import sys; sys.path.insert(0, %r)\n"
            "from BladeInspect import freecad_library; freecad_library.import_freecad()\n"
            "import numpy as np\n"
            "from BladeInspect.cad.demo_blade import make_demo_blade\n"
            "from BladeInspect.inspection.pipeline import load_nominal\n"
            "from BladeInspect.core import transforms as tf\n"
            "make_demo_blade().shape.exportStep(%r)\n"
            "nominal = load_nominal(None)\n"
            "rng = np.random.default_rng(7)\n"
            "for k in range(2):\n"
            "    pick = rng.choice(len(nominal.samples.xyz), 2500, replace=False)\n"
            "    xyz = nominal.samples.xyz[pick] + rng.normal(0, 0.002, (2500, 3))\n"
            "    xyz = tf.apply_transform(tf.random_transform(rng, 20.0), xyz)\n"
            "    np.savetxt(%r %% k, xyz, delimiter=',', header='x,y,z', comments='',\n"
            "               fmt='%%.9f')\n"
            % (HERE, os.path.join(work, "blade.step"), os.path.join(work, "lot", "blade%d.csv")))
    os.makedirs(os.path.join(work, "lot"))
    subprocess.run(["/usr/bin/python3", "-c", code], check=True)


def run_all(checkout, folder, quick):
    os.makedirs(folder)
    stdout, seconds = {}, {}
    for name, argv in commands(quick):
        t0 = time.perf_counter()
        proc = subprocess.run([os.path.join(checkout, "bladeinspect")] + argv, cwd=folder,
                              capture_output=True, text=True)
        seconds[name] = time.perf_counter() - t0
        if proc.returncode != 0:
            raise SystemExit("%s: `%s` failed (%d): %s" % (checkout, " ".join(argv),
                                                          proc.returncode, proc.stderr[-2000:]))
        stdout[name] = proc.stdout
    return stdout, seconds


def _number(text):
    try:
        return float(text)
    except ValueError:
        return None


def _close(a, b):
    return abs(a - b) <= TOLERANCE * max(1.0, abs(a), abs(b)) or (a != a and b != b)


# a UTC time stamp quoted inside a text (an uncertainty task's creation time)
STAMP = re.compile(r"\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}Z")


def _text(text, root):
    return STAMP.sub("<TIME>", text.replace(root, "<ROOT>"))


def compare_values(a, b, where, diffs, roots):
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            diffs.append("%s: keys %s" % (where, sorted(set(a) ^ set(b))))
        for k in sorted(set(a) & set(b)):
            if k not in IGNORED_KEYS:
                compare_values(a[k], b[k], "%s.%s" % (where, k), diffs, roots)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            diffs.append("%s: %d items, not %d" % (where, len(b), len(a)))
        for i, (x, y) in enumerate(zip(a, b)):
            compare_values(x, y, "%s[%d]" % (where, i), diffs, roots)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and \
            not isinstance(a, bool) and not isinstance(b, bool):
        if not _close(float(a), float(b)):
            diffs.append("%s: %r, not %r" % (where, b, a))
    elif isinstance(a, str) and isinstance(b, str):
        if _text(a, roots[0]) != _text(b, roots[1]):
            diffs.append("%s: %r, not %r" % (where, b[:80], a[:80]))
    elif a != b:
        diffs.append("%s: %r, not %r" % (where, b, a))


def compare_csv(pa, pb, where, diffs, roots):
    with open(pa, newline="") as fa, open(pb, newline="") as fb:
        ra, rb = list(csv.reader(fa)), list(csv.reader(fb))
    if len(ra) != len(rb):
        diffs.append("%s: %d rows, not %d" % (where, len(rb), len(ra)))
        return
    header = ra[0] if ra else []
    skip = {i for i, h in enumerate(header) if h in IGNORED_KEYS}
    for n, (x, y) in enumerate(zip(ra, rb)):
        if len(x) != len(y):
            diffs.append("%s row %d: %d fields, not %d" % (where, n, len(y), len(x)))
            continue
        for i, (u, v) in enumerate(zip(x, y)):
            if i in skip:
                continue
            fu, fv = _number(u), _number(v)
            same = _close(fu, fv) if fu is not None and fv is not None else \
                u.replace(roots[0], "<ROOT>") == v.replace(roots[1], "<ROOT>")
            if not same:
                diffs.append("%s row %d col %s: %r, not %r" % (
                    where, n, header[i] if i < len(header) else i, v, u))
                if len(diffs) > 50:
                    return


def html_tables(path):
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    return re.findall(r"<table.*?</table>", text, flags=re.S)


def compare_trees(a, b, roots):
    diffs = []
    files_a = sorted(os.path.relpath(os.path.join(d, f), a) for d, _, fs in os.walk(a)
                     for f in fs)
    files_b = sorted(os.path.relpath(os.path.join(d, f), b) for d, _, fs in os.walk(b)
                     for f in fs)
    if files_a != files_b:
        diffs.append("files: only in reference %s; only in checkout %s"
                     % (sorted(set(files_a) - set(files_b)), sorted(set(files_b) - set(files_a))))
    counted = {"csv": 0, "json": 0, "html": 0, "fcstd": 0}
    for rel in sorted(set(files_a) & set(files_b)):
        pa, pb = os.path.join(a, rel), os.path.join(b, rel)
        ext = rel.rsplit(".", 1)[-1].lower()
        if ext == "csv":
            compare_csv(pa, pb, rel, diffs, roots)
        elif ext == "json":
            with open(pa) as fa, open(pb) as fb:
                compare_values(json.load(fa), json.load(fb), rel, diffs, roots)
        elif ext == "html":
            ta, tb = html_tables(pa), html_tables(pb)
            if [t.replace(roots[0], "<ROOT>") for t in ta] != \
                    [t.replace(roots[1], "<ROOT>") for t in tb]:
                diffs.append("%s: the report's tables differ" % rel)
        elif ext == "fcstd":
            with zipfile.ZipFile(pa) as za, zipfile.ZipFile(pb) as zb:
                if sorted(za.namelist()) != sorted(zb.namelist()):
                    diffs.append("%s: holds other files" % rel)
        else:
            continue
        counted[ext] += 1
    return diffs, counted, len(files_a)


def main(argv):
    quick = "--quick" in argv
    args = [a for a in argv if a != "--quick"]
    if not args:
        raise SystemExit(__doc__)
    reference = os.path.abspath(args[0])
    checkout = os.path.abspath(args[1]) if len(args) > 1 else HERE
    work = tempfile.mkdtemp(prefix="bi-outputs-")
    try:
        prepare_inputs(work)
        roots = (os.path.join(work, "ref"), os.path.join(work, "new"))
        out_ref, t_ref = run_all(reference, roots[0], quick)
        out_new, t_new = run_all(checkout, roots[1], quick)
        diffs, counted, n_files = compare_trees(roots[0], roots[1], roots)
        for name, _ in commands(quick):
            lines_a = [l for l in out_ref[name].replace(roots[0], "<ROOT>").splitlines()
                       if not re.search(r"\d+(\.\d+)? s\b", l)]
            lines_b = [l for l in out_new[name].replace(roots[1], "<ROOT>").splitlines()
                       if not re.search(r"\d+(\.\d+)? s\b", l)]
            if lines_a != lines_b:
                diffs.append("%s: stdout differs" % name)
            print("%-20s reference %6.1f s, checkout %6.1f s" % (name, t_ref[name], t_new[name]))
        print("reference %s\ncheckout  %s" % (reference, checkout))
        print("%d files compared (%d CSV, %d JSON, %d HTML, %d FCStd); %d difference(s)"
              % (n_files, counted["csv"], counted["json"], counted["html"], counted["fcstd"],
                 len(diffs)))
        for d in diffs[:60]:
            print("  " + d)
        return 1 if diffs else 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
