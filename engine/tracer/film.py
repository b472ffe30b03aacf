"""The film: per-pixel accumulators and records of one progressive render.

Design rule: the film only accumulates; it never decides what to trace (that is
:mod:`engine.tracer.adaptive`) and never traces (:mod:`engine.tracer.context`). A pixel holds
its *centre* sample (sample 0, the midpoint estimate that smooth regions keep) apart from its
*anti-aliasing* samples (1, 2, ...; their mean replaces the centre once there are any), so an
edge pixel's value is an unbiased stratified average over its square while a smooth pixel costs
one ray. Beside radiance it keeps, per pixel, the dominant-path signature of the centre sample,
a bit mask of the render objects its ray tree met, and the shallowest tree depth at which each
material was met: what edge finding and re-rendering only what an edit touched need. It also
sums the denoiser's guides (albedo and normal, :func:`engine.tracer.kernels.integrator.
trace_sample`) over every sample traced; they never enter the image.
All arrays are owned by the film and changed only under its lock.
"""
from __future__ import annotations

import threading

import numpy as np

from ..color import LEVEL_THRESHOLDS
from .kernels.film import NEVER, add_centres, add_samples, encode_srgb8, estimate


def _c(a, dtype) -> np.ndarray:
    """``a`` as a C-contiguous array of ``dtype`` (no copy when it already is one)."""
    return np.ascontiguousarray(a, dtype=dtype)


def _index(a) -> np.ndarray:
    """Pixel coordinates as a flat int64 array."""
    return _c(np.asarray(a).ravel(), np.int64)


def _shaped(a, n: int, dtype, shape=()) -> np.ndarray:
    """``a`` as a C-contiguous ``(n, *shape)`` array of ``dtype``; ``ValueError`` if it is not
    that shape (the compiled loops check no bounds)."""
    a = _c(a, dtype)
    if a.shape != (n, *shape):
        raise ValueError(f"film: {a.shape} values for {n} pixels, expected {(n, *shape)}")
    return a


def guide_images(guide_sum, guide_n) -> tuple[np.ndarray, np.ndarray]:
    """``(albedo, normal)``, float32 ``(H, W, 3)`` each, from per-pixel guide sums ``(H, W, 6)``
    over ``guide_n`` ``(H, W)`` samples: their means (zero where none), albedo clipped to
    ``[0, 1]``, normals to ``[-1, 1]`` (not renormalised)."""
    g = guide_sum / np.maximum(guide_n, 1)[..., None]
    return (np.clip(g[..., :3], 0.0, 1.0).astype(np.float32),
            np.clip(g[..., 3:], -1.0, 1.0).astype(np.float32))


class Film:
    """Accumulators for an image of ``width x height`` pixels and ``n_materials`` materials."""

    def __init__(self, width: int, height: int, n_materials: int = 1):
        h, w = int(height), int(width)
        self.width, self.height = w, h
        self.lock = threading.Lock()
        self.centre = np.zeros((h, w, 3))
        self.has_centre = np.zeros((h, w), bool)
        self.aa_sum = np.zeros((h, w, 3))
        self.aa_sumsq = np.zeros((h, w))
        self.aa_count = np.zeros((h, w), np.int64)
        self.preview = np.zeros((h, w, 3))
        self.signature = np.zeros((h, w), np.uint64)
        self.objects = np.zeros((h, w), np.int64)
        self.depth = np.full((h, w, max(1, int(n_materials))), NEVER, np.uint8)
        self.guide_sum = np.zeros((h, w, 6))
        self.guide_n = np.zeros((h, w), np.int64)

    # ----------------------------------------------------------------- accumulation
    def add_centre(self, cols, rows, result) -> None:
        """Store centre samples (a :class:`~engine.tracer.context.PixelResult` of sample 0) of
        distinct pixels ``(cols[p], rows[p])``."""
        cols, rows = self._pixels(cols, rows)
        n, m = len(cols), self.depth.shape[2]
        sums, sig = _shaped(result.sums, n, np.float64, (3,)), _shaped(result.signature, n, np.uint64)
        objects, depth = _shaped(result.objects, n, np.int64), _shaped(result.depth, n, np.int64, (m,))
        with self.lock:  # (the kernel releases the GIL, not the lock)
            add_centres(self.centre, self.has_centre, self.signature, self.objects, self.depth, cols, rows,
                        sums, sig, objects, depth)
            self._add_guides(cols, rows, 1, result.guide)

    def add_aa(self, cols, rows, count, result) -> None:
        """Add ``count[p]`` anti-aliasing samples to distinct pixels ``(cols[p], rows[p])`` (a
        ``PixelResult`` of samples >= 1)."""
        cols, rows = self._pixels(cols, rows)
        n, m = len(cols), self.depth.shape[2]
        count = _shaped(np.broadcast_to(np.asarray(count, np.int64), cols.shape), n, np.int64)
        sums, sumsq = _shaped(result.sums, n, np.float64, (3,)), _shaped(result.sumsq, n, np.float64)
        objects, depth = _shaped(result.objects, n, np.int64), _shaped(result.depth, n, np.int64, (m,))
        with self.lock:
            add_samples(self.aa_sum, self.aa_sumsq, self.aa_count, self.objects, self.depth, cols, rows, count,
                        sums, sumsq, objects, depth)
            self._add_guides(cols, rows, count, result.guide)

    def _add_guides(self, cols, rows, count, guide) -> None:
        """Add the guide sums ``guide`` ``(P, 6)`` of ``count`` samples each to distinct pixels
        (under the lock; nothing for a result without guides, a relabel's)."""
        if guide is None:
            return
        self.guide_sum[rows, cols] += _shaped(guide, len(cols), np.float64, (6,))
        self.guide_n[rows, cols] += count

    def forget(self, mask) -> None:
        """Drop the anti-aliasing samples of the pixels of ``mask`` (``(H, W)`` bool): they show
        their centre again and leave the adaptive rounds (the samples only measured them:
        :func:`engine.tracer.adaptive.inner_steps`). What their trees met stays known."""
        with self.lock:
            self.aa_sum[mask] = 0.0
            self.aa_sumsq[mask] = 0.0
            self.aa_count[mask] = 0

    def _pixels(self, cols, rows) -> tuple:
        """Flat int64 pixel coordinates, checked against the film's size (``ValueError``)."""
        cols, rows = _index(cols), _index(rows)
        if cols.shape != rows.shape:
            raise ValueError(f"film: {cols.size} columns but {rows.size} rows")
        if cols.size and (min(cols.min(), rows.min()) < 0 or cols.max() >= self.width or rows.max() >= self.height):
            raise ValueError(f"film: a pixel outside the {self.width} x {self.height} image")
        return cols, rows

    def set_preview(self, y0, y1, x0, x1, block) -> None:
        """Fill ``[y0, y1) x [x0, x1)`` of the preview layer (shown until centres arrive)."""
        with self.lock:
            self.preview[y0:y1, x0:x1] = block

    def paint_preview(self, cols, rows, values, b: int, tile: int, region=None) -> None:
        """Paint each preview sample ``(cols[p], rows[p])`` (radiance ``values[p]``) over its
        ``b x b`` block, clipped to its ``tile x tile`` tile; ``region`` ``(y0, y1, x0, x1)``
        (pixels, half-open, as :meth:`image` takes it), tile-aligned, holds all the samples
        (default: the whole image)."""
        if tile % b:  # blocks may cross tiles: one block at a time
            for c, r, v in zip(cols, rows, values):
                by, bx = (r // b) * b, (c // b) * b
                x1 = min((c // tile + 1) * tile, self.width)  # the pixel's tile
                y1 = min((r // tile + 1) * tile, self.height)
                self.set_preview(by, min(by + b, y1), bx, min(bx + b, x1), v)
            return
        # blocks then never cross a tile: paint whole blocks, cut at the region's edge
        y0, y1, x0, x1 = region if region is not None else (0, self.height, 0, self.width)
        h, w = y1 - y0, x1 - x0
        grid = np.zeros((-(-h // b), -(-w // b), 3))
        have = np.zeros(grid.shape[:2], bool)
        grid[(rows - y0) // b, (cols - x0) // b] = values
        have[(rows - y0) // b, (cols - x0) // b] = True
        full = np.repeat(np.repeat(grid, b, 0), b, 1)[:h, :w]
        target = self.preview[y0:y1, x0:x1]
        if have.all():  # the usual case: every block's centre
            with self.lock:
                target[...] = full
            return
        on = np.repeat(np.repeat(have, b, 0), b, 1)[:h, :w]
        with self.lock:
            target[on] = full[on]

    # ----------------------------------------------------------------- reading
    def image(self, region=None) -> np.ndarray:
        """Current estimate float32 linear radiance: AA mean, else centre, else preview; always
        finite and >= 0 (a copy, read in compiled code under the lock). The whole ``(H, W, 3)``
        image, or only ``region = (y0, y1, x0, x1)`` (pixels, half-open, cut at the image's
        edges): the window repaints finished tiles many times a second."""
        y0, y1, x0, x1 = self._region(region)
        img = np.empty((y1 - y0, x1 - x0, 3), np.float32)
        with self.lock:
            estimate(self.centre, self.has_centre, self.aa_sum, self.aa_count, self.preview, y0, y1, x0, x1, img)
        return img

    def display(self, region) -> np.ndarray:
        """The display levels (sRGB ``uint8`` ``(h, w, 3)``, :func:`engine.color.
        tonemap_srgb8` of :meth:`image`, bit for bit) of ``region = (y0, y1, x0, x1)``: what the
        window paints as tiles finish, encoded in compiled code outside the lock."""
        img = self.image(region)
        out = np.empty(img.shape, np.uint8)
        encode_srgb8(img, LEVEL_THRESHOLDS, out)
        return out

    def _region(self, region) -> tuple:
        """``(y0, y1, x0, x1)`` of ``region`` (the whole image for ``None``) cut to the image."""
        if region is None:
            return 0, self.height, 0, self.width
        y0, y1, x0, x1 = (int(v) for v in region)
        y0, x0 = min(max(y0, 0), self.height), min(max(x0, 0), self.width)
        return y0, max(min(y1, self.height), y0), x0, max(min(x1, self.width), x0)

    def guides(self) -> tuple[np.ndarray, np.ndarray]:
        """The denoiser's guides ``(albedo, normal)``, float32 ``(H, W, 3)`` each: the mean over
        each pixel's traced samples (zero where none was traced). Albedo in ``[0, 1]``, normals
        in ``[-1, 1]`` (their mean, not renormalised: an edge pixel's is shorter)."""
        with self.lock:
            return guide_images(self.guide_sum, self.guide_n)

    def samples(self) -> np.ndarray:
        """Samples per pixel that make its value (the centre counts as one) ``(H, W)``."""
        with self.lock:
            return np.where(self.aa_count > 0, self.aa_count, self.has_centre.astype(np.int64))

    def mark(self):
        """``(luminance sums, sample counts)`` of the anti-aliasing samples so far, ``(H, W)``
        each (a copy): what the sampling policy compares a round's samples with."""
        with self.lock:
            return self.aa_sum.mean(axis=2), self.aa_count.copy()

    def luminance(self) -> np.ndarray:
        """Mean-of-RGB of the current estimate (float64 ``(H, W)``), for the sampling policy."""
        return self.image().astype(np.float64).mean(axis=2)
