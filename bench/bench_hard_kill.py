"""`inspect` killed outright (SIGKILL) and resumed, through the command line, and what the pass
journal costs:

1. in process, `inspect --rig sim` on the demo blade twice: with the journal, and with its
   writes switched off (the journal's cost: one fsync'd append per pass);
2. `./bladeinspect simrig` + `./bladeinspect inspect --rig serial:PTY`, the inspect process
   killed with SIGKILL as the 2nd path of the 2nd planned section begins; what DIR holds;
3. `inspect --resume` on a new simrig: points.csv and pose against the in-process run's.

    scripts/fcpython bench/bench_hard_kill.py \
        [--seed S] [--heights 30,70] [--keep]
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, HERE)
CLI = os.path.join(HERE, "bladeinspect")

from bench.bench_inspect_resume import against_reference, read, start_simrig, stop  # noqa: E402


def in_process(out, seed, heights, journal=True):
    from BladeInspect.app.document import write_inspection_document
    from BladeInspect.inspection.closed_loop import run_inspect
    from BladeInspect.inspection.run_options import RunOptions
    from BladeInspect.inspection.pipeline import load_nominal
    from BladeInspect.measurement import journal as journal_mod
    from BladeInspect.rig.simulated import simulated_rig_for
    nominal = load_nominal(None)
    rig = simulated_rig_for(nominal, seed=seed)
    append = journal_mod.JournaledRig._append
    spent = [0.0]

    def timed_append(self, readings, rig_s):
        t0 = time.perf_counter()
        append(self, readings, rig_s)
        spent[0] += time.perf_counter() - t0
    journal_mod.JournaledRig._append = (timed_append if journal
                                        else lambda self, readings, rig_s: None)
    try:
        start = time.perf_counter()
        run_inspect(None, out, RunOptions.of(seed=seed, section_heights=heights), rig=rig,
                    nominal=nominal, document=write_inspection_document)
        return time.perf_counter() - start, rig.pass_index, spent[0]
    finally:
        journal_mod.JournaledRig._append = append


def killed_inspect(out, port, seed, heights):
    """Runs `inspect` and SIGKILLs it as the 2nd path of the 2nd planned section begins."""
    args = [CLI, "inspect", "--rig", "serial:" + port, "--out", out, "--seed", str(seed),
            "--section-heights", heights]
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    per_section = {}
    start = time.perf_counter()
    for line in proc.stderr:
        planned = re.search(r"planned scan: path \d+ of \d+ \(section (\S+) %", line)
        if planned:
            per_section[planned.group(1)] = per_section.get(planned.group(1), 0) + 1
            if len(per_section) == 2 and per_section[planned.group(1)] == 2:
                proc.send_signal(signal.SIGKILL)
                break
    status = proc.wait()
    return status, time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--heights", default="30,70")
    parser.add_argument("--keep", action="store_true", help="keep the output folders")
    args = parser.parse_args()
    heights = [float(h) for h in args.heights.split(",")]
    tmp = tempfile.mkdtemp(prefix="bench-hard-kill-")

    # Alternated, best of two each: the machine's load drifts.
    runs = {True: [], False: []}
    for k, journal in enumerate((False, True, False, True)):
        folder = os.path.join(tmp, "sim" if journal else "sim-no-journal-%d" % k)
        shutil.rmtree(folder, ignore_errors=True)
        runs[journal].append(in_process(folder, args.seed, heights, journal))
    with_journal = min(runs[True])
    passes = with_journal[1]
    print("in process, --rig sim (best of 2): %.1f s with the journal, %.1f s without; %d "
          "passes, %.1f ms per pass writing the journal (%.2f s in all)"
          % (with_journal[0], min(runs[False])[0], passes, 1e3 * with_journal[2] / passes,
             with_journal[2]))

    out = os.path.join(tmp, "killed")
    simrig, port = start_simrig(args.seed)
    status, seconds = killed_inspect(out, port, args.seed, args.heights)
    stop(simrig)
    live = os.path.join(out, ".checkpoint")
    state = json.loads(read(os.path.join(live, "scan.json")))["inspection"]
    from BladeInspect.measurement.journal import read_journal
    journal = read_journal(os.path.join(live, "readings.journal"))[0]
    rows = read(os.path.join(live, "points.csv")).count("\n") - 1
    print("inspect --rig serial, SIGKILL at the 2nd path of the 2nd planned section: exit %d "
          "after %.1f s" % (status, seconds))
    print("    DIR holds %s; %s: phase %s, sections done %s, %d rows, %d journal passes "
          "(%d readings) beyond them" % (sorted(os.listdir(out)), ".checkpoint",
                                         state["phase"], state["sections_done"], rows,
                                         len(journal), sum(e["k"] for e in journal)))

    simrig, port = start_simrig(args.seed)
    start = time.perf_counter()
    resumed = subprocess.run([CLI, "inspect", "--rig", "serial:" + port, "--out", out,
                              "--seed", str(args.seed), "--section-heights", args.heights,
                              "--resume"], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    stop(simrig)
    print("inspect --resume on a new simrig: exit %d, %.1f s" % (resumed.returncode, seconds))
    print("%s; %s left" % (against_reference(out, os.path.join(tmp, "sim")),
                           "a live folder" if os.path.exists(live) else "no live folder"))
    if args.keep:
        print("folders in %s" % tmp)
    else:
        shutil.rmtree(tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
