"""Stage edits in the engine: the kinds a designer types, which fields a kind draws, hex colours
both ways, and a stage edit announced by the scene as the change it is and rendered anew."""
from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import pytest

from engine.color import hex_to_linear, linear_to_hex
from engine.model.changes import Change
from engine.model.design import BACKDROP_KINDS, STAGE_KINDS, Stage
from engine.model.scene import Scene
from engine.operations.stage import KIND_NAMES, STAGE_USES, stage_kind, unused
from engine.tracer.reuse import FULL_RENDER, KEEP_FILM, reuse_of
from tests.test_tracer import simple_design


def test_kinds_are_read_in_any_case_with_the_shadow_catcher_alias():
    assert [stage_kind(k) for k in STAGE_KINDS] == list(STAGE_KINDS)
    assert stage_kind(" Table ") == "table" and stage_kind("shadow-catcher") == "shadow"
    assert stage_kind("tabel") is None and stage_kind(3) is None and stage_kind(None) is None
    assert set(STAGE_USES) == set(STAGE_KINDS)
    assert KIND_NAMES == "none, shadow (shadow-catcher), table, glossy, mirror"


def test_only_what_a_kind_draws_may_be_given():
    assert unused("glossy", {"kind": "glossy", "color": (1, 1, 1), "gloss": 0.5}) == []
    assert unused("glossy", {"backdrop": True}) == [] and unused("table", {"backdrop": True}) == []
    assert unused("mirror", {"backdrop": True}) == ["backdrop"]
    assert {k for k, uses in STAGE_USES.items() if "backdrop" in uses} == set(BACKDROP_KINDS), \
        "the kinds offered a sweep are the kinds that draw one"
    assert unused("table", {"gloss": 0.5, "color": (1, 1, 1)}) == ["gloss"]
    assert unused("shadow", {"color": (1, 1, 1), "backdrop": True}) == ["color", "backdrop"]
    assert unused("none", {"backdrop": True}) == ["backdrop"]
    assert unused("none", {"backdrop": False}) == [], "turning the backdrop off is never in vain"


def test_hex_colours_go_to_linear_and_back_exactly():
    for level in range(256):
        grey = f"#{level:02x}{level:02x}{level:02x}"
        assert linear_to_hex(hex_to_linear(grey)) == grey
    assert linear_to_hex(hex_to_linear("#C8A040")) == "#c8a040"
    assert hex_to_linear("#808080") == pytest.approx((0.215861,) * 3, abs=1e-6)
    assert linear_to_hex((-1.0, 0.5, 2.0)) == "#00bcff", "clamped to 0..1 first"


def test_a_stage_edit_is_announced_as_the_field_stage():
    scene = Scene(simple_design())
    seen = []
    scene.subscribe(lambda changed, s: seen.append(changed))
    scene.replace(stage=Stage(kind="table"))
    assert seen == [Change({"stage"})] and seen[0].fields == {"stage"}


def _finished_job(design):
    """A stand-in for a finished, error-free render of ``design`` (all :func:`reuse_of` reads)."""
    return SimpleNamespace(done=True, error=None, cancelled=False, sampling_key=lambda: "sampling",
                           design=design, assets={}, records=None, context=None)


def test_reuse_keeps_the_film_for_the_notes_and_not_for_the_glass():
    design = simple_design()
    previous = _finished_job(design)
    assert reuse_of(previous, dataclasses.replace(design, notes="n"), {}, "sampling", Change({"notes"})) == KEEP_FILM
    glass = dataclasses.replace(design, glass=dataclasses.replace(design.glass, ior=1.6))
    assert reuse_of(previous, glass, {}, "sampling", Change({"glass"})) is FULL_RENDER


def test_a_stage_edit_needs_a_full_render():
    design = simple_design()
    previous = _finished_job(design)
    staged = dataclasses.replace(design, stage=Stage(kind="table"))
    assert reuse_of(previous, staged, {}, "sampling", Change({"stage"})) is FULL_RENDER


def test_with_a_lit_ground_a_label_or_light_edit_renders_again_instead_of_relabelling():
    """The lights' caustic grid on the ground depends on the labels (they block the light) and
    the lights, and no relabel record holds the ground's light."""
    from engine.model.design import Light
    design = dataclasses.replace(simple_design(), stage=Stage(kind="table"), lights=(Light(),))
    previous = _finished_job(design)
    brighter = dataclasses.replace(design, lights=(Light(intensity=2.0),))
    assert reuse_of(previous, brighter, {}, "sampling", Change({"lights"})) is FULL_RENDER
