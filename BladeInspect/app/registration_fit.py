"""A Registration's fit (issue 16, inspection.fitting): the objective, free degrees of freedom,
region weights, decision rule and the fine ICP's weights (``--weights``) as its inputs, and
the fit record, the fit-sensitivity table and the weights used (result.json's ``fit``,
``fit_sensitivity`` and ``weights``) as read-only results.

A Registration made before these existed, or with the default choice, keeps its input
signature, so opening an older document does not register it again."""

import json

from ..core.contracts import json_default
from ..inspection import fitting, weighting
from ..inspection.fit_report import weights_text

GROUP = "Fit"
# (property, FitChoice field, tooltip); the enumerations list their choices.
TEXT_INPUTS = (("FreeDof", "free", "Free degrees of freedom (--free), empty: all six"),
               ("ZoneWeights", "weights_by_zone",
                "Region weights (--weights-by-zone), e.g. LE=2,TE=2; empty: none"))
# The Weights enumeration's entry for FitChoice.weights None (inspection.weighting's rule).
DEFAULT_WEIGHTS = "default"
WEIGHT_CHOICES = (DEFAULT_WEIGHTS,) + weighting.WEIGHT_MODELS


def add_properties(obj, add):
    """``add``: app.objects._add."""
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
    from . import settings
    from .actions import judge_fits   # actions imports app.objects, which imports this
    judge_fits(result, nominal, choice, settings.value("ToleranceMm"))


def store(obj, result):
    obj.FitJson = json.dumps(result.fit, default=json_default) if result.fit else ""
    obj.FitSensitivityJson = (json.dumps(result.fit_sensitivity, default=json_default)
                              if result.fit_sensitivity else "")
    obj.WeightsJson = (json.dumps(result.weights, default=json_default)
                       if result.weights else "")
    obj.WeightsUsed = weights_text(result.weights)


def weights_record(obj):
    """The weights block the Registration stored (result.json's weights), or None."""
    return json.loads(getattr(obj, "WeightsJson", "") or "null")


def restore(obj, result):
    """Give a RegistrationResult rebuilt from the document (app.objects.registration_result)
    the records it was stored with, so a report of it names the weights used."""
    result.weights = weights_record(obj)


def fit_record(obj):
    return json.loads(getattr(obj, "FitJson", "") or "null")


def sensitivity_of(obj):
    return json.loads(getattr(obj, "FitSensitivityJson", "") or "null")
