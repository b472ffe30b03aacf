"""Exact numbers of a plan outline: one table row per segment, in mm at the widest core.

Design rule: as the section table, the model mirrors a ``PlanOutline`` value and never edits it.
It shows ``k P`` (the outline times the widest core's scale ``k``, mm; the body adds the
rounding ``c`` around it). ``setData`` turns a typed number into a *proposed* outline through
:mod:`engine.geometry.editing.plan_tools` (a joint placed exactly, an arc's centre coordinate
placed exactly on its ends' bisector, an arc's radius) with the panel's symmetry, and emits it;
a value the engine refuses emits ``problem`` with its reason and the table keeps the model's
numbers.
"""
from __future__ import annotations

from PySide6.QtCore import QAbstractTableModel, QModelIndex, Qt, Signal
from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QTableView

from engine.errors import OutlineError
from engine.geometry.editing import plan_tools as pt
from widgets import words
from widgets.section_table import MillimetreDelegate

COLUMNS = ("type", "p0 x", "p0 y", "p1 x", "p1 y", "centre x", "centre y", "radius")
HEADERS = ("Type", "Start x", "Start y", "End x", "End y", "Centre x", "Centre y", "Radius")
HEADER_TIPS = (
    "Line or arc (counter-clockwise: the outline is convex)",
    "x (mm) where the segment starts, at the widest core; typed values move the joint exactly",
    "y (mm) where the segment starts",
    "x (mm) where the segment ends (the next segment's start)",
    "y (mm) where the segment ends",
    "x (mm) of the arc's centre; typed values keep its ends (the centre slides on their bisector)",
    "y (mm) of the arc's centre",
    "The arc's radius (mm) in the core outline; the body's corner adds the rounding c",
)


def _cell(seg, column: int, k: float):
    """The value (mm) or word key shown in ``column`` of ``seg`` (``None``: not applicable)."""
    if column == 0:
        return seg.kind
    if column <= 4:
        return (seg.p0, seg.p1)[(column - 1) // 2][(column - 1) % 2] * k
    if seg.kind != "arc":
        return None
    return seg.center[column - 5] * k if column < 7 else seg.radius * k


class PlanTableModel(QAbstractTableModel):
    """Table of a plan's segments; typed joints, centres and radii become proposed outlines.

    Signals
    -------
    planProposed(object, str, str)
        ``(new PlanOutline, undo label, merge key)`` after a typed edit.
    problem(str)
        A typed value the engine refused, with the reason.
    """

    planProposed = Signal(object, str, str)
    problem = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.plan = None
        self.k = 1.0
        self.symmetry = (1, False)

    def set_plan(self, plan, k: float):
        """Show ``plan`` at core scale ``k`` (mm); ``None``: no rows."""
        if plan is not None and self.plan is not None and len(plan.segments) == len(self.plan.segments):
            self.plan, self.k = plan, k
            self.dataChanged.emit(self.index(0, 0), self.index(len(plan.segments) - 1, len(COLUMNS) - 1))
            return
        self.beginResetModel()
        self.plan, self.k = plan, k
        self.endResetModel()

    def rowCount(self, parent=QModelIndex()):
        return 0 if parent.isValid() or self.plan is None else len(self.plan.segments)

    def columnCount(self, parent=QModelIndex()):
        return 0 if parent.isValid() else len(COLUMNS)

    def headerData(self, section, orientation, role=Qt.DisplayRole):
        if orientation != Qt.Horizontal:
            return str(section) if role == Qt.DisplayRole else None
        if role == Qt.DisplayRole:
            return HEADERS[section]
        return HEADER_TIPS[section] if role == Qt.ToolTipRole else None

    def flags(self, index):
        if not index.isValid():
            return Qt.NoItemFlags
        base = Qt.ItemIsEnabled | Qt.ItemIsSelectable
        if index.column() > 0 and _cell(self.plan.segments[index.row()], index.column(), self.k) is not None:
            return base | Qt.ItemIsEditable
        return base

    def data(self, index, role=Qt.DisplayRole):
        if not index.isValid() or self.plan is None:
            return None
        value = _cell(self.plan.segments[index.row()], index.column(), self.k)
        if role == Qt.DisplayRole:
            if value is None:
                return ""
            return words.word(words.SEGMENT_KINDS, value) if index.column() == 0 else f"{value:.2f}"
        if role == Qt.ToolTipRole and isinstance(value, float):
            return f"{HEADERS[index.column()]} of segment {index.row()}: {value:.4f} mm"
        if role == Qt.EditRole:
            return value
        if role == Qt.TextAlignmentRole and isinstance(value, float):
            return int(Qt.AlignRight | Qt.AlignVCenter)
        return None

    def propose(self, row: int, column: int, value: float):
        """The outline after typing ``value`` (mm) into ``(row, column)``; may raise ``OutlineError``."""
        plan, k, (n, mirror) = self.plan, self.k, self.symmetry
        v = float(value) / k
        if column <= 4:
            joint = (row + (column - 1) // 2) % len(plan.segments)
            p = list(plan.segments[joint].p0)
            p[(column - 1) % 2] = v
            return pt.move_joint(plan, joint, p, n, mirror, exact=True)
        if column < 7:
            return pt.place_arc_centre(plan, row, column - 5, v, n, mirror)
        return pt.set_arc_radius(plan, row, v, n, mirror)

    def setData(self, index, value, role=Qt.EditRole):
        if not index.isValid() or self.plan is None or role != Qt.EditRole or index.column() == 0:
            return False
        try:
            proposal = self.propose(index.row(), index.column(), value)
        except (OutlineError, ValueError, TypeError) as exc:
            self.problem.emit(str(exc) if isinstance(exc, OutlineError) else f"segment {index.row()}: {exc}")
            return False
        self.planProposed.emit(proposal, f"Edit plan {HEADERS[index.column()].lower()} of segment {index.row()}", "")
        return True


class PlanTable(QTableView):
    """The view of a :class:`PlanTableModel` with millimetre editors."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setModel(PlanTableModel(self))
        self._mm_delegate = MillimetreDelegate(self)
        for column in range(1, len(COLUMNS)):
            self.setItemDelegateForColumn(column, self._mm_delegate)
        self.setSelectionBehavior(QAbstractItemView.SelectRows)
        self.setToolTip("Exact numbers of the plan's segments at the widest core (mm); double-click "
                        "a value to type it")
        self.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeToContents)
