"""Mesh export (engine.files.mesh_export): every format reads back closed with the right face count."""
import json
import struct

import numpy as np
import pytest
import trimesh

from engine.files.mesh_export import FORMATS, export_mesh
from engine.geometry.tessellate import tessellate_body
from tests.test_offset import spec_shape


@pytest.mark.parametrize("suffix", FORMATS)
def test_export_reads_back_closed(tmp_path, suffix):
    shape = spec_shape(3)
    n_faces = len(tessellate_body(shape, 0.3).faces)
    out = export_mesh(shape, tmp_path / f"bottle{suffix}", 0.3)
    back = trimesh.load(out, force="mesh")
    assert len(back.faces) == n_faces
    back.merge_vertices(merge_norm=True, merge_tex=True)
    assert back.is_watertight and back.is_winding_consistent
    assert back.volume > 0
    size = np.ptp(back.vertices, axis=0)
    scale = 1e-3 if suffix in (".gltf", ".glb") else 1.0
    assert size[2] == pytest.approx(162.0 * scale, rel=1e-5)


def test_glb_layout_and_gltf_units(tmp_path):
    out = export_mesh(spec_shape(1), tmp_path / "b.glb", 0.5)
    data = out.read_bytes()
    magic, version, total = struct.unpack("<III", data[:12])
    assert magic == 0x46546C67 and version == 2 and total == len(data)
    js_len, js_type = struct.unpack("<II", data[12:20])
    doc = json.loads(data[20:20 + js_len])
    assert doc["accessors"][0]["max"][2] == pytest.approx(0.215, rel=1e-6)  # metres


def test_unknown_suffix_and_no_partial_file(tmp_path):
    with pytest.raises(ValueError, match="unknown mesh format"):
        export_mesh(spec_shape(1), tmp_path / "b.step")
    with pytest.raises(ValueError):
        export_mesh(spec_shape(1), tmp_path / "b.stl", -1.0)
    assert list(tmp_path.iterdir()) == []
