"""The section panel with outline bottles: the kind shows with its core and rounding sections,
and no other bottle converts to one yet (the Plan tab edits an outline bottle's plan; nothing
turns another kind into one)."""
from __future__ import annotations

import dataclasses
import os

from benchmarks.oracle_spec import spec_to_design

SPEC = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "oracle", "specs", "outline_public_1.json")


def _outline_item(panel):
    combo = panel.kind_combo
    return combo.model().item(combo.findData("outline"))


def test_the_outline_kind_is_offered_only_to_an_outline_bottle(make_window, qtbot):
    w = make_window()
    panel = w.section_panel
    assert not _outline_item(panel).isEnabled(), "a round bottle has no plan to become an outline"
    assert "cannot turn another kind" in _outline_item(panel).toolTip()
    design, assets = spec_to_design(SPEC)
    design = dataclasses.replace(design, render=dataclasses.replace(design.render, width=24, height=24, spp=1))
    w.files.replace_document(design, assets, None)
    qtbot.waitUntil(lambda: panel.kind_combo.currentData() == "outline", timeout=10000)
    assert _outline_item(panel).isEnabled()
    assert [panel.name_combo.itemData(i) for i in range(panel.name_combo.count())] == ["core", "round"]
    qtbot.waitUntil(w.derived_idle, timeout=60000)


def test_the_wall_of_an_outline_bottle_is_edited_and_undone_with_its_plan_kept(make_window, qtbot):
    design, assets = spec_to_design(SPEC)
    design = dataclasses.replace(design, render=dataclasses.replace(design.render, width=24, height=24, spp=1))
    w = make_window(design, assets=assets)
    panel = w.section_panel
    plan = w.scene.design.shape.plan
    panel.wall_spin.setValue(2.5)
    assert w.scene.design.shape.wall_thickness == 2.5
    assert w.scene.design.shape.plan == plan
    w.undo_stack.undo()
    assert w.scene.design.shape.wall_thickness == 3.0
    qtbot.waitUntil(w.derived_idle, timeout=60000)
