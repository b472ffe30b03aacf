"""The complete glTF 2.0 scene of a design: glass, liquid, labels, closure and camera, as one GLB.

Design rule: every mesh comes from the engine's own chordal-tolerance tessellation
(:func:`engine.geometry.tessellate.tessellate_body` and ``tessellate_liquid``, exact normals;
closure parts revolved here by the same sag rule, :func:`engine.geometry.tessellate.
segment_samples`) at the tolerance the caller gives; labels are sheets of
:mod:`engine.export.gltf_labels`. Glass and liquid are closed, single-sided volumes with
``KHR_materials_transmission`` (1), ``KHR_materials_ior`` and ``KHR_materials_volume``, whose
attenuation is the design's Beer-Lambert absorption exactly: glTF attenuates by
``attenuationColor ** (x / attenuationDistance)``, so with ``attenuationColor = exp(-a d)`` per
channel (``a`` in 1/mm, ``d`` = :func:`attenuation` 's distance in mm) that is ``exp(-a x)``.
``thicknessFactor`` is the material's typical thickness (the wall; the liquid's width). A metal
closure is glTF's metal with aluminium's reflectance at normal incidence times its lacquer, a
plastic one a dielectric of its colour. The design's camera becomes the scene's camera. A
scene past :data:`MAX_VERTICES` is refused before it is written, naming what made it so big.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..appearance.closure_parts import ALUMINIUM_K, ALUMINIUM_N
from ..appearance.closures import closure_geometry
from ..errors import GlassbenchError
from ..geometry import capacity
from ..geometry.tessellate import segment_samples, tessellate_body, tessellate_liquid
from ..geometry.validate import body_profile
from ..model import fill, tint
from .gltf_build import GltfBuilder, look_at_rotation, to_gltf, to_gltf_dir
from .gltf_labels import back_texture, front_textures, oriented, sheet_meshes, _png

#: Most vertices a scene may have (about 100 MB of buffers); more is refused.
MAX_VERTICES = 4_000_000
#: Attenuation colours are kept above exp(-ATTENUATION_EXPONENT) per channel.
ATTENUATION_EXPONENT = 20.0


class SceneError(GlassbenchError, ValueError):
    """The scene cannot be exported as asked (too large for the tolerance); says why."""


@dataclass
class SceneStats:
    """What went into a scene: counts per kind and the vertex total."""

    meshes: int = 0
    labels: int = 0
    textures: int = 0
    vertices: int = 0


def attenuation(absorption) -> dict:
    """``{"attenuationDistance" (m), "attenuationColor"}`` equal to Beer-Lambert ``absorption``
    (1/mm per RGB); ``{}`` for a clear material (glTF's default: no attenuation)."""
    a = max(float(x) for x in absorption)
    if a <= 0.0:
        return {}
    d_mm = min(tint.DEFAULT_THICKNESS_MM, ATTENUATION_EXPONENT / a)
    return {"attenuationDistance": d_mm / 1000.0,
            "attenuationColor": [float(c) for c in tint.transmittance(absorption, d_mm)]}


def volume_material(name: str, ior: float, absorption, thickness_mm: float) -> dict:
    """A transmissive, single-sided volume material (see the module rule)."""
    volume = {"thicknessFactor": thickness_mm / 1000.0, **attenuation(absorption)}
    return {"name": name, "doubleSided": False,
            "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                                     "metallicFactor": 0.0, "roughnessFactor": 0.0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                           "KHR_materials_volume": volume,
                           "KHR_materials_ior": {"ior": float(ior)}}}


def closure_material(mat) -> dict:
    """glTF material of a closure part (:class:`engine.appearance.closure_parts.ClosureMaterial`)."""
    rough = math.sqrt(max(mat.roughness, 0.0))  # glTF's roughness squared is the GGX alpha
    if mat.kind == "conductor":
        n, k = np.asarray(ALUMINIUM_N), np.asarray(ALUMINIUM_K)
        f0 = ((n - 1) ** 2 + k ** 2) / ((n + 1) ** 2 + k ** 2) * np.asarray(mat.tint)
        colour, metal = [float(c) for c in f0], 1.0
    else:
        colour, metal = [float(c) for c in mat.tint], 0.0
    return {"name": f"closure {mat.kind}", "doubleSided": False,
            "pbrMetallicRoughness": {"baseColorFactor": colour + [1.0], "metallicFactor": metal,
                                     "roughnessFactor": max(rough, 0.05)}}


def revolved_mesh(chain, tol_mm: float):
    """``(positions, normals, faces)`` (mm, design frame) of a closed meridian chain revolved
    about z: stations per segment by the sag rule, each segment its own exact normals."""
    r_max = max(max(abs(s.p0[0]), abs(s.p1[0])) for s in chain)
    n_theta = max(24, int(math.ceil(2 * math.pi / math.sqrt(8 * tol_mm / max(r_max, 1e-9)))))
    th = np.linspace(0.0, 2 * math.pi, n_theta, endpoint=False)
    c, s = np.cos(th), np.sin(th)
    pos, nrm, faces = [], [], []
    base = 0
    for seg in chain:
        t = segment_samples(seg, tol_mm)
        p, tan = seg.point(t), seg.tangent(t)
        rings = np.stack([p[:, :1] * c, p[:, :1] * s, np.broadcast_to(p[:, 1:], (len(t), n_theta))], -1)
        nr, nz = tan[:, 1:2], -tan[:, 0:1]
        ring_n = np.stack([nr * c, nr * s, np.broadcast_to(nz, (len(t), n_theta))], -1)
        i, j = np.meshgrid(np.arange(len(t) - 1), np.arange(n_theta), indexing="ij")
        a, b = base + i * n_theta + j, base + i * n_theta + (j + 1) % n_theta
        faces.append(np.concatenate([np.stack([a, b, a + n_theta], -1).reshape(-1, 3),
                                     np.stack([b, b + n_theta, a + n_theta], -1).reshape(-1, 3)]))
        pos.append(rings.reshape(-1, 3))
        nrm.append(ring_n.reshape(-1, 3))
        base += len(t) * n_theta
    pos, nrm, faces = np.concatenate(pos), np.concatenate(nrm), np.concatenate(faces)
    p = pos[faces]
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=-1)
    faces = faces[area > 1e-12 * max(r_max, 1.0) ** 2]  # rings on the axis: drop empty triangles
    return pos, nrm, oriented(faces, pos, nrm)


class SceneWriter:
    """Builds one design's scene into a :class:`GltfBuilder` (see the module rule)."""

    def __init__(self, design, assets, tol_mm: float, progress=None):
        self.design, self.assets, self.tol = design, assets or {}, float(tol_mm)
        self.gltf, self.stats = GltfBuilder(), SceneStats()
        self.progress = progress or (lambda f, m: None)
        self._materials: dict = {}

    def _count(self, n: int, what: str) -> None:
        self.stats.vertices += int(n)
        if self.stats.vertices > MAX_VERTICES:
            raise SceneError(f"the scene passes {MAX_VERTICES:,} vertices at {what} (tolerance "
                             f"{self.tol:g} mm); export it with a coarser --tol")

    def _mesh_node(self, name, pos_mm, nrm, faces, material, uv=None, converted=False):
        pos = pos_mm if converted else to_gltf(pos_mm)
        nrm = nrm if converted else to_gltf_dir(nrm)
        self._count(len(pos), name)
        mesh = self.gltf.mesh(name, pos, nrm, faces, material, uv)
        self.gltf.node({"name": name, "mesh": mesh})
        self.stats.meshes += 1

    def glass(self) -> None:
        d = self.design
        m = tessellate_body(d.shape, self.tol)
        mat = self.gltf.material(volume_material("glass", d.glass.ior, d.glass.absorption,
                                                 d.shape.wall_thickness))
        self._mesh_node("glass", m.vertices, m.normals, m.faces, mat)

    def liquid(self) -> None:
        d = self.design
        height = fill.fill_height_mm(d.shape, d.liquid) if d.liquid is not None else None
        if height is None or height <= body_profile(d.shape).z_ib:
            return
        m = tessellate_liquid(d.shape, height, self.tol)
        width = capacity.max_diameter_mm(d.shape) - 2 * d.shape.wall_thickness
        mat = self.gltf.material(volume_material("liquid", d.liquid.ior, d.liquid.absorption,
                                                 max(width, d.shape.wall_thickness)))
        self._mesh_node("liquid", m.vertices, m.normals, m.faces, mat)

    def closure(self) -> None:
        geom = closure_geometry(self.design)
        for part in (geom.parts if geom is not None else ()):
            pos, nrm, faces = revolved_mesh(part.chain, self.tol)
            mat = self.gltf.material(closure_material(part.material))
            self._mesh_node(f"closure {part.name}", pos, nrm, faces, mat)

    def _label_materials(self, label) -> tuple[int, int]:
        key = (label.front, label.back, label.regions)
        if key not in self._materials:
            base, mr, opaque = front_textures(label, self.assets)
            back = back_texture(label, self.assets, base[..., 3])
            front_pbr = {"baseColorTexture": {"index": self.gltf.texture_png(_png(base))},
                         "metallicFactor": 0.0 if mr is None else 1.0, "roughnessFactor": 1.0}
            if mr is not None:
                front_pbr["metallicRoughnessTexture"] = {"index": self.gltf.texture_png(_png(mr))}
            mode = {"alphaMode": "OPAQUE"} if opaque else {"alphaMode": "BLEND"}
            front = self.gltf.material({"name": f"{label.name} front", "pbrMetallicRoughness": front_pbr, **mode})
            back_pbr = {"baseColorTexture": {"index": self.gltf.texture_png(_png(back))},
                        "metallicFactor": 0.0, "roughnessFactor": 0.9}
            back_mat = self.gltf.material({"name": f"{label.name} back", "pbrMetallicRoughness": back_pbr, **mode})
            self.stats.textures += 2 + (mr is not None)
            self._materials[key] = (front, back_mat)
        return self._materials[key]

    def labels(self) -> None:
        labels = self.design.labels
        for k, label in enumerate(labels):
            front_mat, back_mat = self._label_materials(label)
            front, back = sheet_meshes(self.design, label, self.tol)
            self._mesh_node(f"label {k} {label.name} front", *front[:3], front_mat, front[3], True)
            self._mesh_node(f"label {k} {label.name} back", *back[:3], back_mat, back[3], True)
            self.stats.labels += 1
            if k % 64 == 63:
                self.progress(0.4 + 0.5 * (k + 1) / len(labels), f"label {k + 1} of {len(labels)}")

    def camera(self) -> None:
        cam, render = self.design.camera, self.design.render
        eye, target = to_gltf(cam.eye), to_gltf(cam.target)
        up = to_gltf_dir(cam.up)
        index = self.gltf.camera({"name": "design camera", "type": "perspective", "perspective": {
            "yfov": math.radians(cam.fov_y_deg), "aspectRatio": render.width / render.height,
            "znear": 0.001}})
        self.gltf.node({"name": "design camera", "camera": index, "translation": eye.tolist(),
                        "rotation": look_at_rotation(eye, target, up)})

    def build(self) -> bytes:
        steps = ((self.glass, "glass"), (self.liquid, "liquid"), (self.closure, "closure"),
                 (self.labels, "labels"), (self.camera, "camera"))
        for i, (step, what) in enumerate(steps):
            self.progress(0.1 + 0.15 * i if what != "camera" else 0.9, what)
            step()
        return self.gltf.glb()


def scene_glb(design, assets, tol_mm: float = 0.05, progress=None) -> tuple[bytes, SceneStats]:
    """The GLB bytes of ``design``'s scene at chordal tolerance ``tol_mm`` (mm) and its stats.
    Raises the tessellator's errors for a bad tolerance or shape, ``SceneError`` past
    :data:`MAX_VERTICES`, and the artwork's errors for a label image that cannot be read."""
    writer = SceneWriter(design, assets, tol_mm, progress)
    return writer.build(), writer.stats


def export_scene(design, assets, path, tol_mm: float = 0.05, progress=None) -> SceneStats:
    """Write ``design``'s scene as a GLB file at ``path`` (atomically; ``.glb`` only)."""
    from pathlib import Path

    from ..io.atomic import replacing
    path = Path(path)
    if path.suffix.lower() != ".glb":
        raise ValueError(f"the scene is written as GLB: the file name must end in .glb, got {path.name!r}")
    data, stats = scene_glb(design, assets, tol_mm, progress)
    with replacing(path, suffix=".glb") as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return stats
