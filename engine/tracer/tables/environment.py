"""Light from far away: an equirectangular radiance map with the exact lookup of SPEC section 3.

Design rule: an :class:`EnvironmentMap` is an immutable float32 texel array ``(H, W, 3)``
(linear RGB radiance, row 0 = zenith, column centres at ``u = (i + 0.5) / W``) plus a scale and
a turn about +z; :meth:`EnvironmentMap.lookup` is the bilinear, u-periodic, pole-clamped lookup
of ../shared/oracle/SPEC.md section 3. Maps come from an EXR/HDR file (OpenImageIO) or from the
procedural built-in studio. Every texel is finite and in ``[0, MAX_TEXEL]`` (:func:`clean_texels`,
one rule for every source), and an embedded image is decoded once per distinct file content
(:data:`DECODED`). No Qt here.
"""
from __future__ import annotations

import hashlib
import math
import os
import threading
from collections import OrderedDict
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ...errors import bounded, shown
from ...io.bytes_file import bytes_as_file
from ...limits import (ENV_SCALE_RANGE, MAX_ENV_TEXELS, MAX_TEXEL, MAX_TURN_DEG, check_range)


@dataclass(frozen=True, eq=False)
class EnvironmentMap:
    """Equirectangular radiance (float32 ``(H, W, 3)``, H >= 2), times ``scale``, turned
    ``rotation_deg`` counter-clockwise about +z (seen from above)."""

    texels: np.ndarray
    scale: float = 1.0
    rotation_deg: float = 0.0

    def lookup(self, d):
        """Radiance arriving from far away along unit world directions ``d`` ``(N, 3)``.

        Returns ``(N, 3)`` float64, exactly SPEC 3: ``phi = atan2(dy, dx)`` (turned by
        ``-rotation_deg``), ``u = phi / 2pi mod 1``, ``v = acos(dz) / pi``, ``x = u W - 0.5`` wrapped,
        ``y = v (H - 1)``, bilinear with rows clamped to ``H - 2``.
        """
        d = np.asarray(d, dtype=float)
        tex = self.texels
        h, w = tex.shape[:2]
        phi = np.arctan2(d[:, 1], d[:, 0]) - math.radians(self.rotation_deg)
        u = np.mod(phi / (2.0 * math.pi), 1.0)
        v = np.arccos(np.clip(d[:, 2], -1.0, 1.0)) / math.pi
        x = np.mod(u * w - 0.5, w)
        y = v * (h - 1)
        i0 = np.floor(x).astype(np.int64)
        fx = (x - i0)[:, None]
        i0 = np.minimum(i0, w - 1)  # x == w after rounding of the mod
        i1 = (i0 + 1) % w
        j0 = np.minimum(np.floor(y).astype(np.int64), h - 2)
        fy = (y - j0)[:, None]
        j1 = j0 + 1
        with np.errstate(invalid="ignore", over="ignore"):  # non-finite maps are the caller's to drop
            top = tex[j0, i0] * (1.0 - fx) + tex[j0, i1] * fx
            bot = tex[j1, i0] * (1.0 - fx) + tex[j1, i1] * fx
            return (top * (1.0 - fy) + bot * fy) * self.scale


def read_radiance_image(path) -> np.ndarray:
    """Read a linear RGB image (EXR, HDR, ...) with OpenImageIO as float32 ``(H, W, 3)``.

    Grey images are replicated to RGB; extra channels (alpha) are never read. An image of more
    than :data:`engine.limits.MAX_ENV_TEXELS` texels is refused before its pixels are decoded,
    and the texels are cleaned by :func:`clean_texels`. Raises ``ValueError`` naming the file
    when it cannot be read.
    """
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(f"cannot read environment image {path}: {bounded(oiio.geterror(), 200)}")
    try:
        spec = inp.spec()
        w, h, nch = int(spec.width), int(spec.height), int(spec.nchannels)
        if w < 1 or h < 2 or nch < 1:
            raise ValueError(f"environment image {path} is {w} x {h} x {nch}; it needs at least "
                             f"one column, two rows and one channel")
        if w * h > MAX_ENV_TEXELS:
            raise ValueError(f"environment image {path} has {w} x {h} texels "
                             f"(limit {MAX_ENV_TEXELS}, e.g. 8192 x 4096)")
        pixels = inp.read_image(0, 0, 0, min(nch, 3), oiio.FLOAT)
    finally:
        inp.close()
    if pixels is None:
        raise ValueError(f"cannot decode environment image {path}")
    pixels = np.asarray(pixels, dtype=np.float32).reshape(h, w, min(nch, 3))
    if pixels.shape[2] != 3:
        pixels = np.repeat(pixels[:, :, :1], 3, axis=2)
    return clean_texels(np.ascontiguousarray(pixels))


def clean_texels(pixels: np.ndarray) -> np.ndarray:
    """The one rule for texel values, applied in float32 in place: NaN, -Inf and negative
    radiance become 0; +Inf and anything above :data:`engine.limits.MAX_TEXEL` become
    ``MAX_TEXEL``. Returns ``pixels`` (float32, every value in ``[0, MAX_TEXEL]``)."""
    np.nan_to_num(pixels, copy=False, nan=0.0, posinf=MAX_TEXEL, neginf=0.0)
    np.clip(pixels, 0.0, MAX_TEXEL, out=pixels)
    return pixels


def _smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


@lru_cache(maxsize=1)
def studio_texels(width: int = 1024, height: int = 512) -> np.ndarray:
    """The built-in studio as float32 ``(height, width, 3)`` texels (read-only).

    A dark floor, a floor-to-ceiling gradient and three soft-edged softboxes (key 6.0 at azimuth
    -115 deg, back strip 1.0 at +90 deg, overhead fill 3.5 at -40 deg), like the oracle's studio.
    """
    u = (np.arange(width) + 0.5) / width
    v = np.arange(height) / (height - 1)
    az = np.degrees(u * 2 * math.pi)  # azimuth from +x towards +y, [0, 360)
    el = 90.0 - v * 180.0  # elevation, +90 = zenith
    az_g, el_g = np.meshgrid(az, el)
    t = np.clip(el_g / 90.0, 0.0, 1.0)[..., None]
    ceiling = np.array([0.42, 0.45, 0.5])
    horizon = np.array([0.12, 0.12, 0.13])
    img = horizon * (1 - t) + ceiling * t
    floor = np.array([0.03, 0.03, 0.02])
    img = np.where((el_g < -2.0)[..., None], floor, img)

    def box(center_az, center_el, half_az, half_el, value, soft=3.0):
        daz = (az_g - center_az + 180.0) % 360.0 - 180.0
        m = (1 - _smoothstep(half_az - soft, half_az + soft, np.abs(daz))) * \
            (1 - _smoothstep(half_el - soft, half_el + soft, np.abs(el_g - center_el)))
        return m[..., None], np.array(value)

    for spec in ((-115.0, 20.0, 18.0, 25.0, (6.0, 5.8, 5.4)),
                 (90.0, 10.0, 4.0, 35.0, (0.92, 0.96, 1.0)),
                 (-40.0, 65.0, 20.0, 12.0, (3.5, 3.5, 3.5))):
        m, val = box(*spec)
        img = img * (1 - m) + val * m
    out = img.astype(np.float32)
    out.setflags(write=False)
    return out


class _DecodedCache:
    """Decoded environment images by the SHA-256 of their file bytes, so a render restart (or
    a project reopened) never decodes the same image again. The digest of a bytes object is
    remembered by identity (the object is kept alive with it, so its id cannot be reused), so
    a restart with the same assets does not even hash them again. Both tables are small LRUs."""

    MAPS = 2
    DIGESTS = 8

    def __init__(self):
        self._lock = threading.Lock()
        self._maps: OrderedDict[str, np.ndarray] = OrderedDict()
        self._digests: OrderedDict[int, tuple[object, str]] = OrderedDict()
        self.decodes = 0  # how many images were decoded (for tests and benchmarks)

    def _digest(self, data) -> str:
        hit = self._digests.get(id(data))
        if hit is not None and hit[0] is data:
            self._digests.move_to_end(id(data))
            return hit[1]
        digest = hashlib.sha256(data).hexdigest()
        self._digests[id(data)] = (data, digest)
        while len(self._digests) > self.DIGESTS:
            self._digests.popitem(last=False)
        return digest

    def texels(self, name: str, data) -> np.ndarray:
        """Read-only float32 texels of the image file ``data`` (bytes) called ``name``."""
        with self._lock:  # why: one decode even when two jobs start at once
            key = self._digest(data)
            tex = self._maps.get(key)
            if tex is None:
                tex = _decode_bytes(name, data)
                tex.setflags(write=False)
                self.decodes += 1
                self._maps[key] = tex
                while len(self._maps) > self.MAPS:
                    self._maps.popitem(last=False)
            self._maps.move_to_end(key)
            return tex


def _decode_bytes(name: str, data) -> np.ndarray:
    # OpenImageIO's Python binding reads files only: one temporary file, once per image.
    suffix = os.path.splitext(str(name))[1] or ".exr"
    with bytes_as_file(data, suffix, "env") as p:
        try:
            return read_radiance_image(p)
        except ValueError as exc:
            raise ValueError(str(exc).replace(p, f"asset {shown(str(name))}")) from None


DECODED = _DecodedCache()


def _asset_texels(asset, assets) -> np.ndarray:
    """Texels for a project asset: raw file bytes (decoded once, :data:`DECODED`), a path, or
    an array already decoded (cleaned by :func:`clean_texels` on a copy)."""
    if assets is None or asset not in assets:
        raise ValueError(f"environment asset {shown(asset)} is not in the project")
    item = assets[asset]
    if isinstance(item, np.ndarray):
        h, w = item.shape[:2] if item.ndim == 3 else (0, 0)
        if item.ndim != 3 or item.shape[2] < 3 or h < 2 or w < 1 or h * w > MAX_ENV_TEXELS:
            raise ValueError(f"environment asset {shown(asset)} must be (H >= 2, W, 3) texels, "
                             f"at most {MAX_ENV_TEXELS} of them; got shape {item.shape}")
        return clean_texels(np.array(item[:, :, :3], dtype=np.float32))
    if isinstance(item, (bytes, bytearray, memoryview)):
        return DECODED.texels(str(asset), bytes(item) if not isinstance(item, bytes) else item)
    return read_radiance_image(os.fspath(item))


#: Largest texel a half float holds with room to round (its largest is 65504).
HALF_MAX = 32768.0


class ArrayCache:
    """Values made from arrays (texel maps), by the array's identity: each array is kept alive
    with its value, so its id cannot be reused; the ``size`` most recent; thread-safe. The maps
    are shared and read-only (the studio, :data:`DECODED`'s), so what is made from one is made
    once, not at every edit's render context."""

    def __init__(self, size: int):
        self.size = size
        self._lock = threading.Lock()
        self._items: OrderedDict[int, tuple] = OrderedDict()

    def get(self, array: np.ndarray, build, key: tuple = ()):
        """``build(array)``, made on the first call for this array and ``key`` (hashable
        parameters the value also depends on)."""
        k = (id(array), *key)
        with self._lock:
            hit = self._items.get(k)
            if hit is not None and hit[0] is array:
                self._items.move_to_end(k)
                return hit[1]
        value = build(array)  # (outside the lock: different maps at once)
        with self._lock:
            self._items[k] = (array, value)
            while len(self._items) > self.size:
                self._items.popitem(last=False)
        return value


def _to_half(texels: np.ndarray) -> tuple:
    if not np.all(np.isfinite(texels)):  # (a map made in memory, not cleaned by clean_texels)
        texels = clean_texels(np.array(texels, np.float32))
    top = float(np.max(texels)) if texels.size else 0.0
    factor = 2.0 ** math.ceil(math.log2(top / HALF_MAX)) if top > HALF_MAX else 1.0
    bits = np.ascontiguousarray((texels / np.float32(factor)).astype(np.float16).view(np.uint16))
    bits.setflags(write=False)
    return bits, factor


_HALF = ArrayCache(2)  # (4-9 ms a conversion for 1024 x 512)


@lru_cache(maxsize=1)
def _converts_halves() -> bool:
    """Whether this CPU converts half floats in one instruction (x86-64 F16C, or ARM, where
    half floats are native). Elsewhere LLVM would call a runtime helper that numba's linker
    may not have: the kernels then read float32."""
    import platform

    import llvmlite.binding as ll

    if platform.machine().lower() in ("aarch64", "arm64"):
        return True
    try:
        return bool(ll.get_host_cpu_features().get("f16c", False))
    except RuntimeError:  # (a CPU llvmlite cannot describe)
        return False


def half_texels(texels: np.ndarray) -> tuple:
    """The render kernels' copy of float32 texels ``(H, W, 3)`` (in ``[0, MAX_TEXEL]``): the bit
    patterns (uint16) of half floats holding ``texels / factor``, and ``factor``, a power of two
    (1 unless a texel exceeds :data:`HALF_MAX`). A lookup reads half the bytes (the map is
    random access for rays scattered by glass: 6 MB of float32 texels miss the caches, 3 MB
    miss them less). Each texel keeps 11 significant bits (relative error <= 2**-11), down to
    ``factor * 2**-14``; below, an absolute error <= ``factor * 2**-25``. On a CPU without
    half-float conversion the float32 texels themselves, factor 1."""
    if not _converts_halves():
        return np.ascontiguousarray(texels, dtype=np.float32), 1.0
    if texels.flags.writeable:  # an array that may change: never cached
        return _to_half(texels)
    return _HALF.get(texels, _to_half)


def environment_from_design(environment, assets=None) -> EnvironmentMap:
    """Build the :class:`EnvironmentMap` for an ``engine.model.design.Environment``.

    ``kind == "studio"`` gives the procedural studio; ``kind == "file"`` reads ``assets[asset]``
    (a file path, the file's bytes, or an ``(H, W, 3)`` array). ``scale`` multiplies radiance
    (within :data:`engine.limits.ENV_SCALE_RANGE`, so radiance stays far inside float32) and
    ``rotation_deg`` turns the map about +z. Raises ``ValueError`` naming what is wrong.
    """
    check_range("design.environment.scale", environment.scale, ENV_SCALE_RANGE)
    check_range("design.environment.rotation_deg", environment.rotation_deg, (-MAX_TURN_DEG, MAX_TURN_DEG))
    if environment.kind == "studio":
        tex = studio_texels()
    elif environment.kind == "file":
        tex = _asset_texels(environment.asset, assets)
    else:
        raise ValueError(f"unknown environment kind {environment.kind!r} (expected studio or file)")
    return EnvironmentMap(tex, float(environment.scale), float(environment.rotation_deg))
