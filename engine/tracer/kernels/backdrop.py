"""The stage's backdrop sweep as a surface: the ground's material on a curve and a wall.

Design rule: the sweep (a cyclorama: :func:`engine.tracer.kernels.intersect._sweep_hit`) is
the same sheet as the ground it rises from: a Lambertian base of the stage's colour under the
glossy riser's clear coat when the stage has one, so the floor, the curve and the wall meet
without a seam. Its light is sampled per hit with a control variate, as the ground's: the
irradiance of the sheet under the open environment (the whole sphere's hemisphere about its
normal, which the sweep keeps in one vertical plane: a table over its tilt,
``env_p[SWEEP_SKY:]``, :func:`engine.tracer.tables.stage.sweep_sky_irradiance`) is sent back
at once, less the environment along one cosine-distributed direction about the normal, whose
child brings what really arrives there (the ground with its sky grid, the bottle seen in it,
the sweep itself; the sky again where nothing is in the way, cancelling exactly: the bright
softboxes add no noise). One shadow ray per design light goes towards its centre
through the glass as the labels' (:func:`engine.tracer.kernels.finish.lit_by_lights`: glass
passes it unrefracted, so the lights' caustics do not reach the sweep; they fall on the
ground, where the lights stand above). Every hit sets :data:`~.ground.NOISY_BIT`: its light is
sampled, so its pixels get samples until they settle. The back of the sheet absorbs.

"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .finish import FROST_STREAM, lit_by_lights
from .ground import GROUND_STREAM, NOISY_BIT, light_frame
from .jit import JIT
from .materials import K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, MG_ALBEDO, MG_ALPHA, MG_COAT_IOR, coat
from .microfacet import rough_mirror
from .sampling import env_lookup, uniform01

AIR = 0
#: Where the sweep's open-sky table starts in the environment's row: its count of tilts, then
#: their rgb irradiance over pi (from up to level, evenly in angle).
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
def backdrop(sc, lab, fin, env_p, tex, it, bseed, kids, scratch):
    """The backdrop sweep at interaction ``it`` (module rule): ``(children, r, g, b, bits)``,
    the radiance factors sent back at once (times the branch's weight; negative where the control
    variate takes back what the child will bring) and the object-mask bits consulted
    (:data:`~.ground.NOISY_BIT`, the labels a shadow ray met)."""
    mat_f, mat = sc.mat_f, it.mat
    nx, ny, nz = it.nx, it.ny, it.nz
    cos_i = -(nx * it.dx + ny * it.dy + nz * it.dz)
    if cos_i <= 0.0:  # its back absorbs (a ray from behind the sweep ends there)
        return 0, 0.0, 0.0, 0.0, np.int64(0)
    bits = NOISY_BIT
    ar, ag, ab = mat_f[mat, MG_ALBEDO], mat_f[mat, MG_ALBEDO + 1], mat_f[mat, MG_ALBEDO + 2]
    nk, base = 0, 1.0
    ior = mat_f[mat, MG_COAT_IOR]
    if ior > 0.0:  # the riser's clear coat: its mirror branch, and what reaches the base
        base = coat(ior, it.dx, it.dy, it.dz, nx, ny, nz, cos_i, 1.0, kids, 0)
        if mat_f[mat, MG_ALPHA] > 0.0:
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, mat_f[mat, MG_ALPHA], it.dx, it.dy, it.dz, nx, ny, nz,
                         uniform01(bseed, FROST_STREAM), uniform01(bseed, FROST_STREAM + 1), kids, mat_f, mat, ior)
        nk = 1
    ar, ag, ab = base * ar, base * ag, base * ab
    # the diffuse base: a cosine-distributed direction about the normal (its weight is the albedo)
    u1, u2 = uniform01(bseed, GROUND_STREAM), uniform01(bseed, GROUND_STREAM + 1)
    ux, uy, uz, vx, vy, vz = light_frame(nx, ny, nz)
    r, phi = math.sqrt(u1), 2.0 * math.pi * u2
    a, b, c = r * math.cos(phi), r * math.sin(phi), math.sqrt(max(0.0, 1.0 - u1))
    wx, wy, wz = a * ux + b * vx + c * nx, a * uy + b * vy + c * ny, a * uz + b * vz + c * nz
    kids[nk, KD_X], kids[nk, KD_Y], kids[nk, KD_Z] = wx, wy, wz
    kids[nk, KW_R], kids[nk, KW_G], kids[nk, KW_B] = ar, ag, ab
    kids[nk, K_SIDE] = 0.0
    er = eg = eb = 0.0
    if env_p.shape[0] > SWEEP_SKY:  # the control variate, where its mean is known
        er, eg, eb = open_sweep(env_p, nx, ny, nz)
        lr, lg, lb = env_lookup(tex, env_p[0] * env_p[2], env_p[1], wx, wy, wz)
        er, eg, eb = er - lr, eg - lg, eb - lb
    if fin.lights.shape[0] > 0:
        dr, dg, db, lbits = lit_by_lights(sc, lab, fin.lights, it.obj, AIR, it.px, it.py, it.pz, nx, ny, nz,
                                          nx, ny, nz, nx, ny, nz, scratch)
        er, eg, eb = er + dr, eg + dg, eb + db
        bits |= lbits
    return nk + 1, ar * er, ag * eg, ab * eb, bits
