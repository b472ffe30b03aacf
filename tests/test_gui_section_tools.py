"""Section editing on the Bordeaux sample as a designer does it, through the real widgets: the
finish stays put, typed values keep tangency like drags, "-> arc" keeps smooth neighbours
tangent, messages name the real cause, the fill line drags, and the table shows every number."""
from __future__ import annotations

import math
import os

import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QDoubleSpinBox

from engine.files.project import load_project
from engine.geometry.segments import Arc

pytestmark = pytest.mark.usefixtures("no_leaks")
BORDEAUX = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources",
                        "bordeaux.glassbench")


@pytest.fixture
def window(make_window, qtbot):
    import dataclasses
    design, assets = load_project(BORDEAUX)
    small = dataclasses.replace(design, render=dataclasses.replace(design.render, width=24, height=32, spp=1))
    w = make_window(small, assets=assets)
    w.resize(1400, 950)
    w.show()
    qtbot.waitExposed(w)
    w.section_panel.canvas.fit()
    return w


def _px(canvas, p) -> QPoint:
    return canvas.to_px(p).toPoint()


def _tangent_everywhere(section) -> bool:
    for j, smooth in enumerate(section.smooth):
        a, b = section.segments[j].tangent(1.0), section.segments[j + 1].tangent(0.0)
        if smooth and math.degrees(abs(math.atan2(a[0] * b[1] - a[1] * b[0], a @ b))) > 1e-6:
            return False
    return True


def _type_in_cell(w, qtbot, row, column, text):
    table = w.section_panel.table
    index = table.model().index(row, column)
    table.setCurrentIndex(index)
    table.edit(index)
    editor = table.viewport().findChild(QDoubleSpinBox)
    editor.lineEdit().selectAll()
    qtbot.keyClicks(editor.lineEdit(), text)
    qtbot.keyClick(editor.lineEdit(), Qt.Key_Return)


def test_a_mouse_drag_of_the_shoulder_keeps_the_finish(window, qtbot):
    w, canvas = window, window.section_panel.canvas
    canvas.zoom(2.0)
    before = w.scene.design.shape.primary
    shoulder = before.segments[3].p1  # end of the convex shoulder arc
    start = _px(canvas, shoulder)
    qtbot.mousePress(canvas, Qt.LeftButton, pos=start)
    for k in (4, 8, 12):
        qtbot.mouseMove(canvas, start + QPoint(k, -k))
    qtbot.mouseRelease(canvas, Qt.LeftButton, pos=start + QPoint(12, -12))
    after = w.scene.design.shape.primary
    assert after.segments[3].p1[0] > shoulder[0] + 2 and after.segments[3].p1[1] > shoulder[1] + 2
    assert after.r_top == pytest.approx(14.5) and after.z_top == pytest.approx(300.0)
    assert after.segments[5].p0[0] == pytest.approx(14.5), "the neck stays vertical"
    assert _tangent_everywhere(after)
    assert w.undo_stack.count() == 1


def test_a_typed_end_r_keeps_tangency_as_a_drag_does(window, qtbot):
    w = window
    _type_in_cell(w, qtbot, 2, 1, "36")  # end r of the straight body, between two smooth joints
    qtbot.waitUntil(lambda: w.undo_stack.count() == 1)
    sec = w.scene.design.shape.primary
    assert sec.segments[2].p1[0] == pytest.approx(36.0) and sec.segments[2].p0[0] == pytest.approx(36.0)
    assert _tangent_everywhere(sec) and w.section_panel.message.text() == ""
    assert sec.r_top == pytest.approx(14.5) and sec.z_top == pytest.approx(300.0)


def test_a_negative_end_r_says_it_crosses_the_axis(window, qtbot):
    w = window
    before = w.scene.design
    _type_in_cell(w, qtbot, 2, 1, "-5")
    qtbot.waitUntil(lambda: w.section_panel.message.text() != "")
    assert "crosses the axis" in w.section_panel.message.text()
    assert "tangent" not in w.section_panel.message.text().split("crosses the axis")[0]
    assert w.scene.design == before


def test_a_wall_too_thick_names_the_radius_it_cannot_fit(window, qtbot):
    w = window
    w.section_panel.wall_spin.setValue(14.0)
    message = w.section_panel.message.text()
    assert "9.5 mm radius" in message and "segment 1" in message, message
    assert "base" not in message
    assert w.scene.design.shape.wall_thickness == pytest.approx(3.0)


def test_arc_between_smooth_joints_keeps_the_neighbours_tangent(window):
    w = window
    panel = w.section_panel
    panel.canvas.select(2)  # the straight body: smooth below (heel) and above (shoulder)
    panel.tool_buttons["arc"].click()
    sec = w.scene.design.shape.primary
    assert isinstance(sec.segments[2], Arc), panel.message.text()
    assert _tangent_everywhere(sec)
    assert sec.r_top == pytest.approx(14.5) and sec.z_top == pytest.approx(300.0)
    assert w.undo_action.text() == "&Undo Convert to arc"
    w.undo_stack.undo()
    assert w.scene.design.shape.primary.segments[2].kind == "line"


def test_joints_are_named_by_the_segments_they_join(window):
    w = window
    panel = w.section_panel
    panel.canvas.begin_drag(panel.canvas.handle_at(panel.canvas.to_px(w.scene.design.shape.primary.segments[2].p1)),
                            "name#1")
    panel.canvas.drag_to((-60.0, 0.0))
    panel.canvas.end_drag()
    assert "the joint between segments 2 and 3" in panel.message.text()
    assert w.section_panel.model.headerData(8, Qt.Horizontal) == "Smooth \u2192 next"


def test_the_fill_line_drags_as_one_undoable_step(window, qtbot):
    w = window
    qtbot.waitUntil(w.derived_idle)
    canvas = w.section_panel.canvas
    fill_z = canvas.fill_z
    before = w.scene.design.liquid
    grip = canvas.to_px((w.scene.design.shape.primary.r_top + 5, fill_z)).toPoint()
    assert canvas.fill_grip_at(canvas.to_px((20.0, fill_z)))
    qtbot.mousePress(canvas, Qt.LeftButton, pos=grip)
    for dy in (5, 10, 20):
        qtbot.mouseMove(canvas, grip + QPoint(0, dy))
    qtbot.mouseRelease(canvas, Qt.LeftButton, pos=grip + QPoint(0, 20))
    liquid = w.scene.design.liquid
    assert liquid.fill_mode == "volume" and liquid.fill_value < before.fill_value - 5
    assert w.undo_stack.count() == 1 and w.undo_action.text() == "&Undo Fill level"
    qtbot.waitUntil(lambda: w.derived_idle() and canvas.fill_z < fill_z - 3)
    w.undo_stack.undo()
    assert w.scene.design.liquid == before


def test_table_cells_show_every_number_in_full_and_in_words(window):
    w = window
    table, model = w.section_panel.table, w.section_panel.model
    w.section_panel.canvas.select(2)
    w.section_panel.tool_buttons["arc"].click()  # a centre far off the axis: a wide new value
    assert model.data(model.index(2, 3)).startswith("-") and len(model.data(model.index(2, 3))) >= 7
    assert model.data(model.index(1, 0)) == "Arc" and model.data(model.index(1, 7)) == "convex"
    assert model.data(model.index(0, 7)) == "concave"
    fm = table.fontMetrics()
    header = table.horizontalHeader()
    for col in range(model.columnCount()):
        texts = [model.data(model.index(r, col)) or "" for r in range(model.rowCount())]
        texts.append("-46.66")  # the cut value of the issue
        widest = max(fm.horizontalAdvance(t) for t in texts)
        assert header.sectionSize(col) >= widest + 8, f"column {model.headerData(col, Qt.Horizontal)}"
