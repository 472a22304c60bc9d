"""CPU of the airfoil stage (issue 15) as report/inspect run it, with and without its
uncertainty re-fits, on the demo blade:

- ``report``: `simulate`'s points registered as `report` does (sections from the section table);
- ``planned``: the CAD's section points at the planned scan's 0.1 mm spacing, sigma 3.5 um (as
  the closed loop's), registered at the identity (tests/test_airfoil_pipeline.py's set-up).

    scripts/fcpython bench/bench_airfoil_speed.py [POINTS.csv] [--task-draws N] [--repeats N]
        [--figure-only]

Prints the CPU seconds of run_stage for draws 0 and the default draws, of the kernel alone
(core.airfoil.characteristics on the five nominal cuts), and of one kernel run a measured
section (what every uncertainty re-fit repeats). With the task-specific uncertainty
(inspection.airfoil_task) on the planned case: the first blade of the task making the task
file (``--task-draws``, default the product's 48), and a second blade of the same task (fresh
noise) reusing it -- the figure issue 15's "five sections in under 1 s" is about. BLAS is held
to one thread (core.blas_threads.limit_blas_threads, as the command line does: its spinning
threads double a CPU figure on a shared machine).

The figure: blade 2's run_stage (nominal and measured characteristics of the five sections and
their U from the task file) ``--repeats`` times (default 5), each beside a draws-0 run of the
same blade (interleaved), in CPU seconds of this process, with the nominal cuts' remembered
characteristics (inspection.airfoil_stage.nominal_characteristics) forgotten first, as in a
one-blade process (report, inspect), and for blade 3 with them remembered (a batch worker's
next blade; another blade, so that no foot of blade 2's points on a nominal profile serves
it); the last line states the medians, the range and the load average (os.getloadavg,
uptime's) before and after, and whether the medians are under 1 s. CPU seconds rise with the
machine's load (two shared cores: caches, memory bandwidth), so the load goes with the
figure. ``--figure-only`` skips the other figures and
makes the task file from 2 draws (blade 2 reuses only the draws' sigma: its cost does not
depend on how many draws made the file).
"""
import os
import sys
import tempfile
import time

import numpy as np

from BladeInspect.core import airfoil as kernel
from BladeInspect.core.blas_threads import limit_blas_threads
from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import sections as sections_mod
from BladeInspect.inspection.pipeline import load_nominal, load_points, register

HEIGHTS = (10.0, 30.0, 50.0, 70.0, 90.0)


def stage_cpu(nominal, table, result, draws, warm=False, **options):
    """CPU seconds of one run_stage; unless ``warm``, with no nominal cut remembered from an
    earlier run (a one-blade process)."""
    if not warm:
        stage_mod.clear_nominal_cache()
    t = time.process_time()
    stage = stage_mod.run_stage(nominal, stage_mod.planes_of_table(table),
                                stage_mod.Options(draws=draws, **options), result,
                                table.span_axis)
    return time.process_time() - t, stage


def report_case(nominal, points_path):
    result = register(nominal, load_points(points_path), seed=0)
    return sections_mod.section_table(result, nominal), result


def planned_case(nominal, seed=0):
    from tests.test_airfoil_pipeline import _noisy, _result
    from BladeInspect.measurement.planning import nominal_section
    planes = stage_mod.nominal_planes(nominal, HEIGHTS)
    sections = [nominal_section(nominal, p.origin, p.normal, 0.1)[:2] for p in planes]
    xyz = np.vstack(_noisy(sections, 0.0035, seed))
    result = _result(nominal, xyz)
    return sections_mod.section_table(result, nominal, heights_pct=HEIGHTS, band=0.01), result


def _load():
    return "/".join("%.2f" % x for x in os.getloadavg())


def task_case(nominal, draws, repeats=5):
    """The planned case's task file made on blade 1, then reused by blade 2 (fresh noise):
    ``repeats`` runs of blade 2, each beside a draws-0 run, and issue 15's figure."""
    folder = tempfile.mkdtemp(prefix="bench_task_u_")
    path = os.path.join(folder, "task.json")
    name = "planned, task-specific u"
    table, result = planned_case(nominal, seed=0)
    cpu, stage = stage_cpu(nominal, table, result, stage_mod.DEFAULT_DRAWS,
                           task_uncertainty=path, task_draws=draws)
    print("%s: blade 1 makes the task file (%d draws): %.2f s CPU for %d sections (%s)"
          % (name, draws, cpu, len(stage.blocks),
             "/".join(stage.settings["uncertainty_task"]["sections"].values())))
    table, result = planned_case(nominal, seed=1)
    # a batch worker's next blade is another blade: the nominal profiles' remembered feet of
    # blade 2's points must not serve it (they would, measuring blade 2 again)
    table3, result3 = planned_case(nominal, seed=2)
    load_before = _load()
    reused, bare, warm = [], [], []
    for repeat in range(repeats):
        # a one-blade process (report, inspect): no nominal cut remembered from blade 1
        cpu, stage = stage_cpu(nominal, table, result, stage_mod.DEFAULT_DRAWS,
                               task_uncertainty=path)
        how = "/".join(stage.settings["uncertainty_task"]["sections"].values())
        reused.append(cpu)
        print("%s: blade 2 reuses it: %.2f s CPU for %d sections (%s)"
              % (name, cpu, len(stage.blocks), how))
        cpu0, _ = stage_cpu(nominal, table, result, 0)
        bare.append(cpu0)
        print("%s: blade 2, draws 0 beside it: %.2f s CPU" % (name, cpu0))
        # a batch worker's next blade (blade 3): the nominal cuts' characteristics remembered
        cpu1, _ = stage_cpu(nominal, table3, result3, stage_mod.DEFAULT_DRAWS, warm=True,
                            task_uncertainty=path)
        warm.append(cpu1)
        print("%s: blade 3 reuses it, nominal cuts remembered (a batch worker's next blade): "
              "%.2f s CPU" % (name, cpu1))
    os.unlink(path)
    os.rmdir(folder)
    median = float(np.median(reused))
    print("issue 15 figure -- all characteristics of five sections with U (task file reused, "
          "blade 2, one blade per process as report/inspect): median %.2f s CPU of %d "
          "interleaved runs (%.2f-%.2f; draws 0 beside it: median %.2f; a batch worker's next "
          "blade, nominal cuts remembered: median %.2f); load average %s before, %s after; "
          "under 1 s: %s (batch worker: %s)"
          % (median, len(reused), min(reused), max(reused), float(np.median(bare)),
             float(np.median(warm)), load_before, _load(), "yes" if median < 1.0 else "no",
             "yes" if float(np.median(warm)) < 1.0 else "no"))


def main():
    limit_blas_threads()
    args = list(sys.argv[1:])
    task_draws, repeats = 48, 5
    figure_only = "--figure-only" in args
    if figure_only:
        args.remove("--figure-only")
        task_draws = 2
    if "--task-draws" in args:
        k = args.index("--task-draws")
        task_draws = int(args[k + 1])
        del args[k:k + 2]
    if "--repeats" in args:
        k = args.index("--repeats")
        repeats = int(args[k + 1])
        del args[k:k + 2]
    nominal = load_nominal(None)
    if figure_only:
        task_case(nominal, task_draws, repeats)
        return
    from BladeInspect.cad.airfoil_sections import airfoil_section
    cuts = [airfoil_section(nominal.shape, p.origin, p.normal)[0]
            for p in stage_mod.nominal_planes(nominal, HEIGHTS)]
    t = time.process_time()
    for xy in cuts:
        kernel.characteristics(xy, le_upstream=getattr(stage_mod, "UPSTREAM_2D", (-1.0, 0.0)))
    print("kernel alone, five nominal cuts (%s points): %.2f s CPU"
          % ("/".join(str(len(c)) for c in cuts), time.process_time() - t))
    cases = [("planned (0.1 mm, sigma 3.5 um)", planned_case(nominal))]
    if args:
        cases.insert(0, ("report on %s" % args[0], report_case(nominal, args[0])))
    for name, (table, result) in cases:
        for draws in (0, stage_mod.DEFAULT_DRAWS):
            cpu, stage = stage_cpu(nominal, table, result, draws)
            n = [b["measured"]["n_points"] if b.get("measured") else 0 for b in stage.blocks]
            print("%s: draws %2d: %.2f s CPU for %d sections (points %s)"
                  % (name, draws, cpu, len(n), "/".join(map(str, n))))
        # one kernel run on each measured section (what each of the 12 re-fits repeats)
        measured = [r for r in stage.sections if r.measured is not None]
        t = time.process_time()
        for r in measured:
            kernel.characteristics(r.points_2d, noise_mm=r.noise_mm, le_hint=r.nominal.le_point)
        print("%s: kernel on the %d measured sections: %.3f s CPU each"
              % (name, len(measured), (time.process_time() - t) / max(len(measured), 1)))
    task_case(nominal, task_draws, repeats)


if __name__ == "__main__":
    main()
