"""The window on a 1600 x 1000 screen: all of it on screen, the preview the largest pane and
rendered at its own size in device pixels, and the layout remembered from one window to the next
(in the test's own settings file)."""
from __future__ import annotations

import pytest
from PySide6.QtCore import QPoint, QRect, Qt

from app import layout

pytestmark = pytest.mark.usefixtures("no_leaks")


def _shown(make_window, qtbot, **kw):
    w = make_window(wireframe=True, **kw)
    w.show()
    qtbot.waitExposed(w)
    return w


def _global_rect(widget) -> QRect:
    return QRect(widget.mapToGlobal(QPoint(0, 0)), widget.size())


def test_the_window_fits_the_screen_with_the_preview_the_largest_pane(make_window, qtbot):
    w = _shown(make_window, qtbot)
    screen = w.screen().availableGeometry()
    frame = w.frameGeometry()
    assert frame.width() <= 1600 and frame.height() <= 1000
    assert screen.contains(frame), f"window {frame} off the screen {screen}"
    for part in (w.statusBar(), w.render_progress, w.render_state):
        assert part.isVisible() and screen.contains(_global_rect(part)), "the status bar is on screen"
    # the docks take their default sizes when the main window lays out (an event after the
    # window is exposed; late on a loaded machine): wait for that layout, then check it
    qtbot.waitUntil(lambda: w.preview.width() * w.preview.height() > 0.35 * frame.width() * frame.height(),
                    timeout=10_000)
    preview = w.preview.width() * w.preview.height()
    for name, dock in w.docks.items():
        if dock.isVisible():
            assert preview > dock.width() * dock.height(), f"the preview is larger than {name}"


def test_no_field_is_squeezed_below_its_size(make_window, qtbot):
    w = _shown(make_window, qtbot)
    w.docks["camera"].raise_()
    qtbot.waitUntil(w.camera_panel.spp.isVisible)
    for spin in (w.camera_panel.spp, w.camera_panel.width_px, w.section_panel.wall_spin):
        hint = spin.minimumSizeHint()
        assert spin.width() >= hint.width() and spin.height() >= hint.height(), spin.toolTip()


def test_the_preview_renders_at_the_pane_size_in_device_pixels(make_window, qtbot):
    w = _shown(make_window, qtbot)
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.wanted_size is not None and rc.job is not None and rc.size == rc.wanted_size,
                    timeout=10_000)
    pane = w.preview.pane_pixels()
    dpr = w.preview.devicePixelRatioF()
    assert pane == (round(w.preview.width() * dpr), round(w.preview.height() * dpr))
    design = w.scene.design
    width, height = rc.size
    assert width == pane[0] or height == pane[1], "the render fills the pane in one direction"
    assert width <= pane[0] and height <= pane[1]
    assert width / height == pytest.approx(design.render.width / design.render.height, rel=0.02)
    assert width > 4 * design.render.width, "far more pixels than the design's 48 x 64"
    w.resize(w.width() - 200, w.height())
    qtbot.waitUntil(lambda: rc.size == layout.preview_size(w.preview.pane_pixels(), design.render.width,
                                                          design.render.height, 10 ** 9), timeout=10_000)


def test_the_layout_is_remembered(make_window, qtbot):
    first = _shown(make_window, qtbot)
    first.resizeDocks([first.section_dock], [520], Qt.Horizontal)
    first.docks["camera"].raise_()
    first.section_panel.split.setSizes([200, 400])
    first.materials_panel.glass_thickness.setValue(4.0)
    qtbot.waitUntil(lambda: abs(first.section_dock.width() - 520) <= 2)
    sizes = first.section_panel.split.sizes()
    first.close()
    second = _shown(make_window, qtbot)
    assert abs(second.section_dock.width() - 520) <= 2
    assert second.section_panel.split.sizes()[1] == pytest.approx(sizes[1], abs=3), "the table keeps its height"
    assert second.size() == first.size()
    assert second.materials_panel.glass_thickness.value() == pytest.approx(4.0)
    assert second.undo_stack.count() == 0, "restoring the tint thickness is not an edit"


def test_preview_size_keeps_the_image_shape_and_a_pixel_budget():
    assert layout.preview_size((800, 960), 360, 480, 10 ** 9) == (720, 960)
    assert layout.preview_size((1600, 600), 360, 480, 10 ** 9) == (450, 600)
    w, h = layout.preview_size((4000, 4000), 300, 400, 1_200_000)
    assert w * h <= 1_200_000 and w / h == pytest.approx(0.75, rel=0.01)
