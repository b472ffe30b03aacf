"""The Stage tab: each edit one undoable step, the panel following the scene, only the controls a
kind draws enabled, colours picked in sRGB and stored linear, and the preview rendering the
stage anew."""
from __future__ import annotations

import pytest
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QColorDialog

from engine.color import hex_to_linear, linear_to_hex
from engine.model.design import STAGE_KINDS, Stage
from widgets import words

pytestmark = pytest.mark.usefixtures("no_leaks")


def _shown_kind(panel) -> str:
    return panel.kind.currentData()


def test_choosing_a_table_is_one_undoable_step_and_the_panel_follows_the_scene(make_window):
    w = make_window()
    panel, steps = w.stage_panel, w.undo_stack.count()
    assert w.scene.design.stage.kind == "none" and _shown_kind(panel) == "none"
    assert words.keys_of(panel.kind) == list(STAGE_KINDS)
    assert panel.kind.currentText() == "None" and panel.kind.itemText(1) == "Shadow catcher"
    words.select_key(panel.kind, "table")
    assert w.scene.design.stage == Stage(kind="table")
    assert w.undo_stack.count() == steps + 1 and w.undo_stack.undoText() == "Stage: table"
    w.undo_stack.undo()
    assert w.scene.design.stage.kind == "none" and _shown_kind(panel) == "none"
    w.undo_stack.redo()
    assert _shown_kind(panel) == "table"
    # an edit made elsewhere (here from code, through the same editor) shows in the panel
    assert w.editor.apply("Riser", None, stage=Stage(kind="glossy", color=(0.1, 0.2, 0.3), gloss=0.3))
    assert _shown_kind(panel) == "glossy" and panel.gloss.value() == 0.3
    assert panel.color.text() == linear_to_hex((0.1, 0.2, 0.3))
    panel.gloss.setValue(0.8)
    assert w.scene.design.stage == Stage(kind="glossy", color=(0.1, 0.2, 0.3), gloss=0.8)
    w.undo_stack.undo()
    assert w.scene.design.stage.gloss == 0.3 and panel.gloss.value() == 0.3, "the gloss was a step of its own"


def test_the_backdrop_sweep_is_one_undoable_step_offered_for_a_table_or_riser(make_window):
    w = make_window()
    panel = w.stage_panel
    assert not panel.backdrop.isEnabled(), "nothing to raise a sweep from without a table"
    words.select_key(panel.kind, "table")
    assert panel.backdrop.isEnabled() and not panel.backdrop.isChecked()
    steps = w.undo_stack.count()
    panel.backdrop.click()
    assert w.scene.design.stage == Stage(kind="table", backdrop=True)
    assert w.undo_stack.count() == steps + 1 and w.undo_stack.undoText() == "Backdrop sweep"
    words.select_key(panel.kind, "glossy")
    assert panel.backdrop.isEnabled() and panel.backdrop.isChecked(), "the riser rises behind too"
    words.select_key(panel.kind, "shadow")
    assert not panel.backdrop.isEnabled() and panel.backdrop.isChecked(), "kept, greyed, not drawn"
    assert not w.scene.design.stage.draws_backdrop
    w.undo_stack.undo()
    w.undo_stack.undo()
    assert w.scene.design.stage == Stage(kind="table", backdrop=True) and panel.backdrop.isChecked()
    w.undo_stack.undo()
    assert w.scene.design.stage == Stage(kind="table") and not panel.backdrop.isChecked()


def test_gloss_is_enabled_only_for_the_glossy_riser(make_window):
    w = make_window()
    panel = w.stage_panel
    enabled = {}
    for kind in STAGE_KINDS:
        words.select_key(panel.kind, kind)
        assert w.scene.design.stage.kind == kind
        enabled[kind] = (panel.color.isEnabled(), panel.gloss.isEnabled())
    assert enabled == {"none": (False, False), "shadow": (False, False), "table": (True, False),
                       "glossy": (True, True), "mirror": (True, False)}
    w.undo_stack.undo()  # back to the riser, from the scene: the panel enables its gloss again
    assert _shown_kind(panel) == "glossy" and panel.gloss.isEnabled()
    for control in (panel.kind, panel.color, panel.gloss, panel.backdrop):
        assert control.toolTip(), "every control says what it does"


def test_a_colour_is_picked_in_srgb_and_lands_linear_in_the_model(make_window, monkeypatch):
    w = make_window()
    panel = w.stage_panel
    words.select_key(panel.kind, "table")
    assert panel.set_color((0.5, 0.25, 0.125))
    assert w.scene.design.stage.color == (0.5, 0.25, 0.125)
    assert panel.color.text() == linear_to_hex((0.5, 0.25, 0.125)), "the button shows it in sRGB"
    asked = []

    def get_color(initial, parent, title):
        asked.append(initial.name())
        return QColor("#808080")
    monkeypatch.setattr(QColorDialog, "getColor", staticmethod(get_color))
    panel.color.click()
    assert asked == [linear_to_hex((0.5, 0.25, 0.125))], "the dialog starts from the colour in sRGB"
    assert w.scene.design.stage.color == pytest.approx(hex_to_linear("#808080"), abs=1e-6)
    assert w.scene.design.stage.color[0] == pytest.approx(0.2159, abs=1e-4), "linear, not 128/255"
    assert panel.color.text() == "#808080"
    w.undo_stack.undo()
    assert w.scene.design.stage.color == (0.5, 0.25, 0.125)


def test_a_refused_colour_leaves_the_model_and_the_panel_as_they_were(make_window):
    w = make_window()
    panel = w.stage_panel
    words.select_key(panel.kind, "mirror")
    before, steps = w.scene.design, w.undo_stack.count()
    assert not panel.set_color((2.0, 0.0, 0.0))
    assert w.scene.design == before and w.undo_stack.count() == steps
    assert "design.stage.color[0]" in w.statusBar().currentMessage()
    assert panel.color.text() == linear_to_hex(before.stage.color)


def test_the_stage_is_a_tab_beside_the_camera(make_window):
    w = make_window()
    tabs = w.tabifiedDockWidgets(w.docks["materials"])
    assert w.docks["stage"] in tabs and w.docks["stage"].windowTitle() == "Stage"
    assert w.docks["stage"].widget().widget() is w.stage_panel
    view = next(a.menu() for a in w.menuBar().actions() if a.text() == "&View")
    assert w.docks["stage"].toggleViewAction() in view.actions(), "View lists the tab"


def _converged_job(qtbot, w):
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=120_000)
    return rc.job


def test_a_stage_edit_starts_a_render_of_the_new_stage(make_window, qtbot):
    w = make_window()
    rc = w.render_controller
    first = _converged_job(qtbot, w)
    generation = rc.generation
    words.select_key(w.stage_panel.kind, "table")
    assert rc.generation == generation + 1 and "stage" in rc._since_full
    rc.wait_until_idle(0)
    qtbot.waitUntil(lambda: rc.job is not first and rc.job.done, timeout=120_000)
    assert rc.job.error is None and rc.job.design.stage.kind == "table"


def test_a_stage_edit_is_traced_anew_not_kept(make_window, qtbot):
    w = make_window()
    rc = w.render_controller
    first = _converged_job(qtbot, w)
    words.select_key(w.stage_panel.kind, "mirror")
    rc.wait_until_idle(0)
    qtbot.waitUntil(lambda: rc.job is not first and rc.job.done, timeout=120_000)
    assert rc.job.film is not first.film and rc.job.stats.rays_cast > 0
