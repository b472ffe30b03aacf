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

Threading contract: ``on_tile(job, tile)`` and ``on_done(job)`` run on worker threads,
``on_wave(job, wave)`` on the job's own thread between waves; GUI code must marshal to its own
thread. ``image()``, ``progress`` and ``sample_counts()`` may be read at any time. A job
started with ``previous=`` and ``changed=`` (the design fields an edit changed) reuses the
previous film when nothing it renders changed and it asks the same sampling.

Relabel: when only labels, lights (without a closure: they light its diffuse parts too) or
label images changed (every other field of the design equal, same size and sampling), the job
keeps the previous job's compiled scene (a label edit never rebuilds geometry, media or
environment: :meth:`RenderContext.with_labels`) and replays
the same waves: a pixel's traced samples are reused from the previous job's per-wave record
when the pixel is clean and the wave asks it for the same samples, and traced again otherwise.
A pixel is dirty when its ray trees (any sample, shadow rays included) consulted a label whose
artwork, finish or coefficients changed (the label bits of the object mask,
:mod:`engine.tracer.kernels.labels`), any label when lights changed, and every pixel whose
trees met the object a label lies on (the outer wall, or a closure part for a print on the cap)
before or after it moved, was added, removed or reordered (the new footprint may cover it). A
label whose edit changes its face colours only (artwork of the same size with the same alpha
channel and region map, everything else equal) leaves every ray tree as it was: its pixels are not traced but their label terms recomputed from the recorded hits
(:func:`engine.tracer.kernels.labels.replay_samples`). Since samples are seeded by (pixel,
sample) and the film is the same function of the traced results, the image equals a full render
of the new design bit for bit; a pixel the new image's sampling plan asks other samples of is
traced as in a full render. Records (per wave: each pixel's sums and records, each sample's
label hits) are kept only for designs with labels.
"""
from __future__ import annotations

import dataclasses
import itertools
import os
import random
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from . import adaptive
from .adaptive import NOISE_SPACES
from ..appearance.frame import Placement
from .context import PixelResult, RenderContext, TraceStats, trace_pixels
from ..color import tonemap_srgb8  # noqa: F401 - the encoding the callers of a job use
from .film import Film
from .kernels.integrator import N_COUNTERS
from ..model.design import LabelSide
from .kernels.labels import H_COLS, L_FRONT_TEX, L_REGION_MAP, LABEL_BIT0, MAX_LABEL_BIT, P_OBJECT, replay_samples
from .tables.labels import with_buffers

NOISE_TARGET = adaptive.NOISE_TARGET
#: Design fields the image depends on (an edit of any other field keeps the film).
VISUAL_FIELDS = frozenset({"shape", "glass", "liquid", "camera", "environment", "render", "assets",
                           "labels", "lights", "bumps", "cap"})
#: An anti-aliasing wave is cut into tasks of at most about 1 / (BALANCE x threads) of its
#: samples (:meth:`RenderJob._balanced`).
BALANCE = 4
#: Object-mask bits of all labels (engine.tracer.kernels.labels).
_ALL_LABEL_BITS = np.int64(sum(1 << b for b in range(LABEL_BIT0, MAX_LABEL_BIT + 1)))


def _label_bit(k: int) -> np.int64:
    return np.int64(1 << min(LABEL_BIT0 + k, MAX_LABEL_BIT))


def _object_bit(labels: tuple, k: int) -> np.int64:
    """The object-mask bit of the render object label ``k`` of the tables ``labels`` lies on."""
    return np.int64(1 << int(labels.place[k, P_OBJECT]))


def _placed(label) -> tuple:
    """What fixes where a label lies: its surface and the numbers that place it there."""
    return Placement.of(label), label.surface, label.cap_x_mm, label.cap_y_mm


@dataclass
class _WaveRecord:
    """The traced results of one wave, by pixel index ``row * width + col`` (sorted), and the
    label terms of their samples: pixel ``i``'s samples are ``smp_*[s0[i] : s0[i] + count[i]]``
    (``s0 = -1``: not recorded, the pixel can only be traced again; ``-2``: its samples had no
    label hits, its result does not depend on label colours)."""

    pix: np.ndarray
    first: np.ndarray
    count: np.ndarray
    sums: np.ndarray
    sumsq: np.ndarray
    signature: np.ndarray
    objects: np.ndarray
    depth: np.ndarray
    s0: np.ndarray
    smp_f: np.ndarray = None
    smp_i: np.ndarray = None
    hit_f: np.ndarray = None
    hit_i: np.ndarray = None

    PER_PIXEL = ("pix", "first", "count", "sums", "sumsq", "signature", "objects", "depth", "s0")

    @classmethod
    def join(cls, chunks) -> "_WaveRecord":
        if len(chunks) == 1 and (len(chunks[0].pix) < 2 or bool(np.all(np.diff(chunks[0].pix) > 0))):
            return chunks[0]  # a relabel that kept the whole wave: already a record
        s_off = h_off = 0
        s0, smp_f, smp_i, hit_f, hit_i = [], [], [], [], []
        for c in chunks:
            s0.append(np.where(c.s0 >= 0, c.s0 + s_off, c.s0))
            smp_f.append(c.smp_f)
            smp_i.append(c.smp_i + h_off)
            hit_f.append(c.hit_f)
            hit_i.append(c.hit_i)
            s_off += len(c.smp_f)
            h_off += len(c.hit_f)
        parts = {f: np.concatenate([getattr(c, f) for c in chunks]) for f in cls.PER_PIXEL[:-1]}
        parts["s0"] = np.concatenate(s0)
        order = np.argsort(parts["pix"], kind="stable")
        return cls(**{f: a[order] for f, a in parts.items()}, smp_f=np.concatenate(smp_f),
                   smp_i=np.concatenate(smp_i), hit_f=np.concatenate(hit_f), hit_i=np.concatenate(hit_i))

    def subset(self, idx, sums=None, sumsq=None) -> "_WaveRecord":
        """Pixels ``idx`` (their samples' arrays shared), optionally with new sums."""
        out = {f: getattr(self, f)[idx] for f in self.PER_PIXEL}
        if sums is not None:
            out["sums"], out["sumsq"] = sums, sumsq
        return _WaveRecord(**out, smp_f=self.smp_f, smp_i=self.smp_i, hit_f=self.hit_f, hit_i=self.hit_i)

    def result(self) -> PixelResult:
        return PixelResult(self.sums, self.sumsq, self.signature, self.objects, self.depth,
                           np.zeros(N_COUNTERS, np.int64), len(self.pix))


def _colour_only(a, b, k, prev, job, old_t, new_t) -> bool:
    """Whether label ``k`` changed from ``a`` to ``b`` in its face colours only (artwork of
    the same size with the same alpha, region maps equal, everything else equal): then every ray
    tree is the same and only the label terms change."""
    blank = LabelSide()
    if dataclasses.replace(a, front=blank, back=blank) != dataclasses.replace(b, front=blank, back=blank):
        return False
    pa, ja = prev.assets or {}, job.assets or {}
    for r in a.regions:
        if r.mask_asset is not None and not (pa.get(r.mask_asset) is ja.get(r.mask_asset)
                                             or pa.get(r.mask_asset) == ja.get(r.mask_asset)):
            return False

    def alpha(t):
        m = int(t.f[k, L_FRONT_TEX])
        if m < 0:
            return None
        first, w, h = t.tex_i[m]
        return (int(w), int(h)), t.texels[first:first + w * h, 3]

    def codes(t):
        q = int(t.f[k, L_REGION_MAP])
        if q < 0:
            return None
        first, w, h = t.region_i[q]
        return (int(w), int(h)), t.codes[first:first + w * h]

    for f in (alpha, codes):  # a plain front (no alpha) only matches a plain front
        x, y = f(old_t), f(new_t)
        if (x is None) != (y is None):
            return False
        if x is not None and (x[0] != y[0] or not np.array_equal(x[1], y[1])):
            return False
    return True


#: Samples whose label hits one job keeps for relabels (~40 bytes each, plus their hits); the
#: pixels beyond are traced again by a relabel instead of recomputed.
MAX_RECORDED_SAMPLES = 1 << 21
_NO_SAMPLES = (np.zeros((0, 3)), np.zeros((0, 2), np.int64), np.zeros((0, H_COLS)), np.zeros((0, 2), np.int64))


def _lights_shade(design) -> bool:
    """Whether ``design``'s lights light anything: its labels, or its closure's diffuse
    (plastic, cork) parts."""
    return bool(design.labels) or design.cap is not None


def _without_labels(design):
    return dataclasses.replace(design, labels=(), lights=(), name="", notes="")


def _label_assets_equal(old, new, old_assets, new_assets) -> bool:
    a, b = old_assets or {}, new_assets or {}
    return all(a.get(n) is b.get(n) or a.get(n) == b.get(n) for n in old.asset_names())


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
    on_wave : callable, optional
        ``on_wave(job, wave)`` on the job's thread after each wave that ran to its end, before
        the next starts: the film then holds exactly the samples of waves ``0..wave`` (the
        image a progressive view shows at that moment; benchmarks chart it against time).
    adaptive : bool
        Add the adaptive rounds after the uniform anti-aliasing rounds.
    noise_target : float
        Adaptive rounds stop adding samples to a pixel once its standard error is below this
        fraction of the design's reference level (the environment's mean radiance), or with
        ``noise_space="display"`` below this many display units once tone-mapped.
    noise_space : str
        "linear" (references, final renders) or "display" (the window:
        :data:`~engine.tracer.adaptive.DISPLAY_NOISE`): see :func:`adaptive.noise_targets`.
    previous : RenderJob, optional; changed : set of str, optional
        The job this one replaces and the design fields that changed since: when none of
        :data:`VISUAL_FIELDS` changed and the previous job finished at the same size and
        sampling (spp, adaptivity, noise target and space), its film is kept and this job is
        done at once.
    worker_nice : int
        Niceness added to each worker thread (Linux; ignored elsewhere): the window passes a
        positive value so that, with every core rendering, the scheduler still prefers its GUI
        thread. Never changes the image.
    """

    def __init__(self, design, assets=None, *, width=None, height=None, spp=None, threads=None,
                 tile=32, on_tile=None, on_done=None, on_wave=None, adaptive=True, noise_target=NOISE_TARGET,
                 noise_space="linear", previous=None, changed=None, worker_nice=0, _tile_shuffle_seed=None):
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
        self.on_wave = on_wave
        self.adaptive = bool(adaptive)
        self.noise_target = float(noise_target)
        if noise_space not in NOISE_SPACES:  # (the argument ``adaptive`` hides the module here)
            raise ValueError(f"noise_space must be 'linear' or 'display', not {noise_space!r}")
        self.noise_space = noise_space
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
        self.worker_nice = max(0, int(worker_nice))
        self._cancel_flag = np.zeros(1, np.int64)
        self._cancel = threading.Event()
        self._finished = threading.Event()
        #: set after ``on_done`` returned: what ``wait`` waits for, so that a caller who tears
        #: down what the callback touches (the window's signals) never races the callback
        self._returned = threading.Event()
        self._lock = threading.Lock()
        self._progress = 0.0
        self._thread = None
        self._t0 = None
        #: per wave, the traced results (designs with labels only; relabel reads them)
        self._records = {} if design.labels else None
        self._chunks = None
        self._recorded = 0
        self._ctx = None
        #: for a relabel: the previous job and the (H, W) mask of pixels to trace again
        self._reuse = None
        #: pixels a relabel traced again from the start / recomputed the label terms of (None:
        #: a full render or a kept film); pixels whose samples a new sampling plan asks for are
        #: traced on top of these
        self.relabelled_pixels = None
        self.recoloured_pixels = None

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
        """Block until the job stops and its ``on_done`` returned, or ``timeout`` seconds
        pass; True when it has stopped. (``done`` turns true before ``on_done`` runs, so the
        callback sees it; ``wait`` returns after, so nothing of the job runs any more.)"""
        return self._returned.wait(timeout)

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

    def image(self, region=None) -> np.ndarray:
        """The current estimate, ``(H, W, 3)`` float32 linear radiance (a copy, always finite),
        or only ``region = (y0, y1, x0, x1)`` of it (pixels, half-open)."""
        return self.film.image(region)

    def display(self, region) -> np.ndarray:
        """sRGB display levels ``(h, w, 3)`` uint8 of ``region = (y0, y1, x0, x1)`` of the current
        estimate (:func:`engine.color.tonemap_srgb8` of :meth:`image`): a finished tile
        as the window paints it."""
        return self.film.display(region)

    def sample_counts(self) -> np.ndarray:
        """Samples that make each pixel's value so far, ``(H, W)`` int (a copy)."""
        return self.film.samples()

    # ------------------------------------------------------------------ internals
    def _sampling(self) -> tuple:
        """What decides which samples the job traces, besides the design: two jobs with equal
        ``_sampling()`` of the same design trace the same samples."""
        return self.width, self.height, self.spp, self.adaptive, self.noise_target, self.noise_space

    def _reusable(self) -> bool:
        prev = self._previous
        if prev is None or self._changed is None:
            return False
        visual = self._changed & VISUAL_FIELDS
        if not self.design.labels and not prev.design.labels:
            visual = visual - {"labels"}
        if not _lights_shade(self.design) and not _lights_shade(prev.design):
            visual = visual - {"lights"}
        return (not visual and prev.done and prev.error is None and not prev.cancelled
                and self._sampling() == prev._sampling())

    def _relabel_plan(self):
        """``(context, trace, recolour)`` when this job can relabel the previous one (module
        rule): the previous context with the new labels, the ``(H, W)`` masks of pixels to trace
        again and of pixels whose label terms only are recomputed; else ``None``."""
        prev = self._previous
        if (prev is None or prev._records is None or prev._ctx is None or self._records is None
                or not prev.done or prev.error is not None or prev.cancelled
                or prev._sampling() != self._sampling()
                or _without_labels(prev.design) != _without_labels(self.design)
                or (prev.design.lights != self.design.lights and self.design.cap is not None)):
            return None  # (lights shade a closure's diffuse parts too: those pixels are not recorded)
        env = self.design.environment
        if env.asset is not None:
            a, b = (prev.assets or {}).get(env.asset), (self.assets or {}).get(env.asset)
            if not (a is b or (isinstance(a, bytes) and a == b)):
                return None
        ctx = prev._ctx.with_labels(self.design, self.assets)
        old, new = prev.design.labels, self.design.labels
        bits = colour_bits = np.int64(0)
        if prev.design.lights != self.design.lights:
            bits |= _ALL_LABEL_BITS
        if len(old) != len(new):
            bits |= prev._ctx.labels.objects[0] | ctx.labels.objects[0] | _ALL_LABEL_BITS
        else:
            for k, (a, b) in enumerate(zip(old, new)):
                if a == b and _label_assets_equal(a, b, prev.assets, self.assets):
                    continue
                if _placed(a) != _placed(b):
                    bits |= _object_bit(prev._ctx.labels, k) | _object_bit(ctx.labels, k) | _label_bit(k)
                elif _colour_only(a, b, k, prev, self, prev._ctx.labels, ctx.labels):
                    colour_bits |= _label_bit(k)
                else:
                    bits |= _label_bit(k)
        objects = prev.film.objects
        trace = (objects & bits) != 0
        return ctx, trace, ((objects & colour_bits) != 0) & ~trace

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
                plan = self._relabel_plan()
                if plan is not None:
                    ctx, trace, recolour = plan
                    self._reuse = (trace, recolour)
                    self.relabelled_pixels = int(np.count_nonzero(trace))
                    self.recoloured_pixels = int(np.count_nonzero(recolour))
                    self._render(ctx)
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
            try:
                if self.on_done is not None:
                    self.on_done(self)
            except Exception as exc:  # a failing callback is an error of the job
                if self.error is None:
                    self.error = exc
            finally:
                self._returned.set()

    def _render(self, ctx=None) -> None:
        if ctx is None:
            ctx = RenderContext.from_design(self.design, self.assets, self.width, self.height)
        self._ctx = ctx
        self.film = film = Film(self.width, self.height, ctx.n_materials)
        level = max(ctx.reference_level, 1e-6)
        tiles = self._tiles()
        h, w = self.height, self.width
        b = adaptive.preview_block(w, h)
        with ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="render",
                                initializer=_lower_priority, initargs=(self.worker_nice,)) as pool:
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
                    want = adaptive.noise_targets(film, target, self.noise_target, level, self.noise_space)
                else:
                    want = np.where(edges, target, 0)
                mask = want > film.aa_count
                if not mask.any():
                    break
                self._wave(pool, ctx, tiles, 2 + r, mask, want, roulette=adaptive.ROULETTE if varied else 0.0)
                self._set_progress(0.35 + 0.65 * (r + 1) / len(plan))

    def _wave(self, pool, ctx, tiles, wave, mask, want, preview=None, roulette=0.0) -> None:
        """Trace the pixels of ``mask``: their centres (``want`` None) or anti-aliasing samples
        up to ``want``; one task per tile (small tiles batched, :func:`_batches`), all finished
        before this returns."""
        if self._cancel.is_set():
            return
        film = self.film
        t_wave = time.perf_counter()
        pixels = int(np.count_nonzero(mask))
        samples = pixels if want is None else int(np.sum(np.where(mask, want - film.aa_count, 0)))
        self._chunks = [] if self._records is not None else None
        recording = self._records is not None
        if self._reuse is not None:
            mask = self._replay(wave, mask, want, preview)

        def run(batch):
            if self._cancel.is_set():
                return
            parts = []  # (tile, rows, cols) of the batch's tiles with work
            for x0, y0, x1, y1 in batch:
                ys, xs = np.nonzero(mask[y0:y1, x0:x1])
                if len(xs):
                    parts.append(((x0, y0, x1, y1), ys + y0, xs + x0))
            if not parts:
                return
            rows = np.concatenate([p[1] for p in parts])
            cols = np.concatenate([p[2] for p in parts])
            if want is None:
                res = trace_pixels(ctx, cols, rows, 0, 1, cancel=self._cancel_flag, record_labels=recording)
                if res.finished < len(cols):
                    return
                film.add_centre(cols, rows, res)
                if preview is not None:
                    k = 0
                    for tl, r, c in parts:
                        self._paint_preview(c, r, res.sums[k:k + len(r)], preview, tl)
                        k += len(r)
            else:
                have = film.aa_count[rows, cols]
                count = want[rows, cols] - have
                res = trace_pixels(ctx, cols, rows, have + 1, count, cancel=self._cancel_flag, roulette=roulette,
                                   record_labels=recording)
                if res.finished < len(cols):
                    return
                film.add_aa(cols, rows, count, res)
            chunk = None
            if self._chunks is not None:  # (takes the lock itself)
                first = np.zeros(len(cols), np.int64) if want is None else have + 1
                chunk = self._record(rows, cols, first, 1 if want is None else count, res)
            with self._lock:
                if chunk is not None:
                    self._chunks.append(chunk)
                self.stats.add_counters(res.counters)
                if self.first_tile_seconds is None:
                    self.first_tile_seconds = time.perf_counter() - self._t0
            if self.on_tile is not None:
                for tl, _, _ in parts:
                    if self._cancel.is_set():  # (a cancelled job stops reporting its batch)
                        break
                    self.on_tile(self, Tile(*tl, wave))

        # samples per tile (one pass over the image, not one per tile): which tiles have work,
        # and what a batch of them holds
        t = self.tile
        work = mask.astype(np.int64) if want is None else np.where(mask, want - film.aa_count, 0)
        per_tile = np.add.reduceat(np.add.reduceat(work, np.arange(0, self.height, t), 0),
                                   np.arange(0, self.width, t), 1)
        weighted = [(tl, int(per_tile[tl[1] // t, tl[0] // t])) for tl in tiles]
        weighted = [(tl, w) for tl, w in weighted if w > 0]
        if want is not None:
            weighted = self._balanced(weighted, work)
        tasks = _batches([tl for tl, _ in weighted], [w for _, w in weighted])
        # one pulling loop per worker over the ordered tasks, not one future per tile: a wave of
        # small tiles (the centres' 144 at 384 x 384) spent its first milliseconds submitting
        # them, holding the GIL that a starting worker needs, and each finished future woke
        # this thread
        order = itertools.count()  # (its next() is atomic under the GIL)

        def pull():
            try:
                while not self._cancel.is_set():
                    i = next(order)
                    if i >= len(tasks):
                        return
                    run(tasks[i])
            except BaseException:
                self.cancel()  # the other workers stop at their next tile
                raise

        futures = [pool.submit(pull) for _ in range(min(self.threads, len(tasks)))]
        first_error = None
        for f in futures:
            exc = f.exception()
            if exc is not None and first_error is None:
                first_error = exc
                self.cancel()
        if first_error is not None:
            raise first_error
        if self._chunks:
            self._records[wave] = _WaveRecord.join(self._chunks)
        self._chunks = None
        self.wave_log.append((wave, pixels, samples, time.perf_counter() - t_wave))
        if self.on_wave is not None and not self._cancel.is_set():
            self.on_wave(self, wave)

    def _balanced(self, weighted, work):
        """An anti-aliasing wave's tasks as ``(tile, samples)``: of the busy tiles ``weighted``
        (``((x0, y0, x1, y1), samples)``), one holding more than ``1 / (BALANCE x threads)`` of the
        wave's samples (``work``, per pixel) is cut into quarters (down to 8 px), heaviest first
        (longest-processing-time order). Such a wave's samples crowd into a few tiles, and the
        wave ends at a barrier: one worker's last big tile would keep the others idle. The image
        does not change (samples are seeded by pixel and sample)."""
        share = float(sum(w for _, w in weighted)) / (BALANCE * self.threads)
        out, stack = [], list(weighted)
        while stack:
            (x0, y0, x1, y1), w = stack.pop()
            if w == 0:
                continue
            if w > share and x1 - x0 > 8 and y1 - y0 > 8:
                xm, ym = (x0 + x1) // 2, (y0 + y1) // 2
                for q in ((x0, y0, xm, ym), (xm, y0, x1, ym), (x0, ym, xm, y1), (xm, ym, x1, y1)):
                    stack.append((q, int(work[q[1]:q[3], q[0]:q[2]].sum())))
            else:
                out.append((-w, (x0, y0, x1, y1)))
        return [(tl, -w) for w, tl in sorted(out)]

    def _record(self, rows, cols, first, count, res) -> _WaveRecord:
        """A wave chunk's record. Only samples of pixels with label hits are kept (``s0 = -2``:
        none, the pixel's result does not depend on label colours; ``-1``: not recorded), and at
        most :data:`MAX_RECORDED_SAMPLES` a job, so memory follows the labels' pixels."""
        n = len(cols)
        count = np.broadcast_to(np.asarray(count, np.int64), (n,)).copy()
        s0 = np.full(n, -1, np.int64)
        smp_f, smp_i, hit_f, hit_i = _NO_SAMPLES
        if res.label_record is not None and n:
            smp_f, smp_i, hit_f, hit_i = res.label_record
            starts = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int64)
            hits = np.add.reduceat(smp_i[:, 1] - smp_i[:, 0], starts)
            keep = hits > 0
            kept = int(count[keep].sum())
            with self._lock:
                room = self._recorded + kept <= MAX_RECORDED_SAMPLES
                if room:
                    self._recorded += kept
            if room:
                take = np.repeat(keep, count)
                smp_f, smp_i = smp_f[take], smp_i[take]
                s0 = np.where(keep, np.concatenate([[0], np.cumsum(np.where(keep, count, 0))[:-1]]), -2)
            else:
                s0 = np.where(keep, -1, -2)
                smp_f, smp_i, hit_f, hit_i = _NO_SAMPLES
        return _WaveRecord(rows * self.width + cols, np.asarray(first, np.int64), count, res.sums, res.sumsq,
                           res.signature, res.objects, res.depth, s0.astype(np.int64), smp_f, smp_i, hit_f, hit_i)

    def _paint_preview(self, cols, rows, values, b, region=None) -> None:
        """Paint each centre ``(cols[p], rows[p])`` (its radiance ``values[p]``) over its ``b x b``
        block, clipped to its tile; ``region`` ``(x0, y0, x1, y1)``, tile-aligned, holds all the
        centres (default: the whole image)."""
        film = self.film
        if self.tile % b:  # blocks may cross tiles: one block at a time
            for c, r, v in zip(cols, rows, values):
                by, bx = (r // b) * b, (c // b) * b
                x1 = min((c // self.tile + 1) * self.tile, self.width)  # the pixel's tile
                y1 = min((r // self.tile + 1) * self.tile, self.height)
                film.set_preview(by, min(by + b, y1), bx, min(bx + b, x1), v)
            return
        # blocks then never cross a tile: paint whole blocks, cut at the region's edge
        x0, y0, x1, y1 = region if region is not None else (0, 0, self.width, self.height)
        h, w = y1 - y0, x1 - x0
        grid = np.zeros((-(-h // b), -(-w // b), 3))
        have = np.zeros(grid.shape[:2], bool)
        grid[(rows - y0) // b, (cols - x0) // b] = values
        have[(rows - y0) // b, (cols - x0) // b] = True
        full = np.repeat(np.repeat(grid, b, 0), b, 1)[:h, :w]
        target = film.preview[y0:y1, x0:x1]
        if have.all():  # the usual case: every block's centre
            with film.lock:
                target[...] = full
            return
        on = np.repeat(np.repeat(have, b, 0), b, 1)[:h, :w]
        with film.lock:
            target[on] = full[on]

    def _replay(self, wave, mask, want, preview):
        """Relabel: put the previous job's results of this wave into the film for the pixels it
        traced with the same samples, as they were (clean pixels) or with their label terms
        recomputed for the new colours (module rule); returns the mask of pixels left to trace."""
        rec = self._previous._records.get(wave)
        trace, recolour = self._reuse
        ys, xs = np.nonzero(mask & ~trace)
        if rec is None or not len(xs):
            return mask
        film = self.film
        pix = ys * self.width + xs
        idx = np.minimum(np.searchsorted(rec.pix, pix), len(rec.pix) - 1)
        if want is None:
            first, count = np.zeros(len(xs), np.int64), np.ones(len(xs), np.int64)
        else:
            have = film.aa_count[ys, xs]
            first, count = have + 1, want[ys, xs] - have
        same = (rec.pix[idx] == pix) & (rec.first[idx] == first) & (rec.count[idx] == count)
        same &= ~recolour[ys, xs] | (rec.s0[idx] != -1)  # -2: no label terms to recompute
        idx, rows, cols = idx[same], ys[same], xs[same]
        # every row of the record kept (idx is then 0, 1, ...: both are in pixel order): share
        # its arrays instead of copying them
        whole = len(idx) == len(rec.pix)
        part = rec if whole else rec.subset(idx)
        again = np.nonzero(recolour[rows, cols] & (part.s0 >= 0))[0]
        if len(again):
            sums, sumsq = part.sums.copy(), part.sumsq.copy()
            out_s, out_q = np.zeros((len(again), 3)), np.zeros(len(again))
            replay_samples(with_buffers(self._ctx.labels), part.s0[again], part.count[again], rec.smp_f, rec.smp_i,
                           rec.hit_f, rec.hit_i, out_s, out_q)
            sums[again], sumsq[again] = out_s, out_q
            part = dataclasses.replace(part, sums=sums, sumsq=sumsq)
        res = part.result()
        if want is None:
            film.add_centre(cols, rows, res)
            if preview is not None:
                self._paint_preview(cols, rows, res.sums, preview)
        else:
            film.add_aa(cols, rows, part.count, res)
        self._chunks.append(part)
        left = mask.copy()
        left[rows, cols] = False
        if self.on_tile is not None:
            self.on_tile(self, Tile(0, 0, self.width, self.height, wave))
        return left


#: A task traces at least this many samples (tiles are batched until it does): below it the
#: Python around a tile's kernel call (~50 us) is more than its samples cost (a preview
#: wave's tile holds 4-16 of them).
MIN_TASK_SAMPLES = 512


def _batches(tiles, samples) -> list:
    """Consecutive ``tiles`` (``(x0, y0, x1, y1)``, holding ``samples[i]`` samples each) grouped
    into lists of at least :data:`MIN_TASK_SAMPLES` samples (the last may hold less); order
    kept, so a wave's heaviest tiles still go first."""
    out, batch, total = [], [], 0
    for tl, n in zip(tiles, samples):
        batch.append(tl)
        total += n
        if total >= MIN_TASK_SAMPLES:
            out.append(batch)
            batch, total = [], 0
    if batch:
        out.append(batch)
    return out


def _lower_priority(nice: int) -> None:
    """Raise the calling thread's niceness by ``nice`` (Linux threads have their own)."""
    if nice > 0 and hasattr(os, "setpriority") and hasattr(threading, "get_native_id"):
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(),
                           min(19, os.getpriority(os.PRIO_PROCESS, threading.get_native_id()) + nice))
        except OSError:  # a platform without per-thread priorities: only the GUI's comfort lost
            pass


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

