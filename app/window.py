"""The workbench main window: panels around the scene, menus, undo stack and document.

Design rule: data flows one way. Panels hand edits to the :class:`DesignEditor` (validated,
undoable commands); commands change the scene; the scene's notification (``changed`` = the
top-level Design fields that really changed) reaches :meth:`MainWindow.on_scene_changed`,
which refreshes only the views that depend on those fields. The panels are one table
(:data:`app.layout.PANELS`) and each follows the scene, the editor's refusals and the numbers
derived off the GUI thread itself (:func:`widgets.edit_fields.follow`): the window routes
nothing to them, it only relays the derived numbers to the editor's ``derived`` signal. Where
the panes sit is :mod:`app.layout`'s; undo and redo from any field are :mod:`app.edit_keys`';
the preview's renders are :mod:`app.render_controller`'s, at the preview pane's size in device
pixels.
"""
from __future__ import annotations

import sys

from PySide6.QtCore import QEvent, QObject, QSettings, Qt, QTimer
from PySide6.QtGui import QAction, QKeySequence, QUndoStack
from PySide6.QtWidgets import QDockWidget, QLabel, QMainWindow, QProgressBar

from app import engine_bridge, layout
from app.engine_bridge import DERIVED_FROM, UNSEEN_FIELDS
from app.commands import DesignEditor
from app.document import DocumentDialogs, RecentFiles
from app.edit_keys import UndoKeys
from app.file_actions import FileActions
from app.render_controller import RenderController
from app.wireframe_controller import DerivedController
from widgets.preview_view import PreviewView

#: Most pixels a preview render may have (a 4K pane would otherwise ask for 8 million).
MAX_PREVIEW_PIXELS = 3_000_000
#: How long (ms) the pane's size must hold still before the preview renders at the new size.
RESIZE_SETTLE_MS = 250
STATE_TEXT = {"stale": "Stale: a quick pass while you drag; the full render follows on release",
              "refining": "Refining", "denoised": "Denoised preview", "retinted": "Retinted preview",
              "converged": "Converged",
              "failed": "Render failed",
              "idle": ""}


class _PaneWatcher(QObject):
    """Tells the window when the preview pane is shown or changes size."""

    def __init__(self, window):
        super().__init__(window)
        self.window = window

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        if event.type() in (QEvent.Resize, QEvent.Show):
            self.window.resize_timer.start()
        return False


def capped_note(capped: int, pixels: int) -> str:
    """The status bar's note on the pixels a render's sample cap stopped above its tolerance
    (:attr:`engine.tracer.job.RenderJob.capped`): their share of the image, or their number
    when that share would read 0.0 %; empty when there are none."""
    if not capped:
        return ""
    share = 100.0 * capped / max(1, pixels)
    return f" ({share:.1f} % of pixels at the sample cap)" if share >= 0.05 else f" ({capped} pixels at the sample cap)"


class MainWindow(QMainWindow):
    """The glassbench workbench for one design.

    Parameters
    ----------
    design, assets, path
        The design to open, its embedded assets and the file it came from (``None``: unsaved).
    settings
        Where recent files and the layout are remembered (default: the user's settings).
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
        self.settings = settings or QSettings("glassbench", "glassbench")
        self.scene = engine_bridge.make_scene(design, assets)
        self.undo_stack = QUndoStack(self)
        self.editor = DesignEditor(self.scene, self.undo_stack, self)
        self.dialogs = DocumentDialogs(self)
        self.recent = RecentFiles(self.settings)
        self.trade_numbers: dict = {}
        self.plant_numbers: dict | None = None  # engine.plant.sheet's dict of the design shown
        self.warnings: list[str] = []

        layout.make_panels(self)  # section_panel, trade_panel, ... (app.layout.PANELS)
        self.preview = PreviewView()
        # why: the 3D view is a QOpenGLWidget, which makes Qt compose the whole window with
        # OpenGL, so each tile the preview painted recomposed 1600 x 1000 pixels (in software GL
        # here: 0.8 s of CPU an edit, taken from the render's workers). A native window of its
        # own is flushed alone.
        self.preview.setAttribute(Qt.WA_NativeWindow)
        self.derived_controller = DerivedController(self)
        self.derived_controller.resultReady.connect(self.editor.derived)  # the panels follow them
        self.editor.derived.connect(self._on_derived)
        self.derived_controller.failed.connect(self._show_status)
        self.render_controller = RenderController(self)
        self.render_controller.tileReady.connect(self._on_tile)
        self.render_controller.progressed.connect(self._on_render_progress)
        self.render_controller.failed.connect(self._on_render_failed)
        self.render_controller.stateChanged.connect(self._on_render_state)

        self.final_render = None  # the Render -> Final image dialog, made when first asked for
        self.wireframe = None
        if wireframe:
            from app.wireframe_controller import WireframeController
            from widgets.wireframe_view import WireframeView
            self.wireframe = WireframeView()
            self.wireframe_controller = WireframeController(self)
            self.wireframe_controller.meshReady.connect(self.wireframe.show_lines)
            self.wireframe_controller.failed.connect(self._show_status)
            self.camera_panel.syncFromWireframe.connect(self.camera_from_wireframe)
        self.docks = layout.build_docks(self)
        self.section_dock = self.docks["section"]
        self._restored = layout.restore(self, self.settings)
        if not self._restored:
            layout.fit_to_screen(self)
        self.preview.orbitRequested.connect(self._orbit_from_preview)
        self.preview.orbiting.connect(self.render_controller.hold)
        self.preview.imageDropped.connect(self.add_label_at)
        self.preview.placeRequested.connect(self._place_from_preview)
        self.preview.sizeRequested.connect(self._size_from_preview)
        self._place_key = None
        self.labels_panel.message.connect(self._show_status)
        self.bumps_panel.message.connect(self._show_status)
        self._orbit_start = None
        self.resize_timer = QTimer(self)
        self.resize_timer.setSingleShot(True)
        self.resize_timer.setInterval(RESIZE_SETTLE_MS)
        self.resize_timer.timeout.connect(self.update_render_size)
        self.preview.installEventFilter(_PaneWatcher(self))

        self.files = FileActions(self, path, autosave_ms)
        self.undo_keys = UndoKeys(self, self.undo_stack)
        self.undo_action, self.redo_action = self.undo_keys.undo_action, self.undo_keys.redo_action
        self._build_menus()
        self.section_panel.canvas.dragging.connect(self.render_controller.hold)
        # Render state lives in permanent widgets so edit messages do not hide it.
        self.render_state = QLabel("")
        self.render_progress = QProgressBar()
        self.render_progress.setRange(0, 100)
        self.render_progress.setMaximumWidth(160)
        self.render_progress.setToolTip("How far the preview's render has come")
        self.statusBar().addPermanentWidget(self.render_state)
        self.statusBar().addPermanentWidget(self.render_progress)
        self.editor.refused.connect(self._on_refused)
        self.editor.adjusted.connect(lambda text: self._show_status(text, 8000))
        self.undo_stack.cleanChanged.connect(self._on_clean_changed)
        self._unsubscribe = self.scene.subscribe(self.on_scene_changed)
        self.on_scene_changed(engine_bridge.ALL_CHANGES, self.scene)
        self.files.update_title()

    # ------------------------------------------------------------------------- menus
    def _build_menus(self):
        self.files.build_menu(self.menuBar().addMenu("&File"))
        self.edit_menu = self.menuBar().addMenu("&Edit")
        self.undo_keys.attach_menu(self.edit_menu)
        view = self.menuBar().addMenu("&View")
        for text, slot, key in (("Preview 1:1", self.preview.zoom_one_to_one, "Ctrl+1"),
                                ("Preview fit", self.preview.zoom_fit, "Ctrl+0"),
                                ("Restart render", lambda: self.restart_render(), "F5")):
            act = QAction(text, self)
            act.setShortcut(QKeySequence(key))
            act.triggered.connect(slot)
            view.addAction(act)
        self.raw_preview_action = QAction("Raw preview (no denoiser)", self)
        self.raw_preview_action.setCheckable(True)
        self.raw_preview_action.setToolTip("Show the tracer's film as it is, without the denoised estimate")
        self.raw_preview_action.toggled.connect(lambda raw: self.render_controller.set_denoise(not raw))
        view.addAction(self.raw_preview_action)
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

    def showEvent(self, event):
        super().showEvent(event)
        if not self._restored:  # why here: dock sizes take only once the window is laid out
            self._restored = True
            layout.default_sizes(self, self.docks)

    # ------------------------------------------------------------------ notifications
    def on_scene_changed(self, changed, scene=None):
        """Refresh what the window itself shows of ``changed`` (a
        :class:`~engine.model.changes.Change`): the derived numbers, the 3D view, the render.
        The panels follow the scene for the fields they show (their ``FIELDS``)."""
        design = self.scene.design
        self.section_panel.clear_problem()  # a refusal was about the design before this change
        if self.statusBar().currentMessage().startswith("Refused"):
            self.statusBar().clearMessage()
        if changed & DERIVED_FROM:
            self.derived_controller.request(design)  # trade and plant numbers, inner walls: off-thread
        if self.wireframe is not None:
            if changed & {"shape", "cap", "bumps"}:  # a closure follows the finish and its thread
                self.wireframe_controller.request(design)
            if "camera" in changed:
                self.wireframe.set_camera(design.camera)  # the 3D view looks through the design's camera
        if "render" in changed:
            self.update_render_size(restart=False)
        if changed - UNSEEN_FIELDS:
            self.restart_render(changed)

    def document_replaced(self):
        """A design was opened or started: fit the section to it, offer nothing about its name."""
        self.section_panel.canvas.request_fit()
        self.trade_panel.forget_offer()

    def _show_status(self, text: str, ms: int = 5000):
        self.statusBar().showMessage(text, ms)

    def _on_clean_changed(self, clean: bool):
        self.setWindowModified(not clean)

    def _on_refused(self, message: str):
        """A refused edit: say why, and put the widget that asked for it back to the model."""
        self.statusBar().showMessage(f"Refused: {message}", 8000)

    def _on_derived(self, result):
        """Keep the newest :class:`~app.wireframe_controller.Derived`'s trade and plant numbers
        and warnings (the panels show them themselves)."""
        self.trade_numbers = result.numbers
        self.plant_numbers = result.plant
        self.warnings = list(result.warnings)

    def derived_idle(self) -> bool:
        """Whether the trade and plant numbers and inner walls shown are those of the current
        design."""
        return self.derived_controller.is_idle()

    # --------------------------------------------------------------------- preview
    def update_render_size(self, restart: bool = True):
        """Render at the preview pane's size in device pixels (in the design's image shape),
        or at the design's own size while the pane is not on screen."""
        rc, design = self.render_controller, self.scene.design
        size = None
        if self.preview.isVisible():
            size = layout.preview_size(self.preview.pane_pixels(), design.render.width,
                                       design.render.height, MAX_PREVIEW_PIXELS)
        if size != rc.wanted_size:
            rc.set_size(size)
            if restart:
                self.restart_render()

    def restart_render(self, changed=None):
        """Render the current design; ``changed`` what the scene announced (module rule of
        :mod:`app.render_controller`)."""
        self.render_controller.start(self.scene.snapshot(), engine_bridge.scene_assets(self.scene), changed)

    def _on_tile(self, generation, x0, y0, tile_rgb8):
        self.preview.paint_tile(x0, y0, tile_rgb8)

    def _on_render_progress(self, generation, fraction, width, height):
        if self.preview.image_size() != (width, height):
            self.preview.reset(width, height)

    def _on_render_state(self, state: str, wave: int, fraction: float):
        rc = self.render_controller
        text = STATE_TEXT.get(state, state)
        if state == "refining" and wave >= 0:
            text = f"Refining (wave {wave}) {int(fraction * 100)} %"
        elif state == "denoised":  # an estimate: never called converged
            n = max(1, round(rc.denoised_samples))
            text = f"Denoised preview \u00b7 {n} sample{'' if n == 1 else 's'}"
        elif state == "retinted":  # the last converged image in the new colour: an estimate too
            n = max(1, round(rc.denoised_samples))
            text = f"Retinted preview (the last image, new colour) \u00b7 {n} sample{'' if n == 1 else 's'}"
        elif state == "converged":
            text = f"Converged {rc.size[0]}\u00d7{rc.size[1]}"
            text += capped_note(getattr(rc.job, "capped", 0), rc.size[0] * rc.size[1])
        self.render_state.setText(text)
        self.render_progress.setValue(int(round(fraction * 100)))
        self.preview.set_note({"stale": "stale: live pass", "refining": "refining",
                               "denoised": "denoised preview", "retinted": "retinted preview"}.get(state, ""))

    def _on_render_failed(self, generation, message):
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

    def _surface_at(self, image_xy):
        """``(z_mm, angle_deg)`` on the bottle under render pixel ``image_xy``, or ``None``."""
        size = self.preview.image_size()
        if image_xy is None or size[0] <= 0 or size[1] <= 0:
            return None
        return engine_bridge.surface_point(self.scene.design, image_xy[0] / size[0], image_xy[1] / size[1])

    def add_label_at(self, path: str, image_xy):
        """An image file dropped on the preview at ``image_xy`` (render pixels, or ``None``):
        a label with it as artwork where that point meets the bottle (facing the camera at
        mid-height when it misses the glass); one undo step."""
        self.docks["labels"].raise_()
        return self.labels_panel.add_label(path, self._surface_at(image_xy))

    def _place_from_preview(self, image_xy, finished: bool):
        """A Shift+drag in the preview moves the selected label's centre to the point under the
        pointer."""
        self._label_drag("place-label", self.labels_panel.place_selected, image_xy, finished)

    def _size_from_preview(self, image_xy, finished: bool):
        """A Ctrl+Shift+drag in the preview sizes the selected label, kept centred, so that a
        corner is at the point under the pointer."""
        self._label_drag("size-label", self.labels_panel.size_selected, image_xy, finished)

    def _label_drag(self, name, apply, image_xy, finished: bool):
        """One step of a label drag on the preview: ``apply((z_mm, angle_deg), merge key)`` at
        the surface point under ``image_xy`` (points off the glass are skipped); a whole drag
        is one undo step."""
        if finished:
            self._place_key = None
            return
        if self._place_key is None:
            self._place_key = self.editor.new_merge_key(name)
        at = self._surface_at(image_xy)
        if at is not None:
            apply(at, self._place_key)

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
        layout.save(self, self.settings)
        self.shutdown()
        event.accept()

    def shutdown(self):
        """Stop workers, timers and observers; safe to call twice."""
        self.files.shutdown()
        self.resize_timer.stop()
        if self.final_render is not None:
            self.final_render.shutdown()
        self.derived_controller.shutdown()
        self.render_controller.shutdown()
        if self.wireframe is not None:
            self.wireframe_controller.shutdown()
            self.wireframe.shutdown()
        self.undo_keys.shutdown()
        self.labels_panel.shutdown()
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
            # why: the stack is deleted with the window at exit and announces that it is clean;
            # nothing of the window may answer then
            self.undo_stack.cleanChanged.disconnect(self._on_clean_changed)


__all__ = ["MainWindow"]
