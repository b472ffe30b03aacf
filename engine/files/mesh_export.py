"""Mesh export of the glass shell: binary STL, OBJ, binary PLY, glTF 2.0 (.gltf / .glb).

Design rule: one tessellation (:func:`engine.geometry.tessellate.tessellate_body`) feeds every format and
the format follows the file suffix. Positions are welded (crease copies merged) so each file is a
closed, consistently oriented surface; formats that carry normals keep the exact per-part normals
(OBJ by separate normal indices; PLY and glTF by one vertex per part, same positions). STL, OBJ
and PLY are in millimetres; glTF is in metres, as its specification requires. Files are written
to a temporary name and renamed (:func:`engine.io.atomic.replacing`), so a failed export never
leaves half a file.
"""
from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np

from ..geometry.tessellate import Mesh, tessellate_body
from ..io.atomic import replacing

FORMATS = (".stl", ".obj", ".ply", ".gltf", ".glb")


def _stl(mesh: Mesh) -> bytes:
    v = mesh.vertices[mesh.faces].astype(np.float32)
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    rec = np.zeros(len(v), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"], rec["v"] = n, v
    header = b"glassbench binary STL, millimetres".ljust(80, b" ")
    return header + struct.pack("<I", len(v)) + rec.tobytes()


def _obj(mesh: Mesh) -> bytes:
    pos, faces = mesh.welded()
    lines = ["# glassbench glass shell, millimetres"]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in pos]
    lines += [f"vn {x:.9g} {y:.9g} {z:.9g}" for x, y, z in mesh.normals]
    for (a, b, c), (na, nb, nc) in zip(faces + 1, mesh.faces + 1):
        lines.append(f"f {a}//{na} {b}//{nb} {c}//{nc}")
    return ("\n".join(lines) + "\n").encode("ascii")


def _ply(mesh: Mesh) -> bytes:
    v = np.zeros(len(mesh.vertices), dtype=[("p", "<f4", 3), ("n", "<f4", 3)])
    v["p"], v["n"] = mesh.vertices, mesh.normals
    f = np.zeros(len(mesh.faces), dtype=[("k", "u1"), ("i", "<i4", 3)])
    f["k"], f["i"] = 3, mesh.faces
    header = ("ply\nformat binary_little_endian 1.0\ncomment glassbench glass shell, millimetres\n"
              f"element vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n")
    return header.encode("ascii") + v.tobytes() + f.tobytes()


def _gltf_parts(mesh: Mesh):
    """The glTF JSON document (without buffer uri) and its binary buffer (metres)."""
    pos = (mesh.vertices * 1e-3).astype("<f4")
    nrm = mesh.normals.astype("<f4")
    idx = mesh.faces.astype("<u4").ravel()
    blob = pos.tobytes() + nrm.tobytes() + idx.tobytes()
    n_pos = pos.nbytes
    doc = {
        "asset": {"version": "2.0", "generator": "glassbench"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "glass"}],
        "meshes": [{"name": "glass", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1},
                                                     "indices": 2, "mode": 4}]}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": n_pos, "target": 34962},
            {"buffer": 0, "byteOffset": n_pos, "byteLength": nrm.nbytes, "target": 34962},
            {"buffer": 0, "byteOffset": 2 * n_pos, "byteLength": idx.nbytes, "target": 34963}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
             "min": pos.min(axis=0).tolist(), "max": pos.max(axis=0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": len(nrm), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"}],
    }
    return doc, blob


def _gltf(mesh: Mesh) -> bytes:
    doc, blob = _gltf_parts(mesh)
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    return json.dumps(doc).encode("utf-8")


def glb_container(doc: dict, blob: bytes) -> bytes:
    """A GLB file (the glTF 2.0 binary container) of the JSON document ``doc`` and the bytes of
    its one buffer (``doc["buffers"][0]``, without ``uri``); both chunks padded to 4 bytes."""
    js = json.dumps(doc).encode("utf-8")
    js += b" " * (-len(js) % 4)
    blob = bytes(blob) + b"\0" * (-len(blob) % 4)
    total = 12 + 8 + len(js) + 8 + len(blob)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(js), 0x4E4F534A) + js
            + struct.pack("<II", len(blob), 0x004E4942) + blob)


def _glb(mesh: Mesh) -> bytes:
    return glb_container(*_gltf_parts(mesh))


_WRITERS = {".stl": _stl, ".obj": _obj, ".ply": _ply, ".gltf": _gltf, ".glb": _glb}


def mesh_bytes(mesh: Mesh, suffix: str) -> bytes:
    """The file contents of ``mesh`` in the format named by ``suffix`` (one of :data:`FORMATS`)."""
    writer = _WRITERS.get(suffix.lower())
    if writer is None:
        raise ValueError(f"unknown mesh format {suffix!r}; use one of {', '.join(FORMATS)}")
    return writer(mesh)


def export_mesh(shape, path, tol_mm: float = 0.05) -> Path:
    """Tessellate ``shape`` and write the glass shell to ``path`` in the format of its suffix.

    Parameters
    ----------
    shape : BottleShape
        The bottle (validated by the tessellator).
    path : str or Path
        Target file; the suffix picks the format (:data:`FORMATS`).
    tol_mm : float
        Chordal tolerance (mm) of the tessellation.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ValueError
        Unknown suffix or bad tolerance (nothing is written).
    SectionError, WallError
        Invalid shape.
    OSError
        The file cannot be written.
    """
    path = Path(path)
    if path.suffix.lower() not in _WRITERS:
        raise ValueError(f"unknown mesh format {path.suffix!r}; use one of {', '.join(FORMATS)}")
    data = mesh_bytes(tessellate_body(shape, tol_mm), path.suffix)
    with replacing(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return path
