"""The result tables of the task panels (Table 2, the airfoil characteristics, the fit
sensitivity) laid out for a task panel about 640 px wide: characteristics by their display
names (inspection.characteristic_names) with their unit, short headers over two lines with the
full meaning as a tooltip, the names' column takes the width left (wrapped over two lines when
the panel is narrow, whole with the field name in the tooltip), rows grouped under a line per
section, verdicts coloured. A characteristics table fits a 640 px panel without scrolling
sideways, its headers whole (tests/gui_loop_macro.py checks it; 560 px in
tests/gui_airfoil_macro.py, where the unit and verdict columns wrap to leave the names'
header its width: NamedRowsTable)."""
import re

from PySide import QtCore, QtGui

from ..inspection import airfoil_stage as airfoil_mod
from ..inspection import characteristic_names as names
from .i18n import QT_TRANSLATE_NOOP, translate

# Cell colours of the verdicts (light, so that the text stays readable); a verdict not listed
# (not judged) keeps the table's colour.
VERDICT_COLOURS = {"pass": "#c8e6c9", "fail": "#ffcdd2", "not proven": "#ffe0b2",
                   # a toleranced value withheld is not proven, never a fail
                   "not measured": "#ffe0b2"}
GROUP_COLOUR = "#e0e0e0"
# What a withheld value (null, with its reason) shows where its number would be
NOT_MEASURED = QT_TRANSLATE_NOOP("BladeInspect", "not measured")

AIRFOIL_COLUMNS = (
    (QT_TRANSLATE_NOOP("BladeInspect", "Characteristic"),
     QT_TRANSLATE_NOOP("BladeInspect", "The characteristic; its field name in airfoil.json, "
                                       "airfoil.csv and the --characteristics file in the "
                                       "tooltip")),
    (QT_TRANSLATE_NOOP("BladeInspect", "Unit"),
     QT_TRANSLATE_NOOP("BladeInspect", "Unit of the nominal, actual, deviation, U and "
                                       "tolerance")),
    (QT_TRANSLATE_NOOP("BladeInspect", "Nominal"),
     QT_TRANSLATE_NOOP("BladeInspect", "The CAD's value (or the characteristics file's)")),
    (QT_TRANSLATE_NOOP("BladeInspect", "Actual"),
     QT_TRANSLATE_NOOP("BladeInspect", "The measured value")),
    (QT_TRANSLATE_NOOP("BladeInspect", "Dev."),
     QT_TRANSLATE_NOOP("BladeInspect", "Deviation: actual - nominal")),
    (QT_TRANSLATE_NOOP("BladeInspect", "\u00b1U\nk=2"),
     QT_TRANSLATE_NOOP("BladeInspect", "Expanded uncertainty U (k = 2): the decision's, else "
                                       "2 u of the stated standard uncertainty")),
    (QT_TRANSLATE_NOOP("BladeInspect", "Tol."),
     QT_TRANSLATE_NOOP("BladeInspect", "Tolerance on the deviation (lower / upper limit)")),
    (QT_TRANSLATE_NOOP("BladeInspect", "Verdict"),
     QT_TRANSLATE_NOOP("BladeInspect", "pass, not proven, fail (the decision rule with U), "
                                       "not judged without a tolerance")),
)
# The column that takes the width left over (its names wrapped, whole in their tooltip).
NAME_COLUMN = 0
# The least share of the names' header a narrow panel may leave on its first line (broken
# with a hyphen); narrower, the column keeps its header whole and the table scrolls sideways.
NARROWEST_NAME_SHARE = 0.6
VERDICT_COLUMN = len(AIRFOIL_COLUMNS) - 1
# Sensitivity columns before and after the objectives'
SENSITIVITY_LEADING = (AIRFOIL_COLUMNS[0], AIRFOIL_COLUMNS[1])
SENSITIVITY_CHANGE = (QT_TRANSLATE_NOOP("BladeInspect", "Change"),
                      QT_TRANSLATE_NOOP("BladeInspect", "Largest minus smallest over the "
                                                        "objectives: of a worst deviation's "
                                                        "size |value| (what the verdict "
                                                        "judges against \u00b1T), of an "
                                                        "airfoil characteristic's value"))
# A worst deviation's change marked when it is + under one objective and - under another
SIDE_MARK = " *"
SIDE_NOTE = QT_TRANSLATE_NOOP("BladeInspect", "*: the worst deviation is + under one objective "
                                              "and - under another; the change is of its "
                                              "size, which the verdict judges")


def tr(text):
    return translate("BladeInspect", text)


def _same(text):
    return text


def _header(table, columns, translator=tr):
    """Header labels with tooltips from (label, tip) pairs, translated by ``translator``."""
    for c, (label, tip) in enumerate(columns):
        item = QtGui.QTableWidgetItem(translator(label))
        item.setToolTip(translator(tip))
        if c == 0:   # the names' column: its header's start stays in view when it narrows
            item.setTextAlignment(int(QtCore.Qt.AlignLeft | QtCore.Qt.AlignVCenter))
        table.setHorizontalHeaderItem(c, item)


def _item(text, tip=None, align=None):
    item = QtGui.QTableWidgetItem(text)
    if tip:
        item.setToolTip(tip)
    if align is not None:
        item.setTextAlignment(align)
    return item


NUMBER = int(QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter)


def colour_verdict(item, verdict):
    colour = VERDICT_COLOURS.get(verdict)
    if colour:
        item.setBackground(QtGui.QBrush(QtGui.QColor(colour)))
    return item


def verdict_item(verdict):
    return colour_verdict(_item(tr(verdict) if verdict else ""), verdict)


def _group_row(table, r, text, verdict=None):
    """A line across the table naming the rows under it (a section, the part)."""
    item = _item(text)
    font = item.font()
    font.setBold(True)
    item.setFont(font)
    item.setBackground(QtGui.QBrush(QtGui.QColor(VERDICT_COLOURS.get(verdict,
                                                                     GROUP_COLOUR))))
    table.setItem(r, 0, item)
    table.setSpan(r, 0, 1, table.columnCount())


class NamedRowsTable(QtGui.QTableWidget):
    """A table whose names' column (the stretched one) is never narrower than its header
    while other columns can give way: when the panel is too narrow for every column at its
    contents' width, the ``wrap_columns`` are narrowed in turn to their longest word (their
    cells wrap, "% chord" over two lines) until the names' header reads whole. FreeCAD 1.0's
    task panel at 560 px left "Characteristic" 9 px short ("Characterist"); a wider panel
    keeps every column whole."""
    wrap_columns = ()
    name_column = NAME_COLUMN

    def __init__(self, *args):
        super().__init__(*args)
        self._sharing = False
        self._name_label = None    # the names' header as set, before any break
        self._narrowed = False     # the names' column fixed at its header, the table scrolls

    def resizeEvent(self, event):   # noqa: N802 (Qt's name)
        super().resizeEvent(event)
        self.share_width()

    def _full_width(self, c):
        # what ResizeToContents gives the column
        return max(self.sizeHintForColumn(c), self.horizontalHeader().sectionSizeHint(c))

    def _header_need(self, c, text=None):
        """The header's longest line with the style's header margin on both sides, as the
        header draws its label (its size hint adds more: a sort indicator's room)."""
        header = self.horizontalHeader()
        if text is None:
            item = self.horizontalHeaderItem(c)
            text = item.text() if item is not None else ""
        margin = header.style().pixelMetric(QtGui.QStyle.PM_HeaderMargin, None, header)
        return max(header.fontMetrics().horizontalAdvance(x) for x in text.split("\n")) \
            + 2 * margin + 2

    def _break_name_header(self, room):
        """The names' header whole on one line when ``room`` px hold it, else broken over two
        lines with a hyphen where the first line fills the room: on a panel too narrow for
        it (every other column already at its narrowest) a header cut to "Characteris" reads
        as another word."""
        item = self.horizontalHeaderItem(self.name_column)
        if item is None:
            return
        if self._name_label is None:
            self._name_label = item.text()
        label = text = self._name_label
        if "\n" not in label and self._header_need(self.name_column, label) > room:
            fits = [i for i in range(2, len(label) - 1)
                    if self._header_need(self.name_column, label[:i] + "-") <= room]
            cut = fits[-1] if fits else 2
            text = label[:cut] + "-\n" + label[cut:]
        if item.text() != text:
            item.setText(text)

    def _texts(self, c):
        items = (self.item(r, c) for r in range(self.rowCount()) if self.columnSpan(r, c) == 1)
        return [item.text() for item in items if item is not None and item.text()]

    def _word_width(self, c):
        """The column as wide as its header and its longest word (its cells' padding as
        the delegate's size hint has it: the full width less the widest line)."""
        metrics = self.fontMetrics()
        lines = [line for text in self._texts(c) for line in text.split("\n")]
        if not lines:
            return self._full_width(c)
        pad = self.sizeHintForColumn(c) - max(metrics.horizontalAdvance(x) for x in lines)
        word = max(metrics.horizontalAdvance(w) for x in lines for w in x.split())
        return max(word + pad, self._header_need(c))

    def _longest_word(self, c):
        """The column's longest word with a cell's margins (the size hint of a column with
        group lines spanning it is theirs, not its cells')."""
        metrics = self.fontMetrics()
        words = [w for text in self._texts(c) for w in text.split()]
        margin = 2 * self.style().pixelMetric(QtGui.QStyle.PM_FocusFrameHMargin, None, self) + 6
        return max([metrics.horizontalAdvance(w) for w in words] + [0]) + margin

    def share_width(self):
        header = self.horizontalHeader()
        if self._sharing or (header.sectionResizeMode(self.name_column) !=
                             QtGui.QHeaderView.Stretch and not self._narrowed):
            return
        self._sharing = True
        try:
            item = self.horizontalHeaderItem(self.name_column)
            if self._name_label is None and item is not None:
                self._name_label = item.text()
            need = self._header_need(self.name_column, self._name_label)
            spare = self.viewport().width() - sum(self._full_width(c)
                                                  for c in range(self.columnCount())
                                                  if c != self.name_column)
            for c in self.wrap_columns:
                if spare >= need:
                    header.setSectionResizeMode(c, QtGui.QHeaderView.ResizeToContents)
                    continue
                narrow = self._word_width(c)
                header.setSectionResizeMode(c, QtGui.QHeaderView.Fixed)
                header.resizeSection(c, narrow)
                spare += self._full_width(c) - narrow
            if spare < NARROWEST_NAME_SHARE * need:
                # a header broken that short no longer reads as its word (FreeCAD's default
                # Combo View, about 300 px): the names' column keeps its header and longest
                # word whole, the table scrolls sideways
                header.setSectionResizeMode(self.name_column, QtGui.QHeaderView.Fixed)
                header.resizeSection(self.name_column, max(need, self._longest_word(
                    self.name_column)))
                self._narrowed = True
                self._break_name_header(need)
            else:
                if self._narrowed:
                    header.setSectionResizeMode(self.name_column, QtGui.QHeaderView.Stretch)
                    self._narrowed = False
                self._break_name_header(spare)
            # the wrapped cells' rows as tall as their lines
            for r in range(self.rowCount()):
                if self.columnSpan(r, 0) == 1:
                    self.resizeRowToContents(r)
        finally:
            self._sharing = False


def fit_columns(table, stretch_column=NAME_COLUMN):
    """Every column as wide as its contents but ``stretch_column``, which takes what is left
    of the panel's width, its names wrapped over two lines when the panel is narrow (the rows
    as tall as they need); no row numbers (the rows are named)."""
    rows = table.verticalHeader()
    rows.setVisible(False)
    for r in range(table.rowCount()):
        # a group line keeps one line's height, not the wrapped height of the first column
        if table.columnSpan(r, 0) == 1:
            rows.setSectionResizeMode(r, QtGui.QHeaderView.ResizeToContents)
    table.setWordWrap(True)
    table.setTextElideMode(QtCore.Qt.ElideRight)
    header = table.horizontalHeader()
    for c in range(table.columnCount()):
        header.setSectionResizeMode(c, QtGui.QHeaderView.Stretch if c == stretch_column
                                    else QtGui.QHeaderView.ResizeToContents)
    table.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
    return table


def _number(value, signed=False):
    if value is None:
        return ""
    return ("%+.4f" if signed else "%.4f") % value


def tolerance_text(lower, upper):
    """A tolerance zone on the deviation as a narrow column shows it: ±T, the upper limit
    over the lower, or one-sided."""
    if lower is None and upper is None:
        return ""
    if lower is not None and upper is not None:
        if abs(lower + upper) <= 1e-12 * max(abs(lower), abs(upper), 1.0):
            return "\u00b1%g" % upper
        return "%+g\n%+g" % (upper, lower)
    return ("\u2264 %+g" % upper) if lower is None else ("\u2265 %+g" % lower)


# ---------------------------------------------------------------- airfoil characteristics

def airfoil_rows(blocks):
    """The characteristics table's rows (the blocks' sections named as named_by_height
    names them): per section a group line ``[text, verdict]``, then
    per characteristic [key, name, unit, nominal, actual ("not measured" when withheld),
    deviation, U (k = 2; the decision's, else 2u of the block's standard uncertainty),
    tolerance, verdict, the reason a value is withheld or None] (from
    inspection.airfoil_stage.csv_rows, by its column names)."""
    by_label = {b["label"]: b for b in blocks}
    rows, shown = [], None
    for row in airfoil_mod.csv_rows(blocks):
        r = dict(zip(airfoil_mod.CSV_HEADER, row))
        block = by_label[r["section"]]
        if r["section"] != shown:
            shown = r["section"]
            line = tr("Section %s: %s") % (shown, tr(block.get("verdict") or ""))
            if block.get("summary"):    # what is not measured and why, in one line
                line += " \u2014 " + plus_minus(block["summary"])
            rows.append([line, block.get("verdict")])
        u = r["uncertainty"]
        expanded = r.get("U_k2") if r.get("U_k2") is not None else (
            None if u is None else 2.0 * u)
        key = r["characteristic"]
        # a value withheld (null) says so where the number would be, its reason in the tooltip
        reason = (block.get("withheld") or {}).get(key.split("[")[0]) \
            if r["measured"] is None else None
        rows.append([key, names.display_name(key, block["nominal"], tr),
                     names.unit(key, tr), _number(r["nominal"]),
                     tr(NOT_MEASURED) if reason else _number(r["measured"]),
                     _number(r["deviation"], True), _number(expanded),
                     tolerance_text(r["lower"], r["upper"]), r["verdict"], reason])
    return rows


def airfoil_table(rows):
    """The table of airfoil_rows (group lines spanning it)."""
    table = NamedRowsTable(len(rows), len(AIRFOIL_COLUMNS))
    table.wrap_columns = (1, VERDICT_COLUMN)   # unit, then verdict ("not / judged")
    _header(table, AIRFOIL_COLUMNS)
    for r, row in enumerate(rows):
        if len(row) == 2:
            _group_row(table, r, *row)
            continue
        key, name, unit = row[:3]
        reason = plus_minus(row[9]) if row[9] else None
        table.setItem(r, 0, _item(name, "%s\n%s" % (name, names.meaning(key, tr))))
        table.setItem(r, 1, _item(unit))
        for c, text in enumerate(row[3:8], 2):
            table.setItem(r, c, _item(text, tip=reason if c == 3 else None, align=NUMBER))
        verdict = verdict_item(row[8])
        if reason:
            verdict.setToolTip(reason)
        table.setItem(r, VERDICT_COLUMN, verdict)
    return fit_columns(table)


# ---------------------------------------------------------------- fit sensitivity

def _objective_label(objective):
    # "least-squares" over two lines: the objectives' columns stay as narrow as their numbers
    return objective.replace("-", "-\n", 1)


def sensitivity_groups(sensitivity):
    """The fit_sensitivity rows grouped by section (in the order the sections first appear),
    the part's last: [(label or None for the part, [row, ...])]."""
    groups = {}
    for row in sensitivity["rows"]:
        label, _ = names.sensitivity_row_parts(row)
        groups.setdefault(label, []).append(row)
    part = groups.pop(None, [])
    return list(groups.items()) + [(None, part)]


def sensitivity_table(sensitivity):
    """Each characteristic under each fit objective: its value (the deviation) in a cell
    coloured by that objective's verdict, the verdict and U in the tooltip; the part's verdict
    per objective last."""
    objectives = sensitivity["objectives"]
    definitions = sensitivity.get("airfoil_definitions")
    columns = list(SENSITIVITY_LEADING) + [
        (_objective_label(o), QT_TRANSLATE_NOOP(
            "BladeInspect", "Value under this fit objective; the cell's colour is its "
                            "verdict (tooltip)")) for o in objectives] + [SENSITIVITY_CHANGE]
    groups = sensitivity_groups(sensitivity)
    # a line per section only when it heads several rows (the airfoil characteristics')
    grouped = any(len(rows) > 1 for label, rows in groups if label is not None)
    n_rows = sum(grouped + len(rows) for _, rows in groups) + 1
    table = NamedRowsTable(n_rows, len(columns))
    table.wrap_columns = (1,)   # the unit
    _header(table, columns)
    r = 0
    for label, rows in groups:
        if grouped:
            _group_row(table, r, tr(names.PART) if label is None else tr(names.SECTION) % label)
            r += 1
        for row in rows:
            _, key = names.sensitivity_row_parts(row)
            name = (tr(names.WORST_DEVIATION) if key is None else names.display_name(
                key, definitions, tr)) if grouped else names.sensitivity_row_name(
                row, tr, definitions)
            unit = names.unit(key, tr) if key else "mm"
            table.setItem(r, 0, _item(name, "%s\n%s" % (
                name, names.meaning(key, tr) if key else row["characteristic"])))
            table.setItem(r, 1, _item(unit))
            for c, objective in enumerate(objectives, 2):
                cell = row["by_fit"][objective]
                value = cell.get("value_mm", cell.get("value"))
                U = cell.get("U_mm", cell.get("U"))
                tip = "%s: %s" % (objective, tr(cell.get("verdict") or ""))
                if U is not None:
                    tip += ", U = %.4f %s" % (U, unit)
                table.setItem(r, c, colour_verdict(
                    _item(_number(value, True), tip, NUMBER), cell.get("verdict")))
            side = bool(row.get("side_changes"))
            table.setItem(r, len(columns) - 1, _item(
                "%.4f%s" % (row.get("change_mm", row.get("change")), SIDE_MARK if side else ""),
                tr(SIDE_NOTE) if side else None, NUMBER))
            r += 1
    table.setItem(r, 0, _item(tr(names.PART_VERDICT)))
    for c, objective in enumerate(objectives, 2):
        table.setItem(r, c, verdict_item(sensitivity["verdict_by_fit"][objective]))
    return fit_columns(table)


def largest_change_name(sensitivity):
    """The largest change's characteristic by its display name."""
    return names.sensitivity_row_name(sensitivity["largest_change"], tr,
                                      sensitivity.get("airfoil_definitions"))


# ---------------------------------------------------------------- Table 2

def section_table(header, rows):
    """Table 2 (inspection.report.section_rows): short headers over two lines with their
    meaning as tooltip; the columns share the panel's width, none narrower than the widest
    cell. With the CMM's columns beside the optical ones it is wider than a 640 px panel and
    scrolls sideways."""
    table = QtGui.QTableWidget(len(rows), len(header))
    _header(table, [names.section_column(h, tr) for h in header], _same)
    for r, row in enumerate(rows):
        for c, cell in enumerate(row):
            table.setItem(r, c, _item(str(cell), align=None if c == 0 else NUMBER))
    table.verticalHeader().setVisible(False)
    table.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
    header_view = table.horizontalHeader()
    if any(h.startswith("CMM ") for h in header):
        # twice the columns: wider than a task panel, each as wide as its header and cells
        header_view.setSectionResizeMode(QtGui.QHeaderView.ResizeToContents)
        return table
    # the cells' widest (headers wrap; a cell's number must not be elided)
    header_view.setMinimumSectionSize(max([table.sizeHintForColumn(c)
                                           for c in range(table.columnCount())] + [1]))
    header_view.setSectionResizeMode(QtGui.QHeaderView.Stretch)
    return table


# ---------------------------------------------------------------- the verdict first

# The part's verdict as a user reads it first: the word, in strong colours (white text).
VERDICT_WORDS = {"pass": QT_TRANSLATE_NOOP("BladeInspect", "PASS"),
                 "not proven": QT_TRANSLATE_NOOP("BladeInspect", "NOT PROVEN"),
                 "fail": QT_TRANSLATE_NOOP("BladeInspect", "FAIL"),
                 None: QT_TRANSLATE_NOOP("BladeInspect", "NOT JUDGED")}
BANNER_COLOURS = {"pass": "#2e7d32", "not proven": "#e65100", "fail": "#c62828",
                  None: "#616161"}
# The verdict's word this many times the body's font size
BANNER_SCALE = 1.8


def plus_minus(text):
    """A text for the screen: ASCII "+-" (result.json's summaries) as "±"."""
    return text.replace("+-", "\u00b1")


def part_verdict(verdict):
    """pass, not proven, fail (core.decision) of a verdict dict (inspection.verdict.judge's,
    or a fit-sensitivity cell's), None when nothing was judged; "pass" only when the
    verdict's own pass flag agrees (a not proven is never rounded to pass)."""
    if not verdict:
        return None
    key = verdict.get("verdict")
    if key is None and verdict.get("pass") is not None:
        key = "pass" if verdict["pass"] else "fail"
    if key == "pass" and verdict.get("pass") is False:
        key = "fail"
    return key


def verdict_banner(key, details=""):
    """The verdict first: a label with the word (PASS, NOT PROVEN, FAIL) large and white on
    its colour, and under it ``details`` (what was judged against what; the tolerance, the
    rule) in the body's size, wrapped. Returns (banner, details label or None)."""
    banner = QtGui.QLabel(tr(VERDICT_WORDS.get(key, VERDICT_WORDS[None])))
    font = banner.font()
    font.setBold(True)
    font.setPointSizeF(font.pointSizeF() * BANNER_SCALE)
    banner.setFont(font)
    banner.setAlignment(QtCore.Qt.AlignCenter)
    banner.setStyleSheet("QLabel { color: white; background-color: %s; padding: 4px; }"
                         % BANNER_COLOURS.get(key, BANNER_COLOURS[None]))
    banner.setWordWrap(True)
    banner.verdict = key
    label = None
    if details:
        label = QtGui.QLabel(plus_minus(details))
        label.setWordWrap(True)
    return banner, label


def add_verdict(layout, key, details=""):
    """verdict_banner's labels on top of ``layout``; the banner (its details as .details)."""
    banner, label = verdict_banner(key, details)
    layout.insertWidget(0, banner)
    if label is not None:
        layout.insertWidget(1, label)
    banner.details = label
    return banner


def section_name(height_pct):
    """A section by its nominal height, as every panel names it: "50 %" (of the span)."""
    return "%g %%" % round(float(height_pct), 1)


SECTION_VERDICT_COLUMNS = (
    (QT_TRANSLATE_NOOP("BladeInspect", "Section\n% span"),
     QT_TRANSLATE_NOOP("BladeInspect", "The section by its nominal height, % of the span from "
                                       "hub to tip")),
    (QT_TRANSLATE_NOOP("BladeInspect", "Verdict"),
     QT_TRANSLATE_NOOP("BladeInspect", "The section's worst deviation judged against the "
                                       "tolerance with its U: pass, not proven, fail")),
    (QT_TRANSLATE_NOOP("BladeInspect", "\u00b1U\nmm"),
     QT_TRANSLATE_NOOP("BladeInspect", "Expanded uncertainty U (k = 2) of the worst "
                                       "deviation, mm")),
    (QT_TRANSLATE_NOOP("BladeInspect", "TUR"),
     QT_TRANSLATE_NOOP("BladeInspect", "Test uncertainty ratio: tolerance / U")),
)


def section_verdict_rows(header, rows, verdict):
    """Table 2 (inspection.report.section_rows' header and rows) with each section's verdict
    first: [(label, tip)] columns and rows of [name, verdict, U, TUR, then the table's
    own columns after its label and height]; the verdict's sections matched by label."""
    by_label = {s["label"]: s for s in verdict.get("sections", [])}
    span = header.index("Span %")
    columns = [(tr(label), tr(tip)) for label, tip in SECTION_VERDICT_COLUMNS] + [
        names.section_column(h, tr) for k, h in enumerate(header) if k not in (0, span)]
    out = []
    for row in rows:
        entry = by_label.get(row[0], {})
        key = entry.get("verdict")
        if key is None and entry.get("pass") is not None:
            key = "pass" if entry["pass"] else "fail"
        tur = entry.get("tur")
        out.append([section_name(float(row[span])), key or "", _number(entry.get("U_mm")),
                    "" if tur is None else "%.1f" % tur]
                   + [cell for k, cell in enumerate(row) if k not in (0, span)])
    return columns, out


def section_verdict_table(header, rows, verdict):
    """Table 2 with the verdict, U and TUR of each section first (the
    section named by its height, its verdict coloured). Every column as wide as its header
    and cells (headers over two lines), the names' column too: a narrow panel (FreeCAD's
    default Combo View, about 300 px) scrolls sideways rather than cutting a number or a
    word."""
    columns, out = section_verdict_rows(header, rows, verdict)
    table = QtGui.QTableWidget(len(out), len(columns))
    _header(table, columns, _same)
    for r, row in enumerate(out):
        table.setItem(r, 0, _item(row[0]))
        table.setItem(r, 1, verdict_item(row[1]))
        for c, cell in enumerate(row[2:], 2):
            table.setItem(r, c, _item(str(cell), align=NUMBER))
    table.verticalHeader().setVisible(False)
    table.setEditTriggers(QtGui.QAbstractItemView.NoEditTriggers)
    table.setWordWrap(False)
    table.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarAsNeeded)
    table.horizontalHeader().setSectionResizeMode(QtGui.QHeaderView.ResizeToContents)
    return table


def _renamed_entry(entry, rename):
    # an airfoil_verdict entry "section 2: chord_mm" under its section's new name
    if not entry.startswith("section ") or ": " not in entry:
        return entry
    label, _, key = entry[len("section "):].rpartition(": ")
    return "section %s: %s" % (rename.get(label, label), key)


def named_by_height(analysis):
    """A copy of an airfoil analysis (result.json's airfoil fields) whose sections are named
    by their nominal heights (section_name), in its blocks, its verdict's entries and its
    lean and bow, as Table 2 names them."""
    blocks = analysis.get("airfoil", [])
    rename = {str(b["label"]): section_name(b["height_pct"]) for b in blocks
              if b.get("height_pct") is not None}
    out = dict(analysis, airfoil=[dict(b, label=rename.get(str(b["label"]), b["label"]))
                                  for b in blocks])
    verdict = analysis.get("airfoil_verdict")
    if verdict:
        out["airfoil_verdict"] = dict(verdict, **{
            k: [_renamed_entry(e, rename) for e in verdict[k]]
            for k in ("failed", "not_proven") if verdict.get(k)})
    lean_bow = analysis.get("lean_bow")
    if lean_bow and "largest_bow_section" in lean_bow:
        out["lean_bow"] = dict(lean_bow, largest_bow_section=rename.get(
            str(lean_bow["largest_bow_section"]), lean_bow["largest_bow_section"]))
    return out


def _renamed_row(row, rename):
    label, key = names.sensitivity_row_parts(row)
    if label is None or label not in rename:
        return row
    what = key if key is not None else "worst deviation"
    return dict(row, characteristic="section %s %s" % (rename[label], what))


def sensitivity_named(sensitivity, rename):
    """A copy of a fit_sensitivity block whose section rows name their sections by
    ``rename`` ({label: section_name}), as Table 2 names them."""
    if not rename:
        return sensitivity
    out = dict(sensitivity, rows=[_renamed_row(r, rename) for r in sensitivity["rows"]])
    if sensitivity.get("largest_change"):
        out["largest_change"] = _renamed_row(sensitivity["largest_change"], rename)
    return out


def breakable_paths(text):
    """``text`` with a zero-width space after each "/" of an absolute path (a word that
    starts with "/"), so that a wrapped label breaks a long folder's path at its separators
    instead of widening the panel to hold it."""
    return re.sub(r"(?<!\S)/\S+", lambda m: m.group(0).replace("/", "/\u200b"), text)
