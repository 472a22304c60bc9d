"""Airfoil characteristics (core.airfoil): accuracy against closed forms and CPU time.

    /usr/bin/python3 bench/bench_airfoil.py [--noise-trials 20]

Sections (tests/airfoil_shapes.py): a cambered double-circular-arc section with exact circular
edges (camber line an ellipse), NACA 0012 with a circular tail, and NACA 4412 (its inscribed-
circle camber line against NACA's own camber line). Prints each characteristic's error on the
exact nominal, the NACA nose radius against the zone, the spread at sigma = 2 um noise, and the
CPU time of all characteristics of five sections.
"""
import argparse
import os
import sys
import time

# The kernel's least-squares problems are tiny: BLAS threads would only spin, and their spinning
# counts as this process's CPU time (it doubled the figure on two cores).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from BladeInspect.core import airfoil  # noqa: E402
from tests.airfoil_shapes import (ArcSection, NacaSection, naca_camber,  # noqa: E402
                                  naca_thickness, rigid)
from tests.test_airfoil import angle_diff, angle_of, cambered_naca  # noqa: E402


def arc_errors():
    sec = ArcSection(x_le=-24.0, x_te=27.0, angle_deg=33.0, shift=(4.0, -7.0))
    axis = np.array([np.cos(0.3), np.sin(0.3)])
    ch = airfoil.characteristics(sec.points(), engine_axis=axis, stations_pct=(10, 30, 50, 80))
    ax = angle_of(axis)
    area, centroid = sec.area_centroid()
    own = rigid(rigid(ch.mcl.at(np.linspace(ch.mcl.le_extension, ch.mcl.le_extension
                                            + ch.mcl.inner_length, 3001))[0], 0, -sec.shift),
                -sec.angle_deg, (0, 0))
    um = {
        "LE point": np.linalg.norm(ch.le_point - sec.le_point()),
        "TE point": np.linalg.norm(ch.te_point - sec.te_point()),
        "nose-tail chord": ch.chord_mm - sec.chord(),
        "caliper chord": ch.caliper_chord_mm - sec.caliper(),
        "tangent chord": ch.tangent_chord_mm - sec.extent(sec.pressure_tangent_dir()),
        "axial chord": ch.axial_chord_mm - sec.extent(axis),
        "max thickness": ch.max_thickness_mm - sec.max_thickness(),
        "max thickness position": (ch.max_thickness_pos_pct * ch.chord_mm
                                   - sec.max_thickness_pos_pct() * sec.chord()) / 100,
        "thickness at stations (max)": max(abs(v - sec.thickness_at_station(p)) for p, v in
                                           zip(ch.thickness_stations_pct, ch.thickness_mm)),
        "LE thickness at offsets (max)": max(abs(v - sec.thickness_at_arc(d)) for d, v in
                                             zip(ch.edge_offsets_mm, ch.le_thickness_mm)),
        "TE thickness at offsets (max)": max(abs(v - sec.thickness_at_arc(sec.mcl_length() - d))
                                             for d, v in zip(ch.edge_offsets_mm,
                                                             ch.te_thickness_mm)),
        "LE radius": ch.le_radius_mm - sec.r_le,
        "TE radius": ch.te_radius_mm - sec.r_te,
        "centroid": np.linalg.norm(ch.centroid_mm - centroid),
        "camber line from the ellipse (max)": np.abs(sec.ellipse_distance(own)).max(),
    }
    mdeg = {
        "stagger": angle_diff(ch.stagger_deg, angle_of(sec.chord_dir()) - ax),
        "inlet metal angle": angle_diff(ch.inlet_angle_deg, angle_of(sec.inlet_dir()) - ax),
        "outlet metal angle": angle_diff(ch.outlet_angle_deg, angle_of(sec.outlet_dir()) - ax),
    }
    print("Double-circular-arc section, exact circular edges (r_LE %.4f, r_TE %.4f mm), "
          "edge zone +-%g deg:" % (sec.r_le, sec.r_te, ch.le_circle.zone_deg))
    for k, v in um.items():
        print("  %-38s %+.5f um" % (k, 1000 * v))
    print("  %-38s %+.5f um^2 (area %.4f mm^2)" % ("area", 1000 * (ch.area_mm2 - area), area))
    for k, v in mdeg.items():
        print("  %-38s %.6f mdeg" % (k, 1000 * v))


def naca_errors():
    sec = NacaSection("0012", c=60.0, x0=0.97, angle_deg=-21.0, shift=(2.0, 3.0))
    ch = airfoil.characteristics(sec.points(), stations_pct=(5, 20, 50, 90))
    own = rigid(rigid(ch.mcl.sample(2000), 0.0, -sec.shift), -sec.angle_deg, (0, 0))
    print("NACA 0012, c = 60 mm, circular tail from x = 0.97 c (r_TE %.4f mm):" % sec.r_te)
    rows = {
        "nose-tail chord": ch.chord_mm - sec.chord(),
        "max thickness": ch.max_thickness_mm - sec.max_thickness(),
        "max thickness position": (ch.max_thickness_pos_pct * ch.chord_mm
                                   - sec.max_thickness_pos_pct() * sec.chord()) / 100,
        "thickness at stations (max)": max(abs(v - sec.thickness_at_x(p / 100 * sec.chord()))
                                           for p, v in zip(ch.thickness_stations_pct,
                                                           ch.thickness_mm)),
        "TE radius": ch.te_radius_mm - sec.r_te,
        "camber line from the chord line (max)": np.abs(own[:, 1]).max(),
    }
    for k, v in rows.items():
        print("  %-38s %+.5f um" % (k, 1000 * v))
    print("  %-38s %.6f mdeg" % ("stagger", 1000 * angle_diff(ch.stagger_deg, sec.angle_deg)))
    print("  Nose radius against 1.1019 t^2 c (a circle fitted to the analytic nose over the "
          "same zone in brackets):")
    for digits in ("0006", "0012", "0020"):
        s = NacaSection(digits, c=60.0, x0=0.97)
        prof = airfoil.Profile(s.points())
        cells = []
        for zone in (2.0, 5.0, 10.0, 20.0, 45.0):
            r = airfoil.characteristics(prof, edge_zone_deg=zone, le_hint=(0.0, 0.0)).le_radius_mm
            cells.append("+-%g deg %+.2f %% [%+.2f %%]" % (zone, 100 * (r / s.le_radius() - 1),
                                                          100 * (analytic_nose_fit(s, zone)
                                                                 / s.le_radius() - 1)))
        print("    NACA %s: %s" % (digits, "; ".join(cells)))


def analytic_nose_fit(sec, zone_deg):
    xi = np.linspace(-0.3, 0.3, 200001)
    pts = np.where(xi[:, None] >= 0, sec.surface(np.abs(xi), True),
                   sec.surface(np.abs(xi), False))
    centre = np.array([sec.le_radius(), 0.0])
    for _ in range(30):
        v = pts - centre
        seen = (v / np.linalg.norm(v, axis=1)[:, None]) @ np.array([-1.0, 0.0])
        centre, radius, _ = airfoil.fit_circle_2d(pts[seen >= np.cos(np.radians(zone_deg))])
    return radius


def cambered():
    from scipy.optimize import brentq
    from tests.airfoil_shapes import naca_thickness_slope
    c = 50.0
    ch = airfoil.characteristics(cambered_naca("4412", c))
    xm = brentq(lambda x: naca_thickness_slope(x, 0.12), 0.05, 0.6, xtol=1e-15)
    x = np.linspace(0.05, 0.9, 400)
    yc, _ = naca_camber(x, 0.04, 0.4)
    naca = c * np.column_stack([x, yc])
    mcl = ch.mcl.sample(40001)
    dist = np.array([np.min(np.linalg.norm(mcl - p, axis=1)) for p in naca])
    at_xm = np.min(np.linalg.norm(mcl - c * np.array([xm, float(naca_camber(xm, .04, .4)[0])]),
                                  axis=1))
    print("NACA 4412, c = 50 mm: inscribed-circle camber line against NACA's camber line")
    print("  at x = %.4f c (dy_t/dx = 0): %.4f um apart (they meet there exactly)"
          % (xm, 1000 * at_xm))
    print("  over 5..90 %% chord: up to %.2f um apart (at x = %.2f c); max thickness %+.5f um "
          "from 2 y_t(x_m)" % (1000 * dist.max(), x[np.argmax(dist)],
                               1000 * (ch.max_thickness_mm - 2 * c * naca_thickness(xm, 0.12))))


def noise(trials):
    rng = np.random.default_rng(3)
    sec = ArcSection(x_le=-24.0, x_te=27.0)
    pts = sec.points(0.02)
    prof = airfoil.Profile(pts)
    truth = airfoil.characteristics(prof).as_dict()
    normal = prof.outward_normal(prof.point_params)
    keys = ("chord_mm", "axial_chord_mm", "max_thickness_mm", "le_radius_mm", "te_radius_mm")
    err = {k: [] for k in keys + ("stagger_deg", "inlet_angle_deg", "outlet_angle_deg")}
    for _ in range(trials):
        noisy = pts + rng.normal(0.0, 0.002, len(pts))[:, None] * normal
        d = airfoil.characteristics(noisy, noise_mm=0.002).as_dict()
        for k in err:
            err[k].append(d[k] - truth[k])
    print("Noise sigma = 2 um normal to the section (%d scans, 0.02 mm spacing, noise_mm = "
          "0.002): bias / 1 sigma / max" % trials)
    for k, v in err.items():
        v = np.array(v)
        unit, scale = ("mdeg", 1000.0) if k.endswith("deg") else ("um", 1000.0)
        print("  %-20s %+7.3f / %6.3f / %6.3f %s" % (k, scale * v.mean(), scale * v.std(),
                                                     scale * np.abs(v).max(), unit))


def timing():
    sections = [ArcSection(x_le=-24.0 + k, x_te=27.0 - k, angle_deg=10 * k).points()
                for k in range(3)] + [NacaSection(d, c=60.0, x0=0.97).points()
                                      for d in ("0010", "0012")]
    airfoil.characteristics(sections[0])          # imports and first-call set-up
    t0, w0 = time.process_time(), time.perf_counter()
    for pts in sections:
        airfoil.characteristics(pts, stations_pct=(10, 50, 90))
    cpu, wall = time.process_time() - t0, time.perf_counter() - w0
    print("All characteristics of five sections (%s points): %.3f s CPU, %.3f s wall"
          % ("/".join(str(len(p)) for p in sections), cpu, wall))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--noise-trials", type=int, default=20)
    args = ap.parse_args()
    arc_errors()
    naca_errors()
    cambered()
    noise(args.noise_trials)
    timing()


if __name__ == "__main__":
    main()
