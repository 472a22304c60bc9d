"""The BladeInspect page of FreeCAD's preferences: sensor and rig parameters, scan strategy,
tolerance and colour limits, stored in User parameter:BaseApp/Preferences/Mod/BladeInspect
(app.settings), shown in group boxes by topic."""
from PySide import QtGui

from ..app import settings
from .i18n import QT_TRANSLATE_NOOP, translate
from .forms import form_layout, wrapped_label

# (group title, [(setting, label, tooltip)]), in the page's order; every setting of
# app.settings.SETTINGS once.
PAGE = [
    (QT_TRANSLATE_NOOP("BladeInspect", "Sensor"), [
        ("StandoffMm", QT_TRANSLATE_NOOP("BladeInspect", "Standoff z\u209b"),
         QT_TRANSLATE_NOOP("BladeInspect", "Distance from the sensor to the middle of its "
                           "working range")),
        ("WorkingRangeMm", QT_TRANSLATE_NOOP("BladeInspect", "Working range \u00b1\u03b4"),
         QT_TRANSLATE_NOOP("BladeInspect", "Half the depth of the sensor's working range: it "
                           "measures from z\u209b \u2212 \u03b4 to z\u209b + \u03b4")),
        ("SensorAccuracyMm", QT_TRANSLATE_NOOP("BladeInspect", "Accuracy"),
         QT_TRANSLATE_NOOP("BladeInspect", "The sensor's stated accuracy, added to the "
                           "tolerance when a scan is checked against the CAD")),
        ("PointsPerSecond", QT_TRANSLATE_NOOP("BladeInspect", "Rate"),
         QT_TRANSLATE_NOOP("BladeInspect", "Points the sensor measures per second (the scan "
                           "time estimate)")),
    ]),
    (QT_TRANSLATE_NOOP("BladeInspect", "Scan strategy"), [
        ("Sections", QT_TRANSLATE_NOOP("BladeInspect", "Sections per scan"),
         QT_TRANSLATE_NOOP("BladeInspect", "Sections the Scan command measures over the "
                           "span")),
        ("SectionSpacingMm", QT_TRANSLATE_NOOP("BladeInspect", "Section spacing"),
         QT_TRANSLATE_NOOP("BladeInspect", "Distance between sections; 0 spreads them over "
                           "the span")),
        ("PointSpacingMm", QT_TRANSLATE_NOOP("BladeInspect", "Point spacing"),
         QT_TRANSLATE_NOOP("BladeInspect", "Distance between points along a section")),
        ("Sides", QT_TRANSLATE_NOOP("BladeInspect", "Sides scanned"),
         QT_TRANSLATE_NOOP("BladeInspect", "1: one side; 2: the part turned over to scan "
                           "the other")),
        ("EpsilonMm", QT_TRANSLATE_NOOP("BladeInspect", "Rescan criterion \u03b5"),
         QT_TRANSLATE_NOOP("BladeInspect", "A section is rescanned until every point lies "
                           "within \u03b5 of the sensor's standoff")),
    ]),
    (QT_TRANSLATE_NOOP("BladeInspect", "Tolerance and colour map"), [
        ("ToleranceMm", QT_TRANSLATE_NOOP("BladeInspect", "Profile tolerance"),
         QT_TRANSLATE_NOOP("BladeInspect", "The profile tolerance each section is judged "
                           "against (\u00b1, mm)")),
        ("ColourLimitMm", QT_TRANSLATE_NOOP("BladeInspect", "Colour map limit"),
         QT_TRANSLATE_NOOP("BladeInspect", "The deviation at which the colour map "
                           "saturates; 0: the profile tolerance")),
    ]),
    (QT_TRANSLATE_NOOP("BladeInspect", "Simulation"), [
        ("Seed", QT_TRANSLATE_NOOP("BladeInspect", "Random seed"),
         QT_TRANSLATE_NOOP("BladeInspect", "Seed of the simulated rig and of the "
                           "registration's sampling: the same seed repeats a run")),
    ]),
]


# The units shown after a value; "points/s" is words to translate.
UNITS = {"mm": "mm", "points/s": QT_TRANSLATE_NOOP("BladeInspect", "points/s")}


class PreferencesPage:
    def __init__(self, parent=None):
        self.form = QtGui.QWidget(parent)
        self.form.setWindowTitle(translate("BladeInspect", "BladeInspect"))
        page = QtGui.QVBoxLayout(self.form)
        self.widgets = {}
        for title, rows in PAGE:
            group = QtGui.QGroupBox(translate("BladeInspect", title))
            layout = form_layout(group)
            for name, label, tip in rows:
                widget = self._field(name)
                widget.setToolTip(translate("BladeInspect", tip))
                text = wrapped_label(translate("BladeInspect", label))
                text.setToolTip(translate("BladeInspect", tip))
                layout.addRow(text, widget)
            page.addWidget(group)
        page.addStretch(1)
        self.loadSettings()

    def _field(self, name):
        kind, _, unit, lo, hi, decimals = settings.SETTINGS[name]
        if kind == "int":
            widget = QtGui.QSpinBox()
            widget.setRange(int(lo), int(hi))
        else:
            widget = QtGui.QDoubleSpinBox()
            widget.setDecimals(decimals)
            widget.setRange(lo, hi)
            widget.setSingleStep(10.0 ** -(decimals - 1) if decimals > 1 else 1.0)
        if unit:
            widget.setSuffix(" " + translate("BladeInspect", UNITS[unit]))
        widget.setObjectName(name)
        self.widgets[name] = widget
        return widget

    def loadSettings(self):
        for name, widget in self.widgets.items():
            widget.setValue(settings.value(name))

    def saveSettings(self):
        for name, widget in self.widgets.items():
            settings.store(name, widget.value())
