"""Validation matrix (issue 35, item 6): the airfoil command run as a user runs it on a corpus
of blades it has never seen (bench/corpus/), judged against independent truths.

For each case, manufactured error and scan density: the manufactured part's CAD is built with
FreeCAD (cached as STEP), a scan of it is simulated (random pose, the sensor's +-6 um uniform
noise; cached as CSV), ``inspection.airfoil_stage.run_airfoil`` (what `bladeinspect airfoil
--cad NOMINAL --points SCAN --section-heights 25,50,75` calls) measures it against the
nominal, and each reported deviation is compared with the true deviation = truth(made part) -
truth(nominal), both computed by the corpus (closed forms or brute force on the exact profile),
never by BladeInspect's kernel.

Judged per characteristic: error = reported deviation - true deviation, U its stated expanded
uncertainty (k = 2). Covered: |error| <= U. CONFIDENT WRONG: |error| > 2U and no note of the
section names that characteristic (see ``flagged``). A withheld value (null deviation) is
counted as withheld, never as wrong. A section the command refused, or a case that failed,
is a failure row with its one-line error.

  scripts/fcpython bench/validation_matrix.py [--quick] [--densities 20000,200000]
      [--cases a,b] [--errors none,twist] [--jobs N] [--cache DIR] [--seed S] [--json FILE]
"""
import argparse
import json
import os
import sys
import time
import traceback

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

from corpus import all_cases, truth  # noqa: E402
from corpus.profiles import ArcProfile, DenseLoop  # noqa: E402

HEIGHTS = (25.0, 50.0, 75.0)
DENSITIES = (20000, 50000, 200000, 800000)
# Manufactured errors: uniform oversize (mm), thickness factor, LE change (mm of LE radius on
# unions of circles, mm of LE-circle shift on double circular arcs), twist at the tip (deg,
# about the stacking line, linear from the root).
OVERSIZE_MM = 0.020
THICKNESS_FACTOR = 1.04
LE_RESHAPE = 0.05
LE_SHIFT_ARC_MM = 0.5
TWIST_TIP_DEG = 0.3
# The default matrix (about 30 CPU-minutes at 200k points); thickness and le_reshape on
# request (--errors all).
DEFAULT_ERRORS = ("none", "oversize", "twist")
ANGLES = ("stagger_deg", "inlet_angle_deg", "outlet_angle_deg")
# Characteristics judged (scalar fields of a section block); under "none" every one's true
# deviation is 0 exactly (the part is the CAD).
JUDGED = ("chord_mm", "axial_chord_mm", "stagger_deg", "max_thickness_mm", "le_radius_mm",
          "te_radius_mm", "inlet_angle_deg", "outlet_angle_deg", "area_mm2", "twist_deg")
# What a note must say to flag a characteristic: its field name, or one of its words; an
# edge's characteristic (LE/TE radius, inlet/outlet angle) by a generic word ("radius",
# "metal angle") only when the note also names that edge.
NOTE_WORDS = {
    "chord_mm": ("chord",), "axial_chord_mm": ("axial chord",), "stagger_deg": ("stagger",),
    "max_thickness_mm": ("thickness",), "area_mm2": ("area",), "twist_deg": ("twist",),
    "le_radius_mm": ("le radius", "leading-edge radius"),
    "te_radius_mm": ("te radius", "trailing-edge radius"),
    "inlet_angle_deg": ("inlet",), "outlet_angle_deg": ("outlet",),
}
EDGE_WORDS = {"le_radius_mm": ("LE", "radius"), "te_radius_mm": ("TE", "radius"),
              "inlet_angle_deg": ("LE", "metal angle"), "outlet_angle_deg": ("TE", "metal angle")}


# ------------------------------------------------------------------ building a case's parts

def error_profile(profile, error):
    """The manufactured section (before its station's rotation), or None if the error does
    not apply to this kind of profile."""
    if error in ("none", "twist"):
        return profile
    if error == "oversize":
        if hasattr(profile, "grown"):
            return profile.grown(OVERSIZE_MM)
        closed = {k: v + OVERSIZE_MM for k, v in profile.closed_form().items()
                  if k in ("le_radius_mm", "te_radius_mm")}
        return DenseLoop(truth.offset_loop(profile.points(), OVERSIZE_MM), closed)
    if error == "thickness" and hasattr(profile, "thickened"):
        return profile.thickened(THICKNESS_FACTOR)
    if error == "le_reshape" and hasattr(profile, "le_reshaped"):
        arc = isinstance(profile, ArcProfile)
        return profile.le_reshaped(LE_SHIFT_ARC_MM if arc else LE_RESHAPE)
    return None


def stations_of(case, error):
    """[(q, z, rotation deg, shift)] of the part's sections; one station: an extrusion."""
    qs = case.stations or ((0.0, 0.25, 0.5, 0.75, 1.0) if error == "twist" else (0.5,))
    out = []
    for q in qs:
        rot = (case.twist_deg(q) if case.twist_deg else 0.0) + \
            (TWIST_TIP_DEG * q if error == "twist" else 0.0)
        shift = np.asarray(case.lean_mm(q) if case.lean_mm else (0.0, 0.0), float)
        out.append((q, q * case.span, rot, shift))
    return out


def build_part(case, profile, error, step_path):
    """Build (or read from the cache) one part of a case: its STEP and the truth of each
    station (z, closed forms, brute force on the CAD's own B-spline there)."""
    from corpus import cad
    tpath = step_path[:-5] + ".truth.json"
    if os.path.exists(step_path) and os.path.exists(tpath):
        with open(tpath) as fh:
            return json.load(fh)
    prof = error_profile(profile, error)
    st = stations_of(case, error)
    loops = [(z, truth.rotate(prof.points(), rot) + shift) for q, z, rot, shift in st]
    shape, curves = cad.build(loops, mode=case.mode, hub=case.hub)
    cad.write_step(shape, step_path)
    prismatic = len(st) == 1
    stations = []
    for (q, z, rot, shift), curve in zip(st, curves):
        closed = prof.closed_form()
        for k in ANGLES:
            if k in closed:
                closed[k] += rot
        stations.append({"q": q, "z": z, "closed": closed,
                         "brute": truth.brute(cad.station_loop(curve))})
    doc = {"prismatic": prismatic, "stations": stations, "error": error}
    with open(tpath + ".tmp", "w") as fh:
        json.dump(doc, fh, indent=1)
    os.replace(tpath + ".tmp", tpath)
    return doc


def dense_public(case, cache):
    """A public 2D profile's points are coarse: its errors are applied to the dense profile
    of the nominal CAD's B-spline (what the nominal STEP holds), not to the raw nodes."""
    from corpus import cad
    curve = cad._curve(cad.select_points(case.profile.points()), 0.0)
    return DenseLoop(cad.station_loop(curve))


# ------------------------------------------------------------------ truth of one section

def station_truth(doc, z):
    """The truth dict at height z: any z on an extrusion, else the station within 0.01 mm."""
    st = doc["stations"]
    if doc["prismatic"]:
        s = st[0]
    else:
        near = [s for s in st if abs(s["z"] - z) < 0.01]
        if not near:
            return None
        s = near[0]
    t = dict(s["brute"])
    t.update(s["closed"])          # a closed form beats the brute force where both exist
    return t


def true_deviations(nom_doc, made_doc, error, z, q, fit=None):
    """{characteristic: true deviation} for the section at height z (span fraction q).
    ``fit``: for a twist, the fitted part's rotation relative to the nominal at each judged
    height and the axial chord's change under it (``twist_fit``)."""
    if error == "none":
        return {k: 0.0 for k in JUDGED}
    if error == "twist":
        # Read in the fitted frame: each section is the nominal turned by the twist there
        # less the fit's own turn; lengths keep, the axial chord turns with the profile.
        key = "%.4f" % q
        if fit is None or key not in fit["rel_deg"]:
            return None
        out = {k: 0.0 for k in JUDGED}
        for k in ANGLES + ("twist_deg",):
            out[k] = fit["rel_deg"][key]
        out["axial_chord_mm"] = fit["axial_chord_mm"][key]
        return out
    tn, tm = station_truth(nom_doc, z), station_truth(made_doc, z)
    if tn is None or tm is None:
        return None
    return {k: tm[k] - tn[k] for k in tm if k in tn and k in JUDGED}


def twist_fit(case, profile, made_path, seed, cache_path, n_points=20000):
    """The twist's truth in the fitted frame (corpus.fit_truth): the rigid least-squares
    fit's motion from ``n_points`` of a scan of the made part simulated as the matrix's own
    (same pattern, weights and seed), and at each judged height the section's rotation
    relative to the nominal and the axial chord's change. Cached at ``cache_path``."""
    if os.path.exists(cache_path):
        with open(cache_path) as fh:
            return json.load(fh)
    from BladeInspect.core import transforms as tf
    from BladeInspect.inspection import pipeline
    from BladeInspect.inspection.simulate import simulate_measurement
    from corpus.fit_truth import fitted_rotation
    made = pipeline.load_nominal(made_path)
    ps, to_cad, _, good = simulate_measurement(made, n_points=n_points, seed=seed)
    points = tf.apply_transform(to_cad, ps.xyz)[good]
    loop = profile.points()
    rel, info = fitted_rotation(case, loop, TWIST_TIP_DEG, points, ps.snr[good])
    out = dict(info, rel_deg={}, axial_chord_mm={})
    for h in HEIGHTS:
        q = h / 100.0
        station = truth.rotate(loop, case.twist_deg(q) if case.twist_deg else 0.0)
        r = rel(q)
        out["rel_deg"]["%.4f" % q] = r
        out["axial_chord_mm"]["%.4f" % q] = \
            truth.extent(truth.rotate(station, r)) - truth.extent(station)
    with open(cache_path + ".tmp", "w") as fh:
        json.dump(out, fh, indent=1)
    os.replace(cache_path + ".tmp", cache_path)
    return out


# ------------------------------------------------------------------ judging one report

def flagged(notes, key):
    """Whether a note of the section flags the characteristic ``key`` (NOTE_WORDS,
    EDGE_WORDS). "A note" is any entry of the section block's ``notes`` list."""
    import re
    for n in notes or ():
        text = str(n)
        low = text.lower()
        if key in low or any(w in low for w in NOTE_WORDS.get(key, ())):
            return True
        if key in EDGE_WORDS:
            edge, word = EDGE_WORDS[key]
            if word in low and re.search(r"\b%s\b" % edge, text):
                return True
    return False


def angle_sign(nominal_block, nom_doc, z):
    """+1 when the section plane's frame turns counter-clockwise about +z (the corpus's
    convention), -1 when its normal is -z: read off the nominal's stagger against the
    corpus's own closed form (the frame's orientation, not a value, is taken from it)."""
    t = station_truth(nom_doc, z) if nom_doc else None
    rep = nominal_block.get("stagger_deg")
    if not t or "stagger_deg" not in t or rep is None or abs(t["stagger_deg"]) < 1.0:
        return 1.0
    return -1.0 if abs(rep + t["stagger_deg"]) < abs(rep - t["stagger_deg"]) else 1.0


def judge(case, error, density, doc, nom_doc, made_doc, fit=None):
    rows = []
    for block in doc.get("airfoil") or []:
        label = block.get("label")
        nominal = block.get("nominal") or {}
        z = (nominal.get("centroid_mm") or [None, None, None])[2]
        h = block.get("height_pct")
        q = h / 100.0 if h is not None else None
        td = true_deviations(nom_doc, made_doc, error, z, q, fit) if z is not None else None
        if td is None:
            rows.append(dict(case=case.name, family=case.family, error=error, density=density,
                             section=label, key=None, status="no truth at this plane"))
            continue
        notes = block.get("notes") or []
        dev = block.get("deviation") or {}
        # the block's "uncertainty" is the standard u (k = 1): U = 2u
        unc = {k: (None if v is None else 2.0 * v)
               for k, v in (block.get("uncertainty") or {}).items() if not isinstance(v, list)}
        sign = angle_sign(nominal, nom_doc, z)
        for k in ANGLES + ("twist_deg",):
            if k in td:
                td[k] *= sign
        for key, t in td.items():
            r = dict(case=case.name, family=case.family, error=error, density=density,
                     section=label, key=key, truth=t)
            d, U = dev.get(key), unc.get(key)
            if d is None:
                r["status"] = "withheld"
            elif U is None:
                r.update(error_value=float(d) - t, status="no U")
            else:
                e = float(d) - t
                U = float(U)
                r.update(error_value=e, U=U)
                if abs(e) <= U:
                    r["status"] = "covered"
                elif abs(e) > 2 * U and not flagged(notes, key):
                    r["status"] = "CONFIDENT WRONG"
                elif abs(e) > 2 * U:
                    r["status"] = "wrong, noted"
                else:
                    r["status"] = "outside U"
            rows.append(r)
    return rows


# ------------------------------------------------------------------ running

def run_one(case, error, density, cache, seed, nominal_cache):
    """Rows of one (case, error, density): build, scan, measure, judge. A crash of the
    command is a failure row with its one-line error."""
    from BladeInspect.core.pointio import write_points_csv
    from BladeInspect.inspection import pipeline
    from BladeInspect.inspection.airfoil_stage import run_airfoil
    from BladeInspect.inspection.simulate import simulate_measurement
    d = os.path.join(cache, case.name)
    os.makedirs(d, exist_ok=True)
    base = dict(case=case.name, family=case.family, error=error, density=density, key=None)
    t0 = time.perf_counter()
    out = None
    try:
        if case.cad_path:
            nom_path = made_path = case.cad_path
            nom_doc = made_doc = None
        else:
            profile = case.profile
            if isinstance(profile, DenseLoop) and len(profile.points()) < 5000:
                profile = dense_public(case, cache)
            nom_path = os.path.join(d, "nominal.step")
            nom_doc = build_part(case, profile, "none", nom_path)
            if error == "none":
                made_path, made_doc = nom_path, nom_doc
            else:
                if error_profile(profile, error) is None:
                    return []
                made_path = os.path.join(d, error + ".step")
                made_doc = build_part(case, profile, error, made_path)
        scan = os.path.join(d, "scan_%s_%d_s%d.csv" % (error, density, seed))
        if not os.path.exists(scan):
            made = pipeline.load_nominal(made_path)
            ps, _, _, _ = simulate_measurement(made, n_points=density, seed=seed)
            write_points_csv(scan + ".tmp.csv", ps.xyz, {"snr": ps.snr})
            os.replace(scan + ".tmp.csv", scan)
        out = os.path.join(d, "out_%s_%d_s%d" % (error, density, seed))
        res = os.path.join(out, "airfoil.json")
        if os.path.exists(out + ".failed.json"):
            with open(out + ".failed.json") as fh:
                return [dict(base, **json.load(fh))]
        if not os.path.exists(res):
            if nom_path not in nominal_cache:
                nominal_cache.clear()
                nominal_cache[nom_path] = pipeline.load_nominal(nom_path)
            run_airfoil(nom_path, out, points_path=scan, heights_pct=list(HEIGHTS),
                        seed=seed, nominal=nominal_cache[nom_path])
        with open(res) as fh:
            doc = json.load(fh)
        fit = None
        if error == "twist" and not case.cad_path:
            fit = twist_fit(case, profile, made_path, seed,
                            os.path.join(d, "twist_fit_s%d.json" % seed))
    except Exception as exc:   # a crash is a finding: one line, the matrix goes on
        line = ("%s: %s" % (type(exc).__name__, exc)).splitlines()[0][:200]
        frames = [ln.strip() for ln in traceback.format_exc().splitlines()
                  if ln.strip().startswith("File ")]
        # the deepest frame of the project's code, where the finding is
        where = ([f for f in frames if "BladeInspect" in f] or frames or [""])[-1][:200]
        failure = dict(status="FAILED", message=line, where=where)
        if out is not None:       # the command itself failed: remembered with its results
            with open(out + ".failed.json", "w") as fh:
                json.dump(failure, fh)
        return [dict(base, **failure)]
    rows = judge(case, error, density, doc, nom_doc, made_doc, fit)
    for r in rows:
        r["seconds"] = round(time.perf_counter() - t0, 1)
    return rows


def summarise(rows):
    """{(family, density): counts}"""
    out = {}
    for r in rows:
        k = (r["family"], r["density"])
        s = out.setdefault(k, dict(judged=0, covered=0, within2U=0, confident_wrong=0,
                                   wrong_noted=0, withheld=0, no_U=0, failed=0, no_truth=0))
        st = r["status"]
        if st == "FAILED":
            s["failed"] += 1
        elif st == "no truth at this plane":
            s["no_truth"] += 1
        elif st == "withheld":
            s["withheld"] += 1
        elif st == "no U":
            s["no_U"] += 1
        else:
            s["judged"] += 1
            s["covered"] += st == "covered"
            s["within2U"] += st in ("covered", "outside U")
            s["confident_wrong"] += st == "CONFIDENT WRONG"
            s["wrong_noted"] += st == "wrong, noted"
    return out


def print_table(rows, stream=None):
    w = (stream or sys.stdout).write
    bad = [r for r in rows if r["status"] == "CONFIDENT WRONG"]
    failed = [r for r in rows if r["status"] == "FAILED"]
    if bad:
        w("\nConfident wrong answers (|error| > 2U, no note naming it):\n")
        w("%-22s %-10s %7s %-4s %-17s %11s %9s\n" % ("case", "error", "points", "sec",
                                                      "characteristic", "error", "U"))
        for r in sorted(bad, key=lambda r: (r["case"], r["error"], r["density"], r["section"])):
            w("%-22s %-10s %7d %-4s %-17s %11.4f %9.4f\n" % (
                r["case"], r["error"], r["density"], r["section"], r["key"], r["error_value"],
                r["U"]))
    if failed:
        w("\nFailed runs (the command stopped):\n")
        for r in failed:
            w("  %s %s %d: %s\n" % (r["case"], r["error"], r["density"], r["message"]))
    w("\nValidation matrix (U k=2; covered |error|<=U; CW = confident wrong, |error|>2U with "
      "no note)\n")
    w("%-17s %7s %6s %8s %8s %4s %6s %8s %5s %6s %7s\n" % (
        "family", "points", "judged", "<=U", "<=2U", "CW", "noted", "withheld", "noU", "failed",
        "notruth"))
    summ = summarise(rows)
    tot = dict(judged=0, covered=0, within2U=0, confident_wrong=0, wrong_noted=0, withheld=0,
               no_U=0, failed=0, no_truth=0)
    for (fam, dens), s in sorted(summ.items()):
        for k in tot:
            tot[k] += s[k]
        pct = lambda a: ("%5.1f%%" % (100.0 * a / s["judged"])) if s["judged"] else "   -  "
        w("%-17s %7d %6d %8s %8s %4d %6d %8d %5d %6d %7d\n" % (
            fam, dens, s["judged"], pct(s["covered"]), pct(s["within2U"]),
            s["confident_wrong"], s["wrong_noted"], s["withheld"], s["no_U"], s["failed"],
            s["no_truth"]))
    j = tot["judged"] or 1
    w("%-17s %7s %6d %7.1f%% %7.1f%% %4d %6d %8d %5d %6d %7d\n" % (
        "ALL", "", tot["judged"], 100.0 * tot["covered"] / j, 100.0 * tot["within2U"] / j,
        tot["confident_wrong"], tot["wrong_noted"], tot["withheld"], tot["no_U"],
        tot["failed"], tot["no_truth"]))
    if tot["no_truth"]:
        w("notruth: sections cut off the part's stations (the plane is not the one the corpus "
          "knows the truth of: the span axis is not the stacking axis)\n")
    return tot


QUICK_CASES = ("dca_rotor", "vane_110deg")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="smoke test: %s, errors none and oversize, 20000 points"
                    % ", ".join(QUICK_CASES))
    ap.add_argument("--densities", default=None, help="points per scan, e.g. 20000,200000")
    ap.add_argument("--cases", default=None, help="case names (default all)")
    ap.add_argument("--errors", default=None, help="manufactured errors among none, "
                    "oversize, twist, thickness, le_reshape, or all (default: %s, those that "
                    "apply to each case)" % ",".join(DEFAULT_ERRORS))
    ap.add_argument("--jobs", type=int, default=1, help="processes (default 1)")
    ap.add_argument("--cache", default=os.path.join(
        os.environ.get("TMPDIR", "/tmp"), "bladeinspect-corpus"),
        help="cache of CAD, truths, scans and results (default $TMPDIR/bladeinspect-corpus); "
        "delete a case's results (out_*) to re-measure with new code")
    ap.add_argument("--fresh", action="store_true",
                    help="re-run the airfoil command (keep CAD, truths and scans)")
    ap.add_argument("--cached-only", action="store_true",
                    help="judge only the runs whose results are in the cache (no new runs)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--json", default=None, help="write every row to FILE")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    a = ap.parse_args(argv)
    cases = all_cases()
    if a.list:
        for c in cases:
            print("%-22s %-17s %s %s" % (c.name, c.family, ",".join(c.errors), c.source))
        return 0
    densities = [20000] if a.quick else DENSITIES[2:3]
    if a.densities:
        densities = [int(x) for x in a.densities.split(",")]
    names = QUICK_CASES if (a.quick and not a.cases) else \
        (a.cases.split(",") if a.cases else [c.name for c in cases])
    unknown = set(names) - {c.name for c in cases}
    if unknown:
        ap.error("unknown case(s): %s" % ", ".join(sorted(unknown)))
    errors = ("none", "oversize") if (a.quick and not a.errors) else \
        (tuple(a.errors.split(",")) if a.errors else DEFAULT_ERRORS)
    if errors == ("all",):
        errors = None
    # errors outermost: an interrupted run has judged every case as made first
    order = ("none", "oversize", "twist", "thickness", "le_reshape")
    jobs = [(c, e, n) for n in densities for e in order for c in cases
            if c.name in names and e in c.errors and (errors is None or e in errors)]
    if a.cached_only:
        done = lambda c, e, n: os.path.join(a.cache, c.name, "out_%s_%d_s%d" % (e, n, a.seed))
        jobs = [(c, e, n) for c, e, n in jobs
                if os.path.exists(os.path.join(done(c, e, n), "airfoil.json"))
                or os.path.exists(done(c, e, n) + ".failed.json")]
    if a.fresh:
        import shutil
        for c, e, n in jobs:
            out = os.path.join(a.cache, c.name, "out_%s_%d_s%d" % (e, n, a.seed))
            shutil.rmtree(out, ignore_errors=True)
            if os.path.exists(out + ".failed.json"):
                os.remove(out + ".failed.json")
    t0 = time.perf_counter()
    rows = []
    if a.jobs > 1:
        from concurrent.futures import ProcessPoolExecutor
        with ProcessPoolExecutor(a.jobs) as ex:
            futs = [ex.submit(_run_job, c.name, e, n, a.cache, a.seed) for c, e, n in jobs]
            for f in futs:
                rows += f.result()
    else:
        nominal_cache = {}
        for c, e, n in jobs:
            t1 = time.perf_counter()
            r = run_one(c, e, n, a.cache, a.seed, nominal_cache)
            sys.stderr.write("  %-22s %-10s %7d  %5.1f s  %s\n" % (
                c.name, e, n, time.perf_counter() - t1,
                "FAILED: " + r[0]["message"] if r and r[0]["status"] == "FAILED" else
                "%d judged" % len(r)))
            rows += r
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows, fh, indent=0)
    print_table(rows)
    print("%d runs, %.0f s" % (len(jobs), time.perf_counter() - t0))
    return 0


def _run_job(name, error, density, cache, seed):
    case = [c for c in all_cases() if c.name == name][0]
    return run_one(case, error, density, cache, seed, {})


if __name__ == "__main__":
    sys.exit(main())
