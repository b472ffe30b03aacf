"""The plan canvas: an outline bottle's plan at its widest core, at true scale, with handles.

Design rule: as the section canvas, the plan canvas never changes the model. It draws what it
was given (``show_plan``: the outline ``P``, the core scale ``k`` and rounding ``c`` in mm) and
turns mouse gestures into *proposed* outlines (signal ``planProposed``), computed by the engine
(:mod:`engine.geometry.editing.plan_tools`) from the outline the drag started on; whoever owns
the undo stack validates and applies them, and the scene brings the result back. A refused
proposal (a drag that would make the outline concave) emits ``problem`` and changes nothing.

Drawn: the body's section ``k P (+) disc(c)`` (thick), ``k P`` itself (thin), the joints
(squares) and the arcs' centres (circles); x to the right, y up, in the bottle's own frame
(before its rotation). Mouse: left-drag a joint or an arc's centre (its radius follows: the
centre slides along its ends' bisector); click a segment to select it; wheel zooms about the
cursor; middle- or right-drag pans.
"""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen
from PySide6.QtWidgets import QSizePolicy

from engine.errors import OutlineError
from engine.geometry.editing import Handle
from engine.geometry.editing import plan_tools as pt
from widgets.mm_canvas import MillimetreCanvas
#: Points per radian on a drawn arc.
ARC_STEPS = 24


def segment_points(seg, k: float) -> np.ndarray:
    """Points (mm, ``(N, 2)``) along a plan segment scaled by ``k``, for drawing and picking."""
    if seg.kind == "line":
        return np.array([seg.p0, seg.p1]) * k
    a = seg.theta0 + seg.sweep * np.linspace(0.0, 1.0, max(2, int(seg.sweep * ARC_STEPS) + 2))
    return k * np.stack([seg.center[0] + seg.radius * np.cos(a), seg.center[1] + seg.radius * np.sin(a)], axis=-1)


class PlanCanvas(MillimetreCanvas):
    """Draws one plan at the widest core; proposes joint and arc-centre drags.

    Signals
    -------
    planProposed(object, str, str)
        ``(new PlanOutline, undo label, merge key)`` for every drag step; the outline is in the
        units of the one the drag started on (its ``scale``: see ``plan_tools.with_plan``).
    problem(str)
        A drag step asked for an outline that is not valid; the text says why.
    """

    planProposed = Signal(object, str, str)
    problem = Signal(str)
    _gesture_serial = 0

    def __init__(self, parent=None):
        super().__init__(3.0, QPointF(150.0, 150.0), parent)  # px per mm; pixel of the axis
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Expanding)
        self.setMinimumSize(220, 220)
        self.setMouseTracking(True)
        self.plan = None
        self.k = self.c = 0.0
        self.symmetry = (1, False)  # (n, mirror) the drags apply
        self._fitted = False

    # ----------------------------------------------------------------- model → view
    def show_plan(self, plan, k: float, c: float):
        """Show ``plan`` at core scale ``k`` and rounding ``c`` (mm); ``plan`` ``None``: nothing."""
        self.plan, self.k, self.c = plan, k, c
        if plan is None or self.selected >= len(plan.segments):
            self.select(-1)
        if not self._fitted:
            self.fit()
        self.update()

    # ----------------------------------------------------------------------- mapping
    def fit(self):
        """Zoom so that the whole section fits the canvas, the axis in the middle."""
        if self.plan is None or self.width() < 10:
            return
        reach = max(self.k + self.c, 1.0)
        self.scale = 0.45 * min(self.width(), self.height()) / reach
        self.origin = QPointF(self.width() / 2, self.height() / 2)
        self._fitted = True
        self.update()

    def resizeEvent(self, event):
        super().resizeEvent(event)
        self._fitted = False
        self.fit()

    # ----------------------------------------------------------------------- painting
    def _path(self, points) -> QPainterPath:
        path = QPainterPath()
        for i, p in enumerate(points):
            path.moveTo(self.to_px(p)) if i == 0 else path.lineTo(self.to_px(p))
        return path

    def handles(self) -> list[Handle]:
        """The joints (first, so they win ties) and the arcs' centres, in mm."""
        if self.plan is None:
            return []
        segs = self.plan.segments
        out = [Handle("joint", i, (s.p0[0] * self.k, s.p0[1] * self.k)) for i, s in enumerate(segs)]
        out += [Handle("centre", i, (s.center[0] * self.k, s.center[1] * self.k))
                for i, s in enumerate(segs) if s.kind == "arc"]
        return out

    def paintEvent(self, event):
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        p.fillRect(self.rect(), QColor(250, 250, 247))
        p.setPen(QPen(QColor(120, 120, 120), 1, Qt.DashDotLine))
        p.drawLine(QPointF(self.origin.x(), 0), QPointF(self.origin.x(), self.height()))
        p.drawLine(QPointF(0, self.origin.y()), QPointF(self.width(), self.origin.y()))
        if self.plan is None:
            return
        if self.c > 0:
            outer = self.plan.polyline(self.k, self.c, max_turn_deg=2.0)
            p.setPen(QPen(QColor(20, 20, 20), 2))
            p.drawPath(self._path(np.vstack([outer, outer[:1]])))
        for i, seg in enumerate(self.plan.segments):
            sel = i == self.selected
            p.setPen(QPen(QColor(220, 90, 20) if sel else QColor(90, 90, 160), 2.5 if sel else 1))
            p.drawPath(self._path(segment_points(seg, self.k)))
        for h in self.handles():
            q = self.to_px(h.point)
            p.setPen(QPen(QColor(30, 30, 30), 1))
            if h.kind == "joint":
                p.setBrush(QColor(255, 255, 255))
                p.drawRect(QRectF(q.x() - 4, q.y() - 4, 8, 8))
            else:
                p.setBrush(QColor(255, 210, 120))
                p.drawEllipse(q, 4, 4)
        p.setBrush(Qt.NoBrush)
        p.setPen(QColor(60, 60, 60))
        p.drawText(QPointF(6, 16), f"plan at the widest core: k {self.k:.2f} mm, c {self.c:.2f} mm")

    # ------------------------------------------------------------------------ mouse
    def segment_at(self, pos: QPointF) -> int:
        if self.plan is None:
            return -1
        x, y = self.to_mm(pos)
        best, best_d = -1, 6.0 / self.scale
        for i, seg in enumerate(self.plan.segments):
            pts = segment_points(seg, self.k)
            t = np.linspace(0.0, 1.0, 64)[:, None]
            dense = np.concatenate([a + t * (b - a) for a, b in zip(pts[:-1], pts[1:])])
            d = float(np.hypot(dense[:, 0] - x, dense[:, 1] - y).min())
            if d < best_d:
                best, best_d = i, d
        return best

    def left_pressed(self, pos: QPointF):
        handle = self.handle_at(pos)
        if handle is None:
            self.select(self.segment_at(pos))
            return
        PlanCanvas._gesture_serial += 1
        self.begin_drag(handle, f"plan-{handle.kind}-{handle.index}#{PlanCanvas._gesture_serial}")
        if handle.kind == "centre":
            self.select(handle.index)

    def mouseMoveEvent(self, event):
        pos = event.position()
        if self.panned(pos):
            return
        if self._drag is None:
            h = self.handle_at(pos)
            self.setToolTip("" if h is None else
                            f"Joint {h.index}: drag to move it (the outline must stay convex)" if h.kind == "joint"
                            else f"Centre of arc {h.index}: drag to change its radius (its ends stay)")
            return
        self.drag_to(self.to_mm(pos))

    def begin_drag(self, handle: Handle, key: str):
        """Start dragging ``handle`` as the mouse does (also used by tests)."""
        self._drag = (handle, self.plan, self.k, key)
        self.dragging.emit(True)

    def drag_to(self, point_mm):
        """Propose the drag-start outline with the grabbed handle at ``point_mm`` (mm)."""
        handle, start, k, key = self._drag
        to = (point_mm[0] / k, point_mm[1] / k)
        n, mirror = self.symmetry
        try:
            if handle.kind == "joint":
                proposal, label = pt.move_joint(start, handle.index, to, n, mirror), "Move plan joint"
            else:
                proposal, label = pt.move_arc_centre(start, handle.index, to, n, mirror), "Change plan arc radius"
        except OutlineError as exc:
            self.problem.emit(str(exc))
            return
        self.planProposed.emit(proposal, label, key)
