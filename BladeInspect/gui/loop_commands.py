"""The closed-loop commands (docs/contracts.md): inspect a blade, calibrate the rig, add a CMM file
to an inspection's Table 2, and run the simulation test bed. Each calls the same pipeline
function as the command line (run_inspect, run_calibration, section_table, run_simulation)
through gui.progress.run, and stores the outcome with the app layer's builders, so a failure
or a cancel leaves the document as it was. Inspect and the simulation test bed run as console
lines (app.actions.inspect and app.actions.simulate through commands.run_action), which a
recorded macro replays.

An inspection cancelled or failed after it measured something keeps its checkpoint; the
Inspect panel then offers to resume it (INTERRUPTED), as the command line's --resume does. A
checkpoint in a temporary folder (an unsaved document) lives only while it can be resumed: a
new inspection begun instead, or the end of the session, deletes it."""
import atexit
import contextlib
import os
import shutil
import tempfile


import FreeCAD
import FreeCADGui
from PySide import QtGui

from ..app import actions, loop, settings
from ..core import contracts
from ..core.errors import InputError
from ..inspection import characteristic_names as names
from ..inspection.report import section_rows
from ..measurement.calibration import DEFAULT_DIAMETER, run_calibration
from ..rig.kinematics import read_rig_file
from . import commands, progress, tables, taskpanels
from .command_base import Command, find_nominal, find_registration, nominals_of
from .i18n import QT_TRANSLATE_NOOP, translate
from .session import RIG

CMM_FILTER = QT_TRANSLATE_NOOP("BladeInspect", "CMM files (*.csv *.txt *.dat);;All files (*)")
RIG_FILTER = QT_TRANSLATE_NOOP("BladeInspect", "Rig calibration (*.json);;All files (*)")

NOISE_MODELS = ("uniform", "normal")
# Results shown to the user, newest last: (title, text). Tests read them.
RESULTS = []
# The RIG.json the last calibration wrote: the inspect panel offers it.
LAST_RIG_FILE = [None]
# Callables told of each plan once it is drawn, before its paths run: listener(plan, obj).
# Tests photograph the view there.
PLAN_LISTENERS = []
# The inspection the Inspect panel offers to resume, or None: {"out_dir", "document",
# "nominal" (names), "options" (Inspect.start's), "temporary" (True: delete when dropped)}.
INTERRUPTED = [None]


@contextlib.contextmanager
def inspection_rig(nominal_obj, seed, rig_file=None):
    """The rig Inspect runs on: the connected one, else the simulated rig with the
    preferences' sensor (as ConnectRig opens it), its true geometry ``rig_file``'s, closed
    after."""
    with actions.interactive(rig=RIG.rig), \
            actions.inspection_rig(nominal_obj, seed, rig_file) as rig:
        yield rig


def ask_save_file(title, filters, default_name):
    path, _ = QtGui.QFileDialog.getSaveFileName(FreeCADGui.getMainWindow(), title,
                                                default_name, translate("BladeInspect", filters))
    return path or None


def show_result(title, text):
    RESULTS.append((title, text))
    FreeCAD.Console.PrintMessage("BladeInspect: %s: %s\n" % (title, text))
    if progress.SHOW_DIALOGS and FreeCAD.GuiUp:
        box = QtGui.QMessageBox(QtGui.QMessageBox.Information,
                                translate("BladeInspect", "BladeInspect: %s") % title, text,
                                QtGui.QMessageBox.Ok, FreeCADGui.getMainWindow())
        progress.show_modeless(box)


def output_folder(doc, kind):
    """A new folder for a command's files: beside the saved document, else a temporary one."""
    if doc.FileName:
        base = os.path.splitext(doc.FileName)[0] + "_" + kind
        os.makedirs(base, exist_ok=True)
        return tempfile.mkdtemp(prefix=kind + "-", dir=base)
    return tempfile.mkdtemp(prefix="bladeinspect-%s-" % kind)


def is_temporary(folder):
    return os.path.commonpath([os.path.abspath(folder), tempfile.gettempdir()]) == \
        tempfile.gettempdir()


def interrupted_for(nominal_obj):
    """The interrupted inspection of ``nominal_obj`` the Inspect panel offers, or None."""
    held = INTERRUPTED[0]
    if held is None or nominal_obj is None:
        return None
    if (held["document"], held["nominal"]) != (nominal_obj.Document.Name, nominal_obj.Name) \
            or not os.path.isdir(held["out_dir"]):
        return None
    return held


def drop_interrupted():
    """Forget the interrupted inspection; its folder goes when it is a temporary one."""
    held, INTERRUPTED[0] = INTERRUPTED[0], None
    if held is not None and held["temporary"]:
        shutil.rmtree(os.path.dirname(held["out_dir"]), ignore_errors=True)


atexit.register(drop_interrupted)


def _hide_measured_frame(measurement):
    """The measurement lies in the table or a random frame, away from the CAD and its map."""
    if measurement.ViewObject is not None:
        measurement.ViewObject.Visibility = False


def _show_table(title, table, note, sensitivity=None, warnings=(), verdict=None):
    """Table 2 in a panel under ``note``, the result's ``warnings`` (result.json's, the
    planner's notes among them) and the table's; when the airfoil stage ran on the table, a
    button to its characteristics (the Airfoil command's panel)."""
    header, rows = section_rows(table)
    notes = list(dict.fromkeys([note] + list(warnings) + list(table.warnings)))
    panel = taskpanels.TablePanel(title, header, rows, "; ".join(n for n in notes if n),
                                  sensitivity, verdict=verdict)
    stage = getattr(table, "airfoil", None)
    if stage is not None:
        analysis = stage.extras()
        panel.airfoil_button = QtGui.QPushButton(
            translate("BladeInspect", "Airfoil characteristics..."))
        panel.airfoil_button.clicked.connect(
            lambda: taskpanels.show_panel(taskpanels.AirfoilPanel(analysis)))
        panel.form.layout().addWidget(panel.airfoil_button)
    return taskpanels.show_panel(panel)


# ---------------------------------------------------------------- task panels

class InspectPanel(taskpanels.FormPanel):
    """Nominal section heights, tolerance, seed, the rig calibration file and the fit."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Inspect")

    def __init__(self, on_accept, nominals=None, nominal=None):
        super().__init__()
        self.on_accept = on_accept
        nominal = nominal or find_nominal()
        if nominals is None:
            nominals = nominals_of(FreeCAD.ActiveDocument) if FreeCAD.ActiveDocument else []
        self.nominal = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Nominal CAD"),
            taskpanels.object_combo(nominals, nominal),
            QT_TRANSLATE_NOOP("BladeInspect", "The CAD the rig's part is inspected against (the "
                              "selected one when a CAD is selected)"))
        self.heights = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Section heights (%)"),
            QtGui.QLineEdit(", ".join("%g" % h for h in contracts.SECTION_HEIGHTS_PCT)),
            QT_TRANSLATE_NOOP("BladeInspect",
                              "Nominal sections to measure, % of the span from hub to tip"))
        self.tolerance = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Tolerance"),
            taskpanels.spin_box(settings.value("ToleranceMm"), 0.0001, 10.0, 4, "mm"),
            QT_TRANSLATE_NOOP("BladeInspect", "The profile tolerance each section is judged "
                              "against"))
        self.seed = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Seed"),
            taskpanels.spin_box(settings.value("Seed"), 0, 2 ** 31 - 1),
            QT_TRANSLATE_NOOP("BladeInspect",
                              "Fixture pose of the simulated rig and the registration's sampling"))
        self.rig_file = self.add_file_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Rig calibration"),
            QtGui.QLineEdit(LAST_RIG_FILE[0] or ""),
            QT_TRANSLATE_NOOP("BladeInspect",
                              "RIG.json from Calibrate; empty: the nominal kinematics"),
            QT_TRANSLATE_NOOP("BladeInspect", "Rig calibration"), RIG_FILTER)
        self.airfoil = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Airfoil characteristics"), QtGui.QCheckBox(),
            QT_TRANSLATE_NOOP("BladeInspect", "Chord, stagger, thickness, edge radii, angles, "
                              "shift and twist per section, judged in the verdict (the "
                              "inspect command's default; off: --no-airfoil)"))
        self.airfoil.setChecked(True)
        self.fit = taskpanels.FitSelector()
        self.layout.addRow(self.fit)
        self.layout.addRow(taskpanels.wrapped_label(translate("BladeInspect", "Rig: %s") % (
            RIG.spec if RIG.connected else translate("BladeInspect", "simulated (none connected)"))))
        self.interrupted = interrupted_for(nominal)
        self.resume = QtGui.QCheckBox(translate("BladeInspect",
                                                "Resume the interrupted inspection"))
        self.resume.setVisible(self.interrupted is not None)
        if self.interrupted is not None:
            self.resume.setToolTip(translate(
                "BladeInspect", "Continue the inspection that was cancelled or failed, with "
                "its options, from what it measured (kept in %s); unchecked: a new inspection "
                "replaces it") % self.interrupted["out_dir"])
            self.resume.setChecked(True)
        self.resume.toggled.connect(self._resume_toggled)
        self.layout.insertRow(0, self.resume)   # first: what OK will do
        self._resume_toggled(self.resume.isChecked())

    def _resume_toggled(self, checked):
        """A resumed inspection keeps its own options: shown, and not editable."""
        if checked and self.interrupted is not None:
            saved = self.interrupted["options"]
            self.heights.setText(saved["heights_text"])
            self.tolerance.setValue(saved["tolerance"])
            self.seed.setValue(saved["seed"])
            self.rig_file.setText(saved["rig_file"] or "")
            self.airfoil.setChecked(saved["airfoil"])
        for widget in (self.nominal, self.heights, self.tolerance, self.seed, self.rig_file,
                       self.airfoil, self.fit):
            widget.setEnabled(not checked)

    def validate(self):
        def rig_file():
            path = self.rig_file.text().strip()
            if path:
                read_rig_file(path)
        def chosen():
            if self.nominal.currentData() is None:
                raise InputError(translate("BladeInspect", "No nominal CAD in the document"))
        checks = [self.check(self.nominal, chosen),
                  self.check(self.heights, lambda: contracts.parse_section_heights(
            self.heights.text(), translate("BladeInspect", "Section heights"))),
            self.check(self.rig_file, rig_file)]
        return all(checks)

    def options(self):
        nominal = self.nominal.currentData()
        if self.resume.isChecked() and self.interrupted is not None:
            return dict(self.interrupted["options"], resume=True, nominal=nominal)
        return dict({"nominal": nominal,
                     "heights_text": self.heights.text(), "tolerance": self.tolerance.value(),
                     "seed": self.seed.value(), "rig_file": self.rig_file.text().strip() or None,
                     "airfoil": self.airfoil.isChecked()},
                    **self.fit.values())

    def accept(self):
        if not self.validate():
            return False
        options = self.options()   # read before closing: closing deletes the widgets
        return taskpanels.close_then(self.on_accept, **options)


class CalibratePanel(taskpanels.ConnectRigPanel):
    """The rig (simulated or a serial port), the reference sphere's diameter and, for the
    simulated rig, the axis errors to inject."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Calibrate rig")

    def __init__(self, on_accept):
        super().__init__(on_accept)
        self.diameter = self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Sphere diameter"),
                                     taskpanels.spin_box(DEFAULT_DIAMETER, 1.0, 200.0, 4, "mm"))
        self.offset = self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Axis offset (simulated)"),
                                   taskpanels.spin_box(0.0, 0.0, 10.0, 3, "mm"))
        self.tilt = self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Axis tilt (simulated)"),
                                 taskpanels.spin_box(0.0, 0.0, 5.0, 3, "deg"))
        self.kind.currentIndexChanged.connect(self._update_errors)
        self._update_errors()

    def _update_errors(self, *_):
        simulated = self.kind.currentIndex() == 0
        self.offset.setEnabled(simulated)
        self.tilt.setEnabled(simulated)

    def accept(self):
        options = {"rig_spec": self.spec(), "seed": self.seed.value(),
                   "sphere_diameter": self.diameter.value()}
        if options["rig_spec"] == "sim":
            options.update(axis_offset_mm=self.offset.value(), axis_tilt_deg=self.tilt.value())
        return taskpanels.close_then(self.on_accept, **options)


class SimulatePanel(taskpanels.FormPanel):
    """The simulation test bed's options (inspection.simulate.simulate_measurement)."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Simulation test bed")

    def __init__(self, on_accept):
        super().__init__()
        self.on_accept = on_accept
        self.points = self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Surface points"),
                                   taskpanels.spin_box(20000, 10, 2000000))
        # The noise model's names are the option values run_simulation takes, not prose.
        self.noise = self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Measurement error"),
                                  QtGui.QComboBox())
        self.noise.addItems(list(NOISE_MODELS))
        self.outliers = self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Outlier fraction"),
                                     taskpanels.spin_box(0.0, 0.0, 0.5, 3))
        self.seed = self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Seed"),
                                 taskpanels.spin_box(settings.value("Seed"), 0, 2 ** 31 - 1))

    def options(self):
        return {"seed": self.seed.value(), "n_points": self.points.value(),
                "noise": self.noise.currentText(), "outlier_fraction": self.outliers.value()}

    def accept(self):
        options = self.options()
        return taskpanels.close_then(self.on_accept, **options)


# ---------------------------------------------------------------- commands

class Inspect(Command):
    name = "BladeInspect_Inspect"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Inspect", "Inspect...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Inspect",
        "The whole loop: blind section scan, registration, paths planned from the CAD at its "
        "nominal sections (drawn before they run), their scan, Table 2 and verdict")

    is_active = "with_nominal"

    panel = InspectPanel

    def Activated(self):
        FreeCADGui.Control.showDialog(self.panel(
            self.start, nominals=nominals_of(FreeCAD.ActiveDocument), nominal=find_nominal()))

    def start(self, heights_text, tolerance, seed, rig_file=None, resume=False, nominal=None,
              **fit):
        try:
            heights = contracts.parse_section_heights(heights_text, "section heights")
        except InputError as exc:
            progress.report_error(translate("BladeInspect", "Inspect"), str(exc))
            return None
        options = dict(fit, heights_text=heights_text, tolerance=tolerance, seed=seed,
                       rig_file=rig_file)
        nominal_obj = (FreeCAD.ActiveDocument.getObject(nominal)
                       if nominal and FreeCAD.ActiveDocument else None) or find_nominal()
        summary = self.inspect(nominal_obj, heights, tolerance, seed, rig_file,
                               resume=resume, panel_options=options, **fit)
        if summary is not None:
            self.show(summary)
        return summary

    def inspect(self, nominal_obj, heights, tolerance, seed, rig_file=None, resume=False,
                panel_options=None, **fit):
        """app.actions.inspect on the nominal with the connected rig (else the simulated one),
        the fit ``fit`` chooses; the plan drawn as it is made. ``resume``: continue the
        interrupted inspection (INTERRUPTED) in its folder; otherwise a new folder, and an
        interrupted inspection is dropped. ``panel_options``: the panel's values, kept to
        resume with when this run is interrupted. Returns run_inspect's summary with the new
        objects under "objects", or None."""
        doc = nominal_obj.Document
        held = interrupted_for(nominal_obj) if resume else None
        if resume and held is None:
            progress.report_error(translate("BladeInspect", "Inspect"), translate(
                "BladeInspect", "no interrupted inspection of %s to resume") % nominal_obj.Label)
            return None
        if held is not None:
            out_dir = held["out_dir"]
        else:
            drop_interrupted()
            out_dir = os.path.join(output_folder(doc, "inspections"), "inspection")

        drawn = {}

        def draw(plan):
            obj = drawn["plan"] = loop.show_plan(doc, plan, drawn.get("plan"))
            doc.recompute()
            commands.fit_view()
            QtGui.QApplication.processEvents()
            for listener in PLAN_LISTENERS:
                listener(plan, obj)

        if held is not None:
            fit = dict(fit, resume=True)
        summary = commands.run_action(
            translate("BladeInspect", "Inspect"), "inspect", doc.Name, nominal_obj.Name, out_dir,
            tuple(float(h) for h in heights), float(tolerance), int(seed), rig_file=rig_file,
            on_plan=draw, rig=RIG.rig, **fit)
        if summary is None and os.path.exists(os.path.join(out_dir, "scan.json")):
            # A cancel, or a rig that failed mid-run, leaves what it measured as a checkpoint.
            self.keep_interrupted(nominal_obj, out_dir, held, panel_options)
        elif summary is None:
            # Bad input or a cancel before any measurement: nothing to resume, the folder
            # made for it goes.
            INTERRUPTED[0] = None
            shutil.rmtree(os.path.dirname(out_dir), ignore_errors=True)
        else:
            INTERRUPTED[0] = None
            summary["resumed"] = held is not None
            _hide_measured_frame(summary["objects"]["measurement"])
            if drawn["plan"].ViewObject is not None:
                # The paths ran; drawn over the deviation map they would hide its colours.
                drawn["plan"].ViewObject.Visibility = False
            summary["objects"]["plan"] = drawn["plan"]
            analysis = summary["objects"].get("airfoil")
            for obj in analysis.Group if analysis is not None else ():
                if obj.ViewObject is not None:
                    # The deviation map comes first; the camber lines and edge circles (thin,
                    # grey) are shown on demand from the Model tree.
                    obj.ViewObject.Visibility = False
            doc.recompute()
            commands.fit_view()
        return summary

    @staticmethod
    def keep_interrupted(nominal_obj, out_dir, held, panel_options):
        """Remember the interrupted inspection for the panel to resume, and say so."""
        options = held["options"] if held is not None else dict(panel_options or {})
        temporary = is_temporary(out_dir)
        INTERRUPTED[0] = {"out_dir": out_dir, "document": nominal_obj.Document.Name,
                          "nominal": nominal_obj.Name, "options": options,
                          "temporary": temporary}
        text = translate("BladeInspect", "What was measured is kept in %s. Run Inspect again "
                         "with 'Resume the interrupted inspection' checked to continue from "
                         "there.") % out_dir
        if temporary:
            text += " " + translate("BladeInspect", "The folder is temporary: a new inspection "
                                    "begun instead, or closing FreeCAD, deletes it.")
        progress.report_note(translate("BladeInspect", "Inspect"), text)

    @staticmethod
    def show(summary):
        note = (translate("BladeInspect", "%s. Pose uncertainty %.2f \u00b5m after the planned "
                          "scan (%.2f \u00b5m after the blind scan); ICP weights: %s. Files in %s")
                % (names.part_summary_text(
                    summary["verdict"]["summary"], summary["verdict"].get("airfoil"),
                    getattr(getattr(summary["sections"], "airfoil", None), "blocks", ()),
                    tables.tr), 1e3 * summary["pose_uncertainty_mm"],
                   1e3 * summary["uncertainty_after_blind_mm"],
                   summary["objects"]["registration"].WeightsUsed or "-", summary["out_dir"]))
        if summary.get("resumed"):
            note = translate("BladeInspect", "Resumed from the interrupted inspection's "
                             "checkpoint.") + " " + note
        return _show_table(
            translate("BladeInspect", "Inspection: Table 2 at the nominal sections"),
            summary["sections"], note, summary["result"].fit_sensitivity,
            summary["result"].warnings, verdict=summary["verdict"])


class Calibrate(Command):
    name = "BladeInspect_Calibrate"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Calibrate", "Calibrate rig...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Calibrate",
        "Measure a reference sphere at several rotary angles, find the rotary axis and write "
        "RIG.json (simulated rig or a serial port)")

    panel = CalibratePanel

    def start(self, **options):
        out_path = ask_save_file(translate("BladeInspect", "Write the rig calibration"),
                                 RIG_FILTER, "RIG.json")
        if out_path:
            return self.calibrate(out_path, **options)
        return None

    def calibrate(self, out_path, rig_spec="sim", sphere_diameter=None, seed=0,
                  **simulated_errors):
        if rig_spec != "sim" and RIG.connected and RIG.spec == rig_spec:
            # The calibration opens the port itself; the scan session would hold it busy.
            RIG.disconnect()
        diameter = DEFAULT_DIAMETER if sphere_diameter is None else sphere_diameter
        title = translate("BladeInspect", "Calibrate")
        result = progress.run(title, lambda p: run_calibration(
            out_path, rig_spec=rig_spec, sphere_diameter=diameter, seed=seed, progress=p,
            **simulated_errors))
        if result is not None:
            LAST_RIG_FILE[0] = out_path
            show_result(title, calibration_text(result, out_path))
        return result


def calibration_text(result, out_path):
    lines = [translate("BladeInspect", "Rotary axis through (%.4f, %.4f, %.4f) mm, direction "
                       "(%.7f, %.7f, %.7f).")
             % (tuple(result["axis_point"]) + tuple(result["axis_direction"])),
             translate("BladeInspect", "Tilt from +Y: %.4f deg about Z, %.4f deg about X. "
                       "Sphere measured %.4f mm (nominal %.4f); circle residual RMS %.4f mm.")
             % (result["axis_tilt_about_z_deg"], result["axis_tilt_about_x_deg"],
                result["measured_diameter_mm"], result["sphere_diameter_mm"],
                result["circle_residual_rms_mm"])]
    error = result.get("truth_error")
    if error:
        lines.append(translate("BladeInspect", "Against the simulator's truth: axis position "
                               "%.2f um, direction %.5f deg.")
                     % (1e3 * error["position_mm"], error["direction_deg"]))
    lines.append(translate("BladeInspect", "Written to %s.") % out_path)
    return "\n".join(lines)


class AddCmm(Command):
    name = "BladeInspect_AddCmm"
    menu = QT_TRANSLATE_NOOP("BladeInspect_AddCmm", "Add CMM file...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_AddCmm",
        "Compare a CMM file's sections with the optical ones (Table 2): for an inspection, at"
        " its nominal sections")

    is_active = "with_registered_nominal"

    def Activated(self):
        path = commands.ask_open_file(translate("BladeInspect", "CMM file"), CMM_FILTER)
        if path:
            table = self.add(find_registration(), path)
            if table is not None:
                self.show(table)

    def add(self, registration, cmm_path):
        def job(p):
            p(0.2, translate("BladeInspect", "reading %s and cutting the sections")
              % os.path.basename(cmm_path))
            table, _ = loop.cmm_section_table(registration, cmm_path)
            return table
        return progress.run(translate("BladeInspect", "Add CMM file"), job)

    @staticmethod
    def show(table):
        _show_table(translate("BladeInspect", "Table 2: optical and CMM"), table,
                    translate("BladeInspect", "CMM: %s") % table.cmm_source)


class Simulate(Command):
    name = "BladeInspect_Simulate"
    menu = QT_TRANSLATE_NOOP("BladeInspect_Simulate", "Simulation test bed...")
    tip = QT_TRANSLATE_NOOP(
        "BladeInspect_Simulate",
        "The paper's simulation test bed: points from the CAD (or the demo blade) at a random"
        " pose with measurement error, registered blind; pose error against its bound")

    panel = SimulatePanel

    def start(self, **options):
        return self.simulate(**options)

    def simulate(self, seed=0, **options):
        """app.actions.simulate on the document's nominal, else a new demo blade; adds the
        simulated measurement, its registration and deviation map. Returns (report,
        registration)."""
        doc = commands.active_document()
        title = translate("BladeInspect", "Simulation test bed")
        nominal_obj = find_nominal()
        outcome = commands.run_action(title, "simulate", doc.Name, int(seed),
                                      nominal=nominal_obj.Name if nominal_obj else None,
                                      **options)
        if outcome is None:
            return None
        report, registration, _ = outcome
        _hide_measured_frame(registration.Measurement)
        doc.recompute()
        commands.fit_view()
        show_result(title, simulation_text(report))
        return report, registration


def simulation_text(report):
    return (translate("BladeInspect", "Pose error %.3f um = %.2f x its bound (%.3f um). "
                      "Residual RMS %.4f mm (injected %.4f), min %.4f, max %.4f mm; paper: "
                      "RMS 0.0019, min -0.0053, max 0.006.")
            % (1e3 * report["pose_error_mm"], report["pose_error_over_bound"],
               1e3 * report["pose_uncertainty_mm"], report["residual_rms_mm"],
               report["noise_rms_injected_mm"], report["residual_min_mm"],
               report["residual_max_mm"]))


COMMANDS = [Inspect(), Calibrate(), AddCmm(), Simulate()]
NAMES = [c.name for c in COMMANDS]
BY_NAME = {c.name: c for c in COMMANDS}

for _command in COMMANDS:
    FreeCADGui.addCommand(_command.name, _command)
