"""Project files: exact round trip, atomic save with backup, migration, hostile files."""
from __future__ import annotations

import dataclasses
import io
import json
import os
import stat
import warnings
import zipfile

import pytest

from engine.model.design import (BumpTile, Cap, Camera, Design, Environment, Glass, Label, LabelSide,
                                 Light, Liquid, RenderSettings)
from engine.errors import ProjectError
from engine.files.project import Limits, load_project, load_project_bytes, save_project
from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.files.serialize import CURRENT_FORMAT, design_from_dict, design_to_dict
from engine.geometry.shape import BottleShape


def make_design() -> Design:
    # Body, convex shoulder arc, concave arc into a vertical neck; awkward floats on purpose
    # (the round trip must be exact to the last bit).
    import math
    r, R = 30.0, 7.1
    c = (r - R, 100.0)
    a = math.radians(50.0)
    p = (c[0] + R * math.cos(a), c[1] + R * math.sin(a))
    R2 = (p[0] - 12.0) / (1.0 - math.cos(a))
    c2 = (p[0] + R2 * math.cos(a), p[1] + R2 * math.sin(a))
    sec = Section((Line((0, 0), (r, 0)), Line((r, 0), (r, 100)), Arc(c, R, (r, 100.0), p, "ccw"),
                   Arc(c2, R2, p, (12.0, c2[1]), "cw"), Line((12.0, c2[1]), (12.0, 180.0))))
    return Design(BottleShape("round", (("profile", sec),), wall_thickness=0.1 + 0.2,
                              base_thickness=6.000000000000001),
                  glass=Glass(1.52, (1e-300, 0.1, 0.3), 2.5),
                  liquid=Liquid(1.333, (0.045, 0.02, 0.006), "volume", 300.0),
                  camera=Camera((1.0 / 3.0, -500.0, 160.0), (0, 0, 150.0), (0, 0, 1), 27.5),
                  environment=Environment("file", "studio.exr", 1.25, 10.0),
                  lights=(Light(), Light((1, 0, 1), (0.5, 0.5, 0.4), 2.0)),
                  render=RenderSettings(360, 480, 8, 20, 1e-4),
                  labels=(Label("front", LabelSide("front.png"), z_mm=50.0, height_mm=40.0,
                                width_mm=90.0 + 1.0 / 3.0),), bumps=(BumpTile(),),
                  cap=Cap(height=18.0),
                  name="Test ✓", notes="line1\nline2")


ASSETS = {"studio.exr": b"\x00\x01fake exr" * 10, "front.png": b"\x89PNG fake"}


def raw_zip(members, compression=zipfile.ZIP_DEFLATED) -> bytes:
    buf = io.BytesIO()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # duplicate names warn
        with zipfile.ZipFile(buf, "w", compression=compression) as zf:
            for name, data in members:
                if isinstance(name, zipfile.ZipInfo):
                    zf.writestr(name, data)
                else:
                    zf.writestr(name, data)
    return buf.getvalue()


def good_doc() -> dict:
    return {"format_version": CURRENT_FORMAT, "generator": "test",
            "design": design_to_dict(make_design())}


def archive(doc, assets=ASSETS) -> bytes:
    return raw_zip([("project.json", json.dumps(doc))] +
                   [("assets/" + k, v) for k, v in assets.items()])


def test_round_trip_is_exact(tmp_path):
    path = tmp_path / "p.glassbench"
    design = make_design()
    save_project(path, design, ASSETS)
    loaded, assets = load_project(path)
    assert loaded == design
    assert loaded.shape.wall_thickness == 0.1 + 0.2
    assert loaded.glass.absorption[0] == 1e-300
    assert assets == ASSETS


def test_dict_round_trip_preserves_every_field():
    design = make_design()
    again = design_from_dict(json.loads(json.dumps(design_to_dict(design))))
    for f in dataclasses.fields(Design):
        assert getattr(again, f.name) == getattr(design, f.name), f.name


def test_save_keeps_backup_and_leaves_no_temp(tmp_path):
    path = tmp_path / "p.glassbench"
    first = make_design()
    save_project(path, first, ASSETS)
    second = dataclasses.replace(first, name="second")
    save_project(path, second, ASSETS)
    assert load_project(path)[0].name == "second"
    assert load_project(str(path) + ".bak")[0].name == first.name
    assert sorted(os.listdir(tmp_path)) == ["p.glassbench", "p.glassbench.bak"]


def test_failed_save_leaves_previous_file(tmp_path):
    path = tmp_path / "p.glassbench"
    save_project(path, make_design(), ASSETS)
    before = path.read_bytes()
    bad = dataclasses.replace(make_design(), camera=Camera(fov_y_deg=float("nan")))
    with pytest.raises(ProjectError, match="fov_y_deg"):
        save_project(path, bad, ASSETS)
    with pytest.raises(ProjectError, match="plain file name"):
        save_project(path, make_design(), {"../evil": b""})
    assert path.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["p.glassbench"]


def test_format_0_migrates():
    d = make_design()
    old = {"format_version": 0, "name": "proto",
           "shape": {"cross_section": "round",
                     "sections": {"profile": d.shape.primary.to_dicts()},
                     "wall": 2.5, "base": 5.0, "rotation_deg": 0.0},
           "glass": {"ior": 1.5, "absorption": [0, 0, 0.01]},
           "liquid": {"ior": 1.33, "absorption": [0.1, 0.1, 0.1], "fill_height": 80.0},
           "camera": {"eye": [0, -400, 100], "target": [0, 0, 60], "up": [0, 0, 1], "fov_y_deg": 30},
           "render": {"width": 200, "height": 300, "spp": 4}}
    design, assets = load_project_bytes(raw_zip([("project.json", json.dumps(old))]))
    assert design.name == "proto" and assets == {}
    assert design.shape.wall_thickness == 2.5 and design.shape.base_thickness == 5.0
    assert design.shape.primary == d.shape.primary  # default smoothness flags restored
    assert design.liquid == Liquid(1.33, (0.1, 0.1, 0.1), "height", 80.0)
    assert design.render == RenderSettings(200, 300, 4)
    assert design.environment == Environment() and design.glass.density_g_cm3 == 2.52


def test_newer_format_is_named():
    doc = good_doc()
    doc["format_version"] = CURRENT_FORMAT + 1
    with pytest.raises(ProjectError, match="newer glassbench"):
        load_project_bytes(archive(doc))


def mutate(fn):
    doc = good_doc()
    fn(doc)
    return archive(doc)


@pytest.mark.parametrize("change, message", [
    (lambda d: d.pop("format_version"), "format_version"),
    (lambda d: d.__setitem__("format_version", "1"), "format_version"),
    (lambda d: d["design"].pop("glass"), "lacks 'glass'"),
    (lambda d: d["design"]["glass"].__setitem__("ior", "1.5"), r"design\.glass\.ior must be a number"),
    (lambda d: d["design"]["glass"].__setitem__("ior", True), "must be a number"),
    (lambda d: d["design"]["render"].__setitem__("width", 3.5), "whole number"),
    (lambda d: d["design"]["render"].__setitem__("width", 10 ** 9), "outside"),
    (lambda d: d["design"]["camera"].__setitem__("eye", [0, 1]), "3 items"),
    (lambda d: d["design"].__setitem__("extra", 1), "unknown field"),
    (lambda d: d["design"]["shape"].__setitem__("cross_section", "hexagon"), "unknown cross-section"),
    (lambda d: d["design"]["shape"]["sections"]["profile"]["segments"][1].__setitem__("type", "spline"),
     "unknown segment type"),
    (lambda d: d["design"]["shape"]["sections"]["profile"]["smooth"].append(True), "joints"),
    (lambda d: d["design"]["lights"].extend([d["design"]["lights"][0]] * 5000), "limit"),
    (lambda d: d["design"].__setitem__("notes", "x" * 200_000), "characters"),
    (lambda d: d["design"]["environment"].__setitem__("asset", "missing.exr"), "lacks"),
    (lambda d: d["design"]["liquid"].__setitem__("fill_mode", "weight"), "fill_mode"),
    (lambda d: d.__setitem__("design", []), "must be an object"),
])
def test_bad_documents_name_the_problem(change, message):
    with pytest.raises(ProjectError, match=message):
        load_project_bytes(mutate(change))


@pytest.mark.parametrize("text, message", [
    ('{"format_version": 1, "design": NaN}', "NaN"),
    ('{"format_version": 1, "design": -Infinity}', "Infinity"),
    ('[' * 10000 + ']' * 10000, "nested deeper"),
    ('{"format_version": 1, ', "not valid JSON"),
    (b'\xff\xfe{}', "not UTF-8"),
])
def test_bad_json_text(text, message):
    with pytest.raises(ProjectError, match=message):
        load_project_bytes(raw_zip([("project.json", text)]))


def test_huge_number_is_not_finite():
    doc = json.dumps(good_doc()).replace('"ior": 1.52', '"ior": 1e999')
    with pytest.raises(ProjectError, match=r"glass\.ior is inf"):
        load_project_bytes(raw_zip([("project.json", doc)]))


def symlink_info(name):
    info = zipfile.ZipInfo(name)
    info.external_attr = (stat.S_IFLNK | 0o777) << 16
    return info


@pytest.mark.parametrize("name, message", [
    ("../evil.json", "escapes"),
    ("assets/../../evil", "escapes"),
    ("/etc/passwd", "absolute"),
    ("C:/evil", "absolute"),
    ("assets\\evil.exr", "backslash"),
    ("thumbnail.png", "unexpected member"),
    ("assets/.hidden", "unexpected member"),
    (symlink_info("assets/link.exr"), "symbolic link"),
])
def test_hostile_member_names(name, message):
    blob = raw_zip([("project.json", json.dumps(good_doc())), (name, b"x")]
                   + [("assets/" + k, v) for k, v in ASSETS.items()])
    with pytest.raises(ProjectError, match=message):
        load_project_bytes(blob)


def test_duplicate_member():
    blob = raw_zip([("project.json", json.dumps(good_doc())), ("project.json", "{}")])
    with pytest.raises(ProjectError, match="twice"):
        load_project_bytes(blob)


def test_not_a_zip_and_missing_json(tmp_path):
    p = tmp_path / "x.glassbench"
    p.write_bytes(b"PK\x03\x04 definitely not a zip" * 10)
    with pytest.raises(ProjectError, match="x.glassbench: not a glassbench project"):
        load_project(p)
    with pytest.raises(ProjectError, match="no project.json"):
        load_project_bytes(raw_zip([("assets/a.exr", b"1")]))
    with pytest.raises(ProjectError, match="cannot open"):
        load_project(tmp_path / "absent.glassbench")


def test_compressed_bomb_is_stopped():
    bomb = raw_zip([("project.json", b" " * (3 << 20))])
    assert len(bomb) < 20_000
    with pytest.raises(ProjectError, match="declares"):
        load_project_bytes(bomb, Limits(json_bytes=1 << 20))


def test_lying_size_header_is_caught():
    # Shrink the declared size in both headers: the stream cap / CRC check must notice.
    payload = json.dumps(good_doc()).encode()
    blob = bytearray(raw_zip([("project.json", payload)], compression=zipfile.ZIP_STORED))
    size = len(payload).to_bytes(4, "little")
    assert blob.count(size) >= 2
    blob = bytes(blob).replace(size, (100).to_bytes(4, "little"))
    with pytest.raises(ProjectError):
        load_project_bytes(blob)


def test_limits_on_counts_and_totals():
    many = raw_zip([("project.json", json.dumps(good_doc()))] +
                   [(f"assets/a{i}.bin", b"1") for i in range(20)])
    with pytest.raises(ProjectError, match="members"):
        load_project_bytes(many, Limits(members=10))
    big = archive(good_doc(), {"studio.exr": b"\0" * 5000, "front.png": b"\0" * 5000})
    with pytest.raises(ProjectError, match="in all"):
        load_project_bytes(big, Limits(total_bytes=8000))
    with pytest.raises(ProjectError, match="declares"):
        load_project_bytes(big, Limits(asset_bytes=1000))


def test_invalid_geometry_is_a_project_error_with_the_validation_message():
    # The body goes down again (an overhang): validate_shape refuses it, naming the segment.
    doc = good_doc()
    segs = doc["design"]["shape"]["sections"]["profile"]["segments"]
    segs[1]["p1"] = [30.0, -5.0]
    segs[2]["p0"] = [30.0, -5.0]
    with pytest.raises(ProjectError, match=r"invalid bottle shape: .*segment"):
        load_project_bytes(archive(doc))


def test_wall_too_thick_is_a_project_error():
    doc = good_doc()
    doc["design"]["shape"]["wall_thickness"] = 40.0
    doc["design"]["shape"]["base_thickness"] = 40.0
    with pytest.raises(ProjectError, match="invalid bottle shape"):
        load_project_bytes(archive(doc))


def test_save_refuses_what_load_would_refuse(tmp_path):
    path = tmp_path / "p.glassbench"
    bad_shape = dataclasses.replace(make_design().shape, wall_thickness=40.0, base_thickness=40.0)
    with pytest.raises(ProjectError, match="invalid bottle shape"):
        save_project(path, dataclasses.replace(make_design(), shape=bad_shape), ASSETS)
    with pytest.raises(ProjectError, match="lacks"):
        save_project(path, make_design(), {"front.png": b"x"})  # environment map missing
    with pytest.raises(ProjectError, match="cannot write"):
        save_project(tmp_path / "no" / "such" / "dir.glassbench", make_design(), ASSETS)
    assert not path.exists()


def test_awkward_text_and_asset_names_round_trip(tmp_path):
    design = dataclasses.replace(make_design(), notes="[" * 500 + '{"q": "\\"}' + "\u00e9\U0001F37E",
                                 environment=Environment("file", "my studio (2).exr", 1.0, 0.0),
                                 labels=(Label("front", LabelSide("café label.png"), z_mm=50.0),))
    assets = {"my studio (2).exr": b"env", "café label.png": b"png"}
    save_project(tmp_path / "p.glassbench", design, assets)
    assert load_project(tmp_path / "p.glassbench") == (design, assets)


def test_unencodable_text_is_refused_on_save(tmp_path):
    design = dataclasses.replace(make_design(), notes="lone \ud800 surrogate")
    with pytest.raises(ProjectError, match="design.notes holds a character that cannot be stored"):
        save_project(tmp_path / "p.glassbench", design, ASSETS)
    assert not (tmp_path / "p.glassbench").exists()


def test_member_count_is_checked_before_parsing_the_directory():
    blob = bytearray(archive(good_doc()))
    at = blob.rfind(b"PK\x05\x06")
    blob[at + 8:at + 12] = (60000).to_bytes(2, "little") * 2  # entries on disk / in total
    with pytest.raises(ProjectError, match="60000 members"):
        load_project_bytes(bytes(blob))
    blob[at + 8:at + 12] = (0xFFFF).to_bytes(2, "little") * 2
    with pytest.raises(ProjectError, match="ZIP64"):
        load_project_bytes(bytes(blob))
