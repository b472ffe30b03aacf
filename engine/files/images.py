"""Image files glassbench writes and reads back: renders, final frames with alpha, thumbnails.

Design rule: one writer for every rendered image (``glassbench render``, final renders,
turntables and batches), so a frame is byte for byte the same whichever door wrote it. The
format follows the suffix: EXR holds linear float32 (premultiplied with alpha, as EXR readers
expect), PNG and TIFF the display encoding of :func:`engine.color.tonemap_srgb8` as 8-bit sRGB
(straight alpha over it). Every write replaces the file atomically
(:func:`engine.io.atomic.replacing`): a failed or interrupted write leaves the previous image
whole. OpenImageIO does the encoding.
"""
from __future__ import annotations

import os

import numpy as np

from ..color import tonemap_srgb8
from ..errors import bounded
from ..io.atomic import replacing

IMAGE_SUFFIXES = (".png", ".exr", ".tif", ".tiff")


def save_image(path, rgb, alpha=None, description: str | None = None) -> None:
    """Write linear ``rgb`` ``(H, W, 3)`` (and ``alpha`` ``(H, W)`` in [0, 1], optional) to ``path``,
    with ``description`` as its ``ImageDescription`` (what the image is: raw or denoised).

    Raises ``ValueError`` for a suffix other than :data:`IMAGE_SUFFIXES` and ``OSError`` when the
    file cannot be written.
    """
    import OpenImageIO as oiio

    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in IMAGE_SUFFIXES:
        raise ValueError(f"cannot save {path!r}: the name must end in .png, .exr or .tif")
    # why a copy: an array that arrived from a Dask worker may be a read-only view of its
    # message buffer, which the image writer refuses
    img = np.array(rgb, dtype=np.float32, copy=True)
    h, w = img.shape[:2]
    exr = ext == ".exr"
    if alpha is None:
        data = img if exr else tonemap_srgb8(img)
    else:
        a = np.clip(np.asarray(alpha, np.float32), 0.0, 1.0)[..., None]
        data = (np.concatenate([img * a, a], axis=2) if exr
                else np.concatenate([tonemap_srgb8(img), np.round(a * 255.0).astype(np.uint8)], axis=2))
    spec = oiio.ImageSpec(w, h, data.shape[2], oiio.FLOAT if exr else oiio.UINT8)
    if alpha is not None:
        spec.alpha_channel = 3
        if not exr:
            spec.attribute("oiio:UnassociatedAlpha", 1)
    if description:
        spec.attribute("ImageDescription", str(description))
    with replacing(path, suffix=ext) as tmp:
        out = oiio.ImageOutput.create(tmp)
        if out is None:
            raise OSError(f"cannot write {path}: {bounded(oiio.geterror(), 200)}")
        try:
            ok = out.open(tmp, spec) and out.write_image(np.ascontiguousarray(data))
            error = "" if ok else out.geterror()
        finally:
            ok = out.close() and ok
        if not ok:
            raise OSError(f"cannot write {path}: {bounded(error or oiio.geterror(), 200)}")


def read_image(path: str) -> np.ndarray:
    """The pixels of an image file as stored: float32 for EXR, uint8 otherwise, ``(H, W, C)``."""
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise OSError(f"cannot read {path}: {oiio.geterror()}")
    try:
        exr = path.lower().endswith(".exr")
        data = inp.read_image(0, 0, 0, inp.spec().nchannels, oiio.FLOAT if exr else oiio.UINT8)
    finally:
        inp.close()
    if data is None:
        raise OSError(f"cannot read {path}")
    return np.asarray(data)


def image_description(path) -> str:
    """An image file's ``ImageDescription`` (what :func:`save_image` was told the image is), ``""``
    when it has none; ``OSError`` when it cannot be read."""
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(os.fspath(path))
    if inp is None:
        raise OSError(f"cannot read {path}: {oiio.geterror()}")
    try:
        return inp.spec().get_string_attribute("ImageDescription")
    finally:
        inp.close()


def display_rgb8(path: str) -> np.ndarray:
    """An image file as sRGB ``uint8`` ``(H, W, 3)`` for thumbnails (EXR is tone-mapped)."""
    data = read_image(path)
    if data.dtype != np.uint8:
        return tonemap_srgb8(data[..., :3])
    return np.ascontiguousarray(data[..., :3])


def write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (reports, manifests, contact sheets)."""
    with replacing(path, suffix=os.path.splitext(os.fspath(path))[1]) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
