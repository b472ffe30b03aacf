"""One final image on this machine: render, optional alpha, atomic save, time left, cancel.

Design rule: :class:`FinalRender` is the window's Final image dialog without the window. It
renders a frozen design snapshot with the tracer's own :class:`~engine.tracer.job.RenderJob`
on worker threads (the pixels are those of ``glassbench render`` at the same size and
samples), then on the same worker thread adds the alpha coverage if asked and writes the file
atomically; the file appears only once it is complete, and a cancelled or failed render writes
nothing. ``on_progress(final)`` and ``on_done(final)`` are called on worker threads; a GUI must
marshal them to its own thread. No Qt here.
"""
from __future__ import annotations

import os
import threading
import time

from ..finals import write_final

def time_left_s(elapsed_s: float, fraction: float) -> float | None:
    """Seconds still to go, extrapolated from ``elapsed_s`` at ``fraction`` done (0..1).

    ``None`` while too little is done to say (under 2 % or half a second). The tracer's later
    waves carry more samples per tile than its first ones, so early estimates run short.
    """
    if fraction >= 1.0:
        return 0.0
    if fraction < 0.02 or elapsed_s < 0.5:
        return None
    return elapsed_s * (1.0 - fraction) / fraction


class FinalRender:
    """Render ``design`` to ``path`` (``.png``, ``.exr`` or ``.tif``) at ``width`` x ``height``.

    Parameters
    ----------
    design, assets
        The frozen snapshot and its assets (name -> bytes).
    path : str
        The file to write; its folder must exist. Written only when the render completes.
    width, height, spp : int
        Pixels and samples per pixel (>= 1).
    alpha : bool
        Add the bottle's coverage as an alpha channel (:func:`engine.tracer.picking.coverage`).
    denoise : bool
        Write the denoised image at ``path`` and the raw one beside it (:func:`engine.finals.write_final`).
    threads : int, optional
        Tracer threads (default: the tracer's choice).
    on_progress, on_done : callable, optional
        ``on_progress(self)`` after each tile, ``on_done(self)`` once at the end (worker threads).
    """

    def __init__(self, design, assets, path: str, *, width: int, height: int, spp: int,
                 alpha: bool = False, denoise: bool = False, threads: int | None = None, on_progress=None,
                 on_done=None):
        ext = os.path.splitext(path)[1].lower()
        if ext not in (".png", ".exr", ".tif", ".tiff"):
            raise ValueError(f"the file name must end in .png, .exr or .tif: {path}")
        folder = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(folder):
            raise ValueError(f"the folder {folder} does not exist")
        for name, v in (("width", width), ("height", height), ("spp", spp)):
            if not 1 <= int(v) <= (16384 if name != "spp" else 1 << 20):
                raise ValueError(f"{name} = {v} is out of range")
        self.design, self.assets, self.path = design, dict(assets or {}), os.path.abspath(path)
        self.width, self.height, self.spp = int(width), int(height), int(spp)
        self.alpha = bool(alpha)
        self.denoise = bool(denoise)
        self.threads = threads
        self.on_progress, self.on_done = on_progress, on_done
        self.error: BaseException | None = None
        self.state = "new"  # then "rendering", and at the end "written", "cancelled" or "failed"
        self.job = None
        self.started = None
        self.seconds = None
        self._finished = threading.Event()
        self._returned = threading.Event()  # set once ``on_done`` returned (see ``wait``)

    def start(self) -> "FinalRender":
        """Start rendering on worker threads; returns ``self``."""
        from ..tracer.job import RenderJob
        from ..tracer.job_options import JobObservers
        self.started = time.monotonic()
        self.state = "rendering"
        self.job = RenderJob(self.design, self.assets, width=self.width, height=self.height,
                             spp=self.spp, threads=self.threads,
                             observers=JobObservers(on_tile=self._tile, on_done=self._render_done))
        self.job.start()
        return self

    def cancel(self) -> None:
        """Stop within one tile; nothing is written."""
        if self.job is not None:
            self.job.cancel()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the render has ended (written, cancelled or failed) and ``on_done``
        returned: after a True, none of this render's code runs any more."""
        return self._returned.wait(timeout) and (self.job is None or self.job.wait(timeout))

    @property
    def done(self) -> bool:
        return self._finished.is_set()

    @property
    def written(self) -> bool:
        """Whether the file is complete on disk."""
        return self.state == "written"

    @property
    def progress(self) -> float:
        """Fraction done in [0, 1]; 1 only once the file is written."""
        if self.written:
            return 1.0
        return min(0.999, float(self.job.progress)) if self.job is not None else 0.0

    def time_left(self) -> float | None:
        """Estimated seconds to go (see :func:`time_left_s`), ``None`` when unknown."""
        if self.started is None:
            return None
        return time_left_s(time.monotonic() - self.started, self.progress)

    def _tile(self, job, tile) -> None:
        if self.on_progress is not None:
            self.on_progress(self)

    def _render_done(self, job) -> None:
        try:
            if job.error is not None:
                self.error, self.state = job.error, "failed"
            elif job.cancelled:
                self.state = "cancelled"
            else:
                write_final(job, self.design, self.assets, self.path, alpha=self.alpha, denoise=self.denoise)
                self.state = "written"
        except Exception as exc:  # reported to the caller, never lost
            self.error, self.state = exc, "failed"
        finally:
            self.seconds = time.monotonic() - (self.started or time.monotonic())
            self._finished.set()
            try:
                if self.on_done is not None:
                    self.on_done(self)
            finally:
                self._returned.set()
