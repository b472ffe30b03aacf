"""Where samples go: the progressive plan and the anti-aliasing policy of a render.

Design rule: smooth glass traced Whitted-style has no noise; a pixel's only error is its
footprint, which matters where the image has edges. So every pixel gets its centre sample, and
only pixels that differ from a neighbour (another dominant path, or a radiance step above the
contrast threshold) get stratified anti-aliasing samples, then more where their own samples
still scatter. Every decision here is a pure function of the film after a wave, and every
threshold is local to a pixel or fixed per design (the environment's mean radiance, never the
image's), so a pixel's samples do not depend on thread count, tile order, or on what an edit
changed elsewhere in the image.
"""
from __future__ import annotations

import numpy as np

#: First anti-aliasing round: samples every edge pixel gets.
FIRST_AA = 4
#: Relative radiance step between neighbouring centres that marks an edge.
CONTRAST = 0.04
#: Adaptive rounds raise a pixel to at most this many times ``spp`` samples.
ADAPTIVE_FACTOR = 16
ADAPTIVE_ROUNDS = 2
#: Default target: per-pixel standard error below this fraction of the design's reference level.
NOISE_TARGET = 0.01


def preview_block(width: int, height: int) -> int:
    """Edge (px) of the preview wave's blocks: about 48 blocks across the longer side."""
    return max(2, 2 ** int(np.log2(max(2, max(width, height) // 48))))


def _neighbour_max(a, op):
    """Per pixel, ``op`` of ``a`` with each of its 8 neighbours (edges replicate)."""
    p = np.pad(a, 1, mode="edge")
    h, w = a.shape
    out = np.zeros(a.shape, bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dy or dx:
                out |= op(a, p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w])
    return out


def edge_mask(centre_lum, signature, level: float) -> np.ndarray:
    """Pixels whose centre differs from a neighbour's: another dominant path, or a luminance
    step above ``CONTRAST`` of the larger (plus a floor of 1 % of ``level``)."""
    floor = 0.01 * level
    step = _neighbour_max(centre_lum, lambda a, b: np.abs(a - b) > CONTRAST * np.maximum(a, b) + floor)
    path = _neighbour_max(signature, lambda a, b: a != b)
    return step | path


def noise_targets(film, cap: int, noise_target: float, level: float) -> np.ndarray:
    """Samples each anti-aliased pixel should reach so that its standard error falls below
    ``noise_target x level``: ``n = var / (target level)^2``, at least what it has, at most
    ``cap``; 0 for pixels without anti-aliasing samples."""
    with film.lock:
        n = film.aa_count.astype(float)
        have = film.aa_count.copy()
        mean = film.aa_sum.mean(axis=2) / np.maximum(n, 1)
        var = np.maximum(film.aa_sumsq / np.maximum(n, 1) - mean ** 2, 0.0) * n / np.maximum(n - 1, 1)
    want = np.ceil(var / (noise_target * level) ** 2)
    return np.where(have > 0, np.clip(want, have, cap), 0).astype(np.int64)


def uniform_steps(spp: int):
    """Anti-aliasing sample counts per round up to ``spp``: 4, then doubling (4, 8, 16, ...)."""
    steps, have = [], 0
    nxt = min(FIRST_AA, spp)
    while have < spp:
        steps.append(nxt)
        have = nxt
        nxt = min(spp, 2 * have)
    return steps
