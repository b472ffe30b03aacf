"""The stage's backdrop sweep as a surface: the ground's material on a curve and a wall.

Design rule: the sweep (a cyclorama: :func:`engine.tracer.kernels.intersect._sweep_hit`) is
the same sheet as the ground it rises from: a Lambertian base of the stage's colour under the
glossy riser's clear coat when the stage has one, so the floor, the curve and the wall meet
without a seam. Its light from the environment is estimated with a control variate, as the
ground's: the
irradiance of the sheet with nothing in the way but an open floor (the environment above the
horizon, below it the open floor's radiance: the hemisphere about its normal, which the sweep
keeps in one vertical plane: a table over its tilt, ``env_p[SWEEP_SKY:]``,
:func:`engine.tracer.tables.stage.sweep_sky_irradiance`) is sent back at once, less that model
along one cosine-distributed direction about the normal, whose child brings what really
arrives there (the floor with its sky grid and the bottle's shadow, the bottle seen in it, the
sweep itself; the sky again where nothing is in the way, cancelling exactly: the bright
softboxes add no noise, and the floor, half of what the wall sees, only its departure from
open floor). Per hit that still leaves about 25 % scatter per sample on a plain surface that
fills the frame, so, as the ground's sky grid, the estimate is made once per design on a grid
over the sweep's own coordinates (:mod:`engine.tracer.tables.sweep`, many stratified probes per
cell: :func:`engine.tracer.kernels.sky.sweep_cells`) that a hit reads bilinearly
(:func:`sweep_irradiance`); only without the grid (a small image, a draft while it builds)
does a hit probe and set :data:`~.ground.NOISY_BIT`. One shadow ray per design light goes
towards its centre through the glass as the labels'
(:func:`engine.tracer.kernels.finish.lit_by_lights`: glass passes it unrefracted, so the lights'
caustics do not reach the sweep; they fall on the ground, where the lights stand above). The
back of the sheet absorbs.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .finish import FROST_STREAM, lit_by_lights
from .ground import GROUND_STREAM, NOISY_BIT, light_frame
from .intersect import F_COS, F_PZ, F_SIN, F_SW_RADIUS, F_SW_START
from .jit import INLINE, JIT
from .materials import K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, MG_ALBEDO, MG_ALPHA, MG_COAT_IOR, coat
from .microfacet import rough_mirror
from .sampling import env_lookup, uniform01

AIR = 0
#: Columns of the sweep grid's row (:mod:`engine.tracer.tables.sweep`): the grid's soft scale
#: (mm: cells are about ``A x`` the spacing of ``asinh`` steps, fine near the bottle's foot and
#: growing with distance), cells across and along the profile, the half width and the profile's
#: length covered (mm). Zero cells: no grid.
W_A, W_NU, W_NS, W_UMAX, W_SMAX = range(5)
W_COLS = 5
#: Where the sweep's open-sky table starts in the environment's row: its count of tilts, then
#: their rgb irradiance over pi (from up to level, evenly in angle), then the open floor's
#: radiance (rgb) the table assumes below the horizon.
SWEEP_SKY = 6


@njit(**JIT)
def open_sweep(env_p, nx, ny, nz):
    """The sweep's open-sky irradiance over pi ``(r, g, b)`` at unit normal ``n`` (module rule),
    linear in its tilt between the table's rows; zeros without a table."""
    if env_p.shape[0] <= SWEEP_SKY:
        return 0.0, 0.0, 0.0
    n = int(env_p[SWEEP_SKY])
    f = math.atan2(math.sqrt(nx * nx + ny * ny), nz) / (0.5 * math.pi) * (n - 1)
    f = min(max(f, 0.0), n - 1.0)
    i0 = min(int(f), n - 2)
    t = f - i0
    a, b = SWEEP_SKY + 1 + 3 * i0, SWEEP_SKY + 4 + 3 * i0
    return ((1.0 - t) * env_p[a] + t * env_p[b], (1.0 - t) * env_p[a + 1] + t * env_p[b + 1],
            (1.0 - t) * env_p[a + 2] + t * env_p[b + 2])


@njit(**JIT)
def sweep_point(row, u, s):
    """``(px, py, pz, nx, ny, nz)``: the point ``u`` mm across and ``s`` mm along the profile
    (0: where the curve leaves the floor) of the sweep whose ``obj_f`` row is ``row``, and its
    unit normal facing the bottle."""
    c, sn = row[F_COS], row[F_SIN]
    v0, r, z0 = row[F_SW_START], row[F_SW_RADIUS], row[F_PZ]
    quarter = 0.5 * math.pi * r
    if s < quarter:
        a = s / r
        v, z, nv, nz = v0 + r * math.sin(a), z0 + r - r * math.cos(a), -math.sin(a), math.cos(a)
    else:
        v, z, nv, nz = v0 + r, z0 + r + (s - quarter), -1.0, 0.0
    return c * v - sn * u, sn * v + c * u, z, c * nv, sn * nv, nz


@njit(**JIT)
def sweep_coords(row, px, py, pz):
    """``(u, s)`` (mm) of the sweep point ``p`` (:func:`sweep_point`'s inverse)."""
    c, sn = row[F_COS], row[F_SIN]
    v0, r, z0 = row[F_SW_START], row[F_SW_RADIUS], row[F_PZ]
    u = -sn * px + c * py
    zc = z0 + r
    if pz <= zc:
        return u, r * math.atan2(max(c * px + sn * py - v0, 0.0), zc - pz)
    return u, 0.5 * math.pi * r + (pz - zc)


@njit(**INLINE)
def _grid_f(x, a, n, xmax):
    """The cell coordinate (cell ``i`` spans ``[i, i + 1)``) of ``x >= 0`` mm on an axis of ``n``
    cells ``asinh``-spaced out to ``xmax``."""
    return math.asinh(x / a) / math.asinh(xmax / a) * n


@njit(**JIT)
def sweep_irradiance(fin, row, px, py, pz):
    """``(r, g, b, inside)``: the environment's light on the sweep at its point ``p`` (mm;
    ``row`` its ``obj_f`` row) from the sweep grid, bilinear between cell centres, and whether
    the grid covers it (else zeros: the caller probes)."""
    g = fin.sweep_grid
    nu, ns = int(g[W_NU]), int(g[W_NS])
    if nu <= 0:
        return 0.0, 0.0, 0.0, False
    u, s = sweep_coords(row, px, py, pz)
    if abs(u) > g[W_UMAX] or s > g[W_SMAX]:
        return 0.0, 0.0, 0.0, False
    half = 0.5 * nu
    fu = half + math.copysign(_grid_f(abs(u), g[W_A], half, g[W_UMAX]), u) - 0.5
    fs = _grid_f(s, g[W_A], ns, g[W_SMAX]) - 0.5
    fu, fs = min(max(fu, 0.0), nu - 1.0), min(max(fs, 0.0), ns - 1.0)
    i0, j0 = min(int(fu), nu - 2), min(int(fs), ns - 2)
    tu, ts = fu - i0, fs - j0
    w = fin.sweep
    k00, k10, k01, k11 = j0 * nu + i0, j0 * nu + i0 + 1, (j0 + 1) * nu + i0, (j0 + 1) * nu + i0 + 1
    w00, w10, w01, w11 = (1.0 - tu) * (1.0 - ts), tu * (1.0 - ts), (1.0 - tu) * ts, tu * ts
    return (w00 * w[k00, 0] + w10 * w[k10, 0] + w01 * w[k01, 0] + w11 * w[k11, 0],
            w00 * w[k00, 1] + w10 * w[k10, 1] + w01 * w[k01, 1] + w11 * w[k11, 1],
            w00 * w[k00, 2] + w10 * w[k10, 2] + w01 * w[k01, 2] + w11 * w[k11, 2], True)


@njit(**INLINE)
def open_model(env_p, tex, wx, wy, wz):
    """What the control variate assumes arrives along unit ``w``: the environment above the
    horizon, the open floor below it (module rule)."""
    if wz > 0.0:
        return env_lookup(tex, env_p[0] * env_p[2], env_p[1], wx, wy, wz)
    f = SWEEP_SKY + 1 + 3 * int(env_p[SWEEP_SKY])
    return env_p[f], env_p[f + 1], env_p[f + 2]


@njit(**INLINE)
def cosine_about(nx, ny, nz, u1, u2):
    """A unit direction drawn cosine-distributed about unit ``n`` from uniforms ``u1, u2``."""
    ux, uy, uz, vx, vy, vz = light_frame(nx, ny, nz)
    r, phi = math.sqrt(u1), 2.0 * math.pi * u2
    a, b, c = r * math.cos(phi), r * math.sin(phi), math.sqrt(max(0.0, 1.0 - u1))
    return a * ux + b * vx + c * nx, a * uy + b * vy + c * ny, a * uz + b * vz + c * nz


@njit(**JIT)
def backdrop(tables, it, bseed, kids, scratch):
    """The backdrop sweep at interaction ``it`` (module rule), reading ``tables`` (a
    :class:`~.records.Tables`): ``(children, r, g, b, bits)``,
    the radiance factors sent back at once (times the branch's weight; negative where the control
    variate takes back what the child will bring) and the object-mask bits consulted
    (:data:`~.ground.NOISY_BIT`, the labels a shadow ray met)."""
    sc, fin, env_p, tex = tables.scene, tables.finishes, tables.env, tables.texels
    mat_f, mat = sc.mat_f, it.mat
    nx, ny, nz = it.nx, it.ny, it.nz
    cos_i = -(nx * it.dx + ny * it.dy + nz * it.dz)
    if cos_i <= 0.0:  # its back absorbs (a ray from behind the sweep ends there)
        return 0, 0.0, 0.0, 0.0, np.int64(0)
    bits = np.int64(0)
    ar, ag, ab = mat_f[mat, MG_ALBEDO], mat_f[mat, MG_ALBEDO + 1], mat_f[mat, MG_ALBEDO + 2]
    nk, base = 0, 1.0
    ior = mat_f[mat, MG_COAT_IOR]
    if ior > 0.0:  # the riser's clear coat: its mirror branch, and what reaches the base
        base = coat(ior, it.dx, it.dy, it.dz, nx, ny, nz, cos_i, 1.0, kids, 0)
        if mat_f[mat, MG_ALPHA] > 0.0:
            bits |= NOISY_BIT
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, mat_f[mat, MG_ALPHA], (it.dx, it.dy, it.dz), (nx, ny, nz),
                         uniform01(bseed, FROST_STREAM), uniform01(bseed, FROST_STREAM + 1), kids, mat_f, mat, ior)
        nk = 1
    ar, ag, ab = base * ar, base * ag, base * ab
    er, eg, eb, gridded = sweep_irradiance(fin, sc.geom.obj_f[it.obj], it.px, it.py, it.pz)
    if not gridded:  # beyond the sweep grid (or while it builds): the diffuse base sampled here
        bits |= NOISY_BIT
        # the diffuse base: a cosine-distributed direction about the normal (its weight is the albedo)
        wx, wy, wz = cosine_about(nx, ny, nz, uniform01(bseed, GROUND_STREAM), uniform01(bseed, GROUND_STREAM + 1))
        kids[nk, KD_X], kids[nk, KD_Y], kids[nk, KD_Z] = wx, wy, wz
        kids[nk, KW_R], kids[nk, KW_G], kids[nk, KW_B] = ar, ag, ab
        kids[nk, K_SIDE] = 0.0
        nk += 1
        if env_p.shape[0] > SWEEP_SKY:  # the control variate, where its mean is known
            er, eg, eb = open_sweep(env_p, nx, ny, nz)
            lr, lg, lb = open_model(env_p, tex, wx, wy, wz)
            er, eg, eb = er - lr, eg - lg, eb - lb
    if fin.lights.shape[0] > 0:
        dr, dg, db, lbits = lit_by_lights(tables, fin.lights, it, AIR, (nx, ny, nz, nx, ny, nz), scratch)
        er, eg, eb = er + dr, eg + dg, eb + db
        bits |= lbits
    return nk, ar * er, ag * eg, ab * eb, bits
