"""File > Export > CAD / glTF scene / Review page / Drawing: the command line's exports, in the
window.

Design rule: each action asks its options (the command line's: tolerance, liquid, poster
height, turntable, denoise, sheet) through :class:`ExportDialogs` and its target through the window's
``dialogs.ask_save_path``, both methods tests replace, then runs the engine's export (the same
function the command line calls, through :mod:`app.engine_bridge`) on a snapshot of the design
on a worker thread. The thread reports progress through a Qt signal, so the status bar's
progress bar moves on the GUI thread; the result comes back the same way: a status message, or
the engine's one-line refusal in an error dialog (a shape the CAD kernel rejects, a scene too
large for the tolerance, Node packages missing). The engine writes atomically, so a refused or
failed export leaves any earlier file whole. One export runs at a time.
"""
from __future__ import annotations

import threading
from pathlib import Path

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (QCheckBox, QComboBox, QDialog, QDialogButtonBox, QDoubleSpinBox,
                               QFileDialog, QFormLayout, QHBoxLayout, QLineEdit, QProgressBar,
                               QPushButton, QSpinBox, QWidget)

from app import engine_bridge
from engine.errors import GlassbenchError

#: What an export may raise on bad input, a shape the kernel refuses, a failing disk or a
#: package an export needs that is not installed.
EXPORT_ERRORS = (GlassbenchError, OSError, ValueError, KeyError, TypeError, ArithmeticError,
                 RuntimeError, ImportError)

#: The options of each export and their defaults (the command line's).
DEFAULTS = {"cad": {"tol_mm": 0.001, "liquid": True},
            "scene": {"tol_mm": 0.05},
            "review": {"tol_mm": 0.05, "poster_height": 640, "turntable": "", "denoise": False},
            "drawing": {"sheet": "A3"}}
TITLES = {"cad": "CAD", "scene": "glTF scene", "review": "review page", "drawing": "drawing"}
#: The paper sizes a drawing is laid out on.
SHEETS = ("A4", "A3")
#: The formats a drawing is written in (from the target's suffix; none typed: PDF).
DRAWING_SUFFIXES = (".pdf", ".svg", ".dxf")


class ExportOptionsDialog(QDialog):
    """The options of one export kind, laid out as a form (defaults from :data:`DEFAULTS`)."""

    def __init__(self, kind: str, parent=None):
        super().__init__(parent)
        self.setWindowTitle(f"Export {TITLES[kind]}")
        form = QFormLayout(self)
        self.fields = {}
        for key, value in DEFAULTS[kind].items():
            self.fields[key] = widget = self._field(key, value)
            form.addRow(self._label(kind, key), widget if key != "turntable" else self._browse(widget))
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    @staticmethod
    def _label(kind, key) -> str:
        if key == "tol_mm":
            return "Fit tolerance (mm)" if kind == "cad" else "Chordal tolerance (mm)"
        return {"liquid": "Liquid as its own solid", "poster_height": "Poster height (px)",
                "turntable": "Turntable frames", "denoise": "Denoise the poster", "sheet": "Sheet"}[key]

    @staticmethod
    def _field(key, value):
        if key == "tol_mm":
            w = QDoubleSpinBox()
            w.setDecimals(6)
            w.setRange(1e-6 if value < 0.01 else 0.001, 1.0 if value < 0.01 else 10.0)
            w.setValue(value)
            return w
        if isinstance(value, bool):  # liquid, denoise
            w = QCheckBox()
            w.setChecked(value)
            if key == "denoise":
                w.setToolTip("Write poster.png denoised (Intel Open Image Denoise) and keep the raw render "
                             "beside it as poster.raw.png; the page says which it shows")
            return w
        if key == "sheet":
            w = QComboBox()
            w.addItems(SHEETS)
            w.setCurrentText(value)
            w.setToolTip("The paper size the drawing is laid out on, at a scale that fits it")
            return w
        if key == "poster_height":
            w = QSpinBox()
            w.setRange(8, 4096)
            w.setValue(value)
            return w
        w = QLineEdit(value)
        w.setPlaceholderText("none (a folder of frame_0000.png ...)")
        return w

    def _browse(self, edit) -> QWidget:
        box = QWidget()
        row = QHBoxLayout(box)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(edit)
        button = QPushButton("Browse\u2026")
        button.clicked.connect(lambda: edit.setText(
            QFileDialog.getExistingDirectory(self, "Turntable frames") or edit.text()))
        row.addWidget(button)
        return box

    def values(self) -> dict:
        out = {}
        for key, w in self.fields.items():
            out[key] = (w.value() if isinstance(w, (QDoubleSpinBox, QSpinBox)) else
                        w.isChecked() if isinstance(w, QCheckBox) else
                        w.currentText() if isinstance(w, QComboBox) else w.text().strip())
        return out


class ExportDialogs:
    """The questions the exports ask besides the target path; replace the method in tests."""

    def __init__(self, parent):
        self.parent = parent

    def ask_options(self, kind: str) -> dict | None:
        """The options of export ``kind`` (``cad``, ``scene``, ``review``, ``drawing``), or ``None``."""
        dialog = ExportOptionsDialog(kind, self.parent)
        try:
            return dialog.values() if dialog.exec() == QDialog.Accepted else None
        finally:
            dialog.deleteLater()


class ExportActions(QObject):
    """The File > Export submenu of ``window`` and the exports it runs."""

    progressed = Signal(float, str)
    #: ``(ok, message)`` when an export ends (on the GUI thread).
    finished = Signal(bool, str)

    def __init__(self, window):
        super().__init__(window)
        self.window = window
        self.dialogs = ExportDialogs(window)
        self.thread: threading.Thread | None = None
        self.bar = QProgressBar()
        self.bar.setRange(0, 1000)
        self.bar.setMaximumWidth(160)
        self.bar.setToolTip("How far the export has come")
        self.bar.hide()
        window.statusBar().addPermanentWidget(self.bar)
        self.progressed.connect(self._on_progress)
        self.finished.connect(self._on_finished)
        self.actions = {}

    def build_menu(self, menu) -> None:
        sub = menu.addMenu("E&xport")
        for key, text in (("cad", "&CAD solid (STEP, IGES, BREP)\u2026"),
                          ("scene", "glTF &scene (.glb)\u2026"),
                          ("review", "&Review page\u2026"),
                          ("drawing", "&Drawing (PDF, SVG, DXF)\u2026")):
            act = QAction(text, self.window)
            act.triggered.connect(lambda _=False, k=key: self.export_dialog(k))
            sub.addAction(act)
            self.actions[key] = act

    # ---------------------------------------------------------------------- dialogs
    def export_dialog(self, kind: str) -> bool:
        """Ask the options and the target of export ``kind`` and start it; ``False`` if cancelled."""
        options = self.dialogs.ask_options(kind)
        if options is None:
            return False
        filters = {"cad": ("Export CAD", "CAD solids (*.step *.stp *.iges *.igs *.brep)", "bottle.step"),
                   "scene": ("Export glTF scene", "glTF binary (*.glb)", "bottle.glb"),
                   "review": ("Review page folder", "Folders (*)", "review"),
                   "drawing": ("Export drawing", "Drawings (*.pdf *.svg *.dxf);;PDF (*.pdf);;"
                               "SVG (*.svg);;DXF (*.dxf)", "bottle.pdf")}[kind]
        path = self.window.dialogs.ask_save_path(*filters)
        if path and kind == "drawing" and not Path(path).suffix:
            path += DRAWING_SUFFIXES[0]
        return bool(path) and self.start(kind, path, options)

    # -------------------------------------------------------------------- running
    def start(self, kind: str, path: str, options: dict) -> bool:
        """Run export ``kind`` to ``path`` with ``options`` on a worker thread."""
        if self.thread is not None and self.thread.is_alive():
            self.window.dialogs.show_error("Export already running",
                                           "Wait for the running export to finish.")
            return False
        design = self.window.scene.snapshot()
        assets = dict(engine_bridge.scene_assets(self.window.scene))
        work = {"cad": lambda p: engine_bridge.export_cad(design, path, options["tol_mm"],
                                                          options["liquid"], p),
                "scene": lambda p: engine_bridge.export_scene(design, assets, path, options["tol_mm"], p),
                "review": lambda p: engine_bridge.export_review_page(
                    design, assets, path, options["tol_mm"], options["poster_height"],
                    options["turntable"] or None, p, denoise=options["denoise"]),
                "drawing": lambda p: engine_bridge.export_drawing(design, path, options["sheet"], p)}[kind]
        self.bar.setValue(0)
        self.bar.show()
        self.window.statusBar().showMessage(f"Exporting {TITLES[kind]} to {path}\u2026")
        self.thread = threading.Thread(target=self._run, args=(kind, path, work),
                                       name=f"export-{kind}", daemon=True)
        self.thread.start()
        return True

    def _run(self, kind, path, work) -> None:
        try:
            work(lambda f, m: self.progressed.emit(float(f), str(m)))
        except EXPORT_ERRORS as exc:
            self.finished.emit(False, f"Cannot export {TITLES[kind]}\n{path}:\n{exc}")
            return
        self.finished.emit(True, f"Exported {TITLES[kind]} to {path}")

    def _on_progress(self, fraction: float, message: str) -> None:
        self.bar.setValue(int(round(1000 * min(max(fraction, 0.0), 1.0))))
        self.bar.setFormat(f"{message} %p%")

    def _on_finished(self, ok: bool, message: str) -> None:
        if self.thread is not None:
            self.thread.join()
        self.bar.hide()
        if ok:
            self.window.statusBar().showMessage(message, 8000)
            return
        title, _, text = message.partition("\n")
        self.window.statusBar().showMessage(title, 8000)
        self.window.dialogs.show_error(title, text)
