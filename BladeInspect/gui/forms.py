"""What the input panels share: a form layout that stays readable in a narrow task view, fields
that ask for the width their value needs, combo boxes of document objects, and FormPanel, whose
accept() checks its inputs before the panel closes and shows a bad one's error under its
field."""
import re

import FreeCADGui
from PySide import QtCore, QtGui

from ..core.errors import InputError
from .i18n import QT_TRANSLATE_NOOP, translate


# The Browse buttons' file dialog, ask(title, filters) -> path or None: gui.commands sets it to
# its ask_open_file (which tests answer in its place), since this module cannot import it.
FILE_DIALOG = {"open": None}
# The command line's options as the panels name them: an error the GUI shows names the control
# the user can change, not a flag they cannot type (gui_text).
CLI_CONTROLS = {
    "--allow-mismatch": QT_TRANSLATE_NOOP("BladeInspect",
                                          "the Register panel's 'Allow mismatch' box"),
    "--section-heights": QT_TRANSLATE_NOOP("BladeInspect", "Section heights"),
    "--characteristics": QT_TRANSLATE_NOOP("BladeInspect", "Characteristics file"),
    "--engine-axis": QT_TRANSLATE_NOOP("BladeInspect", "Engine axis"),
    "--chord-method": QT_TRANSLATE_NOOP("BladeInspect", "Chord"),
    "--weights-by-zone": QT_TRANSLATE_NOOP("BladeInspect", "Zone weights"),
    "--weights": QT_TRANSLATE_NOOP("BladeInspect", "ICP weights"),
    "--free": QT_TRANSLATE_NOOP("BladeInspect", "Free DOF"),
    "--fit": QT_TRANSLATE_NOOP("BladeInspect", "Objective"),
    "--decision-rule": QT_TRANSLATE_NOOP("BladeInspect", "Decision rule"),
    "--rig-file": QT_TRANSLATE_NOOP("BladeInspect", "Rig calibration"),
}
_FLAG = re.compile(r"--[a-z][a-z-]*[a-z]")


def gui_text(message):
    """An error message of the pipeline with the command line's options named as the GUI's
    controls."""
    return _FLAG.sub(lambda m: translate("BladeInspect", CLI_CONTROLS[m.group(0)])
                     if m.group(0) in CLI_CONTROLS else m.group(0), message)


# An input error's colour, as FreeCAD's own task panels show one.
ERROR_STYLE = "color: #c00000;"


def form_layout(parent):
    """A form layout that stays readable in a narrow task view (the Combo View is about 230 px
    wide by default): a row whose label and field do not fit side by side puts the field under
    its label instead of clipping either."""
    layout = QtGui.QFormLayout(parent)
    layout.setRowWrapPolicy(QtGui.QFormLayout.WrapLongRows)
    layout.setFieldGrowthPolicy(QtGui.QFormLayout.AllNonFixedFieldsGrow)
    return layout


# The widest a line edit asks to be before its row wraps (px); a longer text scrolls in it.
LINE_EDIT_MAX_MIN_WIDTH = 180


def fit_field(widget):
    """Ask for the width the field needs to show its value whole, so that a form row too narrow
    for label and field side by side wraps (form_layout) rather than clipping the value."""
    if isinstance(widget, (QtGui.QAbstractSpinBox, QtGui.QComboBox)):
        widget.setMinimumWidth(widget.sizeHint().width())
    elif isinstance(widget, QtGui.QLineEdit):
        text = widget.text() or widget.placeholderText()
        widget.setMinimumWidth(min(max(widget.fontMetrics().horizontalAdvance(text) + 16, 80),
                                   LINE_EDIT_MAX_MIN_WIDTH))
    return widget


def wrapped_label(text):
    label = QtGui.QLabel(text)
    label.setWordWrap(True)
    return label


def object_combo(candidates, chosen):
    """A combo box of document objects shown by their labels (names in the tooltip), the
    object ``chosen`` preselected; currentData() is the chosen object's Name."""
    box = QtGui.QComboBox()
    box.setSizeAdjustPolicy(QtGui.QComboBox.AdjustToMinimumContentsLengthWithIcon)
    box.setMinimumContentsLength(8)
    for obj in candidates:
        box.addItem(obj.Label, obj.Name)
        box.setItemData(box.count() - 1, obj.Name, QtCore.Qt.ToolTipRole)
    if chosen is not None and chosen in candidates:
        box.setCurrentIndex(list(candidates).index(chosen))
    return box


class FormPanel:
    """An input panel: labelled rows, and accept() that checks them (validate) before the
    panel closes; a bad input shows its one-line error in red under its field and keeps the
    panel open with what the user typed."""
    title = ""    # marked with QT_TRANSLATE_NOOP("BladeInspect", ...), translated when shown

    def __init__(self):
        self.form = QtGui.QWidget()
        self.form.setWindowTitle(translate("BladeInspect", self.title))
        self.layout = form_layout(self.form)
        self.errors = {}

    def add_row(self, label, widget, tip=None):
        """A form row; ``label`` and ``tip`` are translated here. Its error line (hidden)
        follows it."""
        if tip:
            widget.setToolTip(translate("BladeInspect", tip))
        self.layout.addRow(wrapped_label(translate("BladeInspect", label)), fit_field(widget))
        return self._add_error_line(widget)

    def add_wide_row(self, widget, tip):
        """A row of one widget that names itself (a check box), the panel's width."""
        widget.setToolTip(translate("BladeInspect", tip))
        self.layout.addRow(widget)
        return self._add_error_line(widget)

    def _add_error_line(self, widget):
        error = wrapped_label("")
        error.setStyleSheet(ERROR_STYLE)
        error.setObjectName("error")
        error.hide()
        self.layout.addRow(error)
        self.errors[widget] = error
        return widget

    def add_file_row(self, label, line_edit, tip, dialog_title, filters):
        """A row of a file name with a Browse button that fills it (FILE_DIALOG)."""
        row = QtGui.QWidget()
        box = QtGui.QHBoxLayout(row)
        box.setContentsMargins(0, 0, 0, 0)
        box.addWidget(line_edit, 1)
        button = QtGui.QPushButton(translate("BladeInspect", "Browse..."))
        button.setToolTip(translate("BladeInspect", "Choose the file"))
        box.addWidget(button)

        def browse():
            path = FILE_DIALOG["open"](translate("BladeInspect", dialog_title), filters)
            if path:
                line_edit.setText(path)
                self.clear_error(line_edit)
        button.clicked.connect(browse)
        line_edit.setToolTip(translate("BladeInspect", tip))
        self.add_row(label, row)
        self.errors[line_edit] = self.errors.pop(row)
        line_edit.browse_button = button
        return line_edit

    def show_error(self, widget, text):
        label = self.errors[widget]
        label.setText(text)
        label.setToolTip(text)
        label.show()
        widget.setFocus()

    def clear_error(self, widget):
        self.errors[widget].hide()

    def check(self, widget, parse):
        """parse() with the field's error line cleared, or shown with its InputError; True
        when it parsed."""
        try:
            parse()
        except InputError as exc:
            self.show_error(widget, gui_text(str(exc)))
            return False
        self.clear_error(widget)
        return True

    def validate(self):
        """True when every input reads; else the errors shown (the panel stays open)."""
        return True

    def reject(self):
        FreeCADGui.Control.closeDialog()
        return True
