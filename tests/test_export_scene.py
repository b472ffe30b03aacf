"""glassbench export-scene: the Khronos validator finds no error and no warning on every bundled
sample; glass and liquid are single-sided transmitting volumes whose attenuation is the
design's absorption exactly; labels, closure and camera are there; the tolerance is honoured."""
from __future__ import annotations

import json
import math
import struct

import numpy as np
import pytest

from engine import cli
from engine.export.gltf_scene import attenuation, export_scene
from engine.export.web import validate_glb
from tests.export_helpers import SAMPLES, cap_prints, load, seam_label


def read_glb(path):
    """``(doc, blob)`` of a GLB file, parsed by hand (header, JSON chunk, BIN chunk)."""
    data = path.read_bytes()
    magic, version, total = struct.unpack("<III", data[:12])
    assert (magic, version, total) == (0x46546C67, 2, len(data))
    n_json = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + n_json])
    n_bin = struct.unpack("<I", data[20 + n_json:24 + n_json])[0]
    return doc, data[28 + n_json:28 + n_json + n_bin]


def accessor(doc, blob, index) -> np.ndarray:
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[acc["type"]]
    dtype = "<f4" if acc["componentType"] == 5126 else "<u4"
    a = np.frombuffer(blob, dtype, acc["count"] * width, view["byteOffset"])
    return a.reshape(acc["count"], width) if width > 1 else a


def mesh_of(doc, blob, name):
    node = next(n for n in doc["nodes"] if n.get("name") == name)
    prim = doc["meshes"][node["mesh"]]["primitives"][0]
    return (accessor(doc, blob, prim["attributes"]["POSITION"]),
            accessor(doc, blob, prim["indices"]).reshape(-1, 3), doc["materials"][prim["material"]])


@pytest.mark.parametrize("project", SAMPLES, ids=lambda p: p.stem)
def test_every_sample_validates_without_errors_or_warnings(project, tmp_path, capsys):
    out = tmp_path / "scene.glb"
    assert cli.main(["export-scene", str(project), str(out), "--tol", "0.05"]) == 0
    assert "wrote" in capsys.readouterr().out
    report = validate_glb(out)
    assert (report["errors"], report["warnings"]) == (0, 0), report["messages"]
    assert report["info"]["totalTriangleCount"] > 1000
    design, _ = load(project.name)
    doc, _ = read_glb(out)
    names = [n.get("name") for n in doc["nodes"]]
    assert "glass" in names and "design camera" in names
    assert ("liquid" in names) == (design.liquid is not None)
    assert sum(n.startswith("label ") for n in names) == 2 * len(design.labels)
    assert any(n.startswith("closure") for n in names) == (design.cap is not None)
    assert set(doc["extensionsUsed"]) == {"KHR_materials_transmission", "KHR_materials_volume",
                                          "KHR_materials_ior"}


def test_volumes_attenuate_exactly_as_the_design_absorbs(tmp_path):
    design, assets = load("labelled.glassbench")
    export_scene(design, assets, tmp_path / "s.glb")
    doc, blob = read_glb(tmp_path / "s.glb")
    for name, medium in (("glass", design.glass), ("liquid", design.liquid)):
        _, _, mat = mesh_of(doc, blob, name)
        assert mat["doubleSided"] is False
        ext = mat["extensions"]
        assert ext["KHR_materials_transmission"]["transmissionFactor"] == 1.0
        assert ext["KHR_materials_ior"]["ior"] == medium.ior
        vol = ext["KHR_materials_volume"]
        assert vol["thicknessFactor"] > 0
        if max(medium.absorption) == 0:
            assert "attenuationColor" not in vol
            continue
        for x_mm in (0.5, 3.0, 40.0):  # glTF: colour ** (x / distance); the design: exp(-a x)
            got = [c ** (x_mm / 1000.0 / vol["attenuationDistance"]) for c in vol["attenuationColor"]]
            want = [math.exp(-a * x_mm) for a in medium.absorption]
            assert got == pytest.approx(want, rel=1e-12, abs=1e-300)
    assert attenuation((0.0, 0.0, 0.0)) == {}
    strong = attenuation((5.0, 0.1, 0.0))
    assert min(strong["attenuationColor"]) >= math.exp(-20.0) * (1 - 1e-12)


def test_labels_are_textured_sheets_front_and_back(tmp_path):
    design, assets = load("labelled.glassbench")
    export_scene(design, assets, tmp_path / "s.glb")
    doc, blob = read_glb(tmp_path / "s.glb")
    front_pos, _, front = mesh_of(doc, blob, "label 0 front label front")
    back_pos, _, back = mesh_of(doc, blob, "label 0 front label back")
    assert front["alphaMode"] == back["alphaMode"] == "OPAQUE"  # the sample's paper is opaque
    assert "metallicRoughnessTexture" in front["pbrMetallicRoughness"]  # the gold foil
    assert "metallicRoughnessTexture" not in back["pbrMetallicRoughness"]
    # glTF is +Y up: radius about the vertical axis; the front stands further out than the back
    r_front = np.hypot(front_pos[:, 0], front_pos[:, 2]).mean()
    r_back = np.hypot(back_pos[:, 0], back_pos[:, 2]).mean()
    assert 0.0375 < r_back < r_front < 0.0375 + 0.001
    assert 0.095 - 0.035 - 1e-4 < front_pos[:, 1].min() and front_pos[:, 1].max() < 0.095 + 0.035 + 1e-4


def test_clear_vinyl_is_transparent_and_foil_is_metal():
    """The front texture's alpha is 0 where a clear-vinyl region lets the glass show; a foil
    region is metal (blue channel) with the foil's reflectance as its colour."""
    import dataclasses

    from engine.export.gltf_labels import foil_reflectance, front_textures
    design, assets = load("labelled.glassbench")
    label = design.labels[0]
    base, mr, opaque = front_textures(label, assets)
    gold = mr[..., 2] == 255
    assert opaque and 0.05 < gold.mean() < 0.5
    srgb = np.round(255 * np.where(foil_reflectance("gold_foil") <= 0.0031308,
                                   12.92 * foil_reflectance("gold_foil"),
                                   1.055 * foil_reflectance("gold_foil") ** (1 / 2.4) - 0.055))
    assert (base[gold][:, :3] == srgb).all()
    vinyl = dataclasses.replace(label, regions=(dataclasses.replace(label.regions[0], finish="clear_vinyl"),))
    base, mr, opaque = front_textures(vinyl, assets)
    assert not opaque and mr is None
    assert (base[gold][:, 3] == 0).all() and (base[~gold][:, 3] == 255).all()


def test_a_label_across_the_seam_stays_one_sheet(tmp_path):
    design, assets = seam_label()
    export_scene(design, assets, tmp_path / "s.glb")
    assert validate_glb(tmp_path / "s.glb")["errors"] == 0
    doc, blob = read_glb(tmp_path / "s.glb")
    pos, faces, _ = mesh_of(doc, blob, "label 0 front label front")
    edges = np.linalg.norm(pos[faces] - pos[np.roll(faces, 1, axis=1)], axis=-1)
    assert edges.max() < 0.01  # no triangle spans the bottle (metres)
    assert (pos[:, 0] < 0).all()  # centred on azimuth 180 degrees: world -x, both sides of it
    assert (pos[:, 2] > 0.01).any() and (pos[:, 2] < -0.01).any()


def test_prints_on_the_closure_lie_on_its_top_and_skirt(tmp_path):
    from engine.appearance.cap_surfaces import cap_surface
    from engine.export.gltf_labels import lift_mm
    design, assets = cap_prints()
    export_scene(design, assets, tmp_path / "s.glb", 0.05)
    assert validate_glb(tmp_path / "s.glb")["errors"] == 0
    doc, blob = read_glb(tmp_path / "s.glb")
    top, skirt = cap_surface(design, "cap-top"), cap_surface(design, "cap-skirt")
    pos, _, _ = mesh_of(doc, blob, "label 0 top print front")
    assert pos[:, 1] * 1000 == pytest.approx(top.z0 + lift_mm(0.05), abs=1e-4)  # glTF y is up
    assert np.ptp(pos[:, 0]) * 1000 == pytest.approx(10.0, abs=1e-3)  # 10 mm wide, read from -y
    pos, _, _ = mesh_of(doc, blob, "label 1 skirt print front")
    r = np.hypot(pos[:, 0], pos[:, 2]) * 1000
    assert r == pytest.approx(skirt.radius + lift_mm(0.05), abs=0.05)
    z = pos[:, 1] * 1000
    assert z.min() == pytest.approx(skirt.z0 + 0.5 * skirt.height_mm - 4.0, abs=1e-3)
    closure = next(n for n in doc["nodes"] if n.get("name") == "closure shell")
    mat = doc["materials"][doc["meshes"][closure["mesh"]]["primitives"][0]["material"]]
    assert mat["pbrMetallicRoughness"]["metallicFactor"] == 0.0  # the sample's cap is plastic
    assert mat["pbrMetallicRoughness"]["baseColorFactor"][:3] == pytest.approx(list(design.cap.color))


def test_a_metal_closure_is_lacquered_aluminium(tmp_path):
    from engine.appearance.closure_parts import ALUMINIUM_K, ALUMINIUM_N
    design, assets = load("knurled_jar.glassbench")
    export_scene(design, assets, tmp_path / "s.glb", 0.1)
    doc, blob = read_glb(tmp_path / "s.glb")
    _, _, mat = mesh_of(doc, blob, "closure shell")
    pbr = mat["pbrMetallicRoughness"]
    n, k = np.array(ALUMINIUM_N), np.array(ALUMINIUM_K)
    f0 = ((n - 1) ** 2 + k ** 2) / ((n + 1) ** 2 + k ** 2) * np.array(design.cap.color)
    assert pbr["metallicFactor"] == 1.0 and pbr["baseColorFactor"][:3] == pytest.approx(f0)


def test_the_tolerance_is_the_meshes_chordal_tolerance(tmp_path):
    design, assets = load("bordeaux.glassbench")
    sizes = {}
    for tol in (0.2, 0.02):
        stats = export_scene(design, assets, tmp_path / f"{tol}.glb", tol)
        sizes[tol] = stats.vertices
        doc, blob = read_glb(tmp_path / f"{tol}.glb")
        pos, faces, _ = mesh_of(doc, blob, "glass")
        # every triangle's centroid lies within tol of the exact outer or inner wall or a base
        c = pos[faces].mean(axis=1) * 1000.0  # mm, glTF frame
        r, z = np.hypot(c[:, 0], c[:, 2]), c[:, 1]
        on_body = (z > 30) & (z < 180)  # the straight body: r is 37.5 outside, 34.5 inside
        gap = np.minimum(np.abs(r[on_body] - 37.5), np.abs(r[on_body] - 34.5))
        assert gap.max() <= tol
    assert sizes[0.02] > 3 * sizes[0.2]


def test_the_camera_is_the_designs(tmp_path):
    design, assets = load("bordeaux.glassbench")
    export_scene(design, assets, tmp_path / "s.glb")
    doc, _ = read_glb(tmp_path / "s.glb")
    node = next(n for n in doc["nodes"] if n.get("name") == "design camera")
    cam = doc["cameras"][node["camera"]]["perspective"]
    assert cam["yfov"] == pytest.approx(math.radians(design.camera.fov_y_deg))
    assert cam["aspectRatio"] == pytest.approx(design.render.width / design.render.height)
    ex, ey, ez = design.camera.eye
    assert node["translation"] == pytest.approx([ex / 1000, ez / 1000, -ey / 1000])
    x, y, z, w = node["rotation"]
    # the camera looks down its local -Z: rotate (0, 0, -1) by the quaternion
    v = np.array([0.0, 0.0, -1.0])
    q = np.array([x, y, z])
    look = v + 2 * np.cross(q, np.cross(q, v) + w * v)
    tx, ty, tz = design.camera.target
    want = np.array([tx - ex, tz - ez, -(ty - ey)])
    assert look == pytest.approx(want / np.linalg.norm(want), abs=1e-9)


def test_bad_names_and_tolerances_are_refused(tmp_path, capsys):
    project = str(SAMPLES[0])
    assert cli.main(["export-scene", project, str(tmp_path / "s.gltf")]) == 2
    assert ".glb" in capsys.readouterr().err
    assert cli.main(["export-scene", project, str(tmp_path / "s.glb"), "--tol", "0"]) == 2
    assert "--tol" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
