"""Shared fixtures. The GUI fixtures import Qt only when a GUI test asks for them, so the
engine's tests (and the "engine never imports Qt" check) are unaffected by this file."""
from __future__ import annotations

import dataclasses
import threading

import pytest


@pytest.fixture
def gui_paths(tmp_path, monkeypatch):
    """Point Qt's per-user locations (autosave, settings) into ``tmp_path``."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    return tmp_path


@pytest.fixture
def tiny_design():
    """The built-in sample rendered at 48 x 64 pixels, 1 sample per pixel."""
    from app.sample_design import built_in_design
    from engine.model.design import RenderSettings
    return dataclasses.replace(built_in_design(), render=RenderSettings(width=48, height=64, spp=1))


@pytest.fixture
def no_leaks(qapp):
    """Fail the test if it leaves threads running or top-level widgets alive."""
    from PySide6.QtCore import QCoreApplication, QEvent
    threads_before = set(threading.enumerate())
    widgets_before = set(map(id, qapp.topLevelWidgets()))
    yield
    for t in set(threading.enumerate()) - threads_before:
        t.join(timeout=30)  # why: a worker told to stop may need a moment to see its flag
    QCoreApplication.sendPostedEvents(None, QEvent.DeferredDelete)
    qapp.processEvents()
    leaked_threads = [t.name for t in set(threading.enumerate()) - threads_before if t.is_alive()]
    assert not leaked_threads, f"threads left running: {leaked_threads}"
    leaked = [w for w in qapp.topLevelWidgets() if id(w) not in widgets_before and w.isVisible()]
    assert not leaked, f"widgets left open: {[type(w).__name__ for w in leaked]}"


class FakeDialogs:
    """Answers the window's questions without showing anything; records what was asked."""

    def __init__(self):
        self.open_path = None
        self.save_path = None
        self.unsaved_answer = "discard"
        self.recover_answer = True
        self.errors: list[tuple[str, str]] = []
        self.asked: list[str] = []

    def ask_open_path(self, title, name_filter):
        self.asked.append("open")
        return self.open_path

    def ask_save_path(self, title, name_filter, suggestion=""):
        self.asked.append("save")
        return self.save_path

    def ask_unsaved(self):
        self.asked.append("unsaved")
        return self.unsaved_answer

    def ask_recover(self, description):
        self.asked.append("recover")
        return self.recover_answer

    def show_error(self, title, text):
        self.errors.append((title, text))


@pytest.fixture
def make_window(qtbot, gui_paths, tiny_design, no_leaks):
    """Factory for main windows with fake dialogs and private settings; closes them after."""
    from PySide6.QtCore import QSettings, QTimer
    from app.window import MainWindow
    made = []

    def factory(design=None, *, wireframe=False, autosave_ms=0, path=None, assets=None):
        settings = QSettings(str(gui_paths / "settings.ini"), QSettings.IniFormat)
        w = MainWindow(design or tiny_design, assets, path, settings=settings, wireframe=wireframe,
                       autosave_ms=autosave_ms)
        w.dialogs = FakeDialogs()
        qtbot.addWidget(w)
        made.append(w)
        return w

    yield factory
    for w in made:
        w.undo_stack.setClean()
        w.close()
        w.shutdown()
        # why: QStatusBar's own message-timeout timer is Qt's, not ours
        active = [t for t in w.findChildren(QTimer) if t.isActive()
                  and type(t.parent()).__name__ != "QStatusBar"]
        assert not active, f"timers still running after close: {active}"
