"""Per-tile work of a render: the frozen render context and the pure tile kernel.

Design rule: :class:`RenderContext` holds everything compiled from one ``Design`` snapshot
(geometry, materials, environment, camera, cut-offs). :func:`trace_tile_samples` traces given
sample numbers of given pixels and returns per-pixel sums; it touches no shared state, so any
number of threads may run it at once, and a pixel's result depends only on (pixel, sample
numbers), never on the tile it was grouped in.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .camera import PinholeCamera
from .environment import EnvironmentMap, environment_from_design
from .geometry import RenderGeometry, render_geometry_for
from .integrator import Materials, TraceStats, trace


@dataclass(frozen=True, eq=False)
class RenderContext:
    """The compiled scene for one render (immutable; shared read-only by worker threads)."""

    geometry: RenderGeometry
    materials: Materials
    environment: EnvironmentMap
    camera: PinholeCamera
    max_depth: int
    min_weight: float

    @classmethod
    def from_design(cls, design, assets=None, width=None, height=None) -> "RenderContext":
        """Compile a design (geometry comes from the value cache; see ``render_geometry_for``)."""
        w = int(width or design.render.width)
        h = int(height or design.render.height)
        return cls(render_geometry_for(design), Materials.from_design(design),
                   environment_from_design(design.environment, assets),
                   PinholeCamera.from_design(design.camera, w, h),
                   int(design.render.max_depth), float(design.render.min_weight))


def trace_tile_samples(ctx: RenderContext, cols, rows, first_sample, n_samples,
                       stats: TraceStats | None = None):
    """Trace samples ``first_sample .. first_sample + n_samples - 1`` of each listed pixel.

    Parameters
    ----------
    cols, rows : ndarray of int (P,)
        Pixel columns and rows (may repeat nothing; any order).
    first_sample, n_samples : ndarray of int (P,)
        Per-pixel first sample number and how many samples (>= 0).

    Returns
    -------
    sums : ndarray (P, 3) float64
        Sum of the samples' radiance per pixel.
    sumsq : ndarray (P,) float64
        Sum of the squared per-sample mean-of-RGB radiance (for noise estimates).
    """
    cols = np.asarray(cols, dtype=np.int64)
    rows = np.asarray(rows, dtype=np.int64)
    first = np.asarray(first_sample, dtype=np.int64)
    count = np.asarray(n_samples, dtype=np.int64)
    p = len(cols)
    # Sample-major order: each pixel's rays appear in increasing sample number whatever else
    # shares the batch, which keeps per-pixel sums bit-identical across tilings.
    idx, ks = [], []
    for j in range(int(count.max()) if p else 0):
        sel = np.nonzero(count > j)[0]
        idx.append(sel)
        ks.append(first[sel] + j)
    if not idx:
        return np.zeros((p, 3)), np.zeros(p)
    idx = np.concatenate(idx)
    ks = np.concatenate(ks)
    o, d = ctx.camera.pixel_sample_rays(cols[idx], rows[idx], ks)
    per_ray = trace(ctx.geometry, ctx.materials, ctx.environment, o, d, np.arange(len(idx)), len(idx),
                    max_depth=ctx.max_depth, min_weight=ctx.min_weight, stats=stats)
    lum = per_ray.mean(axis=1)
    sums = np.stack([np.bincount(idx, weights=per_ray[:, c], minlength=p) for c in range(3)], axis=1)
    sumsq = np.bincount(idx, weights=lum * lum, minlength=p)
    return sums, sumsq
