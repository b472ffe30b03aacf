"""Colour encodings: the sRGB curve both ways, the display encoding of a render, hex colours.

Design rule: the sRGB curve (IEC 61966-2-1) is written once, here (:func:`_encode`,
:func:`_decode`), and everything that converts colours calls it: what a screen shows of a linear
render (exposure 1, clamp to [0, 1], the curve: :func:`srgb_encode`, :func:`tonemap_srgb8`), the
window's noise criterion (:mod:`engine.tracer.adaptive`, which needs the curve's slope,
:func:`display_slope`), artwork decoded to linear RGBA and region keys matched in sRGB
(:func:`srgb_to_linear`, :func:`linear_to_srgb`, in float32 as the artwork is stored) and the
colours a designer types and reads (:func:`hex_to_linear`, :func:`linear_to_hex`). So the 8-bit
images the window and the PNG writers produce, the noise criterion and the colour pickers can
never disagree. No imports but numpy: every package may use it.
"""
from __future__ import annotations

import numpy as np

#: Linear value (0..1) below which the sRGB curve is the straight line ``12.92 x``.
SRGB_KNEE = 0.0031308


#: sRGB value (0..1) below which the decoding curve is the straight line ``v / 12.92``.
SRGB_DECODE_KNEE = 0.04045


def _encode(x):
    """The sRGB encoding curve on linear values ``x`` in [0, 1], in ``x``'s own float type."""
    return np.where(x <= SRGB_KNEE, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def _decode(v):
    """The sRGB decoding curve on values ``v`` in [0, 1], in ``v``'s own float type."""
    return np.where(v <= SRGB_DECODE_KNEE, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def srgb_encode(value) -> np.ndarray:
    """Display value in [0, 1] (float64) of linear radiance ``value``: clamped, then sRGB;
    NaN shows black."""
    return _encode(np.clip(np.nan_to_num(np.asarray(value, dtype=np.float64), nan=0.0), 0.0, 1.0))


def srgb_to_linear(v) -> np.ndarray:
    """Linear float32 of sRGB values ``v`` in [0, 1] (artwork texels, picked colours)."""
    return _decode(np.asarray(v, np.float32)).astype(np.float32)


def linear_to_srgb(v) -> np.ndarray:
    """sRGB float32 in [0, 1] of linear values ``v`` (clamped to [0, 1] first)."""
    return _encode(np.clip(np.asarray(v, np.float32), 0.0, 1.0)).astype(np.float32)


def hex_to_linear(text: str):
    """Linear RGB (float64, rounded to 6 decimals) of ``'#rrggbb'`` or ``'rrggbb'`` (sRGB), or
    ``None`` when ``text`` is not such a colour."""
    s = str(text).strip()
    s = s[1:] if s.startswith("#") else s
    if len(s) != 6 or any(c not in "0123456789abcdefABCDEF" for c in s):
        return None
    srgb = np.array([int(s[i:i + 2], 16) / 255.0 for i in (0, 2, 4)])
    return tuple(round(float(c), 6) for c in _decode(srgb))


def linear_to_hex(rgb) -> str:
    """``'#rrggbb'`` (sRGB, 8 bits a channel) of linear RGB ``rgb`` (clamped to 0..1): the
    colour :func:`hex_to_linear` reads back, as a designer types it."""
    srgb = _encode(np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0))
    return "#" + "".join(f"{int(round(float(c) * 255.0)):02x}" for c in srgb)


def display_slope(value) -> np.ndarray:
    """d(display)/d(radiance) of :func:`srgb_encode` at linear ``value``; 0 at and above
    white, where the display clips."""
    v = np.asarray(value, dtype=float)
    slope = np.where(v <= SRGB_KNEE, 12.92, 1.055 / 2.4 * np.maximum(v, SRGB_KNEE) ** (1.0 / 2.4 - 1.0))
    return np.where(v >= 1.0, 0.0, slope)


def tonemap_srgb8(image) -> np.ndarray:
    """Display encoding of a linear image as ``uint8`` (H, W, 3): :func:`srgb_encode`, rounded."""
    return np.clip(np.round(srgb_encode(image) * 255.0), 0, 255).astype(np.uint8)


def _level_thresholds() -> np.ndarray:
    """For each display level 1..255 the smallest float32 radiance :func:`tonemap_srgb8` maps
    to it or above (binary search over the bit patterns of non-negative float32, which order
    as the values do): what the compiled encoder (:func:`engine.tracer.kernels.film.
    encode_srgb8`) counts, so it gives this module's levels bit for bit."""
    lo = np.zeros(255, np.int64)  # bit patterns: 0.0 maps to level 0, 1.0 to 255
    hi = np.full(255, np.float32(1.0).view(np.int32), np.int64)
    want = np.arange(1, 256)
    while np.any(hi - lo > 1):
        mid = (lo + hi) // 2
        level = tonemap_srgb8(mid.astype(np.int32).view(np.float32)[:, None])[:, 0]
        above = level >= want
        hi, lo = np.where(above, mid, hi), np.where(above, lo, mid)
    return hi.astype(np.int32).view(np.float32)


#: :func:`_level_thresholds`, computed once.
LEVEL_THRESHOLDS = _level_thresholds()
