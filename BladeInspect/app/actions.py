"""What the workbench's long commands do, as plain functions of document and object names and
literal options, so that the GUI runs each through FreeCADGui.doCommand (the line shows in the
Python console and a recorded macro replays it, also in FreeCADCmd) — as Fem's commands do.

What only an interactive session has (the status-bar progress with its Cancel, the drawing of
a plan before its paths run, the rig connected in the GUI's session) is not an argument: the
GUI wraps the console line in ``interactive(...)``; a replayed macro runs without them (no
progress, nothing drawn, the simulated rig or a serial port opened from its spec).

No GUI imports (app layer)."""

import ast
import contextlib
import os

import numpy as np

import FreeCAD

from ..core.errors import InputError
from ..core.pointio import read_points
from ..inspection import fitting
from ..inspection import pipeline
from . import loop, objects, settings
from .registration_fit import judge_fits

MODULE = __name__          # "BladeInspect.app.actions": what a console line imports

_INTERACTIVE = {"progress": None, "on_plan": None, "rig": None}


@contextlib.contextmanager
def interactive(progress=None, on_plan=None, rig=None):
    """Run the actions called inside with the GUI's progress(fraction, message) (which may
    raise Cancelled), its on_plan(plan) drawing, and its connected rig."""
    saved = dict(_INTERACTIVE)
    _INTERACTIVE.update(progress=progress, on_plan=on_plan, rig=rig)
    try:
        yield
    finally:
        _INTERACTIVE.update(saved)


def _progress():
    return _INTERACTIVE["progress"] or (lambda fraction, message: None)


def call_text(function, *args, **kwargs):
    """(imports, call): the console lines of ``function(*args, **kwargs)`` of this module.
    Every argument must be a Python literal, so the line replays anywhere."""
    if not callable(globals().get(function)):
        raise ValueError("%s has no action %r" % (MODULE, function))
    for value in list(args) + list(kwargs.values()):
        try:
            literal = ast.literal_eval(repr(value)) == value
        except (SyntaxError, ValueError):
            literal = False
        if not literal:
            raise ValueError("%r: not a Python literal" % (value,))
    parts = [repr(a) for a in args] + ["%s=%r" % kv for kv in sorted(kwargs.items())]
    return ("import %s" % MODULE,), "%s.%s(%s)" % (MODULE, function, ", ".join(parts))


def _document(name):
    doc = FreeCAD.getDocument(name) if name in FreeCAD.listDocuments() else None
    if doc is None:
        raise InputError("%s: no such document" % name)
    return doc


def _object(doc, name, what):
    obj = doc.getObject(name)
    if obj is None:
        raise InputError("%s: no %s %r in the document" % (doc.Name, what, name))
    return obj


def _registration(doc_name, name):
    """(document, Registration) by name; the Registration must have its nominal linked."""
    doc = _document(doc_name)
    reg = _object(doc, name, "registration")
    if reg.Nominal is None:
        raise InputError("%s: no nominal linked" % reg.Label)
    return doc, reg


def fit_choice(fit=fitting.DEFAULT_OBJECTIVE, free=None, weights_by_zone=None,
               decision_rule="iso14253", datum_faces=None, weights=None):
    """The FitChoice of the GUI's fit selector (the same checks as the command line's);
    ``weights``: the fine ICP's, as --weights (None: inspection.weighting's default)."""
    return fitting.FitChoice(objective=fit, free=free or None,
                             weights_by_zone=weights_by_zone or None,
                             decision_rule=decision_rule, datum_faces=datum_faces or None,
                             weights=weights or None)


# ---------------------------------------------------------------- actions

def register(doc_name, measurement, nominal, seed=0, tolerance=None, allow_mismatch=False,
             **fit):
    """Register the Measurement named ``measurement`` to the nominal named ``nominal``
    (pipeline.register; ``allow_mismatch`` keeps a scan that does not fit the CAD, with a
    warning), move it to the fit ``fit`` chooses (keywords of fit_choice) and add the
    Registration with its fit and fit-sensitivity table."""
    doc = _document(doc_name)
    measurement_obj = _object(doc, measurement, "measurement")
    nominal_obj = _object(doc, nominal, "nominal")
    choice = fit_choice(**fit)     # checked first: a typo must not cost a registration
    tolerance = settings.value("ToleranceMm") if tolerance is None else float(tolerance)
    p = _progress()
    p(0.0, "sampling the nominal")
    model = objects.nominal_of(nominal_obj)
    result = pipeline.register(model, objects.pointset_of(measurement_obj), seed=seed,
                               progress=lambda f, m: p(0.85 * f, m), weights=choice.weights,
                               allow_mismatch=bool(allow_mismatch),
                               cad_source=nominal_obj.Label)
    result.cad_source = nominal_obj.Label
    p(0.9, "fit: %s, and its sensitivity" % choice.objective)
    judge_fits(result, model, choice, tolerance)
    return objects.make_registration(doc, result, measurement_obj, nominal_obj, seed,
                                     fit_choice=choice)


def reconstruct(doc_name, measurement):
    """Cubic B-spline section curves of the Measurement named ``measurement`` lofted into
    surfaces (cad.loft.reconstruct), added as its Reconstruction."""
    from ..cad.loft import reconstruct as loft_reconstruct
    doc = _document(doc_name)
    measurement_obj = _object(doc, measurement, "measurement")
    p = _progress()
    p(0.1, "fitting section curves")
    recon = loft_reconstruct(objects.pointset_of(measurement_obj))
    if recon is None:
        raise InputError("%s: no section and angle_deg columns, so no section curves to fit "
                         "(a scan's points have them)" % measurement_obj.Label)
    p(0.9, "storing %d curves, %d surfaces" % (len(recon.curves), len(recon.surfaces)))
    return objects.make_reconstruction(doc, measurement_obj, recon)


def simulate(doc_name, seed=0, nominal=None, **options):
    """The simulation test bed (inspection.simulate.run_simulation, the `simulate` command's)
    on the nominal named ``nominal``, else on a new demo blade; adds the simulated measurement,
    its registration (with the pose error against the simulator's truth) and deviation map.
    Returns (report, registration, deviation map)."""
    from ..inspection.simulate import run_simulation
    doc = _document(doc_name)
    p = _progress()
    with objects.building(doc, "Simulation test bed"):
        if nominal is None:
            p(0.0, "building the demo blade")
            nominal_obj = objects.make_demo_blade(doc)
            doc.recompute()
        else:
            nominal_obj = _object(doc, nominal, "nominal")
        result, report, pointset = run_simulation(
            objects.nominal_of(nominal_obj), seed=seed, progress=p, **options)
        result.cad_source = nominal_obj.Label
        measurement = objects.make_measurement(doc, pointset, name="SimulatedScan")
        registration = objects.make_registration(doc, result, measurement, nominal_obj,
                                                 seed, name="SimulatedRegistration")
        for prop, tip, value in (
                ("PoseErrorMm", "Pose error against the simulator's truth (largest "
                 "bounding-box corner displacement), mm", report["pose_error_mm"]),
                ("PoseErrorOverBound", "Pose error / its Cramer-Rao bound",
                 report["pose_error_over_bound"])):
            registration.addProperty("App::PropertyFloat", prop, "Simulation", tip)
            setattr(registration, prop, value)
            # The simulator's truth, not an input.
            registration.setEditorMode(prop, ["ReadOnly"])
        deviation_map = objects.make_deviation_map(doc, registration, settings.colour_limit())
    return report, registration, deviation_map


def _registered_sections(reg, p):
    """(Nominal, RegistrationResult, section table) of a Registration, as stored; an
    inspection's table at its planned sections (app.loop.section_table_of)."""
    nominal = objects.nominal_of(reg.Nominal)
    p(0.2, "signed distances of the registered points")
    result = objects.registration_result(reg, nominal)
    p(0.5, "cutting sections")
    return nominal, result, loop.section_table_of(reg, result, nominal)


def section_analysis(doc_name, registration, tolerance=None):
    """The section table of the Registration named ``registration`` (inspection.sections;
    an inspection's at its planned sections), its nominal profiles added to the document.
    The table's ``verdict`` is inspection.verdict.judge's against ``tolerance`` (None: the
    preferences'; an inspection's own tolerance for an inspection), per section with U and
    TUR."""
    doc, reg = _registration(doc_name, registration)
    tolerance = settings.value("ToleranceMm") if tolerance is None else float(tolerance)
    p = _progress()
    nominal = objects.nominal_of(reg.Nominal)
    p(0.2, "signed distances of the registered points")
    result = objects.registration_result(reg, nominal)
    p(0.5, "cutting sections")
    table, verdict = loop.judged_section_table(reg, result, nominal, tolerance)
    table.verdict = verdict
    objects.make_section_profiles(doc, table, reg)
    return table


def scan(doc_name, out_dir, rig_spec="sim", rig_seed=0, nominal=None, **options):
    """Scan with the rig (the GUI's connected one, else opened from ``rig_spec`` and
    ``rig_seed``; the simulated rig needs the nominal named ``nominal``) into out_dir with the
    scan ``options`` (measurement.scan.scan_to_dir's), and add the points as a Measurement."""
    from ..measurement.scan import open_rig, scan_to_dir
    doc = _document(doc_name)
    rig = _INTERACTIVE["rig"]
    opened = rig is None
    if opened:
        model = objects.nominal_of(_object(doc, nominal, "nominal")) if nominal else None
        if rig_spec == "sim" and model is None:
            raise InputError("simulated rig: load a CAD or build the demo blade first")
        rig = open_rig(rig_spec, model, rig_seed, sensor=settings.sensor_model())
    try:
        scan_to_dir(out_dir, rig, progress=_progress(), **options)
    finally:
        if opened:
            rig.close()
    path = os.path.join(out_dir, "points.csv")
    return objects.make_measurement(doc, pipeline.load_points(path), name="Scan",
                                    source_file=path)


@contextlib.contextmanager
def inspection_rig(nominal_obj, seed, rig_file=None):
    """The rig Inspect runs on: the GUI's connected one, else the simulated rig with the
    preferences' sensor, its true geometry ``rig_file``'s, closed after."""
    if _INTERACTIVE["rig"] is not None:
        yield _INTERACTIVE["rig"]
        return
    from ..measurement.scan import open_rig
    from ..rig.kinematics import RigKinematics
    kinematics = RigKinematics.from_json(rig_file) if rig_file else None
    rig = open_rig("sim", objects.nominal_of(nominal_obj), seed, kinematics=kinematics,
                   sensor=settings.sensor_model())
    try:
        yield rig
    finally:
        rig.close()


def inspect(doc_name, nominal, out_dir, heights, tolerance, seed, rig_file=None, airfoil=True,
            resume=False, **fit):
    """run_inspect on the nominal named ``nominal`` (the `inspect` command's pipeline), the
    fit ``fit`` chooses, with the airfoil characteristics unless ``airfoil`` is False (as the
    command's default and its --no-airfoil); the points, registration, deviation map, section
    profiles and airfoil objects added. Returns run_inspect's summary with the new objects
    under "objects". ``resume``: continue the inspection interrupted in ``out_dir`` (as the
    command's --resume), with the same options."""
    from ..inspection import airfoil_stage as airfoil_mod
    from ..inspection.closed_loop import run_inspect
    from ..inspection.run_options import LoopOptions, RunOptions
    from . import airfoil_objects
    airfoil_options = airfoil_mod.options_from_args() if airfoil else None
    doc = _document(doc_name)
    nominal_obj = _object(doc, nominal, "nominal")
    choice = fit_choice(**fit)
    if rig_file and not os.path.isfile(rig_file):
        raise InputError("rig calibration %s: no such file" % rig_file)
    p = _progress()
    with objects.building(doc, "Inspect"), inspection_rig(nominal_obj, seed, rig_file) as rig:
        summary = run_inspect(
            getattr(nominal_obj, "SourceFile", "") or None, out_dir,
            RunOptions(section_heights=heights, tolerance=tolerance, seed=seed,
                       rig_file=rig_file, fit_choice=choice, airfoil=airfoil_options,
                       loop=LoopOptions(resume=bool(resume))),
            rig=rig, nominal=objects.nominal_of(nominal_obj), progress=p, document=False,
            on_plan=_INTERACTIVE["on_plan"])
        result = summary["result"]
        p(0.95, "adding the inspection to the document")
        points_csv = os.path.join(out_dir, "points.csv")
        pointset = read_points(points_csv)
        if len(pointset.xyz) != len(result.points_cad):
            # The loop wrote its own points: a mismatch is a bug, not bad input.
            raise RuntimeError("%s: %d rows, the registration has %d points"
                               % (points_csv, len(pointset.xyz), len(result.points_cad)))
        measurement = objects.make_measurement(doc, pointset, name="InspectionPoints",
                                               source_file=points_csv)
        registration = objects.make_registration(doc, result, measurement, nominal_obj,
                                                 seed, name="Inspection", fit_choice=choice)
        n_blind = int(np.count_nonzero(result.columns["phase"] == "blind"))
        loop.mark_inspection(registration, heights, n_blind, out_dir, tolerance=tolerance,
                             airfoil=airfoil)
        p(0.96, "adding the deviation map")
        deviation_map = objects.make_deviation_map(doc, registration, settings.colour_limit(),
                                                   tolerance=tolerance)
        p(0.97, "adding the section profiles")
        profiles = objects.make_section_profiles(doc, summary["sections"], registration)
        p(0.98, "adding the airfoil objects")
        stage = getattr(summary["sections"], "airfoil", None)
        analysis = None if stage is None else airfoil_objects.make_airfoil_objects(
            doc, stage, registration, airfoil_options)
    summary["objects"] = {"measurement": measurement, "registration": registration,
                          "deviation_map": deviation_map, "profiles": profiles,
                          "airfoil": analysis}
    return summary


def airfoil(doc_name, registration, characteristics=None, chord_method=None,
            engine_axis=None, draws=None):
    """The airfoil characteristics (inspection.airfoil_stage) of the Registration named
    ``registration`` at its section table's planes, and the nominal and measured mean camber
    lines and edge circles of each section as document objects (app.airfoil_objects).
    Returns the stage (its ``blocks`` are result.json's ``airfoil``)."""
    from ..inspection import airfoil_stage as airfoil_mod
    from . import airfoil_objects
    doc, reg = _registration(doc_name, registration)
    opts = airfoil_mod.options_from_args(engine_axis=engine_axis,
                                         characteristics=characteristics,
                                         chord_method=chord_method)
    if draws is not None:   # re-fits for the uncertainty (0: none)
        opts.draws = int(draws)
    p = _progress()
    nominal, result, table = _registered_sections(reg, lambda f, m: p(0.5 * f, m))
    p(0.5, "airfoil characteristics")
    stage = airfoil_mod.run_stage(nominal, airfoil_mod.planes_of_table(table), opts, result,
                                  table.span_axis)
    p(0.9, "camber lines and edge circles")
    airfoil_objects.make_airfoil_objects(doc, stage, reg, opts)
    return stage
