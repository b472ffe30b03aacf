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
        # the stage's passes before a render: the sky grid's probes, a light's photons (a small
        # ground: few cells)
        import dataclasses

        from engine.model.design import Light, Stage
        staged = dataclasses.replace(_tiny_design(), stage=Stage(kind="table", half_size_mm=40.0), lights=(Light(),))
        sc = RenderContext.from_design(staged, None, 8, 8, grids=False)  # (the passes themselves, one probe each:)
        from .kernels.caustics import P_COLS, trace_photons
        from .kernels.records import Cutoffs
        from .kernels.sky import Y_COLS, sky_cells, sweep_cells
        from .kernels.tile import make_work
        from .tables.sky import quiet_recorder, sweep_object
        from .tables.stage import ground_object

        tables, ground = sc.tables(), ground_object(sc.scene)
        sky_cells(tables, ground, 0.0, np.array([[20.0, 0.0]]), np.zeros(1, np.int64), 1, 0, 1,
                  Cutoffs(8, 0.01, 0.0, 64), make_work(8), quiet_recorder(sc.scene), np.zeros((1, Y_COLS)))
        swept = RenderContext.from_design(dataclasses.replace(staged, stage=Stage(kind="table", half_size_mm=40.0,
                                                                                  backdrop=True)), None, 8, 8,
                                          grids=False)
        sweep_cells(swept.tables(), sweep_object(swept.scene), np.array([[0.0, 1.0]]), np.zeros(1, np.int64), 1,
                    0, 1, Cutoffs(8, 0.01, 0.0, 64), make_work(8), quiet_recorder(swept.scene), np.zeros((1, Y_COLS)))
        trace_photons(tables, tables.finishes.lights[0], np.array([0.0, 0.0, 100.0, 20.0, 20.0]), 0.0, 0, 1,
                      np.uint64(1), 8, make_work(8), np.zeros((1, P_COLS)))
        _DONE.set()


def warm_up_async() -> threading.Thread:
    """Start :func:`warm_up` on a daemon thread (the GUI at start-up); returns the thread."""
    t = threading.Thread(target=warm_up, name="kernel-warm-up", daemon=True)
    t.start()
    return t
