"""Progressive, tiled, cancellable render job: the API the GUI and the CLI drive.

Design rule: a :class:`RenderJob` renders one frozen ``Design`` snapshot in waves, coarse to
fine: (0) a low-resolution preview (one ray per block, replicated over the block), (1) every
pixel at 1 sample, (2) every pixel up to ``spp`` samples in doubling steps, (3) adaptive rounds
that give extra samples (up to ``ADAPTIVE_FACTOR x spp``) to the pixels whose own samples show
noise above ``NOISE_TARGET`` of the image level. Each wave is split into tiles traced by a pool of
worker threads (embreex and numpy release the GIL); waves are separated by a barrier. Sample k
of a pixel is seeded by (pixel, k) and each pixel gets one addition per wave, so the image is
bit-identical for any thread count and tile order. ``cancel()`` sets a flag that every tile
checks before it starts, so a job stops within one tile.

Threading contract: ``on_tile(job, tile)`` and ``on_done(job)`` run on worker threads; GUI
code must marshal to its own thread. ``image()`` and ``progress`` may be read at any time.
"""
from __future__ import annotations

import math
import os
import random
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .integrator import TraceStats
from .tiles import RenderContext, trace_tile_samples

#: Adaptive rounds may raise a pixel to at most this many times ``spp`` samples.
ADAPTIVE_FACTOR = 16
#: Adaptive sampling aims at a per-pixel standard error below this fraction of the mean image level.
NOISE_TARGET = 0.01
#: Adaptive rounds after the uniform waves (each re-estimates the noise and may quadruple the cap).
ADAPTIVE_ROUNDS = 2


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
        Override ``design.render`` (pixels; samples per pixel every pixel gets).
    threads : int, optional
        Worker threads (default: CPU count, at most 8).
    tile : int
        Tile edge in pixels.
    on_tile, on_done : callable, optional
        ``on_tile(job, tile)`` after each tile, ``on_done(job)`` once when the job stops
        (finished, cancelled or failed); both on worker threads.
    adaptive : bool
        Add the adaptive rounds after the uniform ``spp`` waves (needs ``spp >= 4``).
    noise_target : float
        Adaptive rounds stop adding samples to a pixel once its estimated standard error is
        below this fraction of the mean image level.
    """

    def __init__(self, design, assets=None, *, width=None, height=None, spp=None, threads=None,
                 tile=32, on_tile=None, on_done=None, adaptive=True, noise_target=NOISE_TARGET,
                 _tile_shuffle_seed=None):
        self.design = design
        self.assets = assets
        self.width = int(width or design.render.width)
        self.height = int(height or design.render.height)
        self.spp = max(1, int(spp or design.render.spp))
        self.threads = max(1, int(threads or min(os.cpu_count() or 1, 8)))
        self.tile = max(1, int(tile))
        self.on_tile = on_tile
        self.on_done = on_done
        self.adaptive = bool(adaptive) and self.spp >= 4
        self.noise_target = float(noise_target)
        self.stats = TraceStats()
        self.error = None
        self._shuffle = _tile_shuffle_seed
        self._cancel = threading.Event()
        self._finished = threading.Event()
        self._lock = threading.Lock()
        h, w = self.height, self.width
        self._sum = np.zeros((h, w, 3))
        self._sumsq = np.zeros((h, w))
        self._count = np.zeros((h, w), dtype=np.int64)
        self._preview = np.zeros((h, w, 3))
        self._units_done = 0
        self._units_total = 1
        self._thread = None
        self.seconds = None

    # ------------------------------------------------------------------ public API
    def start(self) -> "RenderJob":
        """Start rendering in the background; returns ``self``. Call once."""
        if self._thread is not None:
            raise RuntimeError("a RenderJob can be started only once")
        self._thread = threading.Thread(target=self._run, name="RenderJob", daemon=True)
        self._thread.start()
        return self

    def cancel(self) -> None:
        """Ask the job to stop; running tiles finish, no new tile starts."""
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
        """Fraction of the planned tile work done, in [0, 1]; 1 when finished."""
        with self._lock:
            return min(1.0, self._units_done / max(self._units_total, 1))

    def image(self) -> np.ndarray:
        """The current estimate, ``(H, W, 3)`` float32 linear radiance (a copy, always finite).

        Pixels without a full-resolution sample yet show the preview wave's block value.
        """
        with self._lock:
            n = self._count
            img = np.where((n > 0)[..., None], self._sum / np.maximum(n, 1)[..., None], self._preview)
        return np.nan_to_num(img, nan=0.0, posinf=0.0, neginf=0.0).astype(np.float32)

    def sample_counts(self) -> np.ndarray:
        """Samples traced per pixel so far, ``(H, W)`` int (a copy)."""
        with self._lock:
            return self._count.copy()

    # ------------------------------------------------------------------ internals
    def _tiles(self):
        t = self.tile
        tiles = [(x, y, min(x + t, self.width), min(y + t, self.height))
                 for y in range(0, self.height, t) for x in range(0, self.width, t)]
        if self._shuffle is not None:
            random.Random(self._shuffle).shuffle(tiles)
        return tiles

    def _plan(self):
        """Uniform waves as (first sample, samples) pairs: 1, then doubling up to spp."""
        steps, have, step = [(0, 1)], 1, 1
        while have < self.spp:
            step = min(max(step * 2, have), self.spp - have)
            steps.append((have, step))
            have += step
        return steps

    def _run(self) -> None:
        import time

        t0 = time.perf_counter()
        try:
            ctx = RenderContext.from_design(self.design, self.assets, self.width, self.height)
            tiles = self._tiles()
            uniform = self._plan()
            n_waves = 1 + len(uniform) + (ADAPTIVE_ROUNDS if self.adaptive else 0)
            with self._lock:
                self._units_total = n_waves * len(tiles)
            with ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="render") as pool:
                self._wave(pool, tiles, 0, lambda tl: self._preview_tile(ctx, tl))
                for wave, (first, n) in enumerate(uniform, start=1):
                    self._wave(pool, tiles, wave, lambda tl, f=first, c=n: self._uniform_tile(ctx, tl, f, c))
                for r in range(ADAPTIVE_ROUNDS if self.adaptive else 0):
                    cap = int(round(self.spp * ADAPTIVE_FACTOR ** ((r + 1) / ADAPTIVE_ROUNDS)))
                    target = self._adaptive_targets(cap)
                    self._wave(pool, tiles, 1 + len(uniform) + r,
                               lambda tl, tg=target: self._adaptive_tile(ctx, tl, tg))
        except BaseException as exc:  # reported, never swallowed
            self.error = exc
            self._cancel.set()
        finally:
            self.seconds = time.perf_counter() - t0
            if self.error is None and not self._cancel.is_set():
                with self._lock:
                    self._units_done = self._units_total
            self._finished.set()
            if self.on_done is not None:
                try:
                    self.on_done(self)
                except Exception as exc:  # a failing callback is an error of the job
                    if self.error is None:
                        self.error = exc

    def _wave(self, pool, tiles, wave, work) -> None:
        if self._cancel.is_set():
            return

        def run(tl):
            if self._cancel.is_set():
                return
            work(tl)
            with self._lock:
                self._units_done += 1
            if self.on_tile is not None:
                self.on_tile(self, Tile(*tl, wave))

        futures = [pool.submit(run, tl) for tl in tiles]
        first_error = None
        for f in futures:
            exc = f.exception()
            if exc is not None and first_error is None:
                first_error = exc
                self._cancel.set()
        if first_error is not None:
            raise first_error

    def _block(self) -> int:
        return max(2, 2 ** int(math.log2(max(2, max(self.width, self.height) // 48))))

    def _preview_tile(self, ctx, tl) -> None:
        x0, y0, x1, y1 = tl
        b = self._block()
        ys, xs = np.mgrid[y0:y1:b, x0:x1:b]
        cols = np.minimum(xs + b // 2, x1 - 1).ravel()
        rows = np.minimum(ys + b // 2, y1 - 1).ravel()
        st = TraceStats()
        sums, _ = trace_tile_samples(ctx, cols, rows, np.zeros(len(cols)), np.ones(len(cols)), st)
        block = sums.reshape(ys.shape + (3,))
        full = np.repeat(np.repeat(block, b, axis=0), b, axis=1)[: y1 - y0, : x1 - x0]
        with self._lock:
            self._preview[y0:y1, x0:x1] = full
            self.stats.add(st)

    def _uniform_tile(self, ctx, tl, first, n) -> None:
        x0, y0, x1, y1 = tl
        ys, xs = np.mgrid[y0:y1, x0:x1]
        cnt = np.full(xs.size, n)
        self._add(ctx, tl, xs.ravel(), ys.ravel(), np.full(xs.size, first), cnt)

    def _adaptive_tile(self, ctx, tl, target) -> None:
        x0, y0, x1, y1 = tl
        ys, xs = np.mgrid[y0:y1, x0:x1]
        with self._lock:
            have = self._count[y0:y1, x0:x1].ravel().copy()
        extra = np.maximum(target[y0:y1, x0:x1].ravel() - have, 0)
        if np.any(extra):
            self._add(ctx, tl, xs.ravel(), ys.ravel(), have, extra)

    def _add(self, ctx, tl, cols, rows, first, count) -> None:
        x0, y0, x1, y1 = tl
        st = TraceStats()
        sums, sumsq = trace_tile_samples(ctx, cols, rows, first, count, st)
        shape = (y1 - y0, x1 - x0)
        with self._lock:
            self._sum[y0:y1, x0:x1] += sums.reshape(shape + (3,))
            self._sumsq[y0:y1, x0:x1] += sumsq.reshape(shape)
            self._count[y0:y1, x0:x1] += np.asarray(count).reshape(shape)
            self.stats.add(st)

    def _adaptive_targets(self, cap: int) -> np.ndarray:
        """Samples each pixel should reach: its noise (from its own samples) over the target."""
        with self._lock:
            n = np.maximum(self._count, 1).astype(float)
            mean_lum = self._sum.mean(axis=2) / n
            var = np.maximum(self._sumsq / n - mean_lum ** 2, 0.0) * n / np.maximum(n - 1, 1)
            level = max(float(mean_lum.mean()), 1e-6)
            have = self._count.copy()
        want = np.ceil(var / (self.noise_target * level) ** 2)
        return np.clip(want, have, cap).astype(np.int64)


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
