"""The preview's denoiser: Intel Open Image Denoise over a whole frame, guided by albedo and normal.

Design rule: a denoised image is a biased estimate, shown and labelled as such and never fed
back: :class:`Denoiser` reads a copy of the film's image and its guides
(:meth:`engine.tracer.film.Film.guides`, from the kernels' dominant path:
:func:`engine.tracer.kernels.integrator.trace_sample`) and returns a new image; the film, the
adaptive rounds, relabel's records and "converged" never see it. It denoises whole frames (a
tile at a time would leave seams where the network sees different neighbours) on a device
whose threads are bounded (``numThreads``, no thread affinity), so the tracer's workers keep
their cores. The guides carry what the designer must see through the noise: the albedo of a
label's texel, the ground or a closure met through the glass (label text, die-cut edges) and
the first hit's shading normal (knurling, cut facets, relief); without them OIDN smears both.

OIDN ships in the ``pyoidn`` wheel (OIDN 2.5.1 and TBB; their licences in
``resources/licenses/``). Units: linear radiance in, linear radiance out (``hdr``).
"""
from __future__ import annotations

import threading

import numpy as np

from .job_options import lower_priority
from .retint import retinted

#: The preview denoiser's threads: one of the machine's cores, the tracer keeps the others.
PREVIEW_THREADS = 1
#: The preview denoiser's quality: OIDN's ``fast`` denoises the window's 715 x 953 frame in about
#: 1 s on one thread (``balanced`` 1.8 s, ``high`` 2.1 s; measured with the tracer busy beside
#: it), so a frame is shown within a wave (``python -m benchmarks.window_converge``).
PREVIEW_QUALITY = "fast"


class DenoiserUnavailable(RuntimeError):
    """OIDN cannot run here (``pyoidn`` missing or its device refused to start)."""


class Denoiser:
    """One OIDN ``RT`` filter on a CPU device of ``threads`` threads, reused across frames (its
    buffers follow the frame's size). Calls are serialised; safe from any thread.

    ``quality`` is OIDN's: ``"high"`` (final renders), ``"balanced"`` or ``"fast"`` (the window's
    preview, :data:`PREVIEW_QUALITY`, where a frame must be ready within a wave)."""

    def __init__(self, threads: int = PREVIEW_THREADS, quality: str = PREVIEW_QUALITY):
        self.threads = max(1, int(threads))
        self.quality = quality
        self._lock = threading.Lock()
        self._device = None
        self._filter = None

    def _start(self):
        """The committed device and filter (made at the first call)."""
        if self._filter is not None:
            return self._filter
        try:
            import pyoidn
        except ImportError as exc:  # (a dependency: pyproject installs it)
            raise DenoiserUnavailable(f"the denoiser needs pyoidn: {exc}") from exc
        qualities = {"high": pyoidn.OIDN_QUALITY_HIGH, "balanced": pyoidn.OIDN_QUALITY_BALANCED,
                     "fast": pyoidn.OIDN_QUALITY_FAST}
        if self.quality not in qualities:
            raise ValueError(f"denoiser quality must be one of {sorted(qualities)}, not {self.quality!r}")
        device = pyoidn.Device(pyoidn.OIDN_DEVICE_TYPE_CPU)
        device.set_int("numThreads", self.threads)
        device.set_bool("setAffinity", False)
        device.commit()
        problem = device.get_error()
        if problem:
            raise DenoiserUnavailable(f"the denoiser's device did not start: {problem}")
        flt = pyoidn.Filter(device, pyoidn.OIDN_FILTER_TYPE_RT)
        self._device, self._filter, self._quality = device, flt, qualities[self.quality]
        return flt

    def __call__(self, color: np.ndarray, albedo: np.ndarray | None = None,
                 normal: np.ndarray | None = None) -> np.ndarray:
        """The denoised ``color`` (linear radiance ``(H, W, 3)``, finite, >= 0), guided by
        ``albedo`` (``[0, 1]``) and ``normal`` (``[-1, 1]``), both ``(H, W, 3)`` or ``None``
        (a normal needs an albedo: OIDN's rule). Returns a new float32 image; the inputs are
        not changed."""
        import pyoidn
        color = _image(color, "color")
        shape = color.shape
        if normal is not None and albedo is None:
            raise ValueError("a normal guide needs an albedo guide")
        guides = [(pyoidn.OIDN_IMAGE_ALBEDO, albedo, "albedo"), (pyoidn.OIDN_IMAGE_NORMAL, normal, "normal")]
        with self._lock:
            flt = self._start()
            out = np.empty(shape, np.float32)
            flt.set_image(pyoidn.OIDN_IMAGE_COLOR, color, pyoidn.OIDN_FORMAT_FLOAT3)
            kept = [color, out]  # (OIDN reads these buffers until execute returns)
            for name, image, what in guides:
                if image is None:
                    flt.unset_image(name)
                    continue
                image = _image(image, what)
                if image.shape != shape:
                    raise ValueError(f"the {what} guide is {image.shape}, the image {shape}")
                flt.set_image(name, image, pyoidn.OIDN_FORMAT_FLOAT3)
                kept.append(image)
            flt.set_image(pyoidn.OIDN_IMAGE_OUTPUT, out, pyoidn.OIDN_FORMAT_FLOAT3)
            flt.set_bool("hdr", True)
            flt.set_quality(self._quality)
            flt.commit()
            flt.execute()
            problem = self._device.get_error()
            if problem:
                raise DenoiserUnavailable(f"the denoiser failed: {problem}")
        return np.maximum(np.nan_to_num(out, nan=0.0, posinf=0.0, neginf=0.0), 0.0)


def _image(a, what: str) -> np.ndarray:
    """``a`` as a C-contiguous float32 ``(H, W, 3)`` array (``ValueError`` otherwise)."""
    a = np.ascontiguousarray(a, np.float32)
    if a.ndim != 3 or a.shape[2] != 3 or min(a.shape[:2]) == 0:
        raise ValueError(f"the {what} image must be (height, width, 3), not {a.shape}")
    return a


#: What a written image says it is (its ``ImageDescription``).
RAW_NOTE = "glassbench: raw render (the tracer's film, unbiased)"
DENOISED_NOTE = ("glassbench: denoised estimate of the raw render {raw} (Intel Open Image Denoise 2.5.1, "
                 "albedo and normal guides; pixels whose own error is under a display level keep the raw "
                 "value; biased, not the converged image)")


def raw_path(path) -> str:
    """Where the raw image beside a denoised one at ``path`` goes: ``NAME.raw.EXT``."""
    import os
    stem, ext = os.path.splitext(os.fspath(path))
    return f"{stem}.raw{ext}"


def denoise_job(job, quality: str = "high", threads: int | None = None) -> np.ndarray:
    """The denoised linear image of a finished ``job`` (a final render's: ``quality`` high, all
    the job's threads, the tracer being done)."""
    return denoised_frame(job, Denoiser(threads or job.threads, quality))


def denoised_frame(job, denoiser: Denoiser) -> np.ndarray:
    """The denoised linear image ``(H, W, 3)`` of ``job``'s film as it is now (a copy of its
    image and guides; the film is not changed), blended per pixel with the raw film by
    :func:`raw_weight`: a pixel whose own error is already small keeps its raw value. Where the
    job traced a sketch (:mod:`engine.tracer.sketch`) the denoiser reads its samples pooled
    with the film's."""
    film = job.film
    raw = job.image()
    sk = getattr(job, "sketch", None)
    if sk is None or not getattr(job, "sketched", 0):
        return _blend(job, film, raw, denoiser(raw, *film.guides()))
    # the display-only sketch pooled with the film's samples (engine.tracer.sketch)
    sampled = job.aa_pixels() if film.has_centre.all() else None
    return _blend(job, film, raw, denoiser(*sk.pooled(film, sampled)), sampled=sampled)


def preview_frame(job, denoiser: Denoiser) -> np.ndarray | None:
    """The window's preview frame of ``job``'s film as it is now: for a colour-only edit (a
    job with a :attr:`~engine.tracer.job.RenderJob.retint` basis) the previous converged film
    retinted by this film's centres (:func:`engine.tracer.retint.retinted`, no denoiser: it is
    already a converged image's), else :func:`denoised_frame`; either blended with the raw film
    by :func:`raw_weight`. ``None`` when a retint has no centre yet (or a draft fills the film)."""
    basis = getattr(job, "retint", None)
    if basis is None:
        return denoised_frame(job, denoiser)
    film = job.film
    made = None if job.drafting else retinted(basis, film)
    if made is None:
        return None
    # the raw film's error must fall to the estimate's own before it shows (none at 3 times it):
    # on the jar at 179 x 238 after the last wave (display levels RMS from the converged image)
    # an inverse-variance mix kept some estimate in every pixel (1.3), raw from half the
    # estimate's error on (1.7), this 0.75
    estimate, error = made
    return _blend(job, film, job.image(), estimate, error, 3.0 * error)


def _blend(job, film, raw, estimate, below=None, above=None, sampled=False) -> np.ndarray:
    """``raw`` and ``estimate`` mixed per pixel by :func:`raw_weight` of ``job``'s ``film``
    (``below``, ``above``: its thresholds, the denoiser's by default; ``sampled``: the job's
    :meth:`~engine.tracer.job.RenderJob.aa_pixels` where the caller has them)."""
    if sampled is False:
        sampled = job.aa_pixels() if film.has_centre.all() else None
    weight = raw_weight(film, sampled, below, above)[..., None]
    return weight * raw + (1.0 - weight) * estimate


#: The raw film's own error (display levels, the standard error of a pixel's mean) below which
#: a pixel shows its raw value, and above which the denoiser's; linear in between. The raw
#: film's error falls as samples come, the denoiser's bias does not: on the jar at 715 x 953 the
#: blend keeps the denoiser's gain early (5.9 against 9.5 levels RMS after the centres) and
#: the raw film's detail late (mean FLIP 0.002 against the denoiser's 0.008 at convergence).
RAW_BELOW_LEVELS, DENOISED_ABOVE_LEVELS = 1.0, 3.0


def raw_weight(film, sampled=None, below=None, above=None) -> np.ndarray:
    """Each pixel's weight ``(H, W)`` in ``[0, 1]`` of the raw film against an estimate's (the
    denoiser's, or a retint's).

    A pixel with anti-aliasing samples is weighed by its own error (:func:`raw_levels`): at or
    under ``below`` -> 1, at or over ``above`` -> 0, linear between (display levels, scalars or
    ``(H, W)``; by default the denoiser's :data:`RAW_BELOW_LEVELS` and
    :data:`DENOISED_ABOVE_LEVELS`). A pixel that shows its
    centre alone keeps it where the rounds will not sample it (not in ``sampled``, the job's
    :meth:`~engine.tracer.job.RenderJob.aa_pixels`: a smooth pixel's centre is its value) and
    takes the denoiser's where they will (an edge not yet anti-aliased). Before every centre is
    traced (``sampled`` ``None``) and where only the preview's blocks are, the denoiser's."""
    below = RAW_BELOW_LEVELS if below is None else below
    above = DENOISED_ABOVE_LEVELS if above is None else above
    levels, centre_only = raw_levels(film)
    weight = np.clip((above - levels) / (above - below), 0.0, 1.0).astype(np.float32)
    if sampled is not None:
        weight[centre_only & ~sampled] = 1.0
    return weight


def raw_levels(film) -> tuple[np.ndarray, np.ndarray]:
    """``(error, centre_only)``: each pixel's own error ``(H, W)`` in display levels, the
    standard error of its anti-aliasing samples' mean luminance as the tone map shows it (from
    the film's sums of squares; stratified samples make it an overestimate, so the raw value is
    trusted late rather than early; ``inf`` below two samples), and the pixels that hold their
    centre alone."""
    from ..color import srgb_encode

    with film.lock:
        n = film.aa_count.astype(np.float64)
        total = film.aa_sum.mean(axis=2)
        sumsq = film.aa_sumsq.copy()
        centre = film.has_centre.copy()
    have = n >= 2
    m = total[have] / n[have]
    var = np.maximum(sumsq[have] / n[have] - m * m, 0.0) * n[have] / (n[have] - 1.0)
    se = np.sqrt(var / n[have])
    levels = np.full(n.shape, np.inf)
    # the error as the display shows it: the tone map's spread over mean +- one standard error
    levels[have] = 127.5 * (srgb_encode(m + se) - srgb_encode(np.maximum(m - se, 0.0)))
    return levels, centre & (n == 0)


class FrameDenoiser:
    """Denoises the newest frame asked for on a thread of its own, one frame at a time.

    :meth:`request` ``(key, job)`` asks for ``job``'s film as it is when the thread gets to it;
    a request made while one is being denoised replaces any that waits (only the newest frame
    matters), so the denoiser never falls behind the tracer. ``deliver(key, image, samples)``
    is called on that thread with the frame (:func:`preview_frame`: denoised, or retinted for
    a colour-only edit; linear) and the film's mean samples per pixel; ``failed(key,
    message)`` when OIDN fails. ``nice`` lowers the thread's priority (and
    that of OIDN's threads, which it starts) like the tracer's workers."""

    def __init__(self, deliver, failed=None, denoiser: Denoiser | None = None, nice: int = 0):
        self.deliver, self.failed = deliver, failed
        self.denoiser = denoiser or Denoiser()
        self.nice = int(nice)
        self._wanted = None
        self._cv = threading.Condition()
        self._closed = False
        self._busy = False
        self._thread = threading.Thread(target=self._run, name="preview-denoiser", daemon=True)
        self._thread.start()

    def request(self, key, job) -> None:
        """Denoise ``job``'s film (newest request wins); ``key`` comes back with the result."""
        with self._cv:
            self._wanted = (key, job)
            self._cv.notify()

    def idle(self) -> bool:
        """Whether nothing waits and nothing is being denoised."""
        with self._cv:
            return self._wanted is None and not self._busy

    def close(self, timeout: float = 10.0) -> None:
        """Stop the thread (after the frame it is on)."""
        with self._cv:
            self._closed = True
            self._wanted = None
            self._cv.notify()
        self._thread.join(timeout)

    def _run(self) -> None:
        lower_priority(self.nice)
        while True:
            with self._cv:
                while self._wanted is None and not self._closed:
                    self._cv.wait()
                if self._closed:
                    return
                (key, job), self._wanted = self._wanted, None
                self._busy = True
            try:
                image = preview_frame(job, self.denoiser)
                samples = float(job.film.samples().mean())
            except Exception as exc:  # why: a failed frame is reported, the preview stays raw
                if self.failed is not None:
                    self.failed(key, f"{type(exc).__name__}: {exc}")
            else:
                if image is not None:
                    self.deliver(key, image, samples)
            finally:
                with self._cv:
                    self._busy = False
