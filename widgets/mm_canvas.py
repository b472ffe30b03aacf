"""A canvas at true scale in millimetres: mapping, zoom, pan, selection and handle picking.

Design rule: what the section canvas and the plan canvas share and nothing of what they draw.
``origin`` is the pixel position of the model's (0, 0), ``scale`` pixels per mm, the model's
second axis up. Middle- or right-drag pans, the wheel zooms about the cursor; a subclass lists
its draggable points (``handles()``: :class:`engine.geometry.editing.Handle` in mm, the ones
that should win ties first), answers a left press (``left_pressed``) and keeps ``_drag`` while
a handle is dragged.
"""
from __future__ import annotations

import math

from PySide6.QtCore import QPointF, Qt, Signal
from PySide6.QtWidgets import QWidget

#: How near (px) the pointer must be to grab a handle.
HANDLE_PX = 7.0


class MillimetreCanvas(QWidget):
    """Base of the editors' canvases (see the module docstring).

    Signals
    -------
    selectionChanged(int)
        Index of the selected segment (-1: none).
    dragging(bool)
        A handle drag started (True) or ended (False): slow consumers may pause meanwhile.
    """

    selectionChanged = Signal(int)
    dragging = Signal(bool)

    def __init__(self, scale: float, origin: QPointF, parent=None):
        super().__init__(parent)
        self.scale = scale
        self.origin = origin
        self.selected = -1
        self._drag = None
        self._pan_from = None

    def handles(self) -> list:
        return []

    def select(self, index: int):
        if index != self.selected:
            self.selected = index
            self.selectionChanged.emit(index)
            self.update()

    # ----------------------------------------------------------------------- mapping
    def to_px(self, p) -> QPointF:
        return QPointF(self.origin.x() + p[0] * self.scale, self.origin.y() - p[1] * self.scale)

    def to_mm(self, q: QPointF) -> tuple[float, float]:
        return ((q.x() - self.origin.x()) / self.scale, (self.origin.y() - q.y()) / self.scale)

    def zoom(self, factor: float, about: QPointF | None = None):
        about = about or QPointF(self.width() / 2, self.height() / 2)
        fixed = self.to_mm(about)
        self.scale = min(max(self.scale * factor, 0.05), 200.0)
        p = self.to_px(fixed)
        self.origin = self.origin + (about - p)
        self.update()

    def handle_at(self, pos: QPointF):
        """The handle within :data:`HANDLE_PX` of ``pos`` (the nearest; earlier ones win ties)."""
        best, best_d = None, HANDLE_PX
        for h in self.handles():
            q = self.to_px(h.point)
            d = math.dist((pos.x(), pos.y()), (q.x(), q.y()))
            if d < best_d - 1e-9 or (best is None and d <= best_d):
                best, best_d = h, d
        return best

    # ------------------------------------------------------------------------ mouse
    def left_pressed(self, pos: QPointF) -> None:
        """The left button went down at ``pos`` (px): grab a handle or select."""

    def mousePressEvent(self, event):
        pos = event.position()
        if event.button() in (Qt.MiddleButton, Qt.RightButton):
            self._pan_from = pos
        elif event.button() == Qt.LeftButton:
            self.left_pressed(pos)

    def panned(self, pos: QPointF) -> bool:
        """Pan to ``pos`` when a pan is under way (``True``), else nothing."""
        if self._pan_from is None:
            return False
        self.origin = self.origin + (pos - self._pan_from)
        self._pan_from = pos
        self.update()
        return True

    def end_drag(self):
        if self._drag is not None:
            self._drag = None
            self.dragging.emit(False)

    def mouseReleaseEvent(self, event):
        self._pan_from = None
        self.end_drag()

    def wheelEvent(self, event):
        self.zoom(1.0015 ** event.angleDelta().y(), event.position())
