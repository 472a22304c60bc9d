"""The nominal section profiles of a section analysis as one Part compound (a plain Part
feature, no proxy: a snapshot the command makes again)."""

import numpy as np

import FreeCAD

from ...core.errors import InputError
from .base import building


def make_section_profiles(doc, table, registration=None, name="SectionProfiles"):
    """The nominal section profiles of a section table (inspection.sections) as Part polylines, one
    compound, for showing where the sections were cut. A snapshot: made again by the command."""
    import Part
    edges = []
    labels = []
    for section in table.sections:
        if section.profile is None:
            continue
        for poly in section.profile.polylines:
            poly = np.asarray(poly, dtype=float)
            if len(poly) >= 2:
                edges.append(Part.makePolygon([FreeCAD.Vector(*p) for p in poly]))
        labels.append(section.label)
    if not edges:
        raise InputError("section analysis: no section plane cuts the nominal")
    with building(doc, "Section profiles"):
        obj = doc.addObject("Part::Feature", name)
        obj.Shape = Part.Compound(edges)
        obj.addProperty("App::PropertyStringList", "Sections", "Sections",
                        "Labels of the sections cut")
        obj.Sections = labels
        if registration is not None:
            obj.addProperty("App::PropertyLink", "Registration", "Sections",
                            "Registration the sections were analysed for")
            obj.Registration = registration
        # What was analysed is a record, not an input: editing it would not recut the sections.
        for prop in ("Sections", "Registration"):
            if prop in obj.PropertiesList:
                obj.setEditorMode(prop, ["ReadOnly"])
        if obj.ViewObject is not None:
            obj.ViewObject.LineColor = (0.8, 0.1, 0.1)
            obj.ViewObject.LineWidth = 3
    return obj
