"""``glassbench render PROJECT -o OUT.png|exr|tif``: render a project file headless.

Design rule: the CLI engineer's ``engine.cli`` parses arguments and calls
:func:`render_command` (also reachable as :func:`render_project`); this module loads the project,
runs a :class:`engine.tracer.job.RenderJob` while printing progress to stderr, and writes the
image with OpenImageIO: EXR as linear float32, PNG and TIFF tone-mapped to sRGB 8-bit.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

from ..errors import bounded
from ..files.atomic import replacing
from ..limits import check_image_size
from .job import RenderJob, tonemap_srgb8

IMAGE_SUFFIXES = (".png", ".exr", ".tif", ".tiff")


def save_image(path, image) -> None:
    """Write ``image`` ``(H, W, 3)`` linear float: ``.exr`` as float32, others as sRGB uint8.

    The file is replaced atomically (:func:`engine.files.atomic.replacing`): a failed or
    interrupted write leaves the previous image whole. Raises ``ValueError`` for an unknown
    suffix and ``OSError`` when the file cannot be written.
    """
    import OpenImageIO as oiio

    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in IMAGE_SUFFIXES:
        raise ValueError(f"cannot save {path!r}: the name must end in .png, .exr or .tif")
    img = np.asarray(image)
    h, w = img.shape[:2]
    if ext == ".exr":
        data, fmt = np.ascontiguousarray(img, dtype=np.float32), oiio.FLOAT
    else:
        data, fmt = np.ascontiguousarray(tonemap_srgb8(img)), oiio.UINT8
    with replacing(path, suffix=ext) as tmp:
        out = oiio.ImageOutput.create(tmp)
        if out is None:
            raise OSError(f"cannot write {path}: {bounded(oiio.geterror(), 200)}")
        try:
            ok = out.open(tmp, oiio.ImageSpec(w, h, 3, fmt)) and out.write_image(data)
            error = "" if ok else out.geterror()
        finally:
            ok = out.close() and ok
        if not ok:
            raise OSError(f"cannot write {path}: {bounded(error or oiio.geterror(), 200)}")


def render_command(project_path, out_path, width=None, height=None, spp=None, threads=None,
                   progress=True) -> int:
    """Render a ``.glassbench`` project to ``out_path``; returns the exit status (0 = written).

    ``width``, ``height`` (pixels) and ``spp`` override the project's render settings. With
    ``progress`` a percentage line is updated on stderr; the time taken is printed on stdout.
    Raises ``engine.errors.ProjectError`` for an unreadable project and ``ValueError`` for a bad
    output name; a failing render re-raises the worker's exception.
    """
    from ..files.project import load_project

    if os.path.splitext(os.fspath(out_path))[1].lower() not in IMAGE_SUFFIXES:
        raise ValueError(f"the output must end in .png, .exr or .tif, got {out_path!r}")
    design, assets = load_project(project_path)
    # The overrides combine with the project's own size: check what will really be rendered.
    check_image_size(width or design.render.width, height or design.render.height,
                     spp or design.render.spp, where="image ")
    t0 = time.perf_counter()
    job = RenderJob(design, assets, width=width, height=height, spp=spp, threads=threads, tile=64)
    job.start()
    while not job.wait(0.25):
        if progress:
            print(f"\rrendering {job.width}x{job.height} at {job.spp} spp: {100 * job.progress:5.1f} %",
                  end="", file=sys.stderr, flush=True)
    if progress:
        print(file=sys.stderr)
    if job.error is not None:
        raise job.error
    secs = time.perf_counter() - t0
    save_image(out_path, job.image())
    print(f"rendered {job.width}x{job.height}, {job.spp} spp, in {secs:.2f} s")
    return 0


def render_project(project_path, out_path, width=None, height=None, spp=None, threads=None,
                   progress=True) -> int:
    """Alias of :func:`render_command` (the name ``engine.cli`` looks up)."""
    return render_command(project_path, out_path, width, height, spp, threads, progress)
