"""Light from far away: an equirectangular radiance map with the exact lookup of SPEC section 3.

Design rule: an :class:`EnvironmentMap` is an immutable float32 texel array ``(H, W, 3)``
(linear RGB radiance, row 0 = zenith, column centres at ``u = (i + 0.5) / W``) plus a scale and
a turn about +z; :meth:`EnvironmentMap.lookup` is the bilinear, u-periodic, pole-clamped lookup
of ../shared/oracle/SPEC.md section 3. Maps come from an EXR/HDR file (OpenImageIO) or from the
procedural built-in studio. No Qt here.
"""
from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass
from functools import lru_cache

import numpy as np


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

    Grey images are replicated to RGB; extra channels (alpha) are dropped. Raises ``ValueError``
    naming the file when it cannot be read.
    """
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(f"cannot read environment image {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        pixels = inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT)
    finally:
        inp.close()
    if pixels is None:
        raise ValueError(f"cannot decode environment image {path}")
    pixels = np.asarray(pixels, dtype=np.float32).reshape(spec.height, spec.width, spec.nchannels)
    if spec.nchannels == 1:
        pixels = np.repeat(pixels, 3, axis=2)
    pixels = np.ascontiguousarray(pixels[:, :, :3])
    if pixels.shape[0] < 2:
        raise ValueError(f"environment image {path} needs at least two rows")
    return np.nan_to_num(pixels, nan=0.0, posinf=0.0, neginf=0.0)


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


def _asset_texels(asset, assets) -> np.ndarray:
    """Texels for a project asset: a path, raw file bytes, or an array already decoded."""
    if assets is None or asset not in assets:
        raise ValueError(f"environment asset {asset!r} is not in the project")
    item = assets[asset]
    if isinstance(item, np.ndarray):
        return np.asarray(item, dtype=np.float32)[:, :, :3]
    if isinstance(item, (bytes, bytearray, memoryview)):
        suffix = os.path.splitext(str(asset))[1] or ".exr"
        with tempfile.TemporaryDirectory() as tmp:
            p = os.path.join(tmp, "env" + suffix)
            with open(p, "wb") as fh:
                fh.write(bytes(item))
            return read_radiance_image(p)
    return read_radiance_image(os.fspath(item))


def environment_from_design(environment, assets=None) -> EnvironmentMap:
    """Build the :class:`EnvironmentMap` for an ``engine.model.design.Environment``.

    ``kind == "studio"`` gives the procedural studio; ``kind == "file"`` reads ``assets[asset]``
    (a file path, the file's bytes, or an ``(H, W, 3)`` array). ``scale`` multiplies radiance
    and ``rotation_deg`` turns the map about +z.
    """
    if environment.kind == "studio":
        tex = studio_texels()
    elif environment.kind == "file":
        tex = _asset_texels(environment.asset, assets)
    else:
        raise ValueError(f"unknown environment kind {environment.kind!r} (expected studio or file)")
    return EnvironmentMap(tex, float(environment.scale), float(environment.rotation_deg))
