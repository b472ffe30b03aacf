"""The work one Dask task does: render one whole frame of one variant, on a worker.

Design rule: a task is a frame, never a tile. The tracer's anti-aliasing decides per pixel from
its neighbours, so a tile would need its neighbours' samples; a whole frame is also what
``glassbench render`` makes, so a distributed frame is bit-identical to a local render (the
tracer seeds every sample by pixel and sample number, never by thread or schedule). The
variant's design and assets arrive as a ``payload`` that the client scattered once per worker;
a task adds only the view's camera and the render settings (a few hundred bytes). Workers never
write files: the frame (and, when the batch denoises, its denoised estimate, made on the
worker from the film's guides) goes back to the client, which writes it inside the output folder.
Progress (fraction, tiles done) is sent as Dask events at most every ``EVENT_PERIOD_S``.
"""
from __future__ import annotations

import dataclasses
import threading
import time

#: Seconds between progress events of one frame.
EVENT_PERIOD_S = 0.25


def render_frame(payload, camera, render, alpha: bool, threads: int, topic: str | None = None,
                 frame_id: str = "", denoise: bool = False) -> dict:
    """Render one frame; returns ``{"images", "seconds", "worker"}``.

    Parameters
    ----------
    payload : tuple
        ``(design, assets)`` of the variant (scattered: shared by the worker's tasks).
    camera : engine.model.design.Camera
        The view's camera (mm, degrees).
    render : engine.model.design.RenderSettings
        Size (pixels) and samples per pixel of the frame.
    alpha : bool
        Also compute the bottle's coverage (:func:`engine.tracer.picking.coverage`).
    threads : int
        Tracer threads for this frame (the worker's Dask threads times this should not
        exceed its cores); the denoiser runs on as many, after the tracer.
    topic, frame_id : str
        Dask event topic and frame name for progress events (no events without a topic).
    denoise : bool
        Also return the denoised estimate of the frame (OIDN quality high).

    Returns
    -------
    dict
        ``images``: :func:`engine.finals.final_images`' ``(rgb, alpha)`` pairs, the raw
        frame first and with ``denoise`` its denoised estimate (``rgb`` ``(H, W, 3)`` float32
        linear radiance, ``alpha`` ``(H, W)`` float32 or ``None``); ``seconds`` of rendering
        and denoising, ``worker`` address (``"local"`` outside Dask).
    """
    from ..tracer.job import RenderJob
    from ..tracer.job_options import JobObservers
    from ..finals import final_images
    design, assets = payload
    design = dataclasses.replace(design, camera=camera, render=render)
    worker = _current_worker()
    report = _Reporter(worker, topic, frame_id)
    threads = max(1, int(threads))
    t0 = time.perf_counter()
    job = RenderJob(design, assets, threads=threads, observers=JobObservers(on_tile=report.tile)).start()
    job.wait()
    if job.error is not None:
        raise job.error
    images = final_images(job, design, assets, alpha=alpha, denoise=denoise, threads=threads)
    seconds = time.perf_counter() - t0
    report.send(1.0)
    return {"images": images, "seconds": seconds,
            "worker": worker.address if worker is not None else "local"}


def _current_worker():
    try:
        from distributed import get_worker
        return get_worker()
    except (ImportError, ValueError):
        return None


class _Reporter:
    """Turns the tracer's ``on_tile`` calls (worker threads) into throttled Dask events."""

    def __init__(self, worker, topic, frame_id):
        self.worker, self.topic, self.frame_id = worker, topic, frame_id
        self.tiles = 0
        self.last = 0.0
        self.lock = threading.Lock()

    def tile(self, job, tile) -> None:
        with self.lock:
            self.tiles += 1
            now = time.monotonic()
            if now - self.last < EVENT_PERIOD_S:
                return
            self.last = now
        self.send(float(job.progress))

    def send(self, fraction: float) -> None:
        if self.worker is None or not self.topic:
            return
        self.worker.log_event(self.topic, {"frame": self.frame_id, "progress": fraction,
                                           "tiles": self.tiles})
