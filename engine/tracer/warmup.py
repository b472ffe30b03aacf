"""Compile (or load from the disk cache) the tracer's kernels before the first real render.

Design rule: the kernels are compiled once per glassbench version and machine into the cache
folder of :mod:`engine.tracer.kernels`; a fresh process only loads them (about a second). The
window calls :func:`warm_up_async` at start-up so the first preview does not pay even that,
and :func:`warm_up` is what the CLI, benchmarks and tests may call to do it in the foreground.
"""
from __future__ import annotations

import threading

_DONE = threading.Event()
_LOCK = threading.Lock()


def _tiny_design():
    from engine.geometry.section import Section
    from engine.geometry.segments import Line
    from engine.geometry.shape import BottleShape
    from engine.model.design import Camera, Design, Liquid, RenderSettings

    segs = (Line((0, 0), (10, 0)), Line((10, 0), (10, 30)), Line((10, 30), (5, 40)), Line((5, 40), (5, 50)))
    section = Section(segs, (False,) * (len(segs) - 1))  # corners everywhere
    shape = BottleShape("round", (("profile", section),), 1.0, 2.0)
    return Design(shape=shape, liquid=Liquid(fill_value=20.0), camera=Camera((0, -150, 25), (0, 0, 25)),
                  render=RenderSettings(width=8, height=8, spp=4))


def warm_up() -> None:
    """Trace a tiny scene through every public kernel entry (compiles or loads them); idempotent."""
    with _LOCK:
        if _DONE.is_set():
            return
        import numpy as np

        from .context import RenderContext, nearest_hits, trace_pixels, trace_rays
        from .film import Film

        ctx = RenderContext.from_design(_tiny_design(), None, 8, 8)
        film = Film(8, 8, ctx.n_materials)
        film.add_centre(np.arange(4), np.arange(4), trace_pixels(ctx, np.arange(4), np.arange(4), 0, 1))
        film.add_aa(np.arange(4), np.arange(4), 2, trace_pixels(ctx, np.arange(4), np.arange(4), 1, 2,
                                                                record=(np.zeros((64, 6), np.float32), np.zeros(1, np.int64))))
        film.display((0, 8, 0, 8))  # (the window's tiles)
        nearest_hits(ctx.geometry, [[0.0, -100.0, 20.0]], [[0.0, 1.0, 0.0]])
        trace_rays(ctx, [[0.0, -100.0, 20.0]], [[0.0, 1.0, 0.0]])
        # the relabel's recomputation of label terms (the types a job passes it)
        from .kernels.labels import H_COLS, replay_samples
        from .tables.labels import with_buffers

        none = np.zeros(0, np.int64)
        replay_samples(with_buffers(ctx.labels), none, none, np.zeros((0, 3)), np.zeros((0, 2), np.int64),
                       np.zeros((0, H_COLS)), np.zeros((0, 2), np.int64), np.zeros((0, 3)), np.zeros(0))
        _DONE.set()


def warm_up_async() -> threading.Thread:
    """Start :func:`warm_up` on a daemon thread (the GUI at start-up); returns the thread."""
    t = threading.Thread(target=warm_up, name="kernel-warm-up", daemon=True)
    t.start()
    return t
