"""Bump tiles compiled into the rows the relief kernels read: one parameter row per tile.

Design rule: :func:`tile_params` is the one place where a :class:`~engine.model.design.BumpTile`
(designer's numbers) becomes a row of :mod:`engine.tracer.kernels.bumps` parameters, and
where every number the kernels need to stay smooth is made safe: rounding widths are clamped
so that grooves, facets and seams meet with continuous normals, bands fade in and out, a
thread is laid out from its standard (:func:`engine.appearance.threads.thread_layout`).
:func:`bump_tables` does this for a whole design: the tiles on the bottle's outer surface
(bands placed by height, converted to the section's arc length ``v``), the closure's own
reliefs, and the designer's tiles on the cap (bands placed by height above the lower edge of
its straight skirt, :func:`engine.appearance.bands.cap_band`), with one float32 atlas holding every relief image.
A thread drawn as true geometry (:func:`engine.appearance.bands.thread_drawings`) gets no relief row: the tracer
raises it as glass. Units mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...model.design import IMAGE_BUMPS
from ..kernels import bumps as K
from .relief_textures import relief_texture
from ...appearance.bands import band_coordinates, cap_band, thread_drawings
from ...appearance.threads import thread_layout

KERNEL_KINDS = {"knurl": K.KNURL, "stipple": K.STIPPLE, "flutes": K.FLUTES, "facets": K.FACETS,
                "diamond": K.DIAMOND, "thread": K.THREAD, "frosted": K.FROSTED,
                **{k: K.MAP for k in IMAGE_BUMPS}}
#: Length (mm) over which a procedural band fades in and out (at most a quarter of the band).
FADE_MM = 1.0
BOTTLE = "bottle"


@dataclass(frozen=True, eq=False)
class BumpTables:
    """Everything the tracer needs to shade a design's reliefs.

    ``kinds`` (n,) int64 kernel kinds; ``params`` (n, ``P_COLS``) float64 rows; ``atlas``
    (m >= 1, 3) float32 texels of every relief image (rows ``params[i, P_TEX0]`` on);
    ``surfaces[i]``: ``"bottle"`` (the outer surface: outer wall, punted bottom) or
    ``"closure:NAME"`` (the closure part called NAME); ``names[i]`` the tile's name.
    """

    kinds: np.ndarray
    params: np.ndarray
    atlas: np.ndarray
    surfaces: tuple[str, ...]
    names: tuple[str, ...]


def tile_params(tile, v0: float, v1: float, radius: float, neck_diameter: float = 0.0,
                texture=None) -> tuple[int, np.ndarray]:
    """``(kernel kind, parameter row)`` of ``tile`` on the band ``v0..v1`` (mm) at reference
    radius ``radius`` (mm); ``neck_diameter`` picks a thread's standard when it names none;
    ``texture`` = ``(tex0, width, height, mode)`` places an image kind in the atlas."""
    kind = KERNEL_KINDS[tile.kind]
    p = np.zeros(K.P_COLS)
    band = v1 - v0
    n = max(int(tile.repeat), 1)
    p[K.P_V0], p[K.P_V1], p[K.P_RADIUS], p[K.P_REPEAT] = v0, v1, radius, n
    p[K.P_DEPTH] = -tile.depth if tile.inverted else tile.depth
    p[K.P_PHASE] = math.radians(tile.angle_deg)
    p[K.P_PITCH] = tile.pitch
    p[K.P_FADE] = min(FADE_MM, 0.25 * band)
    p[K.P_ALPHA] = tile.alpha
    sharp, depth = tile.sharpness, tile.depth
    pu = 2.0 * math.pi * radius / n
    pv = tile.pitch if tile.pitch > 0.0 else pu
    if kind == K.KNURL:
        p[K.P_A] = 1.0 if tile.width >= 0.5 else 0.0
        p[K.P_B] = 0.5 + 0.49 * sharp
    elif kind == K.STIPPLE:
        wu = min(max(tile.width, 0.02), 1.0)
        p[K.P_A], p[K.P_B], p[K.P_C] = wu, min(1.0, wu * pu / pv), 0.5
    elif kind == K.FLUTES:
        p[K.P_A] = min(max(tile.width, 0.02), 1.0)
    elif kind == K.FACETS:
        d = max(radius - min(depth, 0.5 * radius), 1e-9)
        step = 2.0 * math.pi / n
        room = 0.45 * d * (1.0 / math.cos(step) - 1.0) if math.cos(step) > 0.05 else depth
        p[K.P_B] = min(((1.0 - sharp) * 0.5 + 0.01) * depth, room)
    elif kind == K.DIAMOND:
        k = ((1.0 - sharp) * 0.4 + 0.02) * depth
        e = (1.0 - sharp) * 0.08 + 0.004
        half = math.sqrt(0.25 + e * e) - e
        limit = depth * half / (depth + 2.0 * k) if depth > 0.0 else 0.5
        p[K.P_A], p[K.P_B], p[K.P_C] = min(max(0.5 * tile.width, 0.01), limit), k, e
    elif kind == K.THREAD:
        lay = thread_layout(tile, band, neck_diameter or 2.0 * radius)
        p[K.P_PITCH], p[K.P_A], p[K.P_B], p[K.P_C] = lay.pitch, lay.turns, lay.flank_low, lay.flank_high
        p[K.P_D], p[K.P_START], p[K.P_FADE] = lay.runout, v0 + lay.start, 0.0
    elif kind == K.MAP:
        tex0, width, height, mode = texture
        p[K.P_TEX0], p[K.P_TEXW], p[K.P_TEXH], p[K.P_MODE] = tex0, width, height, mode
        p[K.P_SPAN], p[K.P_FADE] = math.radians(tile.width_deg), 0.0
    return kind, p


def tiles_around(tile) -> bool:
    """Whether an image tile's copies tile the whole girth (no free sides)."""
    return tile.width_deg * tile.repeat >= 360.0 * (1.0 - 1e-9)


def bump_tables(design, assets) -> BumpTables:
    """:class:`BumpTables` of ``design``: its bump tiles on the bottle's outer surface (bands
    outside the wall left out), then its closure's reliefs. Relief images are decoded from
    ``assets`` (name -> bytes; cached by content)."""
    from ...appearance.closures import closure_geometry, finish_of
    kinds, rows, surfaces, names, atlas = [], [], [], [], []
    count = 0
    neck = 2.0 * finish_of(design).r_neck
    closure = closure_geometry(design)
    for tile, drawing in zip(design.bumps, thread_drawings(design)):
        if tile.on == "cap":
            band = cap_band(design, tile.z0, tile.z1)
            places = [] if band is None else [(f"closure:{band[0]}", band[1:])]
        elif drawing is not None and drawing.mode == "true":
            places = []   # a thread drawn as true geometry is glass (engine.tracer.thread_geometry)
        else:
            band = band_coordinates(design, tile.z0, tile.z1)
            places = [] if band is None else [(BOTTLE, band)]
        if not places:
            continue
        texture = None
        if tile.kind in IMAGE_BUMPS:
            tex, mode = relief_texture(tile.asset, assets[tile.asset], tile.kind, tile.width,
                                       tiles_around(tile))
            texture = (count, tex.shape[1], tex.shape[0], mode)
            atlas.append(tex.reshape(-1, 3))
            count += tex.shape[0] * tex.shape[1]
        for surface, band in places:
            kind, row = tile_params(tile, *band, neck_diameter=neck, texture=texture)
            kinds.append(kind)
            rows.append(row)
            surfaces.append(surface)
            names.append(tile.name)
    for part in closure.parts if closure is not None else ():
        for relief in part.reliefs:
            kind, row = tile_params(relief.tile, relief.v0, relief.v1, relief.radius, neck)
            kinds.append(kind)
            rows.append(row)
            surfaces.append(f"closure:{part.name}")
            names.append(relief.tile.name)
    flat = np.concatenate(atlas) if atlas else np.zeros((1, 3), np.float32)
    return BumpTables(np.asarray(kinds, np.int64), np.asarray(rows, float).reshape(-1, K.P_COLS),
                      np.ascontiguousarray(flat, np.float32), tuple(surfaces), tuple(names))
