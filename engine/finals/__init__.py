"""Final images: a finished render written as files, raw and (asked) denoised, with alpha.

Design rule: every final image (``glassbench render``, the Final image dialog, batch and
turntable frames, the review page's poster) is written by this one path: the film's raw image
and, with ``denoise``, its denoised estimate beside it (``NAME.EXT`` denoised, ``NAME.raw.EXT``
the film; each file's ``ImageDescription`` says which it is), the bottle's coverage cut out of
both when alpha is asked. It stands above the tracer and the file formats it joins and below
the batch and export packages that call it (tests/test_layers.py). Units: linear radiance in,
files out.
"""
from __future__ import annotations

import os


def write_final(job, design, assets, path, *, alpha: bool = False, denoise: bool = False) -> list[str]:
    """Write the finished ``job``'s image to ``path`` (atomically; PNG/EXR/TIFF), with the
    bottle's coverage as alpha when asked (and on a shadow catcher its shadow). With ``denoise``
    the image at ``path`` is the denoised estimate (:func:`engine.tracer.denoise.denoise_job`)
    and the raw film goes beside it (:func:`engine.tracer.denoise.raw_path`); each file's
    ``ImageDescription`` says which it is. Returns the paths written, the raw one first."""
    return save_final(path, final_images(job, design, assets, alpha=alpha, denoise=denoise))


def final_images(job, design, assets, *, alpha: bool = False, denoise: bool = False,
                 threads: int | None = None) -> list[tuple]:
    """The images of a finished ``job`` to save, as ``(rgb, alpha or None)`` pairs: the raw film
    first and, with ``denoise``, its denoised estimate (OIDN quality high on ``threads``, default
    the job's). With ``alpha`` the bottle's coverage (and a shadow catcher's shadow) is traced
    once and cut out of both (:func:`engine.tracer.picking.cutout_parts`). No files: a batch's
    worker calls this and the client names and saves the pairs (:func:`save_final`)."""
    from ..tracer.denoise import denoise_job
    rgb = job.image()
    images = [rgb]
    if denoise:  # (the film's own image and guides: the denoiser never touches the film)
        images.append(denoise_job(job, threads=threads))
    if not alpha:
        return [(image, None) for image in images]
    from ..tracer.picking import cut_out, cutout_parts
    parts = cutout_parts(design, assets, rgb.shape[1], rgb.shape[0])
    return [cut_out(image, parts) for image in images]


def final_outputs(path, images) -> list[tuple]:
    """``[(where, (rgb, alpha), note)]`` for :func:`final_images`' pairs of a render meant for
    ``path``: the raw image alone at ``path``, or the raw one beside it (``NAME.raw.EXT``,
    :func:`engine.tracer.denoise.raw_path`) and the denoised one at ``path``; each with the
    ``ImageDescription`` that says which it is."""
    from ..tracer.denoise import DENOISED_NOTE, RAW_NOTE, raw_path
    path = os.fspath(path)
    if len(images) == 1:
        return [(path, images[0], RAW_NOTE)]
    raw, denoised = images
    beside = raw_path(path)
    return [(beside, raw, RAW_NOTE), (path, denoised, DENOISED_NOTE.format(raw=os.path.basename(beside)))]


def save_final(path, images) -> list[str]:
    """Save :func:`final_images`' pairs as :func:`final_outputs` names them (each atomically);
    returns the paths written, the raw one first."""
    from ..files.images import save_image
    outputs = final_outputs(path, images)
    for where, (rgb, cov), note in outputs:
        save_image(where, rgb, cov, note)
    return [where for where, _, _ in outputs]
