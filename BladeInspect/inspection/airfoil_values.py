"""The airfoil characteristics' names and a section block's values (result.json's
``airfoil``): the block's characteristics of one core.airfoil.Characteristics, and the
flattened {name or name[i]: number} form the uncertainty, the verdicts and the files read;
the values withheld on a section, its notes in order and its one-line summary."""

from ..core import airfoil as kernel
from .characteristic_names import display_name


# Scalar characteristics, list-valued ones, and which of them have no CAD value (the section's
# position and contour against the nominal: zero on the nominal by definition).
SCALARS = ("chord_mm", "axial_chord_mm", "stagger_deg", "max_thickness_mm",
           "max_thickness_pos_pct", "le_radius_mm", "te_radius_mm", "inlet_angle_deg",
           "outlet_angle_deg", "area_mm2", "twist_deg", "form_mm", "form_location_mm")
LISTS = ("le_thickness_mm", "te_thickness_mm", "centroid_mm", "shift_mm")
POSITION = ("twist_deg", "form_mm", "form_location_mm", "shift_mm")
# Characteristics that are maxima over the points (their u includes the maximum's bias)
MAXIMA = ("form_mm", "form_location_mm")
CHARACTERISTICS = SCALARS + LISTS


def base_name(name):
    return name.split("[", 1)[0]


def char_values(ch, frame, fit=None, contour=None):
    """The block's values of one Characteristics (nominal: fit None)."""
    v = {"chord_mm": ch.chord_mm, "chord_method": ch.chord_method,
         "axial_chord_mm": ch.axial_chord_mm, "stagger_deg": ch.stagger_deg,
         "max_thickness_mm": ch.max_thickness_mm,
         "max_thickness_pos_pct": ch.max_thickness_pos_pct,
         "le_radius_mm": ch.le_radius_mm, "te_radius_mm": ch.te_radius_mm,
         "edge_offsets_mm": list(ch.edge_offsets_mm),
         "le_thickness_mm": list(ch.le_thickness_mm),
         "te_thickness_mm": list(ch.te_thickness_mm),
         "inlet_angle_deg": ch.inlet_angle_deg, "outlet_angle_deg": ch.outlet_angle_deg,
         "area_mm2": ch.area_mm2,
         "centroid_mm": frame.to_3d(ch.centroid_mm)[0].tolist(),
         "shift_mm": [0.0, 0.0] if fit is None else fit.shift_mm.tolist(),
         "twist_deg": 0.0 if fit is None else fit.twist_deg,
         "form_mm": 0.0 if contour is None else contour["all"]["form_mm"],
         "form_location_mm": 0.0 if contour is None else contour["all"]["form_location_mm"]}
    return v


def flat(values):
    """{name or name[i]: number} of a block's numeric characteristics."""
    out = {}
    for name in SCALARS:
        if values.get(name) is not None:
            out[name] = float(values[name])
    for name in LISTS:
        for i, x in enumerate(values.get(name) or []):
            if x is not None:
                out["%s[%d]" % (name, i)] = float(x)
    return out


def unflat(flat, like):
    out = {}
    for name in SCALARS:
        out[name] = flat.get(name)
    for name in LISTS:
        out[name] = [flat.get("%s[%d]" % (name, i)) for i in range(len(like.get(name) or []))]
    return out


def withheld_values(ch, noise_mm):
    """{block name: reason} of the block's values the kernel withholds on a measured section
    because an edge's zone holds too few points (core.airfoil.edge_zone_withheld, its one
    rule): null in measured, deviation and uncertainty, judged "not measured" and never
    failed or passed on (airfoil_verdicts.judge)."""
    names = set(CHARACTERISTICS)
    return {k: reason for k, reason in kernel.edge_zone_withheld(ch, noise_mm).items()
            if k in names}


# Notes ranked by what they change: a value withheld (not measured, not reported) first, then
# a value reported with a caveat on it, then what only informs.
_WITHHELD_WORDS = ("not measured", "not reported", "not measurable", "needed")
_CAVEAT_WORDS = ("not trustworthy", "biased", "depends on", "beyond", "not a circle")


def _note_rank(note):
    text = note.lower()
    if any(w in text for w in _WITHHELD_WORDS):
        return 0
    if any(w in text for w in _CAVEAT_WORDS):
        return 1
    return 2


def ordered_notes(notes):
    """A section's notes once each (the first of equal lines), a withheld value's first, then
    a value's caveat, then the rest, each group in its order of arrival."""
    unique = list(dict.fromkeys(notes))
    return sorted(unique, key=_note_rank)       # sorted() is stable


def section_summary(block):
    """The section's one line (result.json block ``summary``): how many of its characteristics
    (the nominal's numbers) are not measured, which, and why -- e.g. "3 of 17 characteristics
    not measured: TE radius, Chord (nose-tail), Outlet angle — 5 measured points in the TE zone
    (+-45 deg), 12 needed"."""
    notes = block.get("notes") or []
    if block.get("nominal") is None:
        return "not measured: %s" % (notes[0] if notes else "no nominal section")
    nominal = flat(block["nominal"])
    if block.get("measured") is None:
        first = [n for n in notes if n.startswith("measured:")]
        return ("%d characteristics, nominal only%s" %
                (len(nominal), "; " + first[0] if first else ""))
    measured = flat(block["measured"])
    missing = [k for k in nominal if k not in measured]
    if not missing:
        return "all %d characteristics measured" % len(nominal)
    withheld = block.get("withheld") or {}

    def reason(key):
        return withheld.get(key, withheld.get(base_name(key)))
    reasons = list(dict.fromkeys(r for r in map(reason, missing) if r))
    if any(reason(k) is None for k in missing):
        reasons.append("see the notes")
    names = [display_name(k, block["nominal"]) for k in missing]
    return "%d of %d characteristics not measured: %s \u2014 %s" % (
        len(missing), len(nominal), ", ".join(names), "; ".join(reasons))
