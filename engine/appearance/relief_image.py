"""Relief images: height maps, colour codes, normal maps and embossed logos, decoded safely.

Design rule: an image is refused with one clear :class:`ReliefImageError` before it can cost
much: its size is read from the header and checked against :data:`engine.limits.
MAX_RELIEF_TEXELS` before any pixel is decoded, anything Pillow cannot decode is "cannot be
decoded", and a float image holding NaN or infinities is refused (relief has no "clean" value
to put there). The tracer turns the decoded pixels into its relief texture
(:mod:`engine.tracer.tables.relief_textures`); checks are kept by content (a small LRU), so
an image is decoded once however often it is checked.
"""
from __future__ import annotations

import hashlib
import io
import threading
from collections import OrderedDict

import numpy as np

from ..errors import ProjectError, shown
from ..io.quiet import captured_stderr
from ..limits import MAX_RELIEF_TEXELS, RELIEF_SIDE_RANGE

HEIGHT_KINDS = ("height_map", "emboss")
SLOPE_KINDS = ("colour_code", "normal_gl", "normal_dx")


class ReliefImageError(ProjectError, ValueError):
    """A relief image that cannot be used; the message names the asset and the problem."""


def read_relief_pixels(name: str, data: bytes) -> np.ndarray:
    """Decode image bytes to float32 ``(H, W, 4)`` RGBA, top row first, 8- and 16-bit images
    scaled to [0, 1] and float images (TIFF mode F) kept as they are in every channel.

    Raises :class:`ReliefImageError` for an image too large (from its header), one that
    cannot be decoded, or float texels that are NaN or infinite.
    """
    from PIL import Image
    label = f"relief image {shown(str(name))}"
    try:
        img = Image.open(io.BytesIO(bytes(data)))
        w, h = img.size
    except Exception as exc:  # why: Pillow raises many types for a damaged header
        raise ReliefImageError(f"{label} cannot be decoded (PNG, JPEG, TIFF or BMP expected): "
                               f"{type(exc).__name__}") from None
    lo, hi = RELIEF_SIDE_RANGE
    if not (lo <= w <= hi and lo <= h <= hi) or w * h > MAX_RELIEF_TEXELS:
        raise ReliefImageError(f"{label} is {w} x {h} texels; relief images have {lo} to {hi} "
                               f"a side and at most {MAX_RELIEF_TEXELS} texels (2048 x 2048)")
    try:
        with captured_stderr():  # why: Pillow's libtiff prints its read errors on stderr itself
            img.load()
        mode = img.mode
        if mode == "F":
            grey = np.asarray(img, dtype=np.float32)
            px = np.stack([grey, grey, grey, np.ones_like(grey)], axis=-1)
        elif mode.startswith("I"):
            grey = np.asarray(img.convert("I"), dtype=np.float64) / 65535.0
            px = np.stack([grey, grey, grey, np.ones_like(grey)], axis=-1).astype(np.float32)
        else:
            px = np.asarray(img.convert("RGBA"), dtype=np.float32) / 255.0
    except Exception as exc:  # why: truncated or corrupt pixel data, in any decoder
        raise ReliefImageError(f"{label} cannot be decoded: {type(exc).__name__}: "
                               f"{shown(str(exc), 80)}") from None
    if px.shape[:2] != (h, w) or not np.all(np.isfinite(px)):
        raise ReliefImageError(f"{label} holds NaN or infinite texels")
    return np.ascontiguousarray(px)


_LOCK = threading.Lock()


def check_relief_image(name: str, data: bytes) -> None:
    """Raise :class:`ReliefImageError` unless ``data`` is a relief image glassbench can use."""
    key = hashlib.sha256(bytes(data)).hexdigest()
    with _LOCK:
        if key in _CHECKED:
            return
    read_relief_pixels(name, data)
    with _LOCK:
        _CHECKED[key] = True
        while len(_CHECKED) > 64:
            _CHECKED.popitem(last=False)


_CHECKED: OrderedDict = OrderedDict()
