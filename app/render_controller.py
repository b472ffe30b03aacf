"""Runs the progressive tracer for the preview: one job at a time, tiles marshalled to the GUI.

Design rule: each ``start`` bumps a *generation* number and cancels the running job at once;
the worker threads' ``on_tile`` callbacks only emit a queued signal carrying their generation,
and the GUI-thread slot drops anything from an older generation, so a stale tile is never
shown. Finished tiles are collected and painted together at most ~30 times a second. Starting
is debounced (``restart_delay_ms``) so a burst of edits does not build a render scene per edit.

The preview renders at the size the window asks for (the pane in device pixels, see
:meth:`set_size`). While a gesture *holds* the render (a section drag, an orbit), each edit starts
a cheap **live pass** instead: a quarter-size job at 1 sample per pixel, cancelled by the next
edit; releasing the hold starts the full render of the newest design. The controller says
honestly what the picture is (:attr:`state`, signal ``stateChanged``): ``"stale"`` while a hold
keeps the full render back, ``"refining"`` while a full job adds waves, ``"denoised"`` while the
picture is the denoiser's estimate of the film after the newest wave, ``"retinted"`` while after a
colour-only edit it is the last converged image in the new colour (:mod:`engine.tracer.retint`,
shown from the first wave on), ``"converged"`` once it is done for the design shown (the raw film,
never an estimate), ``"failed"``.

The denoised preview (:class:`engine.tracer.denoise.FrameDenoiser`, on a thread of its own with
one OIDN thread, niced like the workers): after each wave of a full job from the first
full-resolution one (wave 1; wave 0 is the block preview) the film and its guides
are denoised as a whole frame; once one is shown the raw tiles of later waves are not painted
over it (a mix of the two would be neither), and convergence paints the raw film whole.
:meth:`set_denoise` (View ▸ Raw preview) turns it off and shows the raw film at once. A job's failure is reported through ``failed`` and
the controller stays usable. Every job is made in :meth:`_make_job`, the one place that knows
the tracer's constructor.
"""
from __future__ import annotations

import os
import time

from PySide6.QtCore import QObject, Qt, QTimer, Signal

from app import engine_bridge
from engine.model.changes import Change
from engine.tracer.job_options import JobObservers, Replaces, Workers

#: The live pass during a held gesture: this fraction of the preview's size, 1 sample per pixel.
LIVE_SCALE = 0.25
LIVE_SPP = 1
#: A gesture's first live pass starts this soon (ms); the next ones at most this often.
LIVE_FIRST_MS = 15
LIVE_INTERVAL_MS = 60
#: Niceness of the render workers: every core renders, and the scheduler still prefers the GUI
#: thread when they compete for a core (``python -m benchmarks.wireframe``).
WORKER_NICE = 10
#: Anti-aliasing waves (2 and later) are painted this many times less often than the first ones.
REFINE_FLUSH_FACTOR = 4


class RenderController(QObject):
    """Owns the preview's render job.

    Signals
    -------
    tileReady(int, int, int, object)
        ``(generation, x0, y0, rgb8 array (h, w, 3))`` of a finished tile, on the GUI thread.
    progressed(int, float, int, int)
        ``(generation, fraction done, image width, image height)``.
    finished(int), failed(int, str)
        The full job of that generation converged / failed (the message says why).
    stateChanged(str, int, float)
        ``(state, wave, fraction)``: see the module rule; ``wave`` is the newest wave shown.
    """

    tileReady = Signal(int, int, int, object)
    progressed = Signal(int, float, int, int)
    finished = Signal(int)
    failed = Signal(int, str)
    stateChanged = Signal(str, int, float)
    _worker_tile = Signal(int, object, object)
    _worker_done = Signal(int, object)
    _worker_wave = Signal(int, object, int)
    _denoised = Signal(int, object, object, float)

    def __init__(self, parent=None, restart_delay_ms: int = 40, flush_ms: int = 33):
        super().__init__(parent)
        self.generation = 0
        self.job = None
        self._old_jobs: list = []
        self._pending = None
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setTimerType(Qt.PreciseTimer)  # why: live passes are due within milliseconds
        self._delay_ms = restart_delay_ms
        self._timer.timeout.connect(self._start_pending)
        self._dirty: list = []
        self._flush_timer = QTimer(self)
        self._flush_timer.setSingleShot(True)
        self._flush_ms = flush_ms  # (each start passes its interval: see _on_worker_tile)
        self._flush_timer.timeout.connect(self.flush_tiles)
        self._worker_tile.connect(self._on_worker_tile)
        self._worker_done.connect(self._on_worker_done)
        self._worker_wave.connect(self._on_worker_wave)
        self._denoised.connect(self._on_denoised)
        self.denoise = True  # False: the raw film only (View ▸ Raw preview)
        self._frame_denoiser = None  # made at the first wave (OIDN loads then)
        self._denoised_generation = -1  # whose denoised frame is on screen
        #: the mean samples per pixel of the denoised frame shown (the status bar says them)
        self.denoised_samples = 0.0
        # why: every core: the tracer's kernels release the GIL, and the GUI thread only copies
        # finished tiles (the GUI-drag benchmark measures the cost of this choice)
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 2)
        self.threads = max(1, min(8, cores))
        self._last_full = None  # the last full render's job: what an edit that changes nothing reuses
        self._since_full = Change()  # what the scene announced since that job was made
        self.held = False
        self._live_allowed = True
        self.converged_generation = -1
        self.ended_generation = -1  # converged or failed: nothing more will come
        self.size = (0, 0)
        self.wanted_size: tuple[int, int] | None = None
        self.live = False  # whether the current job is a live pass
        self.wave = -1
        self.state = "idle"
        self._latest = None  # (design, assets) of the newest start: what a release renders
        self._live_started = -1e9  # when the last live pass started (time.monotonic, s)

    # -------------------------------------------------------------------- control
    def set_size(self, size: tuple[int, int] | None):
        """Render at ``size`` (width, height in pixels: the preview pane in device pixels),
        or at the design's own render size for ``None``; takes effect at the next start."""
        self.wanted_size = None if size is None else (max(1, int(size[0])), max(1, int(size[1])))

    def full_size(self, design) -> tuple[int, int]:
        """The size (pixels) a full render of ``design`` has."""
        return self.wanted_size or (design.render.width, design.render.height)

    def start(self, design, assets=None, changed=None):
        """Cancel what is running and render ``design``: the full render after the debounce
        delay, or while held the live pass (or nothing, for a hold without one). Live passes
        are throttled, not debounced: a continuous drag starts one every
        :data:`LIVE_INTERVAL_MS` of the newest design, where a debounce would wait for a pause.
        ``changed`` is what the scene announced (a :class:`~engine.model.changes.Change`; ``None``:
        nothing new, a restart); the full render is told all of it since the last one."""
        if changed is not None:
            self._since_full = self._since_full | changed
        live_due = self.held and self._timer.isActive() and self._pending is not None and self._pending[3]
        due = self._timer.remainingTime() if live_due else -1
        self.cancel()
        self.generation += 1
        self._latest = (design, dict(assets or {}))
        self._pending = (self.generation, design, self._latest[1], self.held)
        self._set_state("stale" if self.held else "refining", -1, 0.0)
        if not self.held:
            self._timer.start(self._delay_ms)
        elif self._live_allowed:
            since = (time.monotonic() - self._live_started) * 1000.0
            wait = max(LIVE_FIRST_MS, LIVE_INTERVAL_MS - since)
            self._timer.start(int(due if due >= 0 else wait))

    def hold(self, on: bool, live: bool = True):
        """While held (a drag or an orbit in progress) edits start only the live pass (none
        with ``live=False``: a final render wants the cores); releasing renders the newest
        design in full."""
        on = bool(on)
        if on == self.held:
            return
        self.held = on
        self._live_allowed = bool(live)
        if on:
            # why: the running job stays until an edit really arrives (a refused drag changes
            # nothing, and must not leave the preview half rendered)
            if self.live or self._pending is not None:
                self._set_state("stale", self.wave, 0.0)
            return
        if self.live or (self._pending is not None and self._pending[3]):
            design, assets = self._latest
            self.start(design, assets)

    def cancel(self):
        """Cancel the running job and any pending start; late tiles will be ignored."""
        self._timer.stop()
        self._flush_timer.stop()
        self._dirty = []
        self._pending = None
        if self.job is not None:
            self.job.cancel()
            self._old_jobs.append(self.job)
            self.job = None
        self._old_jobs = [j for j in self._old_jobs if not getattr(j, "done", True)]

    def is_idle(self) -> bool:
        return self._pending is None and (self.job is None or bool(getattr(self.job, "done", True)))

    def wait_until_idle(self, timeout: float = 30.0) -> bool:
        """Block until the current job ends (tests; the screenshot). Tiles still need the
        event loop to arrive."""
        if self._pending is not None:
            self._timer.stop()
            self._start_pending()
        return self.job is None or bool(self.job.wait(timeout))

    def shutdown(self, timeout: float = 30.0):
        """Cancel and join every job this controller started."""
        jobs = [self.job] if self.job is not None else []
        self.cancel()
        for job in jobs + self._old_jobs:
            job.wait(timeout)
        self._old_jobs = []
        if self._frame_denoiser is not None:
            self._frame_denoiser.close(timeout)
            self._frame_denoiser = None

    def set_denoise(self, on: bool):
        """Show the denoised preview (``True``, the default) or the raw film only: turning it
        off repaints the raw film at once, turning it on denoises the film as it is now."""
        self.denoise = bool(on)
        job = self.job
        if job is None or self.live:
            return
        if not self.denoise and self._denoised_generation == self.generation:
            self._denoised_generation = -1
            self._paint_whole(job)
            if self.ended_generation != self.generation:
                self._set_state("refining", self.wave, float(job.progress))
        elif self.denoise and self.ended_generation != self.generation and self.wave >= 0:
            self._request_denoise(self.generation, job, self.wave)

    def _paint_whole(self, job):
        """Hand out the raw film's whole frame as one tile (GUI thread)."""
        w, h = self.size
        self.tileReady.emit(self.generation, 0, 0, job.display((0, h, 0, w)))

    def _request_denoise(self, generation, job, wave):
        if self._frame_denoiser is None:
            from engine.color import tonemap_srgb8
            from engine.tracer.denoise import FrameDenoiser

            def deliver(key, image, samples):  # (on the denoiser's thread: the tone map too)
                self._denoised.emit(key[0], key[1], tonemap_srgb8(image), samples)

            def failed(key, message):
                self.failed.emit(key[0], f"denoiser: {message}")

            self._frame_denoiser = FrameDenoiser(deliver, failed, nice=WORKER_NICE)
        self._frame_denoiser.request((generation, job, wave), job)

    def denoiser_idle(self) -> bool:
        """Whether no frame waits for the denoiser or is being denoised (tests, screenshots)."""
        return self._frame_denoiser is None or self._frame_denoiser.idle()

    def _set_state(self, state: str, wave: int, fraction: float):
        self.state, self.wave = state, wave
        self.stateChanged.emit(state, wave, float(fraction))

    def _make_job(self, generation, design, assets, width, height, spp, live=False):
        """The tracer job for one render (the one place that builds one). A full render is told
        what the scene announced since the last full render (:attr:`_since_full`), so that an
        edit of nothing it renders (a name, the notes) keeps that film and a label edit
        relabels it, without comparing designs again."""
        prev = self._last_full
        replaces = Replaces(prev, self._since_full) if not live and prev is not None else None
        if not live:
            self._since_full = Change()
        observers = JobObservers(
            on_tile=lambda j, t, g=generation: self._worker_tile.emit(g, j, t),
            on_done=lambda j, g=generation: self._worker_done.emit(g, j),
            on_wave=None if live else (lambda j, w, g=generation: self._worker_wave.emit(g, j, w)))
        job = engine_bridge.tracer_job_class()(
            design, assets, width=width, height=height, spp=spp, threads=self.threads,
            sampling=engine_bridge.WINDOW_NOISE, workers=Workers(nice=WORKER_NICE), observers=observers,
            replaces=replaces)
        if not live:
            self._last_full = job
        return job

    def _start_pending(self):
        if self._pending is None:
            return
        generation, design, assets, live = self._pending
        self._pending = None
        width, height = self.full_size(design)
        spp = design.render.spp
        if live:
            width, height = max(1, round(width * LIVE_SCALE)), max(1, round(height * LIVE_SCALE))
            spp = LIVE_SPP
            self._live_started = time.monotonic()
        try:
            job = self._make_job(generation, design, assets, width, height, spp, live)
            self.job, self.live, self.size = job, live, (width, height)
            self.progressed.emit(generation, 0.0, width, height)
            job.start()
        except Exception as exc:  # why: a design the tracer cannot build must not kill the GUI
            self.job = None
            self.ended_generation = generation
            self._set_state("failed", -1, 0.0)
            self.failed.emit(generation, f"{type(exc).__name__}: {exc}")

    # ---------------------------------------------------------------- GUI thread
    def _on_worker_tile(self, generation, job, tile):
        if generation != self.generation or job is not self.job:
            return  # stale: from a job that an edit cancelled
        # why: early waves finish many tiles per frame; they are painted together per flush
        self._dirty.append(tile)
        if not self._flush_timer.isActive():
            # why: the first waves build the picture and are shown as they come; the
            # anti-aliasing waves only refine edges, and a repaint of the pane takes a core
            # from the workers
            self._flush_timer.start(self._flush_ms if tile.wave < 2 else REFINE_FLUSH_FACTOR * self._flush_ms)

    def flush_tiles(self):
        """Tone-map and hand out the tiles finished since the last flush (GUI thread)."""
        self._flush_timer.stop()
        tiles, self._dirty = self._dirty, []
        job = self.job
        if not tiles or job is None:
            return
        generation = self.generation
        denoised = self.denoise and not self.live and self._denoised_generation == generation
        try:
            for tile in ([] if denoised else _latest_per_area(tiles)):  # only the tiles' pixels: the film is locked meanwhile
                rgb8 = job.display((tile.y0, tile.y1, tile.x0, tile.x1))
                self.tileReady.emit(generation, tile.x0, tile.y0, rgb8)
        except Exception as exc:  # why: a bad tile is reported, the job keeps running
            self.failed.emit(generation, f"tile: {exc}")
            return
        fraction = float(job.progress)
        self.progressed.emit(generation, fraction, *self.size)
        wave = max(max(t.wave for t in tiles), self.wave)
        state = "stale" if self.live else (_estimate_state(job) if denoised else "refining")
        self._set_state(state, wave, 0.0 if self.live else fraction)

    def _on_worker_wave(self, generation, job, wave):
        # (wave 0 is the block preview: its guides hold only the blocks' centres; a retint
        # needs only centres, and its first frame is due at once; wave 0 comes again after
        # each pass of a sketch, whose frame is the first full one)
        first = 0 if getattr(job, "retint", None) is not None or getattr(job, "sketched", 0) else 1
        if generation != self.generation or job is not self.job or self.live or not self.denoise or wave < first:
            return
        self._request_denoise(generation, job, wave)

    def _on_denoised(self, generation, job, rgb8, samples):
        if (generation != self.generation or job is not self.job or self.live or not self.denoise
                or self.ended_generation == generation):
            return  # stale, converged meanwhile, or the raw film asked for
        self._dirty = []  # (raw tiles of this wave are in the frame)
        self._denoised_generation = generation
        self.denoised_samples = samples
        self.tileReady.emit(generation, 0, 0, rgb8)
        self._set_state(_estimate_state(job), self.wave, float(job.progress))

    def _on_worker_done(self, generation, job):
        if generation != self.generation or job is not self.job:
            return
        self.flush_tiles()  # the last tiles before the verdict
        if getattr(job, "error", None) is not None:
            self.ended_generation = generation
            self._set_state("failed", self.wave, 0.0)
            self.failed.emit(generation, str(job.error))
        elif self.live:
            self._set_state("stale", self.wave, 0.0)  # the full render waits for the release
        elif not getattr(job, "cancelled", False):
            self.ended_generation = generation
            self.converged_generation = generation
            if self._denoised_generation == generation:  # the raw film replaces the estimate
                self._denoised_generation = -1
                self._paint_whole(job)
            self._set_state("converged", self.wave, 1.0)
            self.finished.emit(generation)


def _estimate_state(job) -> str:
    """What an estimate of ``job``'s film shown is called: ``"retinted"`` for a colour-only
    edit's (:mod:`engine.tracer.retint`), else ``"denoised"``."""
    return "retinted" if getattr(job, "retint", None) is not None else "denoised"


def _latest_per_area(tiles):
    """One tile per pixel area (a later wave repaints the same area): the last one wins."""
    by_area = {}
    for tile in tiles:
        by_area[(tile.x0, tile.y0, tile.x1, tile.y1)] = tile
    return list(by_area.values())
