"""Pass or fail against a profile tolerance, per section and for the part, with the worst spots
named by where they lie (paper 4.2-4.3).

A measured point outside +-tolerance fails the part only when it belongs to a spot: a group of
at least ``min_spot_points`` out-of-tolerance points linked through neighbourhoods (each is one
of the ``spot_neighbours`` nearest measured points of another). Neighbourhoods rather than a
fixed distance, so that a dense full scan and a few sparse section lines are judged alike.
A lone point out of tolerance, among neighbours that are all within it, is far more likely a
sensor outlier (a speckle, a glint at grazing incidence) than a defect narrower than the point
spacing; such points are counted and listed, not silently dropped. ``min_spot_points=1``
makes every point count.
"""

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..core.contracts import PROFILE_TOLERANCE_MM
from ..core import decision as decision_mod
from ..core.errors import InputError
from .sections import classify
from . import uncertainty as uncertainty_mod

SPOT_NEIGHBOURS = 8
MIN_SPOT_POINTS = 3

ZONE_TEXT = {"LE": "leading edge", "TE": "trailing edge", "suction": "suction side",
              "pressure": "pressure side", "": "unknown side"}


def linked_groups(points, out_idx, neighbours):
    """Groups of the points ``out_idx`` (the out-of-tolerance ones here; the fit's rejected
    ones in inspection.airfoil_verdicts) linked when one is among the other's nearest
    measured points: (component label per point, component sizes)."""
    n = len(out_idx)
    if n == 0:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    k = min(int(neighbours) + 1, len(points))
    _, nn = cKDTree(points).query(points[out_idx], k=k)
    nn = nn.reshape(n, k)
    position = np.full(len(points), -1)
    position[out_idx] = np.arange(n)
    rows = np.repeat(np.arange(n), k)
    cols = position[nn.ravel()]
    linked = cols >= 0
    graph = coo_matrix((np.ones(np.count_nonzero(linked)), (rows[linked], cols[linked])),
                       shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    return labels, np.bincount(labels)


def _nearest_section(table, xyz):
    heights = np.array([s.height_pct for s in table.sections])
    pct = table.span_pct(xyz)
    return np.argmin(np.abs(pct[:, None] - heights[None, :]), axis=1), pct


def place_of(table, xyz):
    """Where points lie, for people: (nearest section index, span %, zone) per point."""
    xyz = np.atleast_2d(xyz)
    if not table.sections:
        return np.zeros(len(xyz), dtype=int), table.span_pct(xyz), np.full(len(xyz), "")
    k, pct = _nearest_section(table, xyz)
    zone = np.empty(len(xyz), dtype=object)
    for i, sec in enumerate(table.sections):
        sel = k == i
        if sel.any():
            zone[sel] = classify(sec.profile, xyz[sel], table.edge_fraction)
    return k, pct, zone


def decided(value, U, tolerance, rule):
    """core.decision.decide against +-tolerance as JSON: verdict, U_mm, tur. A U that is not
    finite (a pose direction the points do not measure) proves nothing: not proven."""
    if not np.isfinite(U):
        return {"verdict": decision_mod.NOT_PROVEN, "U_mm": None, "tur": 0.0}
    d = decision_mod.decide(value, U, -tolerance, tolerance, rule=rule)
    return {"verdict": d.verdict, "U_mm": float(U),
            "tur": None if d.test_uncertainty_ratio is None or
            not np.isfinite(d.test_uncertainty_ratio) else float(d.test_uncertainty_ratio)}


def _larger_not_fitted(result, dev, worst, left_out):
    """The readings ``left_out`` (those the fit gave no weight, not the isolated outliers)
    whose |deviation| exceeds the part's worst inlier: {n, worst_deviation_mm, xyz}, None when
    there are none. Where a defect straddles the robust fit's cut-off, the worst inlier is
    pinned under it and which readings are inliers follows their measured deviations
    (docs/maintainers.md, "The part's worst inlier: a censored maximum"): the part's largest
    deviation is then not that row's; those readings are judged where a section's band or a
    spot holds them."""
    larger = left_out[np.abs(dev[left_out]) > abs(dev[worst])]
    if not len(larger):
        return None
    top = larger[np.argmax(np.abs(dev[larger]))]
    return {"n": int(len(larger)), "worst_deviation_mm": float(dev[top]),
            "xyz": result.points_cad[top].tolist()}


def judge(result, table, tolerance=PROFILE_TOLERANCE_MM, spot_neighbours=SPOT_NEIGHBOURS,
          min_spot_points=MIN_SPOT_POINTS, n_worst=5, decision_rule="iso14253",
          measurement_model=None):
    """The verdict as JSON-ready data: overall pass, per-section pass (optical, and CMM when
    present), the out-of-tolerance spots worst first with their place, and a one-line summary.

    Every judged value (each section's worst deviation, each listed spot's worst, and the
    part's worst inlier under ``part``) also carries its expanded uncertainty U
    (inspection.uncertainty, ``measurement_model``), the test uncertainty ratio T / U and its
    verdict under ``decision_rule`` (core.decision: pass, not proven, fail); ``verdict`` is
    the part's, combined (core.decision.combine) from the sections' and the spots'. ``pass``
    is True only when that verdict is pass: a "not proven" is never rounded to pass."""
    if decision_rule not in decision_mod.RULES:
        raise InputError("--decision-rule: unknown rule '%s' (use %s)"
                         % (decision_rule, ", ".join(decision_mod.RULES)))
    tolerance = float(tolerance)
    if not np.isfinite(tolerance) or tolerance <= 0:
        raise InputError("tolerance: must be a positive number of mm, got %r" % (tolerance,))
    if int(min_spot_points) < 1 or int(spot_neighbours) < 1:
        raise InputError("verdict: min_spot_points and spot_neighbours must be at least 1")
    dev = np.asarray(result.deviation, dtype=float)
    out_idx = np.flatnonzero(np.abs(dev) > tolerance)
    labels, sizes = linked_groups(result.points_cad, out_idx, spot_neighbours)
    in_spot = np.zeros(len(dev), dtype=bool)
    in_spot[out_idx] = sizes[labels] >= int(min_spot_points) if len(out_idx) else False
    isolated = out_idx[~in_spot[out_idx]]

    spots = []
    for lab in np.flatnonzero(sizes >= int(min_spot_points)):
        members = out_idx[labels == lab]
        worst = members[np.argmax(np.abs(dev[members]))]
        spots.append((abs(dev[worst]), worst, members))
    spots.sort(key=lambda s: -s[0])
    worst_points = [w for _, w, _ in spots[:n_worst]]
    if worst_points:
        k, pct, zone = place_of(table, result.points_cad[worst_points])
    spot_out = []
    for r, (_, worst, members) in enumerate(spots[:n_worst]):
        sec = table.sections[k[r]] if table.sections else None
        where = "%s at %.0f %% span" % (ZONE_TEXT[zone[r] or ""], pct[r])
        if sec is not None:
            where += " (near section %s)" % sec.label
        spot_out.append({
            "deviation_mm": float(dev[worst]),
            "n_points": int(len(members)),
            "xyz": result.points_cad[worst].tolist(),
            "span_pct": float(pct[r]),
            "section": None if sec is None else sec.label,
            "zone": zone[r] or None,
            "where": where,
            "text": "%+.4f mm over %d points, %s" % (dev[worst], len(members), where),
        })

    sections_out = []
    for sec in table.sections:
        idx = sec.point_index
        counted = idx[~np.isin(idx, isolated)]
        counted_dev = np.abs(dev[counted])
        entry = {"label": sec.label, "n": int(len(idx)),
                 "max_abs_mm": float(counted_dev.max()) if len(counted) else None,
                 "n_isolated_out": int(len(idx) - len(counted)),
                 # None: no measured point near this plane, nothing to judge
                 "pass": bool((counted_dev <= tolerance).all()) if len(idx) else None}
        if len(counted):
            worst = counted[np.argmax(counted_dev)]
            entry["worst_zone"] = sec.zone[np.flatnonzero(idx == worst)[0]] or None
            entry["worst_deviation_mm"] = float(dev[worst])
            # U of a maximum over the section's counted points (uncertainty.worst_terms)
            entry.update(decided(dev[worst], uncertainty_mod.worst_expanded_uncertainty(
                result, counted, measurement_model)[1], tolerance, decision_rule))
        if sec.cmm is not None:
            cmm_abs = np.abs(sec.cmm_deviation)
            entry["cmm_max_abs_mm"] = float(cmm_abs.max()) if len(cmm_abs) else None
            entry["cmm_pass"] = bool(len(cmm_abs) > 0 and (cmm_abs <= tolerance).all())
        sections_out.append(entry)

    for spot, (_, worst, members) in zip(spot_out, spots):
        spot.update(decided(dev[worst], uncertainty_mod.worst_expanded_uncertainty(
            result, members, measurement_model)[1], tolerance, decision_rule))
    # The part's largest deviation among the fit's inliers (what minimax minimises), with its
    # own U and verdict: reported beside the sections'; the part's verdict is theirs and the
    # spots' (a defect the robust fit rejected is a spot, not an inlier).
    inlier = np.asarray(result.inlier, dtype=bool)
    not_isolated = np.ones(len(dev), dtype=bool)
    not_isolated[isolated] = False
    judged = np.flatnonzero(inlier & not_isolated)
    left_out = np.flatnonzero(~inlier & not_isolated)
    part = None
    if len(judged):
        worst = judged[np.argmax(np.abs(dev[judged]))]
        part = {"worst_deviation_mm": float(dev[worst]), "of": "the fit's inliers",
                "xyz": result.points_cad[worst].tolist()}
        # the fit chose its inliers by their measured deviations: U of a censored maximum
        # where it left out readings it could have kept (uncertainty.censored_worst_terms)
        part.update(decided(dev[worst], uncertainty_mod.worst_expanded_uncertainty(
            result, judged, measurement_model, left_out)[1], tolerance, decision_rule))
        part["larger_not_fitted"] = _larger_not_fitted(result, dev, worst, left_out)
    decision = decision_mod.combine([s["verdict"] for s in sections_out if "verdict" in s]
                                    + [s["verdict"] for s in spot_out])
    passed = bool(not spots and all(s["pass"] is not False for s in sections_out)
                  and decision in (decision_mod.PASS, None))
    unmeasured = [s["label"] for s in sections_out if s["pass"] is None]
    n_out = int(len(out_idx))
    if passed:
        summary = "PASS: within +-%.3f mm" % tolerance
        if len(isolated):
            summary += " except %d isolated point(s) treated as sensor outliers" % len(isolated)
    elif decision == decision_mod.NOT_PROVEN:
        not_proven = [s["label"] for s in sections_out
                      if s.get("verdict") == decision_mod.NOT_PROVEN]
        summary = ("NOT PROVEN (%s): a judged deviation lies within its U of +-%.3f mm"
                   % (decision_rule, tolerance))
        if not_proven:
            summary += "; section(s) %s not proven" % ", ".join(not_proven)
        if spot_out:
            summary += "; worst %s" % spot_out[0]["text"]
    else:
        failing = [s["label"] for s in sections_out if s["pass"] is False]
        summary = "FAIL: %d spot(s) outside +-%.3f mm" % (len(spots), tolerance)
        if failing:
            summary += "; section(s) %s out of tolerance" % ", ".join(failing)
        if spot_out:
            summary += "; worst %s" % spot_out[0]["text"]
    if unmeasured:
        summary += "; section(s) %s not measured" % ", ".join(unmeasured)
    return {
        "tolerance_mm": tolerance,
        "pass": passed,
        "summary": summary,
        "n_points_out": n_out,
        "pct_points_out": 100.0 * n_out / max(len(dev), 1),
        "n_spots": len(spots),
        "n_isolated_out": int(len(isolated)),
        "spot_neighbours": int(spot_neighbours),
        "min_spot_points": int(min_spot_points),
        "worst_spots": spot_out,
        "sections": sections_out,
        "decision_rule": decision_rule,
        "decision_rule_text": decision_mod.RULE_TEXT[decision_rule],
        "verdict": decision,
        "part": part,
        "measurement_model": (measurement_model
                              or uncertainty_mod.MeasurementModel()).to_json(),
    }
