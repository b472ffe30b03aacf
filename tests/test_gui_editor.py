"""The section editor driven through its widgets: drags, table, tools, undo/redo, refusals."""
from __future__ import annotations

import math

import pytest
from PySide6.QtCore import QPoint, QPointF, Qt

from engine.geometry.segments import Arc, EllipseArc, Line
from widgets import words
from widgets.section_editor import Handle

pytestmark = pytest.mark.usefixtures("no_leaks")


def _px(canvas, p) -> QPoint:
    return canvas.to_px(p).toPoint()


def _window(make_window):
    w = make_window()
    w.resize(1400, 900)
    w.show()
    w.section_panel.canvas.fit()
    return w


def test_mouse_drag_of_a_joint_is_one_undoable_step_and_keeps_the_finish(make_window, qtbot):
    w = _window(make_window)
    canvas = w.section_panel.canvas
    before = w.scene.design
    joint = before.shape.primary.segments[2].p1  # top of the straight body
    start = _px(canvas, joint)
    qtbot.mousePress(canvas, Qt.LeftButton, pos=start)
    for dy in (5, 10, 20, 30):
        qtbot.mouseMove(canvas, start - QPoint(0, dy))
    qtbot.mouseRelease(canvas, Qt.LeftButton, pos=start - QPoint(0, 30))
    after = w.scene.design
    assert after.shape.primary.segments[2].p1[1] > joint[1] + 5, "the body got taller"
    neck, old_neck = after.shape.primary.segments[-1], before.shape.primary.segments[-1]
    assert (neck.p0[0], neck.p1) == (old_neck.p0[0], old_neck.p1), "neck radius and height stay"
    assert w.undo_stack.count() == 1, "a drag must merge into one command"
    assert w.undo_action.text().endswith("Move joint")
    assert w.isWindowModified()
    w.undo_stack.undo()
    assert w.scene.design == before
    assert not w.isWindowModified()
    w.undo_stack.redo()
    assert w.scene.design == after


def test_stretch_drag_keeps_every_smooth_joint_tangent(make_window):
    w = _window(make_window)
    canvas = w.section_panel.canvas
    sec = w.scene.design.shape.primary
    canvas.begin_drag(Handle("joint", 3, sec.segments[3].p1), "k-test")
    canvas.drag_to((2.0, 6.0))
    canvas.end_drag()
    new = w.scene.design.shape.primary
    assert new != sec
    for j, smooth in enumerate(new.smooth):
        if smooth:
            a, b = new.segments[j].tangent(1.0), new.segments[j + 1].tangent(0.0)
            assert math.isclose(a[0], b[0], abs_tol=1e-9) and math.isclose(a[1], b[1], abs_tol=1e-9)


def test_invalid_drag_is_refused_with_a_message(make_window):
    w = _window(make_window)
    canvas = w.section_panel.canvas
    before = w.scene.design
    sec = before.shape.primary
    # Pull the neck joint inside the axis: no bottle has a negative radius.
    canvas.begin_drag(Handle("joint", 4, sec.segments[4].p1), "k-bad")
    canvas.drag_to((-40.0, 0.0), local=True)
    canvas.end_drag()
    assert w.scene.design == before
    assert w.undo_stack.count() == 0
    message = w.section_panel.message.text()
    assert "the joint between segments 4 and 5" in message and "crosses the axis" in message


def test_table_edit_of_an_arc_radius(make_window):
    w = _window(make_window)
    model = w.section_panel.model
    sec = w.scene.design.shape.primary
    assert isinstance(sec.segments[1], Arc)
    assert model.setData(model.index(1, 5), 8.0)
    new = w.scene.design.shape.primary
    assert new.segments[1].radius == pytest.approx(8.0)
    assert model.data(model.index(1, 5)) == "8.00"
    w.undo_stack.undo()
    assert w.scene.design.shape.primary == sec


def test_table_refuses_text_that_is_not_a_number(make_window):
    w = _window(make_window)
    model = w.section_panel.model
    before = w.scene.design
    assert not model.setData(model.index(2, 1), "wide")
    assert w.scene.design == before
    assert "segment 2" in w.section_panel.message.text()


def test_table_model_is_consistent(make_window, qtmodeltester):
    w = _window(make_window)
    qtmodeltester.check(w.section_panel.model)


def test_split_convert_delete_and_smooth_tools(make_window):
    w = _window(make_window)
    panel = w.section_panel
    n = len(w.scene.design.shape.primary.segments)
    panel.canvas.select(2)
    panel.tool_buttons["split"].click()
    assert len(w.scene.design.shape.primary.segments) == n + 1
    panel.canvas.select(3)
    panel.tool_buttons["delete"].click()
    assert len(w.scene.design.shape.primary.segments) == n
    panel.canvas.select(1)
    panel.tool_buttons["ellipse_arc"].click()
    assert isinstance(w.scene.design.shape.primary.segments[1], EllipseArc)
    panel.canvas.select(0)
    panel.tool_buttons["smooth"].click()
    assert w.scene.design.shape.primary.smooth[0] is True
    assert w.undo_stack.count() == 4
    for _ in range(4):
        w.undo_stack.undo()
    assert isinstance(w.scene.design.shape.primary.segments[1], Arc)
    assert len(w.scene.design.shape.primary.segments) == n


def test_converting_a_smooth_line_to_an_arc_is_refused(make_window):
    w = _window(make_window)
    panel = w.section_panel
    before = w.scene.design
    panel.canvas.select(5)  # the vertical neck: an arc there cannot meet the mouth rules
    assert not panel.run_tool("arc")
    assert w.scene.design == before
    assert panel.message.text()
    assert isinstance(before.shape.primary.segments[5], Line)


def test_wall_spin_box_edits_and_refreshes_without_echo(make_window):
    w = _window(make_window)
    spin = w.section_panel.wall_spin
    spin.setValue(4.0)
    assert w.scene.design.shape.wall_thickness == pytest.approx(4.0)
    assert w.undo_stack.count() == 1
    w.undo_stack.undo()
    assert spin.value() == pytest.approx(3.0)
    assert w.undo_stack.count() == 1 and w.undo_stack.index() == 0, "refresh must not echo a command"


def test_cross_section_kind_becomes_rounded_square(make_window):
    w = _window(make_window)
    panel = w.section_panel
    words.select_key(panel.kind_combo, "rounded_square")
    shape = w.scene.design.shape
    assert shape.cross_section == "rounded_square"
    assert [n for n, _ in shape.sections] == ["u", "v"]
    assert words.keys_of(panel.name_combo) == ["u", "v"]
    assert panel.name_combo.itemText(1) == "v \u2014 across the corners", "designer words, not keys"
    words.select_key(panel.name_combo, "v")
    assert panel.model.section == shape.section("v")
    w.undo_stack.undo()
    assert w.scene.design.shape.cross_section == "round"
    assert panel.kind_combo.currentData() == "round" and panel.kind_combo.currentText() == "Round"


def test_zoom_and_pan_change_the_mapping_only(make_window, qtbot):
    w = _window(make_window)
    canvas = w.section_panel.canvas
    before = w.scene.design
    scale = canvas.scale
    canvas.zoom(2.0)
    assert canvas.scale == pytest.approx(2 * scale)
    origin = QPointF(canvas.origin)
    qtbot.mousePress(canvas, Qt.MiddleButton, pos=QPoint(10, 10))
    qtbot.mouseMove(canvas, QPoint(40, 30))
    qtbot.mouseRelease(canvas, Qt.MiddleButton, pos=QPoint(40, 30))
    assert canvas.origin != origin
    assert w.scene.design == before


def test_keyboard_delete_and_escape_on_the_canvas(make_window, qtbot):
    w = _window(make_window)
    canvas = w.section_panel.canvas
    n = len(w.scene.design.shape.primary.segments)
    sec = w.scene.design.shape.primary
    # Click on the middle of the straight body to select it.
    qtbot.mouseClick(canvas, Qt.LeftButton, pos=_px(canvas, tuple(sec.segments[2].point(0.5))))
    assert canvas.selected == 2
    assert w.section_panel.table.currentIndex().row() == 2
    qtbot.keyClick(canvas, Qt.Key_S)
    assert len(w.scene.design.shape.primary.segments) == n + 1
    qtbot.keyClick(canvas, Qt.Key_Delete)
    assert len(w.scene.design.shape.primary.segments) == n
    qtbot.keyClick(canvas, Qt.Key_Escape)
    assert canvas.selected == -1


def test_snap_puts_a_dragged_joint_on_the_grid(make_window, qtbot):
    w = _window(make_window)
    canvas = w.section_panel.canvas
    canvas.zoom(3.0)
    sec = w.scene.design.shape.primary
    joint = sec.segments[5].p1  # the mouth: a stretch moves it straight up
    start = _px(canvas, joint)
    qtbot.mousePress(canvas, Qt.LeftButton, pos=start)
    qtbot.mouseMove(canvas, start - QPoint(0, 17))
    qtbot.mouseRelease(canvas, Qt.LeftButton, pos=start - QPoint(0, 17))
    z = w.scene.design.shape.z_top
    assert z > joint[1] and (z / 0.5) == pytest.approx(round(z / 0.5), abs=1e-9)
    w.section_panel.tool_buttons["snap"].click()
    assert canvas.snap_mm == 0.0


def test_typing_in_the_table_view_edits_the_model(make_window, qtbot):
    from PySide6.QtWidgets import QComboBox, QDoubleSpinBox
    w = _window(make_window)
    table = w.section_panel.table
    model = w.section_panel.model
    index = model.index(2, 2)  # end z of the straight body
    table.setCurrentIndex(index)
    table.edit(index)
    editor = table.viewport().findChild(QDoubleSpinBox)
    assert editor is not None and editor.maximum() > 1000, "bottle heights exceed 99.99 mm"
    editor.lineEdit().selectAll()
    qtbot.keyClicks(editor.lineEdit(), "200")
    qtbot.keyClick(editor.lineEdit(), Qt.Key_Return)
    qtbot.waitUntil(lambda: w.undo_stack.count() == 1)  # the delegate commits on a queued call
    assert w.scene.design.shape.primary.segments[2].p1[1] == pytest.approx(200.0)
    kind = model.index(1, 0)
    table.setCurrentIndex(kind)
    table.edit(kind)
    combo = table.viewport().findChild(QComboBox)
    words.select_key(combo, "ellipse_arc")
    table.commitData(combo)
    assert isinstance(w.scene.design.shape.primary.segments[1], EllipseArc)
    assert w.undo_stack.count() == 2
