"""Relief images as the kernels' textures: heights and slopes of a decoded image.

Design rule: an image decoded and checked by :mod:`engine.appearance.relief_image` becomes a
float32 texture ``(H, W, 3)`` for :func:`engine.tracer.kernels.bumps.map_relief`, row 0 at the
bottom of the band:

* ``MAP_HEIGHT`` (``height_map``, ``emboss``): normalised height ``H`` in [-1, 1] and its
  derivatives per unit of the map's coordinates, by central differences; ``emboss`` raises the
  image's ink (its alpha, else its brightness) and rounds it with a bevel (three box blurs).
* ``MAP_SLOPE`` (``colour_code``, ``normal_gl``, ``normal_dx``): slopes ``dh/du, dh/dv`` as
  drawn. The colour code: red is the vertical deviation of the normal (``2 R - 1``), the
  green:blue balance the horizontal one (``(G - B) / (G + B)``). Normal maps: ``2 rgb - 1``
  in tangent space, green up (OpenGL) or down (DirectX, flipped here).

The height (or slope) is windowed to zero at the band's ends, and at the copy's sides when a
copy does not tile around the girth, so the shading normal stays continuous there. Textures are
kept by content (a small LRU), so renders and swatches decode each image once.
"""
from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict

import numpy as np

from ...appearance.relief_image import HEIGHT_KINDS, SLOPE_KINDS, ReliefImageError, read_relief_pixels
from ...errors import shown
from ..kernels.bumps import MAP_HEIGHT, MAP_SLOPE

#: Smallest |n_z| a drawn normal keeps: slopes stay below 20 (a 87 deg tilt).
MIN_NZ = 0.05
#: Fraction of the map (at least 2 texels) over which relief fades out at a free edge.
EDGE_FRACTION = 0.03


def _luminance(px: np.ndarray) -> np.ndarray:
    return 0.2126 * px[..., 0] + 0.7152 * px[..., 1] + 0.0722 * px[..., 2]


def _box_blur(a: np.ndarray, r: int, axis: int) -> np.ndarray:
    """Mean over ``2 r + 1`` texels along ``axis`` with zeros beyond the edges (cumulative sums)."""
    if r < 1:
        return a
    pad = [(0, 0)] * a.ndim
    pad[axis] = (r + 1, r)
    c = np.cumsum(np.pad(a, pad), axis=axis)
    n = a.shape[axis]
    hi = np.take(c, np.arange(2 * r + 1, 2 * r + 1 + n), axis=axis)
    lo = np.take(c, np.arange(0, n), axis=axis)
    return (hi - lo) / (2 * r + 1)


def _edge_window(n: int) -> np.ndarray:
    """1 inside, a smooth ramp to 0 over the outermost ``EDGE_FRACTION`` (>= 2 texels), 0 at
    the two outermost texels themselves."""
    m = max(2, int(round(EDGE_FRACTION * n)))
    i = np.arange(n, dtype=np.float64)
    d = np.minimum(i, n - 1 - i) - 1.0
    t = np.clip(d / m, 0.0, 1.0)
    return t * t * t * (t * (6 * t - 15) + 10)


def relief_texture(name: str, data: bytes, kind: str, bevel: float = 0.0,
                   tile_u: bool = True) -> tuple[np.ndarray, int]:
    """``(texture (H, W, 3) float32, map mode)`` of an image for bump ``kind`` (module doc).

    ``bevel`` is the emboss's rounding as a fraction of the map's height; ``tile_u`` says the
    copies tile around the girth (no window at the sides). Cached by content.
    """
    key = (hashlib.sha256(bytes(data)).hexdigest(), kind, round(float(bevel), 6), bool(tile_u))
    with _LOCK:
        hit = _TEXTURES.get(key)
        if hit is not None:
            _TEXTURES.move_to_end(key)
            return hit
    result = _build_texture(name, data, kind, bevel, tile_u)
    with _LOCK:
        _TEXTURES[key] = result
        while len(_TEXTURES) > _CACHE_SIZE:
            _TEXTURES.popitem(last=False)
    return result


def _build_texture(name, data, kind, bevel, tile_u):
    if kind not in HEIGHT_KINDS + SLOPE_KINDS:
        raise ReliefImageError(f"{shown(kind)} is not an image relief kind")
    px = read_relief_pixels(name, data)[::-1].astype(np.float64)  # row 0 = bottom of the band
    h, w = px.shape[:2]
    win_v = _edge_window(h)[:, None]
    win_u = np.ones((1, w)) if tile_u else _edge_window(w)[None, :]
    win = win_v * win_u
    out = np.zeros((h, w, 3), np.float32)
    if kind in HEIGHT_KINDS:
        if kind == "emboss":
            has_alpha = bool(np.any(px[..., 3] < 1.0))
            ink = px[..., 3] if has_alpha else _luminance(px)
            r = int(round(max(bevel, 0.0) * h / 3.0))
            for axis in (0, 1, 0, 1, 0, 1):
                ink = _box_blur(ink, r, axis)
            height = ink
        else:
            height = _luminance(px) * px[..., 3]
        peak = float(np.max(np.abs(height)))
        height = height / peak if peak > 0.0 else height
        height = height * win
        du = (np.roll(height, -1, axis=1) - np.roll(height, 1, axis=1)) * (0.5 * w)
        if not tile_u:  # zeros at the sides already; no wrap through them
            du[:, 0] = du[:, -1] = 0.0
        dv = np.gradient(height, axis=0) * h
        out[..., 0], out[..., 1], out[..., 2] = height, du, dv
        return out, MAP_HEIGHT
    if kind == "colour_code":
        g, b = px[..., 1], px[..., 2]
        with np.errstate(invalid="ignore", divide="ignore"):
            nu = np.where(g + b > 0.0, (g - b) / (g + b), 0.0)
        nv = 2.0 * px[..., 0] - 1.0
    else:
        nu, nv = 2.0 * px[..., 0] - 1.0, 2.0 * px[..., 1] - 1.0
        if kind == "normal_dx":
            nv = -nv
    nz = np.sqrt(np.maximum(1.0 - nu * nu - nv * nv, MIN_NZ * MIN_NZ))
    out[..., 1], out[..., 2] = -nu / nz * win, -nv / nz * win
    return out, MAP_SLOPE


_LOCK = threading.Lock()
_TEXTURES: OrderedDict = OrderedDict()
_CACHE_SIZE = 8
