"""The preview: tiles from the real tracer arrive on the GUI thread, edits cancel stale jobs,
a failing render is reported and the window keeps working."""
from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from app import engine_bridge
from app.window import capped_note
from engine.model.design import Glass

pytestmark = pytest.mark.usefixtures("no_leaks")


def _wait_converged(qtbot, w, timeout=60_000):
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=timeout)


def _converged_text(job, width=48, height=64):
    """The status bar's text for a converged ``job``: its size, then the share of the image its
    sample cap stopped above the tolerance, if any."""
    return f"Converged {width}\u00d7{height}{capped_note(job.capped, width * height)}"


def test_the_cap_note_gives_a_share_or_a_count_never_a_share_that_reads_zero():
    assert capped_note(0, 1000) == ""
    assert capped_note(96, 1000) == " (9.6 % of pixels at the sample cap)"
    assert capped_note(12, 715 * 954) == " (12 pixels at the sample cap)"


def test_tiles_arrive_and_the_render_converges(make_window, qtbot):
    w = make_window()
    rc = w.render_controller
    with qtbot.waitSignal(rc.tileReady, timeout=60_000) as blocker:
        pass
    generation, x0, y0, rgb8 = blocker.args
    assert generation == rc.generation
    assert rgb8.dtype == np.uint8 and rgb8.shape[2] == 3
    _wait_converged(qtbot, w)
    assert rc.converged_generation == rc.generation
    assert w.preview.image_size() == (48, 64)
    assert w.preview.tiles_painted >= 1
    assert w.render_state.text() == _converged_text(rc.job)
    assert w.render_progress.value() == 100
    pixels = {w.preview.pixel_rgb(x, y) for x in range(0, 48, 6) for y in range(0, 64, 6)}
    assert len(pixels) > 3, "the preview shows an image, not a flat fill"
    # its own native window: its tiles are not composed with the OpenGL 3D view's window, and a
    # grab of the window (README screenshots) still shows them
    assert w.preview.testAttribute(Qt.WA_NativeWindow) and w.preview.winId() != w.winId()
    grabbed = w.grab().toImage()
    r = w.preview.rect()
    seen = {grabbed.pixelColor(w.preview.mapTo(w, QPoint(x, y))).getRgb()
            for x in range(r.width() // 4, 3 * r.width() // 4, 5) for y in range(r.height() // 4, 3 * r.height() // 4, 5)}
    assert len(seen) > 3, "the window's grab shows the preview's image"


def test_the_status_says_what_share_of_pixels_stopped_at_the_sample_cap(make_window, qtbot, monkeypatch):
    """With a tolerance no pixel meets (a hundredth of a level), the window's render ends with
    edge pixels at the sample cap: the status bar does not call that plainly converged."""
    monkeypatch.setattr(engine_bridge, "WINDOW_NOISE", dataclasses.replace(engine_bridge.WINDOW_NOISE,
                                                                           noise_target=0.01 / 255.0))
    w = make_window()
    rc = w.render_controller
    _wait_converged(qtbot, w)
    assert rc.job.error is None and rc.job.capped > 0
    assert w.render_state.text() == _converged_text(rc.job) != "Converged 48\u00d764"


def test_an_edit_cancels_the_running_job_and_stale_tiles_are_dropped(make_window, qtbot):
    w = make_window()
    rc = w.render_controller
    rc.wait_until_idle(0)  # start the debounced job now
    old_job, old_generation = rc.job, rc.generation
    assert old_job is not None
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.6))
    assert rc.generation == old_generation + 1
    assert old_job.cancelled
    shown = []
    rc.tileReady.connect(lambda g, *rest: shown.append(g))
    # A tile the old job finished late comes through the worker path: it must not be shown.
    rc._worker_tile.emit(old_generation, old_job, SimpleNamespace(x0=0, y0=0, x1=8, y1=8, wave=1))
    _wait_converged(qtbot, w)
    assert shown, "the new job's tiles arrive"
    assert set(shown) == {rc.generation}
    assert old_job.wait(30)


def test_a_failing_render_is_reported_and_the_window_keeps_working(make_window, qtbot, monkeypatch):
    class BrokenJob:
        def __init__(self, *args, **kwargs):
            raise RuntimeError("embree scene could not be built")

    monkeypatch.setattr(engine_bridge, "tracer_job_class", lambda: BrokenJob)
    w = make_window()
    rc = w.render_controller
    with qtbot.waitSignal(rc.failed, timeout=10_000) as blocker:
        pass
    assert "embree scene" in blocker.args[1]
    assert "Render failed" in w.statusBar().currentMessage()
    monkeypatch.undo()
    assert w.editor.apply("Glass IOR", None, glass=Glass(ior=1.55))
    _wait_converged(qtbot, w)
    assert rc.converged_generation == rc.generation


def test_an_error_inside_the_job_is_reported(make_window, qtbot, monkeypatch):
    real = engine_bridge.tracer_job_class()

    class FailingJob(real):
        def _run(self):
            def boom(*a, **k):
                raise ValueError("ray went astray")
            import engine.tracer.context as context
            monkeypatch.setattr(context.RenderContext, "from_design", boom)
            super()._run()

    monkeypatch.setattr(engine_bridge, "tracer_job_class", lambda: FailingJob)
    w = make_window()
    with qtbot.waitSignal(w.render_controller.failed, timeout=30_000) as blocker:
        pass
    assert "ray went astray" in blocker.args[1]


def test_zoom_modes_and_export_image(make_window, qtbot, tmp_path):
    w = make_window()
    _wait_converged(qtbot, w)
    w.preview.resize(300, 300)
    w.preview.zoom_one_to_one()
    assert not w.preview.fit
    assert w.preview._target_rect().width() == 48
    qtbot.mousePress(w.preview, Qt.MiddleButton, pos=QPoint(100, 100))
    qtbot.mouseMove(w.preview, QPoint(130, 110))
    qtbot.mouseRelease(w.preview, Qt.MiddleButton, pos=QPoint(130, 110))
    assert (w.preview.pan.x(), w.preview.pan.y()) == (30, 10)
    w.preview.zoom_fit()
    assert w.preview._target_rect().width() > 48
    assert w.preview.fit
    out = tmp_path / "render.png"
    w.dialogs.save_path = str(out)
    assert w.files.export_image_dialog()
    from PySide6.QtGui import QImage
    img = QImage(str(out))
    assert (img.width(), img.height()) == (48, 64)


def test_orbit_drag_in_the_preview_is_one_camera_step(make_window):
    w = make_window()
    before = w.scene.design.camera
    for dx in (5.0, 10.0, 20.0):
        w.preview.orbitRequested.emit(dx, 0.0, False)
    w.preview.orbitRequested.emit(0.0, 0.0, True)
    after = w.scene.design.camera
    assert after.eye != before.eye
    assert after.target == before.target
    assert w.undo_stack.count() == 1
    dist = lambda c: np.linalg.norm(np.subtract(c.eye, c.target))  # noqa: E731
    assert dist(after) == pytest.approx(dist(before))
    w.undo_stack.undo()
    assert w.scene.design.camera == before


def test_a_held_drag_shows_a_live_pass_and_says_stale_until_release(make_window, qtbot):
    from app.render_controller import LIVE_SCALE
    from widgets.section_editor import Handle
    w = make_window()
    rc = w.render_controller
    _wait_converged(qtbot, w)
    assert w.render_state.text().startswith("Converged")
    canvas = w.section_panel.canvas
    sec = w.scene.design.shape.primary
    canvas.begin_drag(Handle("joint", 2, sec.segments[2].p1), "held#1")
    canvas.drag_to((0.0, 4.0))
    assert rc.state == "stale" and w.render_state.text().startswith("Stale")
    assert w.render_progress.value() == 0, "a held render never claims to be done"
    qtbot.waitUntil(lambda: rc.job is not None and rc.live, timeout=10_000)
    assert rc.size == (round(48 * LIVE_SCALE), round(64 * LIVE_SCALE))
    assert rc.job.spp == 1 and rc.job.sampling.noise_space == "display", "the window judges noise as displayed"
    live = rc.job
    canvas.drag_to((0.0, 8.0))  # the next step cancels the live pass at once
    assert live.cancelled
    qtbot.waitUntil(lambda: w.preview.image_size() == rc.size and w.preview.tiles_painted > 0, timeout=30_000)
    assert rc.state == "stale" and w.preview.note.startswith("stale")
    states = []
    rc.stateChanged.connect(lambda state, wave, fraction: states.append((state, wave)))
    with qtbot.waitSignal(rc.finished, timeout=60_000) as blocker:
        canvas.end_drag()
    assert blocker.args == [rc.generation]
    assert rc.size == (48, 64) and not rc.live
    # wave by wave: the raw film, or once a wave is denoised the denoiser's estimate of it
    assert any(state in ("refining", "denoised") and wave >= 0 for state, wave in states), "refining, wave by wave"
    assert states[-1][0] == "converged" and w.render_state.text() == _converged_text(w.render_controller.job)
    assert w.render_progress.value() == 100


def test_live_passes_are_throttled_not_debounced(make_window, qtbot):
    from app.render_controller import LIVE_FIRST_MS
    from widgets.section_editor import Handle
    w = make_window()
    rc = w.render_controller
    canvas = w.section_panel.canvas
    sec = w.scene.design.shape.primary
    canvas.begin_drag(Handle("joint", 2, sec.segments[2].p1), "throttle#1")
    canvas.drag_to((0.0, 1.0))
    first = rc._timer.remainingTime()
    assert 0 <= first <= LIVE_FIRST_MS + 2 < rc._delay_ms, "the first live pass is due at once"
    for dz in (1.5, 2.0, 2.5, 3.0):  # a continuous drag: each step comes before the pass is due
        canvas.drag_to((0.0, dz))
        assert 0 <= rc._timer.remainingTime() <= first + 2, "a new step never pushes the live pass back"
    qtbot.waitUntil(lambda: rc.job is not None and rc.live, timeout=10_000)
    assert rc.job.design.shape.primary.segments[2].p1[1] == pytest.approx(sec.segments[2].p1[1] + 3.0)
    canvas.end_drag()


def test_an_orbit_drag_in_the_preview_holds_the_render_and_is_one_step(make_window, qtbot):
    w = make_window()
    w.resize(900, 700)
    w.show()
    qtbot.waitExposed(w)
    rc = w.render_controller
    before = w.scene.design.camera
    centre = w.preview.rect().center()
    qtbot.mousePress(w.preview, Qt.LeftButton, pos=centre)
    assert rc.held
    for dx in (10, 20, 40):
        qtbot.mouseMove(w.preview, centre + QPoint(dx, 0))
    assert rc.state == "stale"
    qtbot.waitUntil(lambda: rc.job is not None and rc.live, timeout=10_000)
    qtbot.mouseRelease(w.preview, Qt.LeftButton, pos=centre + QPoint(40, 0))
    assert not rc.held and w.undo_stack.count() == 1
    assert w.scene.design.camera != before
    qtbot.waitUntil(lambda: rc.job is not None and not rc.live, timeout=10_000)
    assert rc.state == "refining"


def test_a_refused_drag_leaves_the_render_running(make_window, qtbot):
    from widgets.section_editor import Handle
    w = make_window()
    rc = w.render_controller
    rc.wait_until_idle(0)
    job, generation = rc.job, rc.generation
    canvas = w.section_panel.canvas
    sec = w.scene.design.shape.primary
    canvas.begin_drag(Handle("joint", 4, sec.segments[4].p1), "refused")
    canvas.drag_to((-60.0, 0.0), local=True)  # through the axis: refused
    canvas.end_drag()
    assert rc.generation == generation and rc.job is job and not job.cancelled
    _wait_converged(qtbot, w)
    assert rc.converged_generation == generation


def test_the_scenes_change_reaches_the_job_once_notes_keep_the_film_and_a_colour_relabels(make_window, qtbot):
    """What an edit changed is named by the scene and handed to the next full render: a notes
    edit starts nothing, a restart with nothing changed keeps the finished film (no new trace),
    a label colour edit relabels (no pixel traced again, the label's pixels recoloured), and the
    relabelled image is a full render's."""
    from pathlib import Path
    from engine.files.project import load_project
    from engine.tracer.job import render_image
    design, assets = load_project(Path(__file__).resolve().parents[1] / "resources" / "labelled.glassbench")
    small = dataclasses.replace(design, render=dataclasses.replace(design.render, width=36, height=48, spp=2))
    w = make_window(small, assets=assets)
    rc = w.render_controller
    _wait_converged(qtbot, w)
    first = rc.job
    assert first.records is not None and first.relabelled_pixels is None
    w.editor.apply("Notes", None, notes="a client's remark")
    assert rc.job is first and rc._since_full == set()
    w.restart_render()
    rc.wait_until_idle(0)
    qtbot.waitUntil(lambda: rc.job is not first and rc.job.done, timeout=60_000)
    assert rc.job.film is first.film  # kept: nothing it shows changed
    kept = rc.job
    label = small.labels[0]
    recoloured = dataclasses.replace(label, front=dataclasses.replace(label.front, color=(0.9, 0.2, 0.1)))
    w.editor.apply("Label colour", None, labels=(recoloured,) + small.labels[1:])
    assert rc._since_full == {"labels"}
    rc.wait_until_idle(0)
    qtbot.waitUntil(lambda: rc.job is not kept and rc.job.done, timeout=60_000)
    job = rc.job
    assert job.error is None and job.context.geometry is first.context.geometry  # the scene was not rebuilt
    assert job.relabelled_pixels == 0 and job.recoloured_pixels > 0
    full = render_image(w.scene.design, dict(w.scene.assets), width=job.width, height=job.height, spp=job.spp,
                        sampling=job.sampling)
    assert np.array_equal(job.image(), full)
