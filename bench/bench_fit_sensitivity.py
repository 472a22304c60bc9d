"""The fit-sensitivity table (inspection.fitting.sensitivity) on the demo blade's CAD-planned
scan: time of each fit objective from the ICP pose, of judging every objective's deviations,
of re-measuring the airfoil characteristics under every objective (their rows of the table,
inspection.airfoil_verdicts.add_to_sensitivity), and of the whole table, with the table itself.

    scripts/fcpython bench/bench_fit_sensitivity.py [--trials 3] [--seed 0]

The inspection (blind scan, registration, CAD-planned scan) runs once on the simulated rig;
its result at the least-squares ICP pose is then copied for each trial, so every trial times
the same work: the three fits, the section table's verdict under each, the table.
"""
import argparse
import dataclasses
import tempfile
import time

import numpy as np

from BladeInspect.inspection import airfoil_stage as airfoil, fitting
from BladeInspect.inspection.closed_loop import run_inspect
from BladeInspect.inspection.pipeline import load_nominal
from BladeInspect.inspection.run_options import RunOptions


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    nominal = load_nominal(None)
    with tempfile.TemporaryDirectory() as out:
        summary = run_inspect(None, out + "/inspect",
                              RunOptions.of(seed=args.seed, airfoil=airfoil.Options()),
                              document=False, nominal=nominal)
    result, table = summary["result"], summary["sections"]
    tolerance = summary["verdict"]["tolerance_mm"]
    print("demo blade, planned scan: %d points (%d inliers), %d sections, tolerance +-%.3f mm"
          % (result.n_points, result.n_inliers, len(table.sections), tolerance))
    choice = fitting.FitChoice()
    totals = []
    for trial in range(args.trials):
        copy = dataclasses.replace(result)
        t0 = time.perf_counter()
        runs = fitting.apply(copy, nominal, choice, tolerance, all_objectives=True)
        doc = fitting.sensitivity(runs, copy, table, tolerance, choice)
        t1 = time.perf_counter()
        airfoil.add_to_sensitivity(doc, table.airfoil, copy, airfoil.Options())
        totals.append(time.perf_counter() - t0)
        print("trial %d: %s, airfoil rows %.2f s; whole table %.2f s" % (trial + 1, ", ".join(
            "%s %.2f s" % kv for kv in doc["timing_s"].items()), time.perf_counter() - t1,
            totals[-1]))
    print("whole fit-sensitivity table: median %.2f s, max %.2f s over %d trials (budget 5 s)"
          % (np.median(totals), max(totals), len(totals)))
    header, rows = fitting.report_rows(doc)
    print(" | ".join(header))
    for row in rows:
        print(" | ".join(row))
    print("%d rows, of which %d airfoil characteristics" % (
        len(doc["rows"]), sum(bool(r.get("airfoil")) for r in doc["rows"])))
    print("largest change: %s, %.4f mm" % (doc["largest_change"]["characteristic"],
                                          doc["largest_change"]["change_mm"]))


if __name__ == "__main__":
    main()
