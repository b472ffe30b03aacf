"""The film: per-pixel accumulators and records of one progressive render.

Design rule: the film only accumulates; it never decides what to trace (that is
:mod:`engine.tracer.adaptive`) and never traces (:mod:`engine.tracer.context`). A pixel holds
its *centre* sample (sample 0, the midpoint estimate that smooth regions keep) apart from its
*anti-aliasing* samples (1, 2, ...; their mean replaces the centre once there are any), so an
edge pixel's value is an unbiased stratified average over its square while a smooth pixel costs
one ray. Beside radiance it keeps, per pixel, the dominant-path signature of the centre sample,
a bit mask of the render objects its ray tree met, and the shallowest tree depth at which each
material was met: what edge finding and re-rendering only what an edit touched need.
All arrays are owned by the film and changed only under its lock.
"""
from __future__ import annotations

import threading

import numpy as np

from .display import LEVEL_THRESHOLDS
from .kernels.film import NEVER, add_centres, add_samples, encode_srgb8, estimate


def _c(a, dtype) -> np.ndarray:
    """``a`` as a C-contiguous array of ``dtype`` (no copy when it already is one)."""
    return np.ascontiguousarray(a, dtype=dtype)


def _index(a) -> np.ndarray:
    """Pixel coordinates as a flat int64 array."""
    return _c(np.asarray(a).ravel(), np.int64)


def _per_pixel(a, n: int, dtype, shape=()) -> np.ndarray:
    """``a`` as a C-contiguous ``(n, *shape)`` array of ``dtype``; ``ValueError`` if it is not
    that shape (the compiled loops check no bounds)."""
    a = _c(a, dtype)
    if a.shape != (n, *shape):
        raise ValueError(f"film: {a.shape} values for {n} pixels, expected {(n, *shape)}")
    return a


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

    # ----------------------------------------------------------------- accumulation
    def add_centre(self, cols, rows, result) -> None:
        """Store centre samples (a :class:`~engine.tracer.context.PixelResult` of sample 0) of
        distinct pixels ``(cols[p], rows[p])``."""
        cols, rows = self._pixels(cols, rows)
        n, m = len(cols), self.depth.shape[2]
        sums, sig = _per_pixel(result.sums, n, np.float64, (3,)), _per_pixel(result.signature, n, np.uint64)
        objects, depth = _per_pixel(result.objects, n, np.int64), _per_pixel(result.depth, n, np.int64, (m,))
        with self.lock:  # (the kernel releases the GIL, not the lock)
            add_centres(self.centre, self.has_centre, self.signature, self.objects, self.depth, cols, rows,
                        sums, sig, objects, depth)

    def add_aa(self, cols, rows, count, result) -> None:
        """Add ``count[p]`` anti-aliasing samples to distinct pixels ``(cols[p], rows[p])`` (a
        ``PixelResult`` of samples >= 1)."""
        cols, rows = self._pixels(cols, rows)
        n, m = len(cols), self.depth.shape[2]
        count = _per_pixel(np.broadcast_to(np.asarray(count, np.int64), cols.shape), n, np.int64)
        sums, sumsq = _per_pixel(result.sums, n, np.float64, (3,)), _per_pixel(result.sumsq, n, np.float64)
        objects, depth = _per_pixel(result.objects, n, np.int64), _per_pixel(result.depth, n, np.int64, (m,))
        with self.lock:
            add_samples(self.aa_sum, self.aa_sumsq, self.aa_count, self.objects, self.depth, cols, rows, count,
                        sums, sumsq, objects, depth)

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

    # ----------------------------------------------------------------- reading
    def image(self, region=None) -> np.ndarray:
        """Current estimate float32 linear radiance: AA mean, else centre, else preview; always
        finite and >= 0 (a copy). The whole ``(H, W, 3)`` image, or only ``region = (y0, y1, x0,
        x1)`` (pixels, half-open): the window repaints finished tiles many times a second, and a
        whole image each time held the film's lock, and the GUI thread, for 27 ms at 715 x 954."""
        ys, xs = (slice(None), slice(None)) if region is None else (slice(region[0], region[1]),
                                                                     slice(region[2], region[3]))
        with self.lock:
            n = self.aa_count[ys, xs]
            img = np.where((n > 0)[..., None], self.aa_sum[ys, xs] / np.maximum(n, 1)[..., None],
                           np.where(self.has_centre[ys, xs][..., None], self.centre[ys, xs], self.preview[ys, xs]))
        img = np.nan_to_num(img, nan=0.0, posinf=0.0, neginf=0.0)
        return np.clip(img, 0.0, np.finfo(np.float32).max).astype(np.float32)

    def display(self, region) -> np.ndarray:
        """The display levels (sRGB ``uint8`` ``(h, w, 3)``, :func:`engine.tracer.display.
        tonemap_srgb8` of :meth:`image`, bit for bit) of ``region = (y0, y1, x0, x1)``: what the
        window paints as tiles finish, in compiled loops that hold the lock (not the GIL) only
        while the estimate is read."""
        y0, y1, x0, x1 = (int(v) for v in region)
        y0, x0 = max(y0, 0), max(x0, 0)
        y1, x1 = max(min(y1, self.height), y0), max(min(x1, self.width), x0)
        img = np.empty((y1 - y0, x1 - x0, 3), np.float32)
        with self.lock:
            estimate(self.centre, self.has_centre, self.aa_sum, self.aa_count, self.preview, y0, y1, x0, x1, img)
        out = np.empty(img.shape, np.uint8)
        encode_srgb8(img, LEVEL_THRESHOLDS, out)
        return out

    def samples(self) -> np.ndarray:
        """Samples per pixel that make its value (the centre counts as one) ``(H, W)``."""
        with self.lock:
            return np.where(self.aa_count > 0, self.aa_count, self.has_centre.astype(np.int64))

    def luminance(self) -> np.ndarray:
        """Mean-of-RGB of the current estimate (float64 ``(H, W)``), for the sampling policy."""
        return self.image().astype(np.float64).mean(axis=2)
