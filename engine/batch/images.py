"""Image files of a batch or a final render: atomic writes, optional alpha, reading back.

Design rule: a file appears complete or not at all. Each write goes to a hidden temporary file
in the destination folder (same suffix, so the writer picks the same format), is flushed, and
is renamed over the destination; a failure removes the temporary file and leaves any older
file as it was. RGB images are written by the tracer's own
:func:`engine.tracer.cli_render.save_image`, so a batch frame is byte-for-byte what
``glassbench render`` writes. With alpha, PNG and TIFF carry straight (unassociated) alpha over
the sRGB colour; EXR carries premultiplied linear colour, as EXR readers expect.
"""
from __future__ import annotations

import contextlib
import os
import uuid

import numpy as np


@contextlib.contextmanager
def atomic_path(path: str):
    """Yield a temporary path beside ``path`` with its suffix; rename it to ``path`` on success."""
    folder = os.path.dirname(os.path.abspath(path)) or "."
    tmp = os.path.join(folder, f".partial-{uuid.uuid4().hex}{os.path.splitext(path)[1]}")
    # Created here, exclusively, with the umask's permissions; writers then fill it by name.
    os.close(os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
    try:
        yield tmp
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_bytes_atomic(path: str, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)


def write_image(path: str, rgb, alpha=None) -> None:
    """Write linear ``rgb`` ``(H, W, 3)`` (and ``alpha`` ``(H, W)`` in [0, 1]) to ``path`` atomically.

    The format follows the suffix (``.png``, ``.exr``, ``.tif``); PNG/TIFF are sRGB 8-bit.
    Raises ``OSError`` when the file cannot be written, ``ValueError`` for a bad suffix.
    """
    from ..tracer.cli_render import save_image
    # why a copy: an array that arrived from a Dask worker may be a read-only view of its
    # message buffer, which the image writer refuses
    rgb = np.array(rgb, dtype=np.float32, copy=True)
    with atomic_path(path) as tmp:
        if alpha is None:
            save_image(tmp, rgb)
        else:
            _write_rgba(tmp, rgb, np.asarray(alpha, dtype=np.float32))


def _write_rgba(path: str, rgb, alpha) -> None:
    import OpenImageIO as oiio
    from ..tracer.job import tonemap_srgb8
    h, w = rgb.shape[:2]
    a = np.clip(alpha, 0.0, 1.0)[..., None]
    if path.lower().endswith(".exr"):
        data, fmt = np.ascontiguousarray(np.concatenate([rgb * a, a], axis=2), dtype=np.float32), oiio.FLOAT
    else:
        a8 = np.round(a * 255.0).astype(np.uint8)
        data, fmt = np.ascontiguousarray(np.concatenate([tonemap_srgb8(rgb), a8], axis=2)), oiio.UINT8
    spec = oiio.ImageSpec(w, h, 4, fmt)
    spec.alpha_channel = 3
    if fmt == oiio.UINT8:
        spec.attribute("oiio:UnassociatedAlpha", 1)
    out = oiio.ImageOutput.create(path)
    if out is None:
        raise OSError(f"cannot write {path}: {oiio.geterror()}")
    try:
        if not out.open(path, spec) or not out.write_image(data):
            raise OSError(f"cannot write {path}: {out.geterror()}")
    finally:
        out.close()


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


def display_rgb8(path: str) -> np.ndarray:
    """An image file as sRGB ``uint8`` ``(H, W, 3)`` for thumbnails (EXR is tone-mapped)."""
    from ..tracer.job import tonemap_srgb8
    data = read_image(path)
    if data.dtype != np.uint8:
        return tonemap_srgb8(data[..., :3])
    return np.ascontiguousarray(data[..., :3])
