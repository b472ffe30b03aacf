"""Starting the window from the command line: the project to open, recovery, the screenshot.

Design rule: ``run`` owns the ``QApplication`` and the event loop. Plain ``glassbench`` opens
the project the designer had open last (the first of the recent files that still exists), or
the bundled sample when there is none; a project named on the command line opens instead; a
project that fails to load is reported in a dialog (or on stderr for ``--screenshot``) and the
sample opens instead, so the designer always gets a working window. ``--screenshot`` (always of
the named project or the sample, never of a recent file) waits, with the event loop running,
until the preview has converged (and the wireframe is built), paints the VTK framebuffer into
the window grab and saves it.
"""
from __future__ import annotations

import os
import shutil
import sys
import tempfile

from PySide6.QtCore import QPoint, QSettings, QTimer
from PySide6.QtGui import QPainter
from PySide6.QtWidgets import QApplication

from app import engine_bridge, layout
from app.document import RecentFiles
from app.sample_design import sample_design
from app.window import MainWindow

#: How long --screenshot waits for the preview to converge at the pane's size (the compiled
#: tracer needs seconds to a minute on two shared cores; compiling its kernels on a fresh
#: machine adds about a minute).
SCREENSHOT_TIMEOUT_MS = 20 * 60 * 1000


def grab_window(window):
    """A pixmap of the whole window with the VTK view's framebuffer painted in (the window
    alone, the 3D view left blank, where the platform gives VTK no OpenGL context)."""
    pixmap = window.grab()
    view = getattr(window, "wireframe", None)
    if view is not None and view.isVisible():
        try:
            image = view.grab_framebuffer()
        except RuntimeError as exc:  # why: pyvista's RenderWindowUnavailable (Qt's offscreen platform)
            print(f"glassbench: warning: the 3D view is not in the screenshot: {exc}", file=sys.stderr)
            return pixmap
        if not image.isNull():
            painter = QPainter(pixmap)
            dpr = pixmap.devicePixelRatio()
            top_left = view.mapTo(window, QPoint(0, 0))
            target = image.scaled(int(view.width() * dpr), int(view.height() * dpr))
            target.setDevicePixelRatio(dpr)
            painter.drawImage(top_left, target)
            painter.end()
    return pixmap


def initial_document(project_path: str | None, recent: RecentFiles | None):
    """``(design, assets, path, load_error)`` to open: ``project_path``, else the newest of
    ``recent`` that exists and loads (``None``: do not look), else the sample (``path`` None).
    ``load_error`` says why a named project could not be opened."""
    design, assets, path = sample_design()
    if project_path:
        try:
            design, assets = engine_bridge.load_project(project_path)
            return design, assets, project_path, None
        except Exception as exc:  # why: any unreadable file is reported, then the sample opens
            return design, assets, path, f"{project_path}: {exc}"
    for candidate in (recent.paths() if recent is not None else []):
        if os.path.isfile(candidate):
            try:
                loaded, loaded_assets = engine_bridge.load_project(candidate)
                return loaded, loaded_assets, candidate, None
            except Exception:  # why: a recent file that broke since is skipped, not fatal
                continue
    return design, assets, path, None


def run(project_path: str | None, screenshot: str | None) -> int:
    """Open the window; with ``screenshot`` save a picture once converged and quit."""
    # why: the tracer's kernels load (or, on a fresh machine, compile) while the window opens
    engine_bridge.warm_up_tracer()
    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("glassbench")
    app.setOrganizationName("glassbench")
    if screenshot:  # why: a screenshot shows the default layout, never the user's own
        scratch = tempfile.mkdtemp(prefix="glassbench-screenshot-")
        settings = QSettings(os.path.join(scratch, "settings.ini"), QSettings.IniFormat)
    else:
        settings = QSettings("glassbench", "glassbench")
    recent = None if screenshot else RecentFiles(settings)
    design, assets, path, load_error = initial_document(project_path, recent)
    window = MainWindow(design, assets, path, settings=settings)
    if path:
        window.recent.add(path)
    if screenshot:
        window.resize(layout.DEFAULT_SIZE)
    window.show()
    status = {"code": 0}
    if screenshot:
        if load_error:
            print(f"glassbench: error: {load_error}", file=sys.stderr)
            window.shutdown()
            window.close()
            return 2
        _arrange_screenshot(window, screenshot, status, app)
    else:
        if load_error:
            QTimer.singleShot(0, lambda: window.dialogs.show_error("Cannot open project", load_error))
        QTimer.singleShot(0, window.files.offer_recovery)
    app.exec()
    if screenshot:
        shutil.rmtree(scratch, ignore_errors=True)
    return status["code"]


def _arrange_screenshot(window, out_path: str, status: dict, app):
    """Poll (on the event loop) until the render converged, then save the picture and quit."""
    poll = QTimer(window)
    poll.setInterval(100)
    deadline = QTimer(window)
    deadline.setSingleShot(True)

    def ready() -> bool:
        rc = window.render_controller
        at_pane_size = rc.wanted_size is not None and not window.resize_timer.isActive()
        converged = rc.ended_generation == rc.generation and at_pane_size and not rc.held
        wire = getattr(window, "wireframe_controller", None)
        return converged and (wire is None or wire.is_idle())

    def finish(code: int):
        poll.stop()
        deadline.stop()
        if code == 0:
            try:
                saved = grab_window(window).save(out_path)
            except Exception as exc:  # why: the app must quit with an error, never hang on it
                print(f"glassbench: error: cannot take the screenshot: {exc}", file=sys.stderr)
                saved = None
            if saved is False:
                print(f"glassbench: error: cannot write {out_path}", file=sys.stderr)
            if not saved:
                code = 2
        else:
            print("glassbench: error: the preview did not converge in time", file=sys.stderr)
        status["code"] = code
        window.files.autosave_timer.stop()
        window.undo_stack.setClean()
        window.close()
        app.quit()

    poll.timeout.connect(lambda: ready() and finish(0))
    deadline.timeout.connect(lambda: finish(3))
    failed = window.render_controller.failed
    failed.connect(lambda gen, msg: print(f"glassbench: render failed: {msg}", file=sys.stderr))
    poll.start()
    deadline.start(SCREENSHOT_TIMEOUT_MS)
