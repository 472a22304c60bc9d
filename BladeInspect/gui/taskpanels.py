"""Task panels: the parameters of a command before it runs, and what a result says after.
Panels collect input and show output; the work is done by the commands' pipeline calls."""
import dataclasses
import json
import math

import FreeCADGui
from PySide import QtGui

from ..app import settings
from ..cad.demo_blade import BladeParams
from ..inspection.result import rival_lines


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


class FormPanel:
    title = ""

    def __init__(self):
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(self.title)
        self.layout = QtGui.QFormLayout(self.form)

    def reject(self):
        FreeCADGui.Control.closeDialog()
        return True


class DemoBladePanel(FormPanel):
    """BladeParams as spin boxes; OK builds the demo blade through on_accept(params)."""
    title = "Demo blade"

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
            box = spin_box(value, -1e4, 1e4)
            self.boxes[field.name] = box
            self.layout.addRow(field.name.replace("_", " "), box)

    def params(self):
        return self.params_type(**{name: type(getattr(self.params_type(), name))(box.value())
                                   for name, box in self.boxes.items()})

    def accept(self):
        params = self.params()   # read before closing: closing deletes the widgets
        FreeCADGui.Control.closeDialog()
        self.on_accept(params)
        return True


class ConnectRigPanel(FormPanel):
    """Simulated rig, or a serial port picked from the ports pyserial finds."""
    title = "Connect rig"

    def __init__(self, on_accept):
        super().__init__()
        self.on_accept = on_accept
        self.kind = QtGui.QComboBox()
        self.kind.addItems(["Simulated rig", "Serial port"])
        self.port = QtGui.QComboBox()
        self.port.setEditable(True)
        for port in self._ports():
            self.port.addItem(port)
        self.seed = spin_box(settings.value("Seed"), 0, 2 ** 31 - 1)
        self.layout.addRow("Rig", self.kind)
        self.layout.addRow("Port", self.port)
        self.layout.addRow("Seed (simulated)", self.seed)
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

    def accept(self):
        spec, seed = self.spec(), self.seed.value()
        FreeCADGui.Control.closeDialog()
        self.on_accept(spec, seed)
        return True


class ScanPanel(FormPanel):
    """Scan parameters (the scan strategy's options), defaults from the preferences."""
    title = "Scan"

    def __init__(self, on_accept):
        super().__init__()
        self.on_accept = on_accept
        self.sections = spin_box(settings.value("Sections"), 1, 200)
        self.spacing = spin_box(settings.value("SectionSpacingMm"), 0.0, 1000.0, 2, "mm")
        self.spacing.setToolTip("Distance between sections; 0 spreads them over the span")
        self.point_spacing = spin_box(settings.value("PointSpacingMm"), 0.005, 10.0, 3, "mm")
        self.sides = spin_box(settings.value("Sides"), 1, 2)
        self.sides.setToolTip("2 turns the part over to scan the other side")
        self.epsilon = spin_box(settings.value("EpsilonMm"), 0.01, 50.0, 2, "mm")
        self.epsilon.setToolTip("Rescan a section until every point is within this distance "
                                "of the sensor's standoff")
        self.seed = spin_box(settings.value("Seed"), 0, 2 ** 31 - 1)
        self.layout.addRow("Sections", self.sections)
        self.layout.addRow("Section spacing", self.spacing)
        self.layout.addRow("Point spacing", self.point_spacing)
        self.layout.addRow("Sides", self.sides)
        self.layout.addRow("Standoff criterion \u03b5", self.epsilon)
        self.layout.addRow("Seed", self.seed)

    def options(self):
        spacing = self.spacing.value()
        return {"n_sections": self.sections.value(),
                "section_spacing": spacing if spacing > 0 else None,
                "point_spacing": self.point_spacing.value(), "sides": self.sides.value(),
                "epsilon": self.epsilon.value(), "seed": self.seed.value()}

    def accept(self):
        options = self.options()
        FreeCADGui.Control.closeDialog()
        self.on_accept(options)
        return True


def registration_html(obj):
    """The pose, its uncertainty and the deviation statistics of a Registration, as a table."""
    pose = obj.Pose
    axis, angle = pose.Rotation.Axis, math.degrees(pose.Rotation.Angle)
    t, ts, rs = pose.Base, obj.TranslationSigmaMm, obj.RotationSigmaDeg
    rows = [
        ("Translation", "%.4f, %.4f, %.4f mm" % (t.x, t.y, t.z)),
        ("Rotation", "%.4f&deg; about (%.4f, %.4f, %.4f)" % (angle, axis.x, axis.y, axis.z)),
        ("Pose uncertainty (1&sigma;, worst corner)", "%.3f &micro;m"
         % (obj.PoseUncertaintyMm * 1000.0)),
        ("Translation 1&sigma;", "%.3f, %.3f, %.3f &micro;m"
         % (ts.x * 1000, ts.y * 1000, ts.z * 1000)),
        ("Rotation 1&sigma;", "%.2f, %.2f, %.2f arcsec"
         % (rs.x * 3600, rs.y * 3600, rs.z * 3600)),
        ("RMS (inliers)", "%.4f mm" % obj.RmsMm),
        ("Points / inliers", "%d / %d" % (obj.NPoints, obj.NInliers)),
        ("Deviation min / max", "%.4f / %.4f mm" % (obj.DeviationMinMm, obj.DeviationMaxMm)),
        ("Mean &plusmn; std", "%.4f &plusmn; %.4f mm" % (obj.DeviationMeanMm, obj.DeviationStdMm)),
        ("Within 1&sigma; / 3&sigma;", "%.1f %% / %.1f %%"
         % (obj.PctWithin1Sigma, obj.PctWithin3Sigma)),
    ]
    html = "<table cellspacing='4'>" + "".join(
        "<tr><td><b>%s</b></td><td>%s</td></tr>" % row for row in rows) + "</table>"
    notes = list(obj.Warnings) + rival_lines(json.loads(obj.CoarseJson or "{}"))
    if notes:
        html += "<p><b>Warnings</b><br>" + "<br>".join(
            w.replace("&", "&amp;").replace("<", "&lt;") for w in notes) + "</p>"
    return html


class RegistrationPanel:
    """What a registration found: the pose and how well it is known."""

    def __init__(self, obj):
        self.obj = obj
        self.form = QtGui.QWidget()
        self.form.setWindowTitle("Registration: " + obj.Label)
        layout = QtGui.QVBoxLayout(self.form)
        self.text = QtGui.QTextBrowser()
        self.text.setHtml(registration_html(obj))
        self.text.setMinimumHeight(320)
        layout.addWidget(self.text)

    def getStandardButtons(self):
        return int(QtGui.QDialogButtonBox.Close)

    def reject(self):
        FreeCADGui.Control.closeDialog()
        if FreeCADGui.ActiveDocument is not None and FreeCADGui.ActiveDocument.getInEdit():
            FreeCADGui.ActiveDocument.resetEdit()
        return True


class TablePanel:
    """A table of text cells with its header: the section analysis."""

    def __init__(self, title, header, rows, note=""):
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(title)
        layout = QtGui.QVBoxLayout(self.form)
        self.table = QtGui.QTableWidget(len(rows), len(header))
        self.table.setHorizontalHeaderLabels(list(header))
        for r, row in enumerate(rows):
            for c, cell in enumerate(row):
                self.table.setItem(r, c, QtGui.QTableWidgetItem(str(cell)))
        self.table.resizeColumnsToContents()
        self.table.setMinimumHeight(260)
        layout.addWidget(self.table)
        if note:
            label = QtGui.QLabel(note)
            label.setWordWrap(True)
            layout.addWidget(label)

    def getStandardButtons(self):
        return int(QtGui.QDialogButtonBox.Close)

    def reject(self):
        FreeCADGui.Control.closeDialog()
        return True
