"""Bump tiles compiled into the rows the relief kernels read: one parameter row per tile.

Design rule: :func:`tile_params` is the one place where a :class:`~engine.model.design.BumpTile`
(designer's numbers) becomes a row of :mod:`engine.tracer.kernels.bumps` parameters, and
where every number the kernels need to stay smooth is made safe: rounding widths are clamped
so that grooves, facets and seams meet with continuous normals, bands fade in and out, a
thread is laid out from its standard (:func:`engine.appearance.threads.thread_layout`).
:func:`bump_tables` does this for a whole design: the tiles on the bottle's outer surface
(bands placed by height, converted to the section's arc length ``v``), the closure's own
reliefs, and the designer's tiles on the cap (bands placed by height above the lower edge of
its straight skirt, :func:`cap_band`), with one float32 atlas holding every relief image.
A thread drawn as true geometry (:func:`thread_drawings`) gets no relief row: the tracer
raises it as glass. Units mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..geometry.chain import locate, radius_at
from ..geometry.validate import body_profile
from ..model.design import IMAGE_BUMPS
from ..tracer.kernels import bumps as K
from .relief_image import relief_texture
from .threads import thread_layout, thread_rendering

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


def band_coordinates(design, z0: float, z1: float):
    """``(v0, v1, radius)`` of the band of heights ``z0..z1`` on the outer wall: ``v`` as the
    tracer measures it (round bottles: arc length from the axis along the outer section;
    otherwise the height) and the reference radius (the wall's radius at mid-band, of the
    first section). ``None`` for a band outside the wall (clipped to it otherwise)."""
    prof = body_profile(design.shape)
    wall = prof.sections[0].outer_wall
    lo, hi = max(z0, wall[0].p0[1]), min(z1, wall[-1].p1[1])
    if not hi - lo > 1e-6:
        return None
    radius = float(radius_at(wall, 0.5 * (lo + hi)))
    if design.shape.cross_section != "round":
        return float(lo), float(hi), radius
    base = sum(sg.length for sg in prof.sections[0].outer_base)
    starts = np.concatenate([[0.0], np.cumsum([sg.length for sg in wall])])
    idx, t = locate(wall, np.array([lo, hi]))
    v = base + starts[idx] + t * np.array([wall[i].length for i in idx])
    return float(v[0]), float(v[1]), radius


def thread_drawings(design) -> tuple:
    """How each of ``design``'s bump tiles that is a thread is drawn: a tuple as long as
    ``design.bumps``, a :class:`~engine.appearance.threads.ThreadRendering` for a thread and
    ``None`` for any other tile. The rule is :func:`~engine.appearance.threads.thread_rendering`;
    this adds what it needs from the shape: the wall's thickness at mid-band and whether true
    geometry can be built there (a round neck, a raised ridge, its band on one straight piece
    of the outer wall that no earlier true thread uses, room for its turns). Cached by
    ``(shape, bumps)``."""
    return _thread_drawings(design.shape, design.bumps)


@lru_cache(maxsize=32)
def _thread_drawings(shape, bumps) -> tuple:
    from ..geometry.segments import Line
    from ..model.design import Design
    from .closures import finish_of
    design = Design(shape=shape, bumps=bumps)
    prof = body_profile(shape)
    wall, inner = prof.sections[0].outer_wall, prof.sections[0].inner_wall
    neck = 2.0 * finish_of(design).r_neck
    taken, out = set(), []
    for tile in bumps:
        if tile.kind != "thread" or tile.on != "bottle":
            out.append(None)
            continue
        lo, hi = max(tile.z0, wall[0].p0[1]), min(tile.z1, wall[-1].p1[1])
        mid = 0.5 * (lo + hi)
        thick = float(radius_at(wall, mid) - radius_at(inner, mid)) if hi > lo else math.nan
        piece = next((j for j, sg in enumerate(wall) if isinstance(sg, Line) and sg.p1[1] > sg.p0[1]
                      and sg.p0[1] <= lo + 1e-9 and sg.p1[1] >= hi - 1e-9), None)
        band = band_coordinates(design, tile.z0, tile.z1)
        turns = thread_layout(tile, band[1] - band[0], neck).turns if band is not None else 0.0
        if shape.cross_section != "round":
            obstacle = "a round neck"
        elif band is None:
            obstacle = "its band on the wall"
        elif tile.inverted or not tile.depth > 0.0:
            obstacle = "a raised ridge (not an inverted or flat thread)"
        elif piece is None:
            obstacle = "its band on one straight piece of the neck"
        elif not turns > 0.0:
            obstacle = "room on its band for part of a turn"
        elif piece in taken:
            obstacle = "a straight piece no other true thread uses"
        else:
            obstacle = ""
        drawing = thread_rendering(tile.geometry, tile.depth, thick, obstacle, lo, hi)
        if drawing.mode == "true":
            taken.add(piece)
        out.append(drawing)
    return tuple(out)


def cap_band(design, z0: float, z1: float):
    """``(part name, v0, v1, radius)``: where the band of heights ``z0..z1`` (mm above the
    lower edge of the closure's straight skirt, as a skirt print is placed:
    :func:`engine.appearance.cap_surfaces.cap_surface`) lies on the skirt, as the tracer
    measures ``v`` on that part (arc length along its chain); ``None`` without a cap, for a
    closure without a straight skirt (a crown), or where the band misses the skirt."""
    from ..errors import DesignError
    from .cap_surfaces import cap_surface
    from .closures import closure_geometry
    try:
        skirt = cap_surface(design, "cap-skirt")
    except DesignError:
        return None
    a, b = max(z0, 0.0), min(z1, skirt.height_mm)
    if not b - a > 1e-6:
        return None
    part = closure_geometry(design).parts[skirt.part]
    return part.name, skirt.v0 + a, skirt.v0 + b, skirt.radius


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
    from .closures import closure_geometry, finish_of
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
