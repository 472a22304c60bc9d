"""The airfoil characteristics' names and a section block's values (result.json's
``airfoil``): the block's characteristics of one core.airfoil.Characteristics, and the
flattened {name or name[i]: number} form the uncertainty, the verdicts and the files read."""


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
