"""The 3D wireframe follows edits from a worker thread, coalesces bursts, and closes cleanly;
plus a guard against the PySide6 build that loses references to None."""
from __future__ import annotations

import sys

import numpy as np
import pytest

from widgets.section_editor import Handle

pytestmark = pytest.mark.usefixtures("no_leaks")


def test_wireframe_follows_a_drag_and_coalesces_requests(make_window, qtbot, monkeypatch):
    import threading

    from app import engine_bridge
    w = make_window(wireframe=True)
    ctrl = w.wireframe_controller
    qtbot.waitUntil(ctrl.is_idle, timeout=30_000)
    assert w.wireframe.uploads == 1
    z_before = float(w.wireframe.poly.points[:, 2].max())
    # hold the worker in its first rebuild while the drag goes on: however fast a rebuild is,
    # the drag's later requests then pile up as one pending request, never one rebuild each
    gate = threading.Event()
    build = engine_bridge.design_wireframe
    monkeypatch.setattr(engine_bridge, "design_wireframe", lambda d, tol: gate.wait(30) and build(d, tol))
    canvas = w.section_panel.canvas
    sec = w.scene.design.shape.primary
    mouth = len(sec.segments) - 1  # the mouth: a drag up makes the bottle taller
    canvas.begin_drag(Handle("joint", mouth, sec.segments[mouth].p1), "wire-drag")
    for dz in np.linspace(1.0, 25.0, 25):
        canvas.drag_to((0.0, float(dz)))
    canvas.end_drag()
    gate.set()
    qtbot.waitUntil(ctrl.is_idle, timeout=30_000)
    assert w.wireframe.uploads <= 1 + 2, "a burst of edits must not queue one rebuild each"
    z_after = float(w.wireframe.poly.points[:, 2].max())
    assert z_after == pytest.approx(w.scene.design.shape.z_top, abs=1e-6)
    assert z_after > z_before + 20
    assert ctrl.latencies_s, "latency of the newest request is measured"


def test_the_wireframe_framebuffer_can_be_grabbed(make_window, qtbot):
    w = make_window(wireframe=True)
    w.resize(1200, 800)
    w.show()
    qtbot.waitUntil(w.wireframe_controller.is_idle, timeout=30_000)
    image = w.wireframe.grab_framebuffer()
    assert not image.isNull()
    colours = {image.pixel(x, image.height() // 2) for x in range(0, image.width(), 3)}
    assert len(colours) >= 2, "the bottle's lines are drawn over the background"


def _distance(cam):
    return float(np.linalg.norm(np.subtract(cam.eye, cam.target)))


def test_the_3d_view_shows_the_design_camera_and_copies_it_back_without_a_jump(make_window, qtbot):
    w = make_window(wireframe=True)
    qtbot.waitUntil(w.wireframe_controller.is_idle, timeout=30_000)
    before = w.scene.design.camera
    vtk = w.wireframe.plotter.camera
    assert tuple(vtk.position) == pytest.approx(before.eye) and vtk.view_angle == pytest.approx(before.fov_y_deg)
    w.camera_panel.sync_button.click()
    assert w.scene.design.camera == before and w.undo_stack.count() == 0, \
        "the 3D view already shows the design's camera: copying it changes nothing"
    w.camera_panel.azimuth.setValue(40.0)  # the design camera turns: the 3D view turns with it
    assert tuple(w.wireframe.plotter.camera.position) == pytest.approx(w.scene.design.camera.eye)
    w.undo_stack.undo()
    vtk.azimuth = vtk.azimuth + 25.0  # the designer orbits the 3D view ...
    w.camera_panel.sync_button.click()  # ... and takes that view for the design
    after = w.scene.design.camera
    assert after.eye != pytest.approx(before.eye)
    assert _distance(after) == pytest.approx(_distance(before), rel=1e-6), "the framing is kept"
    assert after.fov_y_deg == pytest.approx(before.fov_y_deg)
    w.undo_stack.undo()
    assert w.scene.design.camera == before


def test_the_wireframe_shows_the_cap_and_follows_it(make_window, qtbot):
    from engine.appearance.closures import closure_geometry
    from widgets import words
    w = make_window(wireframe=True)
    ctrl = w.wireframe_controller
    qtbot.waitUntil(ctrl.is_idle, timeout=30_000)
    bare = len(w.wireframe.poly.points)
    assert float(w.wireframe.poly.points[:, 2].max()) == pytest.approx(w.scene.design.shape.z_top, abs=1e-6)
    words.select_key(w.cap_panel.kind, "screw")
    qtbot.waitUntil(lambda: ctrl.is_idle() and len(w.wireframe.poly.points) > bare, timeout=30_000)
    cap = closure_geometry(w.scene.design)
    assert float(w.wireframe.poly.points[:, 2].max()) == pytest.approx(cap.z_max, abs=1e-6)
    w.undo_stack.undo()
    qtbot.waitUntil(lambda: ctrl.is_idle() and len(w.wireframe.poly.points) == bare, timeout=30_000)


def test_a_refused_shape_is_reported_not_fatal(make_window, qtbot, monkeypatch):
    from app import engine_bridge
    w = make_window(wireframe=True)
    qtbot.waitUntil(w.wireframe_controller.is_idle, timeout=30_000)

    def broken(shape, tol):
        raise ValueError("cannot tessellate")
    monkeypatch.setattr(engine_bridge, "wireframe_lines", broken)
    with qtbot.waitSignal(w.wireframe_controller.failed, timeout=10_000) as blocker:
        w.wireframe_controller.request(w.scene.design)
    assert "cannot tessellate" in blocker.args[0]


def test_void_qt_calls_keep_none_alive(qapp):
    """PySide6 6.12.0 on CPython 3.11 dropped a reference to None per void call, which
    aborted the GUI after a few thousand calls; the project pins a build that does not."""
    from PySide6.QtCore import QTimer
    timer = QTimer()
    before = sys.getrefcount(None)
    for _ in range(2000):
        timer.start(1000)
        timer.stop()
    assert sys.getrefcount(None) >= before - 50


def test_a_closed_wireframe_keeps_no_wrapper_of_its_gl_surface(make_window, qtbot):
    """The interactor held its GL surface as a plain ``QSurface`` wrapper, which PySide cannot
    see deleted: the next Qt object born at that address came back as that "QSurface" (a
    section table's selection model, a flaky GUI failure). After shutdown none may remain."""
    import gc

    from PySide6.QtGui import QSurface
    w = make_window(wireframe=True)
    w.show()
    qtbot.waitExposed(w)
    qtbot.waitUntil(w.wireframe_controller.is_idle, timeout=30_000)
    w.wireframe.shutdown()
    assert not [o for o in gc.get_objects() if type(o) is QSurface]


def test_a_stopped_worker_with_a_request_left_is_idle(qtbot):
    """A window closed while a request waits (pytest-qt closes widgets before fixtures end,
    and the derived numbers of an outline take a few tenths of a second): the stopped worker
    computes nothing more, so it is idle once its last computation ended, not never."""
    import threading

    from app.wireframe_controller import LatestOnlyWorker

    gate, started = threading.Event(), threading.Event()

    class Slow(LatestOnlyWorker):
        def compute(self, value):
            started.set()
            gate.wait(30)
            return value

    worker = Slow()
    worker.request(1)
    qtbot.waitUntil(started.is_set, timeout=10_000)
    worker.request(2)  # waits behind the first
    assert not worker.is_idle()
    gate.set()
    worker.shutdown()
    assert worker.is_idle()
