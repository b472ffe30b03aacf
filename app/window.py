"""The workbench main window: panels around the scene, menus, undo stack and document.

Design rule: data flows one way. Panels hand edits to the :class:`DesignEditor` (validated,
undoable commands); commands change the scene; the scene's notification (``changed`` = the
top-level Design fields that really changed) reaches :meth:`MainWindow.on_scene_changed`,
which refreshes only the views that depend on those fields.
"""
from __future__ import annotations

import sys


from PySide6.QtCore import QSettings, Qt
from PySide6.QtGui import QAction, QKeySequence, QUndoStack
from PySide6.QtWidgets import QDockWidget, QLabel, QMainWindow, QProgressBar, QSplitter

from app import engine_bridge
from app.commands import DesignEditor
from app.document import DocumentDialogs, RecentFiles
from app.file_actions import FileActions
from app.render_controller import RenderController
from app.wireframe_controller import DerivedController
from widgets.camera_panel import CameraPanel
from widgets.materials_panel import MaterialsPanel
from widgets.preview_view import PreviewView
from widgets.section_panel import SectionPanel
from widgets.trade_panel import TradeNumbersPanel



class MainWindow(QMainWindow):
    """The glassbench workbench for one design.

    Parameters
    ----------
    design, assets, path
        The design to open, its embedded assets and the file it came from (``None``: unsaved).
    settings
        Where recent files are remembered (default: the user's glassbench settings).
    wireframe
        Build the 3D wireframe view (tests of other parts may leave it out for speed).
    autosave_ms
        Autosave period; 0 switches autosave off.
    """

    def __init__(self, design, assets=None, path: str | None = None, *, settings: QSettings | None = None,
                 wireframe: bool = True, autosave_ms: int = 60_000, parent=None):
        super().__init__(parent)
        # why: worker threads (tracer, wireframe) hold the GIL in numpy-heavy stretches; a short
        # switch interval hands it back to the GUI thread quickly, so drags stay smooth.
        sys.setswitchinterval(min(sys.getswitchinterval(), 0.001))
        self.setAttribute(Qt.WA_DeleteOnClose, False)
        self.resize(1500, 950)
        self.scene = engine_bridge.make_scene(design, assets)
        self.undo_stack = QUndoStack(self)
        self.editor = DesignEditor(self.scene, self.undo_stack, self)
        self.dialogs = DocumentDialogs(self)
        self.recent = RecentFiles(settings)
        self.trade_numbers: dict = {}

        self.section_panel = SectionPanel(self.editor)
        self.materials_panel = MaterialsPanel(self.editor)
        self.trade_panel = TradeNumbersPanel()
        self.camera_panel = CameraPanel(self.editor)
        self.preview = PreviewView()
        self.derived_controller = DerivedController(self)
        self.derived_controller.resultReady.connect(self._on_derived)
        self.derived_controller.failed.connect(lambda msg: self.statusBar().showMessage(msg, 5000))
        self.render_controller = RenderController(self)
        self.render_controller.tileReady.connect(self._on_tile)
        self.render_controller.progressed.connect(self._on_render_progress)
        self.render_controller.failed.connect(self._on_render_failed)
        self.render_controller.finished.connect(self._on_render_finished)

        self.final_render = None  # the Render -> Final image dialog, made when first asked for
        self.wireframe = None
        if wireframe:
            from app.wireframe_controller import WireframeController
            from widgets.wireframe_view import WireframeView
            self.wireframe = WireframeView()
            self.wireframe_controller = WireframeController(self)
            self.wireframe_controller.meshReady.connect(self.wireframe.show_lines)
            self.wireframe_controller.failed.connect(lambda msg: self.statusBar().showMessage(msg, 5000))
            self.camera_panel.syncFromWireframe.connect(self.camera_from_wireframe)

        views = QSplitter(Qt.Horizontal)
        views.addWidget(self.preview)
        if self.wireframe is not None:
            views.addWidget(self.wireframe)
        self.views = views
        self.preview.orbitRequested.connect(self._orbit_from_preview)
        self._orbit_start = None
        self.setCentralWidget(views)
        self.section_dock = self._dock("Section", self.section_panel, Qt.LeftDockWidgetArea)
        self._dock("Materials", self.materials_panel, Qt.RightDockWidgetArea)
        self._dock("Trade numbers", self.trade_panel, Qt.RightDockWidgetArea)
        self._dock("Camera and environment", self.camera_panel, Qt.RightDockWidgetArea)
        self.section_dock.setMinimumWidth(560)

        self.files = FileActions(self, path, autosave_ms)
        self._build_menus()
        self.section_panel.canvas.dragging.connect(self.render_controller.hold)
        # Render state lives in permanent widgets so edit messages do not hide it.
        self.render_state = QLabel("")
        self.render_progress = QProgressBar()
        self.render_progress.setRange(0, 100)
        self.render_progress.setMaximumWidth(160)
        self.statusBar().addPermanentWidget(self.render_state)
        self.statusBar().addPermanentWidget(self.render_progress)
        self.editor.refused.connect(self._on_refused)
        self.undo_stack.cleanChanged.connect(lambda clean: self.setWindowModified(not clean))
        self._unsubscribe = self.scene.subscribe(self.on_scene_changed)
        self.on_scene_changed(engine_bridge.ALL_CHANGES, self.scene)
        self.files.update_title()

    def _dock(self, title, widget, area) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(title)
        dock.setWidget(widget)
        self.addDockWidget(area, dock)
        return dock

    # ------------------------------------------------------------------------- menus
    def _build_menus(self):
        self.files.build_menu(self.menuBar().addMenu("&File"))
        edit = self.menuBar().addMenu("&Edit")
        self.undo_action = self.undo_stack.createUndoAction(self, "&Undo")
        self.undo_action.setShortcut(QKeySequence.Undo)
        self.redo_action = self.undo_stack.createRedoAction(self, "&Redo")
        self.redo_action.setShortcut(QKeySequence.Redo)
        edit.addAction(self.undo_action)
        edit.addAction(self.redo_action)
        view = self.menuBar().addMenu("&View")
        for text, slot, key in (("Preview 1:1", self.preview.zoom_one_to_one, "Ctrl+1"),
                                ("Preview fit", self.preview.zoom_fit, "Ctrl+0"),
                                ("Restart render", self.restart_render, "F5")):
            act = QAction(text, self)
            act.setShortcut(QKeySequence(key))
            act.triggered.connect(slot)
            view.addAction(act)
        for dock in self.findChildren(QDockWidget):
            view.addAction(dock.toggleViewAction())
        render = self.menuBar().addMenu("&Render")
        self.final_image_action = QAction("&Final image\u2026", self)
        self.final_image_action.setShortcut(QKeySequence("Ctrl+Shift+R"))
        self.final_image_action.triggered.connect(self.show_final_render)
        render.addAction(self.final_image_action)

    def show_final_render(self):
        """Open (or raise) the Final image dialog; returns it."""
        if self.final_render is None:
            from app.final_render import FinalRenderDialog
            self.final_render = FinalRenderDialog(self)
        self.final_render.show()
        self.final_render.raise_()
        return self.final_render

    # ------------------------------------------------------------------ notifications
    def on_scene_changed(self, changed, scene=None):
        """Refresh what depends on ``changed`` (a set of Design field names)."""
        design = self.scene.design
        if changed & {"shape", "liquid", "glass"}:
            self.derived_controller.request(design)  # trade numbers, inner walls: off-thread
        if changed & {"shape", "liquid"}:
            self.section_panel.refresh(design)
        if changed & {"glass", "liquid"}:
            self.materials_panel.refresh(design)
        if changed & {"camera", "environment", "render"}:
            self.camera_panel.refresh(design)
        if "shape" in changed and self.wireframe is not None:
            self.wireframe_controller.request(design.shape)
        if changed - {"name", "notes"}:
            self.restart_render()

    def _on_refused(self, message: str):
        """A refused edit: say why, and put the widget that asked for it back to the model."""
        self.statusBar().showMessage(f"Refused: {message}", 8000)
        design = self.scene.design
        self.materials_panel.refresh(design)
        self.camera_panel.refresh(design)

    def _on_derived(self, result):
        design, numbers, inner = result
        self.trade_numbers = numbers
        self.materials_panel.trade_numbers = numbers
        self.trade_panel.refresh(numbers)
        fill_z = numbers.get("fill_height_mm") if design.liquid is not None else None
        self.section_panel.set_derived(inner, fill_z)

    def derived_idle(self) -> bool:
        """Whether the trade numbers and inner walls shown are those of the current design."""
        return self.derived_controller.is_idle()

    def restart_render(self):
        self.render_controller.start(self.scene.snapshot(), engine_bridge.scene_assets(self.scene))

    def _on_tile(self, generation, x0, y0, tile_rgb8):
        self.preview.paint_tile(x0, y0, tile_rgb8)

    def _on_render_progress(self, generation, fraction, width, height):
        if self.preview.image_size() != (width, height):
            self.preview.reset(width, height)
        self.render_progress.setValue(int(round(fraction * 100)))
        self.render_state.setText(f"Rendering {width}\u00d7{height}")

    def _on_render_finished(self, generation):
        self.render_progress.setValue(100)
        self.render_state.setText("Render converged")

    def _on_render_failed(self, generation, message):
        self.render_state.setText("Render failed")
        self.statusBar().showMessage(f"Render failed: {message}")

    def _orbit_from_preview(self, d_azimuth, d_elevation, finished):
        """A drag in the preview orbits the design camera (one undo step per drag)."""
        if finished:
            self._orbit_start = None
            return
        if self._orbit_start is None:
            self._orbit_start = (self.scene.design.camera, self.editor.new_merge_key("orbit"))
        start, key = self._orbit_start
        self.editor.apply("Orbit camera", key, camera=engine_bridge.orbited(start, d_azimuth, d_elevation))

    def camera_from_wireframe(self):
        """Copy the 3D view's camera into the design (one undo step)."""
        if self.wireframe is None:
            return
        cam = self.wireframe.current_camera(self.scene.design.camera)
        self.editor.apply("Camera from 3D view", None, camera=cam)

    # ---------------------------------------------------------------------- closing
    def closeEvent(self, event):
        if not self.files.may_discard():
            event.ignore()
            return
        self.shutdown()
        event.accept()

    def shutdown(self):
        """Stop workers, timers and observers; safe to call twice."""
        self.files.shutdown()
        if self.final_render is not None:
            self.final_render.shutdown()
        self.derived_controller.shutdown()
        self.render_controller.shutdown()
        if self.wireframe is not None:
            self.wireframe_controller.shutdown()
            self.wireframe.shutdown()
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None


__all__ = ["MainWindow"]
