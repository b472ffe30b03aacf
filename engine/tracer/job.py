"""Progressive, tiled, cancellable render job: the API the GUI, the CLI and batches drive.

Design rule: a :class:`RenderJob` renders one frozen ``Design`` snapshot in waves; the waves'
content comes from :mod:`engine.tracer.adaptive` (what to trace), the samples from
:func:`engine.tracer.context.trace_pixels` (compiled, GIL-free) and the accumulation from
:class:`engine.tracer.film.Film`. Waves: (0) a preview, the centres of coarse blocks; (1) every
other pixel's centre; (2...) stratified anti-aliasing samples for the pixels on edges, in
doubling rounds up to ``spp``; then adaptive rounds for the edge pixels whose own samples still
scatter (up to ``ADAPTIVE_FACTOR x spp``). Each wave is cut into tiles traced by a pool of worker
threads, waves are separated by a barrier, and a pixel's samples are seeded by (pixel, sample),
so the image is bit-identical for any thread count and tile order. ``cancel()`` raises a flag
the kernels poll between pixels: a job stops within one pixel's work.

Threading contract: ``on_tile(job, tile)`` and ``on_done(job)`` run on worker threads; GUI code
must marshal to its own thread. ``image()``, ``progress`` and ``sample_counts()`` may be read
at any time. A job started with ``previous=`` and ``changed=`` (the design fields an edit
changed) reuses the previous film when nothing it renders changed.
"""
from __future__ import annotations

import os
import random
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from . import adaptive
from .context import RenderContext, TraceStats, trace_pixels
from .film import Film

NOISE_TARGET = adaptive.NOISE_TARGET
#: Design fields the image depends on (an edit of any other field keeps the film).
VISUAL_FIELDS = frozenset({"shape", "glass", "liquid", "camera", "environment", "render", "assets",
                           "bumps", "cap", "lights"})


@dataclass(frozen=True)
class Tile:
    """A finished piece of work: pixels ``[x0, x1) x [y0, y1)`` of wave ``wave`` (0 = preview)."""

    x0: int
    y0: int
    x1: int
    y1: int
    wave: int


class RenderJob:
    """Render ``design`` progressively on worker threads.

    Parameters
    ----------
    design : engine.model.design.Design
        The frozen snapshot to render; never mutated.
    assets : mapping, optional
        Project assets (environment image bytes / paths / arrays by name).
    width, height, spp : int, optional
        Override ``design.render`` (pixels; anti-aliasing samples per edge pixel).
    threads : int, optional
        Worker threads (default: the CPUs this process may use, at most 8).
    tile : int
        Tile edge in pixels.
    on_tile, on_done : callable, optional
        ``on_tile(job, tile)`` after each tile, ``on_done(job)`` once when the job stops
        (finished, cancelled or failed); both on worker threads.
    adaptive : bool
        Add the adaptive rounds after the uniform anti-aliasing rounds.
    noise_target : float
        Adaptive rounds stop adding samples to a pixel once its standard error is below this
        fraction of the design's reference level (the environment's mean radiance).
    previous : RenderJob, optional; changed : set of str, optional
        The job this one replaces and the design fields that changed since: when none of
        :data:`VISUAL_FIELDS` changed and the previous job finished at the same size, its film
        is kept and this job is done at once.
    """

    def __init__(self, design, assets=None, *, width=None, height=None, spp=None, threads=None,
                 tile=32, on_tile=None, on_done=None, adaptive=True, noise_target=NOISE_TARGET,
                 previous=None, changed=None, _tile_shuffle_seed=None):
        self.design = design
        self.assets = assets
        self.width = int(width or design.render.width)
        self.height = int(height or design.render.height)
        self.spp = max(1, int(spp or design.render.spp))
        if threads is None:
            cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
            threads = min(cpus, 8)
        self.threads = max(1, int(threads))
        self.tile = max(1, int(tile))
        self.on_tile = on_tile
        self.on_done = on_done
        self.adaptive = bool(adaptive)
        self.noise_target = float(noise_target)
        self.stats = TraceStats()
        self.error = None
        self.seconds = None
        self.first_tile_seconds = None
        #: ``(wave, pixels, samples, seconds)`` per wave traced (benchmarks, the status bar)
        self.wave_log = []
        self.film = Film(self.width, self.height)
        self._previous = previous
        self._changed = None if changed is None else frozenset(changed)
        self._shuffle = _tile_shuffle_seed
        self._cancel_flag = np.zeros(1, np.int64)
        self._cancel = threading.Event()
        self._finished = threading.Event()
        self._lock = threading.Lock()
        self._progress = 0.0
        self._thread = None
        self._t0 = None

    # ------------------------------------------------------------------ public API
    def start(self) -> "RenderJob":
        """Start rendering in the background; returns ``self``. Call once."""
        if self._thread is not None:
            raise RuntimeError("a RenderJob can be started only once")
        self._t0 = time.perf_counter()
        self._thread = threading.Thread(target=self._run, name="RenderJob", daemon=True)
        self._thread.start()
        return self

    def cancel(self) -> None:
        """Ask the job to stop: the kernels stop at the next pixel, no new tile starts."""
        self._cancel_flag[0] = 1
        self._cancel.set()

    def wait(self, timeout=None) -> bool:
        """Block until the job stops or ``timeout`` seconds pass; True when it has stopped."""
        return self._finished.wait(timeout)

    @property
    def done(self) -> bool:
        """True once the job has stopped (finished, cancelled or failed)."""
        return self._finished.is_set()

    @property
    def cancelled(self) -> bool:
        """True once ``cancel()`` was called."""
        return self._cancel.is_set()

    @property
    def progress(self) -> float:
        """Fraction of the work done, in [0, 1] (monotone); 1 when finished."""
        with self._lock:
            return self._progress

    def image(self) -> np.ndarray:
        """The current estimate, ``(H, W, 3)`` float32 linear radiance (a copy, always finite)."""
        return self.film.image()

    def sample_counts(self) -> np.ndarray:
        """Samples that make each pixel's value so far, ``(H, W)`` int (a copy)."""
        return self.film.samples()

    # ------------------------------------------------------------------ internals
    def _reusable(self) -> bool:
        prev = self._previous
        return (prev is not None and self._changed is not None and not (self._changed & VISUAL_FIELDS)
                and prev.done and prev.error is None and not prev.cancelled
                and (prev.width, prev.height, prev.spp) == (self.width, self.height, self.spp))

    def _tiles(self):
        t = self.tile
        tiles = [(x, y, min(x + t, self.width), min(y + t, self.height))
                 for y in range(0, self.height, t) for x in range(0, self.width, t)]
        if self._shuffle is not None:
            random.Random(self._shuffle).shuffle(tiles)
        return tiles

    def _set_progress(self, value: float) -> None:
        if self._cancel.is_set():  # skipped waves are not progress
            return
        with self._lock:
            self._progress = max(self._progress, min(1.0, float(value)))

    def _run(self) -> None:
        try:
            if self._reusable():
                self.film = self._previous.film
                self.stats = self._previous.stats
            else:
                self._render()
        except BaseException as exc:  # reported, never swallowed
            self.error = exc
            self.cancel()
        finally:
            self.seconds = time.perf_counter() - self._t0
            if self.error is None and not self._cancel.is_set():
                self._set_progress(1.0)
            self._finished.set()
            if self.on_done is not None:
                try:
                    self.on_done(self)
                except Exception as exc:  # a failing callback is an error of the job
                    if self.error is None:
                        self.error = exc

    def _render(self) -> None:
        ctx = RenderContext.from_design(self.design, self.assets, self.width, self.height)
        self.film = film = Film(self.width, self.height, ctx.n_materials)
        level = max(ctx.reference_level, 1e-6)
        tiles = self._tiles()
        h, w = self.height, self.width
        b = adaptive.preview_block(w, h)
        with ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="render") as pool:
            # (0) preview: the centre of every b x b block, painted over the block
            grid = np.zeros((h, w), bool)
            grid[np.minimum(np.arange(0, h, b) + b // 2, h - 1)[:, None],
                 np.minimum(np.arange(0, w, b) + b // 2, w - 1)[None, :]] = True
            self._wave(pool, ctx, tiles, 0, grid, None, preview=b)
            self._set_progress(0.03)
            # (1) every other centre
            self._wave(pool, ctx, tiles, 1, ~grid, None)
            self._set_progress(0.35)
            # (2...) anti-aliasing on edges: uniform rounds, then (adaptive) where samples scatter
            edges = adaptive.edge_mask(film.luminance(), film.signature, level)
            plan = adaptive.plan(self.spp, self.adaptive)
            for r, (target, varied) in enumerate(plan):
                if varied:
                    want = adaptive.noise_targets(film, target, self.noise_target, level)
                else:
                    want = np.where(edges, target, 0)
                mask = want > film.aa_count
                if not mask.any():
                    break
                self._wave(pool, ctx, tiles, 2 + r, mask, want, roulette=adaptive.ROULETTE if varied else 0.0)
                self._set_progress(0.35 + 0.65 * (r + 1) / len(plan))

    def _wave(self, pool, ctx, tiles, wave, mask, want, preview=None, roulette=0.0) -> None:
        """Trace the pixels of ``mask``: their centres (``want`` None) or anti-aliasing samples
        up to ``want``; one task per tile, all finished before this returns."""
        if self._cancel.is_set():
            return
        film = self.film
        t_wave = time.perf_counter()
        pixels = int(np.count_nonzero(mask))
        samples = pixels if want is None else int(np.sum(np.where(mask, want - film.aa_count, 0)))

        def run(tl):
            x0, y0, x1, y1 = tl
            if self._cancel.is_set():
                return
            ys, xs = np.nonzero(mask[y0:y1, x0:x1])
            if not len(xs):
                return
            rows, cols = ys + y0, xs + x0
            if want is None:
                res = trace_pixels(ctx, cols, rows, 0, 1, cancel=self._cancel_flag)
                if res.finished < len(cols):
                    return
                film.add_centre(cols, rows, res)
                if preview is not None:
                    for c, r, v in zip(cols, rows, res.sums):
                        by, bx = (r // preview) * preview, (c // preview) * preview
                        film.set_preview(by, min(by + preview, y1), bx, min(bx + preview, x1), v)
            else:
                have = film.aa_count[rows, cols]
                count = want[rows, cols] - have
                res = trace_pixels(ctx, cols, rows, have + 1, count, cancel=self._cancel_flag, roulette=roulette)
                if res.finished < len(cols):
                    return
                film.add_aa(cols, rows, count, res)
            with self._lock:
                self.stats.add_counters(res.counters)
                if self.first_tile_seconds is None:
                    self.first_tile_seconds = time.perf_counter() - self._t0
            if self.on_tile is not None:
                self.on_tile(self, Tile(x0, y0, x1, y1, wave))

        futures = [pool.submit(run, tl) for tl in tiles]
        first_error = None
        for f in futures:
            exc = f.exception()
            if exc is not None and first_error is None:
                first_error = exc
                self.cancel()
        if first_error is not None:
            raise first_error
        self.wave_log.append((wave, pixels, samples, time.perf_counter() - t_wave))


def render_image(design, assets=None, **kw) -> np.ndarray:
    """Render to completion and return ``(H, W, 3)`` float32 linear radiance.

    Keyword arguments are those of :class:`RenderJob`. Raises the worker's exception if a tile
    failed.
    """
    job = RenderJob(design, assets, **kw).start()
    job.wait()
    if job.error is not None:
        raise job.error
    return job.image()


def tonemap_srgb8(image) -> np.ndarray:
    """Display encoding: exposure 1, clamp to [0, 1], sRGB transfer curve, ``uint8`` (H, W, 3)."""
    x = np.clip(np.nan_to_num(np.asarray(image, dtype=np.float64), nan=0.0), 0.0, 1.0)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
    return np.clip(np.round(srgb * 255.0), 0, 255).astype(np.uint8)
