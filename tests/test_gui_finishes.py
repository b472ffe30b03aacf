"""The bump-tiles and cap panels in a real window: a tile added and its kind changed redraws
its swatch, a relief image is embedded (a bad one refused), a cap is set and unset, the trade
numbers show the closure and the overall height, and save / reopen keeps tiles, cap and images."""
from __future__ import annotations

import shutil
import zipfile

import numpy as np
import pytest

from tests.export_helpers import RESOURCES
from tests.label_helpers import write_image
from widgets import words

pytestmark = pytest.mark.usefixtures("no_leaks")


def _logo(tmp_path, name="logo.png"):
    px = np.full((32, 64), 255, np.uint8)
    px[8:24, 16:48] = 0
    return write_image(tmp_path / name, px[..., None].repeat(3, axis=2))


def test_adding_a_tile_and_changing_its_kind_redraws_the_swatch(make_window):
    w = make_window()
    panel = w.bumps_panel
    assert panel.swatch_pixels is None
    words.select_key(panel.add_kind, "knurl")
    panel.add_button.click()
    tiles = w.scene.design.bumps
    assert len(tiles) == 1 and tiles[0].kind == "knurl"
    knurl = panel.swatch_pixels.copy()
    assert knurl.shape == (128, 128, 3) and knurl.std() > 1.0, "a pattern, not a flat colour"
    words.select_key(panel.kind, "flutes")
    tile = w.scene.design.bumps[0]
    assert tile.kind == "flutes" and (tile.z0, tile.z1) == (tiles[0].z0, tiles[0].z1)
    assert tile.repeat == 16, "a new kind starts from its usual numbers"
    flutes = panel.swatch_pixels.copy()
    assert np.abs(flutes.astype(int) - knurl.astype(int)).mean() > 2.0
    panel.repeat.setValue(8)
    assert w.scene.design.bumps[0].repeat == 8
    assert np.abs(panel.swatch_pixels.astype(int) - flutes.astype(int)).mean() > 0.5, "edits redraw it"
    w.undo_stack.undo()
    w.undo_stack.undo()
    assert w.scene.design.bumps[0].kind == "knurl"
    assert np.array_equal(panel.swatch_pixels, knurl)
    panel.remove_button.click()
    assert w.scene.design.bumps == () and panel.swatch_pixels is None


def test_a_relief_image_tile_embeds_its_image_and_a_bad_one_is_refused(make_window, tmp_path):
    w = make_window()
    panel = w.bumps_panel
    data = _logo(tmp_path)
    panel.choose_image_file = lambda title: str(tmp_path / "logo.png")
    words.select_key(panel.add_kind, "emboss")
    panel.add_button.click()
    tile = w.scene.design.bumps[0]
    assert tile.kind == "emboss" and w.scene.assets[tile.asset] == data
    assert panel.swatch_pixels is not None
    (tmp_path / "bad.png").write_bytes(data[:40])
    panel.choose_image_file = lambda title: str(tmp_path / "bad.png")
    before = w.scene.design
    panel.add_button.click()
    assert w.scene.design == before and "bad.png" in panel.problem.text()
    panel.remove_button.click()
    assert tile.asset not in w.scene.assets, "an image no tile uses leaves the project"


def test_a_cap_set_and_unset_shows_in_the_trade_numbers(make_window, qtbot):
    w = make_window()
    panel = w.cap_panel
    qtbot.waitUntil(w.derived_idle)
    assert w.trade_panel.text("closure") == "\u2014"
    top = w.scene.design.shape.z_top
    words.select_key(panel.kind, "screw")
    assert w.scene.design.cap is not None and w.scene.design.cap.kind == "screw"
    qtbot.waitUntil(lambda: w.derived_idle() and w.trade_numbers.get("closure") is not None)
    assert w.trade_panel.text("closure").startswith("screw")
    overall = w.trade_numbers["overall_height_mm"]
    assert overall > top
    assert w.trade_panel.text("overall_height_mm") == f"{overall:.1f} mm"
    panel.cap_height.setValue(20.0)
    assert w.scene.design.cap.height == 20.0
    # a taller skirt reaches further down the neck: the closure is taller, its top stays put
    qtbot.waitUntil(lambda: w.derived_idle() and w.trade_numbers["closure"]["height_mm"] == 20.0)
    assert w.trade_panel.text("closure").endswith("\u00d7 20.0 mm") and "20.0 mm high" in panel.size_text.text()
    panel.choose_color = lambda rgb, title: (0.5, 0.1, 0.1)
    panel.color.click()
    assert w.scene.design.cap.color == (0.5, 0.1, 0.1)
    words.select_key(panel.kind, "none")
    assert w.scene.design.cap is None and not panel.material.isEnabled()
    qtbot.waitUntil(lambda: w.derived_idle() and w.trade_numbers.get("closure") is None)
    assert w.trade_panel.text("closure") == "\u2014"
    w.undo_stack.undo()
    assert w.scene.design.cap.color == (0.5, 0.1, 0.1)
    assert words.keys_of(panel.kind)[panel.kind.currentIndex()] == "screw"


def test_save_and_reopen_keeps_tiles_cap_and_images(make_window, tmp_path):
    w = make_window()
    data = _logo(tmp_path)
    w.bumps_panel.choose_image_file = lambda title: str(tmp_path / "logo.png")
    words.select_key(w.bumps_panel.add_kind, "emboss")
    w.bumps_panel.add_button.click()
    words.select_key(w.bumps_panel.add_kind, "thread")
    w.bumps_panel.add_button.click()
    words.select_key(w.cap_panel.kind, "lug")
    w.cap_panel.count.setValue(6)
    design = w.scene.design
    assert len(design.bumps) == 2 and design.cap.count == 6
    path = str(tmp_path / "finished.glassbench")
    assert w.files.save_to(path)
    w2 = make_window()
    assert w2.files.open_path(path, ask=False)
    assert w2.scene.design.bumps == design.bumps and w2.scene.design.cap == design.cap
    assert w2.scene.assets[design.bumps[0].asset] == data
    assert w2.bumps_panel.list.count() == 2 and w2.cap_panel.count.value() == 6


def test_the_new_tabs_fit_the_side_dock_without_squeezing(make_window, qtbot):
    w = make_window(wireframe=True)
    w.show()
    qtbot.waitExposed(w)
    for name, panel, spin in (("labels", w.labels_panel, w.labels_panel.placement.z_mm),
                              ("bumps", w.bumps_panel, w.bumps_panel.z0),
                              ("cap", w.cap_panel, w.cap_panel.cap_height)):
        w.docks[name].raise_()
        qtbot.waitUntil(spin.isVisible)
        assert w.tabifiedDockWidgets(w.docks["materials"]).count(w.docks[name]) == 1, "a tab, not a new pane"
        area = w.docks[name].widget()
        assert panel.minimumSizeHint().width() <= area.viewport().width(), f"{name} needs a side scroll bar"
        hint = spin.minimumSizeHint()
        assert spin.width() >= hint.width() and spin.height() >= hint.height()
    preview = w.preview.width() * w.preview.height()
    assert all(preview > d.width() * d.height() for d in w.docks.values() if d.isVisible())


def test_a_tile_moved_onto_the_cap_follows_its_skirt_and_is_refused_without_a_cap(make_window):
    from engine.appearance.bands import cap_band
    w = make_window()
    panel = w.bumps_panel
    words.select_key(panel.add_kind, "knurl")
    panel.add_button.click()
    before = w.scene.design
    words.select_key(panel.on, "cap")  # the sample has no cap: refused, nothing changes
    assert w.scene.design == before and "no cap" in panel.problem.text()
    assert panel.on.currentData() == "bottle"
    words.select_key(w.cap_panel.kind, "screw")
    words.select_key(panel.on, "cap")
    tile = w.scene.design.bumps[0]
    assert tile.on == "cap" and "on the cap" in panel.list.item(0).text()
    assert cap_band(w.scene.design, tile.z0, tile.z1) is not None, "the band lies on the skirt"
    assert "lower edge of the cap's skirt" in panel.z0.toolTip()
    w.undo_stack.undo()
    assert w.scene.design.bumps[0].on == "bottle" and panel.on.currentData() == "bottle"


def test_a_thread_shows_how_it_is_drawn_and_the_choice_is_undoable(make_window):
    w = make_window()
    panel = w.bumps_panel
    words.select_key(panel.add_kind, "thread")
    panel.add_button.click()
    tile = w.scene.design.bumps[0]
    assert tile.kind == "thread" and tile.geometry == "auto"
    assert panel.drawn_as.isEnabled() and "(auto)" in panel.drawing.text()
    words.select_key(panel.drawn_as, "true")
    assert w.scene.design.bumps[0].geometry == "true"
    assert panel.drawing.text().startswith("Drawn as true geometry, as chosen")
    words.select_key(panel.drawn_as, "relief")
    assert "relief, as chosen" in panel.drawing.text()
    w.undo_stack.undo()
    assert w.scene.design.bumps[0].geometry == "true" and panel.drawn_as.currentData() == "true"
    words.select_key(panel.add_kind, "knurl")
    panel.add_button.click()
    assert not panel.drawn_as.isEnabled() and panel.drawing.text() == ""


def _members(path) -> dict:
    with zipfile.ZipFile(path) as z:
        return {n: z.read(n) for n in z.namelist()}


@pytest.mark.parametrize("what", ["image tile", "plain tile"])
def test_removing_a_tile_through_either_door_saves_the_same_project(make_window, tmp_path, what):
    """``glassbench bump P remove I`` and the panel's Remove are one operation
    (:func:`engine.operations.tiles.remove_tile`): the saved projects agree member by member, and
    an image no tile uses any more is gone from both."""
    from engine import cli
    from engine.files.project import load_project
    source = RESOURCES / "frosted_logo.glassbench"   # a frosting and an embossed logo
    design, assets = load_project(source)
    i = next(k for k, t in enumerate(design.bumps) if (t.asset is not None) == (what == "image tile"))
    by_cli = tmp_path / "cli.glassbench"
    shutil.copyfile(source, by_cli)
    assert cli.main(["bump", str(by_cli), "remove", str(i)]) == 0
    w = make_window(design, assets=assets)
    w.bumps_panel.list.setCurrentRow(i)
    w.bumps_panel.remove_button.click()
    by_panel = tmp_path / "panel.glassbench"
    assert w.files.save_to(by_panel)
    cli_members, panel_members = _members(by_cli), _members(by_panel)
    assert cli_members == panel_members
    gone = design.bumps[i].asset
    if gone is not None:
        assert not any(name.endswith(gone) for name in cli_members), "the removed tile's image stays"
    assert load_project(by_cli)[0].bumps == design.bumps[:i] + design.bumps[i + 1:]


def test_a_closure_set_through_either_door_saves_the_same_project(make_window, tmp_path):
    """``glassbench cap P set crown --count 21`` and the Cap panel (kind, then count) are the
    operations of :mod:`engine.operations.closure`: the same project, member by member."""
    from engine import cli
    from engine.files.project import load_project
    source = RESOURCES / "bordeaux.glassbench"
    by_cli = tmp_path / "cli.glassbench"
    shutil.copyfile(source, by_cli)
    assert cli.main(["cap", str(by_cli), "set", "crown", "--count", "21"]) == 0
    design, assets = load_project(source)
    w = make_window(design, assets=assets)
    words.select_key(w.cap_panel.kind, "crown")
    w.cap_panel.count.setValue(21)
    by_panel = tmp_path / "panel.glassbench"
    assert w.files.save_to(by_panel)
    assert _members(by_cli) == _members(by_panel)
    assert load_project(by_cli)[0].cap.count == 21


def test_a_refusal_puts_every_panel_back_to_the_model_without_the_window_routing_it(make_window):
    """Panels follow the editor's refusals themselves (widgets.edit_fields.follow): a widget
    left showing what was asked for shows the model again; the window only says why."""
    from PySide6.QtCore import QSignalBlocker

    from app.layout import PANELS
    w = make_window()
    assert all(isinstance(getattr(w, p.attr), p.cls) for p in PANELS)
    design = w.scene.design
    asked = ((w.stage_panel.gloss, 0.123), (w.materials_panel.glass_ior, 1.9))
    for spin, value in asked:
        with QSignalBlocker(spin):
            spin.setValue(value)
    with QSignalBlocker(w.trade_panel.name):
        w.trade_panel.name.setText("not the name")
    w.editor.refused.emit("refused for the test")
    assert w.stage_panel.gloss.value() == design.stage.gloss
    assert w.materials_panel.glass_ior.value() == pytest.approx(design.glass.ior)
    assert w.trade_panel.name.text() == design.name
    assert w.statusBar().currentMessage() == "Refused: refused for the test"


def test_derived_numbers_reach_the_panels_without_the_window_routing_them(make_window, qtbot):
    """The numbers derived off the GUI thread come through the editor (``editor.derived``) and
    each panel that shows them follows them (widgets.edit_fields.follow); the window keeps its
    copy and names no panel. Every panel's ``refresh`` shows the design."""
    import inspect

    from app.layout import PANELS
    from app.window import MainWindow
    from app.wireframe_controller import Derived
    assert "_panel" not in inspect.getsource(MainWindow._on_derived)
    assert all(list(inspect.signature(p.cls.refresh).parameters)[1] == "design" for p in PANELS)
    w = make_window()
    qtbot.waitUntil(w.derived_idle)
    numbers = {"brimful_ml": 321.0, "fill_ml": 123.4, "fill_height_mm": 50.0}
    w.editor.derived.emit(Derived(w.scene.design, numbers, {}, ("a warning for the test",), None))
    assert w.trade_panel.text("brimful_ml") == "321.0 ml" and w.trade_panel.text("glass_mass_g") == "\u2014"
    assert w.trade_panel.plant_text("least_tip") == "\u2014"
    assert w.section_panel.warnings.text() == "\u26a0 a warning for the test"
    assert w.materials_panel.trade_numbers is numbers and w.trade_numbers is numbers
