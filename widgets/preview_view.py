"""The render preview: the tracer's image, painted tile by tile, at 1:1 or fitted.

Design rule: the view holds a ``QImage`` the size of the render and only ever writes tiles
handed to it on the GUI thread (``paint_tile``); it knows nothing of jobs or generations. A new
image starts as the old picture scaled to the new size (never a blank flash), and the window's
note (``set_note``: "stale", "refining") is drawn over it. Renders are sized in device pixels
(:meth:`pane_pixels`), so at 1:1 one image pixel is one screen pixel. Dragging in the view asks
for a camera orbit (``orbitRequested``); the window turns that into an undoable camera edit,
which restarts the render; Shift+drag asks to place the selected label instead
(``placeRequested``). At 1:1 the middle button pans. An image file dropped on the view is
announced (``imageDropped``) with the render pixel under the drop; the window makes it a label.
"""
from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QImage, QPainter
from PySide6.QtWidgets import QSizePolicy, QWidget


class PreviewView(QWidget):
    """Shows the progressive render.

    Signals
    -------
    orbitRequested(float, float, bool)
        ``(degrees of azimuth, degrees of elevation, drag finished)`` from a mouse drag.
    orbiting(bool)
        An orbit drag started (True) or ended (False): the render holds meanwhile.
    imageDropped(str, object)
        An image file (its path) was dropped at ``(x, y)`` render pixels (``None``: off the
        picture).
    placeRequested(object, bool)
        A Shift+drag asks to put the selected label at ``(x, y)`` render pixels (``None``: off
        the picture); ``True`` when the drag ends.
    sizeRequested(object, bool)
        A Ctrl+Shift+drag asks to size the selected label so that a corner is at ``(x, y)``
        render pixels (``None``: off the picture); ``True`` when the drag ends.
    """

    orbitRequested = Signal(float, float, bool)
    orbiting = Signal(bool)
    imageDropped = Signal(str, object)
    placeRequested = Signal(object, bool)
    sizeRequested = Signal(object, bool)
    #: File endings accepted as a drop (the label artwork formats).
    DROP_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr")

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Expanding)
        self.setMinimumSize(200, 200)
        self._image = QImage()
        self.fit = True
        self.tiles_painted = 0
        self._press = None
        self._pan_from = None
        self._placing = None  # a Shift+drag placing the selected label: its signal
        self.pan = QPointF(0.0, 0.0)  # offset (px) of the 1:1 image from centred
        self.note = ""
        self.setAcceptDrops(True)
        self.setToolTip("The glass as the tracer sees it: drag to orbit the camera; Ctrl+1 for 1:1, "
                        "Ctrl+0 to fit; drop an image file on the bottle to add a label there, Shift+drag "
                        "to move the selected label, Ctrl+Shift+drag to size it by a corner")

    # ----------------------------------------------------------------------- image
    def image_size(self) -> tuple[int, int]:
        return (self._image.width(), self._image.height())

    def pane_pixels(self) -> tuple[int, int]:
        """The view's size in device pixels (what a render at the pane's resolution needs)."""
        dpr = self.devicePixelRatioF()
        return (max(1, round(self.width() * dpr)), max(1, round(self.height() * dpr)))

    def set_note(self, text: str):
        """A line drawn over the picture saying what it is (empty: none)."""
        if text != self.note:
            self.note = text
            self.update()

    def reset(self, width: int, height: int):
        """Start a new image of ``width`` x ``height`` pixels, showing the old picture scaled
        until the new tiles arrive."""
        old = self._image
        self._image = QImage(width, height, QImage.Format_RGB888)
        if old.isNull():
            self._image.fill(QColor(40, 40, 44))
        else:
            p = QPainter(self._image)
            p.setRenderHint(QPainter.SmoothPixmapTransform)
            p.drawImage(QRectF(0, 0, width, height), old)
            p.end()
        self.tiles_painted = 0
        self.update()

    def paint_tile(self, x0: int, y0: int, rgb8: np.ndarray):
        """Copy an ``(h, w, 3)`` uint8 tile to ``(x0, y0)`` of the image."""
        h, w = rgb8.shape[:2]
        if self._image.isNull() or x0 + w > self._image.width() or y0 + h > self._image.height():
            return
        data = np.ascontiguousarray(rgb8, dtype=np.uint8)
        tile = QImage(data.data, w, h, 3 * w, QImage.Format_RGB888)
        p = QPainter(self._image)
        p.drawImage(x0, y0, tile)
        p.end()
        self.tiles_painted += 1
        self.update(self._target_rect().toAlignedRect())

    def image(self) -> QImage:
        """A copy of the current image (what Export image saves)."""
        return self._image.copy()

    def pixel_rgb(self, x: int, y: int) -> tuple[int, int, int]:
        c = self._image.pixelColor(x, y)
        return (c.red(), c.green(), c.blue())

    # ------------------------------------------------------------------------ zoom
    def zoom_one_to_one(self):
        self.fit = False
        self.pan = QPointF(0.0, 0.0)
        self.update()

    def zoom_fit(self):
        self.fit = True
        self.update()

    def _target_rect(self) -> QRectF:
        iw, ih = self._image.width(), self._image.height()
        if iw == 0 or ih == 0:
            return QRectF()
        scale = min(self.width() / iw, self.height() / ih) if self.fit else 1.0 / self.devicePixelRatioF()
        w, h = iw * scale, ih * scale
        offset = QPointF(0.0, 0.0) if self.fit else self.pan
        return QRectF((self.width() - w) / 2 + offset.x(), (self.height() - h) / 2 + offset.y(), w, h)

    def paintEvent(self, event):
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(28, 28, 30))
        if not self._image.isNull():
            p.setRenderHint(QPainter.SmoothPixmapTransform, self.fit)
            p.drawImage(self._target_rect(), self._image)
        p.setPen(QColor(200, 200, 200))
        p.drawText(QPointF(8, 16), "fit" if self.fit else "1:1")
        if self.note:
            p.drawText(QPointF(8, self.height() - 8), self.note)

    # ----------------------------------------------------------------------- orbit
    def mousePressEvent(self, event):
        if event.button() == Qt.LeftButton and event.modifiers() & Qt.ShiftModifier:
            sizing = bool(event.modifiers() & Qt.ControlModifier)
            self._placing = self.sizeRequested if sizing else self.placeRequested
            self._placing.emit(self.image_point(event.position()), False)
        elif event.button() == Qt.LeftButton:
            self._press = event.position()
            self.orbiting.emit(True)
        elif event.button() == Qt.MiddleButton and not self.fit:
            self._pan_from = event.position()

    def mouseMoveEvent(self, event):
        if self._placing is not None:
            self._placing.emit(self.image_point(event.position()), False)
        elif self._pan_from is not None:
            self.pan = self.pan + (event.position() - self._pan_from)
            self._pan_from = event.position()
            self.update()
        elif self._press is not None:
            d = event.position() - self._press
            self.orbitRequested.emit(-d.x() * 0.4, d.y() * 0.3, False)

    def mouseReleaseEvent(self, event):
        self._pan_from = None
        if self._placing is not None:
            signal, self._placing = self._placing, None
            signal.emit(None, True)
        if self._press is not None:
            self._press = None
            self.orbitRequested.emit(0.0, 0.0, True)
            self.orbiting.emit(False)

    # ------------------------------------------------------------------------ drops
    def _dropped_image(self, mime) -> str | None:
        for url in mime.urls() if mime.hasUrls() else ():
            path = url.toLocalFile()
            if path and path.lower().endswith(self.DROP_EXTENSIONS):
                return path
        return None

    def image_point(self, pos: QPointF):
        """``(x, y)`` render pixels under widget point ``pos`` (``None``: off the picture)."""
        r = self._target_rect()
        if r.isEmpty() or not r.contains(pos):
            return None
        return ((pos.x() - r.x()) / r.width() * self._image.width(),
                (pos.y() - r.y()) / r.height() * self._image.height())

    def dragEnterEvent(self, event):  # noqa: N802 - Qt's name
        if self._dropped_image(event.mimeData()):
            event.acceptProposedAction()

    def dragMoveEvent(self, event):  # noqa: N802
        if self._dropped_image(event.mimeData()):
            event.acceptProposedAction()

    def dropEvent(self, event):  # noqa: N802
        path = self._dropped_image(event.mimeData())
        if path:
            event.acceptProposedAction()
            self.imageDropped.emit(path, self.image_point(event.position()))
