"""The airfoil stage's verdicts: each characteristic's deviation judged against its tolerance
row under the decision rule (U = k u, core.decision), the stage's verdict over the sections,
and the airfoil rows of the fit-sensitivity table (every measured characteristic judged under
each fit objective's pose).
"""

import dataclasses

import numpy as np

from ..core import background
from ..core import decision as decision_mod
from ..core import transforms as tf
from ..core.errors import InputError
from .airfoil_measure import measure_at, section_points
from .airfoil_values import SCALARS, base_name, char_values, flat, unflat, withheld_values


def _tolerance_for(tolerances, label, key):
    """The most specific row for (section, characteristic): a named section before all, an
    element name[i] before the whole list."""
    base = base_name(key)
    best, rank = None, -1
    for t in tolerances:
        if t.section != label and t.section.lower() != "all":
            continue
        if t.characteristic != key and t.characteristic != base:
            continue
        r = (2 if t.section == label else 0) + (1 if t.characteristic == key else 0)
        if r > rank:
            best, rank = t, r
    return best


# Expanded uncertainty of a judged characteristic: k times its standard uncertainty (the
# ``uncertainty`` block, by re-fitting perturbed points).
COVERAGE_FACTOR = 2.0
# A characteristic judged with no stated uncertainty (Options.draws = 0) is decided by simple
# acceptance, and says so: the ISO rule needs a U.
NO_U_RULE = "simple"
JUDGED = (decision_mod.PASS, decision_mod.FAIL, decision_mod.NOT_PROVEN, "not measured")


def decision(deviation, u, t, rule):
    """The decision on one characteristic's deviation against its tolerance row: U = k u under
    ``rule``; without u, simple acceptance (NO_U_RULE), named in the result."""
    if u is not None and np.isfinite(u):
        U, used = COVERAGE_FACTOR * float(u), rule
    else:
        U, used = None, NO_U_RULE
    d = decision_mod.decide(deviation, 0.0 if U is None else U, t.lower, t.upper, rule=used)
    tur = d.test_uncertainty_ratio
    return {"verdict": d.verdict, "rule": used, "U": U, "k": COVERAGE_FACTOR,
            "tur": None if tur is None or not np.isfinite(tur) else float(tur)}


def judge(block, tolerances, measured_part=True, rule="iso14253"):
    """Deviation, tolerance and verdict of each characteristic of one section block (the
    decision rule ``rule`` with U = k u, core.decision); returns (the keys that failed, the
    keys not proven)."""
    if block["nominal"] is None:
        block.update(tolerance={}, verdicts={}, decisions={}, verdict="not measured")
        return [], []
    nominal = flat(block["nominal"])
    measured = flat(block["measured"]) if block["measured"] else {}
    sd = flat(block["uncertainty"]) if block.get("uncertainty") else {}
    deviation, tol_out, verdicts, decisions, failed, unproven = {}, {}, {}, {}, [], []
    # A toleranced characteristic the CAD has no value for (a corner's edge radius) is judged
    # against the drawing's nominal if the row gives one, else cannot be signed off.
    keys = list(nominal) + [k for k in SCALARS if k not in nominal
                            and _tolerance_for(tolerances, block["label"], k) is not None]
    for key in keys:
        t = _tolerance_for(tolerances, block["label"], key)
        if t is not None and t.nominal is not None:
            nominal[key] = t.nominal
        elif key not in nominal:
            judged = measured_part and (t.lower is not None or t.upper is not None)
            tol_out[key] = {"lower": t.lower, "upper": t.upper, "row": t.row}
            verdicts[key] = "not measured" if judged else "not judged"
            if judged:
                failed.append(key + " (no nominal: not a rounded edge on the CAD)")
            continue
        if key in measured:
            deviation[key] = measured[key] - nominal[key]
        if t is None or (t.lower is None and t.upper is None):
            verdicts[key] = "not judged"
            continue
        tol_out[key] = {"lower": t.lower, "upper": t.upper, "row": t.row}
        if not measured_part:
            verdicts[key] = "not judged"
            continue
        if key not in deviation:
            verdicts[key] = "not measured"
            if _withheld(block, key):
                # withheld for a stated reason (too few points at its edge): not signed off,
                # and not failed on a number that was never read
                unproven.append(key + " (not measured)")
            else:
                # a toleranced characteristic that could not be measured cannot be signed off
                failed.append(key + " (not measured)")
            continue
        decisions[key] = decision(deviation[key], sd.get(key), t, rule)
        verdicts[key] = decisions[key]["verdict"]
        if verdicts[key] == decision_mod.FAIL:
            failed.append(key)
        elif verdicts[key] == decision_mod.NOT_PROVEN:
            unproven.append(key)
    like = block["nominal"]
    block["nominal"] = dict(like, **{k: v for k, v in unflat(nominal, like).items()})
    block["deviation"] = unflat(deviation, like) if measured else None
    block["tolerance"] = tol_out
    block["verdicts"] = verdicts
    block["decisions"] = decisions
    judged = combinable(block)
    block["verdict"] = decision_mod.combine(judged) if judged else "not judged"
    return failed, unproven


def _withheld(block, key):
    withheld = block.get("withheld") or {}
    return key in withheld or base_name(key) in withheld


def combinable(block):
    """The block's judged verdicts as core.decision combines them: a toleranced value not
    measured fails, unless it was withheld for a stated reason (the block's ``withheld``):
    then it is not proven -- a verdict never passes or fails on a withheld value."""
    out = []
    for key, v in (block.get("verdicts") or {}).items():
        if v not in JUDGED:
            continue
        if v == "not measured":
            v = decision_mod.NOT_PROVEN if _withheld(block, key) else decision_mod.FAIL
        out.append(v)
    return out


def stage_verdict(results, failed, unproven):
    """airfoil_verdict: pass only when every judged characteristic passed (None when nothing
    is judged); ``verdict`` core.decision's combined pass / not proven / fail."""
    n_judged = sum(v in JUDGED for r in results for v in r.block["verdicts"].values())
    combined = (None if n_judged == 0 else decision_mod.FAIL if failed else
                decision_mod.NOT_PROVEN if unproven else decision_mod.PASS)
    if n_judged == 0:
        summary = "airfoil: no characteristic toleranced"
    elif failed:
        summary = "airfoil: FAIL %d of %d: %s" % (len(failed), n_judged, "; ".join(failed))
    elif unproven:
        summary = "airfoil: NOT PROVEN %d of %d: %s" % (len(unproven), n_judged,
                                                        "; ".join(unproven))
    else:
        summary = "airfoil: PASS (%d characteristics)" % n_judged
    return {"pass": None if n_judged == 0 else combined == decision_mod.PASS,
            "verdict": combined, "n_judged": n_judged, "failed": failed,
            "not_proven": unproven, "summary": summary}


def check_sections(opts, planes):
    """A tolerance row's section must be one of the planes' labels (or all)."""
    labels = {p.label for p in planes}
    for t in opts.tolerances:
        if t.section.lower() != "all" and t.section not in labels:
            raise InputError("%s: row %d: section %r is not one of the sections (%s)"
                             % (opts.characteristics_file, t.row, t.section,
                                ", ".join(sorted(labels))))


UNITS = {"deg": "deg", "pct": "%", "mm2": "mm2", "mm": "mm"}


def _unit_of(key):
    base = base_name(key)
    return next(UNITS[u] for u in ("deg", "pct", "mm2", "mm") if base.endswith("_" + u))


def add_to_sensitivity(doc, stage, result, opts):
    """The airfoil characteristics as rows of ``fit_sensitivity`` (inspection.fitting): every
    measured characteristic's deviation and verdict under each fit objective, re-measured from
    the points moved by that objective's motion (``cad_motion_by_fit``, from the least-squares
    start; the result stands at the chosen one's). U is the chosen fit's (the measurement's,
    about the same under every pose). ``largest_change_airfoil`` names the row whose change
    across the fits is largest in units of its U (k = 2), and ``airfoil_verdict_by_fit`` the
    airfoil verdict under each fit."""
    motions = doc.get("cad_motion_by_fit")
    if not motions:
        return
    chosen = np.asarray(motions[doc["chosen"]], dtype=float)
    back = np.linalg.inv(chosen)
    per_fit = {}
    quiet = dataclasses.replace(opts, draws=0)
    for objective in doc["objectives"]:
        if objective == doc["chosen"]:
            per_fit[objective] = {r.plane.label: r.block for r in stage.sections}
            continue
        move = np.asarray(motions[objective], dtype=float) @ back
        if np.allclose(move, np.eye(4), atol=1e-15):
            per_fit[objective] = {r.plane.label: r.block for r in stage.sections}
            continue
        view = dataclasses.replace(result, points_cad=tf.apply_transform(move, result.points_cad))
        blocks = {}
        for r in stage.sections:
            if r.measured is None:
                continue
            idx = section_points(r.plane, stage.counted)
            try:
                # numpy and scipy only: beside a GUI's event loop (core.background)
                ch, fit, cont, _, noise = background.run(lambda: measure_at(
                    view.points_cad[idx], view.normal[idx], r.frame, r.nominal, quiet))
            except InputError:
                continue
            b = {"label": r.block["label"], "nominal": dict(r.block["nominal"]),
                 "measured": char_values(ch, r.frame, fit, cont),
                 "withheld": withheld_values(ch, noise),
                 "uncertainty": r.block.get("uncertainty")}
            judge(b, opts.tolerances, True, opts.decision_rule)
            blocks[r.plane.label] = b
        per_fit[objective] = blocks
    rows, largest = [], None
    for r in stage.sections:
        label = r.plane.label
        base = per_fit[doc["chosen"]].get(label)
        if base is None or not base.get("deviation"):
            continue
        for key in flat(base["deviation"]):
            cells = {}
            for objective in doc["objectives"]:
                b = per_fit[objective].get(label)
                dev = flat(b["deviation"]).get(key) if b and b.get("deviation") else None
                d = (b or {}).get("decisions", {}).get(key, {})
                cells[objective] = {"value": dev, "U": d.get("U"),
                                    "verdict": (b or {}).get("verdicts", {}).get(key)}
            values = [c["value"] for c in cells.values() if c["value"] is not None]
            change = float(max(values) - min(values)) if values else 0.0
            row = {"characteristic": "section %s %s" % (label, key), "unit": _unit_of(key),
                   "by_fit": cells, "change": change, "airfoil": True}
            rows.append(row)
            u = flat(base.get("uncertainty") or {}).get(key)
            if u:
                score = change / (COVERAGE_FACTOR * u)
                if largest is None or score > largest["change_over_U"]:
                    largest = {"characteristic": row["characteristic"], "change": change,
                               "unit": row["unit"], "change_over_U": float(score)}
    doc["rows"] = doc["rows"] + rows
    # what completes these rows' display names (inspection.characteristic_names)
    doc["airfoil_definitions"] = {
        "chord_method": opts.definition.chord_method,
        "edge_offsets_mm": [float(x) for x in opts.definition.edge_offsets_mm]}
    doc["largest_change_airfoil"] = largest
    doc["largest_change_airfoil_rule"] = ("the airfoil row whose change across the fits is "
                                          "largest in units of its U (k = 2); none when no "
                                          "u is stated")
    by_fit = {}
    for objective, blocks in per_fit.items():
        by_fit[objective] = decision_mod.combine(
            [v for b in blocks.values() for v in combinable(b)])
    doc["airfoil_verdict_by_fit"] = by_fit
