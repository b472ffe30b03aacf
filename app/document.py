"""The open document: file path, dirty state, recent files, autosave and crash recovery.

Design rule: the window asks questions only through the ``ask_*`` / ``show_error`` methods of
:class:`DocumentDialogs`, which tests replace, so no test ever blocks on a modal dialog. The
dirty state is the undo stack's clean state. Autosave writes, on a timer, a copy of unsaved work
to ``<AppDataLocation>/recovery/autosave-<pid>.glassbench`` (plus a small JSON note naming the
original file); a clean exit removes it, so a copy left behind means a crash, and the next start
offers it back.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from PySide6.QtCore import QSettings, QStandardPaths
from PySide6.QtWidgets import QFileDialog, QMessageBox

from app import engine_bridge

PROJECT_FILTER = "glassbench projects (*.glassbench)"
MAX_RECENT = 8


class DocumentDialogs:
    """Every question the document asks; replace the methods in tests."""

    def __init__(self, parent):
        self.parent = parent

    def ask_open_path(self, title: str, name_filter: str) -> str | None:
        path, _ = QFileDialog.getOpenFileName(self.parent, title, "", name_filter)
        return path or None

    def ask_save_path(self, title: str, name_filter: str, suggestion: str = "") -> str | None:
        path, _ = QFileDialog.getSaveFileName(self.parent, title, suggestion, name_filter)
        return path or None

    def ask_unsaved(self) -> str:
        """``"save"``, ``"discard"`` or ``"cancel"`` for a document with unsaved changes."""
        answer = QMessageBox.question(
            self.parent, "Unsaved changes", "The design has unsaved changes. Save them first?",
            QMessageBox.Save | QMessageBox.Discard | QMessageBox.Cancel, QMessageBox.Save)
        return {QMessageBox.Save: "save", QMessageBox.Discard: "discard"}.get(answer, "cancel")

    def ask_recover(self, description: str) -> bool:
        answer = QMessageBox.question(
            self.parent, "Recover unsaved work",
            f"glassbench found unsaved work from a session that did not close:\n{description}\n"
            "Recover it?", QMessageBox.Yes | QMessageBox.No, QMessageBox.Yes)
        return answer == QMessageBox.Yes

    def show_error(self, title: str, text: str):
        QMessageBox.warning(self.parent, title, text)


def recovery_dir() -> Path:
    """Where autosaved copies live (created on demand)."""
    base = QStandardPaths.writableLocation(QStandardPaths.AppDataLocation) or str(Path.home() / ".glassbench")
    path = Path(base) / "recovery"
    path.mkdir(parents=True, exist_ok=True)
    return path


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, ValueError):
        return False
    except PermissionError:
        return True
    return True


def orphaned_autosaves() -> list[Path]:
    """Autosave files left by sessions that are no longer running, newest first."""
    found = []
    for path in recovery_dir().glob("autosave-*.glassbench"):
        try:
            pid = int(path.stem.split("-", 1)[1])
        except ValueError:
            continue
        if not _pid_alive(pid):
            found.append(path)
    return sorted(found, key=lambda p: p.stat().st_mtime, reverse=True)


class Autosaver:
    """Writes unsaved work to this process's recovery file; removes it when told."""

    def __init__(self):
        self.path = recovery_dir() / f"autosave-{os.getpid()}.glassbench"
        self.note = self.path.with_suffix(".json")

    def write(self, design, assets, original_path: str | None):
        # No backup: the recovery copy is itself the spare, and a .bak would outlive discard().
        engine_bridge.save_project(str(self.path), design, assets, keep_backup=False)
        self.note.write_text(json.dumps({"original": original_path, "name": design.name}))

    def discard(self):
        self.remove(self.path)

    @staticmethod
    def original_of(autosave: Path) -> str | None:
        note = autosave.with_suffix(".json")
        try:
            return json.loads(note.read_text()).get("original")
        except (OSError, ValueError, AttributeError):
            return None

    @staticmethod
    def remove(autosave: Path):
        """Remove a recovery file, its note and any backup of it (older versions kept one)."""
        for p in (autosave, autosave.with_suffix(".json"), autosave.with_name(autosave.name + ".bak")):
            p.unlink(missing_ok=True)


class RecentFiles:
    """Most recently used project paths in ``QSettings`` (key ``recent_files``)."""

    def __init__(self, settings: QSettings | None = None):
        self.settings = settings or QSettings("glassbench", "glassbench")

    def paths(self) -> list[str]:
        value = self.settings.value("recent_files", [])
        if isinstance(value, str):
            value = [value]
        return [str(v) for v in (value or [])]

    def add(self, path: str):
        path = str(Path(path).resolve())
        items = [path] + [p for p in self.paths() if p != path]
        self.settings.setValue("recent_files", items[:MAX_RECENT])
        self.settings.sync()

    def remove(self, path: str):
        self.settings.setValue("recent_files", [p for p in self.paths() if p != path])
        self.settings.sync()
