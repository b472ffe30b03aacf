"""The section canvas: a vertical section in the (r, z) plane at true scale, with handles.

Design rule: the canvas never changes the model. It draws what it was given (``show``) and
turns mouse gestures into *proposed* sections (signal ``sectionProposed``); whoever owns the
undo stack validates and applies them, and the scene notification brings the result back here.
A refused proposal therefore leaves the canvas showing the last valid section.

Mouse: left-drag a joint (square), an arc centre (circle), an ellipse radius handle (diamond)
or the fill line (the dashed blue line, by its triangle at the right); a joint drag stretches the
section and keeps the finish (the neck's radius and the height), Shift moves the joint alone and
Alt carries everything above it along; click a segment to select it; wheel zooms about the
cursor; middle- or right-drag pans. Holding Ctrl disables snap. The geometry of every gesture is
the engine's (:mod:`engine.geometry.editing`); the canvas only maps pixels to millimetres.
"""
from __future__ import annotations

import math

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import QSizePolicy

from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc
from engine.geometry import editing as edits
from engine.geometry.editing import Handle, handles_of, propose_drag
from widgets.mm_canvas import MillimetreCanvas


class SectionCanvas(MillimetreCanvas):
    """Draws one section with grid, dimensions, inner wall and fill line; proposes drag edits.

    Signals
    -------
    sectionProposed(object, str, str)
        ``(new Section, undo label, merge key)`` for every drag step.
    selectionChanged(int)
        Index of the selected segment (-1: none).
    fillProposed(float, str)
        ``(fill height in mm, merge key)`` for every step of a drag of the fill line.
    dragging(bool)
        A handle drag started (True) or ended (False): slow consumers may pause meanwhile.
    toolRequested(str)
        A keyboard shortcut asked for a segment tool (``"delete"``, ``"split"``).
    problem(str)
        A drag step asked for geometry that does not exist; the text says why.
    """

    sectionProposed = Signal(object, str, str)
    fillProposed = Signal(float, str)
    toolRequested = Signal(str)
    problem = Signal(str)
    _gesture_serial = 0

    def __init__(self, parent=None):
        super().__init__(1.5, QPointF(60.0, 400.0), parent)  # px per mm; pixel of (r, z) = (0, 0)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Expanding)
        self.setMinimumSize(240, 240)
        self.setMouseTracking(True)
        self.setFocusPolicy(Qt.StrongFocus)
        self.section: Section | None = None
        self.inner = None
        self.fill_z: float | None = None
        self.ghosts: list[Section] = []
        self.snap_mm = 0.5
        self._fitted = False

    # ----------------------------------------------------------------- model → view
    def show_section(self, section: Section, inner=None, fill_z=None, ghosts=()):
        """Show ``section`` (and its inner wall, fill height in mm, other sections faintly)."""
        self.section, self.inner, self.fill_z, self.ghosts = section, inner, fill_z, list(ghosts)
        if self.selected >= len(section.segments):
            self.select(-1)
        if not self._fitted and self.width() > 0:
            self.fit()
        self.update()

    def request_fit(self):
        """Fit the section to the canvas now, or as soon as the canvas has a size (a newly
        opened design)."""
        self._fitted = False
        if self.isVisible() and self.width() >= 10:
            self.fit()

    # ----------------------------------------------------------------------- mapping
    def fit(self):
        """Zoom and pan so the whole section (both halves, the fill line and the dimensions)
        fits the canvas."""
        if self.section is None or self.width() < 10:
            return
        pts = edits.section_polyline(self.section)
        rmax = max(float(pts[:, 0].max()), 1.0)
        zmax = max(float(pts[:, 1].max()), self.fill_z or 0.0, 1.0)
        margin_x, margin_top, margin_bottom = 44.0, 40.0, 28.0  # room for the labels
        self.scale = min((self.width() - 2 * margin_x) / (2 * rmax),
                         (self.height() - margin_top - margin_bottom) / zmax)
        self.origin = QPointF(self.width() / 2, self.height() - margin_bottom)
        self._fitted = True
        self.update()

    def resizeEvent(self, event):
        super().resizeEvent(event)
        if not self._fitted:
            self.fit()

    # ----------------------------------------------------------------------- painting
    def _grid_step(self) -> float:
        for step in (0.1, 0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500):
            if step * self.scale >= 12:
                return step
        return 1000.0

    def _path(self, segments, mirror=False) -> QPainterPath:
        pts = edits.section_polyline(segments)
        path = QPainterPath()
        for k, (r, z) in enumerate(pts):
            q = self.to_px((-r if mirror else r, z))
            path.moveTo(q) if k == 0 else path.lineTo(q)
        return path

    def paintEvent(self, event):
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        p.fillRect(self.rect(), QColor(250, 250, 247))
        self._paint_grid(p)
        if self.section is None:
            return
        for ghost in self.ghosts:
            p.setPen(QPen(QColor(170, 170, 200), 1, Qt.DashLine))
            p.drawPath(self._path(ghost))
        p.setPen(QPen(QColor(150, 150, 150), 1))
        p.drawPath(self._path(self.section, mirror=True))
        if self.inner:
            p.setPen(QPen(QColor(90, 140, 200), 1.2))
            p.drawPath(self._path(self.inner))
            p.drawPath(self._path(self.inner, mirror=True))
        if self.fill_z is not None:
            above = self.fill_z > self.section.z_top + 1e-6
            colour = QColor(200, 40, 40) if above else QColor(40, 120, 220)
            p.setPen(QPen(colour, 1.5, Qt.DashDotLine))
            a, b = self.to_px((-self._rmax(), self.fill_z)), self.to_px((self._rmax(), self.fill_z))
            p.drawLine(a, b)
            p.setBrush(colour)
            p.drawPolygon(QPolygonF([b, b + QPointF(9, -6), b + QPointF(9, 6)]))  # the grip
            p.setBrush(Qt.NoBrush)
            # why above the left half: the joints' handles are all on the right half
            text = f"fill {self.fill_z:.1f} mm" + (" (above the brim)" if above else "")
            p.drawText(a + QPointF(2, -4), text)
        for i, seg in enumerate(self.section.segments):
            sel = i == self.selected
            p.setPen(QPen(QColor(220, 90, 20) if sel else QColor(20, 20, 20), 3 if sel else 2))
            p.drawPath(self._path([seg]))
        self._paint_dimensions(p)
        self._paint_handles(p)

    def _rmax(self) -> float:
        return float(edits.section_polyline(self.section)[:, 0].max())

    def _paint_grid(self, p: QPainter):
        step = self._grid_step()
        r0, z1 = self.to_mm(QPointF(0, 0))
        r1, z0 = self.to_mm(QPointF(self.width(), self.height()))
        for major in (False, True):
            s = step * (10 if major else 1)
            p.setPen(QPen(QColor(215, 215, 215) if major else QColor(236, 236, 236), 1))
            k = math.floor(r0 / s)
            while k * s <= r1:
                x = self.to_px((k * s, 0)).x()
                p.drawLine(QPointF(x, 0), QPointF(x, self.height()))
                k += 1
            k = math.floor(z0 / s)
            while k * s <= z1:
                y = self.to_px((0, k * s)).y()
                p.drawLine(QPointF(0, y), QPointF(self.width(), y))
                k += 1
        p.setPen(QPen(QColor(120, 120, 120), 1, Qt.DashDotLine))
        x = self.origin.x()
        p.drawLine(QPointF(x, 0), QPointF(x, self.height()))
        p.drawText(QPointF(4, self.height() - 4), f"grid {step:g} mm")

    def _paint_dimensions(self, p: QPainter):
        sec = self.section
        p.setPen(QPen(QColor(160, 40, 40), 1))
        rmax, ztop = self._rmax(), sec.z_top
        x = self.to_px((rmax, 0)).x() + 20
        a, b = QPointF(x, self.to_px((0, 0)).y()), QPointF(x, self.to_px((0, ztop)).y())
        p.drawLine(a, b)
        p.save()  # why upright along the line: a narrow canvas has no room for it sideways
        p.translate(x + 14, (a.y() + b.y()) / 2)
        p.rotate(-90)
        text = f"H {ztop:.2f}"
        p.drawText(QPointF(-p.fontMetrics().horizontalAdvance(text) / 2, 0), text)
        p.restore()
        y = self.to_px((0, ztop)).y() - 14
        p.drawLine(QPointF(self.to_px((-rmax, 0)).x(), y), QPointF(self.to_px((rmax, 0)).x(), y))
        p.drawText(QPointF(self.origin.x() + 4, y - 4), f"\u2300 {2 * rmax:.2f}")
        if 0 <= self.selected < len(sec.segments):
            seg = sec.segments[self.selected]
            text = f"#{self.selected} {seg.kind}  L {seg.length:.2f}"
            if isinstance(seg, Arc):
                text += f"  R {seg.radius:.2f}"
            elif isinstance(seg, EllipseArc):
                text += f"  Rr {seg.radius_r:.2f}  Rz {seg.radius_z:.2f}"
            p.drawText(QPointF(8, 16), text)

    def _paint_handles(self, p: QPainter):
        for h in handles_of(self.section):
            q = self.to_px(h.point)
            p.setPen(QPen(QColor(30, 30, 30), 1))
            if h.kind == "joint":
                p.setBrush(QColor(255, 255, 255))
                p.drawRect(QRectF(q.x() - 4, q.y() - 4, 8, 8))
            elif h.kind == "centre":
                p.setBrush(QColor(255, 210, 120))
                p.drawEllipse(q, 4, 4)
            else:
                p.setBrush(QColor(160, 220, 160))
                p.drawPolygon(QPolygonF([q + QPointF(0, -5), q + QPointF(5, 0), q + QPointF(0, 5),
                                         q + QPointF(-5, 0)]))
        p.setBrush(Qt.NoBrush)

    # ------------------------------------------------------------------------ mouse
    def fill_grip_at(self, pos: QPointF) -> bool:
        """Whether ``pos`` is on the fill line (within a few pixels, right of the axis)."""
        if self.fill_z is None or self.section is None:
            return False
        y = self.to_px((0.0, self.fill_z)).y()
        right = self.to_px((self._rmax(), 0.0)).x() + 10
        return abs(pos.y() - y) <= 4 and self.origin.x() <= pos.x() <= right

    def handles(self) -> list[Handle]:
        """The section's handles, joints first (they win ties)."""
        return [] if self.section is None else handles_of(self.section)

    def segment_at(self, pos: QPointF) -> int:
        if self.section is None:
            return -1
        r, z = self.to_mm(pos)
        best, best_d = -1, 6.0 / self.scale
        for i, seg in enumerate(self.section.segments):
            # why: dense samples of every kind (a line drawn from its two ends has no middle)
            n = int(min(2000, max(16, seg.length * self.scale / 2)))
            pts = np.atleast_2d(seg.point(np.linspace(0.0, 1.0, n)))
            d = float(((pts[:, 0] - r) ** 2 + (pts[:, 1] - z) ** 2).min()) ** 0.5
            if d < best_d:
                best, best_d = i, d
        return best

    def _snap(self, value: float, enabled: bool) -> float:
        return round(value / self.snap_mm) * self.snap_mm if enabled and self.snap_mm > 0 else value

    def left_pressed(self, pos: QPointF):
        handle = self.handle_at(pos)
        if handle is None and self.fill_grip_at(pos):
            handle = Handle("fill", -1, (0.0, self.fill_z))
        if handle is not None:
            SectionCanvas._gesture_serial += 1
            key = f"drag-{handle.kind}-{handle.index}#{SectionCanvas._gesture_serial}"
            self.begin_drag(handle, key)
            if handle.kind not in ("joint", "fill"):
                self.select(handle.index)
            return
        self.select(self.segment_at(pos))

    def mouseMoveEvent(self, event):
        pos = event.position()
        if self.panned(pos):
            return
        if self._drag is None:
            self.setToolTip(self._hover_text(pos))
            return
        handle, start, key = self._drag
        mods = event.modifiers()
        snap = not (mods & Qt.ControlModifier)
        r, z = self.to_mm(pos)
        target = (self._snap(r, snap), self._snap(z, snap))
        delta = (target[0] - handle.point[0], target[1] - handle.point[1])
        self.drag_to(delta, local=bool(mods & Qt.ShiftModifier), carry=bool(mods & Qt.AltModifier))

    def _hover_text(self, pos: QPointF) -> str:
        """What the thing under the pointer is and what dragging it does (its tooltip)."""
        handle = self.handle_at(pos)
        if handle is None:
            return ("Drag the fill line to change the fill level" if self.fill_grip_at(pos) else "")
        if handle.kind == "joint":
            n = len(self.section.segments)
            if handle.index == n - 1:
                return "The mouth: drag to change the height"
            smooth = handle.index < len(self.section.smooth) and self.section.smooth[handle.index]
            what = edits.joint_name(handle.index).capitalize() + (" (smooth)" if smooth else " (corner)")
            return what + ": drag to stretch (the finish stays), Shift alone, Alt carries the top along"
        if handle.kind == "centre":
            return f"Centre of arc {handle.index}: drag to change its radius"
        return f"Radius of ellipse arc {handle.index}: drag to change it"

    def drag_to(self, delta, local: bool = False, carry: bool = False):
        """Propose the drag-start section with the grabbed handle moved by ``delta`` (mm)."""
        handle, start, key = self._drag
        if handle.kind == "fill":
            self.fillProposed.emit(max(handle.point[1] + delta[1], 0.0), key)
            return
        try:
            proposal = propose_drag(start, handle, delta, local, carry)
        except ValueError as exc:
            self.problem.emit(f"{edits.joint_name(handle.index)}: {exc}" if handle.kind == "joint" else str(exc))
            return
        label = {"joint": "Move joint", "centre": "Change arc radius"}.get(handle.kind, "Change ellipse radius")
        self.sectionProposed.emit(proposal, label, key)

    def begin_drag(self, handle: Handle, key: str):
        """Start dragging ``handle`` as the mouse does (also used by tests and benchmarks)."""
        self._drag = (handle, self.section, key)
        self.dragging.emit(True)

    def keyPressEvent(self, event):
        key = event.key()
        if key in (Qt.Key_Delete, Qt.Key_Backspace):
            self.toolRequested.emit("delete")
        elif key == Qt.Key_S and not event.modifiers():
            self.toolRequested.emit("split")
        elif key == Qt.Key_Escape:
            self.select(-1)
        elif key == Qt.Key_F:
            self.fit()
        else:
            super().keyPressEvent(event)
