"""Labels and prints on the closure as glTF sheets: a front and a back, textured, with alpha.

Design rule: a sheet is a grid over the artwork's ``(s, t)`` whose nodes lie on the exact
surface the label follows (:meth:`engine.appearance.frame.LabelFrame.points` on the wall; the
closure's flat top or straight skirt for a print), refined until every cell's centre and edge
midpoints are within the chordal tolerance of the grid's chords, then lifted off the glass by
:func:`lift_mm` along the surface normal so that no rasteriser sees it fight the glass. The
front faces out and reads ``uv = (s, t)``; the back (seen from inside, through the glass) faces
in and reads :func:`engine.appearance.decal.back_coordinates`. Textures are sRGB PNGs with the
front artwork's alpha as the sheet's outline (clear-vinyl regions transparent: the glass shows
as in the tracer; a face whose texels are all opaque is glTF's ``OPAQUE``, else ``BLEND``);
foil regions become metal through a metallic-roughness texture (blue =
metal, green = roughness ``1 - gloss``) and take the foil's reflectance at normal incidence
from its complex index (:data:`engine.appearance.presets.FOIL_OPTICS`). Identical faces share
one texture and material. Units mm in, the builder's glTF frame out.
"""
from __future__ import annotations

import io
import math

import numpy as np
from PIL import Image

from ..appearance.cap_surfaces import cap_surface, top_corners
from ..appearance.frame import Placement, label_frame
from ..appearance.images import asset_image
from ..color import linear_to_srgb
from ..appearance.presets import FOIL_OPTICS
from ..appearance.regions import region_map
from .gltf_build import to_gltf, to_gltf_dir

#: Largest side (texels) of a label texture in the scene (WebGL on phones: 4096 at most).
MAX_TEXTURE_SIDE = 2048
#: Grid nodes a side a sheet starts from and may grow to.
START_NODES, MAX_NODES = 5, 513
#: Roughness of plain paper (glTF's perceptual roughness).
PAPER_ROUGHNESS = 0.6


def lift_mm(tol_mm: float) -> float:
    """How far (mm) the front sheet stands off the surface: twice the chordal tolerance (so its
    chords stay outside the glass's), at least 0.05 mm, at most 1 mm; the back half of it."""
    return min(max(2.0 * tol_mm, 0.05), 1.0)


def _png(rgba8: np.ndarray) -> bytes:
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgba8), "RGBA").save(buf, "PNG")
    return buf.getvalue()


def _shrunk(rgba: np.ndarray) -> np.ndarray:
    h, w = rgba.shape[:2]
    k = max(h, w) / MAX_TEXTURE_SIDE
    if k <= 1.0:
        return rgba
    size = (max(int(w / k), 1), max(int(h / k), 1))
    return np.asarray(Image.fromarray(rgba).resize(size, Image.Resampling.LANCZOS))


def foil_reflectance(kind: str) -> np.ndarray:
    """A foil's reflectance at normal incidence (linear RGB) from its complex index."""
    n, k = (np.asarray(v, float) for v in FOIL_OPTICS[kind])
    return ((n - 1) ** 2 + k ** 2) / ((n + 1) ** 2 + k ** 2)


def front_textures(label, assets):
    """``(base_rgba8, metal_rough_rgba8 or None, opaque)`` of the label's front (module rule)."""
    if label.front.asset is not None:
        art = np.array(asset_image(assets, label.front.asset), np.float32)
    else:
        art = np.ones((4, 4, 4), np.float32)
        art[..., :3] = label.front.color
    codes = region_map(label, assets) if label.regions else None
    rough = np.full(art.shape[:2], PAPER_ROUGHNESS, np.float32)
    metal = np.zeros(art.shape[:2], np.float32)
    for k, region in enumerate(label.regions):
        if codes is None or codes.shape != art.shape[:2]:
            break
        where = codes == k + 1
        if region.finish in FOIL_OPTICS:
            art[where, :3] = foil_reflectance(region.finish)
            metal[where] = 1.0
        if region.finish == "clear_vinyl":
            art[where, 3] = 0.0
        if region.finish in FOIL_OPTICS or region.finish in ("varnish", "clear_vinyl_white"):
            rough[where] = max(1.0 - region.gloss, 0.05)
    base = np.empty(art.shape, np.uint8)
    base[..., :3] = np.round(linear_to_srgb(np.clip(art[..., :3], 0, 1)) * 255)
    base[..., 3] = np.round(np.clip(art[..., 3], 0, 1) * 255)
    mr = None
    if metal.any():
        mr = np.zeros(art.shape, np.uint8)
        mr[..., 1], mr[..., 2], mr[..., 3] = np.round(rough * 255), np.round(metal * 255), 255
        mr = _shrunk(mr)
    return _shrunk(base), mr, bool(base[..., 3].min() == 255)


def back_texture(label, assets, front_alpha: np.ndarray) -> np.ndarray:
    """The back face's sRGB RGBA (the back artwork or colour, the front's outline as alpha),
    mirrored left to right as the back reads from inside."""
    h, w = front_alpha.shape
    if label.back.asset is not None:
        art = np.asarray(asset_image(assets, label.back.asset), np.float32)[..., :3]
        art = np.asarray(Image.fromarray(np.round(linear_to_srgb(np.clip(art, 0, 1)) * 255)
                                         .astype(np.uint8)).resize((w, h)))
    else:
        art = np.broadcast_to(np.round(linear_to_srgb(np.asarray(label.back.color)) * 255), (h, w, 3))
    out = np.empty((h, w, 4), np.uint8)
    out[..., :3] = art[:, ::-1]  # the back reads (1 - s, t): texel columns mirrored
    out[..., 3] = front_alpha[:, ::-1]
    return out


# ----------------------------------------------------------------------------- sheet grids
def refined_grid(points_of, tol_mm: float):
    """``(P (nt, ns, 3), s (ns,), t (nt,))``: a grid of exact surface points, refined along ``s``
    and ``t`` until every cell's edge midpoints and centre lie within ``tol_mm`` of its chords."""
    ns = nt = START_NODES
    while True:
        s, t = np.linspace(0, 1, ns), np.linspace(0, 1, nt)
        grid = points_of(*np.meshgrid(s, t))
        sm, tm = 0.5 * (s[1:] + s[:-1]), 0.5 * (t[1:] + t[:-1])
        e_s = np.abs(points_of(*np.meshgrid(sm, t)) - 0.5 * (grid[:, 1:] + grid[:, :-1])).max()
        e_t = np.abs(points_of(*np.meshgrid(s, tm)) - 0.5 * (grid[1:] + grid[:-1])).max()
        centre = 0.25 * (grid[1:, 1:] + grid[1:, :-1] + grid[:-1, 1:] + grid[:-1, :-1])
        e_c = np.abs(points_of(*np.meshgrid(sm, tm)) - centre).max()
        grow_s = (e_s > tol_mm or e_c > tol_mm) and ns < MAX_NODES
        grow_t = (e_t > tol_mm or e_c > tol_mm) and nt < MAX_NODES
        if not (grow_s or grow_t):
            return grid, s, t
        ns, nt = (2 * ns - 1 if grow_s else ns), (2 * nt - 1 if grow_t else nt)


def sheet_points(design, label, tol_mm: float):
    """``(P, s, t, outward)``: the label's grid on its surface (mm, world frame) and the
    direction its front faces, ``(nt, ns, 3)`` (the surface's outward normal there)."""
    if label.surface == "wall":
        frame = label_frame(design.shape, Placement.of(label))
        grid, s, t = refined_grid(frame.points, tol_mm)
        radial = grid * np.array([1.0, 1.0, 0.0])
        return grid, s, t, radial
    surf = cap_surface(design, label.surface)
    if label.surface == "cap-top":
        c = top_corners(label)  # top-left, top-right, bottom-right, bottom-left

        def flat(ss, tt):
            xy = ((1 - tt)[..., None] * ((1 - ss)[..., None] * c[0] + ss[..., None] * c[1])
                  + tt[..., None] * ((1 - ss)[..., None] * c[3] + ss[..., None] * c[2]))
            return np.concatenate([xy, np.full(xy.shape[:-1] + (1,), surf.z0)], -1)
        grid, s, t = refined_grid(flat, tol_mm)
        return grid, s, t, np.broadcast_to([0.0, 0.0, 1.0], grid.shape)
    span = label.width_mm / surf.radius
    theta0 = math.radians(label.angle_deg) - 0.5 * span
    z_top = surf.z0 + label.z_mm + 0.5 * label.height_mm

    def skirt(ss, tt):
        th = theta0 + ss * span
        return np.stack([surf.radius * np.cos(th), surf.radius * np.sin(th),
                         z_top - tt * label.height_mm], -1)
    grid, s, t = refined_grid(skirt, tol_mm)
    return grid, s, t, grid * np.array([1.0, 1.0, 0.0])


def sheet_normals(grid: np.ndarray, outward: np.ndarray) -> np.ndarray:
    """Unit normals ``(nt, ns, 3)`` of a grid (central differences), turned to face ``outward``."""
    ds = np.gradient(grid, axis=1)
    dt = np.gradient(grid, axis=0)
    n = np.cross(ds, dt)
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-300)
    flip = np.sum(n * outward, axis=-1, keepdims=True) < 0
    return np.where(flip, -n, n)


def grid_faces(nt: int, ns: int, flip: bool) -> np.ndarray:
    """Two triangles per cell of an ``nt x ns`` grid (row-major vertices)."""
    i, j = np.meshgrid(np.arange(nt - 1), np.arange(ns - 1), indexing="ij")
    a = (i * ns + j).ravel()
    b, c, d = a + 1, a + ns, a + ns + 1
    faces = np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)])
    return faces[:, ::-1] if flip else faces


def oriented(faces: np.ndarray, pos: np.ndarray, nrm: np.ndarray) -> np.ndarray:
    """``faces`` with each triangle's winding turned to agree with its vertices' normals."""
    p = pos[faces]
    geo = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    bad = np.sum(geo * nrm[faces].sum(axis=1), axis=-1) < 0
    out = faces.copy()
    out[bad] = out[bad][:, ::-1]
    return out


def sheet_meshes(design, label, tol_mm: float):
    """``(front, back)``, each ``(positions, normals, faces, uv)`` in glTF's frame."""
    grid, s, t, outward = sheet_points(design, label, tol_mm)
    n = sheet_normals(grid, outward)
    nt, ns = grid.shape[:2]
    ss, tt = np.meshgrid(s, t)
    lift = lift_mm(tol_mm)
    out = []
    for d, sign, uv in ((lift, 1.0, np.stack([ss, tt], -1)),
                        (0.5 * lift, -1.0, np.stack([1.0 - ss, tt], -1))):
        pos = to_gltf((grid + d * n).reshape(-1, 3))
        nrm = to_gltf_dir((sign * n).reshape(-1, 3))
        faces = oriented(grid_faces(nt, ns, False), pos, nrm)
        out.append((pos, nrm, faces, uv.reshape(-1, 2)))
    return out
