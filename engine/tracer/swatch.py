"""A small shaded picture of a bump tile's relief, for the bump-tiles panel.

Design rule: the swatch shows the relief field itself, not a render: the same compiled height
and slopes the tracer uses (:func:`engine.tracer.kernels.bumps.relief_grid`, on the same row
from :func:`engine.tracer.tables.bump_rows.tile_params`) over a flat patch of the band, lit by
one light with numpy (diffuse plus a highlight), so a parameter edit shows at once. The patch
spans about three repeats around and the matching height of the band (an image tile: one
copy, letterboxed), top of the picture at the top of the band; relief too gentle to see at
that size is drawn steeper (:data:`MIN_SHOWN_SLOPE`). Frosting, which has no relief,
is shown as a highlight spread by its roughness. Output: ``(H, W, 3)`` uint8 sRGB.
"""
from __future__ import annotations

import math

import numpy as np

from ..color import tonemap_srgb8
from ..model.design import IMAGE_BUMPS
from .kernels import bumps as K
from .tables.bump_rows import tile_params, tiles_around
from .tables.relief_textures import relief_texture

LIGHT = np.array([-0.45, 0.55, 0.70]) / np.linalg.norm([-0.45, 0.55, 0.70])
GLASS_RGB = np.array([0.62, 0.74, 0.78])
#: Relief whose steepest slope is below this is drawn with its slopes scaled up to it, so a
#: gentle pattern still shows in a small picture.
MIN_SHOWN_SLOPE = 0.6


def _shade(nx, ny, nz, spec_power=40.0):
    """Linear RGB of unit normals lit by :data:`LIGHT` (viewer along +z)."""
    ndl = np.clip(nx * LIGHT[0] + ny * LIGHT[1] + nz * LIGHT[2], 0.0, 1.0)
    hx, hy, hz = LIGHT + np.array([0.0, 0.0, 1.0])
    norm = math.sqrt(hx * hx + hy * hy + hz * hz)
    ndh = np.clip((nx * hx + ny * hy + nz * hz) / norm, 0.0, 1.0)
    spec = ndh ** spec_power
    return (0.18 + 0.62 * ndl)[..., None] * GLASS_RGB + 0.6 * spec[..., None]


def swatch_rgb(tile, assets=None, size: tuple[int, int] = (96, 96), radius: float = 30.0) -> np.ndarray:
    """The swatch of ``tile`` (see the module rule) ``size = (width, height)`` pixels; the
    tile is laid on a band of its own height at ``radius`` mm. Raises like
    :func:`~engine.tracer.tables.relief_textures.relief_texture` for an unusable image."""
    w, h = int(size[0]), int(size[1])
    band = max(tile.z1 - tile.z0, 1e-3)
    texture, atlas = None, np.zeros((1, 3), np.float32)
    if tile.kind in IMAGE_BUMPS:
        tex, mode = relief_texture(tile.asset, (assets or {})[tile.asset], tile.kind, tile.width,
                                   tiles_around(tile))
        texture, atlas = (0, tex.shape[1], tex.shape[0], mode), np.ascontiguousarray(tex.reshape(-1, 3))
    kind, p = tile_params(tile, 0.0, band, radius, neck_diameter=2.0 * radius, texture=texture)
    if kind == K.FROSTED:
        y, x = np.mgrid[0:h, 0:w]
        d2 = ((x - 0.35 * w) / w) ** 2 + ((y - 0.35 * h) / h) ** 2
        spread = 0.02 + 0.5 * tile.alpha
        glow = np.exp(-d2 / (2.0 * spread * spread))
        return tonemap_srgb8((0.25 + 0.35 * glow)[..., None] * GLASS_RGB + 0.45 * glow[..., None])
    period = 2.0 * math.pi * radius / p[K.P_REPEAT]
    if kind == K.MAP:
        span = min(p[K.P_SPAN], 2.0 * math.pi / p[K.P_REPEAT]) * radius
        across, up = span, band
        u_start = p[K.P_PHASE] * radius - 0.5 * span if span < period * (1 - 1e-9) else 0.0
        v_start = 0.0
    else:
        across = min(max(3.0 * period, 4.0), 2.0 * math.pi * radius, max(band, 4.0))
        up = min(band, across * h / w)
        u_start, v_start = 0.0, 0.5 * (band - up)
    scale = min(w / across, h / up)                           # pixels per mm, letterboxed
    us = u_start + (np.arange(w) + 0.5 - 0.5 * (w - across * scale)) / scale
    vs = v_start + up - (np.arange(h) + 0.5 - 0.5 * (h - up * scale)) / scale
    uu, vv = np.meshgrid(us, vs)
    out = np.zeros((uu.size, 3))
    K.relief_grid(kind, p, atlas, np.ascontiguousarray(uu.ravel()), np.ascontiguousarray(vv.ravel()), out)
    hu, hv = out[:, 1].reshape(h, w), out[:, 2].reshape(h, w)
    steepest = float(np.max(np.hypot(hu, hv)))
    if 0.0 < steepest < MIN_SHOWN_SLOPE:  # gentle relief (big facets) is drawn steeper
        hu, hv = hu * (MIN_SHOWN_SLOPE / steepest), hv * (MIN_SHOWN_SLOPE / steepest)
    norm = np.sqrt(1.0 + hu * hu + hv * hv)
    rgb = _shade(-hu / norm, -hv / norm, 1.0 / norm)
    inside = ((uu >= u_start) & (uu <= u_start + across) & (vv >= v_start) & (vv <= v_start + up))
    rgb[~inside] = 0.12
    return tonemap_srgb8(rgb)
