"""Scene model: value-compared change sets, one notification per edit or batch, assets."""
from __future__ import annotations

import dataclasses

import pytest

from engine.model.design import Camera, Design, Glass, Liquid
from engine.model.scene import DESIGN_FIELDS, Scene, changed_fields
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape


def make_design(radius: float = 30.0) -> Design:
    sec = Section((Line((0, 0), (radius, 0)), Line((radius, 0), (radius, 100)),
                   Line((radius, 100), (radius, 120))))
    return Design(BottleShape("round", (("profile", sec),)))


def recorder(scene):
    calls = []
    scene.subscribe(lambda changed, s: calls.append((changed, s)))
    return calls


def test_replace_announces_only_really_changed_fields():
    scene = Scene(make_design())
    calls = recorder(scene)
    changed = scene.replace(glass=Glass(ior=1.5), camera=Camera())  # camera equal by value
    assert changed == {"glass"}
    assert calls == [(frozenset({"glass"}), scene)]
    assert scene.design.glass.ior == 1.5


def test_equal_value_announces_nothing():
    scene = Scene(make_design())
    calls = recorder(scene)
    assert scene.set_design(make_design()) == frozenset()
    assert scene.replace(glass=Glass()) == frozenset()
    assert calls == []


def test_shape_change_compared_by_value():
    scene = Scene(make_design(30.0))
    calls = recorder(scene)
    scene.set_design(dataclasses.replace(make_design(31.0), name="Other"))
    assert calls[0][0] == {"shape", "name"}


def test_batch_gives_one_notification_with_union():
    scene = Scene(make_design())
    calls = recorder(scene)
    with scene.batch():
        scene.replace(glass=Glass(ior=1.6))
        with scene.batch():
            scene.replace(liquid=Liquid())
        scene.set_asset("env.exr", b"x")
        assert calls == []
    assert [c for c, _ in calls] == [frozenset({"glass", "liquid", "assets"})]


def test_batch_with_no_change_is_silent():
    scene = Scene(make_design())
    calls = recorder(scene)
    with scene.batch():
        scene.replace(glass=Glass())
    assert calls == []


def test_unsubscribe_stops_notifications():
    scene = Scene(make_design())
    calls = []
    unsubscribe = scene.subscribe(lambda c, s: calls.append(c))
    scene.replace(name="a")
    unsubscribe()
    unsubscribe()  # harmless twice
    scene.replace(name="b")
    assert calls == [frozenset({"name"})]


def test_snapshot_is_frozen_value_unaffected_by_later_edits():
    scene = Scene(make_design())
    snap = scene.snapshot()
    scene.replace(glass=Glass(ior=1.7))
    assert snap.glass.ior == 1.52
    with pytest.raises(dataclasses.FrozenInstanceError):
        snap.name = "x"  # type: ignore[misc]


def test_assets_read_only_and_set_asset_changes():
    scene = Scene(make_design(), {"a.png": b"1"})
    calls = recorder(scene)
    with pytest.raises(TypeError):
        scene.assets["b"] = b"2"  # type: ignore[index]
    assert scene.set_asset("a.png", b"1") is False
    assert scene.set_asset("a.png", b"2") is True
    assert scene.set_asset("a.png", None) is True
    assert scene.set_asset("a.png", None) is False
    assert dict(scene.assets) == {}
    assert [c for c, _ in calls] == [frozenset({"assets"})] * 2


def test_replace_rejects_unknown_field():
    scene = Scene(make_design())
    with pytest.raises(TypeError, match="bogus"):
        scene.replace(bogus=1)


def test_failing_observer_does_not_starve_others():
    scene = Scene(make_design())
    seen = []

    def bad(changed, s):
        raise RuntimeError("panel bug")
    scene.subscribe(bad)
    scene.subscribe(lambda c, s: seen.append(c))
    with pytest.raises(RuntimeError):
        scene.replace(name="x")
    assert seen == [frozenset({"name"})]
    assert scene.design.name == "x"


def test_load_replaces_design_and_assets_in_one_notification():
    scene = Scene(make_design(), {"old": b"1"})
    calls = recorder(scene)
    changed = scene.load(make_design(40.0), {"new": b"2"})
    assert changed == {"shape", "assets"}
    assert len(calls) == 1 and dict(scene.assets) == {"new": b"2"}


def test_changed_fields_and_field_names():
    a, b = make_design(), dataclasses.replace(make_design(), notes="n")
    assert changed_fields(a, b) == {"notes"}
    assert {"shape", "glass", "liquid", "camera", "render"} <= DESIGN_FIELDS
