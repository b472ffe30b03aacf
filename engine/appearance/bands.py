"""Where a bump tile's band lies, on the bottle or on the closure, and how a thread is drawn.

Design rule: domain geometry of the finishes, no tracer formats: :func:`band_coordinates` puts a
band of heights on the outer wall in the surface coordinate ``v`` the tracer measures (arc
length along a round section, else the height), :func:`cap_band` on the closure's straight
skirt, and :func:`thread_drawings` applies the one rule of
:func:`engine.appearance.threads.thread_rendering` to each thread tile with what it needs from
the shape. The tracer's rows (:mod:`engine.tracer.tables.bump_rows`), the panels and the
defaults of new tiles read them. Units mm.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..geometry.chain import locate, radius_at
from ..geometry.validate import body_profile
from .threads import thread_layout, thread_rendering


def band_coordinates(design, z0: float, z1: float):
    """``(v0, v1, radius)`` of the band of heights ``z0..z1`` on the outer wall: ``v`` as the
    tracer measures it (round bottles: arc length from the axis along the outer section;
    otherwise the height) and the tile's reference radius at mid-band
    (:meth:`~engine.geometry.crosssection.CrossSection.tile_radius`: the first section's radius,
    an outline's girth over 2 pi). ``None`` for a band outside the wall (clipped to it
    otherwise); ``DesignError`` on a bottle whose kind cannot carry relief."""
    xs = design.shape.xs
    xs.require("relief")
    prof = body_profile(design.shape)
    wall = prof.sections[0].outer_wall
    lo, hi = max(z0, wall[0].p0[1]), min(z1, wall[-1].p1[1])
    if not hi - lo > 1e-6:
        return None
    mid = 0.5 * (lo + hi)
    radius = xs.tile_radius([radius_at(sp.outer_wall, mid) for sp in prof.sections])
    if not design.shape.xs.revolved:
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
        if not shape.xs.revolved:
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
