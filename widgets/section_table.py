"""Exact numbers for a section: one table row per segment (QAbstractTableModel).

Design rule: the model mirrors a ``Section`` value and never edits it. ``setData`` turns a
typed value into a *proposed* section (via :mod:`engine.geometry.editing`: a typed end point
is placed exactly with the smooth joints solved as a drag solves them, and the finish kept) and
emits it; the owner validates and applies it, and ``set_section`` then shows the result. A
refused or impossible value leaves the table showing the model's numbers. Cells show the
designer's words (:mod:`widgets.words`) and millimetres to 0.01 mm (the tooltip has 0.0001 mm);
the view widens a column whenever a value would not fit, so no number is ever cut off.
"""
from __future__ import annotations

from PySide6.QtCore import QAbstractTableModel, QModelIndex, Qt, Signal
from PySide6.QtWidgets import (QAbstractItemView, QComboBox, QDoubleSpinBox, QHeaderView,
                               QStyledItemDelegate, QTableView)

from engine.geometry import editing as edits
from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc
from widgets import words

COLUMNS = ("type", "end r", "end z", "centre r", "centre z", "radius / r", "radius z", "dir", "smooth")
HEADERS = ("Type", "End r", "End z", "Centre r", "Centre z", "Radius", "Radius z", "Bulge",
           "Smooth → next")
HEADER_TIPS = (
    "Line, arc or ellipse arc (the base segment stays what it is)",
    "Radius (mm from the axis) where the segment ends; typed values keep smooth joints tangent",
    "Height (mm above the standing plane) where the segment ends",
    "Radius (mm) of the arc's or ellipse's centre",
    "Height (mm) of the arc's or ellipse's centre",
    "Arc radius, or the ellipse's radius along r (mm)",
    "The ellipse's radius along z (mm)",
    "Convex (bulges outwards) or concave (curves inwards)",
    "Tangent (smooth) where this segment meets the next one, the segment in the row below",
)
KINDS = ("line", "arc", "ellipse_arc")
#: Widest number a column must show without cutting it.
WIDEST_NUMBER = "-99999.99"


def _cell(seg, column: int):
    """The value shown in ``column`` for ``seg`` (``None``: not applicable)."""
    if column == 0:
        return seg.kind
    if column in (1, 2):
        return seg.p1[column - 1]
    if isinstance(seg, (Arc, EllipseArc)):
        if column in (3, 4):
            return seg.center[column - 3]
        if column == 5:
            return seg.radius if isinstance(seg, Arc) else seg.radius_r
        if column == 6:
            return seg.radius_z if isinstance(seg, EllipseArc) else None
        if column == 7:
            return seg.direction
    return None


class SectionTableModel(QAbstractTableModel):
    """Table of segments; editable end point, radii, kind and smoothness.

    Signals
    -------
    sectionProposed(object, str, str)
        ``(new Section, undo label, merge key)`` after a typed edit.
    problem(str)
        A typed value that cannot be turned into geometry, with the reason.
    """

    sectionProposed = Signal(object, str, str)
    problem = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.section: Section | None = None

    def set_section(self, section: Section):
        """Show ``section``: a reset when the number of segments changed, else one
        ``dataChanged`` (cheap while a drag edits the values 60 times a second)."""
        if self.section is not None and len(self.section.segments) == len(section.segments):
            self.section = section
            self.dataChanged.emit(self.index(0, 0), self.index(len(section.segments) - 1, len(COLUMNS) - 1))
            return
        self.beginResetModel()
        self.section = section
        self.endResetModel()

    def rowCount(self, parent=QModelIndex()):
        return 0 if parent.isValid() or self.section is None else len(self.section.segments)

    def columnCount(self, parent=QModelIndex()):
        return 0 if parent.isValid() else len(COLUMNS)

    def headerData(self, section, orientation, role=Qt.DisplayRole):
        if orientation != Qt.Horizontal:
            if role == Qt.DisplayRole:
                return str(section)
            return f"Segment {section}" if role == Qt.ToolTipRole else None
        if role == Qt.DisplayRole:
            return HEADERS[section]
        return HEADER_TIPS[section] if role == Qt.ToolTipRole else None

    def flags(self, index):
        if not index.isValid():
            return Qt.NoItemFlags
        base = Qt.ItemIsEnabled | Qt.ItemIsSelectable
        seg = self.section.segments[index.row()]
        col = index.column()
        if col == 8:
            return base | Qt.ItemIsUserCheckable if index.row() < len(self.section.segments) - 1 else base
        if col == 0 and index.row() > 0:
            return base | Qt.ItemIsEditable
        if col in (1, 2) or (col == 5 and isinstance(seg, (Arc, EllipseArc))) or \
                (col == 6 and isinstance(seg, EllipseArc)):
            return base | Qt.ItemIsEditable
        return base

    def data(self, index, role=Qt.DisplayRole):
        if not index.isValid() or self.section is None:
            return None
        seg = self.section.segments[index.row()]
        col = index.column()
        if col == 8:
            if role == Qt.CheckStateRole and index.row() < len(self.section.smooth):
                return Qt.Checked if self.section.smooth[index.row()] else Qt.Unchecked
            return None
        value = _cell(seg, col)
        if role == Qt.DisplayRole:
            if value is None:
                return ""
            if isinstance(value, float):
                return f"{value:.2f}"
            return words.word(words.SEGMENT_KINDS if col == 0 else words.DIRECTIONS, value)
        if role == Qt.ToolTipRole:
            if isinstance(value, float):
                return f"{HEADERS[col]} of segment {index.row()}: {value:.4f} mm"
            table = words.SEGMENT_KINDS if col == 0 else words.DIRECTIONS
            return table.get(value, ("", ""))[1] if value is not None else None
        if role == Qt.EditRole:
            return value
        if role == Qt.TextAlignmentRole and isinstance(value, float):
            return int(Qt.AlignRight | Qt.AlignVCenter)
        return None

    def propose(self, row: int, column: int, value) -> Section:
        """The section after typing ``value`` into ``(row, column)``; may raise ``ValueError``."""
        sec = self.section
        seg = sec.segments[row]
        if column == 0:
            if value not in KINDS:
                raise ValueError("a segment is a line, an arc or an ellipse arc")
            return edits.convert_segment(sec, row, value)
        if column == 8:
            return edits.set_smooth(sec, row, bool(value))
        number = float(value)
        if column == 1:
            return edits.place_joint(sec, row, r=number)
        if column == 2:
            return edits.place_joint(sec, row, z=number)
        if column == 5 and isinstance(seg, Arc):
            return edits.set_arc_radius(sec, row, number)
        if column == 5:
            return edits.set_ellipse_radii(sec, row, number, seg.radius_z)
        if column == 6:
            return edits.set_ellipse_radii(sec, row, seg.radius_r, number)
        raise ValueError(f"column {COLUMNS[column]!r} cannot be edited")

    def setData(self, index, value, role=Qt.EditRole):
        if not index.isValid() or self.section is None:
            return False
        col = index.column()
        if role == Qt.CheckStateRole and col == 8:
            value = value in (Qt.Checked, Qt.Checked.value, 2, True)
        elif role != Qt.EditRole:
            return False
        try:
            proposal = self.propose(index.row(), col, value)
        except (ValueError, TypeError) as exc:
            self.problem.emit(f"segment {index.row()}: {exc}")
            return False
        self.sectionProposed.emit(proposal, f"Edit {HEADERS[col].lower()} of segment {index.row()}", "")
        return True


class KindDelegate(QStyledItemDelegate):
    """Edits the ``type`` column with a list of the segment kinds instead of free text."""

    def createEditor(self, parent, option, index):
        combo = QComboBox(parent)
        words.fill_combo(combo, words.SEGMENT_KINDS, KINDS)
        return combo

    def setEditorData(self, editor, index):
        words.select_key(editor, str(index.data(Qt.EditRole)))

    def setModelData(self, editor, model, index):
        model.setData(index, editor.currentData(), Qt.EditRole)


class MillimetreDelegate(QStyledItemDelegate):
    """Edits a length with 4 decimals over a bottle-sized range (Qt's default spin box stops at
    99.99, which no bottle height respects)."""

    def createEditor(self, parent, option, index):
        spin = QDoubleSpinBox(parent)
        spin.setRange(-100000.0, 100000.0)
        spin.setDecimals(4)
        spin.setSuffix(" mm")
        return spin

    def setEditorData(self, editor, index):
        value = index.data(Qt.EditRole)
        editor.setValue(float(value) if value is not None else 0.0)

    def setModelData(self, editor, model, index):
        editor.interpretText()
        model.setData(index, editor.value(), Qt.EditRole)


class SectionTable(QTableView):
    """The table of a :class:`SectionTableModel`: kind and millimetre editors, and columns that
    widen so that every value shows in full (checked on every change; it never shrinks during a
    drag, so the columns do not jump)."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setModel(SectionTableModel(self))
        self.setItemDelegateForColumn(0, KindDelegate(self))
        self._mm_delegate = MillimetreDelegate(self)
        for column in range(1, 7):
            self.setItemDelegateForColumn(column, self._mm_delegate)
        self.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.setToolTip("Exact numbers of the section's segments; double-click a value to type it")
        header = self.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.Interactive)
        self.model().modelReset.connect(self.fit_columns)
        self.model().dataChanged.connect(lambda *_: self.fit_columns(grow_only=True))

    def needed_width(self, column: int) -> int:
        """Pixels ``column`` needs for its header and its widest value (and a plausible one)."""
        fm = self.fontMetrics()
        model = self.model()
        texts = [model.headerData(column, Qt.Horizontal)]
        texts += [model.data(model.index(row, column)) or "" for row in range(model.rowCount())]
        if 1 <= column <= 6:
            texts.append(WIDEST_NUMBER)
        pad = 2 * self.style().pixelMetric(self.style().PixelMetric.PM_FocusFrameHMargin) + 16
        if column == 8:
            pad += 24  # the check box
        return max(fm.horizontalAdvance(str(t)) for t in texts) + pad

    def fit_columns(self, grow_only: bool = False):
        header = self.horizontalHeader()
        for column in range(self.model().columnCount()):
            need = self.needed_width(column)
            if not grow_only or header.sectionSize(column) < need:
                header.resizeSection(column, need)
