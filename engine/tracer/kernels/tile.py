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
from .labels import LB_HIT_N, record_sample
from .materials import KID_COLS, MAX_CHILDREN
from .roots import JIT, JIT_NRT
from .sampling import C_EYE, C_W, camera_ray, mix64, pixel_offset


@njit(**JIT_NRT)
def make_work(max_depth):
    """Scratch arrays for one worker: the stack (a depth-first tree holds at most
    ``MAX_CHILDREN - 1`` waiting siblings per level) and solver space."""
    cap = (MAX_CHILDREN - 1) * max_depth + 2
    return (np.zeros((cap, 9)), np.zeros((cap, 4), np.int64), np.zeros(cap, np.uint64),
            np.zeros(16), np.zeros(5), np.zeros((64, 2)), np.zeros((MAX_CHILDREN, KID_COLS)),
            np.zeros(MAX_CHILDREN, np.int64))


@njit(**JIT_NRT)
def render_pixels(scene, tex, env_p, cam, cols, rows, first, count, max_depth, min_weight,
                  rr_weight, rr_from, max_nodes, out_sum, out_sumsq, out_sig, out_mask, out_depth, counters, cancel,
                  rec_rays, rec_n, labels, finish):
    """Trace the listed samples of each pixel ``(cols[p], rows[p])``.

    Writes ``out_sum[p]`` (RGB radiance sum over the samples), ``out_sumsq[p]`` (sum of the
    squared per-sample mean of RGB, for noise estimates), ``out_sig[p]`` (the first sample's
    dominant-path signature), ``out_mask[p]`` (objects met, OR over samples) and min-s
    ``out_depth[p, m]`` (shallowest depth each material was met). Samples numbered ``rr_from``
    and up play Russian roulette below ``rr_weight`` (see :func:`trace_sample`); ``labels`` is
    the tuple of label tables :func:`trace_sample` takes. Stops early, leaving the
    rest untouched, once ``cancel[0]`` is non-zero; returns the number of pixels finished.
    ``finish`` is the finish tuple handed on to :func:`trace_sample`.
    """
    work = make_work(max_depth)
    return _render_loop(scene, tex, env_p, cam, cols, rows, first, count, max_depth, min_weight, rr_weight,
                        rr_from, max_nodes, out_sum, out_sumsq, out_sig, out_mask, out_depth, counters, cancel,
                        rec_rays, rec_n, labels, finish, work)


@njit(**JIT)
def _render_loop(scene, tex, env_p, cam, cols, rows, first, count, max_depth, min_weight, rr_weight, rr_from,
                 max_nodes, out_sum, out_sumsq, out_sig, out_mask, out_depth, counters, cancel, rec_rays, rec_n,
                 labels, finish, work):
    """The loop of :func:`render_pixels` over its pixels and samples, with the worker's scratch
    ``work``. Compiled without reference counting: from a kernel that counts references, each
    call of :func:`trace_sample` would increment and decrement the count of every array in its
    tuples (some forty, atomically, once per sample: 11 % of the Bordeaux frame, measured with
    ``perf``)."""
    width = int(cam[C_W])
    ex, ey, ez = cam[C_EYE], cam[C_EYE + 1], cam[C_EYE + 2]
    smp = 0
    for p in range(cols.shape[0]):
        if cancel[0] != 0:
            return p
        pix = rows[p] * width + cols[p]
        sr = sg = sb = ssq = 0.0
        mask = np.int64(0)
        for k in range(first[p], first[p] + count[p]):
            fx, fy = pixel_offset(pix, k)
            dx, dy, dz = camera_ray(cam, cols[p] + fx, rows[p] + fy)
            seed = mix64(np.uint64(pix) * np.uint64(0x9E3779B97F4A7C15) ^ np.uint64(k))
            h0 = labels[LB_HIT_N][0]
            r, g, b, sig, m = trace_sample(scene, tex, env_p, ex, ey, ez, dx, dy, dz, seed,
                                           max_depth, min_weight, rr_weight if k >= rr_from else 0.0,
                                           max_nodes, work, out_depth[p],
                                           counters, rec_rays, rec_n, labels, finish)
            record_sample(labels, smp, h0)
            smp += 1
            if k == first[p]:
                out_sig[p] = sig
            sr += r
            sg += g
            sb += b
            lum = (r + g + b) / 3.0
            ssq += lum * lum
            mask |= m
        out_sum[p, 0] += sr
        out_sum[p, 1] += sg
        out_sum[p, 2] += sb
        out_sumsq[p] += ssq
        out_mask[p] |= mask
    return cols.shape[0]
