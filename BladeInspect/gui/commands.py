"""The workbench's commands (BladeInspect_<Verb>). Each gathers its inputs from the document
and the selection, runs a pipeline stage with progress and cancel (gui.progress.run), and
stores the outcome as document objects through the app layer's make_* functions, which remove
what they made if anything fails."""
import os
import tempfile

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from ..app import objects, settings
from ..app.document import write_inspection_document
from ..cad.loft import reconstruct
from ..core.errors import InputError
from ..inspection.pipeline import load_points, register
from ..inspection.report import section_rows, write_result_report
from ..inspection.sections import section_table
from ..measurement.scan import open_rig, scan_to_dir
from . import progress, resources, taskpanels, viewproviders  # noqa: F401 (registers VPs)
from .preferences import PreferencesPage
from .session import RIG

# Marks the command texts for translation (FreeCAD translates them in the command's context).
QT_TRANSLATE_NOOP = FreeCAD.Qt.QT_TRANSLATE_NOOP

POINT_FILTER = "Point files (*.csv *.xyz *.asc *.txt *.ply *.pcd);;All files (*)"
CAD_FILTER = "CAD files (*.step *.stp *.iges *.igs *.brep *.brp *.FCStd *.dat);;All files (*)"


# ---------------------------------------------------------------- file dialogs (tests replace)

def ask_open_file(title, filters):
    path, _ = QtGui.QFileDialog.getOpenFileName(FreeCADGui.getMainWindow(), title, "", filters)
    return path or None


def ask_directory(title):
    path = QtGui.QFileDialog.getExistingDirectory(FreeCADGui.getMainWindow(), title)
    return path or None


def open_in_browser(path):
    QtGui.QDesktopServices.openUrl(QtCore.QUrl.fromLocalFile(path))


# ---------------------------------------------------------------- document helpers

def active_document(create=True):
    doc = FreeCAD.ActiveDocument
    if doc is None and create:
        doc = FreeCAD.newDocument("Inspection")
    return doc


def _selected():
    return [s for s in FreeCADGui.Selection.getSelection()] if FreeCAD.GuiUp else []


def find_input(type_names):
    """The selected object of one of these BladeInspect types, else the newest in the active
    document, else None."""
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    for obj in _selected():
        if objects.proxy_type(obj) in type_names:
            return obj
    for obj in reversed(doc.Objects):
        if objects.proxy_type(obj) in type_names:
            return obj
    return None


def find_nominal():
    """A nominal: a DemoBlade or CadModel object, else a selected Part feature with faces."""
    obj = find_input((objects.DemoBlade.Type, objects.CadModel.Type))
    if obj is not None:
        return obj
    for sel in _selected():
        shape = getattr(sel, "Shape", None)
        if shape is not None and not shape.isNull() and shape.Faces:
            return sel
    return None


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

class _Command:
    name = ""
    menu = ""
    tip = ""

    def GetResources(self):
        return {"Pixmap": resources.icon_path(self.name), "MenuText": self.menu,
                "ToolTip": self.tip}

    def IsActive(self):
        return not progress.busy() and self.ready()

    def ready(self):
        return True


class DemoBlade(_Command):
    name = "BladeInspect_DemoBlade"
    menu = QT_TRANSLATE_NOOP("BladeInspect_DemoBlade", "Demo blade")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_DemoBlade",
        "Build the parametric demo blade as the nominal CAD (parameters in a task panel)")

    def Activated(self):
        FreeCADGui.Control.showDialog(taskpanels.DemoBladePanel(self.build))

    def build(self, params):
        doc = active_document()
        obj = progress.run("Demo blade", lambda p: do_command(
            (APP_OBJECTS, "from BladeInspect.cad.demo_blade import BladeParams"),
            "objects.make_demo_blade(%s, %r)" % (document_text(doc), params)))
        if obj is not None:
            _recompute_gui(doc)
        return obj


class LoadCad(_Command):
    name = "BladeInspect_LoadCad"
    menu = QT_TRANSLATE_NOOP("BladeInspect_LoadCad", "Load CAD...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_LoadCad",
        "Load the nominal blade from a STEP, IGES, BREP or FCStd file (or a section table)")

    def Activated(self):
        path = ask_open_file("Nominal CAD", CAD_FILTER)
        if path:
            self.load(path)

    def load(self, path):
        doc = active_document()
        obj = progress.run("Load CAD", lambda p: do_command(
            (APP_OBJECTS,), "objects.make_cad_model(%s, %r)" % (document_text(doc), path)))
        if obj is not None:
            _recompute_gui(doc)
        return obj


def simulated_rig(nominal, seed, kinematics=None):
    """The simulated rig of ``nominal`` (a Nominal) with the sensor the preferences describe,
    as ConnectRig opens it; ``kinematics``: its true geometry (default nominal)."""
    from ..measurement.scan import open_rig
    return open_rig("sim", nominal, seed, kinematics=kinematics, sensor=settings.sensor_model())


class ConnectRig(_Command):
    name = "BladeInspect_ConnectRig"
    menu = QT_TRANSLATE_NOOP("BladeInspect_ConnectRig", "Connect rig...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_ConnectRig",
        "Connect the four-axis rig: the simulated rig (needs a nominal) or a serial port")

    def Activated(self):
        FreeCADGui.Control.showDialog(taskpanels.ConnectRigPanel(self.connect))

    def connect(self, spec, seed):
        def job(p):
            nominal_obj = find_nominal()
            if spec == "sim" and nominal_obj is None:
                raise InputError("simulated rig: load a CAD or build the demo blade first")
            nominal = objects.nominal_of(nominal_obj) if nominal_obj is not None else None
            p(0.5, "opening %s" % spec)
            RIG.connect(open_rig(spec, nominal, seed, sensor=settings.sensor_model()), spec)
            return RIG.rig
        rig = progress.run("Connect rig", job)
        if rig is not None:
            FreeCAD.Console.PrintMessage("BladeInspect: rig connected (%s)\n" % spec)
        return rig


class Scan(_Command):
    name = "BladeInspect_Scan"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Scan", "Scan...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Scan",
        "Scan the blade section by section with the connected rig (progress and abort)")

    def ready(self):
        return RIG.connected

    def Activated(self):
        FreeCADGui.Control.showDialog(taskpanels.ScanPanel(self.scan))

    def scan(self, options):
        doc = active_document()
        out_dir = scan_folder(doc)

        def job(p):
            scan_to_dir(out_dir, RIG.rig, progress=p, **options)
            path = os.path.join(out_dir, "points.csv")
            pointset = load_points(path)
            return objects.make_measurement(doc, pointset, name="Scan", source_file=path)
        obj = progress.run("Scan", job)
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


class ImportPoints(_Command):
    name = "BladeInspect_ImportPoints"
    menu = QT_TRANSLATE_NOOP("BladeInspect_ImportPoints", "Import points...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_ImportPoints",
        "Import a measured point cloud (csv/xyz/asc/txt with optional SNR, ply, pcd)")

    def Activated(self):
        path = ask_open_file("Measured points", POINT_FILTER)
        if path:
            self.load(path)

    def load(self, path):
        doc = active_document()

        def job(p):
            p(0.1, "reading %s" % os.path.basename(path))
            obj = do_command(
                (APP_OBJECTS, "from BladeInspect.inspection.pipeline import load_points"),
                "objects.make_measurement(%s, load_points(%r), name='Measurement', "
                "source_file=%r)" % (document_text(doc), path, path))
            obj.Label = os.path.splitext(os.path.basename(path))[0]
            return obj
        obj = progress.run("Import points", job)
        if obj is not None:
            _recompute_gui(doc)
        return obj


class Reconstruct(_Command):
    name = "BladeInspect_Reconstruct"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Reconstruct", "Reconstruct")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Reconstruct",
        "Fit cubic B-spline section curves to the measurement and loft them into surfaces")

    def ready(self):
        return find_input((objects.Measurement.Type,)) is not None

    def Activated(self):
        self.reconstruct(find_input((objects.Measurement.Type,)))

    def reconstruct(self, measurement):
        doc = measurement.Document

        def job(p):
            p(0.1, "fitting section curves")
            recon = reconstruct(objects.pointset_of(measurement))
            p(0.9, "storing %d curves, %d surfaces" % (len(recon.curves), len(recon.surfaces)))
            return objects.make_reconstruction(doc, measurement, recon)
        obj = progress.run("Reconstruct", job)
        if obj is not None:
            _recompute_gui(doc)
        return obj


class Register(_Command):
    name = "BladeInspect_Register"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Register", "Register")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Register",
        "Register the measurement to the nominal with no starting pose (PCA, then SNR-"
        "weighted ICP) and show the pose with its uncertainty")

    def ready(self):
        return find_input((objects.Measurement.Type,)) is not None and find_nominal() is not None

    def Activated(self):
        obj = self.register(find_input((objects.Measurement.Type,)), find_nominal())
        if obj is not None:
            self.show(obj)

    def register(self, measurement, nominal_obj, seed=None):
        doc = measurement.Document
        seed = settings.value("Seed") if seed is None else seed

        def job(p):
            p(0.0, "sampling the nominal")
            nominal = objects.nominal_of(nominal_obj)
            result = register(nominal, objects.pointset_of(measurement), seed=seed, progress=p)
            result.cad_source = nominal_obj.Label
            return objects.make_registration(doc, result, measurement, nominal_obj, seed)
        obj = progress.run("Register", job)
        if obj is not None:
            doc.recompute()
            for warning in obj.Warnings:
                FreeCAD.Console.PrintWarning("BladeInspect: %s\n" % warning)
        return obj

    @staticmethod
    def show(obj):
        FreeCADGui.Control.closeDialog()
        FreeCADGui.Control.showDialog(taskpanels.RegistrationPanel(obj))


class DeviationMap(_Command):
    name = "BladeInspect_DeviationMap"
    menu = QT_TRANSLATE_NOOP("BladeInspect_DeviationMap", "Deviation map")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_DeviationMap",
        "Colour the registered points by signed deviation (limits from the preferences)")

    def ready(self):
        return find_input((objects.Registration.Type,)) is not None

    def Activated(self):
        self.make(find_input((objects.Registration.Type,)))

    def make(self, registration, limit=None):
        doc = registration.Document
        limit = settings.colour_limit() if limit is None else limit
        obj = progress.run("Deviation map", lambda p: do_command(
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


class SectionAnalysis(_Command):
    name = "BladeInspect_SectionAnalysis"
    menu = QT_TRANSLATE_NOOP("BladeInspect_SectionAnalysis", "Section analysis")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_SectionAnalysis",
        "Profile errors per section (Table 2): RMS, worst deviation, leading/trailing edge")

    def ready(self):
        reg = find_input((objects.Registration.Type,))
        return reg is not None and reg.Nominal is not None

    def Activated(self):
        table = self.analyse(find_input((objects.Registration.Type,)))
        if table is not None:
            self.show(table)

    def analyse(self, registration):
        """The section table of a registration (inspection.sections), its nominal profiles added
        to the document; None when it failed (reported)."""
        doc = registration.Document

        def job(p):
            if registration.Nominal is None:
                raise InputError("%s: no nominal linked" % registration.Label)
            nominal = objects.nominal_of(registration.Nominal)
            p(0.2, "signed distances of the registered points")
            result = objects.registration_result(registration, nominal)
            p(0.5, "cutting sections")
            table = section_table(result, nominal)
            objects.make_section_profiles(doc, table, registration)
            return table
        table = progress.run("Section analysis", job)
        if table is not None:
            doc.recompute()
            for warning in table.warnings:
                FreeCAD.Console.PrintWarning("BladeInspect: %s\n" % warning)
        return table

    @staticmethod
    def show(table):
        header, rows = section_rows(table)
        FreeCADGui.Control.closeDialog()
        FreeCADGui.Control.showDialog(taskpanels.TablePanel(
            "Section analysis", header, rows, "; ".join(table.warnings)))


class Report(_Command):
    name = "BladeInspect_Report"
    menu = "Report..."
    tip = "Write the inspection report (HTML and PDF, result.json, deviations.csv) to a folder"

    def ready(self):
        reg = find_input((objects.Registration.Type,))
        return reg is not None and reg.Measurement is not None and reg.Nominal is not None

    def Activated(self):
        out_dir = ask_directory("Report folder")
        if out_dir:
            summary = self.report(find_input((objects.Registration.Type,)), out_dir)
            html = os.path.join(out_dir, "report.html")
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
            return write_result_report(result, nominal, out_dir,
                                       tolerance=settings.value("ToleranceMm"), progress=p,
                                       document=writer, cad_path=cad_path)
        doc = registration.Document
        try:
            return progress.run("Report", job)
        finally:
            # The report saves its own document, which leaves another one active.
            FreeCAD.setActiveDocument(doc.Name)
            FreeCADGui.setActiveDocument(doc.Name)


class Preferences(_Command):
    name = "BladeInspect_Preferences"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Preferences", "Preferences...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Preferences",
        "Sensor and rig parameters, tolerance and colour limits")

    def Activated(self):
        FreeCADGui.showPreferences("BladeInspect")


COMMANDS = [DemoBlade(), LoadCad(), ConnectRig(), Scan(), ImportPoints(), Reconstruct(),
            Register(), DeviationMap(), SectionAnalysis(), Report(), Preferences()]
TOOLBAR = [c.name for c in COMMANDS if c.name != Preferences.name]
MENU = [c.name for c in COMMANDS]
BY_NAME = {c.name: c for c in COMMANDS}

for _command in COMMANDS:
    FreeCADGui.addCommand(_command.name, _command)


def register_preferences():
    # The preferences dialog shows a group's icon by the name "preferences-<group>".
    FreeCADGui.addIconPath(resources.ICON_DIR)
    FreeCADGui.addPreferencePage(PreferencesPage, "BladeInspect")
