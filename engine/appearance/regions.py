"""Finish regions of a label's front: chroma keys and masks -> one uint8 region index map.

Design rule: :func:`region_map` turns ``Label.regions`` into an array the size of the front
artwork, ``0`` for plain paper and ``k + 1`` where region ``k`` applies; later regions win
where they overlap (the last one that claims a texel gets it). A chroma region claims the
texels (with any paper there, alpha > 0) whose **sRGB** colour (what the eyedropper showed,
0..1) lies within ``tolerance`` (Euclidean) of one of its keys; a mask region claims the texels
where its image is inked, ``(1 - mean sRGB) * alpha >= 0.5`` (dark on light or on transparent,
as print separations come), the mask resampled to the map's size by nearest texel. Without
front artwork the map is the size of the largest mask (1 x 1 without one: the plain colour
keyed as a single texel). Maps are cached by the content of the images and the regions, and
read-only.
"""
from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict

import numpy as np

from ..color import linear_to_srgb
from .images import asset_image

_LOCK = threading.Lock()
_MAPS: OrderedDict = OrderedDict()
#: Region maps kept (at most 16 MB each).
CACHED_MAPS = 8


def chroma_mask(srgb: np.ndarray, alpha: np.ndarray, keys, tolerance: float) -> np.ndarray:
    """Boolean ``(H, W)``: texels of ``srgb`` ``(H, W, 3)`` within ``tolerance`` of any key."""
    hit = np.zeros(srgb.shape[:2], bool)
    tol2 = float(tolerance) ** 2
    for key in keys:
        d2 = np.sum((srgb - np.asarray(key, np.float32)) ** 2, axis=2)
        hit |= d2 <= tol2
    return hit & (alpha > 0.0)


def ink_mask(mask_rgba: np.ndarray, shape) -> np.ndarray:
    """Boolean ``shape`` ``(H, W)``: where a mask image (linear RGBA) is inked (module rule)."""
    srgb = linear_to_srgb(mask_rgba[..., :3])
    ink = (1.0 - srgb.mean(axis=2)) * mask_rgba[..., 3] >= 0.5
    h, w = shape
    rows = np.minimum(((np.arange(h) + 0.5) * ink.shape[0] / h).astype(np.int64), ink.shape[0] - 1)
    cols = np.minimum(((np.arange(w) + 0.5) * ink.shape[1] / w).astype(np.int64), ink.shape[1] - 1)
    return ink[rows[:, None], cols[None, :]]


def _digest(assets, name) -> str | None:
    return None if name is None else hashlib.sha256(bytes(assets[name])).hexdigest()


def region_map(label, assets) -> np.ndarray:
    """Read-only uint8 ``(H, W)`` region index map of ``label``'s front (module rule).

    Raises :class:`engine.appearance.images.ArtworkError` for a missing or bad image.
    """
    front = label.front
    key = (_digest(assets, front.asset), front.color, label.regions,
           tuple(_digest(assets, r.mask_asset) for r in label.regions))
    with _LOCK:
        hit = _MAPS.get(key)
        if hit is not None:
            _MAPS.move_to_end(key)
            return hit
    out = _build(label, assets)
    out.setflags(write=False)
    with _LOCK:
        _MAPS[key] = out
        while len(_MAPS) > CACHED_MAPS:
            _MAPS.popitem(last=False)
    return out


def _build(label, assets) -> np.ndarray:
    front = label.front
    masks = {r.mask_asset: asset_image(assets, r.mask_asset, "mask") for r in label.regions
             if r.source == "mask"}
    if front.asset is not None:
        art = asset_image(assets, front.asset)
        srgb, alpha = linear_to_srgb(art[..., :3]), art[..., 3]
    else:
        size = max((m.shape[:2] for m in masks.values()), key=lambda s: s[0] * s[1], default=(1, 1))
        srgb = np.broadcast_to(linear_to_srgb(np.asarray(front.color, np.float32)), size + (3,))
        alpha = np.ones(size, np.float32)
    out = np.zeros(srgb.shape[:2], np.uint8)
    for k, region in enumerate(label.regions):
        if region.source == "chroma":
            claimed = chroma_mask(srgb, alpha, region.keys, region.tolerance)
        else:
            claimed = ink_mask(masks[region.mask_asset], out.shape)
        out[claimed] = k + 1
    return out
