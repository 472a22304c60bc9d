"""The workbench's commands (BladeInspect_<Verb>). Each gathers its inputs from the document
and the selection, runs a pipeline stage with progress and cancel (gui.progress.run), and
stores the outcome as document objects through the app layer's make_* functions, which remove
what they made if anything fails. What makes objects runs as a console line through
FreeCADGui.doCommand (do_command, run_action): an app.objects or app.actions call with literal
arguments, which a recorded macro replays."""
import os
import tempfile

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from ..app import actions, loop, objects, settings
from ..app.document import write_inspection_document
from ..core.errors import InputError
from ..inspection.report import section_rows, write_result_report
from ..inspection.run_options import ReportSources
from ..measurement.scan import open_rig
from . import forms, progress, resources, taskpanels, viewproviders  # noqa: F401 (VPs)
from .command_base import (Command, find_measurement, find_nominal, find_registration,
                           inputs_of, nominals_of)
from .i18n import QT_TRANSLATE_NOOP, translate
from .preferences import PreferencesPage
from .session import RIG

POINT_FILTER = QT_TRANSLATE_NOOP(
    "BladeInspect", "Point files (*.csv *.xyz *.asc *.txt *.ply *.pcd);;All files (*)")
CAD_FILTER = QT_TRANSLATE_NOOP(
    "BladeInspect",
    "CAD files (*.step *.stp *.iges *.igs *.brep *.brp *.FCStd *.dat);;All files (*)")


# ---------------------------------------------------------------- file dialogs (tests replace)

def ask_open_file(title, filters):
    path, _ = QtGui.QFileDialog.getOpenFileName(FreeCADGui.getMainWindow(), title, "",
                                                translate("BladeInspect", filters))
    return path or None


def ask_directory(title):
    path = QtGui.QFileDialog.getExistingDirectory(FreeCADGui.getMainWindow(), title)
    return path or None


def open_in_browser(path):
    QtGui.QDesktopServices.openUrl(QtCore.QUrl.fromLocalFile(path))


# The input panels' Browse buttons open this module's dialog, looked up when clicked.
forms.FILE_DIALOG["open"] = lambda title, filters: ask_open_file(title, filters)


# ---------------------------------------------------------------- document helpers

def active_document(create=True):
    doc = FreeCAD.ActiveDocument
    if doc is None and create:
        doc = FreeCAD.newDocument("Inspection")
    return doc


def do_command(imports, call):
    """Make a document object by running ``call`` (Python text) through FreeCADGui.doCommand,
    after the ``imports`` lines, so that it shows in the Python console and is recorded in a
    macro, as FreeCAD's own commands (Fem's) make theirs. Returns the object made (the
    console's ``obj``); an error raised by ``call`` propagates as it is."""
    for line in ("import FreeCAD",) + tuple(imports):
        FreeCADGui.doCommand(line)
    FreeCADGui.doCommand("obj = " + call)
    import __main__
    return __main__.obj


def document_text(doc):
    """Python text naming ``doc`` in the console."""
    return "FreeCAD.getDocument(%r)" % doc.Name


def object_text(obj):
    """Python text naming the document object ``obj`` in the console."""
    return "%s.getObject(%r)" % (document_text(obj.Document), obj.Name)


APP_OBJECTS = "from BladeInspect.app import objects"


def run_action(title, function, *args, on_plan=None, rig=None, **kwargs):
    """app.actions.<function>(*args, **kwargs) as a console line (do_command) under
    progress.run(title): the status-bar progress, the plan drawing ``on_plan`` and the
    connected ``rig`` reach it through actions.interactive. Returns its value, or None when it
    failed or was cancelled (reported)."""
    imports, call = actions.call_text(function, *args, **kwargs)

    def job(p):
        with actions.interactive(progress=p, on_plan=on_plan, rig=rig):
            try:
                return do_command(imports, call)
            except InputError as exc:
                # The GUI's user changes a control, not a command-line option.
                raise InputError(forms.gui_text(str(exc))) from None
    return progress.run(title, job)


def announced(title, obj):
    """``obj``, named in the Report view as what the command ``title`` works on (the selected
    one, else the newest): a command without a panel still says what it uses."""
    FreeCAD.Console.PrintMessage(translate("BladeInspect", "BladeInspect: %s uses %s (%s)")
                                 % (title, obj.Label, obj.Name) + "\n")
    return obj


def fit_view():
    if FreeCADGui.ActiveDocument is not None:
        view = FreeCADGui.ActiveDocument.ActiveView
        if hasattr(view, "viewIsometric"):
            view.viewIsometric()
            view.fitAll()


def _recompute_gui(doc):
    doc.recompute()
    fit_view()


# ---------------------------------------------------------------- commands

class _OpenFileCommand(Command):
    """A command that reads one file the user picks and makes an object of it (self.load)."""
    dialog_title = ""
    file_filter = ""

    def Activated(self):
        path = ask_open_file(translate("BladeInspect", self.dialog_title), self.file_filter)
        if path:
            self.load(path)


class DemoBlade(Command):
    name = "BladeInspect_DemoBlade"
    menu = QT_TRANSLATE_NOOP("BladeInspect_DemoBlade", "Demo blade")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_DemoBlade",
        "Build the parametric demo blade as the nominal CAD (parameters in a task panel)")

    panel = taskpanels.DemoBladePanel

    def start(self, params):
        return self.build(params)

    def build(self, params):
        doc = active_document()
        obj = progress.run(translate("BladeInspect", "Demo blade"), lambda p: do_command(
            (APP_OBJECTS, "from BladeInspect.cad.demo_blade import BladeParams"),
            "objects.make_demo_blade(%s, %r)" % (document_text(doc), params)))
        if obj is not None:
            _recompute_gui(doc)
        return obj


class LoadCad(_OpenFileCommand):
    name = "BladeInspect_LoadCad"
    menu = QT_TRANSLATE_NOOP("BladeInspect_LoadCad", "Load CAD...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_LoadCad",
        "Load the nominal blade from a STEP, IGES, BREP or FCStd file (or a section table)")
    dialog_title = QT_TRANSLATE_NOOP("BladeInspect", "Nominal CAD")
    file_filter = CAD_FILTER

    def load(self, path):
        doc = active_document()
        obj = progress.run(translate("BladeInspect", "Load CAD"), lambda p: do_command(
            (APP_OBJECTS,), "objects.make_cad_model(%s, %r)" % (document_text(doc), path)))
        if obj is not None:
            _recompute_gui(doc)
        return obj


class ConnectRig(Command):
    name = "BladeInspect_ConnectRig"
    menu = QT_TRANSLATE_NOOP("BladeInspect_ConnectRig", "Connect rig...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_ConnectRig",
        "Connect the four-axis rig: the simulated rig (needs a nominal) or a serial port")

    panel = taskpanels.ConnectRigPanel

    def start(self, spec, seed):
        return self.connect(spec, seed)

    def connect(self, spec, seed):
        def job(p):
            nominal_obj = find_nominal()
            if spec == "sim" and nominal_obj is None:
                raise InputError(translate(
                    "BladeInspect", "simulated rig: load a CAD or build the demo blade first"))
            nominal = objects.nominal_of(nominal_obj) if nominal_obj is not None else None
            p(0.5, translate("BladeInspect", "opening %s") % spec)
            RIG.connect(open_rig(spec, nominal, seed, sensor=settings.sensor_model()), spec,
                        seed)
            return RIG.rig
        rig = progress.run(translate("BladeInspect", "Connect rig"), job)
        if rig is not None:
            FreeCAD.Console.PrintMessage(
                translate("BladeInspect", "BladeInspect: rig connected (%s)") % spec + "\n")
        return rig


class Scan(Command):
    name = "BladeInspect_Scan"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Scan", "Scan...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Scan",
        "Scan the blade section by section with the connected rig (progress and abort)")

    is_active = "with_rig"

    panel = taskpanels.ScanPanel

    def start(self, options):
        return self.scan(options)

    def scan(self, options):
        """app.actions.scan with the connected rig; the line names the rig's spec and seed
        so that a replayed macro opens the same one."""
        doc = active_document()
        nominal_obj = find_nominal()
        obj = run_action(translate("BladeInspect", "Scan"), "scan", doc.Name, scan_folder(doc),
                         rig_spec=RIG.spec, rig_seed=RIG.seed, rig=RIG.rig,
                         nominal=nominal_obj.Name if nominal_obj is not None else None,
                         **options)
        if obj is not None:
            _recompute_gui(doc)
        return obj


def scan_folder(doc):
    """Where a scan's points.csv goes: beside the saved document, else a new temporary folder."""
    if doc.FileName:
        base = os.path.splitext(doc.FileName)[0] + "_scans"
        os.makedirs(base, exist_ok=True)
        return tempfile.mkdtemp(prefix="scan-", dir=base)
    return tempfile.mkdtemp(prefix="bladeinspect-scan-")


class ImportPoints(_OpenFileCommand):
    name = "BladeInspect_ImportPoints"
    menu = QT_TRANSLATE_NOOP("BladeInspect_ImportPoints", "Import points...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_ImportPoints",
        "Import a measured point cloud (csv/xyz/asc/txt with optional SNR, ply, pcd)")
    dialog_title = QT_TRANSLATE_NOOP("BladeInspect", "Measured points")
    file_filter = POINT_FILTER

    def load(self, path):
        doc = active_document()

        def job(p):
            p(0.1, translate("BladeInspect", "reading %s") % os.path.basename(path))
            obj = do_command(
                (APP_OBJECTS, "from BladeInspect.inspection.pipeline import load_points"),
                "objects.make_measurement(%s, load_points(%r), name='Measurement', "
                "source_file=%r)" % (document_text(doc), path, path))
            obj.Label = os.path.splitext(os.path.basename(path))[0]
            return obj
        obj = progress.run(translate("BladeInspect", "Import points"), job)
        if obj is not None:
            _recompute_gui(doc)
        return obj


class Reconstruct(Command):
    name = "BladeInspect_Reconstruct"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Reconstruct", "Reconstruct")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Reconstruct",
        "Fit cubic B-spline section curves to the measurement and loft them into surfaces")

    is_active = "with_measurement"

    def Activated(self):
        self.reconstruct(announced(translate("BladeInspect", "Reconstruct"), find_measurement()))

    def reconstruct(self, measurement):
        """app.actions.reconstruct of the measurement."""
        doc = measurement.Document
        obj = run_action(translate("BladeInspect", "Reconstruct"), "reconstruct", doc.Name,
                         measurement.Name)
        if obj is not None:
            _recompute_gui(doc)
        return obj


class Register(Command):
    name = "BladeInspect_Register"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Register", "Register")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Register",
        "Register the measurement to the nominal with no starting pose (PCA, then SNR-"
        "weighted ICP), move it to the chosen fit and show the pose with its uncertainty and "
        "the fit-sensitivity table")
    panel = taskpanels.RegisterPanel

    is_active = "with_measurement_and_nominal"

    def Activated(self):
        doc = FreeCAD.ActiveDocument
        FreeCADGui.Control.showDialog(self.panel(
            self.start, nominals=nominals_of(doc), measurements=inputs_of(
                doc, (objects.Measurement.Type,)),
            nominal=find_nominal(), measurement=find_measurement()))

    def start(self, nominal, measurement, seed, allow_mismatch=False, **fit):
        doc = FreeCAD.ActiveDocument
        obj = self.register(doc.getObject(measurement), doc.getObject(nominal), seed,
                            allow_mismatch, **fit)
        if obj is not None:
            self.show(obj)
        return obj

    def register(self, measurement, nominal_obj, seed=None, allow_mismatch=False, **fit):
        """app.actions.register; ``allow_mismatch`` keeps a scan that does not fit the CAD;
        ``fit``: the fit selector's choice (app.actions.fit_choice)."""
        doc = measurement.Document
        seed = settings.value("Seed") if seed is None else seed
        if allow_mismatch:
            fit["allow_mismatch"] = True
        obj = run_action(translate("BladeInspect", "Register"), "register", doc.Name,
                         measurement.Name, nominal_obj.Name, int(seed),
                         tolerance=float(settings.value("ToleranceMm")), **fit)
        if obj is not None:
            doc.recompute()
            for warning in obj.Warnings:
                FreeCAD.Console.PrintWarning("BladeInspect: %s\n" % warning)
        return obj

    @staticmethod
    def show(obj):
        taskpanels.show_panel(taskpanels.RegistrationPanel(obj))


class DeviationMap(Command):
    name = "BladeInspect_DeviationMap"
    menu = QT_TRANSLATE_NOOP("BladeInspect_DeviationMap", "Deviation map")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_DeviationMap",
        "Colour the registered points by signed deviation (limits from the preferences)")

    is_active = "with_registration"

    def Activated(self):
        self.make(announced(translate("BladeInspect", "Deviation map"), find_registration()))

    def make(self, registration, limit=None):
        doc = registration.Document
        limit = settings.colour_limit() if limit is None else limit
        obj = progress.run(translate("BladeInspect", "Deviation map"), lambda p: do_command(
            (APP_OBJECTS,), "objects.make_deviation_map(%s, %s, %r)"
            % (document_text(doc), object_text(registration), float(limit))))
        if obj is not None:
            # The map shows the points on the CAD; the measurement and its reconstruction lie
            # in the measured frame elsewhere and would only pull the view away.
            measurement = registration.Measurement
            for other in doc.Objects:
                in_measured_frame = other == measurement or (
                    objects.proxy_type(other) == objects.Reconstruction.Type
                    and other.Measurement == measurement)
                if measurement is not None and in_measured_frame and other.ViewObject:
                    other.ViewObject.Visibility = False
            _recompute_gui(doc)
        return obj


class SectionAnalysis(Command):
    name = "BladeInspect_SectionAnalysis"
    menu = QT_TRANSLATE_NOOP("BladeInspect_SectionAnalysis", "Section analysis")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_SectionAnalysis",
        "Profile errors per section (Table 2): RMS, worst deviation, leading/trailing edge")

    is_active = "with_registered_nominal"

    def Activated(self):
        table = self.analyse(announced(translate("BladeInspect", "Section analysis"),
                                       find_registration()))
        if table is not None:
            self.show(table)

    def analyse(self, registration):
        """The section table of a registration (app.actions.section_analysis), its nominal
        profiles added to the document; None when it failed (reported)."""
        doc = registration.Document
        table = run_action(translate("BladeInspect", "Section analysis"), "section_analysis",
                           doc.Name, registration.Name)
        if table is not None:
            doc.recompute()
            for warning in table.warnings:
                FreeCAD.Console.PrintWarning("BladeInspect: %s\n" % warning)
        return table

    @staticmethod
    def show(table):
        header, rows = section_rows(table)
        taskpanels.show_panel(taskpanels.TablePanel(
            translate("BladeInspect", "Section analysis"), header, rows,
            "; ".join(table.warnings), verdict=getattr(table, "verdict", None)))


class Report(Command):
    name = "BladeInspect_Report"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Report", "Report...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Report",
        "Write the inspection report (HTML and PDF, result.json, deviations.csv) to a folder")

    is_active = "with_registered_inputs"

    def Activated(self):
        out_dir = ask_directory(translate("BladeInspect", "Report folder"))
        if out_dir:
            registration = announced(translate("BladeInspect", "Report"), find_registration())
            summary = self.report(registration, out_dir)
            html = os.path.join(out_dir, "report.html")
            if summary is not None:
                FreeCAD.Console.PrintMessage(
                    translate("BladeInspect", "BladeInspect: report in %s; ICP weights: %s")
                    % (out_dir, registration.WeightsUsed or "-") + "\n")
            if summary is not None and os.path.exists(html):
                open_in_browser(html)

    def report(self, registration, out_dir):
        """The `report` files of the registration as the document holds it (no second
        registration, nothing written outside out_dir)."""
        nominal_obj = registration.Nominal
        cad_path = getattr(nominal_obj, "SourceFile", "") or None
        # inspection.FCStd rebuilds the nominal from its CAD file, or as the demo blade; a shape
        # that is neither has no file the document could point at, so it gets no document.
        is_demo = objects.proxy_type(nominal_obj) == objects.DemoBlade.Type
        writer = write_inspection_document if cad_path or is_demo else None

        def job(p):
            if registration.Proxy.signature(registration) != registration.InputSignature:
                registration.recompute()    # the inputs changed since it was stored
            nominal = objects.nominal_of(nominal_obj)
            result = objects.registration_result(registration, nominal)
            result.cad_source = cad_path or "built-in demo blade"
            # an inspection's report judges its sections, tolerance and airfoil as it did
            options, planned = loop.report_options(registration, settings.value("ToleranceMm"))
            return write_result_report(result, nominal, out_dir, options, progress=p,
                                       document=writer,
                                       sources=ReportSources(cad_path=cad_path, planned=planned))
        doc = registration.Document
        try:
            return progress.run(translate("BladeInspect", "Report"), job)
        finally:
            # The report saves its own document, which leaves another one active.
            FreeCAD.setActiveDocument(doc.Name)
            FreeCADGui.setActiveDocument(doc.Name)


class Airfoil(Command):
    name = "BladeInspect_Airfoil"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Airfoil", "Airfoil analysis...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Airfoil",
        "Airfoil characteristics per section (chord, stagger, thickness, edge radii, angles, "
        "shift, twist) nominal and measured, judged against a characteristics file; the mean "
        "camber lines and edge circles added to the document")
    panel = taskpanels.AirfoilOptionsPanel

    is_active = "with_registered_nominal"

    def Activated(self):
        doc = FreeCAD.ActiveDocument
        FreeCADGui.Control.showDialog(self.panel(
            self.start, registrations=[r for r in inputs_of(doc, (objects.Registration.Type,))
                                       if r.Nominal is not None],
            registration=find_registration()))

    def start(self, registration, **options):
        stage = self.analyse(FreeCAD.ActiveDocument.getObject(registration), **options)
        if stage is not None:
            self.show(stage.extras())
        return stage

    def analyse(self, registration, **options):
        """app.actions.airfoil; ``options``: characteristics, chord_method, engine_axis (the
        `airfoil` command's --characteristics, --chord-method, --engine-axis)."""
        doc = registration.Document
        stage = run_action(translate("BladeInspect", "Airfoil analysis"), "airfoil", doc.Name,
                           registration.Name, **options)
        if stage is not None:
            _recompute_gui(doc)
        return stage

    @staticmethod
    def show(analysis):
        taskpanels.show_panel(taskpanels.AirfoilPanel(analysis))


class Help(Command):
    name = "BladeInspect_Help"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Help", "BladeInspect user guide")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Help",
        "Open the user guide: the workflows, their panels and what the results mean")
    pixmap = "BladeInspect"

    def Activated(self):
        open_in_browser(user_guide_path())


def user_guide_path():
    """docs/user-guide.md of the installed workbench, else its README."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    guide = os.path.join(root, "docs", "user-guide.md")
    return guide if os.path.exists(guide) else os.path.join(root, "README.md")


class Preferences(Command):
    name = "BladeInspect_Preferences"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Preferences", "Preferences...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Preferences",
        "Sensor and rig parameters, tolerance and colour limits")

    def Activated(self):
        FreeCADGui.showPreferences("BladeInspect")


COMMANDS = [DemoBlade(), LoadCad(), ConnectRig(), Scan(), ImportPoints(), Reconstruct(),
            Register(), DeviationMap(), SectionAnalysis(), Airfoil(), Report(), Preferences(),
            Help()]
TOOLBAR = [c.name for c in COMMANDS if c.name not in (Preferences.name, Help.name)]
MENU = [c.name for c in COMMANDS if c.name != Help.name]
# FreeCAD's Help menu gains the workbench's user guide while the workbench is active.
HELP_MENU = [Help.name]
BY_NAME = {c.name: c for c in COMMANDS}

for _command in COMMANDS:
    FreeCADGui.addCommand(_command.name, _command)


def register_preferences():
    # The preferences dialog shows a group's icon by the name "preferences-<group>".
    FreeCADGui.addIconPath(resources.ICON_DIR)
    FreeCADGui.addPreferencePage(PreferencesPage, "BladeInspect")
