"""Batch ray queries for tests, tools and benchmarks: nearest hits and radiance of any rays.

Design rule: thin compiled loops over the same kernels a render uses (nothing is re-implemented
here), so what a test checks is what a render does.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .integrator import trace_sample
from .intersect import nearest_hit, object_normal
from .jit import JIT_NRT
from .records import Ray, Recorder, Scratch
from .tile import make_work


@njit(**JIT_NRT)
def hits(geom, o, d, medium, last, side, out_t, out_k, out_part, out_n):
    """Nearest true hit of each ray ``o[i] + t d[i]`` against ``geom`` (see :func:`nearest_hit`)."""
    scratch = Scratch(np.zeros(16), np.zeros(5), np.zeros((64, 2)))
    for i in range(o.shape[0]):
        t, k, part, nx, ny, nz = nearest_hit(geom, Ray(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2]),
                                             medium[i], last[i], side[i], scratch)
        out_t[i], out_k[i], out_part[i] = t, k, part
        out_n[i, 0], out_n[i, 1], out_n[i, 2] = nx, ny, nz


@njit(**JIT_NRT)
def normals(geom, k, part, p, out):
    """Oriented normals of object ``k[i]`` of ``geom`` at points ``p[i]`` on its part ``part[i]``."""
    for i in range(p.shape[0]):
        nx, ny, nz = object_normal(geom, k[i], part[i], p[i, 0], p[i, 1], p[i, 2])
        out[i, 0], out[i, 1], out[i, 2] = nx, ny, nz


@njit(**JIT_NRT)
def radiance(tables, o, d, cut, out, counters, seed):
    """Radiance of each ray starting in air (the tree of :func:`trace_sample` through ``tables``,
    a :class:`~.records.Tables`), into ``out``; the counters add up in ``counters``; ray ``i``
    draws its random numbers (roulette, rough lobes) from stream ``seed + i``."""
    work = make_work(cut.max_depth)
    rec = Recorder(np.full(tables.scene.mat_i.shape[0], 255, np.int64), counters, np.zeros((0, 6), np.float32),
                   np.zeros(1, np.int64))
    for i in range(o.shape[0]):
        r, g, b, _, _, _ = trace_sample(tables, Ray(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2]),
                                     np.uint64(seed) + np.uint64(i), cut, work, rec)
        out[i, 0], out[i, 1], out[i, 2] = r, g, b
