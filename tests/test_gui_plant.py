"""The plant's figures in the window (issue 43): computed off the GUI thread with the trade
numbers, shown in the Design panel's Plant group and following a shape edit; the plant's limits
edited there as undoable steps, their warnings in the section's amber; a non-round plan's stress
a dash with the reason; File > Export > Drawing writing the sheet."""
from __future__ import annotations

import dataclasses

import pytest

from benchmarks.oracle_spec import spec_to_design
from engine.files.project import load_project
from engine.plant.sheet import plant_numbers
from tests.export_helpers import RESOURCES
from tests.test_gui_export import FakeOptions  # the export options dialog, answered
from widgets.trade_panel import AMBER, DASH, STATES, plant_texts

pytestmark = pytest.mark.usefixtures("no_leaks")
SPECS = RESOURCES.parents[1] / "shared" / "oracle" / "specs"

#: Longest the drawing export may take here (ms).
EXPORT_MS = 120_000


def _sample(name):
    """A bundled sample at a tiny render size (the preview is not what these tests look at)."""
    design, assets = load_project(RESOURCES / f"{name}.glassbench")
    small = dataclasses.replace(design.render, width=24, height=32, spp=1)
    return dataclasses.replace(design, render=small), assets


def _shown(w, qtbot):
    """Wait until the derived numbers shown are the current design's; the panel."""
    qtbot.waitUntil(w.derived_idle, timeout=60_000)
    return w.trade_panel


def _assert_panel_shows(panel, plant):
    for key, (text, _) in plant_texts(plant).items():
        assert panel.plant_text(key) == text, key


def test_the_plant_group_shows_the_engines_figures_and_follows_a_wall_edit(make_window, qtbot):
    design, assets = _sample("bordeaux")
    w = make_window(design, assets=assets)
    panel = _shown(w, qtbot)
    before = w.plant_numbers
    assert before == plant_numbers(w.scene.design, tolerant=True), "the worker's are the engine's"
    _assert_panel_shows(panel, before)
    for key in ("least_tip", "weight_to_capacity", "capacity_band", "max_stress",
                *(f"{kind}_{state}" for kind in ("tip", "cg") for state in STATES)):
        assert panel.plant_text(key) != DASH, f"a filled round bottle has {key}"
    assert panel.plant_text("least_tip").startswith(f"{before['least_tip']['deg']:.1f}\u00b0")
    assert "\u00b1" in panel.plant_text("capacity_band") and "MPa" in panel.plant_text("max_stress")

    wall = w.section_panel.wall_spin
    wall.setValue(wall.value() + 1.0)  # a heavier glass: more grams per millilitre
    assert w.scene.design.shape.wall_thickness == pytest.approx(design.shape.wall_thickness + 1.0)
    qtbot.waitUntil(lambda: w.derived_idle() and w.plant_numbers is not before, timeout=60_000)
    after = w.plant_numbers
    assert after == plant_numbers(w.scene.design, tolerant=True)
    assert after["weight_to_capacity"]["ratio_g_per_ml"] > before["weight_to_capacity"]["ratio_g_per_ml"]
    assert panel.plant_text("weight_to_capacity") != plant_texts(before)["weight_to_capacity"][0]
    _assert_panel_shows(panel, after)


def test_a_tip_limit_above_the_bottles_tip_angle_warns_in_amber_and_undo_clears_it(make_window, qtbot):
    design, assets = _sample("bordeaux")
    w = make_window(design, assets=assets)
    panel = _shown(w, qtbot)
    assert panel.plant_warnings.text() == "" and w.plant_numbers["warnings"] == []
    least = w.plant_numbers["least_tip"]["deg"]
    limit = panel.plant_fields["min_tip_deg"]
    assert limit.value() == pytest.approx(design.plant.min_tip_deg)

    limit.setValue(round(least + 5.0, 1))
    assert w.scene.design.plant.min_tip_deg == pytest.approx(round(least + 5.0, 1))
    assert w.scene.design.plant == dataclasses.replace(design.plant, min_tip_deg=w.scene.design.plant.min_tip_deg)
    assert w.undo_stack.count() == 1 and "least tip angle" in w.undo_action.text()
    qtbot.waitUntil(lambda: w.derived_idle() and panel.plant_warnings.text() != "", timeout=60_000)
    assert panel.plant_warnings.text() == "\n".join(f"\u26a0 {t}" for t in w.plant_numbers["warnings"])
    assert AMBER in panel.plant_warnings.styleSheet()
    assert panel.plant_warnings.styleSheet() == w.section_panel.warnings.styleSheet(), "the same amber"
    assert panel.plant_text("least_tip") == plant_texts(w.plant_numbers)["least_tip"][0], \
        "a limit changes no figure"

    w.undo_stack.undo()
    assert w.scene.design.plant == design.plant
    assert limit.value() == pytest.approx(design.plant.min_tip_deg), "the field follows the undo"
    assert w.undo_stack.count() == 1 and w.undo_stack.index() == 0, "no echo from the refresh"
    qtbot.waitUntil(lambda: w.derived_idle() and panel.plant_warnings.text() == "", timeout=60_000)
    assert w.plant_numbers["warnings"] == []


def test_every_plant_setting_is_an_undoable_edit_of_design_plant(make_window, qtbot):
    design, assets = _sample("bordeaux")
    w = make_window(design, assets=assets)
    panel = w.trade_panel
    new = {"proof_pressure_mpa": 2.5, "liquid_density_g_ml": 1.05, "closure_mass_g": 12.0,
           "label_gsm": 80.0, "min_tip_deg": 5.0, "max_stress_mpa": 40.0, "min_glass_mass_g": 300.0}
    assert set(panel.plant_fields) == set(new)
    for field, value in new.items():
        assert panel.plant_fields[field].toolTip(), field
        panel.plant_fields[field].setValue(value)
    assert dataclasses.asdict(w.scene.design.plant) == pytest.approx(new)
    assert w.undo_stack.count() == len(new), "one step per field"
    while w.undo_stack.canUndo():
        w.undo_stack.undo()
    assert w.scene.design.plant == design.plant
    assert {f: s.value() for f, s in panel.plant_fields.items()} == \
        pytest.approx(dataclasses.asdict(design.plant))
    _shown(w, qtbot)


def test_a_non_round_plan_has_no_stress_figure_and_says_why(make_window, qtbot):
    design, assets = _sample("square")
    w = make_window(design, assets=assets)
    panel = _shown(w, qtbot)
    stress = w.plant_numbers["stress"]
    assert stress["max_mpa"] is None and stress["note"]
    assert panel.plant_text("max_stress") == DASH
    assert panel.plant_labels["max_stress"].toolTip() == stress["note"]
    assert panel.plant_text("least_tip") != DASH, "its stability is still given"


def test_an_outline_flacons_thin_shoulder_warns_where_and_how_thin(make_window, qtbot):
    """outline_public_1: its stability is given, its stress a dash with the outline's reason,
    and its shoulder's glass, thinner along its normal than the wall, one amber line."""
    design, assets = spec_to_design(SPECS / "outline_public_1.json")
    design = dataclasses.replace(design, render=dataclasses.replace(design.render, width=24, height=32, spp=1))
    w = make_window(design, assets=assets)
    panel = _shown(w, qtbot)
    plant = w.plant_numbers
    assert plant == plant_numbers(w.scene.design, tolerant=True)
    _assert_panel_shows(panel, plant)
    (run,) = plant["thin_wall"]
    assert panel.plant_warnings.text() == "\n".join(f"\u26a0 {t}" for t in plant["warnings"])
    assert f"from z = {run['z_from_mm']:.1f} to {run['z_to_mm']:.1f} mm" in panel.plant_warnings.text()
    assert f"{run['least_mm']:.2f} mm thick along its normal" in panel.plant_warnings.text()
    assert panel.plant_text("least_tip") != DASH and panel.plant_text("max_stress") == DASH
    assert panel.plant_labels["max_stress"].toolTip() == plant["stress"]["note"]


def test_a_design_with_no_plant_numbers_shows_dashes(make_window, qtbot):
    w = make_window()
    panel = _shown(w, qtbot)
    panel.show_plant(None)
    assert {panel.plant_text(key) for key in panel.plant_labels} == {DASH}
    assert panel.plant_warnings.text() == ""


# ----------------------------------------------------------------------------- export
def test_the_export_menus_drawing_action_writes_a_pdf(make_window, qtbot, tmp_path):
    design, assets = _sample("bordeaux")
    w = make_window(design, assets=assets)
    exports = w.files.exports
    file_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&File")
    export_menu = next(a.menu() for a in file_menu.actions() if a.menu() and "xport" in a.text())
    action = exports.actions["drawing"]
    assert action in export_menu.actions() and "Drawing" in action.text()
    exports.dialogs = FakeOptions(sheet="A4")
    out = tmp_path / "bordeaux"  # no suffix typed: a PDF
    w.dialogs.save_path = str(out)
    with qtbot.waitSignal(exports.finished, timeout=EXPORT_MS) as blocker:
        action.trigger()
    ok, message = blocker.args
    pdf = tmp_path / "bordeaux.pdf"
    assert ok, message
    assert exports.dialogs.asked == ["drawing"] and w.dialogs.errors == []
    assert str(pdf) in message and not exports.bar.isVisible()
    assert pdf.read_bytes()[:5] == b"%PDF-"


def test_a_refused_drawing_is_a_one_line_error(make_window, qtbot, tmp_path):
    w = make_window()
    exports = w.files.exports
    exports.dialogs = FakeOptions(sheet="A3")
    w.dialogs.save_path = str(tmp_path / "missing" / "folder" / "sheet.pdf")
    with qtbot.waitSignal(exports.finished, timeout=EXPORT_MS) as blocker:
        exports.actions["drawing"].trigger()
    assert blocker.args[0] is False
    [(title, text)] = w.dialogs.errors
    assert title == "Cannot export drawing" and "sheet.pdf" in text
