"""The sky's light on the ground and the backdrop sweep, estimated once per design: the grids' cells.

Design rule: a cell's value is the ground's own control-variate estimate
(:func:`engine.tracer.kernels.ground.ground`) made with many probes at once at the cell's centre:
``n_side x n_side`` directions stratified over the ground's own probe window
(:func:`~.ground.probe_window`: the bottle's bounding cylinder, or the whole sky), each traced by the camera's own
integrator (:func:`~.integrator.trace_sample`, leaving the ground), less the open sky along it.
A probe's tree is cut where the ground's own probe would cut it: its branches weigh ``albedo x
share`` of the pixel's (at most :data:`MAX_CUT`). Cell ``c`` draws batch ``b``'s jitter from ``mix64(seed ^ c)`` and the batch: a grid is bit for
bit the same for any split of its cells into chunks and threads. The finish tables passed in carry no sky grid, so a probe
whose tree meets the ground again probes from there, as a render without the grid would.

The sweep grid's cells (:func:`sweep_cells`) are the backdrop's own control-variate estimate
(:func:`~.backdrop.backdrop`) made the same way at points of the sweep: probes stratified over
the cosine-weighted hemisphere about its normal, less the open model along each.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .backdrop import cosine_about, open_model, sweep_point
from .ground import probe_window
from .integrator import trace_sample
from .intersect import O_MAT
from .jit import INLINE, JIT
from .materials import MG_ALBEDO, MG_SHADOW
from .records import Cutoffs, Ray
from .sampling import branch_seed, env_lookup, mix64, uniform01


#: Columns of a cell's record: the sums over its probes of what arrives less the open sky
#: (rgb; what arrives, under the cylinder), of the squared luminance of that, the share of
#: the cosine-weighted sky the probes stand for, and 1 where the open sky was taken off (the
#: control variate: :func:`~.ground.probe_window`), 0 under the cylinder.
Y_R, Y_G, Y_B, Y_SQ, Y_SHARE, Y_CONTROLLED = range(6)
Y_COLS = 6
#: A probe's weight cut at most (the first reflection off glass, 4 %, is always traced).
MAX_CUT = 0.03


@njit(**INLINE)
def stratum(cs, batch, n_side, a, b):
    """``(k, u1, u2)``: probe ``k`` of a cell seeded ``cs``, in stratum ``(a, b)`` of batch
    ``batch``'s ``n_side x n_side`` square, and its jittered uniforms there."""
    k = (batch * n_side + a) * n_side + b
    return k, (a + uniform01(cs, 2 * k)) / n_side, (b + uniform01(cs, 2 * k + 1)) / n_side


@njit(**INLINE)
def probe_cut(cut, weight):
    """The render's cut-offs ``cut`` for a probe whose branch weighs ``weight`` in the pixel: its
    tree cut where the pixel's would be, at most at :data:`MAX_CUT`."""
    return Cutoffs(cut.max_depth, min(max(cut.min_weight, cut.min_weight / max(weight, 1e-9)), MAX_CUT),
                   cut.rr_weight, cut.max_nodes)


@njit(**JIT)
def sky_cells(tables, ground, z0, cells, idx, n_side, batch, seed, cut, work, rec, out):
    """Probe batch ``batch`` (``n_side^2`` stratified directions) of the cells ``idx`` (rows of
    ``cells``, ``(x, y)`` centres in mm on the ground plane ``z = z0`` of ground object
    ``ground``) into the same rows of ``out`` (``Y_*`` columns; module rule). ``rec``: the
    probes' :class:`~.records.Recorder` (:func:`~.integrator.trace_sample`'s; its rays none)."""
    sc, env_p, tex = tables.scene, tables.env, tables.texels
    mat = sc.geom.obj_i[ground, O_MAT]
    albedo = 1.0
    if sc.mat_f[mat, MG_SHADOW] < 0.5:
        albedo = max(sc.mat_f[mat, MG_ALBEDO], max(sc.mat_f[mat, MG_ALBEDO + 1], sc.mat_f[mat, MG_ALBEDO + 2]))
    scale, rot = env_p[0] * env_p[2], env_p[1]
    for j in range(idx.shape[0]):
        c = idx[j]
        px, py = cells[c, 0], cells[c, 1]
        cs = mix64(np.uint64(seed) ^ np.uint64(c))
        half_az, s_max, share, phi0, controlled = probe_window(sc.mat_f, mat, px, py, z0)
        # the tree's weight cut as the ground's own probe would meet it (its weight: albedo x share)
        cut_c = probe_cut(cut, albedo * share)
        sr = sg = sb = sq = 0.0
        for a in range(n_side):
            for b in range(n_side):
                k, u1, u2 = stratum(cs, batch, n_side, a, b)
                s = u1 * s_max
                phi = phi0 + (2.0 * u2 - 1.0) * half_az
                r = math.sqrt(max(0.0, 1.0 - s))
                wx, wy, wz = r * math.cos(phi), r * math.sin(phi), math.sqrt(s)
                lr, lg, lb, _, _, _ = trace_sample(tables, Ray(px, py, z0, wx, wy, wz), branch_seed(cs, k), cut_c, work,
                                                rec, ground)
                if controlled:
                    er, eg, eb = env_lookup(tex, scale, rot, wx, wy, wz)
                    lr, lg, lb = lr - er, lg - eg, lb - eb
                sr, sg, sb = sr + lr, sg + lg, sb + lb
                lum = (lr + lg + lb) / 3.0
                sq += lum * lum
        out[j, Y_R], out[j, Y_G], out[j, Y_B], out[j, Y_SQ] = sr, sg, sb, sq
        out[j, Y_SHARE] = share
        out[j, Y_CONTROLLED] = 1.0 if controlled else 0.0


@njit(**JIT)
def sweep_cells(tables, sweep, cells, idx, n_side, batch, seed, cut, work, rec, out):
    """Probe batch ``batch`` of the sweep grid's cells ``idx`` (rows of ``cells``: ``(u, s)`` in
    mm across and along the profile of sweep object ``sweep``, :func:`~.backdrop.sweep_point`)
    into the same rows of ``out`` (``Y_*`` columns, always controlled; module rule)."""
    sc, env_p, tex = tables.scene, tables.env, tables.texels
    row = sc.geom.obj_f[sweep]
    mat = sc.geom.obj_i[sweep, O_MAT]
    albedo = max(sc.mat_f[mat, MG_ALBEDO], max(sc.mat_f[mat, MG_ALBEDO + 1], sc.mat_f[mat, MG_ALBEDO + 2]))
    cut_c = probe_cut(cut, albedo)
    for j in range(idx.shape[0]):
        c = idx[j]
        px, py, pz, nx, ny, nz = sweep_point(row, cells[c, 0], cells[c, 1])
        cs = mix64(np.uint64(seed) ^ np.uint64(c))
        sr = sg = sb = sq = 0.0
        for a in range(n_side):
            for b in range(n_side):
                k, u1, u2 = stratum(cs, batch, n_side, a, b)
                wx, wy, wz = cosine_about(nx, ny, nz, u1, u2)
                lr, lg, lb, _, _, _ = trace_sample(tables, Ray(px, py, pz, wx, wy, wz), branch_seed(cs, k), cut_c, work,
                                                rec, sweep)
                er, eg, eb = open_model(env_p, tex, wx, wy, wz)
                lr, lg, lb = lr - er, lg - eg, lb - eb
                sr, sg, sb = sr + lr, sg + lg, sb + lb
                lum = (lr + lg + lb) / 3.0
                sq += lum * lum
        out[j, Y_R], out[j, Y_G], out[j, Y_B], out[j, Y_SQ] = sr, sg, sb, sq
        out[j, Y_SHARE], out[j, Y_CONTROLLED] = 1.0, 1.0
