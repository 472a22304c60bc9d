"""What a metrology engineer reads for each airfoil characteristic: its name,
its unit and a one-line meaning, keyed by the result.json field name (``chord_mm``;
``le_thickness_mm[1]`` for a list element). The report writes these names, the workbench shows
them through Qt's translation. The field name stays what the files and ``--characteristics``
use; a tooltip gives it beside the name.

Texts are marked with QT_TRANSLATE_NOOP in the workbench's context so that
scripts/update-translations collects them; this layer does not import FreeCAD, so the marker is
the identity here and the GUI translates the text when it shows it. Functions take ``tr``, the
translator (the identity for the report)."""


def QT_TRANSLATE_NOOP(context, text):   # noqa: N802 (the name scripts/update-translations reads)
    return text


def _same(text):
    return text


MM = "mm"
DEG = "\u00b0"
PCT_CHORD = QT_TRANSLATE_NOOP("BladeInspect", "% chord")
MM2 = "mm\u00b2"

# name, unit, meaning. A list field's name is a template:
# "%s" takes the element's offset (edge thickness) or axis (centroid, shift).
NAMES = {
    "chord_mm": (QT_TRANSLATE_NOOP("BladeInspect", "Chord (%s)"),
                 MM,
                 QT_TRANSLATE_NOOP("BladeInspect", "Chord by the method named (nose-tail: LE "
                                                   "point to TE point; caliper; tangent)")),
    "axial_chord_mm": (QT_TRANSLATE_NOOP("BladeInspect", "Axial chord"),
                       MM,
                       QT_TRANSLATE_NOOP("BladeInspect", "Extent of the profile along the "
                                                         "engine axis")),
    "stagger_deg": (QT_TRANSLATE_NOOP("BladeInspect", "Stagger angle (%s)"),
                    DEG,
                    QT_TRANSLATE_NOOP("BladeInspect", "Angle of the chord named (its method) "
                                                      "from the engine axis in the section "
                                                      "plane, LE towards TE")),
    "max_thickness_mm": (QT_TRANSLATE_NOOP("BladeInspect", "Max. thickness"),
                         MM,
                         QT_TRANSLATE_NOOP("BladeInspect", "Diameter of the largest "
                                                           "inscribed circle")),
    "max_thickness_pos_pct": (QT_TRANSLATE_NOOP("BladeInspect", "Max. thickness position"),
                              PCT_CHORD,
                              QT_TRANSLATE_NOOP("BladeInspect", "Where the largest inscribed "
                                                                "circle lies, % of the chord "
                                                                "from the LE")),
    "le_radius_mm": (QT_TRANSLATE_NOOP("BladeInspect", "LE radius"),
                     MM,
                     QT_TRANSLATE_NOOP("BladeInspect", "Radius of the circle fitted to the "
                                                       "leading-edge zone")),
    "te_radius_mm": (QT_TRANSLATE_NOOP("BladeInspect", "TE radius"),
                     MM,
                     QT_TRANSLATE_NOOP("BladeInspect", "Radius of the circle fitted to the "
                                                       "trailing-edge zone")),
    "inlet_angle_deg": (QT_TRANSLATE_NOOP("BladeInspect", "Inlet metal angle"),
                        DEG,
                        QT_TRANSLATE_NOOP("BladeInspect", "Camber line's tangent at the LE, "
                                                          "from the engine axis")),
    "outlet_angle_deg": (QT_TRANSLATE_NOOP("BladeInspect", "Outlet metal angle"),
                         DEG,
                         QT_TRANSLATE_NOOP("BladeInspect", "Camber line's tangent at the TE, "
                                                           "from the engine axis")),
    "area_mm2": (QT_TRANSLATE_NOOP("BladeInspect", "Section area"),
                 MM2,
                 QT_TRANSLATE_NOOP("BladeInspect", "Area enclosed by the profile")),
    "twist_deg": (QT_TRANSLATE_NOOP("BladeInspect", "Twist"),
                  DEG,
                  QT_TRANSLATE_NOOP("BladeInspect", "Rotation of the measured section against "
                                                    "the nominal (its 2D best fit)")),
    "form_mm": (QT_TRANSLATE_NOOP("BladeInspect", "Form error"),
                MM,
                QT_TRANSLATE_NOOP("BladeInspect", "Largest contour deviation after the "
                                                  "section's own 2D best fit")),
    "form_location_mm": (QT_TRANSLATE_NOOP("BladeInspect", "Form and location error"),
                         MM,
                         QT_TRANSLATE_NOOP("BladeInspect", "Largest contour deviation before "
                                                           "the section's 2D fit")),
    "le_thickness_mm": (QT_TRANSLATE_NOOP("BladeInspect", "LE thickness at %s mm"),
                        MM,
                        QT_TRANSLATE_NOOP("BladeInspect", "Thickness normal to the camber "
                                                          "line at this distance from the LE "
                                                          "point")),
    "te_thickness_mm": (QT_TRANSLATE_NOOP("BladeInspect", "TE thickness at %s mm"),
                        MM,
                        QT_TRANSLATE_NOOP("BladeInspect", "Thickness normal to the camber "
                                                          "line at this distance from the TE "
                                                          "point")),
    "centroid_mm": (QT_TRANSLATE_NOOP("BladeInspect", "Centroid %s"),
                    MM,
                    QT_TRANSLATE_NOOP("BladeInspect", "Centroid of the section area, in the "
                                                      "CAD frame")),
    "shift_mm": (QT_TRANSLATE_NOOP("BladeInspect", "Shift %s"),
                 MM,
                 QT_TRANSLATE_NOOP("BladeInspect", "Displacement of the measured section "
                                                   "against the nominal in its plane (x along "
                                                   "the engine axis)")),
}
# The element names of the list fields that are not edge offsets.
AXES = {"centroid_mm": ("x", "y", "z"),
        "shift_mm": (QT_TRANSLATE_NOOP("BladeInspect", "x (engine axis)"), "y")}
EDGE_FIELDS = ("le_thickness_mm", "te_thickness_mm")

# The other rows of the fit-sensitivity table (inspection.fitting.section_worst_characteristics)
WORST_DEVIATION = QT_TRANSLATE_NOOP("BladeInspect", "Worst deviation")
PART = QT_TRANSLATE_NOOP("BladeInspect", "Part")
SECTION = QT_TRANSLATE_NOOP("BladeInspect", "Section %s")
PART_VERDICT = QT_TRANSLATE_NOOP("BladeInspect", "Part verdict")

# The airfoil verdict's line (inspection.airfoil_verdicts.stage_verdict's summary) in display names;
# result.json's ``summary`` keeps the field names, which files, scripts and tests match.
AIRFOIL_VERDICT_LINES = {
    None: QT_TRANSLATE_NOOP("BladeInspect", "Airfoil: no characteristic toleranced"),
    "fail": QT_TRANSLATE_NOOP("BladeInspect", "Airfoil: FAIL, %d of %d characteristics: %s"),
    "not proven": QT_TRANSLATE_NOOP("BladeInspect", "Airfoil: NOT PROVEN, %d of %d "
                                                    "characteristics: %s"),
    "pass": QT_TRANSLATE_NOOP("BladeInspect", "Airfoil: PASS (%d characteristics)"),
}
NOT_MEASURED = " (not measured)"   # inspection.airfoil_verdicts.judge's suffix of an unmeasured key
NOT_MEASURED_NAME = QT_TRANSLATE_NOOP("BladeInspect", "%s (not measured)")

# Verdicts as core.decision and inspection.airfoil_verdicts write them, marked so that they are
# translated where they are shown.
VERDICTS = (QT_TRANSLATE_NOOP("BladeInspect", "pass"),
            QT_TRANSLATE_NOOP("BladeInspect", "fail"),
            QT_TRANSLATE_NOOP("BladeInspect", "not proven"),
            QT_TRANSLATE_NOOP("BladeInspect", "not judged"),
            QT_TRANSLATE_NOOP("BladeInspect", "not measured"))


def split_key(key):
    """(field name, element index or None) of ``chord_mm`` or ``le_thickness_mm[1]``."""
    if key.endswith("]") and "[" in key:
        base, index = key[:-1].split("[", 1)
        return base, int(index)
    return key, None


def _element(base, index, values, tr):
    if base in EDGE_FIELDS:
        offsets = (values or {}).get("edge_offsets_mm") or []
        return "%g" % offsets[index] if index < len(offsets) else "#%d" % (index + 1)
    axes = AXES[base]
    return tr(axes[index]) if index < len(axes) else "#%d" % (index + 1)


def display_name(key, values=None, tr=_same):
    """The name of ``key`` as a report or panel shows it. ``values``: the section's nominal
    block (its ``chord_method`` and ``edge_offsets_mm`` complete the name); a key with no entry
    shows as the key itself."""
    base, index = split_key(key)
    entry = NAMES.get(base)
    if entry is None:
        return key
    text = tr(entry[0])
    if base in ("chord_mm", "stagger_deg"):   # a chord's length and angle: one line
        method = (values or {}).get("chord_method")
        return text % method if method else text.replace(" (%s)", "")
    if index is not None:
        return text % _element(base, index, values, tr)
    return text


def unit(key, tr=_same):
    """The unit of ``key``'s values, deviation and uncertainty ("mm", "°", "% chord",
    "mm²")."""
    base, _ = split_key(key)
    return tr(NAMES[base][1]) if base in NAMES else ""


def meaning(key, tr=_same):
    """A line on what ``key`` measures, with its field name (for files and tolerances)."""
    base, _ = split_key(key)
    if base not in NAMES:
        return key
    return "%s (%s)" % (tr(NAMES[base][2]), key)


def sensitivity_row_parts(row):
    """(section label or None for the part, characteristic key or None for a worst deviation)
    of a fit_sensitivity row: the rows name them as "section 2 twist_deg", "section 2 worst
    deviation" and "part worst deviation"."""
    name = row["characteristic"]
    if name.startswith("part "):
        return None, None
    rest = name[len("section "):] if name.startswith("section ") else name
    if row.get("airfoil"):
        label, _, key = rest.rpartition(" ")
        return label, key
    suffix = " worst deviation"
    return (rest[:-len(suffix)] if rest.endswith(suffix) else rest), None


def sensitivity_row_name(row, tr=_same, values=None):
    """"Section 2: Twist" for a fit_sensitivity row. ``values``: what completes an airfoil
    name (``chord_method``, ``edge_offsets_mm``: the document's ``airfoil_definitions``)."""
    label, key = sensitivity_row_parts(row)
    what = tr(WORST_DEVIATION) if key is None else display_name(key, values, tr)
    where = tr(PART) if label is None else tr(SECTION) % label
    return "%s: %s" % (where, what)


def verdict_entry_name(entry, values_by_section=None, tr=_same):
    """"Section 2: LE thickness at 1 mm" for an airfoil_verdict ``failed`` / ``not_proven``
    entry "section 2: le_thickness_mm[1]" (its " (not measured)" kept). ``values_by_section``:
    each section label's nominal block (what completes the names); an entry of another form
    is returned as it is."""
    if not entry.startswith("section ") or ": " not in entry:
        return entry
    label, _, key = entry[len("section "):].rpartition(": ")
    missing = key.endswith(NOT_MEASURED)
    if missing:
        key = key[:-len(NOT_MEASURED)]
    name = display_name(key, (values_by_section or {}).get(label), tr)
    if missing:
        name = tr(NOT_MEASURED_NAME) % name
    return "%s: %s" % (tr(SECTION) % label, name)


def airfoil_verdict_text(verdict, blocks=(), tr=_same):
    """The airfoil verdict's line (result.json's airfoil_verdict) with the failed or not
    proven characteristics by their display names; ``blocks``: result.json's ``airfoil``."""
    if not verdict:
        return ""
    values = {str(b["label"]): b.get("nominal") for b in blocks or ()}
    n_judged = verdict.get("n_judged", 0)
    if not n_judged:
        return tr(AIRFOIL_VERDICT_LINES[None])
    for word, entries in (("fail", verdict.get("failed")),
                          ("not proven", verdict.get("not_proven"))):
        if entries:
            return tr(AIRFOIL_VERDICT_LINES[word]) % (
                len(entries), n_judged,
                "; ".join(verdict_entry_name(e, values, tr) for e in entries))
    return tr(AIRFOIL_VERDICT_LINES["pass"]) % n_judged


def part_summary_text(summary, airfoil_verdict, blocks=(), tr=_same):
    """The part verdict's summary with the airfoil clause inspection.airfoil_stage.attach appended
    (the stage's summary, field names) in display names; as it is without that clause."""
    clause = (airfoil_verdict or {}).get("summary")
    if not clause or clause not in summary:
        return summary
    return summary.replace(clause, airfoil_verdict_text(airfoil_verdict, blocks, tr))


# Table 2's columns (inspection.report.section_rows' header) as a narrow panel shows them: a
# short header over two lines and its meaning ("CMM points", "CMM max", "CMM RMS" are short
# already, and the GUI test finds the columns by them). The share-within column's header carries its
# band ("0.02 mm (%)"), matched by WITHIN_SUFFIX.
SECTION_COLUMNS = {
    "Section": (QT_TRANSLATE_NOOP("BladeInspect", "Section"),
                QT_TRANSLATE_NOOP("BladeInspect", "Section label")),
    "Span %": (QT_TRANSLATE_NOOP("BladeInspect", "Span\n%"),
               QT_TRANSLATE_NOOP("BladeInspect", "Section height, % of the span from hub "
                                                 "to tip")),
    "Points": (QT_TRANSLATE_NOOP("BladeInspect", "Points"),
               QT_TRANSLATE_NOOP("BladeInspect", "Registered points in the section's band")),
    "CMM points": (QT_TRANSLATE_NOOP("BladeInspect", "CMM points"),
                   QT_TRANSLATE_NOOP("BladeInspect", "CMM points in the section")),
    "Max |dev| (mm)": (QT_TRANSLATE_NOOP("BladeInspect", "Max |dev|\nmm"),
                       QT_TRANSLATE_NOOP("BladeInspect", "Largest absolute deviation from "
                                                         "the CAD in the section (mm)")),
    "CMM max": (QT_TRANSLATE_NOOP("BladeInspect", "CMM max"),
                QT_TRANSLATE_NOOP("BladeInspect", "The CMM's largest absolute deviation "
                                                  "(mm)")),
    "RMS (mm)": (QT_TRANSLATE_NOOP("BladeInspect", "RMS\nmm"),
                 QT_TRANSLATE_NOOP("BladeInspect", "RMS of the deviations in the section "
                                                   "(mm)")),
    "CMM RMS": (QT_TRANSLATE_NOOP("BladeInspect", "CMM RMS"),
                QT_TRANSLATE_NOOP("BladeInspect", "RMS of the CMM's deviations (mm)")),
    "CMM %": (QT_TRANSLATE_NOOP("BladeInspect", "CMM\n%"),
              QT_TRANSLATE_NOOP("BladeInspect", "Share of the CMM's points within the band")),
    "LE max |dev|": (QT_TRANSLATE_NOOP("BladeInspect", "LE max\nmm"),
                     QT_TRANSLATE_NOOP("BladeInspect", "Largest absolute deviation at the "
                                                       "leading edge (mm)")),
    "TE max |dev|": (QT_TRANSLATE_NOOP("BladeInspect", "TE max\nmm"),
                     QT_TRANSLATE_NOOP("BladeInspect", "Largest absolute deviation at the "
                                                       "trailing edge (mm)")),
    "CMM LE max": (QT_TRANSLATE_NOOP("BladeInspect", "CMM LE\nmm"),
                   QT_TRANSLATE_NOOP("BladeInspect", "The CMM's largest absolute deviation "
                                                     "at the leading edge (mm)")),
    "CMM TE max": (QT_TRANSLATE_NOOP("BladeInspect", "CMM TE\nmm"),
                   QT_TRANSLATE_NOOP("BladeInspect", "The CMM's largest absolute deviation "
                                                     "at the trailing edge (mm)")),
}
WITHIN_SUFFIX = " mm (%)"
WITHIN = (QT_TRANSLATE_NOOP("BladeInspect", "Within\n\u00b1%s mm\n%%"),
          QT_TRANSLATE_NOOP("BladeInspect", "Share of the section's points within \u00b1%s mm "
                                            "of the CAD"))


def section_column(header, tr=_same):
    """(short header, meaning) of a Table 2 column; a header with no entry as it is."""
    if header in SECTION_COLUMNS:
        short, tip = SECTION_COLUMNS[header]
        return tr(short), tr(tip)
    if header.endswith(WITHIN_SUFFIX):
        band = header[:-len(WITHIN_SUFFIX)]
        return tr(WITHIN[0]) % band, tr(WITHIN[1]) % band
    return header, header
