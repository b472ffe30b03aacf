"""Runs the progressive tracer for the preview: one job at a time, tiles marshalled to the GUI.

Design rule: each ``start`` bumps a *generation* number and cancels the running job at once;
the worker threads' ``on_tile`` callbacks only emit a queued signal carrying their generation,
and the GUI-thread slot drops anything from an older generation, so a stale tile is never
shown. Finished tiles are collected and painted together at most ~30 times a second. A job's failure is reported through ``failed`` and the controller stays usable. Starting
is debounced (``restart_delay_ms``) so a drag does not build a render scene per mouse event.
"""
from __future__ import annotations

import os

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal

from app import engine_bridge


class RenderController(QObject):
    """Owns the preview's render job.

    Signals
    -------
    tileReady(int, int, int, object)
        ``(generation, x0, y0, rgb8 array (h, w, 3))`` of a finished tile, on the GUI thread.
    progressed(int, float, int, int)
        ``(generation, fraction done, image width, image height)``.
    finished(int), failed(int, str)
        The job of that generation converged / failed (the message says why).
    """

    tileReady = Signal(int, int, int, object)
    progressed = Signal(int, float, int, int)
    finished = Signal(int)
    failed = Signal(int, str)
    _worker_tile = Signal(int, object, object)
    _worker_done = Signal(int, object)

    def __init__(self, parent=None, restart_delay_ms: int = 40, flush_ms: int = 33):
        super().__init__(parent)
        self.generation = 0
        self.job = None
        self._old_jobs: list = []
        self._pending = None
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(restart_delay_ms)
        self._timer.timeout.connect(self._start_pending)
        self._dirty: list = []
        self._flush_timer = QTimer(self)
        self._flush_timer.setSingleShot(True)
        self._flush_timer.setInterval(flush_ms)
        self._flush_timer.timeout.connect(self.flush_tiles)
        self._worker_tile.connect(self._on_worker_tile)
        self._worker_done.connect(self._on_worker_done)
        # why: leave one core to the GUI thread, or drags stutter while the tracer runs
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 2)
        self.threads = max(1, min(8, cores - 1))
        self.held = False
        self.converged_generation = -1
        self.ended_generation = -1  # converged or failed: nothing more will come
        self.size = (0, 0)

    # -------------------------------------------------------------------- control
    def start(self, design, assets=None):
        """Cancel what is running and render ``design`` (after the debounce delay)."""
        self.cancel()
        self.generation += 1
        self._pending = (self.generation, design, dict(assets or {}))
        if not self.held:
            self._timer.start()

    def hold(self, on: bool):
        """While held (a drag in progress) edits cancel the job but start none; releasing
        starts the newest pending render."""
        self.held = bool(on)
        if on:
            # why: the running job stays until an edit really arrives (a refused drag changes
            # nothing, and must not leave the preview half rendered)
            self._timer.stop()
        elif self._pending is not None:
            self._timer.start()

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

    def _start_pending(self):
        if self._pending is None:
            return
        generation, design, assets = self._pending
        self._pending = None
        job_class = engine_bridge.tracer_job_class()
        r = design.render
        try:
            job = job_class(design, assets, width=r.width, height=r.height, spp=r.spp,
                            threads=self.threads,
                            on_tile=lambda j, t, g=generation: self._worker_tile.emit(g, j, t),
                            on_done=lambda j, g=generation: self._worker_done.emit(g, j))
            self.job = job
            self.size = (r.width, r.height)
            self.progressed.emit(generation, 0.0, r.width, r.height)
            job.start()
        except Exception as exc:  # why: a design the tracer cannot build must not kill the GUI
            self.job = None
            self.ended_generation = generation
            self.failed.emit(generation, f"{type(exc).__name__}: {exc}")

    # ---------------------------------------------------------------- GUI thread
    def _on_worker_tile(self, generation, job, tile):
        if generation != self.generation or job is not self.job:
            return  # stale: from a job that an edit cancelled
        # why: early waves finish many tiles per frame; one image() copy per flush, not per tile
        self._dirty.append(tile)
        if not self._flush_timer.isActive():
            self._flush_timer.start()

    def flush_tiles(self):
        """Tone-map and hand out the tiles finished since the last flush (GUI thread)."""
        self._flush_timer.stop()
        tiles, self._dirty = self._dirty, []
        job = self.job
        if not tiles or job is None:
            return
        generation = self.generation
        try:
            image = np.asarray(job.image())
            for tile in _latest_per_area(tiles):
                region = image[tile.y0:tile.y1, tile.x0:tile.x1]
                rgb8 = np.ascontiguousarray(engine_bridge.tonemap_srgb8(region)[..., :3])
                self.tileReady.emit(generation, tile.x0, tile.y0, rgb8)
        except Exception as exc:  # why: a bad tile is reported, the job keeps running
            self.failed.emit(generation, f"tile: {exc}")
            return
        self.progressed.emit(generation, float(job.progress), *self.size)

    def _on_worker_done(self, generation, job):
        if generation != self.generation or job is not self.job:
            return
        self.flush_tiles()  # the last tiles before the verdict
        self.ended_generation = generation
        if getattr(job, "error", None) is not None:
            self.failed.emit(generation, str(job.error))
        elif not getattr(job, "cancelled", False):
            self.converged_generation = generation
            self.finished.emit(generation)


def _latest_per_area(tiles):
    """One tile per pixel area (a later wave repaints the same area): the last one wins."""
    by_area = {}
    for tile in tiles:
        by_area[(tile.x0, tile.y0, tile.x1, tile.y1)] = tile
    return list(by_area.values())
