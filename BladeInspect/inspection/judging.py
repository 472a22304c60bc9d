"""The step every command takes between a registration and its verdict: move the
result to the chosen fit's pose (inspection.fitting.apply, every objective fitted for the
sensitivity table), tabulate its sections, judge them with the chosen decision rule
(inspection.verdict.judge) and record the fit-sensitivity table. `report`, `inspect` and the
GUI's Register differ only in the section table they judge, which the caller builds."""

from . import fitting
from . import verdict as verdict_mod


def fit_and_judge(result, nominal, fit_choice, tolerance, section_table,
                  measurement_model=None):
    """(table, verdict) of ``result`` at ``fit_choice``'s pose (None: least squares, ISO
    14253-1): ``section_table(result)`` builds the table after the fit has moved the points;
    result.fit and result.fit_sensitivity are recorded on ``result``."""
    fit_choice = fit_choice or fitting.FitChoice()
    runs = fitting.apply(result, nominal, fit_choice, tolerance, all_objectives=True)
    table = section_table(result)
    judge_options = {"measurement_model": measurement_model}
    verdict = verdict_mod.judge(result, table, tolerance=tolerance,
                                decision_rule=fit_choice.decision_rule, **judge_options)
    result.fit_sensitivity = fitting.sensitivity(runs, result, table, tolerance, fit_choice,
                                                 judge_options)
    return table, verdict
