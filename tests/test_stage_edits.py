"""Stage edits in the engine: the kinds a designer types, which fields a kind draws, hex colours
both ways, and a stage edit announced by the scene as the change it is."""
from __future__ import annotations

import pytest

from engine.color import hex_to_linear, linear_to_hex
from engine.model.changes import Change
from engine.model.design import STAGE_KINDS, Stage
from engine.model.scene import Scene
from engine.operations.stage import KIND_NAMES, STAGE_USES, stage_kind, unused
from tests.test_tracer import simple_design


def test_kinds_are_read_in_any_case_with_the_shadow_catcher_alias():
    assert [stage_kind(k) for k in STAGE_KINDS] == list(STAGE_KINDS)
    assert stage_kind(" Table ") == "table" and stage_kind("shadow-catcher") == "shadow"
    assert stage_kind("tabel") is None and stage_kind(3) is None and stage_kind(None) is None
    assert set(STAGE_USES) == set(STAGE_KINDS)
    assert KIND_NAMES == "none, shadow (shadow-catcher), table, glossy, mirror"


def test_only_what_a_kind_draws_may_be_given():
    assert unused("glossy", {"kind": "glossy", "color": (1, 1, 1), "gloss": 0.5, "backdrop": True}) == []
    assert unused("table", {"gloss": 0.5, "color": (1, 1, 1)}) == ["gloss"]
    assert unused("shadow", {"color": (1, 1, 1), "backdrop": True}) == ["color"]
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

