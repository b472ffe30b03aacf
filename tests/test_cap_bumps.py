"""Bump tiles on the cap: placed on its straight skirt by height above the skirt's lower edge
(as a skirt print is), drawn on the cap only, following the cap when the finish moves, refused
where they cannot be drawn, saved."""
from __future__ import annotations

import copy
import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

from engine.appearance.bands import cap_band
from engine.tracer.tables.bump_rows import bump_tables
from engine.appearance.cap_surfaces import cap_surface
from engine.appearance.closure_shapes import default_cap
from engine.appearance.closures import closure_geometry
from engine.operations.tiles import new_tile
from engine.cli import main as cli
from engine.errors import DesignError
from engine.files.migrate_fields import migrate_2_to_3
from engine.files.project import load_project, save_project
from engine.files.serialize import MIGRATIONS, design_from_document, document_from_design
from engine.model.check import check_values
from engine.tracer.tables.render_objects import render_geometry_for
from tests.test_finish_render import _image

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "resources"))
from make_samples import bordeaux_section, round_shape  # noqa: E402


@pytest.fixture(scope="module")
def capped():
    design, assets = load_project(ROOT / "resources" / "bordeaux.glassbench")
    return dataclasses.replace(design, cap=default_cap("screw")), assets


def test_a_band_on_the_cap_lies_on_its_skirt_by_height_above_the_skirts_lower_edge(capped):
    design, _ = capped
    closure = closure_geometry(design)
    skirt = cap_surface(design, "cap-skirt")
    assert skirt.radius == pytest.approx(closure.r_max, rel=1e-9)  # the outside of the shell
    part, a, b, r = cap_band(design, 1.0, 3.0)
    assert (part, r) == (closure.parts[skirt.part].name, skirt.radius)
    assert (a, b) == pytest.approx((skirt.v0 + 1.0, skirt.v0 + 3.0))
    assert cap_band(design, -5.0, 3.0)[1] == pytest.approx(skirt.v0)  # clipped to the skirt
    assert cap_band(design, skirt.height_mm + 1.0, skirt.height_mm + 5.0) is None
    crowned = dataclasses.replace(design, cap=default_cap("crown"))
    assert cap_band(crowned, 1.0, 3.0) is None  # a crown's flared skirt is not straight


def test_a_tile_on_the_cap_changes_the_cap_only(capped):
    design, assets = capped
    closure = closure_geometry(design)
    skirt = cap_surface(design, "cap-skirt")
    tile = new_tile(design, "flutes", 1.0, skirt.height_mm - 1.0, on="cap", depth=0.5)
    fluted = dataclasses.replace(design, bumps=(tile,))
    tables = bump_tables(fluted, assets)
    assert tables.surfaces == ("closure:shell",) + tables.surfaces[1:] and len(tables.surfaces) >= 2
    w, h = 40, 40
    # a view of the neck and cap, close up, from the side
    cam = dataclasses.replace(design.camera, eye=(0.0, -120.0, closure.z_min + 5.0),
                              target=(0.0, 0.0, closure.z_min + 5.0), fov_y_deg=20.0)
    plain, _, _ = _image(dataclasses.replace(design, camera=cam), assets, w, h)
    img, res, _ = _image(dataclasses.replace(fluted, camera=cam), assets, w, h)
    n_bottle = render_geometry_for(design).obj_i.shape[0]
    on_cap = (res.objects.reshape(h, w) >> n_bottle) & 1 == 1
    changed = np.abs(img - plain).sum(-1) > 1e-9
    assert changed.sum() > 20, "the flutes bend the cap's shading normal"
    assert not np.any(changed & ~on_cap), "trees that never met the cap are untouched"
    assert res.counters[1] == 0 and res.counters[2] == 0  # no leaks, no medium mismatches


def test_a_tile_on_the_cap_follows_the_cap_when_the_neck_moves(capped):
    design, assets = capped
    tile = new_tile(design, "knurl", 2.0, 6.0, on="cap")
    rows = []
    for top in (280.0, 300.0):
        d = dataclasses.replace(design, shape=round_shape(bordeaux_section(190.0, top=top)), bumps=(tile,))
        _, v0, v1, _ = cap_band(d, tile.z0, tile.z1)
        rows.append((closure_geometry(d).z_min, v0, v1))
    assert rows[1][0] - rows[0][0] == pytest.approx(20.0, abs=1e-6)
    assert rows[1][1:] == pytest.approx(rows[0][1:])  # the same place on the cap


def test_without_a_cap_a_cap_tile_is_kept_but_not_drawn(capped):
    design, assets = capped
    tile = new_tile(design, "knurl", 2.0, 6.0, on="cap")
    bare = dataclasses.replace(design, cap=None, bumps=(tile,))
    check_values(bare)
    assert len(bump_tables(bare, assets).kinds) == 0


def test_bad_surfaces_and_threads_on_the_cap_are_refused(capped):
    design, _ = capped
    with pytest.raises(DesignError, match=r"bumps\[0\]\.on 'lid' is not one of bottle, cap"):
        check_values(dataclasses.replace(design, bumps=(dataclasses.replace(new_tile(design, "knurl", 2, 6), on="lid"),)))
    with pytest.raises(DesignError, match="thread on the cap"):
        check_values(dataclasses.replace(design, bumps=(dataclasses.replace(new_tile(design, "thread", 270, 290), on="cap"),)))


def test_format_2_tiles_migrate_to_the_bottle_and_cap_tiles_round_trip(capped, tmp_path):
    design, assets = capped
    tiles = (new_tile(design, "knurl", 2.0, 12.0), new_tile(design, "stipple", 2.0, 6.0, on="cap"))
    d = dataclasses.replace(design, bumps=tiles)
    path = tmp_path / "capped.glassbench"
    save_project(path, d, assets)
    assert load_project(path)[0] == d
    doc = document_from_design(d)
    old = copy.deepcopy(doc)
    old["format_version"] = 2
    for t in old["design"]["bumps"]:
        del t["on"]
    before = copy.deepcopy(old)
    new = migrate_2_to_3(old)
    assert old == before and MIGRATIONS[2] is migrate_2_to_3
    assert [t.on for t in design_from_document(new).bumps] == ["bottle", "bottle"]


def test_the_command_line_puts_tiles_on_the_cap_and_refuses_what_cannot_be_drawn(capped, tmp_path, capsys):
    design, assets = capped
    path = tmp_path / "p.glassbench"
    save_project(path, dataclasses.replace(design, bumps=()), assets)
    assert cli(["bump", str(path), "add", "knurl", "--z0", "2", "--z1", "6", "--on", "cap"]) == 0
    assert "above the lower edge of the cap's skirt" in capsys.readouterr().out
    tile, = load_project(path)[0].bumps
    assert tile.on == "cap" and (tile.z0, tile.z1) == (2.0, 6.0)
    for args, why in ((["thread"], "belongs to the glass finish"),
                      (["knurl", "--z0", "80", "--z1", "90"], "skirt miss it")):
        argv = ["bump", str(path), "add", args[0], "--z0", "2", "--z1", "6"] + args[1:] + ["--on", "cap"]
        assert cli(argv) == 2
        assert why in capsys.readouterr().err
    assert cli(["cap", str(path), "set", "none"]) == 0
    assert cli(["bump", str(path), "list"]) == 0
    assert "on the cap (no cap: not drawn)" in capsys.readouterr().out
    assert cli(["bump", str(path), "add", "knurl", "--z0", "2", "--z1", "6", "--on", "cap"]) == 2
    assert "has no cap" in capsys.readouterr().err
    assert len(load_project(path)[0].bumps) == 1  # nothing lost to a refusal
