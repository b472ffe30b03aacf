"""A small glTF 2.0 builder: one binary buffer, typed accessors, PNG textures, named nodes.

Design rule: the scene is assembled in glTF's own frame and units (metres, +Y up, a camera
looking down its local -Z), so everything that enters here is converted once by
:func:`to_gltf` (millimetres, +Z up -> metres, +Y up: ``(x, y, z) -> (x, z, -y) / 1000``, a
rotation, so windings and normals keep their sense). Every array is appended to the one buffer
aligned to 4 bytes; vertex attributes and indices get their ``target``, positions their
``min``/``max``, and an extension is listed in ``extensionsUsed`` the first time a material
names it, so what the builder writes is what the Khronos validator asks for. The file is a GLB
(:func:`engine.files.mesh_export.glb_container`).
"""
from __future__ import annotations

import io
import math

import numpy as np

from ..files.mesh_export import glb_container

ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
FLOAT, UNSIGNED_INT = 5126, 5125
#: Millimetres (design) per metre (glTF).
MM_PER_M = 1000.0


def to_gltf(points) -> np.ndarray:
    """Design points or directions ``(..., 3)`` (mm, +Z up) in glTF's frame (m, +Y up); for
    directions, divide by nothing: call :func:`to_gltf_dir`."""
    p = np.asarray(points, float)
    return np.stack([p[..., 0], p[..., 2], -p[..., 1]], -1) / MM_PER_M


def to_gltf_dir(vectors) -> np.ndarray:
    """Design directions ``(..., 3)`` in glTF's frame (the same rotation, no scaling)."""
    v = np.asarray(vectors, float)
    return np.stack([v[..., 0], v[..., 2], -v[..., 1]], -1)


def look_at_rotation(eye, target, up) -> list[float]:
    """The unit quaternion ``[x, y, z, w]`` turning a glTF camera (looking down -Z, +Y up)
    at ``eye`` towards ``target`` with ``up`` (all in glTF's frame)."""
    f = np.asarray(target, float) - np.asarray(eye, float)
    f /= np.linalg.norm(f)
    r = np.cross(f, np.asarray(up, float))
    if np.linalg.norm(r) < 1e-12:  # looking along up: any right-angle will do
        r = np.cross(f, [1.0, 0.0, 0.0] if abs(f[0]) < 0.9 else [0.0, 0.0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.stack([r, u, -f], axis=1)  # columns: the camera's x, y, z axes
    return _quaternion(m)


def _quaternion(m) -> list[float]:
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i], q[j], q[k] = 0.25 * s, (m[j, i] + m[i, j]) / s, (m[k, i] + m[i, k]) / s
    q = np.asarray(q)
    return [float(v) for v in q / np.linalg.norm(q)]


class GltfBuilder:
    """Collects buffers, meshes, materials, textures and nodes; :meth:`glb` writes them."""

    def __init__(self, generator: str = "glassbench"):
        self.doc = {"asset": {"version": "2.0", "generator": generator}, "scene": 0,
                    "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
                    "accessors": [], "bufferViews": [], "buffers": [], "textures": [],
                    "images": [], "samplers": [], "cameras": []}
        self.blob = io.BytesIO()
        self._used: set[str] = set()

    def _view(self, data: bytes, target: int | None = None) -> int:
        pad = -self.blob.tell() % 4
        self.blob.write(b"\0" * pad)
        view = {"buffer": 0, "byteOffset": self.blob.tell(), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.blob.write(data)
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, array, kind: str, component: int, target: int, bounds: bool = False) -> int:
        dtype = "<f4" if component == FLOAT else "<u4"
        a = np.ascontiguousarray(array, dtype=dtype)
        acc = {"bufferView": self._view(a.tobytes(), target), "componentType": component,
               "count": int(a.shape[0]) if kind != "SCALAR" else int(a.size), "type": kind}
        if bounds:
            acc["min"], acc["max"] = a.min(axis=0).tolist(), a.max(axis=0).tolist()
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, name: str, positions, normals, faces, material: int, uv=None) -> int:
        """A one-primitive triangle mesh (positions and unit normals in glTF's frame, ``faces``
        ``(m, 3)`` counter-clockwise seen from the normals' side, ``uv`` ``(n, 2)``)."""
        normals = np.asarray(normals, float)
        normals = normals / np.linalg.norm(normals, axis=-1, keepdims=True)
        attrs = {"POSITION": self._accessor(positions, "VEC3", FLOAT, ARRAY_BUFFER, True),
                 "NORMAL": self._accessor(normals, "VEC3", FLOAT, ARRAY_BUFFER)}
        if uv is not None:
            attrs["TEXCOORD_0"] = self._accessor(uv, "VEC2", FLOAT, ARRAY_BUFFER)
        prim = {"attributes": attrs, "mode": 4, "material": material,
                "indices": self._accessor(np.asarray(faces).ravel(), "SCALAR", UNSIGNED_INT,
                                          ELEMENT_ARRAY_BUFFER)}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def material(self, spec: dict) -> int:
        """Add a material (glTF JSON); its extensions are declared as used."""
        self._used.update(spec.get("extensions", {}))
        self.doc["materials"].append(spec)
        return len(self.doc["materials"]) - 1

    def texture_png(self, png: bytes) -> int:
        """A texture of PNG bytes, sampled linearly (mipmapped) and clamped at its edges."""
        if not self.doc["samplers"]:
            self.doc["samplers"].append({"magFilter": 9729, "minFilter": 9987,
                                         "wrapS": 33071, "wrapT": 33071})
        self.doc["images"].append({"bufferView": self._view(png), "mimeType": "image/png"})
        self.doc["textures"].append({"sampler": 0, "source": len(self.doc["images"]) - 1})
        return len(self.doc["textures"]) - 1

    def node(self, spec: dict, root: bool = True) -> int:
        """Add a node (glTF JSON); a root node joins the scene."""
        self.doc["nodes"].append(spec)
        index = len(self.doc["nodes"]) - 1
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def camera(self, spec: dict) -> int:
        self.doc["cameras"].append(spec)
        return len(self.doc["cameras"]) - 1

    def glb(self) -> bytes:
        """The GLB file: empty top-level arrays left out, the buffer's length set."""
        blob = self.blob.getvalue()
        doc = {k: v for k, v in self.doc.items() if v != []}
        doc["buffers"] = [{"byteLength": len(blob) + (-len(blob) % 4)}]
        if self._used:
            doc["extensionsUsed"] = sorted(self._used)
        return glb_container(doc, blob)
