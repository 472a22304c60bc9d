"""The noisy profile fit's systematic error at the rig's own noise: each characteristic of the
whole-chain Monte Carlo's planned sections (bench_uncertainty_mc.py's recorded scan, the sensor's
noise only: no reading bias, no calibration error) against the noise-free chain's, over repeated
scans: the mean error, its t-value (mean over its standard error) and the 1 sigma scatter, and
the u (k = 1) the stage states for one more scan of the whole model (noise, the sensor's
accuracy, the pose, the rig calibration: what a user is shown).

A fit whose mean error is many standard errors from zero reads every part of that section
off by that much, scan after scan; the stated U (docs/fits.md) covers it only while it stays
inside U.

``--variant``: ``nominal-knots`` is the stage's fit (core.airfoil._knots_from_nominal: the
knots the nominal's shape wants, joined with the smoothing spline's, least squares on them);
``smoothing`` is FITPACK's smoothing spline alone -- the stage's fit before 2026-12-05, and
still the fit of a profile measured without its nominal or whose points do not thin out in
runs (docs/airfoil.md, "Where the points thin out"). The stated u is the stage's either way.

    scripts/fcpython bench/bench_airfoil_fit_bias.py [--blade demo|rotor67] [--scans 24]
        [--seed 100] [--draws 12] [--variant nominal-knots|smoothing]
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_uncertainty_mc as mc  # noqa: E402
from BladeInspect.core import airfoil as kernel  # noqa: E402

SCALARS = ("axial_chord_mm", "max_thickness_mm", "max_thickness_pos_pct", "le_radius_mm",
           "te_radius_mm", "inlet_angle_deg", "outlet_angle_deg")


def scans(blade, seed, count, draws):
    """The noise-free chain's section points, ``count`` noisy scans' (points, noise) per
    section, each section's nominal Characteristics, and the stage's stated u of each section
    (its uncertainty block) on one more scan, ``draws`` re-fits."""
    chain = mc.Chain(blade, 2026, 31)
    exact = chain.stage_sections(np.random.default_rng(seed), errors=())
    noisy = [[(sr.points_2d, sr.noise_mm) for sr in chain.stage_sections(
        np.random.default_rng(seed + 1 + k), errors=("noise",), bias_mm=0.0)]
        for k in range(count)]
    stated = [sr.block["uncertainty"] for sr in chain.stage_sections(
        np.random.default_rng(seed + 1 + count), draws=draws)]
    return [sr.points_2d for sr in exact], noisy, [sr.nominal for sr in exact], stated


def values(points, noise, nominal, variant):
    profile = kernel.Profile(kernel.order_by_nominal(points, nominal.profile), noise,
                             nominal=nominal.profile if variant == "nominal-knots" else None)
    ch = kernel.characteristics(profile, noise_mm=noise)
    row = {name: getattr(ch, name) for name in SCALARS}
    for side in ("le", "te"):
        for i, x in enumerate(getattr(ch, side + "_thickness_mm")):
            row["%s_thickness_mm[%d]" % (side, i)] = x
    return row, len(profile._tck[0]) - 7


def stated_u(block, name):
    """A characteristic's u (k = 1) from a result.json uncertainty block; NaN if not stated."""
    if "[" in name:
        base, i = name[:-1].split("[")
        values = block.get(base) or []
        x = values[int(i)] if int(i) < len(values) else None
    else:
        x = block.get(name)
    return float("nan") if x is None else float(x)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--blade", choices=("demo", "rotor67"), default="demo")
    ap.add_argument("--scans", type=int, default=24)
    ap.add_argument("--seed", type=int, default=100)
    ap.add_argument("--variant", choices=("nominal-knots", "smoothing"), default="nominal-knots")
    ap.add_argument("--draws", type=int, default=12)
    args = ap.parse_args()
    t0 = time.time()
    truth_pts, noisy, nominals, stated = scans(args.blade, args.seed, args.scans, args.draws)
    print("%s, %d scans (noise only) against the noise-free chain, fit: %s; scans made in "
          "%.0f s" % (args.blade, args.scans, args.variant, time.time() - t0))
    for i, nominal in enumerate(nominals):
        truth, _ = values(truth_pts[i], 0.0, nominal, "smoothing")
        rows, knots = [], []
        for scan in noisy:
            row, n = values(scan[i][0], scan[i][1], nominal, args.variant)
            rows.append(row)
            knots.append(n)
        print("\nsection %d (%d points, noise %.2f um), fit's free coefficients %d-%d (mean %.0f)"
              % (i + 1, len(noisy[0][i][0]), 1e3 * np.mean([s[i][1] for s in noisy]),
                 min(knots), max(knots), np.mean(knots)))
        print("  %-24s %10s %8s %10s %10s %8s %6s" % ("characteristic", "mean err", "t",
                                                        "1 sigma", "stated u", "err/u", "unit"))
        for name in truth:
            if truth[name] is None:
                continue
            unit, scale = ("%", 1.0) if name.endswith("pct") else \
                ("mdeg", 1e3) if name.endswith("deg") else ("um", 1e3)
            err = scale * (np.array([r[name] for r in rows if r[name] is not None], float)
                           - truth[name])
            sd = err.std(ddof=1)
            u = scale * stated_u(stated[i], name)
            print("  %-24s %+10.3f %8.1f %10.3f %10.3f %8.2f %6s"
                  % (name, err.mean(), err.mean() / (sd / np.sqrt(len(err))), sd, u,
                     err.mean() / u, unit))


if __name__ == "__main__":
    main()
