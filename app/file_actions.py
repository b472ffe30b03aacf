"""The File menu of the workbench: new, open, save, recent files, import, export, autosave.

Design rule: every action reports failure as a dialog (``window.dialogs.show_error``) or a
status message and leaves the open document as it was; nothing here can leave a dead window.
Opening or creating a document replaces the scene's design and assets in one notification and
clears the undo history; saving marks the undo stack clean, which clears the title's ``*``.
"""
from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QObject, QTimer
from PySide6.QtGui import QAction, QKeySequence

from app import engine_bridge
from app.document import PROJECT_FILTER, Autosaver, orphaned_autosaves
from app.sample_design import built_in_design
from engine.errors import GlassbenchError

#: Errors an engine file operation may raise on bad input or a failing disk.
FILE_ERRORS = (GlassbenchError, OSError, ValueError, KeyError, TypeError)


class FileActions(QObject):
    """File operations for ``window`` (a :class:`app.window.MainWindow`)."""

    def __init__(self, window, path: str | None, autosave_ms: int):
        super().__init__(window)
        self.window = window
        self.path = path
        self.autosaver = Autosaver()
        self.autosave_timer = QTimer(self)
        self.autosave_timer.setInterval(max(autosave_ms, 1))
        self.autosave_timer.timeout.connect(self.autosave_now)
        if autosave_ms > 0:
            self.autosave_timer.start()
        self.recent_menu = None

    # ------------------------------------------------------------------------ menu
    def build_menu(self, menu):
        w = self.window
        for text, slot, key in (("&New", self.new_design, QKeySequence.New),
                                ("&Open\u2026", self.open_dialog, QKeySequence.Open),
                                ("&Save", self.save, QKeySequence.Save),
                                ("Save &As\u2026", self.save_as, QKeySequence.SaveAs)):
            act = QAction(text, w)
            act.setShortcut(key)
            act.triggered.connect(slot)
            menu.addAction(act)
        self.recent_menu = menu.addMenu("Open &Recent")
        self.recent_menu.aboutToShow.connect(self._fill_recent)
        menu.addSeparator()
        for text, slot in (("Import &DXF section\u2026", self.import_dxf_dialog),
                           ("Export &image\u2026", self.export_image_dialog),
                           ("Export &mesh\u2026", self.export_mesh_dialog)):
            act = QAction(text, w)
            act.triggered.connect(slot)
            menu.addAction(act)
        from app.export_actions import ExportActions  # File > Export: CAD, glTF scene, review page
        self.exports = ExportActions(w)
        self.exports.build_menu(menu)
        menu.addSeparator()
        quit_action = QAction("&Quit", w)
        quit_action.setShortcut(QKeySequence.Quit)
        quit_action.triggered.connect(w.close)
        menu.addAction(quit_action)

    def _fill_recent(self):
        self.recent_menu.clear()
        for path in self.window.recent.paths():
            act = self.recent_menu.addAction(path)
            act.triggered.connect(lambda _=False, p=path: self.open_path(p))
        if not self.recent_menu.actions():
            self.recent_menu.addAction("(none)").setEnabled(False)

    def update_title(self):
        name = Path(self.path).name if self.path else f"{self.window.scene.design.name} (unsaved)"
        self.window.setWindowTitle(f"{name}[*] \u2014 glassbench")
        self.window.setWindowModified(not self.window.undo_stack.isClean())

    # ------------------------------------------------------------------- documents
    def may_discard(self) -> bool:
        """``True`` when the current document may be replaced or closed (asks if dirty)."""
        if self.window.undo_stack.isClean():
            return True
        answer = self.window.dialogs.ask_unsaved()
        if answer == "save":
            return self.save()
        return answer == "discard"

    def replace_document(self, design, assets, path: str | None, dirty: bool = False):
        """Show ``design`` as the open document (clears undo history)."""
        w = self.window
        w.scene.load(design, assets)  # one notification for design and assets
        w.undo_stack.clear()
        if dirty:
            w.undo_stack.resetClean()
        else:
            w.undo_stack.setClean()
        self.path = path
        self.update_title()
        w.setWindowModified(dirty)
        w.document_replaced()

    def new_design(self) -> bool:
        if not self.may_discard():
            return False
        self.replace_document(built_in_design(), {}, None)
        self.window.statusBar().showMessage("New design", 3000)
        return True

    def open_dialog(self) -> bool:
        if not self.may_discard():
            return False
        path = self.window.dialogs.ask_open_path("Open project", PROJECT_FILTER)
        return bool(path) and self.open_path(path, ask=False)

    def open_path(self, path: str, ask: bool = True) -> bool:
        """Open the project at ``path``; on failure report it and keep the current document."""
        if ask and not self.may_discard():
            return False
        try:
            design, assets = engine_bridge.load_project(path)
        except FILE_ERRORS as exc:
            self.window.dialogs.show_error("Cannot open project", f"{path}:\n{exc}")
            self.window.statusBar().showMessage(f"Could not open {path}", 8000)
            return False
        self.replace_document(design, dict(assets), str(path))
        self.window.recent.add(str(path))
        self.window.statusBar().showMessage(f"Opened {path}", 4000)
        return True

    def save(self) -> bool:
        return self.save_to(self.path) if self.path else self.save_as()

    def save_as(self) -> bool:
        path = self.window.dialogs.ask_save_path("Save project", PROJECT_FILTER, self.path or "")
        if not path:
            return False
        if not path.endswith(".glassbench"):
            path += ".glassbench"
        return self.save_to(path)

    def save_to(self, path: str) -> bool:
        w = self.window
        try:
            engine_bridge.save_project(path, w.scene.snapshot(), engine_bridge.scene_assets(w.scene))
        except FILE_ERRORS as exc:
            w.dialogs.show_error("Cannot save project", f"{path}:\n{exc}")
            return False
        self.path = str(path)
        w.undo_stack.setClean()
        self.autosaver.discard()
        w.recent.add(self.path)
        self.update_title()
        w.statusBar().showMessage(f"Saved {path}", 4000)
        return True

    # ------------------------------------------------------------- import / export
    def import_dxf_dialog(self) -> bool:
        path = self.window.dialogs.ask_open_path("Import DXF section", "DXF drawings (*.dxf)")
        return bool(path) and self.import_dxf(path)

    def import_dxf(self, path: str) -> bool:
        """Replace the bottle's shape by the section in a DXF file (one undo step)."""
        w = self.window
        try:
            design = engine_bridge.import_dxf(path, w.scene.design)
        except FILE_ERRORS as exc:
            w.dialogs.show_error("Cannot import DXF", f"{path}:\n{exc}")
            return False
        return w.editor.apply(f"Import {Path(path).name}", None, shape=design.shape)

    def export_image_dialog(self) -> bool:
        path = self.window.dialogs.ask_save_path("Export image", "Images (*.png *.jpg *.tif)", "render.png")
        return bool(path) and self.export_image(path)

    def export_image(self, path: str) -> bool:
        try:  # atomic: a full disk never leaves a truncated image in place of the old one
            with engine_bridge.replace_file_atomically(path, Path(path).suffix) as tmp:
                if not self.window.preview.image().save(tmp):
                    raise OSError(f"could not write {path}")
        except OSError as exc:
            self.window.dialogs.show_error("Cannot export image", str(exc) or f"could not write {path}")
            return False
        self.window.statusBar().showMessage(f"Exported {path}", 4000)
        return True

    def export_mesh_dialog(self) -> bool:
        path = self.window.dialogs.ask_save_path(
            "Export mesh", "Meshes (*.stl *.obj *.ply *.glb *.gltf)", "bottle.stl")
        return bool(path) and self.export_mesh(path)

    def export_mesh(self, path: str) -> bool:
        try:
            engine_bridge.export_mesh(self.window.scene.design.shape, path)
        except FILE_ERRORS as exc:
            self.window.dialogs.show_error("Cannot export mesh", f"{path}:\n{exc}")
            return False
        self.window.statusBar().showMessage(f"Exported {path}", 4000)
        return True

    # -------------------------------------------------------------------- autosave
    def autosave_now(self) -> bool:
        """Write unsaved work to the recovery file; ``False`` when there was nothing to do."""
        w = self.window
        if w.undo_stack.isClean():
            return False
        try:
            self.autosaver.write(w.scene.snapshot(), engine_bridge.scene_assets(w.scene), self.path)
        except FILE_ERRORS as exc:
            w.statusBar().showMessage(f"Autosave failed: {exc}", 8000)
            return False
        return True

    def offer_recovery(self) -> bool:
        """If a crashed session left unsaved work, offer it; ``True`` when it was recovered."""
        for autosave in orphaned_autosaves():
            original = Autosaver.original_of(autosave)
            description = f"{original or 'an unsaved design'} (autosaved {autosave.name})"
            if not self.window.dialogs.ask_recover(description):
                Autosaver.remove(autosave)
                continue
            try:
                design, assets = engine_bridge.load_project(str(autosave))
            except FILE_ERRORS as exc:
                self.window.dialogs.show_error("Cannot recover", str(exc))
                Autosaver.remove(autosave)
                continue
            self.replace_document(design, dict(assets), original, dirty=True)
            Autosaver.remove(autosave)
            self.autosave_now()
            return True
        return False

    def shutdown(self):
        self.autosave_timer.stop()
        self.autosaver.discard()
