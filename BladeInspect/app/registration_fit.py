"""A Registration's fit (inspection.fitting): the objective, free degrees of freedom,
region weights, decision rule and the fine ICP's weights (``--weights``) as its inputs, and
the fit record, the fit-sensitivity table and the weights used (result.json's ``fit``,
``fit_sensitivity`` and ``weights``) as read-only results.

A Registration made before these existed, or with the default choice, keeps its input
signature, so opening an older document does not register it again."""

import json

import numpy as np

from ..core.contracts import json_default
from ..core.icp import InlierCut, Neighbourhoods
from ..inspection import fitting, weighting
from ..inspection.fit_report import weights_text
from ..inspection.judging import fit_and_judge
from ..inspection.sections import section_table
from . import settings

GROUP = "Fit"
# (property, FitChoice field, tooltip); the enumerations list their choices.
TEXT_INPUTS = (("FreeDof", "free", "Free degrees of freedom (--free), empty: all six"),
               ("ZoneWeights", "weights_by_zone",
                "Region weights (--weights-by-zone), e.g. LE=2,TE=2; empty: none"))
# The Weights enumeration's entry for FitChoice.weights None (inspection.weighting's rule).
DEFAULT_WEIGHTS = "default"
WEIGHT_CHOICES = (DEFAULT_WEIGHTS,) + weighting.WEIGHT_MODELS


def add_properties(obj, add):
    """``add``: app.objects.add_property."""
    for prop, choices, tip in (
            ("Fit", fitting.OBJECTIVE_NAMES, "Fit objective after the robust ICP (--fit)"),
            ("DecisionRule", ("iso14253", "simple"),
             "iso14253: pass / not proven / fail; simple: simple acceptance"),
            ("Weights", WEIGHT_CHOICES,
             "The fine ICP's weights (--weights): snr (the paper's), sensor (the sensor "
             "model's, needs angle_deg); default: " + weighting.DEFAULT_RULE)):
        if prop not in obj.PropertiesList:
            add(obj, "App::PropertyEnumeration", prop, GROUP, tip)
            setattr(obj, prop, list(choices))
    for prop, _, tip in TEXT_INPUTS:
        add(obj, "App::PropertyString", prop, GROUP, tip)
    # What the registration produced: shown but not editable, or kept for the report only.
    for prop, tip, mode in (
            ("WeightsUsed", "The weights the fine ICP used and why (result.json's weights)",
             "read_only"),
            ("WeightsJson", "The weights' record, as result.json's weights", "hidden"),
            ("FitJson", "The fit's record, as result.json's fit", "hidden"),
            ("FitSensitivityJson", "Each judged value and the verdict under each fit "
             "objective (fit_sensitivity)", "hidden")):
        add(obj, "App::PropertyString", prop, GROUP, tip, **{mode: True})
    # Where the fine ICP's weights reach 0 (core.icp.InlierCut), so that a reopened document
    # states the part's worst as the run did (inspection.uncertainty.censored_worst_terms).
    for prop in CUT_ARRAYS:
        add(obj, "App::PropertyFloatList", prop, GROUP,
            "The fine ICP's zero-weight boundaries, per point (core.icp.InlierCut)", hidden=True)
    add(obj, "App::PropertyIntegerList", "InlierCutOrder", GROUP,
        "The fine ICP's defect-test neighbourhoods: the points' order along its curve",
        hidden=True)
    add(obj, "App::PropertyString", "InlierCutJson", GROUP,
        "The fine ICP's per-point and neighbourhood cuts (core.icp.InlierCut)", hidden=True)
    # The fine ICP's final weights: the worst deviations' U (inspection.uncertainty) of a
    # reopened document, or of its section analysis, are then the run's own.
    add(obj, "App::PropertyFloatList", "IcpWeights", GROUP,
        "The fine ICP's final weight of each point", hidden=True)


# InlierCut's per-point arrays as FloatList properties
CUT_ARRAYS = {"InlierCutRoot": "root", "InlierCutLimit": "limit",
              "InlierCutAllowance": "allowance"}


def choice_of(obj):
    """The FitChoice a Registration's inputs name (the default for an older one)."""
    if "Fit" not in obj.PropertiesList:
        return fitting.FitChoice()
    weights = getattr(obj, "Weights", DEFAULT_WEIGHTS)
    return fitting.FitChoice(objective=obj.Fit, free=obj.FreeDof or None,
                             weights_by_zone=obj.ZoneWeights or None,
                             decision_rule=obj.DecisionRule,
                             weights=None if weights == DEFAULT_WEIGHTS else weights)


def set_choice(obj, choice):
    obj.Fit = choice.objective
    obj.DecisionRule = choice.decision_rule
    obj.FreeDof = choice.free or ""
    obj.ZoneWeights = choice.weights_by_zone or ""
    obj.Weights = choice.weights or DEFAULT_WEIGHTS


def register_options(obj):
    """pipeline.register's keywords for the object's choice: the weights when chosen, none
    for the default (the call of a Registration made before weights could be chosen)."""
    weights = choice_of(obj).weights
    return {} if weights is None else {"weights": weights}


def signature_part(obj):
    """() for the default choice (the signature older documents stored), else the choice;
    the weights only when chosen, so a document stored before they were keeps its signature."""
    choice = choice_of(obj)
    if choice == fitting.FitChoice():
        return ()
    part = (choice.objective, choice.free, choice.weights_by_zone, choice.decision_rule)
    return part if choice.weights is None else part + (choice.weights,)


def refit(obj, result, nominal):
    """After a recompute registered again: move ``result`` to the object's fit with its
    sensitivity table, as the Register command did. The default choice is the ICP's pose
    itself; then the recompute stays what it was before fits existed (the table, which
    needs a section cut and every objective's fit, is dropped rather than left stale)."""
    choice = choice_of(obj)
    if choice == fitting.FitChoice():
        return
    judge_fits(result, nominal, choice, settings.value("ToleranceMm"))


def judge_fits(result, nominal, choice, tolerance):
    """Move ``result`` to the chosen fit's pose and record result.fit and result.fit_sensitivity,
    as the `report` command does before it writes (inspection.report.write_result_report)."""
    fit_and_judge(result, nominal, choice, tolerance,
                  lambda fitted: section_table(fitted, nominal))
    return result


def store(obj, result):
    obj.FitJson = json.dumps(result.fit, default=json_default) if result.fit else ""
    obj.FitSensitivityJson = (json.dumps(result.fit_sensitivity, default=json_default)
                              if result.fit_sensitivity else "")
    obj.WeightsJson = (json.dumps(result.weights, default=json_default)
                       if result.weights else "")
    obj.WeightsUsed = weights_text(result.weights)
    cut = getattr(result, "inlier_cut", None)
    for prop, field in CUT_ARRAYS.items():
        values = None if cut is None else getattr(cut, field)
        setattr(obj, prop, [] if values is None else np.asarray(values, dtype=float).tolist())
    if "IcpWeights" in obj.PropertiesList:
        weights = getattr(result, "icp_weights", None)
        obj.IcpWeights = [] if weights is None else np.asarray(weights, dtype=float).tolist()
    hoods = None if cut is None else cut.neighbourhoods
    obj.InlierCutOrder = [] if hoods is None else np.asarray(hoods.order).tolist()
    obj.InlierCutJson = ("" if cut is None else json.dumps(
        {"point_cut": cut.point_cut, "neighbourhood_cut": (
            None if not np.isfinite(cut.neighbourhood_cut) else cut.neighbourhood_cut),
         "neighbourhood_size": None if hoods is None else hoods.size}))


def weights_record(obj):
    """The weights block the Registration stored (result.json's weights), or None."""
    return json.loads(getattr(obj, "WeightsJson", "") or "null")


def restore(obj, result):
    """Give a RegistrationResult rebuilt from the document (app.objects.registration_result)
    the records it was stored with, so a report of it names the weights used."""
    result.weights = weights_record(obj)
    result.inlier_cut = inlier_cut_of(obj, len(result.deviation))
    weights = np.asarray(getattr(obj, "IcpWeights", ()) or (), dtype=float)
    result.icp_weights = weights if len(weights) == len(result.deviation) else None


def inlier_cut_of(obj, n):
    """The core.icp.InlierCut a Registration stored for its ``n`` points, or None (a document
    from before it was stored, or a result without one)."""
    record = json.loads(getattr(obj, "InlierCutJson", "") or "null")
    if not record or len(getattr(obj, "InlierCutRoot", ())) != n:
        return None
    arrays = {field: np.asarray(getattr(obj, prop), dtype=float)
              for prop, field in CUT_ARRAYS.items()}
    with_test = record["neighbourhood_cut"] is not None and len(arrays["limit"]) == n
    order = getattr(obj, "InlierCutOrder", ())
    hoods = (Neighbourhoods.from_order(order, record["neighbourhood_size"])
             if with_test and record.get("neighbourhood_size") and len(order) == n else None)
    return InlierCut(arrays["root"], float(record["point_cut"]),
                     arrays["limit"] if with_test else None,
                     arrays["allowance"] if with_test else None,
                     float(record["neighbourhood_cut"]) if with_test else np.inf, hoods)


def fit_record(obj):
    return json.loads(getattr(obj, "FitJson", "") or "null")


def sensitivity_of(obj):
    return json.loads(getattr(obj, "FitSensitivityJson", "") or "null")
