"""Document side of the closed loop: the planned paths as Part geometry, and what an
inspection leaves on its Registration so a CMM file can be added to its Table 2 later.
No GUI imports: the workbench commands in gui/loop_commands.py call these."""

import numpy as np

import FreeCAD

from ..core.errors import InputError
from ..inspection.sections import read_cmm, section_table
from . import objects

PLAN_GROUP = "Planned paths"
INSPECTION_GROUP = "Inspection"


def path_polylines(plan):
    """Each planned path's target points on the CAD (CAD frame, (K, 3)) in the order the rig
    reads them: what the 3D view draws before the paths run."""
    return [np.asarray(plan.sections[path.section].target_cad[path.points], dtype=float)
            for path in plan.paths]


def _path_shape(plan):
    import Part
    pieces = []
    for poly in path_polylines(plan):
        if len(poly) >= 2:
            pieces.append(Part.makePolygon([FreeCAD.Vector(*p) for p in poly]))
        elif len(poly) == 1:
            pieces.append(Part.Vertex(FreeCAD.Vector(*poly[0])))
    if not pieces:
        raise InputError("planned paths: the plan has no points to draw")
    return Part.Compound(pieces)


def show_plan(doc, plan, obj=None, name="PlannedPaths"):
    """The plan's paths as one Part compound of polylines (CAD frame), in a new object, or in
    ``obj`` (the object drawn for the first plan of the same inspection): a re-plan replaces
    its shape, so the view shows the paths about to run."""
    shape = _path_shape(plan)
    if obj is None:
        with objects.building(doc, "Planned paths"):
            obj = doc.addObject("Part::Feature", name)
            obj.addProperty("App::PropertyFloatList", "HeightsPct", PLAN_GROUP,
                            "Nominal section heights, % of span")
            obj.addProperty("App::PropertyInteger", "NPaths", PLAN_GROUP, "Rig passes")
            obj.addProperty("App::PropertyInteger", "NPoints", PLAN_GROUP, "Planned readings")
            # The plan's record: editing it would not re-plan the paths.
            for prop in ("HeightsPct", "NPaths", "NPoints"):
                obj.setEditorMode(prop, ["ReadOnly"])
            if obj.ViewObject is not None:
                # Magenta is on no deviation colour (blue-green-red): paths stay apart from maps.
                obj.ViewObject.LineColor = (0.85, 0.0, 0.85)
                obj.ViewObject.LineWidth = 3
                obj.ViewObject.PointColor = (0.85, 0.0, 0.85)
                obj.ViewObject.PointSize = 4
    obj.Shape = shape
    obj.HeightsPct = [float(s.height_pct) for s in plan.sections]
    obj.NPaths = len(plan.paths)
    obj.NPoints = int(plan.n_points)
    return obj


def mark_inspection(registration, heights_pct, first_planned_row, out_dir):
    """Record on a Registration made by an inspection which rows were measured along the
    planned paths and at which heights, so a CMM file added later is compared at the same
    nominal sections."""
    for kind, prop, tip in (
            ("App::PropertyFloatList", "InspectionHeights", "Nominal section heights, % of span"),
            ("App::PropertyInteger", "FirstPlannedRow",
             "Rows from here on were measured along the planned paths"),
            ("App::PropertyPath", "InspectionFolder", "Where the inspection wrote its files"),
            ("App::PropertyFile", "CmmFile", "CMM file compared in Table 2")):
        if prop not in registration.PropertiesList:
            registration.addProperty(kind, prop, INSPECTION_GROUP, tip)
            # Set by the inspection (and AddCmm), read by AddCmm: not an input to edit.
            registration.setEditorMode(prop, ["ReadOnly"])
    registration.InspectionHeights = [float(h) for h in heights_pct]
    registration.FirstPlannedRow = int(first_planned_row)
    registration.InspectionFolder = out_dir


def cmm_section_table(registration, cmm_path):
    """Table 2 of a Registration with the CMM file's columns beside the optical ones. For an
    inspection, at its nominal sections from the planned points only; for any other
    registration, the sections the section analysis would choose."""
    if registration.Nominal is None:
        raise InputError("%s: no nominal linked" % registration.Label)
    cmm = read_cmm(cmm_path)
    nominal = objects.nominal_of(registration.Nominal)
    result = objects.registration_result(registration, nominal)
    heights = list(getattr(registration, "InspectionHeights", []) or [])
    if heights:
        first = int(registration.FirstPlannedRow)
        if not 0 <= first < len(result.points_cad):
            raise InputError("%s: FirstPlannedRow %d is outside its %d points"
                             % (registration.Label, first, len(result.points_cad)))
        planned = result.planned_rows(np.arange(first, len(result.points_cad)))
        table = section_table(planned, nominal, heights_pct=heights, cmm=cmm)
    else:
        table = section_table(result, nominal, cmm=cmm)
    if "CmmFile" not in registration.PropertiesList:
        registration.addProperty("App::PropertyFile", "CmmFile", INSPECTION_GROUP,
                                 "CMM file compared in Table 2")
    registration.CmmFile = cmm_path
    return table, nominal
