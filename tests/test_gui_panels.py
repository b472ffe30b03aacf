"""Materials, trade numbers and camera panels: widget edits become commands, model changes
refresh the widgets without echo, trade numbers follow the section live."""
from __future__ import annotations

import pytest

from engine.model.design import Glass
from engine.model.tint import absorption_from_transmittance, transmittance
from widgets import words
from widgets.section_editor import Handle

pytestmark = pytest.mark.usefixtures("no_leaks")


def test_glass_ior_spin_box_is_an_undoable_command(make_window):
    w = make_window()
    panel = w.materials_panel
    panel.glass_ior.setValue(1.6)
    assert w.scene.design.glass.ior == pytest.approx(1.6)
    assert w.undo_action.text().endswith("Glass IOR")
    w.undo_stack.undo()
    assert panel.glass_ior.value() == pytest.approx(1.52)
    assert w.undo_stack.index() == 0 and w.undo_stack.count() == 1


def test_consecutive_spin_steps_merge_into_one_step(make_window):
    w = make_window()
    for v in (1.53, 1.54, 1.55):
        w.materials_panel.glass_ior.setValue(v)
    assert w.undo_stack.count() == 1
    w.undo_stack.undo()
    assert w.scene.design.glass.ior == pytest.approx(1.52)


def test_model_change_refreshes_the_panel_without_an_echo(make_window):
    w = make_window()
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.7, density_g_cm3=2.6))
    assert w.materials_panel.glass_ior.value() == pytest.approx(1.7)
    assert w.materials_panel.glass_density.value() == pytest.approx(2.6)
    assert w.undo_stack.count() == 1


def test_tint_colour_goes_through_the_replaceable_picker(make_window):
    w = make_window()
    panel = w.materials_panel
    panel.choose_color = lambda rgb, title: (0.5, 0.8, 0.6)
    panel.glass_tint.click()
    absorption = w.scene.design.glass.absorption
    assert transmittance(absorption, panel.glass_thickness.value()) == pytest.approx((0.5, 0.8, 0.6))
    panel.choose_color = lambda rgb, title: None  # a cancelled dialog changes nothing
    panel.glass_tint.click()
    assert w.undo_stack.count() == 1


def test_absorption_colour_round_trip():
    rgb = (0.2, 0.9, 1.0)
    assert transmittance(absorption_from_transmittance(rgb, 7.0), 7.0) == pytest.approx(rgb)


def test_fill_by_volume_keeps_the_level_and_updates_trade_numbers(make_window, qtbot):
    w = make_window()
    qtbot.waitUntil(w.derived_idle)
    panel = w.materials_panel
    height = w.scene.design.liquid.fill_value
    fill_ml = w.trade_numbers["fill_ml"]
    words.select_key(panel.fill_mode, "volume")
    qtbot.waitUntil(w.derived_idle)
    liquid = w.scene.design.liquid
    assert liquid.fill_mode == "volume"
    assert liquid.fill_value == pytest.approx(fill_ml, abs=0.01)
    assert w.trade_numbers["fill_height_mm"] == pytest.approx(height, abs=0.05)
    panel.fill_value.setValue(500.0)
    qtbot.waitUntil(w.derived_idle)
    assert w.trade_numbers["fill_ml"] == pytest.approx(500.0, rel=1e-6)
    assert w.trade_panel.text("fill_ml") == "500.0 ml"


def test_emptying_and_filling_the_bottle(make_window, qtbot):
    w = make_window()
    panel = w.materials_panel
    panel.filled.setChecked(False)
    qtbot.waitUntil(w.derived_idle)
    assert w.scene.design.liquid is None
    assert w.trade_panel.text("fill_ml") == "\u2014"
    assert not panel.fill_value.isEnabled()
    panel.filled.setChecked(True)
    assert w.scene.design.liquid is not None


def test_trade_numbers_follow_a_section_drag(make_window, qtbot):
    w = make_window()
    qtbot.waitUntil(w.derived_idle)
    brimful = w.trade_numbers["brimful_ml"]
    glass = w.trade_numbers["glass_mass_g"]
    canvas = w.section_panel.canvas
    sec = w.scene.design.shape.primary
    canvas.begin_drag(Handle("joint", 2, sec.segments[2].p1), "grow")
    canvas.drag_to((0.0, 20.0))
    canvas.end_drag()
    qtbot.waitUntil(w.derived_idle)
    assert w.trade_numbers["brimful_ml"] > brimful + 50
    assert w.trade_numbers["glass_mass_g"] > glass
    assert w.trade_panel.text("brimful_ml") == f"{w.trade_numbers['brimful_ml']:.1f} ml"


def test_camera_orbit_spin_boxes(make_window):
    w = make_window()
    cam_panel = w.camera_panel
    target = w.scene.design.camera.target
    cam_panel.azimuth.setValue(45.0)
    cam = w.scene.design.camera
    assert cam.target == target
    assert cam.eye[0] > 0 and cam.eye[1] < 0
    cam_panel.spp.setValue(2)
    assert w.scene.design.render.spp == 2
    w.undo_stack.undo()
    w.undo_stack.undo()
    assert cam_panel.azimuth.value() == pytest.approx(0.0, abs=0.05)


def _write_sky_exr(path):
    """A tiny equirectangular environment: bright sky over a dark floor."""
    import numpy as np
    import OpenImageIO as oiio
    pixels = np.zeros((16, 32, 3), np.float32)
    pixels[:8] = (1.5, 1.6, 1.8)
    pixels[8:] = (0.1, 0.08, 0.05)
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(32, 16, 3, "float"))
    out.write_image(pixels)
    out.close()


def test_environment_image_is_embedded_with_one_undoable_step(make_window, qtbot, tmp_path):
    w = make_window()
    studio = tmp_path / "studio.exr"
    _write_sky_exr(studio)
    w.camera_panel.choose_environment_file = lambda: str(studio)
    w.camera_panel.env_load.click()
    env = w.scene.design.environment
    assert (env.kind, env.asset) == ("file", "studio.exr")
    assert w.scene.assets["studio.exr"][:4] == b"\x76\x2f\x31\x01"  # OpenEXR magic
    assert w.camera_panel.env_kind.currentData() == "file"
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=60_000)
    assert rc.converged_generation == rc.generation, "the tracer lit the bottle with the image"
    w.undo_stack.undo()
    assert w.scene.design.environment.kind == "studio"
    assert "studio.exr" not in w.scene.assets
    assert w.camera_panel.env_kind.currentData() == "studio"


def test_a_fill_level_above_the_mouth_is_refused(make_window):
    w = make_window()
    before = w.scene.design
    w.materials_panel.fill_value.setValue(5000.0)
    assert w.scene.design == before
    assert "fill height" in w.statusBar().currentMessage()
    assert w.materials_panel.fill_value.value() == pytest.approx(before.liquid.fill_value)


def test_a_refractive_index_below_one_is_refused(make_window):
    w = make_window()
    assert not w.editor.apply("Glass IOR", None, glass=Glass(ior=0.5))
    assert w.scene.design.glass.ior == pytest.approx(1.52)
