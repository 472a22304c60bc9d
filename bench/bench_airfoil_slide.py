"""Is the noisy profile's fit a continuous function of the points? A measured section's points
slid along the profile by the same small amount -- which does not change the curve they sample
-- should leave every characteristic where it was. FITPACK's smoothing spline re-chooses its
knots as they slide, and the characteristics jump (docs/airfoil.md, "How the knots' jumps
reach the results"): the acceptance check of a fit meant to be continuous.

The section is the whole-chain Monte Carlo's demo scan (bench_uncertainty_mc.py: planned
section 2 at 70 % span, noise seed 11, a reading bias of -3 um: on that scan FITPACK's
outlet angle steps by 0.05 deg; at no bias the same slides move it by 2 mdeg, so how far a
fit jumps depends on the scan), registered as the loop does; its points are slid along the
nominal profile's tangent and measured by core.airfoil alone.

    scripts/fcpython bench/bench_airfoil_slide.py [--from -0.003] [--to 0.001] [--steps 17]
        [--bias-um -3] [--normal] [--smoothing]

Prints per slide (mm) the outlet and inlet angles, the max-thickness position, the TE radius
and the fit's knot count, then each one's largest change between neighbouring slides.
``--normal`` slides along the normal instead (a real offset of the curve, for comparison);
``--smoothing`` fits without the nominal's knots (core.airfoil._knots_from_nominal), as the
stage did before 2026-12-05.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_uncertainty_mc as mc  # noqa: E402
from BladeInspect.core import airfoil as kernel  # noqa: E402

FIELDS = ("outlet_angle_deg", "inlet_angle_deg", "max_thickness_pos_pct", "te_radius_mm")


def measured_section(bias_mm, noise_seed=11, section=1):
    """(points in the plane, their noise, the nominal Characteristics) of one section of the
    Monte Carlo's demo scan measured with noise and a reading bias ``bias_mm``."""
    sr = mc.Chain("demo", 2026, 31).stage_sections(np.random.default_rng(noise_seed),
                                                   errors=("noise",), bias_mm=bias_mm)[section]
    return sr.points_2d, sr.noise_mm, sr.nominal


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--from", dest="start", type=float, default=-0.003)
    ap.add_argument("--to", dest="stop", type=float, default=0.001)
    ap.add_argument("--steps", type=int, default=17)
    ap.add_argument("--bias-um", type=float, default=-3.0)
    ap.add_argument("--normal", action="store_true")
    ap.add_argument("--smoothing", action="store_true",
                    help="FITPACK's smoothing spline alone (no nominal's knots)")
    args = ap.parse_args()
    pts, noise, nominal = measured_section(1e-3 * args.bias_um)
    u, _ = nominal.profile.closest(pts)
    normal = nominal.profile.outward_normal(u)
    along = normal if args.normal else np.column_stack([-normal[:, 1], normal[:, 0]])
    print("demo section 2 (70 %%), reading bias %+.1f um: %d points, noise %.2f um; slid along "
          "the %s" % (args.bias_um, len(pts), 1e3 * noise,
                      "normal" if args.normal else "profile"))
    print("%9s %10s %10s %9s %9s %6s" % ("slide um", "outlet deg", "inlet deg", "maxpos %",
                                          "te_r um", "knots"))
    rows = []
    for d in np.linspace(args.start, args.stop, args.steps):
        profile = kernel.Profile(kernel.order_by_nominal(pts + d * along, nominal.profile),
                                 noise, nominal=None if args.smoothing else nominal.profile)
        ch = kernel.characteristics(profile, noise_mm=noise)
        rows.append([getattr(ch, f) for f in FIELDS])
        print("%+9.2f %10.4f %10.4f %9.3f %9.2f %6d"
              % (1e3 * d, ch.outlet_angle_deg, ch.inlet_angle_deg, ch.max_thickness_pos_pct,
                 1e3 * ch.te_radius_mm, len(profile._tck[0])))
    step = np.abs(np.diff(np.asarray(rows, dtype=float), axis=0)).max(axis=0)
    print("largest change between neighbouring slides: outlet %.4f deg, inlet %.4f deg, "
          "max-thickness position %.4f %%, TE radius %.3f um"
          % (step[0], step[1], step[2], 1e3 * step[3]))


if __name__ == "__main__":
    main()
