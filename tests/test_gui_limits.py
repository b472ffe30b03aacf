"""The panels refuse what a project may not hold (issue 11, class 3), naming the field, and a
shape edit that takes the mouth below the liquid lowers the liquid in the same undo step."""
from __future__ import annotations

import dataclasses

import pytest

from engine.geometry.segments import Line


@pytest.mark.parametrize("part, field", [
    (lambda d: dict(camera=dataclasses.replace(d.camera, fov_y_deg=0.0)), "design.camera.fov_y_deg"),
    (lambda d: dict(camera=dataclasses.replace(d.camera, target=d.camera.eye)), "looks nowhere"),
    (lambda d: dict(glass=dataclasses.replace(d.glass, density_g_cm3=-2.5)), "design.glass.density_g_cm3"),
    (lambda d: dict(environment=dataclasses.replace(d.environment, scale=1e300)), "design.environment.scale"),
    (lambda d: dict(render=dataclasses.replace(d.render, min_weight=0.0)), "design.render.min_weight"),
    (lambda d: dict(liquid=dataclasses.replace(d.liquid, fill_value=1e6)), "design.liquid.fill_value"),
    (lambda d: dict(name="lone \ud800"), "design.name"),
])
def test_the_editor_refuses_out_of_range_values_naming_the_field(make_window, part, field):
    w = make_window()
    before = w.scene.design
    refused = []
    w.editor.refused.connect(refused.append)
    assert not w.editor.apply("hostile edit", None, **part(before))
    assert w.scene.design == before and w.undo_stack.count() == 0
    assert refused and field in refused[-1]


def test_lowering_the_mouth_below_the_liquid_lowers_the_liquid_too(make_window, tiny_design):
    full = dataclasses.replace(tiny_design, liquid=dataclasses.replace(tiny_design.liquid, fill_value=295.0))
    w = make_window(full)
    design = w.scene.design
    sec = design.shape.primary
    neck = sec.segments[-1]
    low_top = 285.0
    short = design.shape.with_section("profile", sec.replace_segment(
        len(sec) - 1, Line(neck.p0, (neck.p1[0], low_top))))
    assert neck.p0[1] < low_top
    assert w.editor.apply("Shorter neck", None, shape=short)
    assert w.scene.design.liquid.fill_value == pytest.approx(low_top)
    assert w.undo_stack.count() == 1
    w.undo_stack.undo()
    assert w.scene.design == design


def test_an_environment_image_too_large_to_embed_is_refused_before_it_is_read(make_window, tmp_path,
                                                                              monkeypatch):
    from engine.files.project import Limits
    w = make_window()
    big = tmp_path / "huge.exr"
    big.write_bytes(b"\0" * 2048)
    monkeypatch.setattr("widgets.camera_panel.DEFAULT_LIMITS", Limits(asset_bytes=1024))
    monkeypatch.setattr("pathlib.Path.read_bytes", lambda self: pytest.fail("read a file too large"))
    w.camera_panel.choose_environment_file = lambda: str(big)
    before = w.scene.design
    assert not w.camera_panel.load_environment()
    assert w.scene.design == before and "larger than 1024" in w.camera_panel.env_load.toolTip()
