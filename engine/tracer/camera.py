"""Pinhole camera and sample positions, exactly as ../shared/oracle/SPEC.md section 2.

Design rule: pixel ``(i, j)`` (column, row) covers ``[i, i+1] x [j, j+1]`` in image-plane pixel
coordinates, ``(0, 0)`` top-left, ``y`` growing downwards. A pixel's value is the box-filtered
average over its square, estimated from sub-pixel sample positions. Sample ``k`` of a pixel is
a pure function of (pixel index, k) through a counter-based hash, so an image never depends on
the order in which tiles are traced or on the number of threads.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def pixel_offsets(pixel_index, sample_index):
    """Sub-pixel positions in [0, 1)^2 for the given pixels and sample numbers: those the
    render kernels use (:func:`engine.tracer.kernels.sampling.pixel_offset`).

    Parameters
    ----------
    pixel_index : array_like of int
        ``row * width + column`` (>= 0).
    sample_index : array_like of int
        Sample number within the pixel (>= 0); broadcast against ``pixel_index``.

    Returns
    -------
    ndarray, shape (N, 2)
        ``(dx, dy)`` offsets, deterministic in (pixel, sample): sample 0 is the centre, samples
        ``k >= 1`` the per-pixel Owen-scrambled Sobol points ``k - 1``.
    """
    from .kernels.sampling import pixel_offsets_batch

    p, k = np.broadcast_arrays(np.asarray(pixel_index, dtype=np.int64), np.asarray(sample_index, dtype=np.int64))
    p, k = np.ascontiguousarray(p.ravel()), np.ascontiguousarray(k.ravel())
    if np.any(p < 0) or np.any(k < 0):
        raise ValueError("pixel and sample indices must be >= 0")
    out = np.empty((p.size, 2))
    pixel_offsets_batch(p, k, out)
    return out


@dataclass(frozen=True)
class PinholeCamera:
    """A pinhole camera (SPEC 2) for an image of ``width x height`` pixels.

    ``eye``/``target`` in mm; ``fov_y_deg`` is the full vertical field of view. ``up`` must not be
    parallel to the viewing direction.
    """

    eye: tuple
    target: tuple
    up: tuple
    fov_y_deg: float
    width: int
    height: int

    @classmethod
    def from_design(cls, camera, width: int, height: int) -> "PinholeCamera":
        """Build from an ``engine.model.design.Camera`` and an image size in pixels."""
        return cls(tuple(map(float, camera.eye)), tuple(map(float, camera.target)),
                   tuple(map(float, camera.up)), float(camera.fov_y_deg), int(width), int(height))

    def basis(self):
        """``(forward, right, up', tan(fov/2))``: unit vectors of SPEC 2 and the half-angle tangent."""
        eye, tgt, up = (np.array(v, dtype=float) for v in (self.eye, self.target, self.up))
        f = tgt - eye
        f = f / np.linalg.norm(f)
        r = np.cross(f, up)
        nr = np.linalg.norm(r)
        if nr < 1e-12:
            raise ValueError("camera up vector is parallel to the viewing direction")
        r = r / nr
        return f, r, np.cross(r, f), math.tan(math.radians(self.fov_y_deg) / 2.0)

    def rays(self, x, y):
        """Primary rays through image-plane points ``(x, y)`` (pixels, y down).

        Returns
        -------
        origins, directions : ndarray, shape (N, 3)
            Origins are all ``eye`` (mm); directions are unit vectors (float64).
        """
        f, r, u, t = self.basis()
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        sx = (2.0 * x / self.width - 1.0) * t * self.width / self.height
        sy = (1.0 - 2.0 * y / self.height) * t
        d = f + sx[:, None] * r + sy[:, None] * u
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        o = np.broadcast_to(np.array(self.eye, dtype=float), d.shape).copy()
        return o, d

    def pixel_sample_rays(self, cols, rows, sample_index):
        """Rays for sample ``sample_index`` of pixels ``(cols, rows)`` (box filter, seeded positions)."""
        cols = np.asarray(cols)
        rows = np.asarray(rows)
        off = pixel_offsets(rows.astype(np.int64) * self.width + cols, sample_index)
        return self.rays(cols + off[:, 0], rows + off[:, 1])
