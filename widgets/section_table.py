"""Exact numbers for a section: one table row per segment (QAbstractTableModel).

Design rule: the model mirrors a ``Section`` value and never edits it. ``setData`` turns a
typed value into a *proposed* section (via :mod:`engine.geometry.editing`) and emits it; the owner
validates and applies it, and ``set_section`` then shows the result. A refused or impossible
value leaves the table showing the model's numbers.
"""
from __future__ import annotations

from PySide6.QtCore import QAbstractTableModel, QModelIndex, Qt, Signal
from PySide6.QtWidgets import QComboBox, QDoubleSpinBox, QStyledItemDelegate

from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc
from engine.geometry import editing as edits

COLUMNS = ("type", "end r", "end z", "centre r", "centre z", "radius / r", "radius z", "dir", "smooth")
KINDS = ("line", "arc", "ellipse_arc")


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
        if role != Qt.DisplayRole:
            return None
        return COLUMNS[section] if orientation == Qt.Horizontal else str(section)

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
            return "" if value is None else (f"{value:.4f}" if isinstance(value, float) else value)
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
                raise ValueError(f"segment type must be one of {', '.join(KINDS)}")
            return edits.convert_segment(sec, row, value)
        if column == 8:
            return edits.set_smooth(sec, row, bool(value))
        number = float(value)
        if column in (1, 2):
            target = list(seg.p1)
            target[column - 1] = number
            delta = (target[0] - seg.p1[0], target[1] - seg.p1[1])
            return edits.move_joint(sec, row, delta, "exact")
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
        self.sectionProposed.emit(proposal, f"Edit {COLUMNS[col]} of segment {index.row()}", "")
        return True


class KindDelegate(QStyledItemDelegate):
    """Edits the ``type`` column with a list of the segment kinds instead of free text."""

    def createEditor(self, parent, option, index):
        combo = QComboBox(parent)
        combo.addItems(list(KINDS))
        return combo

    def setEditorData(self, editor, index):
        editor.setCurrentText(str(index.data(Qt.EditRole)))

    def setModelData(self, editor, model, index):
        model.setData(index, editor.currentText(), Qt.EditRole)


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
