"""Document side of the closed loop: the planned paths as Part geometry, and what an
inspection leaves on its Registration, so that its report, section analysis, airfoil analysis
and a CMM file added later take the inspection's own sections and judge as it did.
No GUI imports: the workbench commands in gui/loop_commands.py call these."""

import numpy as np

import FreeCAD

from ..core.errors import InputError
from ..inspection import verdict as verdict_mod
from ..inspection.planned_sections import PlannedSections
from ..inspection.sections import read_cmm, section_table
from . import objects, registration_fit

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


def mark_inspection(registration, heights_pct, first_planned_row, out_dir, tolerance=None,
                    airfoil=False):
    """Record on a Registration made by an inspection which rows were measured along the
    planned paths, at which heights, against which tolerance and whether the airfoil
    characteristics were judged: its report, section analysis, airfoil analysis and a CMM file
    added later all take the same nominal sections (planned_sections) and judge as it did."""
    for kind, prop, tip in (
            ("App::PropertyFloatList", "InspectionHeights", "Nominal section heights, % of span"),
            ("App::PropertyInteger", "FirstPlannedRow",
             "Rows from here on were measured along the planned paths"),
            ("App::PropertyPath", "InspectionFolder", "Where the inspection wrote its files"),
            ("App::PropertyFile", "CmmFile", "CMM file compared in Table 2"),
            ("App::PropertyFloat", "InspectionToleranceMm",
             "Profile tolerance the inspection judged against, mm"),
            ("App::PropertyBool", "InspectionAirfoil",
             "The inspection judged the airfoil characteristics")):
        if prop not in registration.PropertiesList:
            registration.addProperty(kind, prop, INSPECTION_GROUP, tip)
            # Set by the inspection (and AddCmm), read by AddCmm: not an input to edit.
            registration.setEditorMode(prop, ["ReadOnly"])
    registration.InspectionHeights = [float(h) for h in heights_pct]
    registration.FirstPlannedRow = int(first_planned_row)
    registration.InspectionFolder = out_dir
    if tolerance is not None:
        registration.InspectionToleranceMm = float(tolerance)
    registration.InspectionAirfoil = bool(airfoil)


def planned_sections(registration):
    """An inspection's sections (inspection.planned_sections.PlannedSections) from what
    mark_inspection recorded; None for a registration no inspection made."""
    heights = list(getattr(registration, "InspectionHeights", []) or [])
    if not heights:
        return None
    return PlannedSections(tuple(float(h) for h in heights), int(registration.FirstPlannedRow))


def tolerance_of(registration, default):
    """The profile tolerance an inspection judged against; ``default`` for any other
    registration (or an inspection stored before the tolerance was recorded)."""
    tolerance = float(getattr(registration, "InspectionToleranceMm", 0.0) or 0.0)
    return tolerance if tolerance > 0 else float(default)


def judges_airfoil(registration):
    """Whether the inspection that made ``registration`` judged the airfoil characteristics."""
    return bool(getattr(registration, "InspectionAirfoil", False))


def section_table_of(registration, result, nominal, cmm=None):
    """Table 2 of a Registration: for an inspection, at its planned sections from the points
    measured along the planned paths (the blind scan's passes only placed the part); for any
    other registration, the sections the points' section column or the default heights give."""
    planned = planned_sections(registration)
    if planned is None:
        return section_table(result, nominal, cmm=cmm)
    return planned.table(result, nominal, cmm=cmm)


def judged_section_table(registration, result, nominal, tolerance):
    """(Table 2, verdict) of a Registration as stored (at its fit's pose): section_table_of
    judged against the inspection's tolerance (``tolerance`` for another registration) under
    its fit's decision rule, with U and TUR per section (inspection.verdict.judge)."""
    table = section_table_of(registration, result, nominal)
    verdict = verdict_mod.judge(result, table, tolerance=tolerance_of(registration, tolerance),
                                decision_rule=registration_fit.choice_of(registration)
                                .decision_rule)
    return table, verdict


def cmm_section_table(registration, cmm_path):
    """Table 2 of a Registration with the CMM file's columns beside the optical ones. For an
    inspection, at its nominal sections from the planned points only; for any other
    registration, the sections the section analysis would choose."""
    if registration.Nominal is None:
        raise InputError("%s: no nominal linked" % registration.Label)
    cmm = read_cmm(cmm_path)
    nominal = objects.nominal_of(registration.Nominal)
    result = objects.registration_result(registration, nominal)
    table = section_table_of(registration, result, nominal, cmm=cmm)
    if "CmmFile" not in registration.PropertiesList:
        registration.addProperty("App::PropertyFile", "CmmFile", INSPECTION_GROUP,
                                 "CMM file compared in Table 2")
    registration.CmmFile = cmm_path
    return table, nominal


def report_options(registration, default_tolerance):
    """(inspection.run_options.RunOptions, PlannedSections or None) of the report of a
    Registration: its fit; for an inspection, the inspection's tolerance, sections and airfoil
    characteristics, so that the report judges what the inspection judged."""
    from ..inspection import airfoil_stage
    from ..inspection.run_options import RunOptions
    options = RunOptions(tolerance=tolerance_of(registration, default_tolerance),
                         fit_choice=registration_fit.choice_of(registration),
                         airfoil=airfoil_stage.options_from_args()
                         if judges_airfoil(registration) else None)
    return options, planned_sections(registration)
