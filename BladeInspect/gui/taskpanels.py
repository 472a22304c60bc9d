"""Task panels: the parameters of a command before it runs, and what a result says after.
Panels collect input and show output; the work is done by the commands' pipeline calls."""
import dataclasses
import functools
import json
import math

import FreeCADGui
from PySide import QtCore, QtGui

from ..app import registration_fit, settings
from ..cad.demo_blade import BladeParams
from ..core import decision
from ..core.airfoil import CHORD_METHODS
from ..core.errors import InputError
from ..inspection import characteristic_names as names
from ..inspection import fitting
from ..inspection.airfoil_stage import parse_engine_axis, read_characteristics
from ..inspection.result import rival_lines
from . import tables
from .forms import FormPanel, fit_field, form_layout, object_combo, wrapped_label
from .i18n import QT_TRANSLATE_NOOP, translate


def close_then(action, *args, **kwargs):
    """What a parameter panel's accept() returns: the panel closes, and ``action(*args,
    **kwargs)`` (the work, then its result panel) runs from the event loop once FreeCAD has let
    go of the panel. FreeCAD keeps the panel as the active dialog until its accept() returns,
    so a result panel shown from inside it fails with "Active task dialog found"."""
    FreeCADGui.Control.closeDialog()
    QtCore.QTimer.singleShot(0, functools.partial(action, *args, **kwargs))
    return True


def show_panel(panel):
    """Show ``panel`` in the task view in place of whatever panel is open."""
    FreeCADGui.Control.closeDialog()
    FreeCADGui.Control.showDialog(panel)
    return panel


def spin_box(value, minimum, maximum, decimals=3, suffix=""):
    if isinstance(value, int) and not isinstance(value, bool):
        box = QtGui.QSpinBox()
        box.setRange(int(minimum), int(maximum))
    else:
        box = QtGui.QDoubleSpinBox()
        box.setDecimals(decimals)
        box.setRange(minimum, maximum)
        box.setSingleStep(10 ** -(decimals - 1) if decimals > 1 else 1.0)
    box.setValue(value)
    if suffix:
        box.setSuffix(" " + suffix)
    return box


# The demo blade's parameters (cad.demo_blade.BladeParams) as the panel names them, with
# their units; a parameter not listed shows under its field name.
DEMO_BLADE_LABELS = {
    "span": (QT_TRANSLATE_NOOP("BladeInspect", "Span"), "mm"),
    "chord_root": (QT_TRANSLATE_NOOP("BladeInspect", "Chord at the hub"), "mm"),
    "chord_tip": (QT_TRANSLATE_NOOP("BladeInspect", "Chord at the tip"), "mm"),
    "thickness_root": (QT_TRANSLATE_NOOP("BladeInspect", "Thickness / chord at the hub"), ""),
    "thickness_tip": (QT_TRANSLATE_NOOP("BladeInspect", "Thickness / chord at the tip"), ""),
    "thickness_position": (QT_TRANSLATE_NOOP("BladeInspect",
                                             "Thickest point / chord"), ""),
    "camber_root": (QT_TRANSLATE_NOOP("BladeInspect", "Camber / chord at the hub"), ""),
    "camber_tip": (QT_TRANSLATE_NOOP("BladeInspect", "Camber / chord at the tip"), ""),
    "camber_position": (QT_TRANSLATE_NOOP("BladeInspect", "Most cambered point / chord"), ""),
    "stagger_root_deg": (QT_TRANSLATE_NOOP("BladeInspect", "Stagger at the hub"), "\u00b0"),
    "twist_deg": (QT_TRANSLATE_NOOP("BladeInspect", "Twist, hub to tip"), "\u00b0"),
    "twist_exponent": (QT_TRANSLATE_NOOP("BladeInspect", "Twist exponent"), ""),
    "sweep": (QT_TRANSLATE_NOOP("BladeInspect", "Sweep of the tip (+X)"), "mm"),
    "lean": (QT_TRANSLATE_NOOP("BladeInspect", "Lean of the tip (+Y)"), "mm"),
    "le_radius_root": (QT_TRANSLATE_NOOP("BladeInspect", "LE radius at the hub"), "mm"),
    "le_radius_tip": (QT_TRANSLATE_NOOP("BladeInspect", "LE radius at the tip"), "mm"),
    "te_radius_root": (QT_TRANSLATE_NOOP("BladeInspect", "TE radius at the hub"), "mm"),
    "te_radius_tip": (QT_TRANSLATE_NOOP("BladeInspect", "TE radius at the tip"), "mm"),
    "n_sections": (QT_TRANSLATE_NOOP("BladeInspect", "Sections lofted"), ""),
    "n_profile": (QT_TRANSLATE_NOOP("BladeInspect", "Points per side and section"), ""),
}


DEMO_BLADE_TIP = QT_TRANSLATE_NOOP(
    "BladeInspect", "A parameter of the parametric demo blade, interpolated from hub to tip")


class DemoBladePanel(FormPanel):
    """BladeParams as spin boxes; OK builds the demo blade through on_accept(params)."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Demo blade")

    def __init__(self, on_accept):
        super().__init__()
        self.on_accept = on_accept
        self.params_type = BladeParams
        self.boxes = {}
        defaults = BladeParams()
        for field in dataclasses.fields(BladeParams):
            value = getattr(defaults, field.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                continue
            label, unit = DEMO_BLADE_LABELS.get(field.name,
                                                (field.name.replace("_", " "), ""))
            box = spin_box(value, -1e4, 1e4, suffix=unit)
            self.boxes[field.name] = box
            self.add_row(label, box, DEMO_BLADE_TIP)
        # BladeParams.validate names the field it refuses; its error shows under the last row.
        self.errors[self.form] = self.errors[box]

    def params(self):
        return self.params_type(**{name: type(getattr(self.params_type(), name))(box.value())
                                   for name, box in self.boxes.items()})

    def validate(self):
        return self.check(self.form, lambda: self.params().validate())

    def accept(self):
        if not self.validate():
            return False
        params = self.params()   # read before closing: closing deletes the widgets
        return close_then(self.on_accept, params)


class ConnectRigPanel(FormPanel):
    """Simulated rig, or a serial port picked from the ports pyserial finds."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Connect rig")

    def __init__(self, on_accept):
        super().__init__()
        self.on_accept = on_accept
        self.kind = QtGui.QComboBox()
        self.kind.addItems([translate("BladeInspect", "Simulated rig"),
                            translate("BladeInspect", "Serial port")])
        self.port = QtGui.QComboBox()
        self.port.setEditable(True)
        for port in self._ports():
            self.port.addItem(port)
        self.seed = spin_box(settings.value("Seed"), 0, 2 ** 31 - 1)
        self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Rig"), self.kind,
                     QT_TRANSLATE_NOOP("BladeInspect", "The simulated rig measures the nominal "
                                       "CAD; a serial port drives the real rig"))
        self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Port"), self.port,
                     QT_TRANSLATE_NOOP("BladeInspect", "The rig's serial port"))
        self.add_row(QT_TRANSLATE_NOOP("BladeInspect", "Seed (simulated)"), self.seed,
                     QT_TRANSLATE_NOOP("BladeInspect", "Random seed of the simulated rig's "
                                       "fixture pose and noise"))
        self.kind.currentIndexChanged.connect(self._update)
        self._update()

    @staticmethod
    def _ports():
        try:
            from serial.tools import list_ports
        except ImportError:
            return []
        return [p.device for p in list_ports.comports()]

    def _update(self, *_):
        serial = self.kind.currentIndex() == 1
        self.port.setEnabled(serial)
        self.seed.setEnabled(not serial)

    def spec(self):
        if self.kind.currentIndex() == 0:
            return "sim"
        return "serial:" + self.port.currentText().strip()

    def validate(self):
        def port():
            if self.spec() == "serial:":
                raise InputError(translate("BladeInspect", "Name the serial port"))
        return self.check(self.port, port)

    def accept(self):
        if not self.validate():
            return False
        spec, seed = self.spec(), self.seed.value()
        return close_then(self.on_accept, spec, seed)


class ScanPanel(FormPanel):
    """Scan parameters (the scan strategy's options), defaults from the preferences."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Scan")

    def __init__(self, on_accept):
        super().__init__()
        self.on_accept = on_accept
        self.sections = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Sections"),
            spin_box(settings.value("Sections"), 1, 200),
            QT_TRANSLATE_NOOP("BladeInspect", "Sections scanned over the span"))
        self.spacing = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Section spacing"),
            spin_box(settings.value("SectionSpacingMm"), 0.0, 1000.0, 2, "mm"),
            QT_TRANSLATE_NOOP("BladeInspect",
                              "Distance between sections; 0 spreads them over the span"))
        self.point_spacing = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Point spacing"),
            spin_box(settings.value("PointSpacingMm"), 0.005, 10.0, 3, "mm"),
            QT_TRANSLATE_NOOP("BladeInspect", "Distance between points along a section"))
        self.sides = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Sides"), spin_box(settings.value("Sides"), 1, 2),
            QT_TRANSLATE_NOOP("BladeInspect", "2 turns the part over to scan the other side"))
        self.epsilon = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Standoff criterion \u03b5"),
            spin_box(settings.value("EpsilonMm"), 0.01, 50.0, 2, "mm"),
            QT_TRANSLATE_NOOP("BladeInspect", "Rescan a section until every point is within "
                                              "this distance of the sensor's standoff"))
        self.seed = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Seed"),
            spin_box(settings.value("Seed"), 0, 2 ** 31 - 1),
            QT_TRANSLATE_NOOP("BladeInspect", "Random seed of the simulated rig's noise"))

    def options(self):
        spacing = self.spacing.value()
        return {"n_sections": self.sections.value(),
                "section_spacing": spacing if spacing > 0 else None,
                "point_spacing": self.point_spacing.value(), "sides": self.sides.value(),
                "epsilon": self.epsilon.value(), "seed": self.seed.value()}

    def accept(self):
        options = self.options()
        return close_then(self.on_accept, options)


class FitSelector(QtGui.QGroupBox):
    """The fit choice: --fit, --free, --weights-by-zone, --decision-rule and the
    fine ICP's --weights, as the command line's (inspection.fitting checks them when the
    command runs)."""

    def __init__(self):
        super().__init__(translate("BladeInspect", "Fit"))
        layout = form_layout(self)
        self.objective = QtGui.QComboBox()
        self.objective.addItems(list(fitting.OBJECTIVE_NAMES))
        self.objective.setToolTip(translate(
            "BladeInspect", "least-squares: the robust ICP's pose; minimax: minimum zone; "
            "tolerance: largest margin inside the tolerance; datum: the CAD's datum faces"))
        self.free = QtGui.QLineEdit()
        self.free.setPlaceholderText(translate("BladeInspect", "all six"))
        self.free.setToolTip(translate(
            "BladeInspect", "Free degrees of freedom, any of tx,ty,tz,rx,ry,rz and t_stacking,"
            "r_stacking,t_engine,r_engine; empty: all six"))
        self.weights = QtGui.QLineEdit()
        self.weights.setPlaceholderText(translate("BladeInspect", "none"))
        self.weights.setToolTip(translate(
            "BladeInspect", "Least-squares region weights, e.g. LE=2,TE=2,suction=1,pressure=1"))
        self.rule = QtGui.QComboBox()
        self.rule.addItems(list(decision.RULES))
        self.rule.setToolTip(translate(
            "BladeInspect", "iso14253: pass / not proven / fail (ISO 14253-1); simple: simple "
            "acceptance"))
        self.icp_weights = QtGui.QComboBox()
        self.icp_weights.addItems(list(registration_fit.WEIGHT_CHOICES))
        self.icp_weights.setToolTip(translate(
            "BladeInspect", "The fine ICP's weights: snr, the paper's SNR-linear weights; "
            "sensor, the sensor model's 1/(sigma_beam cos incidence)^2 (needs the readings' "
            "angle_deg); default: sensor when the points carry snr and angle_deg, else snr"))
        for label, widget in ((QT_TRANSLATE_NOOP("BladeInspect", "Objective"), self.objective),
                              (QT_TRANSLATE_NOOP("BladeInspect", "Free DOF"), self.free),
                              (QT_TRANSLATE_NOOP("BladeInspect", "Zone weights"), self.weights),
                              (QT_TRANSLATE_NOOP("BladeInspect", "Decision rule"), self.rule),
                              (QT_TRANSLATE_NOOP("BladeInspect", "ICP weights"),
                               self.icp_weights)):
            layout.addRow(wrapped_label(translate("BladeInspect", label)), fit_field(widget))

    def values(self):
        """Keywords of app.actions.fit_choice (literals, for the console line)."""
        weights = self.icp_weights.currentText()
        return {"fit": self.objective.currentText(),
                "free": self.free.text().strip() or None,
                "weights_by_zone": self.weights.text().strip() or None,
                "decision_rule": self.rule.currentText(),
                "weights": None if weights == registration_fit.DEFAULT_WEIGHTS else weights}


class RegisterPanel(FormPanel):
    """Which CAD (nominal) and which measured points the registration uses, preselected from
    the selection, its seed, whether a scan that does not fit the CAD is kept, and the fit to
    move it to. on_accept(nominal name, measurement name, seed, allow_mismatch, **fit)."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Register")

    def __init__(self, on_accept, nominals=(), measurements=(), nominal=None,
                 measurement=None):
        super().__init__()
        self.on_accept = on_accept
        self.nominal = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Nominal CAD"), object_combo(nominals, nominal),
            QT_TRANSLATE_NOOP("BladeInspect", "The CAD the points are registered to (the "
                              "selected one when a CAD is selected)"))
        self.measurement = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Measured points"),
            object_combo(measurements, measurement),
            QT_TRANSLATE_NOOP("BladeInspect", "The point set to register (the selected one "
                              "when a point set is selected)"))
        self.seed = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Seed"),
            spin_box(settings.value("Seed"), 0, 2 ** 31 - 1),
            QT_TRANSLATE_NOOP("BladeInspect", "Random seed of the coarse stage"))
        self.allow_mismatch = self.add_wide_row(
            QtGui.QCheckBox(translate("BladeInspect", "Allow mismatch")),
            QT_TRANSLATE_NOOP("BladeInspect", "Keep the registration, with a warning, when "
                              "too few points lie near the CAD's surface (another part's "
                              "scan, or a part far out of tolerance); off: refuse it"))
        self.fit = FitSelector()
        self.layout.addRow(self.fit)

    def validate(self):
        ok = self.check(self.nominal, lambda: self._chosen(
            self.nominal, translate("BladeInspect", "No nominal CAD in the document")))
        return self.check(self.measurement, lambda: self._chosen(
            self.measurement, translate("BladeInspect", "No measured points in the "
                                        "document"))) and ok

    @staticmethod
    def _chosen(combo, missing):
        if combo.currentIndex() < 0:
            raise InputError(missing)

    def accept(self):
        if not self.validate():
            return False
        nominal, measurement = self.nominal.currentData(), self.measurement.currentData()
        seed, fit = self.seed.value(), self.fit.values()
        return close_then(self.on_accept, nominal, measurement, seed,
                          self.allow_mismatch.isChecked(), **fit)


def _escape(text):
    return text.replace("&", "&amp;").replace("<", "&lt;")


def registration_html(obj):
    """The pose, its uncertainty and the deviation statistics of a Registration, as a table."""
    pose = obj.Pose
    axis, angle = pose.Rotation.Axis, math.degrees(pose.Rotation.Angle)
    t, ts, rs = pose.Base, obj.TranslationSigmaMm, obj.RotationSigmaDeg
    tr = lambda text: translate("BladeInspect", text)  # noqa: E731
    rows = [
        (tr("Translation"), "%.4f, %.4f, %.4f mm" % (t.x, t.y, t.z)),
        (tr("Rotation"), tr("%.4f&deg; about (%.4f, %.4f, %.4f)")
         % (angle, axis.x, axis.y, axis.z)),
        (tr("Pose uncertainty (1&sigma;, worst corner)"), "%.3f &micro;m"
         % (obj.PoseUncertaintyMm * 1000.0)),
        (tr("Translation 1&sigma;"), "%.3f, %.3f, %.3f &micro;m"
         % (ts.x * 1000, ts.y * 1000, ts.z * 1000)),
        (tr("Rotation 1&sigma;"), "%.2f, %.2f, %.2f arcsec"
         % (rs.x * 3600, rs.y * 3600, rs.z * 3600)),
        (tr("RMS (inliers)"), "%.4f mm" % obj.RmsMm),
        (tr("Points / inliers"), "%d / %d" % (obj.NPoints, obj.NInliers)),
        (tr("Deviation min / max"), "%.4f / %.4f mm" % (obj.DeviationMinMm, obj.DeviationMaxMm)),
        (tr("Mean &plusmn; std"), "%.4f &plusmn; %.4f mm"
         % (obj.DeviationMeanMm, obj.DeviationStdMm)),
        (tr("Within 1&sigma; / 3&sigma;"), "%.1f %% / %.1f %%"
         % (obj.PctWithin1Sigma, obj.PctWithin3Sigma)),
    ]
    record = registration_fit.fit_record(obj)
    if record:
        rows.append((tr("Fit"), _escape("%s, free %s, decision rule %s" % (
            record["objective"], ",".join(record["free"]) if isinstance(record["free"], list)
            else record["free"], record["decision_rule"]))))
    weights = getattr(obj, "WeightsUsed", "")
    if weights:   # which weights the fine ICP used, and why
        rows.append((tr("ICP weights"), _escape(weights)))
    html = "<table cellspacing='4'>" + "".join(
        "<tr><td><b>%s</b></td><td>%s</td></tr>" % row for row in rows) + "</table>"
    notes = list(obj.Warnings) + rival_lines(json.loads(obj.CoarseJson or "{}"))
    if notes:
        html += "<p><b>%s</b><br>" % tr("Warnings") + "<br>".join(
            _escape(w) for w in notes) + "</p>"
    return html


# Rows of the fit-sensitivity table shown without scrolling (the demo's sections, part and
# airfoil rows run to about twenty).
SENSITIVITY_ROWS_SHOWN = 12
# Rows of a section table shown without scrolling (Table 2 of the usual five to nine sections).
TABLE_ROWS_SHOWN = 9


def fit_rows_height(table, max_rows):
    """Make ``table`` tall enough for its header and up to ``max_rows`` rows (a scroll bar
    beyond), so a short table shows whole in a task panel instead of scrolling in a strip."""
    rows = min(table.rowCount(), max_rows)
    # Room for a horizontal scroll bar too: whether the panel is wide enough is known only
    # once it is shown.
    table.setMinimumHeight(table.horizontalHeader().sizeHint().height()
                           + sum(table.rowHeight(r) for r in range(rows))
                           + 2 * table.frameWidth()
                           + table.horizontalScrollBar().sizeHint().height())


def sensitivity_widget(sensitivity, rename=None):
    """The fit-sensitivity table (result.json's fit_sensitivity) with its largest change
    (gui.tables: grouped by section, a value's cell coloured by its verdict); ``rename``:
    {section label: name} (tables.section_name), the sections as Table 2 names them."""
    sensitivity = tables.sensitivity_named(sensitivity, rename)
    box = QtGui.QGroupBox(translate("BladeInspect", "Fit sensitivity"))
    layout = QtGui.QVBoxLayout(box)
    table = tables.sensitivity_table(sensitivity)
    fit_rows_height(table, SENSITIVITY_ROWS_SHOWN)
    layout.addWidget(table)
    lines = [translate("BladeInspect", "Deviation from the nominal under each fit objective; "
                       "the colour is its verdict (green pass, amber not proven, red fail, "
                       "none: not judged), the verdict and U in the tooltip.")]
    largest = sensitivity.get("largest_change")
    if largest:
        lines.append(translate("BladeInspect", "Largest change: %s, %.4f mm; the verdict %s "
                               "with the fit.")
                     % (tables.largest_change_name(sensitivity), largest["change_mm"],
                        translate("BladeInspect", "changes")
                        if sensitivity["verdict_changes"]
                        else translate("BladeInspect", "does not change")))
    if any(row.get("side_changes") for row in sensitivity["rows"]):
        lines.append(tables.tr(tables.SIDE_NOTE))
    label = QtGui.QLabel("\n".join(lines))
    label.setWordWrap(True)
    layout.addWidget(label)
    return box


class _ResultPanel:
    """A panel that only shows a result: a Close button."""

    def getStandardButtons(self):
        return int(QtGui.QDialogButtonBox.Close)

    def reject(self):
        FreeCADGui.Control.closeDialog()
        if FreeCADGui.ActiveDocument is not None and FreeCADGui.ActiveDocument.getInEdit():
            FreeCADGui.ActiveDocument.resetEdit()
        return True


class RegistrationPanel(_ResultPanel):
    """What a registration found: the pose and how well it is known, the fit and what the
    choice of fit changes."""

    def __init__(self, obj):
        self.obj = obj
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(translate("BladeInspect", "Registration: %s") % obj.Label)
        layout = QtGui.QVBoxLayout(self.form)
        self.text = QtGui.QTextBrowser()
        self.text.setHtml(registration_html(obj))
        self.text.setMinimumHeight(320)
        layout.addWidget(self.text)
        sensitivity = registration_fit.sensitivity_of(obj)
        self.sensitivity = None
        self.verdict_banner = None
        if sensitivity:
            # an inspection's sections by their planned heights, as Table 2 names them
            heights = list(getattr(obj, "InspectionHeights", []) or [])
            self.sensitivity = sensitivity_widget(sensitivity, {
                str(k + 1): tables.section_name(h) for k, h in enumerate(heights)})
            layout.addWidget(self.sensitivity)
            # the verdict under the registration's own fit first: what the user came for
            record = registration_fit.fit_record(obj) or {}
            objective = record.get("objective")
            verdict = (sensitivity.get("verdict_by_fit") or {}).get(objective)
            if verdict is not None:
                self.verdict_banner = tables.add_verdict(layout, verdict, translate(
                    "BladeInspect", "The part's verdict under the %s fit (%s); the table below "
                    "gives it under every fit.") % (objective, record.get("decision_rule")))


class TablePanel(_ResultPanel):
    """A table of text cells with its header: the section analysis; ``sensitivity`` (a
    fit_sensitivity block) adds its table below."""

    def __init__(self, title, header, rows, note="", sensitivity=None, verdict=None):
        """``verdict``: inspection.verdict.judge's of the table: the part's verdict on top,
        large, and each section's verdict, worst deviation, U and TUR first in the table."""
        self.form = QtGui.QWidget()
        # The task box's title does not wrap: a long one ("Inspection: Table 2 at the nominal
        # sections") would widen the panel past FreeCAD's default Combo View. Its first part
        # is the title, the rest a wrapped line under the verdict.
        head, _, rest = title.partition(": ")
        self.form.setWindowTitle(head)
        layout = QtGui.QVBoxLayout(self.form)
        # the details under the table (the weight model, the folder): the form's first label
        self.note = QtGui.QLabel(tables.breakable_paths(tables.plus_minus(note)), self.form) \
            if note else None
        self.verdict_banner = None
        if verdict:
            self.verdict_banner = tables.add_verdict(
                layout, tables.part_verdict(verdict), verdict_details(verdict, len(rows)))
            self.table = tables.section_verdict_table(header, rows, verdict)
        else:
            self.table = tables.section_table(header, rows)
        if rest:
            subtitle = QtGui.QLabel(rest)
            subtitle.setWordWrap(True)
            layout.insertWidget(0 if self.verdict_banner is None else 1, subtitle)
        fit_rows_height(self.table, TABLE_ROWS_SHOWN)
        layout.addWidget(self.table)
        if self.note is not None:
            self.note.setWordWrap(True)
            self.note.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
            layout.addWidget(self.note)
        if sensitivity:
            span = header.index("Span %") if "Span %" in header else None
            layout.addWidget(sensitivity_widget(sensitivity, None if span is None else {
                row[0]: tables.section_name(float(row[span])) for row in rows}))


def verdict_details(verdict, n_sections):
    """The line under a part's verdict: what it judged, against what, by which rule."""
    text = translate("BladeInspect", "%d sections and the out-of-tolerance spots judged "
                     "against \u00b1%.3f mm (%s).") % (
        n_sections, verdict["tolerance_mm"], verdict.get("decision_rule", ""))
    if verdict.get("n_isolated_out"):
        text += " " + translate("BladeInspect", "%d isolated points treated as sensor "
                                "outliers.") % verdict["n_isolated_out"]
    return text


# ---------------------------------------------------------------- airfoil

CHARACTERISTICS_FILTER = QT_TRANSLATE_NOOP("BladeInspect",
                                           "Characteristics (*.csv);;All files (*)")


class AirfoilOptionsPanel(FormPanel):
    """The `airfoil` command's options: the registration it analyses, the characteristics file,
    chord method, engine axis. on_accept(registration name, **options)."""
    title = QT_TRANSLATE_NOOP("BladeInspect", "Airfoil analysis")

    def __init__(self, on_accept, registrations=(), registration=None):
        super().__init__()
        self.on_accept = on_accept
        self.registration = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Registration"),
            object_combo(registrations, registration),
            QT_TRANSLATE_NOOP("BladeInspect", "The registered measurement to analyse (the "
                              "selected one when a registration is selected)"))
        self.characteristics = self.add_file_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Characteristics file"), QtGui.QLineEdit(),
            QT_TRANSLATE_NOOP("BladeInspect", "CSV: characteristic,section,lower,upper"
                              "[,nominal]; empty: every characteristic reported, none judged"),
            QT_TRANSLATE_NOOP("BladeInspect", "Characteristics file"), CHARACTERISTICS_FILTER)
        self.chord = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Chord"), QtGui.QComboBox(),
            QT_TRANSLATE_NOOP("BladeInspect", "How the chord line is drawn"))
        self.chord.addItems(list(CHORD_METHODS))
        self.axis = self.add_row(
            QT_TRANSLATE_NOOP("BladeInspect", "Engine axis"), QtGui.QLineEdit("x"),
            QT_TRANSLATE_NOOP("BladeInspect", "A letter (x, y, z, -x, ...) or a vector"))

    def options(self):
        return {"characteristics": self.characteristics.text().strip() or None,
                "chord_method": self.chord.currentText(),
                "engine_axis": self.axis.text().strip() or None}

    def validate(self):
        def registration():
            if self.registration.currentIndex() < 0:
                raise InputError(translate("BladeInspect", "No registration in the document"))

        def characteristics():
            path = self.characteristics.text().strip()
            if path:
                read_characteristics(path)
        def axis():
            text = self.axis.text().strip()
            if text:
                parse_engine_axis(text)
        checks = [self.check(self.registration, registration),
                  self.check(self.characteristics, characteristics),
                  self.check(self.axis, axis)]
        return all(checks)

    def accept(self):
        if not self.validate():
            return False
        registration, options = self.registration.currentData(), self.options()
        return close_then(self.on_accept, registration, **options)


class AirfoilPanel(_ResultPanel):
    """The airfoil characteristics of every section (result.json's airfoil blocks), the
    airfoil verdict and the lean and bow."""

    def __init__(self, analysis):
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(translate("BladeInspect", "Airfoil characteristics"))
        layout = QtGui.QVBoxLayout(self.form)
        summary = (analysis.get("airfoil_verdict") or {}).get("summary", "")
        # sections named by their nominal heights, as Table 2 names them
        analysis = tables.named_by_height(analysis)
        # per section a line and its characteristics (gui.tables)
        self.rows = tables.airfoil_rows(analysis.get("airfoil", []))
        self.table = tables.airfoil_table(self.rows)
        self.table.setMinimumHeight(420)
        # the failed characteristics by the names the table shows (result.json's summary,
        # with the field names, in the tooltip)
        verdict_ = analysis.get("airfoil_verdict") or {}
        lines = [names.airfoil_verdict_text(verdict_, analysis.get("airfoil", []), tables.tr)]
        lean_bow = analysis.get("lean_bow")
        if lean_bow:
            lines.append(translate("BladeInspect", "Lean and bow: largest bow at section %s.")
                         % lean_bow["largest_bow_section"])
        label = QtGui.QLabel("\n".join(line for line in lines if line))
        label.setWordWrap(True)
        label.setToolTip(summary)
        layout.addWidget(label)
        self.verdict_label = label
        layout.addWidget(self.table)
        # how the values were measured and their U found: details, under the table
        settings_ = analysis.get("airfoil_settings", {})
        if settings_:
            method = QtGui.QLabel(translate("BladeInspect", "Chord: %s; U = 2 x the %s (%s).")
                                  % (settings_.get("chord_method"),
                                     settings_.get("uncertainty_coverage"),
                                     settings_.get("uncertainty_method")))
            method.setWordWrap(True)
            layout.addWidget(method)
        # the verdict first; a characteristic withheld as not measured is in no verdict
        self.verdict_banner = tables.add_verdict(
            layout, tables.part_verdict(verdict_), translate(
                "BladeInspect", "Airfoil characteristics of %d sections; a value not "
                "measured is shown without a verdict, with its reason.")
            % len(analysis.get("airfoil", [])))
        # What the stage says it could not do well (sparse edges, non-circular ends): a
        # number shown without its caveat would be trusted where it should not be.
        notes = ["%s %s: %s" % (translate("BladeInspect", "Section"), block["label"],
                                tables.plus_minus(note))
                 for block in analysis.get("airfoil", []) for note in block.get("notes", [])]
        if notes:
            self.notes = QtGui.QTextBrowser()
            self.notes.setPlainText("\n".join(notes))
            self.notes.setMaximumHeight(140)
            layout.addWidget(self.notes)
