"""A render job's options that travel together, each as one small immutable record.

Design rule: :class:`engine.tracer.job.RenderJob` takes its design, size, ``spp``, sampling
(:class:`engine.tracer.sampling.Sampling`) and threads one by one, and each group of the other
choices whole: who watches the job (:class:`JobObservers`), the job it replaces and what changed
since (:class:`Replaces`), how its workers cut and share the machine (:class:`Workers`), and the
benchmarks' and tests' hooks (:class:`BenchHooks`). Only :class:`BenchHooks` changes which samples
are traced; the others never change a finished image. The records import nothing of the tracer, so a
caller can name its options at import time; :func:`lower_priority` is what the workers run first.
"""
from __future__ import annotations

import os
import threading
from dataclasses import dataclass
from typing import Any, Callable


@dataclass(frozen=True)
class Tile:
    """A finished piece of work: pixels ``[x0, x1) x [y0, y1)`` of wave ``wave`` (0 = preview)."""

    x0: int
    y0: int
    x1: int
    y1: int
    wave: int


@dataclass(frozen=True)
class JobObservers:
    """Who watches a job; each callback ``None`` or a callable.

    Attributes
    ----------
    on_tile : callable, optional
        ``on_tile(job, tile)`` after each finished :class:`Tile`, on a worker thread.
    on_done : callable, optional
        ``on_done(job)`` once when the job stops (finished, cancelled or failed), on a worker
        thread; an exception it raises becomes the job's error.
    on_wave : callable, optional
        ``on_wave(job, wave)`` on the job's thread after each wave that ran to its end, before
        the next starts: the film then holds exactly the samples of waves ``0..wave`` (the
        image a progressive view shows at that moment; benchmarks chart it against time).
    """

    on_tile: Callable | None = None
    on_done: Callable | None = None
    on_wave: Callable | None = None


@dataclass(frozen=True)
class Replaces:
    """The job a new job replaces, and what changed since: :func:`engine.tracer.reuse.reuse_of`
    decides from them once whether the new job keeps the previous film (done at once),
    relabels or retints it, or renders everything.

    Attributes
    ----------
    previous : engine.tracer.job.RenderJob
        The job replaced (finished or not; the new job lets go of it once it has started).
    changed : engine.model.changes.Change or set of str or None
        The scene's :class:`~engine.model.changes.Change` since ``previous``'s design, or the
        names of the fields changed; ``None`` (not known) renders everything.
    """

    previous: Any
    changed: Any


@dataclass(frozen=True)
class Workers:
    """How a job's worker threads cut the image and share the machine (their number is the
    job's ``threads``). Neither changes the image.

    Attributes
    ----------
    tile : int
        Tile edge in pixels, at least 1.
    nice : int
        Niceness added to each worker thread (Linux; ignored elsewhere), at least 0: the
        window passes a positive value so that, with every core rendering, the scheduler
        still prefers its GUI thread (:func:`lower_priority`).
    """

    tile: int = 32
    nice: int = 0

    def __post_init__(self):
        object.__setattr__(self, "tile", max(1, int(self.tile)))
        object.__setattr__(self, "nice", max(0, int(self.nice)))


@dataclass(frozen=True)
class BenchHooks:
    """Benchmarks and tests only (a job's ``_bench``): the defaults are every other render's.

    Attributes
    ----------
    tile_shuffle_seed : int or None
        Order each wave's tiles at random with this seed (tests: the image must not depend
        on the order); ``None``: row by row.
    sample_base : int
        Anti-aliasing sample ``k`` of a pixel is traced as sample ``k + sample_base`` of its
        sequence (other positions, other seeds), so that a reference image shares no
        anti-aliasing sample with the render it checks. 0 for every render.
    """

    tile_shuffle_seed: int | None = None
    sample_base: int = 0

    def __post_init__(self):
        object.__setattr__(self, "sample_base", int(self.sample_base))


def lower_priority(nice: int) -> None:
    """Raise the calling thread's niceness by ``nice`` (Linux threads have their own)."""
    if nice > 0 and hasattr(os, "setpriority") and hasattr(threading, "get_native_id"):
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(),
                           min(19, os.getpriority(os.PRIO_PROCESS, threading.get_native_id()) + nice))
        except OSError:  # a platform without per-thread priorities: only the GUI's comfort lost
            pass
