"""Surface finishes at a hit, compiled: relief-bent shading normals, frosted (rough) glass, caps.

Design rule: the integrator calls :func:`finish_hit` at a boundary only when the hit object
carries finish rows or its material is ``PLASTIC`` (one test per hit); otherwise it runs the
plain materials exactly as before, so a design without bumps or cap renders bit for bit as it
did. :func:`finish_hit` writes the branch's children itself:

* **Relief** (bump tiles on the bottle's outer surface or a closure part) bends the *shading*
  normal only (:func:`~engine.tracer.kernels.bumps.perturb_normal` from the summed slopes of
  the rows of the object whose band holds the hit), made consistent with the ray
  (:func:`~engine.tracer.kernels.bumps.consistent_normal`). The geometric normal still decides
  media: after the material wrote its children, any child on the wrong side of the *geometric*
  surface (a reflection that a bent normal sent into the glass, or a refraction sent back out)
  takes the direction the smooth geometric surface would give it
  (:func:`~engine.tracer.kernels.materials.keep_sides`). Its
  weight is kept, so energy is conserved and a relief can never make a branch travel inside a
  medium it is not in (no leak, no mismatch).
* **Frosted** rows make the glass a rough dielectric (GGX, roughness ``alpha``) and a frosted
  row on a closure part (its material's roughness) makes a metal or a plastic coat glossy:
  one visible microfacet per hit from the branch's own stream (``uniform01(seed, 7 / 8)``:
  deterministic), its single scattering compensated for the energy that bounces between
  microfacets (:mod:`~engine.tracer.kernels.microfacet`: a white furnace stays 1).
* ``PLASTIC`` (a closure): the coat's mirror branch (Fresnel of the coat IOR) plus the diffuse
  base returned as radiance at once: ``(1 - R) albedo (E_env(n) + sum_l V_l E_l max(0, n.l) /
  pi)`` with ``E_env`` the environment's cosine-weighted irradiance over pi (a prefiltered map
  in the environment's own layout, white 1 in a white environment; the scene's own occlusion of
  the environment is ignored) and ``V_l`` the transmittance of one shadow ray towards each
  distant light (:func:`lit_by_lights`: the labels' :func:`~engine.tracer.kernels.labels.
  shadow`, so closure parts block it, labels block it by alpha, glass and liquid pass ``1 - R``
  per interface and media absorb; a light behind the geometric surface is hidden by the part
  itself). The light that the base sends back out through the coat is not reduced by the
  coat's exit Fresnel (a small over-estimate that stays below 1 in a white furnace without
  lights).

The finish tuple (:mod:`engine.tracer.tables.finishes`): ``(obj_rows (n_obj, 2) int64 first/count
of each object's rows, kinds (n,) int64, params (n, P_COLS), atlas (m, 3) float32, irradiance
(h, w, 3) float32, lights (L, 6) float64 direction towards the light (unit) and RGB
irradiance, then glass (2, N_X, N_ALPHA, N_MU), mirror (N_ALPHA, N_MU) and mirror_avg
(N_ALPHA,) float64)``: the last three the albedo tables of
:mod:`~engine.tracer.kernels.microfacet`. Units mm.
"""
from __future__ import annotations

import math

from numba import njit

import numpy as np

from .bumps import FROSTED, P_ALPHA, P_V0, P_V1, consistent_normal, perturb_normal, surface_slope
from .intersect import O_KIND, PLANE, REVOLVED
from .labels import shadow
from .materials import (CONDUCTOR, M_KIND, MF_ALBEDO, MF_COAT_IOR, PLASTIC, SMOOTH_DIELECTRIC, coat,
                        conductor, keep_sides, smooth_dielectric)
from .microfacet import frosted_glass, rough_mirror
from .revolved import segment_v
from .roots import JIT, hypot2
from .sampling import env_lookup, uniform01

#: Streams of a branch's seed the frosted microfacet draws from (the integrator's Russian
#: roulette uses stream 0 of each child's seed).
FROST_STREAM = 7


@njit(**JIT)
def shading_frame(fin, seg, obj_i, k, part, px, py, pz, nx, ny, nz):
    """``(sx, sy, sz, alpha)``: the relief-bent unit shading normal (same orientation as the
    object's oriented normal ``n``) and the largest frosted roughness whose band holds the hit
    (0: smooth) at point ``p`` of object ``k`` (its segment row ``part``)."""
    obj_rows, kinds, params, atlas = fin[0], fin[1], fin[2], fin[3]
    first, count = obj_rows[k, 0], obj_rows[k, 1]
    rho = hypot2(px, py)
    okind = obj_i[k, O_KIND]
    if okind == REVOLVED:
        v = segment_v(seg, part, px, py, pz)
    elif okind == PLANE:
        v = rho
    else:
        v = pz
    theta = math.atan2(py, px)
    su = sv = 0.0
    alpha = 0.0
    for j in range(first, first + count):
        p = params[j]
        if kinds[j] == FROSTED:
            if v >= p[P_V0] and v <= p[P_V1]:
                alpha = max(alpha, p[P_ALPHA])
            continue
        a, b = surface_slope(kinds[j], p, atlas, theta, v, rho)
        su += a
        sv += b
    if su == 0.0 and sv == 0.0:
        return nx, ny, nz, alpha
    ex, ey = (px / rho, py / rho) if rho > 0.0 else (1.0, 0.0)
    # t_u = dp/dtheta / rho, t_v along the meridian towards increasing v (n = (T_z, -T_r))
    tvx, tvy, tvz = -nz * ex, -nz * ey, nx * ex + ny * ey
    sx, sy, sz = perturb_normal(nx, ny, nz, -ey, ex, 0.0, tvx, tvy, tvz, su, sv)
    return sx, sy, sz, alpha


@njit(**JIT)
def lit_by_lights(scene, lab, lights, k, medium, px, py, pz, nx, ny, nz, sx, sy, sz, fx, fy, fz,
                  roots, crit, ivals):
    """Irradiance over pi ``(r, g, b, bits)`` of the distant ``lights`` on a diffuse point ``p``
    of object ``k`` seen from ``medium``: oriented normal ``n``, shading normal ``s`` and
    geometric normal ``f`` both facing the seen side. Each light in front of both normals casts
    one shadow ray (:func:`~engine.tracer.kernels.labels.shadow`; ``bits`` the labels it
    consulted, for the sample's object mask)."""
    er = eg = eb = 0.0
    bits = np.int64(0)
    for q in range(lights.shape[0]):
        lx, ly, lz = lights[q, 0], lights[q, 1], lights[q, 2]
        c = sx * lx + sy * ly + sz * lz
        if c <= 0.0 or fx * lx + fy * ly + fz * lz <= 0.0:  # behind the part itself
            continue
        side = 1 if nx * lx + ny * ly + nz * lz >= 0.0 else -1
        tr, tg, tb, b = shadow(scene, lab, px, py, pz, lx, ly, lz, medium, k, side, roots, crit, ivals)
        bits |= b
        c /= math.pi
        er += c * tr * lights[q, 3]
        eg += c * tg * lights[q, 4]
        eb += c * tb * lights[q, 5]
    return er, eg, eb, bits


@njit(**JIT)
def finish_hit(fin, scene, lab, k, part, mat, px, py, pz, nx, ny, nz, dx, dy, dz, inc, trn, bseed, kids,
               env_p, roots, crit, ivals):
    """Children of a branch meeting object ``k`` (material ``mat``) at ``p`` with oriented
    geometric normal ``n``, or ``-1`` when no finish applies (module doc); ``lab`` the label
    tables, ``roots, crit, ivals`` intersection scratch (for shadow rays). Returns ``(children,
    r, g, b, bits)``: the radiance factors ``(r, g, b)`` the hit sends back at once (a diffuse
    base; multiply by the branch's weight) and the object-mask bits of the labels its shadow
    rays consulted."""
    seg, obj_i, media, mat_i, mat_f = scene[0], scene[4], scene[6], scene[7], scene[8]
    kind = mat_i[mat, M_KIND]
    bits = np.int64(0)
    if fin[0][k, 1] == 0 and kind != PLASTIC:
        return -1, 0.0, 0.0, 0.0, bits
    sx, sy, sz, alpha = shading_frame(fin, seg, obj_i, k, part, px, py, pz, nx, ny, nz)
    dn = nx * dx + ny * dy + nz * dz
    if dn < 0.0:
        fx, fy, fz = nx, ny, nz
    else:
        fx, fy, fz, sx, sy, sz = -nx, -ny, -nz, -sx, -sy, -sz
    sx, sy, sz = consistent_normal(sx, sy, sz, fx, fy, fz, dx, dy, dz)
    cos_i = -(dx * sx + dy * sy + dz * sz)
    er = eg = eb = 0.0
    eta = media[trn, 0] / media[inc, 0]
    u1, u2 = uniform01(bseed, FROST_STREAM), uniform01(bseed, FROST_STREAM + 1)
    if kind == SMOOTH_DIELECTRIC:
        if alpha > 0.0:
            nk = frosted_glass(fin[6], alpha, dx, dy, dz, sx, sy, sz, eta, u1, u2, kids)
        else:
            nk = smooth_dielectric(dx, dy, dz, sx, sy, sz, cos_i, eta, 1.0, kids, 0)
    elif kind == CONDUCTOR:
        nk = conductor(mat_f, mat, dx, dy, dz, sx, sy, sz, cos_i, 1.0, kids, 0)
        if alpha > 0.0:
            rough_mirror(fin[7], fin[8], alpha, dx, dy, dz, sx, sy, sz, u1, u2, kids, mat_f, mat, -1.0)
    elif kind == PLASTIC:
        base = coat(mat_f[mat, MF_COAT_IOR], dx, dy, dz, sx, sy, sz, cos_i, 1.0, kids, 0)
        nk = 1
        if alpha > 0.0:
            rough_mirror(fin[7], fin[8], alpha, dx, dy, dz, sx, sy, sz, u1, u2, kids, mat_f, mat,
                         mat_f[mat, MF_COAT_IOR])
        ir, ig, ib = env_lookup(fin[4], env_p[0], env_p[1], sx, sy, sz)
        if fin[5].shape[0] > 0:
            lr, lg, lb, bits = lit_by_lights(scene, lab, fin[5], k, inc, px, py, pz, nx, ny, nz, sx, sy, sz,
                                             fx, fy, fz, roots, crit, ivals)
            ir, ig, ib = ir + lr, ig + lg, ib + lb
        er = base * mat_f[mat, MF_ALBEDO] * ir
        eg = base * mat_f[mat, MF_ALBEDO + 1] * ig
        eb = base * mat_f[mat, MF_ALBEDO + 2] * ib
    else:
        nk = 0
    keep_sides(kids, nk, dx, dy, dz, fx, fy, fz, eta)
    return nk, er, eg, eb, bits
