"""Artwork and mask images: checked from their header, decoded once to linear float32 RGBA.

Design rule: an image reaches a label only through :func:`probe_image` (format by content,
size from the header, before a single texel is decoded) and :func:`decode_image` (the texels,
decoded once per distinct content: an LRU keyed by SHA-256, arrays read-only, shared by every
render). Accepted: PNG, JPEG, TIFF and EXR through OpenImageIO. Integer images (8/16-bit) are
sRGB and are decoded to linear; float images (EXR, float TIFF) are linear already and must be
finite. The result is ``(H, W, 4)`` float32, row 0 the artwork's top, **straight** (not
premultiplied) linear RGB in [0, 1] and alpha in [0, 1] (1 where the file has none). Anything
else (empty, corrupt, truncated, too large, too small, deep, NaN) is an :class:`ArtworkError`
of one line naming the image. No Qt here.
"""
from __future__ import annotations

import hashlib
import os
import struct
import threading
import zlib
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from .. import limits as L
from ..color import linear_to_srgb, srgb_to_linear
from ..errors import GlassbenchError, InputFileError, bounded, shown
from ..io.bytes_file import bytes_as_file
from ..io.quiet import captured_stderr
from ..io.read import read_bounded

#: Leading bytes of the formats artwork may have, and the extension OpenImageIO is told.
MAGIC = ((b"\x89PNG\r\n\x1a\n", ".png"), (b"\xff\xd8\xff", ".jpg"), (b"II*\x00", ".tif"),
         (b"MM\x00*", ".tif"), (b"v/1\x01", ".exr"))
#: Extensions of files the panels and command line offer as artwork.
EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr")


class ArtworkError(GlassbenchError, ValueError):
    """An image that cannot be label artwork or a mask; the message names it and says why."""


@dataclass(frozen=True)
class ImageInfo:
    """What an image's header says: size (texels), channels, format extension, float or not."""

    width: int
    height: int
    channels: int
    extension: str
    is_float: bool


def image_extension(data, name: str = "image") -> str:
    """The extension (``.png`` ...) of the format ``data`` starts like; ``ArtworkError`` if none."""
    if len(data) == 0:
        raise ArtworkError(f"{name} is empty (0 bytes)")
    for magic, ext in MAGIC:
        if bytes(data[:len(magic)]) == magic:
            return ext
    raise ArtworkError(f"{name} is not a PNG, JPEG, TIFF or EXR image")


def read_image_file(path) -> bytes:
    """The bytes of an image file, read no further than :data:`engine.limits.MAX_ARTWORK_BYTES`
    and checked with :func:`probe_image`; ``ArtworkError`` (or ``OSError``) otherwise."""
    path = os.fspath(path)
    try:
        data = read_bounded(path, L.MAX_ARTWORK_BYTES, "image")
    except InputFileError as exc:
        raise ArtworkError(str(exc)) from None
    probe_image(data, os.path.basename(path))
    return data


def _open(path: str, name: str, unassociated: bool = False):
    import OpenImageIO as oiio
    config = oiio.ImageSpec()
    if unassociated:
        config.attribute("oiio:UnassociatedAlpha", 1)  # PNG/TIFF alpha as stored, not multiplied in
    inp = oiio.ImageInput.open(path, config)
    if inp is None:
        raise ArtworkError(f"{name} is not a readable image ({bounded(oiio.geterror(), 160) or 'corrupt'})")
    return inp


def _info(spec, ext: str, name: str) -> ImageInfo:
    w, h, nch = int(spec.width), int(spec.height), int(spec.nchannels)
    if spec.deep:
        raise ArtworkError(f"{name} is a deep image; artwork must be flat")
    _check_size(w, h, name)
    if not 1 <= nch <= 64:
        raise ArtworkError(f"{name} has {nch} channels")
    return ImageInfo(w, h, nch, ext, str(spec.format) in ("half", "float", "double"))


def _check_size(w: int, h: int, name: str) -> None:
    if w < L.MIN_ARTWORK_SIDE or h < L.MIN_ARTWORK_SIDE:
        raise ArtworkError(f"{name} is {w} x {h} pixels; artwork needs at least "
                           f"{L.MIN_ARTWORK_SIDE} x {L.MIN_ARTWORK_SIDE} (a uniform face is a plain colour)")
    if max(w, h) > L.MAX_ARTWORK_SIDE or w * h > L.MAX_ARTWORK_TEXELS:
        raise ArtworkError(f"{name} is {w} x {h} pixels, more than artwork may have "
                           f"({L.MAX_ARTWORK_TEXELS} pixels, {L.MAX_ARTWORK_SIDE} a side)")


class _Decoded:
    """Decoded images by the SHA-256 of their bytes (an LRU of at most ``BUDGET`` texels), and
    the header of each content seen (an LRU of ``INFOS``). One lock: one decode per content."""

    BUDGET = L.MAX_DESIGN_ARTWORK_TEXELS
    INFOS = 256

    def __init__(self):
        self._lock = threading.Lock()
        self._images: OrderedDict[str, np.ndarray] = OrderedDict()
        self._infos: OrderedDict[str, ImageInfo] = OrderedDict()
        self.decodes = 0  # images decoded so far (tests count them)

    def info(self, data, name: str) -> ImageInfo:
        key = hashlib.sha256(data).hexdigest()
        with self._lock:
            hit = self._infos.get(key)
            if hit is None:
                ext = image_extension(data, name)
                if ext == ".png":
                    check_png_chunks(data, name)
                hit = _with_file(data, ext, lambda p: _probe_path(p, ext, name))
                self._infos[key] = hit
                while len(self._infos) > self.INFOS:
                    self._infos.popitem(last=False)
            self._infos.move_to_end(key)
            return hit

    def image(self, data, name: str) -> np.ndarray:
        key = hashlib.sha256(data).hexdigest()
        with self._lock:
            img = self._images.get(key)
            if img is None:
                ext = image_extension(data, name)
                img = _with_file(data, ext, lambda p: _decode_path(p, ext, name))
                img.setflags(write=False)
                self.decodes += 1
                self._images[key] = img
                while sum(a.shape[0] * a.shape[1] for a in self._images.values()) > self.BUDGET \
                        and len(self._images) > 1:
                    self._images.popitem(last=False)
            self._images.move_to_end(key)
            return img


def _with_file(data, ext: str, fn):
    # OpenImageIO's Python binding reads files only: one private temporary file per decode;
    # libpng and libtiff print on stderr by themselves, so their words are caught (kept only
    # when the decode fails, inside the one-line error).
    with bytes_as_file(data, ext, "image") as path:
        try:
            with captured_stderr():
                return fn(path)
        except ArtworkError as exc:  # the temporary's path means nothing to the user
            raise ArtworkError(str(exc).replace(f' ("{path}")', "").replace(path, "the file")) from None


def check_png_chunks(data, name: str) -> None:
    """Walk a PNG's chunks (length, type, CRC) to IEND; ``ArtworkError`` for a truncated or
    damaged one. libpng reports such files on the process's stderr by itself, so they are
    refused here first, with the usual one line; the IHDR size is checked on the way."""
    at, n, seen_ihdr = 8, len(data), False
    while True:
        if at + 12 > n:
            raise ArtworkError(f"{name} is truncated (the PNG ends before its IEND chunk)")
        length, kind = struct.unpack_from(">I4s", data, at)
        end = at + 12 + length
        if length > n or end > n:
            raise ArtworkError(f"{name} is truncated or damaged (a PNG chunk runs past the end of the file)")
        if not kind.isalpha() or (not seen_ihdr and kind != b"IHDR"):
            raise ArtworkError(f"{name} is a damaged PNG (bad chunk {shown(kind)})")
        if zlib.crc32(data[at + 4:end - 4]) != struct.unpack_from(">I", data, end - 4)[0]:
            raise ArtworkError(f"{name} is a damaged PNG (chunk {kind.decode()} fails its checksum)")
        if kind == b"IHDR":
            w, h = struct.unpack_from(">II", data, at + 8)
            _check_size(w, h, name)
            seen_ihdr = True
        if kind == b"IEND":
            return
        at = end


def _probe_path(path: str, ext: str, name: str) -> ImageInfo:
    inp = _open(path, name)
    try:
        return _info(inp.spec(), ext, name)
    finally:
        inp.close()


def _decode_path(path: str, ext: str, name: str) -> np.ndarray:
    import OpenImageIO as oiio
    inp = _open(path, name, unassociated=True)
    try:
        spec = inp.spec()
        info = _info(spec, ext, name)
        alpha = int(spec.alpha_channel)
        pixels = inp.read_image(0, 0, 0, info.channels, oiio.FLOAT)
        problem = inp.geterror() if inp.has_error else ""
    finally:
        inp.close()
    if pixels is None or problem:
        raise ArtworkError(f"{name} cannot be decoded (damaged or truncated: "
                           f"{bounded(problem or oiio.geterror(), 160) or 'no pixels'})")
    px = np.asarray(pixels, dtype=np.float32).reshape(info.height, info.width, info.channels)
    return to_linear_rgba(px, alpha, info.is_float, name)


def to_linear_rgba(px: np.ndarray, alpha_channel: int, is_float: bool, name: str = "image") -> np.ndarray:
    """Straight linear RGBA float32 ``(H, W, 4)`` from decoded channels ``(H, W, C)`` (module rule)."""
    h, w, nch = px.shape
    if is_float and not np.isfinite(px).all():
        raise ArtworkError(f"{name} holds NaN or infinite values")
    colour = [c for c in range(nch) if c != alpha_channel][:3]
    rgb = px[:, :, colour] if len(colour) == 3 else np.repeat(px[:, :, colour[:1]], 3, axis=2)
    a = px[:, :, alpha_channel] if 0 <= alpha_channel < nch else np.ones((h, w), np.float32)
    out = np.empty((h, w, 4), np.float32)
    a = np.clip(a, 0.0, 1.0)
    if is_float:  # EXR stores colour premultiplied by alpha: divide it back out
        with np.errstate(divide="ignore", invalid="ignore"):
            straight = np.where(a[..., None] > 0, rgb / a[..., None], 0.0)
        out[:, :, :3] = np.clip(straight, 0.0, 1.0)
    else:
        out[:, :, :3] = srgb_to_linear(np.clip(rgb, 0.0, 1.0))
    out[:, :, 3] = a
    return out


DECODED = _Decoded()


def probe_image(data, name: str = "image") -> ImageInfo:
    """The header of image bytes ``data`` (cached by content); ``ArtworkError`` unless it is
    an image artwork may be (module rule). Decodes no texels."""
    data = bytes(data) if not isinstance(data, bytes) else data
    return DECODED.info(data, str(name))


def decode_image(data, name: str = "image") -> np.ndarray:
    """Read-only straight linear RGBA float32 ``(H, W, 4)`` of image bytes (decoded once per
    content; module rule). Raises :class:`ArtworkError` naming ``name``."""
    data = bytes(data) if not isinstance(data, bytes) else data
    probe_image(data, name)  # the size is checked before anything is decoded
    return DECODED.image(data, str(name))


def display_rgba8(rgba: np.ndarray) -> np.ndarray:
    """sRGB uint8 ``(H, W, 4)`` of a decoded image, for showing it (and eyedroppers)."""
    out = np.empty(rgba.shape, np.uint8)
    out[..., :3] = np.round(linear_to_srgb(rgba[..., :3]) * 255.0)
    out[..., 3] = np.round(np.clip(rgba[..., 3], 0, 1) * 255.0)
    return out


def asset_image(assets, asset: str, what: str = "artwork") -> np.ndarray:
    """The decoded image of project asset ``asset`` (``ArtworkError`` if missing or bad)."""
    if assets is None or asset not in assets:
        raise ArtworkError(f"{what} {shown(asset)} is not in the project")
    return decode_image(assets[asset], f"{what} {shown(asset)}")
