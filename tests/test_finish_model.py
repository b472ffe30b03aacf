"""Bump tiles and closures as data: ranges, the format 1 -> 2 migration, exact round trips."""
from __future__ import annotations

import copy
import dataclasses
import io
import json
import zipfile

import numpy as np
import pytest

from engine.errors import DesignError, ProjectError
from engine.files.migrate_finishes import migrate_1_to_2
from engine.files.project import load_project, load_project_bytes, save_project
from engine.operations.check import check_design
from engine.files.serialize import CURRENT_FORMAT, MIGRATIONS, design_to_dict
from engine.model.check import check_values
from engine.model.design import BUMP_KINDS, BumpTile, Cap, Design
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape


def bottle(neck_r=14.0, top=200.0) -> Design:
    sec = Section((Line((0, 0), (35, 0)), Line((35, 0), (35, 150)), Line((35, 150), (neck_r, 170)),
                   Line((neck_r, 170), (neck_r, top))), (False, False, False))
    return Design(BottleShape("round", (("profile", sec),), 2.5, 5.0), name="finish test")


def png(w=8, h=6) -> bytes:
    from PIL import Image
    buf = io.BytesIO()
    Image.fromarray((np.arange(w * h).reshape(h, w) * 4 % 256).astype(np.uint8)).save(buf, "PNG")
    return buf.getvalue()


def every_finish() -> Design:
    tiles = tuple(BumpTile(kind, kind, z0=10.0 + i, z1=60.0 + i, repeat=3 + i, depth=0.25,
                           asset="art.png" if kind in ("height_map", "colour_code", "normal_gl",
                                                       "normal_dx", "emboss") else None,
                           finish="28-410" if kind == "thread" else "", inverted=i % 2 == 1)
                  for i, kind in enumerate(BUMP_KINDS))
    return dataclasses.replace(bottle(), bumps=tiles, cap=Cap("ropp", "metal", (1.0, 0.7, 0.3), 55.0, 40))


def test_every_kind_round_trips_exactly(tmp_path):
    path = tmp_path / "f.glassbench"
    design = every_finish()
    save_project(path, design, {"art.png": png()})
    loaded, assets = load_project(path)
    assert loaded == design and set(assets) == {"art.png"}
    assert json.loads(zipfile.ZipFile(path).read("project.json"))["format_version"] == CURRENT_FORMAT


@pytest.mark.parametrize("change, message", [
    (dict(kind="wobble"), "is not one of"),
    (dict(z0=50.0, z1=40.0), "not above its bottom"),
    (dict(z1=float("nan")), "outside"),
    (dict(repeat=0), "repeat"),
    (dict(repeat=10 ** 6), "repeat"),
    (dict(kind="facets", repeat=2), "at least 3"),
    (dict(depth=-0.1), "depth"),
    (dict(depth=11.0), "depth"),
    (dict(width=1.5), "width"),
    (dict(alpha=0.6), "alpha"),
    (dict(alpha=0.01), "alpha"),
    (dict(kind="emboss"), "names no image"),
    (dict(asset="x.png"), "takes no image"),
    (dict(kind="thread", finish="27-999"), "not a finish"),
    (dict(width_deg=0.0), "width_deg"),
])
def test_bad_tiles_name_the_field(change, message):
    design = dataclasses.replace(bottle(), bumps=(BumpTile(**change),))
    with pytest.raises(DesignError, match=message) as info:
        check_values(design)
    assert "design.bumps[0]" in str(info.value)


@pytest.mark.parametrize("change, message", [
    (dict(kind="cap"), "is not one of"),
    (dict(material="wood"), "material"),
    (dict(color=(1.2, 0.0, 0.0)), r"color\[0\]"),
    (dict(height=-1.0), "height"),
    (dict(height=400.0), "height"),
    (dict(count=-1), "count"),
    (dict(kind="lug", count=12), "count"),
    (dict(kind="crown", count=2), "at least 3"),
])
def test_bad_caps_name_the_field(change, message):
    with pytest.raises(DesignError, match=message):
        check_values(dataclasses.replace(bottle(), cap=Cap(**change)))


def test_a_tile_names_an_asset_the_project_lacks():
    design = dataclasses.replace(bottle(), bumps=(BumpTile(kind="emboss", asset="logo.png"),))
    with pytest.raises(ProjectError, match=r"bumps\[0\] names asset 'logo.png'"):
        check_design(design, {})
    check_design(design, {"logo.png": png()})


# ------------------------------------------------------------------------------ migration
def format_1_doc() -> dict:
    design = design_to_dict(bottle())
    design["bumps"] = [{"name": "old frost", "kind": "frosted"}, {"name": "odd", "kind": "satin"}]
    design["cap"] = {"height": 18.0}
    return {"format_version": 1, "generator": "glassbench 0.1.0", "design": design}


def test_migration_1_to_2_fills_in_tiles_and_cap_and_leaves_its_input_alone():
    doc = format_1_doc()
    before = copy.deepcopy(doc)
    new = migrate_1_to_2(doc)
    assert doc == before
    assert MIGRATIONS[1](copy.deepcopy(doc)) == new and new["format_version"] == 2
    frost, odd = new["design"]["bumps"]
    assert frost["name"] == "old frost" and frost["kind"] == "frosted"
    assert (frost["z0"], frost["z1"]) == (0.0, 200.0)  # the whole bottle
    assert odd["kind"] == "frosted"  # an unknown placeholder kind
    assert new["design"]["cap"]["kind"] == "screw" and new["design"]["cap"]["height"] == 18.0
    again = migrate_1_to_2(dict(new, format_version=1))  # the new layout passes through
    assert again["design"]["bumps"] == new["design"]["bumps"]


def test_a_format_1_project_opens():
    doc = format_1_doc()
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("project.json", json.dumps(doc))
    design, _ = load_project_bytes(buf.getvalue())
    assert [t.kind for t in design.bumps] == ["frosted", "frosted"]
    assert design.cap == Cap(height=18.0)
    assert design.shape == bottle().shape
