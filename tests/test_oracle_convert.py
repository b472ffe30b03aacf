"""SPEC scenes -> glassbench projects: every shared scene converts and round-trips exactly."""
from __future__ import annotations

import json

import pytest

from benchmarks.oracle import main, spec_to_design
from engine.errors import ProjectError
from engine.files.project import load_project
from benchmarks.paths import ORACLE_SPECS

SPECS = ORACLE_SPECS
SPEC_FILES = sorted(SPECS.glob("public_*.json"))


def test_all_four_shared_scenes_are_present():
    assert [p.name for p in SPEC_FILES] == [f"public_{i}.json" for i in range(1, 5)]


@pytest.mark.parametrize("spec_path", SPEC_FILES, ids=lambda p: p.stem)
def test_convert_and_round_trip(spec_path, tmp_path):
    spec = json.loads(spec_path.read_text())
    design, assets = spec_to_design(spec_path)
    cam = spec["camera"]
    assert design.camera.eye == tuple(cam["eye"]) and design.camera.target == tuple(cam["look_at"])
    assert design.camera.fov_y_deg == cam["fov_y_deg"]
    assert (design.render.width, design.render.height) == (cam["width"], cam["height"])
    env_file = (spec_path.parent / spec["environment"]["file"]).resolve()
    assert assets[design.environment.asset] == env_file.read_bytes()
    assert design.environment.kind == "file" and design.environment.scale == spec["environment"]["scale"]
    bottle = spec["bottle"]
    assert design.shape.cross_section == bottle["cross_section"]["kind"]
    assert design.shape.wall_thickness == bottle["wall_thickness"]
    assert design.shape.rotation_deg == bottle.get("rotation_deg", 0.0)
    assert design.glass.ior == bottle["glass"]["ior"]
    assert design.glass.absorption == tuple(bottle["glass"]["sigma_a"])
    if bottle["cross_section"]["kind"] == "round":
        assert design.shape.primary.to_dicts() == bottle["profile"]
    else:
        assert design.shape.section("u").to_dicts() == bottle["cross_section"]["profile_u"]
        assert design.shape.section("v").to_dicts() == bottle["cross_section"]["profile_v"]
    if spec["liquid"] is None:
        assert design.liquid is None
    else:
        assert design.liquid.fill_value == spec["liquid"]["fill_height"]
        assert design.liquid.absorption == tuple(spec["liquid"]["sigma_a"])
        assert design.liquid.ior == spec["liquid"]["ior"]

    out = tmp_path / f"{spec_path.stem}.glassbench"
    assert main(["convert", str(spec_path), str(out)]) == 0
    loaded, loaded_assets = load_project(out)
    assert loaded == design and loaded_assets == assets


def test_air_ior_other_than_one_is_refused(tmp_path):
    spec = json.loads(SPEC_FILES[0].read_text())
    spec["air_ior"] = 1.0003
    spec["environment"]["file"] = str((SPECS / spec["environment"]["file"]).resolve())
    p = tmp_path / "s.json"
    p.write_text(json.dumps(spec))
    with pytest.raises(ProjectError, match="air_ior"):
        spec_to_design(p)
    assert main(["convert", str(p), str(tmp_path / "o.glassbench")]) == 2
    assert not (tmp_path / "o.glassbench").exists()


def test_unknown_cross_section_and_missing_field(tmp_path):
    spec = json.loads(SPEC_FILES[0].read_text())
    spec["environment"]["file"] = str((SPECS / spec["environment"]["file"]).resolve())
    spec["bottle"]["cross_section"] = {"kind": "hexagon"}
    p = tmp_path / "s.json"
    p.write_text(json.dumps(spec))
    with pytest.raises(ProjectError, match="hexagon"):
        spec_to_design(p)
    del spec["camera"]
    p.write_text(json.dumps(spec))
    with pytest.raises(ProjectError, match="camera"):
        spec_to_design(p)


def test_render_dispatches_to_the_tracer_oracle_renderer(monkeypatch):
    import sys
    import types
    seen = []
    fake = types.ModuleType("benchmarks.oracle_render")
    fake.main = lambda argv: seen.append(argv) or 0
    monkeypatch.setitem(sys.modules, "benchmarks.oracle_render", fake)
    import benchmarks
    monkeypatch.setattr(benchmarks, "oracle_render", fake, raising=False)
    argv = ["render", str(SPEC_FILES[0]), "-o", "out.exr", "--spp", "4"]
    assert main(argv) == 0
    assert seen == [argv[1:]]
