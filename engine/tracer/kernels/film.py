"""A tile's per-pixel results into the film's image-sized arrays.

Design rule: the film (:class:`engine.tracer.film.Film`) holds ``(H, W, ...)`` arrays; a worker
hands it the results of a list of pixels. Written with numpy's fancy indexing this held the
GIL for about a tenth of a millisecond per tile (seven scatter operations and their index
arrays), long enough for the other worker to wait on it; these loops release it. The caller
holds the film's lock. Pixels in one call are distinct (a tile's, or a relabel's).
"""
from __future__ import annotations

from numba import njit

from .roots import JIT

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
