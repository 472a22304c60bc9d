"""The inspection report (paper 4.2-4.3, Tables 2-3, Figs 8-12): one self-contained report.html
(figures embedded as base64 PNG) and the same content as a multi-page report.pdf.

Contents: the verdict, the pose and its uncertainty, three views of the colour-mapped points
with a legend, the deviation histogram with +-sigma and +-3 sigma, the Table 3 band table, the
Table 2 section table (with CMM columns when a CMM file was given) and one whisker plot per
section (nominal profile, deviations drawn along the normal, magnified).

Figures are drawn once with matplotlib's Agg backend and saved to both files, so the HTML and
the PDF cannot disagree. ``run_report`` is the whole `report` command.
"""

import datetime
import html
import os
import time

import numpy as np

from ..core import background, colourmap, contracts
from ..core import stats as stats_mod
from . import airfoil_stage as airfoil_mod
from . import airfoil_report
from . import characteristic_names
from . import pipeline
from . import sections as sections_mod
from . import fit_report
from . import judging
from . import verdict as verdict_mod
from .checks import check_out_dir
from .report_table import TableStyle, html_table, img_tag, mpl, pdf_table, png_bytes
from .result import rival_lines
from .run_options import ReportSources, RunOptions

# Enough points for a faithful picture; more only costs time and PDF size.
MAX_VIEW_POINTS = 120000
MAX_WHISKERS = 1500
PDF_DPI = 150
# The PDF's first page lists at most this many planning notes (the HTML has them all).
MAX_PDF_NOTES = 8

PAGE_TITLES = ("Summary", "Decision rule, uncertainty and fit", "Deviation map",
               "Deviation histogram (Table 3)", "Section profile errors (Table 2)")


def _cmap_and_norm(limit):
    _, ListedColormap, Normalize = mpl()
    return ListedColormap(colourmap.colourmap_table(), name="bladeinspect"), \
        Normalize(-limit, limit)


def _add_legend(fig, ax_or_axes, limit, label="deviation (mm), + outside material", cax=None):
    from matplotlib.cm import ScalarMappable
    cmap, norm = _cmap_and_norm(limit)
    mappable = ScalarMappable(norm=norm, cmap=cmap)
    if cax is not None:
        bar = fig.colorbar(mappable, cax=cax)
    else:
        bar = fig.colorbar(mappable, ax=ax_or_axes, fraction=0.035, pad=0.02)
    values, _ = colourmap.legend_ticks(limit)
    bar.set_ticks(values)
    bar.set_ticklabels(["%+.3f" % v if v else "0" for v in values])
    bar.set_label(label)
    return bar


# ---------------------------------------------------------------- figures

def _view_frame(result, table):
    """Three orthonormal directions: span (hub->tip), chord of the mid-span section and the
    direction from the pressure to the suction side, so the views face the blade squarely."""
    span = table.span_axis
    mid = None
    with_profile = [s for s in table.sections if s.profile is not None]
    if with_profile:
        mid = with_profile[len(with_profile) // 2].profile
    if mid is not None:
        chord = mid.chord_dir - (mid.chord_dir @ span) * span
    else:
        d = result.points_cad - result.points_cad.mean(axis=0)
        d -= np.outer(d @ span, span)
        chord = np.linalg.svd(d, full_matrices=False)[2][0]
    chord /= np.linalg.norm(chord)
    across = np.cross(span, chord)
    if mid is not None and mid.side_tree is not None:
        suction = mid.side_label == "suction"
        if suction.any() and (~suction).any():
            cross_coord = mid.side_tree.data[:, 1]
            to_suction = np.sign(cross_coord[suction].mean() - cross_coord[~suction].mean())
            if (across @ mid.cross_dir) * to_suction < 0:
                across = -across
    return span, chord, across


def raster_view(xyz, colours, right, up, toward_viewer, px_per_mm, splat=1):
    """An orthographic z-buffered picture of coloured points: (RGBA image (H, W, 4), extent
    (left, right, bottom, top) in mm). Each point covers a (2 splat + 1)^2 pixel square and
    the point nearest the viewer wins a pixel, so the visible surface hides the far one; a
    numpy sort, not a plotting call per point, so a full blade draws in a fraction of a
    second."""
    u, v, depth = xyz @ right, xyz @ up, xyz @ toward_viewer
    pad = (splat + 1) / px_per_mm
    u0, v1 = u.min() - pad, v.max() + pad
    width = int(np.ceil((u.max() + pad - u0) * px_per_mm)) + 1
    height = int(np.ceil((v1 - (v.min() - pad)) * px_per_mm)) + 1
    col = np.floor((u - u0) * px_per_mm).astype(np.int64)
    row = np.floor((v1 - v) * px_per_mm).astype(np.int64)
    offsets = np.arange(-splat, splat + 1)
    pix, dep, src = [], [], []
    for dr in offsets:
        for dc in offsets:
            pix.append((row + dr) * width + (col + dc))
            dep.append(depth)
            src.append(np.arange(len(xyz)))
    pix, dep, src = np.concatenate(pix), np.concatenate(dep), np.concatenate(src)
    order = np.lexsort((dep, pix))
    pix, src = pix[order], src[order]
    last = np.r_[pix[1:] != pix[:-1], True]       # nearest point of each pixel
    image = np.ones((height * width, 4))
    image[:, 3] = 0.0
    image[pix[last], :3] = colours[src[last]]
    image[pix[last], 3] = 1.0
    extent = (u0, u0 + width / px_per_mm, v1 - height / px_per_mm, v1)
    return image.reshape(height, width, 4), extent


def figure_views(result, table, limit, max_points=MAX_VIEW_POINTS, seed=0):
    """Three orthographic views of the points coloured by deviation, with the colour legend."""
    plt, _, _ = mpl()
    xyz = result.points_cad
    dev = result.deviation
    if len(xyz) > max_points:
        keep = np.sort(np.random.default_rng(seed).choice(len(xyz), max_points, replace=False))
        xyz, dev = xyz[keep], dev[keep]
    span, chord, across = _view_frame(result, table)
    colours = colourmap.deviation_colours(dev, limit)
    # (title, right, up, toward the viewer), each right-handed so no view is mirrored
    views = (("suction side", -chord, span, across),
             ("pressure side", chord, span, -across),
             ("from the tip", chord, across, span))
    fig, axes = plt.subplots(1, 3, figsize=(13, 5.2),
                             gridspec_kw={"width_ratios": [1, 1, 1.2]})
    fig.subplots_adjust(left=0.04, right=0.88, bottom=0.1, top=0.88, wspace=0.25)
    extent_mm = np.ptp(xyz @ np.column_stack([chord, span, across]), axis=0).max()
    px_per_mm = 900.0 / max(extent_mm, 1e-6)
    for ax, (title, right, up, toward_viewer) in zip(axes, views):
        image, extent = raster_view(xyz, colours, right, up, toward_viewer, px_per_mm)
        ax.imshow(image, extent=extent, interpolation="antialiased")
        ax.set_title(title)
        ax.set_xlabel("mm")
        ax.tick_params(labelsize=8)
    cax = fig.add_axes([0.91, 0.12, 0.015, 0.74])
    _add_legend(fig, None, limit, cax=cax)
    fig.suptitle("Deviation map: %d points, colours saturate at +-%.3f mm"
                 % (len(result.deviation), limit))
    return fig


def figure_histogram(result, band_edges):
    """Histogram of the deviations with mean +-sigma and +-3 sigma (Fig. 12) and the tolerance
    bands' edges (tolerance_histogram)."""
    plt, _, _ = mpl()
    dev = result.deviation
    stats = result.deviation_stats
    mean, sigma = stats["mean"], stats["std"]
    lo = min(np.percentile(dev, 0.05), mean - 4 * sigma, band_edges[0] * 1.2)
    hi = max(np.percentile(dev, 99.95), mean + 4 * sigma, band_edges[-1] * 1.2)
    bins = np.linspace(lo, hi, 121)
    counts, edges = np.histogram(np.clip(dev, lo, hi), bins=bins)
    centres = 0.5 * (edges[:-1] + edges[1:])
    limit = max(abs(band_edges[0]), abs(band_edges[-1]))
    fig, ax = plt.subplots(figsize=(10, 4.8))
    fig.subplots_adjust(left=0.08, right=0.97, bottom=0.12, top=0.9)
    ax.bar(centres, counts, width=np.diff(edges),
           color=colourmap.deviation_colours(centres, limit), edgecolor="none")
    top = counts.max() if len(counts) else 1
    for k, style, name in ((1, "--", "sigma"), (3, ":", "3 sigma")):
        for sign in (-1, 1):
            ax.axvline(mean + sign * k * sigma, color="black", linestyle=style, linewidth=1.2)
        pct = stats["pct_within_1sigma" if k == 1 else "pct_within_3sigma"]
        ax.text(mean + k * sigma, top * (0.95 if k == 1 else 0.8),
                " +-%s: %.2f %%" % (name, pct), fontsize=9, va="top")
    for e in band_edges:
        ax.axvline(e, color="0.6", linewidth=0.8)
    ax.set_xlabel("signed deviation (mm), + outside material; the end bins hold all beyond")
    ax.set_ylabel("points")
    ax.set_title("Deviations: mean %+.4f mm, sigma %.4f mm, RMS %.4f mm; dashed +-sigma, "
                 "dotted +-3 sigma, grey the tolerance bands" % (mean, sigma, stats["rms"]),
                 fontsize=10)
    return fig


def _nice_magnification(value):
    steps = np.array([1, 2, 5])
    exp = np.floor(np.log10(max(value, 1e-9)))
    candidates = np.concatenate([steps * 10 ** (exp - 1), steps * 10 ** exp])
    return float(candidates[candidates <= value].max()) if (candidates <= value).any() \
        else float(candidates.min())


def _offset(poly2d, distance):
    t = np.gradient(poly2d, axis=0)
    n = np.column_stack([t[:, 1], -t[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-12)[:, None]
    return poly2d + distance * n


def figure_section(sec, result, tolerance, magnification=None, max_whiskers=MAX_WHISKERS,
                   seed=0):
    """Nominal profile with each point's deviation drawn from its closest CAD point along the
    outward normal, magnified (Figs 9-10); the tolerance band at the same magnification; CMM
    points, when given, as black whiskers with round ends."""
    plt, _, _ = mpl()
    from matplotlib.collections import LineCollection
    chord = sec.profile.chord if sec.profile is not None else 50.0
    if magnification is None:
        # the tolerance is drawn as 2 % of the chord: whiskers readable, profile recognisable
        magnification = _nice_magnification(0.02 * chord / tolerance)
    outline = [sec.plane_coords(poly) for poly in (sec.profile.polylines
                                                     if sec.profile is not None else [])]
    if sec.cmm_xyz is not None and len(sec.cmm_xyz):
        outline.append(sec.plane_coords(sec.cmm_xyz))
    if len(sec.point_index):
        outline.append(sec.plane_coords(result.points_cad[sec.point_index]))
    both = np.vstack(outline) if outline else np.zeros((1, 2))
    margin = 2.0 * tolerance * magnification + 1.0
    width_mm = np.ptp(both[:, 0]) + 2 * margin
    height_mm = np.ptp(both[:, 1]) + 2 * margin
    # the figure takes the profile's own proportions, so equal axes leave no empty band
    fig_w = 11.0
    fig_h = float(np.clip(fig_w * 0.9 * height_mm / max(width_mm, 1e-6) + 1.1, 2.8, 9.0))
    fig, ax = plt.subplots(figsize=(fig_w, fig_h))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.7 / fig_h, top=1 - 0.45 / fig_h)
    if sec.profile is not None:
        for p2 in outline[:len(sec.profile.polylines)]:
            ax.plot(p2[:, 0], p2[:, 1], color="0.15", linewidth=1.0)
            for sign in (-1, 1):
                band = _offset(p2, sign * tolerance * magnification)
                ax.plot(band[:, 0], band[:, 1], color="0.55", linewidth=0.6, linestyle="--")
    idx = sec.point_index
    if len(idx) > max_whiskers:
        idx = np.sort(np.random.default_rng(seed).choice(idx, max_whiskers, replace=False))
    if len(idx):
        base = sec.plane_coords(result.closest[idx])
        tip = base + sec.vectors_in_plane(result.normal[idx]) * \
            (result.deviation[idx] * magnification)[:, None]
        colours = colourmap.deviation_colours(result.deviation[idx], tolerance)
        # rasterized: thousands of vector whiskers make a PDF slow to write and to view
        ax.add_collection(LineCollection(np.stack([base, tip], axis=1), colors=colours,
                                         linewidths=1.0, rasterized=True))
        ax.scatter(tip[:, 0], tip[:, 1], c=colours, s=3, linewidths=0, rasterized=True)
    if sec.cmm_xyz is not None and len(sec.cmm_xyz):
        base = sec.plane_coords(sec.cmm_closest)
        tip = base + sec.vectors_in_plane(sec.cmm_normal) * \
            (sec.cmm_deviation * magnification)[:, None]
        ax.add_collection(LineCollection(np.stack([base, tip], axis=1), colors="black",
                                         linewidths=0.8))
        ax.scatter(tip[:, 0], tip[:, 1], facecolors="none", edgecolors="black", s=10,
                   linewidths=0.6, label="CMM")
        ax.legend(loc="upper right", fontsize=8)
    if sec.profile is not None:
        ax.annotate("LE", (0.0, 0.0), xytext=(-12, 0), textcoords="offset points",
                    ha="right", va="center", fontweight="bold")
        ax.annotate("TE", (sec.profile.chord, 0.0), xytext=(12, 0), textcoords="offset points",
                    ha="left", va="center", fontweight="bold")
    # The margin enters the data limits, not fixed axis limits: an equal aspect that adjusts the
    # data limits cannot also keep both fixed (matplotlib 3.10 warns and drops the y limits).
    ax.update_datalim([both.min(axis=0) - margin, both.max(axis=0) + margin])
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("along the chord from the leading edge (mm)")
    ax.set_ylabel("across (mm)")
    o = sec.optical
    figures = ("n %d, max |dev| %.4f mm, RMS %.4f mm" % (o["n"], o["max_abs_mm"], o["rms_mm"])
               if o["n"] else "no measured points")
    ax.set_title("Section %s at %.0f %% span: %s; deviations x%g in the deviation map's "
                 "colours, dashed: +-%.3f mm" % (sec.label, sec.height_pct, figures,
                                                 magnification, tolerance), fontsize=10)
    return fig


# ---------------------------------------------------------------- tables as rows

def _fmt(value, pattern="%.4f"):
    return "-" if value is None else pattern % value


def tolerance_histogram(result, tolerance):
    """The deviations counted in the bands of the run's profile tolerance T (core.stats
    tolerance_bands: +-T, +-1.5T, +-2T; Table 3's bands when T = 0.04 mm)."""
    bands = stats_mod.tolerance_bands(tolerance)
    return stats_mod.deviation_statistics(result.deviation, bands)["histogram"]


def histogram_rows(histogram):
    """The report's histogram table of ``histogram`` (tolerance_histogram's bands)."""
    rows = []
    for band in histogram:
        lo, hi = band["lo"], band["hi"]
        name = ("< %.3f" % hi if lo is None else "> %.3f" % lo if hi is None
                else "%.3f to %.3f" % (lo, hi))
        rows.append([name, "%d" % band["count"], "%.3f" % band["pct"]])
    return ["Deviation range (mm)", "Number of points", "Percentage (%)"], rows


def section_rows(table):
    with_cmm = table.cmm_source is not None
    header = ["Section", "Span %", "Points"] + (["CMM points"] if with_cmm else []) + \
        ["Max |dev| (mm)"] + (["CMM max"] if with_cmm else []) + \
        ["RMS (mm)"] + (["CMM RMS"] if with_cmm else []) + \
        ["%.2f mm (%%)" % table.within] + (["CMM %"] if with_cmm else []) + \
        ["LE max |dev|", "TE max |dev|"] + (["CMM LE max", "CMM TE max"] if with_cmm else [])
    rows = []
    for s in table.sections:
        o, c = s.optical, s.cmm or {}
        cl, ct = c.get("le", {}), c.get("te", {})
        row = [s.label, "%.1f" % s.height_pct, "%d" % o["n"]]
        if with_cmm:
            row.append("%d" % c.get("n", 0))
        row.append(_fmt(o["max_abs_mm"]))
        if with_cmm:
            row.append(_fmt(c.get("max_abs_mm")))
        row.append(_fmt(o["rms_mm"]))
        if with_cmm:
            row.append(_fmt(c.get("rms_mm")))
        row.append(_fmt(o["pct_within"], "%.2f"))
        if with_cmm:
            row.append(_fmt(c.get("pct_within"), "%.2f"))
        row += [_fmt(o["le"]["max_abs_mm"]), _fmt(o["te"]["max_abs_mm"])]
        if with_cmm:
            row += [_fmt(cl.get("max_abs_mm")), _fmt(ct.get("max_abs_mm"))]
        rows.append(row)
    return header, rows


def pose_rows(result):
    T = np.asarray(result.measured_to_cad)
    cov = np.asarray(result.pose_covariance)
    sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    # The 1 sigma figures cover the measured directions only (inspection.checks).
    unmeasured = [["Not measured by the points (not in the 1 sigma figures)",
                   "; ".join(u["motion"].replace(" is not measured", "")
                             for u in result.pose_unmeasured)]] \
        if getattr(result, "pose_unmeasured", None) else []
    return unmeasured + [
        ["Points (inliers)", "%d (%d)" % (result.n_points, result.n_inliers)],
        ["Rows skipped", "%d" % result.n_rows_skipped],
        ["Residual RMS of inliers", "%.4f mm" % result.rms_mm],
        ["Pose uncertainty (1 sigma, worst bounding-box corner)",
         "%.2f um" % (1000.0 * result.pose_uncertainty_mm)
         + (" (covers the rival pose; statistical bound %.2f um)"
            % (1000.0 * result.pose_uncertainty_statistical_mm)
            if result.pose_uncertainty_includes_rival else "")],
        ["Translation 1 sigma (x, y, z)", "%.2f, %.2f, %.2f um" % tuple(1000.0 * sd[:3])],
        ["Rotation 1 sigma (x, y, z)", "%.2f, %.2f, %.2f urad" % tuple(1e6 * sd[3:])],
        ["measured_to_cad row 1", "  ".join("%.6f" % v for v in T[0])],
        ["measured_to_cad row 2", "  ".join("%.6f" % v for v in T[1])],
        ["measured_to_cad row 3", "  ".join("%.6f" % v for v in T[2])],
    ] + [["Coarse pose ambiguous", line] for line in rival_lines(result.coarse)]


# ---------------------------------------------------------------- HTML

_CSS = """
body{font-family:sans-serif;max-width:1200px;margin:1em auto;color:#222}
table{border-collapse:collapse;margin:0.5em 0 1.2em}
td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}
th{background:#eee} td:first-child{text-align:left}
.pass{color:#fff;background:#2a7d2e;padding:4px 10px;font-weight:bold}
.fail{color:#fff;background:#b3261e;padding:4px 10px;font-weight:bold}
img{max-width:100%} .note{color:#555;font-size:0.9em}
"""


def _verdict_lines(verdict, table):
    stage = getattr(table, "airfoil", None)
    lines = [characteristic_names.part_summary_text(   # the airfoil clause in display names
                 verdict["summary"], verdict.get("airfoil"),
                 stage.blocks if stage is not None else ()),
             "Points outside +-%.3f mm: %d (%.3f %%), in %d spot(s); %d isolated point(s)"
             % (verdict["tolerance_mm"], verdict["n_points_out"], verdict["pct_points_out"],
                verdict["n_spots"], verdict["n_isolated_out"])]
    lines += ["Spot %d: %s" % (k + 1, s["text"]) for k, s in enumerate(verdict["worst_spots"])]
    for s in verdict["sections"]:
        text = "Section %s: %s" % (s["label"], {True: "pass", False: "FAIL",
                                                 None: "not measured"}[s["pass"]])
        if s.get("worst_deviation_mm") is not None:
            text += ", worst %+.4f mm at the %s" % (s["worst_deviation_mm"],
                                                    verdict_mod.ZONE_TEXT[s["worst_zone"] or ""])
        if "cmm_pass" in s:
            text += "; CMM %s" % ("pass" if s["cmm_pass"] else "FAIL")
        lines.append(text)
    return lines


# ---------------------------------------------------------------- the report

def planning_notes(result):
    """The planner's notes of a result (what it left out and why), one line each, in the
    order given and without repeats: the report's "Planning notes" list."""
    return list(dict.fromkeys(str(n) for n in getattr(result, "planning_notes", None) or ()))


def write_report(out, result, nominal, sections, verdict, tolerance, magnification=None,
                 title=None):
    """report.html and report.pdf for a registration, its section table and verdict. Written
    into ``out``: an open pipeline.AtomicOutput, or a folder (written atomically).
    Returns {'html': name, 'pdf': name, 'pdf_pages': count}."""
    if not isinstance(out, pipeline.AtomicOutput):
        with pipeline.AtomicOutput(out) as output:
            return write_report(output, result, nominal, sections, verdict, tolerance,
                                magnification=magnification, title=title)
    # Pages drawn with numpy and matplotlib alone: beside the GUI's event loop (a minute of
    # drawing for a blade of many sections), stopping between pages on a cancel.
    return background.run(lambda: _write_report(out, result, sections, verdict, tolerance,
                                                magnification, title))


def _write_report(output, result, sections, verdict, tolerance, magnification, title):
    """write_report's files into the open AtomicOutput ``output``."""
    plt, _, _ = mpl()
    from matplotlib.backends.backend_pdf import PdfPages
    table = sections
    tolerance = float(tolerance)
    title = title or "BladeInspect inspection report"
    histogram = tolerance_histogram(result, tolerance)
    band_edges = [b["lo"] for b in histogram[1:]]
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    verdict_lines = _verdict_lines(verdict, table)
    h_header, h_rows = histogram_rows(histogram)
    s_header, s_rows = section_rows(table)
    p_rows = pose_rows(result)

    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>%s</title>"
             "<style>%s</style></head><body>" % (html.escape(title), _CSS),
             "<h1>%s</h1>" % html.escape(title),
             "<p class='note'>%s; points: %s; CAD: %s</p>" % (
                 stamp, html.escape(result.source or "-"), html.escape(result.cad_source or "-")),
             "<h2>Verdict</h2><p><span class='%s'>%s</span> profile tolerance +-%.3f mm</p>" % (
                 "pass" if verdict["pass"] else "fail", fit_report.verdict_word(verdict),
                 tolerance),
             "<ul>" + "".join("<li>%s</li>" % html.escape(x) for x in verdict_lines) + "</ul>",
             "<h2>Pose and its uncertainty</h2>", html_table(["Quantity", "Value"], p_rows)]
    parts += _fit_parts(result, verdict)
    notes = planning_notes(result)
    if notes:
        parts += ["<h2>Planning notes</h2>",
                  "<ul>" + "".join("<li>%s</li>" % html.escape(x) for x in notes) + "</ul>"]
    for w in list(result.warnings) + list(table.warnings):
        if w not in notes:
            parts.append("<p class='note'>Warning: %s</p>" % html.escape(str(w)))

    pdf_path = output.path("report.pdf")
    n_pages = 0
    with PdfPages(pdf_path) as pdf:
        fig = plt.figure(figsize=(8.27, 11.69))
        fig.text(0.06, 0.95, title, fontsize=16, weight="bold")
        fig.text(0.06, 0.925, "%s   points: %s" % (stamp, os.path.basename(result.source or "-")),
                 fontsize=8)
        fig.text(0.06, 0.89, "%s  (profile tolerance +-%.3f mm)"
                 % (fit_report.verdict_word(verdict), tolerance), fontsize=14,
                 color="#2a7d2e" if verdict["pass"] else "#b3261e", weight="bold")
        y = 0.86
        for line in verdict_lines[:24]:
            fig.text(0.06, y, line, fontsize=8, wrap=True)
            y -= 0.018
        if notes:
            fig.text(0.06, y, "Planning notes", fontsize=9, weight="bold")
            y -= 0.018
            more = ["(%d more in report.html and result.json)" % (len(notes) - MAX_PDF_NOTES)]
            for line in notes[:MAX_PDF_NOTES] + (more if len(notes) > MAX_PDF_NOTES else []):
                fig.text(0.06, y, "- " + line, fontsize=7, wrap=True)
                y -= 0.03
        pdf_table(fig, [0.06, 0.05, 0.88, max(0.1, y - 0.1)], ["Quantity", "Value"], p_rows,
                  TableStyle(7.5, cell_loc="left", col_widths=[0.45, 0.55]),
                  title="Pose and its uncertainty")
        n_pages += _page(pdf, plt, fig)

        n_pages += _add_fit_pages(pdf, plt, result, verdict)

        fig = figure_views(result, table, tolerance)
        parts += ["<h2>Deviation map</h2>", img_tag(png_bytes(fig), "deviation map, three views")]
        n_pages += _page(pdf, plt, fig)

        fig = figure_histogram(result, band_edges)
        png = png_bytes(fig)
        parts += ["<h2>Deviation histogram (Table 3)</h2>", img_tag(png, "deviation histogram"),
                  html_table(h_header, h_rows),
                  "<p>Within +-1 sigma: %.3f %%; within +-3 sigma: %.3f %% (sigma = %.4f mm "
                  "about the mean %+.4f mm).</p>" % (
                      result.deviation_stats["pct_within_1sigma"],
                      result.deviation_stats["pct_within_3sigma"],
                      result.deviation_stats["std"], result.deviation_stats["mean"])]
        n_pages += _page(pdf, plt, fig)

        fig = plt.figure(figsize=(11.69, 8.27))
        pdf_table(fig, [0.03, 0.52, 0.94, 0.42], s_header, s_rows or [["-"] * len(s_header)],
                  TableStyle(7.5, loc="upper center"),
                  title="Table 2: section profile errors (points within +-%.2f mm of each "
                  "plane or of the section column)" % table.band)
        pdf_table(fig, [0.03, 0.05, 0.94, 0.42], h_header, h_rows,
                  TableStyle(8, loc="upper center"), title="Table 3: deviation bands")
        notes = ["LE/TE: points within %.0f %% of the chord of each end of the nominal profile."
                 % (100 * table.edge_fraction)]
        if table.cmm_source:
            notes.append(sections_mod.CMM_COMPENSATION_NOTE)
        fig.text(0.03, 0.02, "\n".join(notes), fontsize=7, wrap=True)
        n_pages += _page(pdf, plt, fig)

        parts += ["<h2>Section profile errors (Table 2)</h2>", html_table(s_header, s_rows),
                  "<p class='note'>%s</p>" % html.escape(notes[0])]
        if table.cmm_source:
            parts.append("<p>CMM: %s. %s</p>" % (html.escape(table.cmm_source),
                                                 html.escape(sections_mod.CMM_COMPENSATION_NOTE)))
        for sec in table.sections:
            fig = figure_section(sec, result, tolerance, magnification=magnification)
            parts += ["<h3>Section %s</h3>" % html.escape(sec.label),
                      img_tag(png_bytes(fig), "section %s whisker plot" % sec.label)]
            n_pages += _page(pdf, plt, fig)
        n_pages += airfoil_report.add_pages(pdf, parts, table)
        meta = pdf.infodict()
        meta["Title"] = title
        meta["Creator"] = "BladeInspect"

    parts.append("</body></html>")
    with open(output.path("report.html"), "w", encoding="utf-8") as fh:
        fh.write("\n".join(parts))
    return {"html": "report.html", "pdf": "report.pdf", "pdf_pages": n_pages}


def _fit_parts(result, verdict):
    """The report.html sections of the fit and its sensitivity (inspection.fit_report)."""
    return fit_report.html_parts(result, verdict, html_table)


def _add_fit_pages(pdf, plt, result, verdict):
    """The PDF pages of the fit and its sensitivity (inspection.fit_report); their count."""
    n_pages = 0
    for fig in fit_report.pdf_pages(plt, result, verdict):
        n_pages += _page(pdf, plt, fig)
    return n_pages


def _page(pdf, plt, fig):
    """``fig`` saved as the PDF's next page and closed; a cancel stops the report here."""
    pdf.savefig(fig, dpi=PDF_DPI)
    plt.close(fig)
    background.check()
    return 1


# ---------------------------------------------------------------- the `report` command

def run_report(cad_path, points_path, out_dir, options=None, progress=None, nominal=None,
               document=None, batch_inputs=None):
    """Register, then write_result_report: result.json, deviations.csv, report.html,
    report.pdf and inspection.FCStd into out_dir, all or nothing, with ``options``
    (inspection.run_options.RunOptions; None: the defaults). ``nominal`` skips loading the
    CAD (a batch loads it once); ``options.flip_faces`` as ``--flip-face`` (cad.orient).
    ``options.allow_mismatch``: write the result of a scan that does not fit the CAD, with the
    warning (pipeline.register). ``document``, ``batch_inputs``: as for write_result_report.
    Returns a summary dict."""
    options = options or RunOptions()
    check_out_dir(out_dir)
    progress = progress or (lambda f, m: None)
    options = options.replace(tolerance=contracts.profile_tolerance(options.tolerance))
    timing = {}
    t0 = time.perf_counter()
    if nominal is None:
        nominal = pipeline.load_nominal(cad_path, flip_faces=options.flip_faces)
    timing["load_cad"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    points = pipeline.load_points(points_path)
    cmm_data = sections_mod.read_cmm(options.cmm) if options.cmm is not None else None
    timing["load_points"] = time.perf_counter() - t0
    result = pipeline.register(nominal, points, seed=options.seed,
                               progress=lambda f, m: progress(0.8 * f, m),
                               options=options.register_options(cad_path or "the demo blade"))
    result.timing_s = dict(timing, **result.timing_s)
    result.cad_source = cad_path or "built-in demo blade"
    return write_result_report(result, nominal, out_dir, options, progress, document,
                               ReportSources(cad_path=cad_path, cmm_data=cmm_data,
                                             batch_inputs=batch_inputs))


def write_result_report(result, nominal, out_dir, options=None, progress=None, document=None,
                        sources=None):
    """The `report` files of a registration already made (a RegistrationResult, e.g. a
    document's Registration): tabulate the sections, judge, and write result.json,
    deviations.csv, report.html, report.pdf and inspection.FCStd into out_dir, all or nothing:
    the files are made in a private folder beside out_dir and moved in only when every one is
    complete. ``options``: inspection.run_options.RunOptions (None: the defaults): its
    tolerance, section heights, airfoil options (None: no airfoil characteristics), fit
    (inspection.fitting.FitChoice, default least squares and ISO 14253-1) and measurement
    model (inspection.uncertainty) choose what is measured and decided. ``document``: the
    writer of inspection.FCStd (app.document.write_inspection_document, which this layer
    cannot import), or None for no document. ``sources``: inspection.run_options.ReportSources,
    what the report is made from besides the registration: the CAD file of the nominal (None:
    the demo blade), the CMM's table (sections.read_cmm; None: none) and what a batch made
    this file from (inspection.batch), kept in result.json so that a lot run again knows the
    file done. Returns a summary dict."""
    options = options or RunOptions()
    sources = sources or ReportSources()
    check_out_dir(out_dir)
    progress = progress or (lambda f, m: None)
    tolerance = contracts.profile_tolerance(options.tolerance)
    t0 = time.perf_counter()
    progress(0.82, "section table")
    table, verdict = _fit_and_judge(result, nominal, options.replace(tolerance=tolerance),
                                    sources.cmm_data, sources.planned)
    if options.airfoil is not None:   # the airfoil characteristics join the verdict
        airfoil_mod.attach(result, nominal, table, verdict, options.airfoil)
    result.timing_s["sections"] = time.perf_counter() - t0
    with pipeline.AtomicOutput(out_dir) as out:
        t0 = time.perf_counter()
        progress(0.86, "report")
        files = write_report(out, result, nominal, table, verdict, tolerance)
        result.timing_s["report"] = time.perf_counter() - t0
        if document:
            t0 = time.perf_counter()
            progress(0.95, "FreeCAD document")
            document(out.path("inspection.FCStd"), nominal, result, table,
                     tolerance=tolerance, verdict=verdict, cad_path=sources.cad_path)
            result.timing_s["document"] = time.perf_counter() - t0
        pipeline.write_register_outputs(out_dir, result, extra={
            "sections": table.to_json(), "verdict": verdict, "tolerance_mm": tolerance,
            **airfoil_mod.extras_of(table),
            **({"batch_inputs": sources.batch_inputs}
               if sources.batch_inputs is not None else {})},
            output=out)
    progress(1.0, verdict["summary"])
    return {"out_dir": os.path.abspath(out_dir), "result": result, "sections": table,
            "verdict": verdict, "files": sorted(os.listdir(out_dir)),
            "pdf_pages": files["pdf_pages"]}


def _fit_and_judge(result, nominal, options, cmm_data, planned=None):
    """(section table, verdict) of ``result`` moved to the pose of the fit ``options`` choose
    (inspection.judging), the table at their section heights with the CMM's columns, or at an
    inspection's ``planned`` sections (inspection.planned_sections) from its planned rows."""
    if planned is not None:
        def table_of(fitted):
            return planned.table(fitted, nominal, cmm=cmm_data)
    else:
        def table_of(fitted):
            return sections_mod.section_table(fitted, nominal,
                                              heights_pct=options.section_heights, cmm=cmm_data)
    return judging.fit_and_judge(result, nominal, options.fit_choice, options.tolerance,
                                 table_of, measurement_model=options.measurement_model)
