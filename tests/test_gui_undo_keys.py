"""Undo and redo from every widget, with real key events: a focused spin box or table cell
commits its edit, then Ctrl+Z undoes the design (not the field's text); a refusal message goes
once the design changes under it."""
from __future__ import annotations

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDoubleSpinBox

pytestmark = pytest.mark.usefixtures("no_leaks")


def _active(make_window, qtbot, **kw):
    w = make_window(**kw)
    w.show()
    w.activateWindow()
    qtbot.waitUntil(w.isActiveWindow, timeout=5000)
    return w


def _type(qtbot, spin, text: str, enter: bool = True):
    spin.setFocus()
    qtbot.waitUntil(spin.lineEdit().hasFocus, timeout=5000)
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), text)
    if enter:
        qtbot.keyClick(spin.lineEdit(), Qt.Key_Return)


def _undo(qtbot, widget):
    qtbot.keyClick(widget, Qt.Key_Z, Qt.ControlModifier)


def _redo(qtbot, widget):
    qtbot.keyClick(widget, Qt.Key_Z, Qt.ControlModifier | Qt.ShiftModifier)


def test_ctrl_z_in_the_fill_level_field_undoes_the_fill(make_window, qtbot):
    w = _active(make_window, qtbot)
    spin = w.materials_panel.fill_value
    before = w.scene.design.liquid.fill_value
    _type(qtbot, spin, "95")
    assert w.scene.design.liquid.fill_value == pytest.approx(95.0)
    _undo(qtbot, spin.lineEdit())
    assert w.scene.design.liquid.fill_value == pytest.approx(before)
    assert spin.value() == pytest.approx(before), "the field shows the design, not its own text undo"
    _redo(qtbot, spin.lineEdit())
    assert w.scene.design.liquid.fill_value == pytest.approx(95.0)


def test_ctrl_z_commits_a_value_still_being_typed_then_undoes_it(make_window, qtbot):
    w = _active(make_window, qtbot)
    spin = w.camera_panel.width_px
    before = w.scene.design.render.width
    _type(qtbot, spin, "200", enter=False)
    assert w.scene.design.render.width == before and w.undo_stack.count() == 0
    _undo(qtbot, spin.lineEdit())
    assert w.undo_stack.count() == 1, "the typed value became a step of its own ..."
    assert w.scene.design.render.width == before, "... which Ctrl+Z undid"
    _redo(qtbot, spin.lineEdit())
    assert w.scene.design.render.width == 200


def test_ctrl_z_from_a_cell_being_edited_in_the_table(make_window, qtbot):
    w = _active(make_window, qtbot)
    w.resize(1400, 900)
    table, model = w.section_panel.table, w.section_panel.model
    before = w.scene.design.shape.primary
    index = model.index(2, 2)  # end z of the straight body
    table.setCurrentIndex(index)
    table.edit(index)
    editor = table.viewport().findChild(QDoubleSpinBox)
    editor.setFocus()
    qtbot.waitUntil(editor.lineEdit().hasFocus, timeout=5000)
    editor.lineEdit().selectAll()
    qtbot.keyClicks(editor.lineEdit(), "200")
    _undo(qtbot, editor.lineEdit())
    assert w.undo_stack.count() == 1 and w.undo_stack.index() == 0
    assert w.scene.design.shape.primary == before
    w.undo_action.trigger()  # nothing left to undo: harmless
    w.redo_action.trigger()
    assert w.scene.design.shape.primary.segments[2].p1[1] == pytest.approx(200.0)


def test_the_edit_menu_commits_a_field_too(make_window, qtbot):
    w = _active(make_window, qtbot)
    spin = w.materials_panel.glass_ior
    _type(qtbot, spin, "1.6", enter=False)
    w.edit_menu.aboutToShow.emit()  # the designer opens the Edit menu ...
    assert w.undo_action.isEnabled(), "... and Undo is offered for the value just typed"
    w.undo_action.trigger()
    assert w.scene.design.glass.ior == pytest.approx(1.52)
    assert w.undo_action.isEnabled() is False and w.redo_action.isEnabled()
    assert "Glass IOR" in w.redo_action.text()


def test_undo_clears_a_refusal_whose_cause_it_removes(make_window, qtbot):
    w = _active(make_window, qtbot)
    panel = w.section_panel
    _type(qtbot, panel.wall_spin, "5")  # accepted: a 5 mm wall fits this bottle
    assert w.scene.design.shape.wall_thickness == pytest.approx(5.0)
    _type(qtbot, panel.base_spin, "4")  # refused: the base must be at least the 5 mm wall
    assert "at least as thick" in panel.message.text()
    assert w.scene.design.shape.base_thickness == pytest.approx(6.0)
    _undo(qtbot, panel.base_spin.lineEdit())  # undoes the 5 mm wall: the cause
    assert w.scene.design.shape.wall_thickness == pytest.approx(3.0)
    assert panel.message.text() == ""
    assert not w.statusBar().currentMessage().startswith("Refused")


def test_two_values_typed_a_moment_apart_are_two_steps(make_window, qtbot, monkeypatch):
    import app.commands as commands
    w = _active(make_window, qtbot)
    spin = w.materials_panel.fill_value
    _type(qtbot, spin, "95")
    monkeypatch.setattr(commands, "FIELD_MERGE_S", -1.0)  # as if the designer paused
    _type(qtbot, spin, "96")
    assert w.undo_stack.count() == 2
    _undo(qtbot, spin.lineEdit())
    assert w.scene.design.liquid.fill_value == pytest.approx(95.0)
