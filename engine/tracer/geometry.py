"""Render geometry built once from a Design's shape and liquid level, from the geometry engine.

Design rule: the tracer owns no geometry of its own. The glass shell is
:func:`engine.geometry.tessellate.tessellate_body` (all cross-sections, punts, per-segment walls), the
liquid's free surface comes from :func:`engine.geometry.tessellate.tessellate_liquid`, and the exact
surfaces are :class:`engine.geometry.body.BottleBody` / its :class:`engine.geometry.offset.BodyProfile`. The
mesh (coarse, float32 in Embree) only finds candidate hits; :mod:`engine.tracer.refine` moves
each onto the true surface with its exact normal. The bottle becomes six oriented interface
surfaces, each knowing the medium on either side (../shared/oracle/SPEC.md sections 4-5);
``front`` is the medium the oriented normal points into:

=============  ============  ==========================  =============================
surface        mesh part     oriented normal points to    front | back
=============  ============  ==========================  =============================
OUTER_WALL     outer         away from the glass          air | glass
BOTTOM         base_outer    away from the glass (-z)     air | glass
INNER_WALL     inner         into the cavity              liquid below fill else air | glass
INNER_BASE     base_inner    into the cavity (+z)         liquid (or air if empty) | glass
RIM            rim           +z                           air | glass
FREE_SURFACE   surface       +z                           air | liquid
=============  ============  ==========================  =============================

The liquid meets the glass along the inner wall (one surface, media by the hit's exact
height). Geometry depends only on ``(shape, fill_height)`` and is cached by value, so camera,
colour or IOR edits reuse it. Units: mm; the world z axis is the bottle axis, z = 0 the bottom.
"""
from __future__ import annotations

import math
import threading
from dataclasses import dataclass

import numpy as np

from ..geometry.body import BottleBody
from ..geometry.tessellate import BODY_PARTS, tessellate_body, tessellate_liquid
from . import refine as _refine
from .embree_scene import EmbreeTriangles

AIR, GLASS, LIQUID = 0, 1, 2
OUTER_WALL, BOTTOM, INNER_WALL, INNER_BASE, RIM, FREE_SURFACE = range(6)
#: Chordal tolerance (mm) of the render mesh. Hits are refined onto the exact surfaces
#: (:mod:`engine.tracer.refine`), so the mesh only decides which surface a ray meets and moves
#: silhouettes by at most this much. Measured (``benchmarks/tracer.py``, 96 px, 2 spp): a
#: coarser mesh is not faster (more candidates to pass, more lost rays to recover) but less
#: accurate: image change vs 0.005 mm of 0.7 % / 1.7 % / 8 % (public_1) at 0.02 / 0.05 / 0.2 mm;
#: 0.02 mm keeps the build at ~0.2 s for a rounded square (0.9 s at 0.005 mm).
MESH_TOL_MM = 0.02
#: Tessellation part -> surface id (module table).
SURFACE_OF_PART = {"outer": OUTER_WALL, "base_outer": BOTTOM, "inner": INNER_WALL,
                   "base_inner": INNER_BASE, "rim": RIM}


@dataclass(frozen=True, eq=False)
class RenderGeometry:
    """Tessellated, medium-labelled interfaces of one bottle (+ liquid) over the exact body.

    Attributes
    ----------
    triangles : EmbreeTriangles
        The Embree scene of all interfaces (float32, one geometry): finds candidate hits.
    surface_of_triangle : ndarray of int8
        Surface id (module table) per triangle.
    body : BottleBody
        The exact surfaces (engine geometry) hits are refined onto.
    z_ib, z_top : float
        Lowest height of the cavity and the mouth (mm).
    fill_height : float or None
        Liquid level (mm), ``None`` when empty.
    face_sign : ndarray (T, 3) float32
        Triangle normals (unnormalised), facing like the surface's oriented normal (the
        tessellation faces out of the glass and the free surface up): only their sign is used.
    window_mm : float
        Largest distance (mm, along a ray) between a mesh hit and its true hit.
    tol_mm : float
        Chordal tolerance of the mesh (mm).
    """

    triangles: EmbreeTriangles
    surface_of_triangle: np.ndarray
    body: BottleBody
    z_ib: float
    z_top: float
    fill_height: float | None
    face_sign: np.ndarray
    window_mm: float
    tol_mm: float

    def media(self, surface, z):
        """``(front, back)`` medium ids (AIR, GLASS, LIQUID) of hits on ``surface`` at height ``z``."""
        has_liquid = self.fill_height is not None
        front = np.full(surface.shape, AIR, dtype=np.int8)
        back = np.full(surface.shape, GLASS, dtype=np.int8)
        if has_liquid:
            wet = ((surface == INNER_WALL) & (z < self.fill_height)) | (surface == INNER_BASE)
            front[wet] = LIQUID
            back[surface == FREE_SURFACE] = LIQUID
        return front, back

    def refine(self, o, d, t_mesh, surface):
        """Exact distances and oriented normals of mesh hits (:func:`engine.tracer.refine.refine`)."""
        return _refine.refine(self, o, d, t_mesh, surface)

    def exact_normals(self, points, surface):
        """Unit oriented normals (module table) of the true surfaces at ``points`` (N, 3) mm."""
        return _refine.exact_normals(self, np.asarray(points, float), surface)

    def in_cavity(self, points):
        """True where ``points`` (N, 3) mm lie strictly inside the inner wall's outline."""
        return self.body.wall_implicit("inner", points)[0] < 0.0


def _free_surface(shape, body, fill, tol):
    """Vertices and faces of the liquid's free surface, its edge on the inner wall pushed
    ``2 tol`` into the glass so it overlaps the (chordal) inner-wall mesh: no crack for light.
    Hits on the overlap are not in the cavity and are passed by the integrator."""
    liq = tessellate_liquid(shape, fill, tol)
    f = liq.faces[liq.part == liq.part_names.index("surface")]
    used = np.unique(f)
    v = liq.vertices[used].copy()
    g, grad = body.wall_implicit("inner", v)
    edge = np.abs(g) < 1e-6
    h = grad[edge, :2] / np.linalg.norm(grad[edge, :2], axis=1, keepdims=True)
    v[edge, :2] += 2.0 * tol * h
    remap = np.full(len(liq.vertices), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return v, remap[f]


def build_render_geometry(shape, fill_height: float | None, tol_mm: float = MESH_TOL_MM) -> RenderGeometry:
    """Tessellate (``engine.geometry.tessellate``) and label the interfaces of ``shape`` with liquid up
    to ``fill_height`` (mm).

    ``fill_height`` is clamped into ``(z_ib, z_top)``; ``None`` (or a level at or below the
    inner base) means an empty bottle. Every shape the engine validates renders (all four
    cross-sections, punts, per-segment walls); an invalid one raises ``SectionError`` /
    ``WallError``.
    """
    body = BottleBody(shape)
    prof = body.profile
    mesh = tessellate_body(shape, tol_mm)
    if fill_height is not None and fill_height <= prof.z_ib:
        fill_height = None
    if fill_height is not None:
        fill_height = float(min(fill_height, prof.z_top - 1e-3))
    part_to_surface = np.array([SURFACE_OF_PART[p] for p in BODY_PARTS], dtype=np.int8)
    verts, faces, surf = [mesh.vertices], [mesh.faces], [part_to_surface[mesh.part]]
    if fill_height is not None:
        v, f = _free_surface(shape, body, fill_height, tol_mm)
        faces.append(f + len(mesh.vertices))
        verts.append(v)
        surf.append(np.full(len(f), FREE_SURFACE, dtype=np.int8))
    r_max = max(float(np.max(np.hypot(mesh.vertices[:, 0], mesh.vertices[:, 1]))), 1.0)
    window = 2.0 * math.sqrt(2.0 * r_max * tol_mm) + 10.0 * tol_mm
    verts, faces = np.concatenate(verts), np.concatenate(faces)
    tri = verts[faces]
    face_sign = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]).astype(np.float32)
    return RenderGeometry(EmbreeTriangles(verts, faces), np.concatenate(surf), body, float(prof.z_ib),
                          float(prof.z_top), fill_height, face_sign, window, float(tol_mm))


_CACHE: dict = {}
_CACHE_LOCK = threading.Lock()
_CACHE_SIZE = 4


def fill_height_of(design) -> float | None:
    """The liquid level (mm) of a design, or ``None`` when it has no liquid.

    ``fill_mode == "volume"`` is solved through :func:`engine.geometry.capacity.fill_height_for_volume`.
    """
    liq = design.liquid
    if liq is None:
        return None
    if liq.fill_mode == "volume":
        from ..geometry.capacity import fill_height_for_volume  # geometry issue's module; only when needed

        return float(fill_height_for_volume(design.shape, liq.fill_value))
    return float(liq.fill_value)


def render_geometry_for(design) -> RenderGeometry:
    """The cached :class:`RenderGeometry` for a design's ``(shape, fill height)``.

    Thread-safe; keeps the few most recent geometries so toggling between edits stays fast.
    """
    key = (design.shape, fill_height_of(design), MESH_TOL_MM)
    with _CACHE_LOCK:
        hit = _CACHE.get(key)
        if hit is not None:
            return hit
    geom = build_render_geometry(*key)
    with _CACHE_LOCK:
        _CACHE[key] = geom
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)))
    return geom
