"""The BladeInspect page of FreeCAD's preferences: sensor and rig parameters, tolerance and
colour limits, stored in User parameter:BaseApp/Preferences/Mod/BladeInspect (app.settings)."""
from PySide import QtGui

from ..app import settings
from .i18n import translate


class PreferencesPage:
    def __init__(self, parent=None):
        self.form = QtGui.QWidget(parent)
        self.form.setWindowTitle(translate("BladeInspect", "BladeInspect"))
        layout = QtGui.QFormLayout(self.form)
        self.widgets = {}
        for name, (kind, default, label, unit, lo, hi) in settings.SETTINGS.items():
            if kind == "int":
                widget = QtGui.QSpinBox()
                widget.setRange(int(lo), int(hi))
            else:
                widget = QtGui.QDoubleSpinBox()
                widget.setDecimals(4)
                widget.setRange(lo, hi)
                if unit:
                    widget.setSuffix(" " + unit)
            widget.setObjectName(name)
            self.widgets[name] = widget
            layout.addRow(translate("BladeInspect", label), widget)
        self.loadSettings()

    def loadSettings(self):
        for name, widget in self.widgets.items():
            widget.setValue(settings.value(name))

    def saveSettings(self):
        for name, widget in self.widgets.items():
            settings.store(name, widget.value())
