"""Samples of many pixels into film buffers: the one kernel a worker thread calls.

Design rule: :func:`render_pixels` traces samples ``first[p] .. first[p] + count[p] - 1`` of each
listed pixel and writes per-pixel sums into the caller's buffers; it touches nothing shared
except the read-only scene and a cancel flag it polls between pixels, so any number of threads
may run it at once (it holds no GIL) and a pixel's result depends only on (pixel, samples).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .integrator import trace_sample
from .jit import JIT, JIT_NRT
from .labels import record_sample
from .materials import KID_COLS, MAX_CHILDREN
from .records import Cutoffs, Ray, Recorder, Scratch, Work
from .sampling import C_EYE, C_W, camera_ray, mix64, pixel_offset


@njit(**JIT_NRT)
def make_work(max_depth):
    """Scratch for one worker (a :class:`~.records.Work`): the stack (a depth-first tree holds
    at most ``MAX_CHILDREN - 1`` waiting siblings per level), the children of a hit and the
    solvers' space."""
    cap = (MAX_CHILDREN - 1) * max_depth + 2
    return Work(np.zeros((cap, 9)), np.zeros((cap, 4), np.int64), np.zeros((cap, 2), np.uint64),
                np.zeros((MAX_CHILDREN, KID_COLS)), np.zeros(MAX_CHILDREN, np.int64),
                Scratch(np.zeros(16), np.zeros(5), np.zeros((64, 2))))


@njit(**JIT_NRT)
def render_pixels(tables, cam, px, cut, rr_from, out, cancel, rays):
    """Trace the listed samples of each pixel of ``px`` (a :class:`~.records.Pixels`).

    Adds into ``out`` (a :class:`~.records.PixelSums`): ``sum[p]`` (RGB radiance sum over the
    samples), ``sumsq[p]`` (sum of the squared per-sample mean of RGB, for noise estimates),
    ``sig[p]`` (the first sample's dominant-path signature), ``mask[p]`` (objects met, OR over
    samples), min-s ``depth[p, m]`` (shallowest depth each material was met), ``guide[p]`` (the
    sums of the denoiser's guides, albedo and normal) and the kernel counters. ``cut`` are the tree's cut-offs (:class:`~.records.Cutoffs`); samples numbered
    ``rr_from`` and up play Russian roulette below ``cut.rr_weight``, the others not (see
    :func:`~.integrator.trace_sample`); ``tables`` what the trees read (a
    :class:`~.records.Tables`), ``rays`` the ``(float32 (N, 6 or 9), count (1,))`` buffers every
    intersection query is copied into while room lasts (benchmarks; zero rows: none). Stops
    early, leaving the rest untouched, once ``cancel[0]`` is non-zero; returns the number of
    pixels finished.
    """
    work = make_work(cut.max_depth)
    return _render_loop(tables, cam, px, cut, rr_from, out, cancel, rays, work)


@njit(**JIT)
def _render_loop(tables, cam, px, cut, rr_from, out, cancel, rays, work):
    """The loop of :func:`render_pixels` over its pixels and samples, with the worker's scratch
    ``work``. Compiled without reference counting: from a kernel that counts references, each
    call of :func:`trace_sample` would increment and decrement the count of every array in its
    records (some forty, atomically, once per sample: 11 % of the Bordeaux frame, measured with
    ``perf``)."""
    cols, rows, first, count = px
    lab = tables.labels
    width = int(cam[C_W])
    ex, ey, ez = cam[C_EYE], cam[C_EYE + 1], cam[C_EYE + 2]
    plain = Cutoffs(cut.max_depth, cut.min_weight, 0.0, cut.max_nodes)
    smp = 0
    for p in range(cols.shape[0]):
        if cancel[0] != 0:
            return p
        pix = rows[p] * width + cols[p]
        pseed = mix64(np.uint64(pix) ^ np.uint64(0x2545F4914F6CDD1D))  # the pixel's, for every sample
        sr = sg = sb = ssq = 0.0
        mask = np.int64(0)
        rec = Recorder(out.depth[p], out.counters, rays[0], rays[1])  # (the pixel's, for every sample)
        for k in range(first[p], first[p] + count[p]):
            fx, fy = pixel_offset(pix, k)
            dx, dy, dz = camera_ray(cam, cols[p] + fx, rows[p] + fy)
            seed = mix64(np.uint64(pix) * np.uint64(0x9E3779B97F4A7C15) ^ np.uint64(k))
            h0 = lab.hit_n[0]
            r, g, b, sig, m, guide = trace_sample(tables, Ray(ex, ey, ez, dx, dy, dz), seed, cut if k >= rr_from else plain,
                                           work, rec, -1, k - 1, pseed)
            record_sample(lab, smp, h0)
            smp += 1
            if k == first[p]:
                out.sig[p] = sig
            sr += r
            sg += g
            sb += b
            lum = (r + g + b) / 3.0
            ssq += lum * lum
            mask |= m
            for j in range(6):
                out.guide[p, j] += guide[j]
        out.sum[p, 0] += sr
        out.sum[p, 1] += sg
        out.sum[p, 2] += sb
        out.sumsq[p] += ssq
        out.mask[p] |= mask
    return cols.shape[0]
