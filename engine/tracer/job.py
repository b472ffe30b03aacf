"""Progressive, tiled, cancellable render job: the API the GUI, the CLI and batches drive.

Design rule: a :class:`RenderJob` renders one frozen ``Design`` snapshot in waves and composes
the parts that know one thing each: what to trace (:mod:`engine.tracer.adaptive`), where and on
which thread (:class:`engine.tracer.scheduler.TileScheduler`: tiles, tasks, workers, knowing no
material), how (:func:`engine.tracer.context.trace_pixels`, compiled, GIL-free), into what
(:class:`engine.tracer.film.Film`), and what to take over from the job it replaces
(:func:`engine.tracer.reuse.reuse_of`: the whole film, or a relabel). Waves: (0) a preview, the
centres of coarse blocks, and in the window, where the centres would be slow, the display-only
sketch (:mod:`engine.tracer.sketch`: cheap samples in every pixel, never in the film); (1)
every other pixel's centre; (2...) stratified anti-aliasing samples
for the pixels on edges, in doubling rounds up to ``spp``; then adaptive rounds for the edge
pixels whose own samples still scatter (final renders up to ``LINEAR_FACTOR x spp``, samples in
proportion to a pixel's scatter; the window's split policy ``SPLIT_FACTOR x spp``, its samples
playing a heavier roulette). A design on a diffuse ground whose grids are not built yet gets a
draft preview first (its ground probed per hit) while they build, on the job's thread. Waves
are separated by a barrier, and a pixel's samples are seeded by (pixel, sample), so the image is
bit-identical for any thread count and tile order. ``cancel()`` raises a flag the kernels poll
between pixels: a job stops within one pixel's work.

Threading contract (the observers, :class:`~engine.tracer.job_options.JobObservers`):
``on_tile(job, tile)`` and ``on_done(job)`` run on worker threads, ``on_wave(job, wave)`` on the
job's own thread between waves; GUI code must marshal to its own thread. ``image()``,
``progress`` and ``sample_counts()`` may be read at any time.
"""
from __future__ import annotations

import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import adaptive
from . import sketch as sketching
from ..color import tonemap_srgb8  # noqa: F401 - the encoding the callers of a job use
from .context import RenderContext, TraceStats, trace_pixels
from .film import Film
from .job_options import BenchHooks, JobObservers, Tile, Workers, lower_priority
from .relabel import LabelRecorder, RelabelPlan, replay
from .reuse import VISUAL_FIELDS, reuse_of  # noqa: F401 - VISUAL_FIELDS for callers
from .sampling import FINAL_SAMPLING, Sampling
from .scheduler import TileScheduler
from .tables.sky import GridCancelled
from .tables.stage import stage_grids_ready


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
    sampling : engine.tracer.sampling.Sampling
        Where the adaptive rounds stop (the default: a final render's).
    threads : int, optional
        Worker threads (default: the CPUs this process may use, at most 8).
    workers : engine.tracer.job_options.Workers
        The tile edge (pixels) and the niceness added to each worker thread (the window's is
        positive, so that its GUI thread comes first); neither changes the image.
    observers : engine.tracer.job_options.JobObservers
        ``on_tile(job, tile)`` after each tile and ``on_done(job)`` once when the job stops
        (finished, cancelled or failed), on worker threads; ``on_wave(job, wave)`` on the job's
        thread after each whole wave, the film holding exactly the samples of waves ``0..wave``
        (wave 0 is reported again after each pass of a sketch, :attr:`sketched` then > 0).
    replaces : engine.tracer.job_options.Replaces, optional
        The job this one replaces and what changed since (a :class:`~engine.model.changes.Change`
        or field names): :mod:`engine.tracer.reuse` decides once whether this job keeps the
        previous film (done at once), relabels or retints it. ``None``: nothing to take over.
    _bench : engine.tracer.job_options.BenchHooks
        Benchmarks and tests only: the tiles' shuffle seed, and where in each pixel's sample
        sequence its anti-aliasing samples start (so that a reference shares none with the
        render it checks). The defaults for every other render.
    """

    def __init__(self, design, assets=None, *, width=None, height=None, spp=None, sampling=FINAL_SAMPLING,
                 threads=None, workers=Workers(), observers=JobObservers(), replaces=None, _bench=BenchHooks()):
        """A job for ``design`` (class docstring); every option but the design is keyword-only
        with a default, so a call names just what it changes. Options that travel together come
        as one immutable record each (:class:`~engine.tracer.sampling.Sampling`, those of
        :mod:`engine.tracer.job_options`), checked here (``TypeError``, not an error in the
        middle of the render); the size, ``spp`` and ``threads`` stay single, set one by one."""
        for name, value, kind in (("sampling", sampling, Sampling), ("workers", workers, Workers),
                                  ("observers", observers, JobObservers), ("_bench", _bench, BenchHooks)):
            if not isinstance(value, kind):
                raise TypeError(f"{name} must be a {kind.__name__}, not {type(value).__name__}")
        self.design = design
        self.assets = assets
        self.width = int(width or design.render.width)
        self.height = int(height or design.render.height)
        self.spp = max(1, int(spp or design.render.spp))
        self.sampling = sampling
        if threads is None:
            cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
            threads = min(cpus, 8)
        self.threads = max(1, int(threads))
        self.tile, self.worker_nice = workers.tile, workers.nice
        self.on_tile, self.on_done, self.on_wave = observers.on_tile, observers.on_done, observers.on_wave
        self.stats = TraceStats()
        self.error = None
        self.seconds = None
        self.first_tile_seconds = None
        #: ``(wave, pixels, samples, seconds)`` per wave traced (benchmarks, the status bar)
        self.wave_log = []
        #: pixels the window's split policy stopped at its sample cap with their estimate still
        #: above its tolerance (:func:`~engine.tracer.adaptive.split_unconverged`); 0 when
        #: every pixel met it or the render has no such rounds (the status bar says how many)
        self.capped = 0
        #: the per-pixel tolerance (display units) the split policy's adaptive rounds settled at
        #: (:func:`~engine.tracer.adaptive.split_tolerance`); ``None`` without such rounds
        self.tolerance = None
        self.film = Film(self.width, self.height)
        #: the compiled scene of the render (``None`` until it starts, or for a kept film)
        self.context = None
        #: per wave, the traced results (designs with labels only; a relabel reads them)
        self.records = LabelRecorder(self.width) if design.labels else None
        #: pixels a relabel traced again from the start / recomputed the label terms of (None:
        #: a full render or a kept film); pixels whose samples a new sampling plan asks for are
        #: traced on top of these
        self.relabelled_pixels = None
        self.recoloured_pixels = None
        #: a colour-only edit's basis (:class:`~engine.tracer.retint.RetintBasis`: the previous
        #: converged film, retinted by this job's centres for the preview); ``None`` otherwise
        self.retint = None
        #: True while a draft (a diffuse ground without its grids) fills the film
        self.drafting = False
        #: the display-only sketch's sums (:class:`~engine.tracer.sketch.Sketch`) and the
        #: samples per pixel of its last finished pass (0: none); ``None`` without a sketch
        self.sketch = None
        self.sketched = 0
        #: ``(samples per pixel, seconds)`` per sketch pass (benchmarks)
        self.sketch_log = []
        # (the previous job, not the record: the job lets go of it once it runs)
        self._previous, self._changed = (None, None) if replaces is None else (replaces.previous, replaces.changed)
        self._sample_base = _bench.sample_base
        self._scheduler = TileScheduler(self.width, self.height, self.tile, self.threads, _bench.tile_shuffle_seed)
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
        self._plan: RelabelPlan | None = None

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
        """Ask the job to stop: the kernels stop at the next pixel, no new tile starts. A job
        that has finished stays finished (its film whole: the next job may reuse it)."""
        if self._finished.is_set() and self.error is None and not self._cancel.is_set():
            return
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
        estimate (:func:`engine.color.tonemap_srgb8` of :meth:`image`): a finished tile as the
        window paints it."""
        return self.film.display(region)

    def sample_counts(self) -> np.ndarray:
        """Samples that make each pixel's value so far, ``(H, W)`` int (a copy)."""
        return self.film.samples()

    def sampling_key(self) -> tuple:
        """What decides which samples the job traces, besides the design: two jobs with equal
        ``sampling_key()`` of the same design trace the same samples."""
        return (self.width, self.height, self.spp, self.sampling)

    # ------------------------------------------------------------------ internals
    def _set_progress(self, value: float) -> None:
        if self._cancel.is_set():  # skipped waves are not progress
            return
        with self._lock:
            self._progress = max(self._progress, min(1.0, float(value)))

    def _run(self) -> None:
        try:
            prev, self._previous = self._previous, None  # (a chain of jobs must not keep every film alive)
            reuse_of(prev, self.design, self.assets, self.sampling_key(), self._changed).run(self, prev)
        except GridCancelled:  # the ground's grids stopped building because the job was cancelled
            self.cancel()
        except BaseException as exc:  # reported, never swallowed
            self.error = exc
            self.cancel()
        finally:
            self._plan = None
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
        draft = None
        if ctx is None and not stage_grids_ready(self.design, self.assets, self.width, self.height):
            # a diffuse ground whose grids are not built yet (seconds): the first picture comes
            # from a draft whose ground probes per hit and shows no caustic, while they build
            draft = RenderContext.from_design(self.design, self.assets, self.width, self.height, grids=False)
        elif ctx is None:
            ctx = RenderContext.from_design(self.design, self.assets, self.width, self.height)
        h, w = self.height, self.width
        b = adaptive.preview_block(w, h)
        with ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="render",
                                initializer=lower_priority, initargs=(self.worker_nice,)) as pool:
            # (0) preview: the centre of every b x b block, painted over the block
            grid = np.zeros((h, w), bool)
            grid[np.minimum(np.arange(0, h, b) + b // 2, h - 1)[:, None],
                 np.minimum(np.arange(0, w, b) + b // 2, w - 1)[None, :]] = True
            if draft is not None:
                self.context, self.film = draft, Film(self.width, self.height, draft.n_materials)
                self.drafting = True
                self._wave(pool, draft, 0, grid, None, preview=b)
                ctx = RenderContext.from_design(self.design, self.assets, self.width, self.height,
                                                cancelled=self._cancel.is_set)
                if self.records is not None:  # (the draft's samples are not the render's)
                    self.records = LabelRecorder(self.width)
            self.context = ctx
            self.film = film = Film(self.width, self.height, ctx.n_materials)
            self.drafting = False
            level = max(ctx.reference_level, 1e-6)
            rays = self.stats.rays_cast
            self._wave(pool, ctx, 0, grid, None, preview=b)
            self._set_progress(0.03)
            if self._sketches((self.stats.rays_cast - rays) / max(int(np.count_nonzero(grid)), 1)):
                self._sketch(pool, ctx)
            # (1) every other centre
            self._wave(pool, ctx, 1, ~grid, None)
            self._set_progress(0.35)
            # (2...) anti-aliasing on edges (in final renders also on smooth pixels of the bottle
            # whose own samples step away from their centre): uniform rounds, then (adaptive)
            # where samples scatter
            edges = self.aa_pixels()
            s = self.sampling
            measured = adaptive.measure_mask(film.objects, edges, s.adaptive, s.noise_space)
            first = 2
            if measured.any():  # (final renders) samples in each smooth pixel on the bottle ...
                def keep_inner():  # ... kept where they show detail inside it
                    inner = adaptive.inner_steps(film, measured, level)
                    film.forget(measured & ~inner)
                    edges[...] |= inner

                self._wave(pool, ctx, first, measured, np.where(measured, adaptive.MEASURE_AA, 0), settle=keep_inner)
                first += 1
            policy = adaptive.sampling_policy(s.noise_space, s.policy, s.noise_target, s.cap_factor)
            plan = policy.rounds(self.spp, s.adaptive)
            mark = None
            for r, (target, varied) in enumerate(plan):
                want = policy.targets(film, target, varied, edges, mark, level)
                if policy.tolerance is not None:
                    self.tolerance = policy.tolerance
                mask = want > film.aa_count
                if not mask.any():
                    break
                mark = policy.mark(film)
                self._wave(pool, ctx, first + r, mask, want, roulette=policy.roulette if varied else 0.0)
                self._set_progress(0.35 + 0.65 * (r + 1) / len(plan))
            else:  # every round ran: the last one's pixels may have stopped at the cap, not converged
                if plan[-1][1]:
                    self.capped = policy.capped(film, mark)

    def _sketches(self, preview_rays: float) -> bool:
        """Whether this render traces the sketch (:mod:`engine.tracer.sketch`): asked for by its
        sampling, watched wave by wave (``on_wave``: no one else could show it; the window's
        live drags are not), a full render (a relabel replays its centres at once, a colour-only
        edit shows its retint) and heavy trees (``preview_rays``, the rays per pixel of its
        wave 0, at least :data:`~engine.tracer.sketch.SKETCH_RAYS`: a function of the design,
        so whether it sketches does not change with the machine's load)."""
        if (not self.sampling.sketch or self.on_wave is None or self._plan is not None or self.retint is not None
                or self._cancel.is_set()):
            return False
        return preview_rays >= sketching.SKETCH_RAYS

    def _sketch(self, pool, ctx) -> None:
        """Trace the sketch's passes into :attr:`sketch` (never the film), each while the sketch
        stays within its budget (:func:`~engine.tracer.sketch.next_pass_fits`), and report each as wave
        0 again (``on_wave``: the film still holds wave 0's samples alone; :attr:`sketched`
        says a sketch frame is there to show)."""
        h, w = self.height, self.width
        self.sketch = sk = sketching.Sketch(w, h)
        everywhere = np.ones((h, w), bool)
        base = sketching.SKETCH_BASE + self._sample_base
        spent, last = 0.0, None
        for target in sketching.SKETCH_PASSES:
            have = int(sk.samples)
            if self._cancel.is_set() or (last is not None and not sketching.next_pass_fits(spent, *last, target - have)):
                return  # (the next pass would overrun the sketch's budget: the film's waves come first)
            t_pass = time.perf_counter()

            def run_batch(parts, have=have, target=target):
                rows = np.concatenate([p[1] for p in parts])
                cols = np.concatenate([p[2] for p in parts])
                res = trace_pixels(ctx, cols, rows, base + have + 1, target - have, cancel=self._cancel_flag,
                                   roulette=sketching.SKETCH_ROULETTE)
                if res.finished < len(cols):
                    return
                sk.add(cols, rows, target - have, res)
                with self._lock:
                    self.stats.add_counters(res.counters)

            work = np.full((h, w), target - have, np.int64)
            self._scheduler.run(pool, self._scheduler.tasks(work, balance=False), everywhere, run_batch,
                                self._cancel.is_set, self.cancel)
            if self._cancel.is_set():
                return
            self.sketched = target
            seconds = time.perf_counter() - t_pass
            spent, last = spent + seconds, (seconds, target - have)
            self.sketch_log.append((target, seconds))
            if self.on_wave is not None:
                self.on_wave(self, 0)

    def aa_pixels(self) -> np.ndarray:
        """The pixels ``(H, W)`` bool the anti-aliasing rounds sample, as judged from the film's
        centres once wave 1 has traced them all: edges (:func:`engine.tracer.adaptive.edge_mask`)
        and pixels that met a sampled surface (noisy anywhere). Every other pixel keeps its centre
        (a final render may still measure some: :func:`~engine.tracer.adaptive.measure_mask`)."""
        film, ctx = self.film, self.context
        edges = adaptive.edge_mask(film.luminance(), film.signature, max(ctx.reference_level, 1e-6))
        edges |= (film.objects & ctx.stochastic_objects) != 0  # a sampled surface: noisy anywhere
        return edges

    def adopt(self, previous) -> None:
        """Take ``previous``'s film as this job's (:data:`~engine.tracer.reuse.KEEP_FILM`): its
        scene and records describe it, for the next job."""
        self.film, self.stats, self.context, self.records = previous.film, previous.stats, previous.context, previous.records
        self.capped, self.tolerance = previous.capped, previous.tolerance

    def relabel(self, plan: RelabelPlan) -> None:
        """Render by replaying the previous film and tracing ``plan``'s pixels again."""
        self._plan = plan
        self.relabelled_pixels = int(np.count_nonzero(plan.trace))
        self.recoloured_pixels = int(np.count_nonzero(plan.recolour))
        self._render(plan.context)

    def _wave(self, pool, ctx, wave, mask, want, preview=None, roulette=0.0, settle=None) -> None:
        """Trace the pixels of ``mask``: their centres (``want`` None) or anti-aliasing samples
        up to ``want``, on the scheduler's workers; all finished before this returns. ``settle``
        (no arguments) runs on the finished film before ``on_wave`` observers see it."""
        if self._cancel.is_set():
            return
        film = self.film
        t_wave = time.perf_counter()
        pixels = int(np.count_nonzero(mask))
        samples = pixels if want is None else int(np.sum(np.where(mask, want - film.aa_count, 0)))
        recording = self.records is not None
        if self._plan is not None:
            mask, cols, rows, res = replay(self._plan, film, wave, mask, want, self.width, self.records)
            if len(cols):
                if want is None and preview is not None:
                    film.paint_preview(cols, rows, res.sums, preview, self.tile)
                if self.on_tile is not None:
                    self.on_tile(self, Tile(0, 0, self.width, self.height, wave))

        def run_batch(parts):
            rows = np.concatenate([p[1] for p in parts])
            cols = np.concatenate([p[2] for p in parts])
            if want is None:
                res = trace_pixels(ctx, cols, rows, 0, 1, cancel=self._cancel_flag, record_labels=recording)
                if res.finished < len(cols):
                    return
                film.add_centre(cols, rows, res)
                if preview is not None:
                    k = 0
                    for (x0, y0, x1, y1), r, c in parts:
                        film.paint_preview(c, r, res.sums[k:k + len(r)], preview, self.tile, (y0, y1, x0, x1))
                        k += len(r)
            else:
                have = film.aa_count[rows, cols]
                count = want[rows, cols] - have
                res = trace_pixels(ctx, cols, rows, have + 1 + self._sample_base, count, cancel=self._cancel_flag,
                                   roulette=roulette, record_labels=recording)
                if res.finished < len(cols):
                    return
                film.add_aa(cols, rows, count, res)
            if recording:  # (takes the recorder's lock itself)
                first = np.zeros(len(cols), np.int64) if want is None else have + 1
                self.records.add(self.records.record(rows, cols, first, 1 if want is None else count, res))
            with self._lock:
                self.stats.add_counters(res.counters)
                if self.first_tile_seconds is None:
                    self.first_tile_seconds = time.perf_counter() - self._t0
            if self.on_tile is not None:
                for tl, _, _ in parts:
                    if self._cancel.is_set():  # (a cancelled job stops reporting its batch)
                        break
                    self.on_tile(self, Tile(*tl, wave))

        work = mask.astype(np.int64) if want is None else np.where(mask, want - film.aa_count, 0)
        tasks = self._scheduler.tasks(work, balance=want is not None)
        self._scheduler.run(pool, tasks, mask, run_batch, self._cancel.is_set, self.cancel)
        if recording:
            self.records.end_wave(wave)
        if settle is not None and not self._cancel.is_set():
            settle()
        self.wave_log.append((wave, pixels, samples, time.perf_counter() - t_wave))
        if self.on_wave is not None and not self._cancel.is_set():
            self.on_wave(self, wave)


def render_image(design, assets=None, **kw) -> np.ndarray:
    """Render to completion and return ``(H, W, 3)`` float32 linear radiance.

    Keyword arguments are those of :class:`RenderJob` (its records from
    :mod:`engine.tracer.job_options`). Raises the worker's exception if a tile
    failed.
    """
    job = RenderJob(design, assets, **kw).start()
    job.wait()
    if job.error is not None:
        raise job.error
    return job.image()
