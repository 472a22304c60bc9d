"""The report's airfoil pages: per section a characteristics table (nominal, actual,
deviation, +-u, tolerance, verdict) and a figure of the profile with its mean camber line, a
few inscribed circles, the LE/TE circles and the chord line; then shift and twist along the
span. Drawn from the stage inspection.airfoil_stage attached to the section table."""

import html
import textwrap

import numpy as np

from ..core import background
from . import airfoil_values as values
from . import characteristic_names
from .report_table import TableStyle, html_table, img_tag, mpl, pdf_table, png_bytes

# Inscribed circles drawn per profile besides the largest one.
N_CIRCLES = 5
TABLE_HEADER = ["Characteristic", "Unit", "Nominal", "Actual", "Deviation", "+-u (1 sigma)",
                "U (k=2)", "Tolerance", "Verdict"]
# Column widths on the page (fractions of the table's): the names need about a quarter.
TABLE_WIDTHS = [0.24, 0.07, 0.09, 0.09, 0.09, 0.09, 0.08, 0.14, 0.11]


def _num(v, key, sign=""):
    # mm to 0.1 um, degrees to 0.1 mdeg, per cent of chord to 0.001 %
    return "-" if v is None else ("%" + sign + (".3f" if "_pct" in key else ".4f")) % v


def characteristics_rows(block):
    """One row per characteristic of one section block, by its display name and unit."""
    if block["nominal"] is None:
        return []
    nom = values.flat(block["nominal"])
    mea = values.flat(block["measured"]) if block["measured"] else {}
    dev = values.flat(block["deviation"]) if block.get("deviation") else {}
    unc = values.flat(block["uncertainty"]) if block.get("uncertainty") else {}
    rows = []
    for key in list(nom) + [k for k in block["verdicts"] if k not in nom]:   # as csv_rows
        t = block["tolerance"].get(key)
        tol = "-" if t is None else "%s .. %s" % (
            "-inf" if t["lower"] is None else "%+g" % t["lower"],
            "+inf" if t["upper"] is None else "%+g" % t["upper"])
        decision = (block.get("decisions") or {}).get(key, {})
        rows.append([characteristic_names.display_name(key, block["nominal"]),
                     characteristic_names.unit(key), _num(nom.get(key), key), _num(mea.get(key), key),
                     _num(dev.get(key), key, "+"),
                     _num(unc.get(key), key), _num(decision.get("U"), key), tol,
                     block["verdicts"].get(key, "-")])
    return rows


def _circle(ax, centre, radius, **style):
    t = np.linspace(0.0, 2.0 * np.pi, 200)
    ax.plot(centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t), **style)


def figure_profile(section):
    """The nominal profile in its plane frame (x along the engine axis), the measured points
    when there are any, the camber line, inscribed circles, edge circles and the chord."""
    plt, _, _ = mpl()
    ch = section.nominal
    loop = np.vstack([ch.profile.dense, ch.profile.dense[:1]])
    # the figure takes the profile's proportions, so equal axes leave no empty band
    height = float(np.clip(10.0 * np.ptp(loop[:, 1]) / max(np.ptp(loop[:, 0]), 1e-6) + 1.6,
                           3.0, 9.0))
    fig, ax = plt.subplots(figsize=(11.0, height))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.8 / height, top=1 - 0.45 / height)
    ax.plot(loop[:, 0], loop[:, 1], color="0.15", linewidth=1.0, label="nominal profile")
    if section.points_2d is not None:
        ax.plot(section.points_2d[:, 0], section.points_2d[:, 1], ".", color="#1f77b4",
                markersize=1.0, label="measured points")
    mcl = ch.mcl.sample(300)
    ax.plot(mcl[:, 0], mcl[:, 1], color="#d62728", linewidth=0.9, label="mean camber line")
    pick = np.linspace(0, len(ch.inscribed_radii) - 1, N_CIRCLES + 2).astype(int)[1:-1]
    for k in pick:
        _circle(ax, ch.inscribed_centres[k], ch.inscribed_radii[k], color="#ff7f0e",
                linewidth=0.6)
    _circle(ax, ch.max_thickness_center, ch.max_thickness_mm / 2.0, color="#ff7f0e",
            linewidth=1.1, linestyle="--")
    for name, circle in ch.edge_circles():   # none for a withheld (corner) edge
        _circle(ax, circle.center, circle.radius, color="#2ca02c", linewidth=1.1)
        ax.annotate("%s r = %.4f" % (name, circle.radius), circle.center, fontsize=7,
                    xytext=(4, 8), textcoords="offset points")
    ax.plot([ch.le_point[0], ch.te_point[0]], [ch.le_point[1], ch.te_point[1]], color="0.4",
            linewidth=0.8, linestyle=":", label="%s chord" % "nose-tail")
    ax.set_aspect("equal")
    ax.set_xlabel("along the engine axis in the section plane (mm)")
    ax.set_ylabel("mm")
    ax.legend(fontsize=7, loc="best")
    ax.set_title("Section %s (%.1f %% span): MCL, inscribed circles (dashed: the largest), "
                 "edge circles, chord" % (section.plane.label, section.plane.height_pct),
                 fontsize=10)
    return fig


def figure_span(stage):
    """Shift (both components, um) and twist (mdeg) of each measured section along the span."""
    plt, _, _ = mpl()
    measured = [s for s in stage.sections if s.fit is not None]
    h = [s.plane.height_pct for s in measured]
    shift = np.array([s.fit.shift_mm for s in measured]).reshape(-1, 2) * 1000.0
    twist = np.array([s.fit.twist_deg for s in measured]) * 1000.0
    unc = [s.block.get("uncertainty") or {} for s in measured]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11.0, 4.2))
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.14, top=0.88, wspace=0.25)
    for i, name in enumerate(("x (engine axis)", "y")):
        err = [1000.0 * (u.get("shift_mm") or [0.0, 0.0])[i] or 0.0 for u in unc]
        a.errorbar(h, shift[:, i], yerr=err, marker="o", capsize=3, label="shift " + name)
    a.axhline(0.0, color="0.6", linewidth=0.6)
    a.set_xlabel("span %")
    a.set_ylabel("shift (um)")
    a.legend(fontsize=8)
    b.errorbar(h, twist, yerr=[1000.0 * (u.get("twist_deg") or 0.0) for u in unc], marker="o",
               capsize=3, color="#d62728")
    b.axhline(0.0, color="0.6", linewidth=0.6)
    b.set_xlabel("span %")
    b.set_ylabel("twist (mdeg)")
    lb = stage.lean_bow
    fig.suptitle("Section position along the span (error bars 1 sigma)" + (
        "; lean %.4f deg, largest bow: section %s (%.1f um)"
        % (lb["lean_deg"], lb["largest_bow_section"], 1000.0 * max(lb["bow_magnitude_mm"]))
        if lb else ""), fontsize=10)
    return fig


def add_pages(pdf, parts, table):
    """The airfoil pages into the open PdfPages and the HTML parts; returns the page count
    (0 when no airfoil stage was attached to the table)."""
    stage = getattr(table, "airfoil", None)
    if stage is None:
        return 0
    plt, _, _ = mpl()
    pages = 0
    parts += ["<h2>Airfoil characteristics</h2>",
              "<p>%s</p>" % html.escape(characteristic_names.airfoil_verdict_text(
                  stage.verdict, stage.blocks)),
              "<p class='note'>Definitions: docs/user-guide.md; chord %s; angles from the engine "
              "axis %s; LE: %s; uncertainty: %s, %s. Tolerances limit the deviation; "
              "decision rule: %s (%s).</p>"
              % (html.escape(stage.settings["chord_method"]),
                 html.escape(str(stage.settings["engine_axis"])),
                 html.escape(stage.settings["le_rule_meaning"]),
                 html.escape(stage.settings["uncertainty_coverage"]),
                 html.escape(stage.settings["uncertainty_method"]),
                 html.escape(stage.settings["decision_rule_text"]),
                 html.escape(stage.settings["decision_without_u"]))]
    for section in stage.sections:
        block = section.block
        rows = characteristics_rows(block)
        parts += ["<h3>Section %s (%.1f %% span): %s</h3>"
                  % (html.escape(block["label"]), block["height_pct"],
                     html.escape(block.get("verdict", "-"))),
                  html_table(TABLE_HEADER, rows)]
        if block.get("summary"):
            parts.append("<p><b>%s</b></p>" % html.escape(block["summary"]))
        parts += ["<p class='note'>%s</p>" % html.escape(n) for n in block.get("notes", [])]
        if section.nominal is None:
            continue
        fig = plt.figure(figsize=(8.27, 11.69))
        pdf_table(fig, [0.04, 0.04, 0.92, 0.9], TABLE_HEADER,
                  rows or [["-"] * len(TABLE_HEADER)],
                  TableStyle(6.5, title_size=10, loc="upper center", col_widths=TABLE_WIDTHS),
                  title="Airfoil characteristics, section %s (%.1f %% span): %s%s"
                  % (block["label"], block["height_pct"], block.get("verdict", "-"),
                     "\n" + textwrap.fill(block["summary"], 100) if block.get("summary")
                     else ""))
        pdf.savefig(fig)
        plt.close(fig)
        fig = figure_profile(section)
        parts.append(img_tag(png_bytes(fig), "section %s airfoil" % block["label"]))
        pdf.savefig(fig)
        plt.close(fig)
        pages += 2
        background.check()    # a cancelled report stops between sections
    if stage.lean_bow is not None:
        fig = figure_span(stage)
        parts += ["<h3>Shift and twist along the span</h3>",
                  img_tag(png_bytes(fig), "shift and twist")]
        pdf.savefig(fig)
        plt.close(fig)
        pages += 1
    return pages
