"""`inspect` through the serial driver, interrupted and resumed, all through the command line:

1. `./bladeinspect inspect --rig sim` in process (the reference);
2. `./bladeinspect simrig` serving the same rig on a pty, `inspect --rig serial:PTY` run whole;
3. the same, with the simrig process killed (its pty vanishes) at the 2nd path of the 2nd
   planned section, then a new simrig and `inspect --resume` into the same folder.

Prints the times, what the interrupted folder holds, and whether points.csv and the pose of
2 and 3 equal the reference's.

    scripts/fcpython bench/bench_inspect_resume.py \
        [--seed S] [--heights 30,70] [--keep]
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLI = os.path.join(HERE, "bladeinspect")


def start_simrig(seed):
    """A `./bladeinspect simrig` process and the port it serves."""
    proc = subprocess.Popen([CLI, "simrig", "--seed", str(seed)], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    for line in proc.stdout:
        found = re.search(r" on (\S+)$", line.strip())
        if found:
            return proc, found.group(1)
    raise SystemExit("simrig did not print its port")


def stop(proc):
    proc.terminate()
    proc.wait(timeout=10)


def inspect(out, rig, seed, heights, resume=False, kill=None):
    """Runs `inspect`; with ``kill`` (a process), kills it as the 2nd path of the 2nd planned
    section begins. Returns (exit status, seconds, error lines)."""
    args = [CLI, "inspect", "--rig", rig, "--out", out, "--seed", str(seed),
            "--section-heights", heights] + (["--resume"] if resume else [])
    start = time.perf_counter()
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    errors = []
    paths_per_section = {}
    for line in proc.stderr:
        if "error" in line:
            errors.append(line.strip())
        planned = re.search(r"planned scan: path \d+ of \d+ \(section (\S+) %", line)
        if kill is not None and planned:
            height = planned.group(1)
            paths_per_section[height] = paths_per_section.get(height, 0) + 1
            if len(paths_per_section) == 2 and paths_per_section[height] == 2:
                kill.kill()
                kill.wait()
                kill = None
    status = proc.wait()
    return status, time.perf_counter() - start, errors


def read(path):
    with open(path) as fh:
        return fh.read()


def pose(folder):
    return np.asarray(json.loads(read(os.path.join(folder, "result.json")))["measured_to_cad"])


def against_reference(folder, reference):
    """'points.csv IDENTICAL to|DIFFERS from the in-process run's (N rows); pose differs by X'"""
    expected = read(os.path.join(reference, "points.csv"))
    same = read(os.path.join(folder, "points.csv")) == expected
    return ("points.csv %s the in-process run's (%d rows); pose differs by %.1e"
            % ("IDENTICAL to" if same else "DIFFERS from", expected.count("\n") - 1,
               np.max(np.abs(pose(folder) - pose(reference)))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--heights", default="30,70")
    parser.add_argument("--keep", action="store_true", help="keep the output folders")
    args = parser.parse_args()
    tmp = tempfile.mkdtemp(prefix="bench-inspect-resume-")
    folders = {k: os.path.join(tmp, k) for k in ("sim", "serial", "resumed")}

    status, seconds, errors = inspect(folders["sim"], "sim", args.seed, args.heights)
    print("inspect --rig sim:                 exit %d, %.1f s %s" % (status, seconds, errors))

    simrig, port = start_simrig(args.seed)
    status, seconds, errors = inspect(folders["serial"], "serial:" + port, args.seed,
                                      args.heights)
    stop(simrig)
    print("inspect --rig serial (whole):      exit %d, %.1f s %s" % (status, seconds, errors))

    simrig, port = start_simrig(args.seed)
    status, seconds, errors = inspect(folders["resumed"], "serial:" + port, args.seed,
                                      args.heights, kill=simrig)
    print("inspect --rig serial, simrig killed in the 2nd planned section: exit %d, %.1f s"
          % (status, seconds))
    for line in errors:
        print("    " + line)
    kept = sorted(os.listdir(folders["resumed"]))
    state = json.loads(read(os.path.join(folders["resumed"], "scan.json")))["inspection"]
    n_rows = read(os.path.join(folders["resumed"], "points.csv")).count("\n") - 1
    print("    kept: %s; phase %s, attempt %d, sections done %s, %d rows"
          % (", ".join(kept), state["phase"], state["attempt"], state["sections_done"], n_rows))

    simrig, port = start_simrig(args.seed)
    status, seconds, errors = inspect(folders["resumed"], "serial:" + port, args.seed,
                                      args.heights, resume=True)
    stop(simrig)
    print("inspect --resume on a new simrig:  exit %d, %.1f s %s" % (status, seconds, errors))

    for name in ("serial", "resumed"):
        if not os.path.exists(os.path.join(folders[name], "result.json")):
            print("%s: no result" % name)
            continue
        print("%-8s %s" % (name, against_reference(folders[name], folders["sim"])))
    if args.keep:
        print("folders in %s" % tmp)
    else:
        shutil.rmtree(tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
