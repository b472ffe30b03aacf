"""A tile's per-pixel results into the film's image-sized arrays, and a region back out as
display levels.

Design rule: the film (:class:`engine.tracer.film.Film`) holds ``(H, W, ...)`` arrays; a worker
hands it the results of a list of pixels. Written with numpy's fancy indexing this held the
GIL for about a tenth of a millisecond per tile (seven scatter operations and their index
arrays), long enough for the other worker to wait on it; these loops release it. The caller
holds the film's lock and has checked the pixels' bounds. Pixels in one call are distinct (a
tile's, or a relabel's). The window reads each finished tile back as sRGB levels
(:func:`estimate`, :func:`encode_srgb8`), about 2000 tiles an edit on the GUI thread.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .jit import JIT

#: Depth recorded for a material a pixel's tree never met (the film's ``uint8`` records).
NEVER = 255


@njit(**JIT)
def _records(objects, depth, cols, rows, mask, dep):
    """OR the object masks and min the per-material depths (capped at :data:`NEVER`)."""
    for p in range(cols.shape[0]):
        y, x = rows[p], cols[p]
        objects[y, x] |= mask[p]
        for m in range(depth.shape[2]):
            d = min(dep[p, m], NEVER)
            if d < depth[y, x, m]:
                depth[y, x, m] = d


@njit(**JIT)
def add_centres(centre, has_centre, signature, objects, depth, cols, rows, sums, sig, mask, dep):
    """Store the centre samples (``sums`` ``(P, 3)`` radiance, ``sig`` signatures) of pixels
    ``(cols[p], rows[p])`` and their records."""
    for p in range(cols.shape[0]):
        y, x = rows[p], cols[p]
        for c in range(3):
            centre[y, x, c] = sums[p, c]
        has_centre[y, x] = True
        signature[y, x] = sig[p]
    _records(objects, depth, cols, rows, mask, dep)


@njit(**JIT)
def add_samples(aa_sum, aa_sumsq, aa_count, objects, depth, cols, rows, count, sums, sumsq, mask, dep):
    """Add ``count[p]`` anti-aliasing samples' sums (``sums`` ``(P, 3)``, ``sumsq`` ``(P,)``)
    to pixels ``(cols[p], rows[p])`` and their records."""
    for p in range(cols.shape[0]):
        y, x = rows[p], cols[p]
        for c in range(3):
            aa_sum[y, x, c] += sums[p, c]
        aa_sumsq[y, x] += sumsq[p]
        aa_count[y, x] += count[p]
    _records(objects, depth, cols, rows, mask, dep)


@njit(**JIT)
def estimate(centre, has_centre, aa_sum, aa_count, preview, y0, y1, x0, x1, out):
    """The film's current estimate of pixels ``[y0, y1) x [x0, x1)`` into ``out`` (float32
    ``(y1 - y0, x1 - x0, 3)``): the anti-aliasing mean, else the centre, else the preview;
    NaN and infinities 0, values clipped to float32's range (:meth:`engine.tracer.film.Film.image`)."""
    top = 3.4028234663852886e38  # float32's largest
    for y in range(y0, y1):
        for x in range(x0, x1):
            n = aa_count[y, x]
            for c in range(3):
                if n > 0:
                    v = aa_sum[y, x, c] / n
                elif has_centre[y, x]:
                    v = centre[y, x, c]
                else:
                    v = preview[y, x, c]
                if v != v or v == np.inf or v == -np.inf:
                    v = 0.0
                out[y - y0, x - x0, c] = min(max(v, 0.0), top)


@njit(**JIT)
def encode_srgb8(image, thresholds, out):
    """8-bit display levels of a float32 image: level ``k`` is the number of ``thresholds`` (the
    smallest float32 value of each level 1..255, ascending) at or below the value, so it equals
    :func:`engine.color.tonemap_srgb8` wherever that is monotone (everywhere); NaN is 0."""
    for y in range(image.shape[0]):
        for x in range(image.shape[1]):
            for c in range(3):
                v = image[y, x, c]
                lo, hi = 0, thresholds.shape[0]
                if v == v:
                    while lo < hi:  # first threshold above v
                        m = (lo + hi) // 2
                        if thresholds[m] <= v:
                            lo = m + 1
                        else:
                            hi = m
                out[y, x, c] = lo
