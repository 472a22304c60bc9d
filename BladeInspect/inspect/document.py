"""inspection.FCStd: the inspection as a FreeCAD document, written headless.

Objects: the nominal CAD (Part::Feature "Nominal"), the registered points coloured by deviation
(Points::FeatureCustom "Deviations" with an added App::PropertyColorList "Color", one colour per
point, and the signed deviations beside it: FreeCAD shows per-point colours from that property
when the view's display mode is "Color"), and the nominal section curves (Part::Feature per
section, in a "Sections" group). The pose and verdict are properties of the "Deviations" object
so a document on its own says what it shows.

Plain document objects rather than the workbench's FeaturePython objects: a file written on a
line PC must open anywhere, even where the workbench is not installed, and nothing in it needs
recomputing.
"""

import json
import os

import numpy as np

from ..core import colormap
from ..core.errors import InputError


def _fc():
    import FreeCAD
    import Part
    import Points
    return FreeCAD, Part, Points


def _polyline_shape(Part, FreeCAD, polylines):
    edges = []
    for poly in polylines:
        pts = [FreeCAD.Vector(*p) for p in np.asarray(poly, dtype=float)]
        if len(pts) >= 2:
            edges.append(Part.makePolygon(pts))
    return Part.makeCompound(edges)


def write_inspection_document(path, nominal, result, sections, tolerance=0.04, verdict=None,
                              name="Inspection"):
    """Save the inspection document at ``path`` (.FCStd) and close it. Returns the path."""
    FreeCAD, Part, Points = _fc()
    if not str(path).lower().endswith(".fcstd"):
        raise InputError("%s: an inspection document must be an .FCStd file" % path)
    # hidden: when the GUI is up (a report run from the workbench) no 3D view opens for it
    doc = FreeCAD.newDocument(name, hidden=True)
    try:
        cad = doc.addObject("Part::Feature", "Nominal")
        cad.Shape = nominal.shape
        cad.Label = "Nominal CAD"

        cloud = doc.addObject("Points::FeatureCustom", "Deviations")
        cloud.Label = "Deviations (colour +-%.3f mm)" % tolerance
        xyz = np.asarray(result.points_cad, dtype=float)
        cloud.Points = Points.Points([tuple(p) for p in xyz.tolist()])
        cloud.addProperty("App::PropertyColorList", "Color", "Deviation",
                          "Colour of every point: blue -limit, green 0, red +limit")
        colors = colormap.deviation_colors(result.deviation, tolerance)
        cloud.Color = [tuple(c) for c in colors.tolist()]
        cloud.addProperty("App::PropertyFloatList", "Deviation", "Deviation",
                          "Signed deviation of every point, + outside material, mm")
        cloud.Deviation = np.asarray(result.deviation, dtype=float).tolist()
        cloud.addProperty("App::PropertyFloat", "ColorLimit", "Deviation",
                          "Deviation at which the colours saturate, mm")
        cloud.ColorLimit = float(tolerance)
        cloud.addProperty("App::PropertyMatrix", "MeasuredToCad", "Registration",
                          "Measured -> CAD transform of the points (as in result.json)")
        cloud.MeasuredToCad = FreeCAD.Matrix(*np.asarray(result.measured_to_cad,
                                                          dtype=float).ravel().tolist())
        cloud.addProperty("App::PropertyFloat", "PoseUncertaintyMm", "Registration",
                          "1 sigma at the worst corner of the CAD's bounding box, mm")
        cloud.PoseUncertaintyMm = float(result.pose_uncertainty_mm)
        cloud.addProperty("App::PropertyFloat", "RmsMm", "Registration",
                          "RMS of the inliers' deviations, mm")
        cloud.RmsMm = float(result.rms_mm)
        if verdict is not None:
            cloud.addProperty("App::PropertyString", "Verdict", "Verdict",
                              "Pass/fail summary against the profile tolerance")
            cloud.Verdict = verdict["summary"]
            cloud.addProperty("App::PropertyString", "VerdictJson", "Verdict",
                              "The verdict as in result.json")
            cloud.VerdictJson = json.dumps(verdict)

        group = doc.addObject("App::DocumentObjectGroup", "Sections")
        for sec in sections.sections:
            if sec.profile is None or not sec.profile.polylines:
                continue
            obj = doc.addObject("Part::Feature", "Section%s" % _safe(sec.label))
            obj.Shape = _polyline_shape(Part, FreeCAD, sec.profile.polylines)
            obj.Label = "Section %s (%.0f %% span)" % (sec.label, sec.height_pct)
            group.addObject(obj)
        doc.recompute()
        doc.saveAs(os.path.abspath(path))
    finally:
        FreeCAD.closeDocument(doc.Name)
    return path


def _safe(label):
    return "".join(ch if ch.isalnum() else "_" for ch in str(label))

