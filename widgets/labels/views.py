"""The pictures of the labels panel: the front artwork (with the eyedropper) and the flat die-line.

Design rule: views only: they draw what they are given (sRGB pixels, a label report) and report
a click as a signal; the panel's parts decide what it means.
"""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import QSizePolicy, QWidget

from widgets import edit_fields as ef

#: Side (px) of the artwork picture drawn in the panel.
THUMB_PX = 220


class ArtworkView(QWidget):
    """The front artwork, fitted; a click reports the texel's sRGB colour (``picked``)."""

    picked = Signal(tuple, bool)  # (r, g, b) sRGB 0..1, shift held (add a key)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumSize(THUMB_PX // 2, THUMB_PX // 2)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        self.pixels: np.ndarray | None = None  # sRGB uint8 (H, W, 4)
        self._image = None
        self.claimed: np.ndarray | None = None
        self.text = "no artwork"

    def sizeHint(self):  # noqa: N802 - Qt's name
        from PySide6.QtCore import QSize
        return QSize(THUMB_PX, THUMB_PX)

    def set_pixels(self, pixels: np.ndarray | None, text: str = "", claimed: np.ndarray | None = None):
        """Show ``pixels`` (sRGB uint8 RGBA; what the eyedropper reads) with the texels where
        ``claimed`` (bool, same rows and columns) is true tinted magenta: the selected region."""
        self.pixels = pixels
        self.claimed = claimed
        shown = pixels
        if pixels is not None and claimed is not None and claimed.shape == pixels.shape[:2]:
            shown = pixels.copy()
            tint = np.array([255, 0, 200], np.float32)
            shown[claimed, :3] = np.round(0.45 * shown[claimed, :3] + 0.55 * tint).astype(np.uint8)
            shown[claimed, 3] = 255
        self._image = ef.qimage_of(shown) if shown is not None else None
        self.text = text
        self.update()

    def image_rect(self) -> QRectF:
        """Where the artwork is drawn (widget px), aspect kept."""
        if self.pixels is None:
            return QRectF()
        h, w = self.pixels.shape[:2]
        scale = min(self.width() / w, self.height() / h)
        return QRectF((self.width() - w * scale) / 2, (self.height() - h * scale) / 2, w * scale, h * scale)

    def texel_at(self, pos: QPointF):
        """``(row, column)`` of the artwork under widget point ``pos``, or ``None``."""
        r = self.image_rect()
        if self.pixels is None or not r.contains(pos):
            return None
        h, w = self.pixels.shape[:2]
        col = min(int((pos.x() - r.x()) / r.width() * w), w - 1)
        row = min(int((pos.y() - r.y()) / r.height() * h), h - 1)
        return row, col

    def colour_at(self, pos: QPointF):
        at = self.texel_at(pos)
        if at is None:
            return None
        return tuple(float(v) / 255.0 for v in self.pixels[at[0], at[1], :3])

    def paintEvent(self, event):  # noqa: N802
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(60, 60, 64))
        if self._image is not None:
            p.drawImage(self.image_rect(), self._image)
        else:
            p.setPen(QColor(200, 200, 200))
            p.drawText(self.rect(), Qt.AlignCenter, self.text)

    def mousePressEvent(self, event):  # noqa: N802
        colour = self.colour_at(event.position())
        if colour is not None and event.button() == Qt.LeftButton:
            self.picked.emit(colour, bool(event.modifiers() & Qt.ShiftModifier))


class DielineView(QWidget):
    """The label's flat shape to scale (outline in mm, y up), warnings marked in red."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumSize(THUMB_PX // 2, THUMB_PX // 2)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        self.outline: np.ndarray | None = None
        self.figures: dict = {}
        self.marks: list[tuple[float, float]] = []
        self.setToolTip("The flat die-line a printer cuts, to scale; red: where the label cannot lie flat")

    def sizeHint(self):  # noqa: N802
        from PySide6.QtCore import QSize
        return QSize(THUMB_PX, THUMB_PX)

    def set_report(self, report):
        """Show ``report`` (a :class:`engine.appearance.report.LabelReport`, ``None``: nothing)."""
        if report is None:
            self.outline, self.figures, self.marks = None, {}, []
        else:
            self.outline = np.asarray(report.flat.outline(), float)
            self.figures = dict(report.flat.figures)
            self.marks = [(w.x_mm, w.y_mm) for w in report.warnings]
        self.update()

    @property
    def kind(self) -> str | None:
        return self.figures.get("kind")

    def paintEvent(self, event):  # noqa: N802
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        p.fillRect(self.rect(), QColor(250, 250, 248))
        if self.outline is None or len(self.outline) < 3:
            return
        lo, hi = self.outline.min(axis=0), self.outline.max(axis=0)
        span = np.maximum(hi - lo, 1e-6)
        margin = 10.0
        scale = min((self.width() - 2 * margin) / span[0], (self.height() - 2 * margin) / span[1])
        cx, cy = (lo + hi) / 2

        def to_px(x, y):
            return QPointF(self.width() / 2 + (x - cx) * scale, self.height() / 2 - (y - cy) * scale)

        path = QPainterPath()
        path.addPolygon(QPolygonF([to_px(x, y) for x, y in self.outline]))
        path.closeSubpath()
        p.setPen(QPen(QColor(20, 20, 20), 1.5))
        p.setBrush(QColor(255, 255, 255))
        p.drawPath(path)
        p.setPen(Qt.NoPen)
        p.setBrush(QColor(220, 30, 30))
        for x, y in self.marks:
            p.drawEllipse(to_px(x, y), 4, 4)
