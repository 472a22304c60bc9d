"""The report's decision, uncertainty and fit pages: the decision rule, U and the
test uncertainty ratio of every judged value, the fit used and the fit-sensitivity table."""

import html

from ..core import decision as decision_mod
from . import characteristic_names, fitting
from .report_table import PORTRAIT, TableStyle, pdf_table_pages, rows_that_fit

VERDICT_WORD = {decision_mod.PASS: "PASS", decision_mod.NOT_PROVEN: "NOT PROVEN",
                decision_mod.FAIL: "FAIL"}


def verdict_word(verdict):
    """PASS, NOT PROVEN or FAIL: the decision rule's verdict, else today's pass/fail."""
    if verdict.get("verdict") in VERDICT_WORD:
        return VERDICT_WORD[verdict["verdict"]]
    return "PASS" if verdict["pass"] else "FAIL"


def _u(value):
    return "-" if value is None else "%.4f" % value


def decision_rows(verdict):
    """(header, rows): each judged value with its U (k = 2), TUR and verdict."""
    header = ["judged value", "deviation (mm)", "U, k=2 (mm)", "TUR (T/U)", "verdict"]
    rows = []
    for s in verdict["sections"]:
        if "verdict" in s:
            rows.append(["section %s worst" % s["label"], "%+.4f" % s["worst_deviation_mm"],
                         _u(s["U_mm"]), _u(s["tur"]), s["verdict"]])
    for k, spot in enumerate(verdict["worst_spots"]):
        if "verdict" in spot:
            rows.append(["spot %d worst" % (k + 1), "%+.4f" % spot["deviation_mm"],
                         _u(spot["U_mm"]), _u(spot["tur"]), spot["verdict"]])
    part = verdict.get("part")
    if part:
        rows.append(["part worst inlier (reported)", "%+.4f" % part["worst_deviation_mm"],
                     _u(part["U_mm"]), _u(part["tur"]), part["verdict"]])
        larger = part.get("larger_not_fitted")
        if larger:
            rows.append(["  %d reading(s) the fit left out lie beyond it, up to"
                         % larger["n"], "%+.4f" % larger["worst_deviation_mm"], "", "",
                         "not fitted"])
    return header, rows


def model_lines(verdict):
    model = verdict.get("measurement_model") or {}
    return ["%s: %s" % (k, model[k]) for k in ("noise", "systematic", "pose", "calibration",
                                               "fit") if k in model]


def weights_text(record):
    """One line naming the fine ICP's weights (result.json's ``weights``) and why they were
    chosen; "" for none."""
    if not record:
        return ""
    return "%s, noise along the normal %s; %s" % (
        record["model"], record.get("normal_noise", "?"), record.get("chosen_by", "?"))


def fit_lines(result):
    weights = weights_text(getattr(result, "weights", None))
    lines = ["ICP weights: " + weights] if weights else []
    fit = result.fit
    if not fit:
        return lines
    lines += ["objective %s, free %s, region weights %s; start: %s"
             % (fit["objective"], fit["free"] if isinstance(fit["free"], str)
                else ",".join(fit["free"]), fit.get("weights_by_zone") or "none", fit["start"])]
    if fit.get("margin_mm") is not None:
        lines.append("fit to +-%.3f mm: %s, margin %+.4f mm%s"
                     % (fit["tolerance_mm"], "fits" if fit["fits"] else "does not fit",
                        fit["margin_mm"], "" if fit["fits"] else
                        ", least violation %.4f mm" % fit["violation_mm"]))
    if fit.get("zone_rule"):
        lines.append("zones: %s %s" % (fit["zone_rule"], fit.get("zone_counts")))
    size = fit.get("size_deviation")
    if size:
        lines.append("size deviation (uniform offset along the normals, + oversize): %+.4f mm, "
                     "U (k=%g) %s mm" % (size["value_mm"], size["k"], _u(size["U_mm"])))
    take_up = fit.get("size_take_up")
    if take_up:
        lines.append("size take-up: " + take_up["note"])
    return lines


def html_parts(result, verdict, table_html):
    """HTML of the decision and fit sections; ``table_html(header, rows)`` the report's table."""
    parts = ["<h2>Decision rule and uncertainty</h2>",
             "<p>%s</p>" % html.escape(verdict.get("decision_rule_text", ""))]
    header, rows = decision_rows(verdict)
    parts.append(table_html(header, rows))
    parts.append("<ul>" + "".join("<li>%s</li>" % html.escape(x) for x in model_lines(verdict))
                 + "</ul>")
    lines = fit_lines(result)
    if lines:
        parts += ["<h2>Fit</h2>", "<ul>" + "".join("<li>%s</li>" % html.escape(x)
                                                  for x in lines) + "</ul>"]
    if result.fit_sensitivity:
        s = result.fit_sensitivity
        header, rows = fitting.report_rows(s)
        largest = s["largest_change"]
        parts += ["<h2>Fit sensitivity</h2>", table_html(header, rows),
                  "<p>Largest change: %s, %.4f mm between objectives.%s</p>" % (
                      html.escape(characteristic_names.sensitivity_row_name(largest)),
                      largest["change_mm"],
                      " The verdict depends on the fit." if s["verdict_changes"] else "")
                  if largest else ""]
        if any(r.get("side_changes") for r in s["rows"]):
            parts.append("<p class='note'>%s</p>" % html.escape(fitting.SIDE_NOTE))
    return parts


def pdf_pages(plt, result, verdict):
    """A4 pages: the decision table, the measurement model, the fit and its sensitivity, each
    table continued on further pages rather than cut off."""
    fig = plt.figure(figsize=PORTRAIT)
    fig.text(0.06, 0.95, "Decision rule, uncertainty and fit", fontsize=14, weight="bold")
    y = 0.92
    for line in [verdict.get("decision_rule_text", "")] + model_lines(verdict) + \
            fit_lines(result):
        fig.text(0.06, y, line, fontsize=7, wrap=True)
        y -= 0.02
    sensitivity = (fitting.report_rows(result.fit_sensitivity) if result.fit_sensitivity
                   else None)
    header, rows = decision_rows(verdict)
    bottom = 0.5 if sensitivity else 0.05
    rect = [0.06, bottom, 0.88, max(0.05, y - bottom - 0.02)]
    pages = [fig]
    if rows:
        pages += pdf_table_pages(plt, header, rows, TableStyle(7), None, first=(fig, rect))
    if sensitivity:
        header, rows = sensitivity
        # the names (about 35 characters) a third of the width, the objectives share the rest
        n_fits = len(header) - 3
        style = TableStyle(6.5, col_widths=[0.32, 0.06] + [0.54 / n_fits] * n_fits + [0.08])
        lower = [0.06, 0.05, 0.88, 0.4]
        # on the first page when it all fits there, else on pages of its own
        first = (pages[-1], lower) if len(pages) == 1 and \
            len(rows) <= rows_that_fit(fig, lower) else None
        if any(r[-1].endswith(fitting.SIDE_MARK) for r in rows):
            title = ("Fit sensitivity (*: the worst deviation changes side; the change is of "
                     "its size)")
        else:
            title = "Fit sensitivity"
        pages += pdf_table_pages(plt, header, rows, style, title, first=first)
    return pages
