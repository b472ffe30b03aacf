"""Render -> Final image: a print-size render of the current design, off the GUI thread.

Design rule: the dialog renders a frozen snapshot taken when Render is pressed, through the
engine's :class:`engine.batch.still.FinalRender` (the pixels of ``glassbench render``); edits
made meanwhile do not change it. While it runs, the live preview is cancelled and held so the
final render has the cores; when it ends (written, cancelled or failed) the hold is released
and the preview renders the current design again. Worker-thread callbacks only emit queued
signals; every widget is touched on the GUI thread. Questions (where to save) go through the
window's replaceable ``dialogs``, and opening the folder through :meth:`open_folder`, so tests
drive the real widgets without a modal dialog or a file manager.
"""
from __future__ import annotations

import os

from PySide6.QtCore import QElapsedTimer, QUrl, Signal
from PySide6.QtGui import QDesktopServices
from PySide6.QtWidgets import (QCheckBox, QComboBox, QDialog, QFormLayout, QHBoxLayout, QLabel,
                               QLineEdit, QProgressBar, QPushButton, QSpinBox, QVBoxLayout)

from engine.batch.still import FinalRender

FORMATS = (("PNG (sRGB 8-bit)", ".png"), ("EXR (linear float)", ".exr"), ("TIFF (sRGB 8-bit)", ".tif"))
IMAGE_FILTER = "Images (*.png *.exr *.tif *.tiff)"


def _spin(lo, hi, value, suffix=""):
    s = QSpinBox()
    s.setRange(lo, hi)
    s.setValue(value)
    s.setSuffix(suffix)
    return s


def format_seconds(seconds: float | None) -> str:
    """``"1 min 05 s"``, ``"12 s"``, or ``"estimating\u2026"`` for ``None``."""
    if seconds is None:
        return "estimating\u2026"
    s = int(round(seconds))
    return f"{s // 60} min {s % 60:02d} s" if s >= 60 else f"{s} s"


class FinalRenderDialog(QDialog):
    """Size, samples, format and alpha of a final image; render, progress, cancel, open folder.

    Signals
    -------
    ended(str, str)
        ``(state, message)`` once a render ends: state ``"written"``, ``"cancelled"`` or
        ``"failed"``.
    """

    ended = Signal(str, str)
    _worker_progress = Signal(object)
    _worker_done = Signal(object)

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.setWindowTitle("Final image")
        self.current = None
        self._clock = QElapsedTimer()
        r = window.scene.design.render
        self.width_px = _spin(1, 16384, r.width, " px")
        self.height_px = _spin(1, 16384, r.height, " px")
        self.samples = _spin(1, 65536, r.spp, " spp")
        self.format = QComboBox()
        for text, _ in FORMATS:
            self.format.addItem(text)
        self.alpha = QCheckBox("Alpha (the bottle's coverage)")
        self.denoise = QCheckBox("Denoise (keep the raw image beside it)")
        self.denoise.setToolTip("Writes the denoised estimate (Intel Open Image Denoise, guided by albedo and normal) "
                                "and the raw render as NAME.raw.EXT; each file says which it is")
        self.path = QLineEdit(self._default_path())
        self.browse = QPushButton("Browse\u2026")
        self.render_button = QPushButton("Render")
        self.cancel_button = QPushButton("Cancel")
        self.open_button = QPushButton("Open folder")
        self.close_button = QPushButton("Close")
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.status = QLabel("")
        self.time_left = QLabel("")
        self._layout()
        self.format.currentIndexChanged.connect(self._format_changed)
        self.browse.clicked.connect(self._browse)
        self.render_button.clicked.connect(self.start)
        self.cancel_button.clicked.connect(self.cancel)
        self.open_button.clicked.connect(lambda: self.open_folder(os.path.dirname(self.path.text())))
        self.close_button.clicked.connect(self.close)
        self._worker_progress.connect(self._on_progress)
        self._worker_done.connect(self._on_done)
        self._set_running(False)
        self.open_button.setEnabled(False)

    def _layout(self):
        form = QFormLayout()
        form.addRow("Width", self.width_px)
        form.addRow("Height", self.height_px)
        form.addRow("Samples", self.samples)
        form.addRow("Format", self.format)
        form.addRow("", self.alpha)
        form.addRow("", self.denoise)
        where = QHBoxLayout()
        where.addWidget(self.path, 1)
        where.addWidget(self.browse)
        form.addRow("File", where)
        buttons = QHBoxLayout()
        for b in (self.render_button, self.cancel_button, self.open_button, self.close_button):
            buttons.addWidget(b)
        box = QVBoxLayout(self)
        box.addLayout(form)
        box.addWidget(self.progress)
        box.addWidget(self.time_left)
        box.addWidget(self.status)
        box.addLayout(buttons)

    def _default_path(self) -> str:
        project = self.window.files.path
        folder = os.path.dirname(os.path.abspath(project)) if project else os.getcwd()
        stem = os.path.splitext(os.path.basename(project))[0] if project else "render"
        return os.path.join(folder, f"{stem}-final.png")

    def _format_changed(self, index: int):
        stem = os.path.splitext(self.path.text())[0]
        self.path.setText(stem + FORMATS[index][1])
        self.alpha.setToolTip("EXR: premultiplied linear colour" if index == 1 else "straight alpha")

    def _browse(self):
        path = self.window.dialogs.ask_save_path("Save final image", IMAGE_FILTER, self.path.text())
        if path:
            self.path.setText(path)
            ext = os.path.splitext(path)[1].lower()
            suffixes = [s for _, s in FORMATS]
            if ext in suffixes:
                self.format.setCurrentIndex(suffixes.index(ext))

    # ----------------------------------------------------------------------- running
    def is_running(self) -> bool:
        return self.current is not None and not self.current.done

    def start(self) -> bool:
        """Render the current design with the dialog's settings; ``False`` if refused."""
        if self.is_running():
            return False
        try:
            self.current = FinalRender(
                self.window.scene.snapshot(), dict(self.window.scene.assets), self.path.text(),
                width=self.width_px.value(), height=self.height_px.value(), spp=self.samples.value(),
                alpha=self.alpha.isChecked(), denoise=self.denoise.isChecked(),
                on_progress=self._worker_progress.emit, on_done=self._worker_done.emit)
        except ValueError as exc:
            self.status.setText(f"Cannot render: {exc}")
            return False
        preview = self.window.render_controller
        preview.cancel()
        preview.hold(True, live=False)  # why: the final render gets the cores; released in _on_done
        self.open_button.setEnabled(False)
        self.progress.setValue(0)
        r = self.current
        self.status.setText(f"Rendering {r.width}\u00d7{r.height} at {r.spp} spp\u2026")
        self.time_left.setText("Time left: estimating\u2026")
        self._set_running(True)
        self._clock.start()
        self.current.start()
        return True

    def cancel(self):
        """Stop the running render (nothing is written)."""
        if self.is_running():
            self.status.setText("Cancelling\u2026")
            self.current.cancel()

    def _set_running(self, running: bool):
        for w in (self.width_px, self.height_px, self.samples, self.format, self.alpha, self.denoise, self.path,
                  self.browse, self.render_button):
            w.setEnabled(not running)
        self.cancel_button.setEnabled(running)

    def _on_progress(self, render):
        if render is not self.current or render.done:
            return
        self.progress.setValue(int(render.progress * 1000))
        self.time_left.setText(f"Time left: {format_seconds(render.time_left())}")

    def _on_done(self, render):
        if render is not self.current:
            return
        self._set_running(False)
        preview = self.window.render_controller
        preview.hold(False)
        self.window.restart_render()
        if render.state == "written":
            self.progress.setValue(1000)
            message = f"Saved {render.path} in {render.seconds:.1f} s"
            self.open_button.setEnabled(True)
        elif render.state == "cancelled":
            message = "Cancelled; nothing was written"
        else:
            message = f"Failed: {render.error}"
        self.time_left.setText("")
        self.status.setText(message)
        self.ended.emit(render.state, message)

    def open_folder(self, folder: str) -> bool:
        """Show ``folder`` in the desktop's file manager (tests replace this method)."""
        return QDesktopServices.openUrl(QUrl.fromLocalFile(folder))

    # ----------------------------------------------------------------------- closing
    def shutdown(self, timeout: float = 60.0):
        """Cancel a running render and wait for its threads; safe to call twice."""
        render, self.current = self.current, None  # a late "done" signal is now ignored
        if render is not None:
            render.cancel()
            render.wait(timeout)  # returns once the render's job and callbacks have ended
        self.hide()

    def closeEvent(self, event):
        self.cancel()
        super().closeEvent(event)
