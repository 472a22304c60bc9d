"""CPU of the airfoil stage (issue 15) as report/inspect run it, with and without its
uncertainty re-fits, on the demo blade:

- ``report``: `simulate`'s points registered as `report` does (sections from the section table);
- ``planned``: the CAD's section points at the planned scan's 0.1 mm spacing, sigma 3.5 um (as
  the closed loop's), registered at the identity (tests/test_airfoil_pipeline.py's set-up).

    scripts/fcpython bench/bench_airfoil_speed.py [POINTS.csv]

Prints the CPU seconds of run_stage for draws 0 and the default draws, of the kernel alone
(core.airfoil.characteristics on the five nominal cuts), and of one kernel run a measured
section (what every uncertainty re-fit repeats). BLAS is held to one thread (its
spinning threads double a CPU figure on a shared machine).
"""
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from BladeInspect.core import airfoil as kernel  # noqa: E402
from BladeInspect.inspection import airfoil as stage_mod  # noqa: E402
from BladeInspect.inspection import sections as sections_mod  # noqa: E402
from BladeInspect.inspection.pipeline import load_nominal, load_points, register  # noqa: E402

HEIGHTS = (10.0, 30.0, 50.0, 70.0, 90.0)


def stage_cpu(nominal, table, result, draws):
    t = time.process_time()
    stage = stage_mod.run_stage(nominal, stage_mod.planes_of_table(table),
                                stage_mod.Options(draws=draws), result, table.span_axis)
    return time.process_time() - t, stage


def report_case(nominal, points_path):
    result = register(nominal, load_points(points_path), seed=0)
    return sections_mod.section_table(result, nominal), result


def planned_case(nominal):
    from tests.test_airfoil_pipeline import _noisy, _result
    from BladeInspect.measurement.planning import nominal_section
    planes = stage_mod.nominal_planes(nominal, HEIGHTS)
    sections = [nominal_section(nominal, p.origin, p.normal, 0.1)[:2] for p in planes]
    xyz = np.vstack(_noisy(sections, 0.0035, 0))
    result = _result(nominal, xyz)
    return sections_mod.section_table(result, nominal, heights_pct=HEIGHTS, band=0.01), result


def main():
    nominal = load_nominal(None)
    from BladeInspect.cad.airfoil_sections import airfoil_section
    cuts = [airfoil_section(nominal.shape, p.origin, p.normal)[0]
            for p in stage_mod.nominal_planes(nominal, HEIGHTS)]
    t = time.process_time()
    for xy in cuts:
        kernel.characteristics(xy, le_upstream=getattr(stage_mod, "UPSTREAM_2D", (-1.0, 0.0)))
    print("kernel alone, five nominal cuts (%s points): %.2f s CPU"
          % ("/".join(str(len(c)) for c in cuts), time.process_time() - t))
    cases = [("planned (0.1 mm, sigma 3.5 um)", planned_case(nominal))]
    if len(sys.argv) > 1:
        cases.insert(0, ("report on %s" % sys.argv[1], report_case(nominal, sys.argv[1])))
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


if __name__ == "__main__":
    main()
