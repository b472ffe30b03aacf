"""The bump tiles' one door (issue 44, item 1): every edit of a tile is an operation of
engine.operations.tiles returning an Edit; the rules and their words are the model's; an image
no tile uses any more leaves the project, one shared with a label stays."""
from __future__ import annotations

import dataclasses
import io

import numpy as np
from PIL import Image
import pytest

from engine.errors import DesignError
from engine.files.project import load_project
from engine.operations import tiles
from engine.operations.edit import assets_in_use
from tests.export_helpers import RESOURCES


@pytest.fixture
def frosted():
    return load_project(RESOURCES / "frosted_logo.glassbench")


def _logo(frosted) -> int:
    design, _ = frosted
    return next(i for i, t in enumerate(design.bumps) if t.asset is not None)


def test_removing_an_image_tile_releases_its_image_unless_a_label_prints_it(frosted):
    design, assets = frosted
    i = _logo(frosted)
    edit = tiles.remove_tile(design, i)
    asset = design.bumps[i].asset
    assert edit.assets == {asset: None} and asset not in edit.assets_after(assets)
    # the same image also printed by a label: it stays
    labelled, _ = load_project(RESOURCES / "labelled.glassbench")
    label = dataclasses.replace(labelled.labels[0], front=dataclasses.replace(labelled.labels[0].front, asset=asset))
    shared = dataclasses.replace(design, labels=(label,))
    assert tiles.remove_tile(shared, i).assets == {}


def test_a_thread_is_refused_on_the_cap_in_the_models_words(frosted):
    design, assets = frosted
    capped, _ = load_project(RESOURCES / "threaded_bottle.glassbench")
    k = next(i for i, t in enumerate(capped.bumps) if t.kind == "thread")
    with pytest.raises(DesignError, match="a thread belongs to the glass finish"):
        tiles.set_tile_surface(capped, k, "cap")
    with pytest.raises(DesignError, match="a thread belongs to the glass finish"):
        tiles.add_tile(capped, {}, "thread", 1.0, 5.0, on="cap")


def test_replacing_an_image_lets_the_old_one_go_and_a_bad_edit_changes_nothing(frosted):
    design, assets = frosted
    i = _logo(frosted)
    old = design.bumps[i].asset
    buf = io.BytesIO()
    Image.fromarray(np.tile(np.arange(64, dtype=np.uint8), (32, 1))).save(buf, "PNG")
    edit = tiles.set_tile_image(design, assets, i, "ramp.png", buf.getvalue())
    after = edit.assets_after(assets)
    assert edit.design.bumps[i].asset == "ramp.png" and after["ramp.png"] == buf.getvalue()
    assert old not in after and set(after) >= assets_in_use(edit.design)
    with pytest.raises(DesignError, match="depth"):
        tiles.edit_tile(design, i, "Tile depth", depth=-1.0)
    assert tiles.edit_tile(design, i, "Tile depth", depth=design.bumps[i].depth) is None


def test_moving_a_tile_swaps_it_and_stops_at_the_ends(frosted):
    design, _ = frosted
    edit = tiles.move_tile(design, 0, 1)
    assert edit.design.bumps == (design.bumps[1], design.bumps[0]) and edit.select == 1
    assert tiles.move_tile(design, 0, -1) is None
