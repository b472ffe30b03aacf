"""Finishes at a hit, compiled: the shading frame a relief bends, frosting, and the light on a
closure's diffuse base.

Design rule: lookups only; what a finish does to a branch is the surface layer's
(:func:`engine.tracer.kernels.surface.scatter` and its bump adapter). Here:

* :func:`shading_frame`: the *shading* normal a relief bends the geometric one to
  (:func:`~engine.tracer.kernels.bumps.perturb_normal` from the summed slopes of the rows of
  the object whose band holds the hit) and the roughness of a frosted band there (GGX ``alpha``:
  the glass becomes a rough dielectric, a closure's metal or plastic coat glossy; one visible
  microfacet per hit from the branch's own stream ``uniform01(seed, 7 / 8)``, its single
  scattering compensated for the energy that bounces between microfacets,
  :mod:`~engine.tracer.kernels.microfacet`: a white furnace stays 1).
* :func:`lit_by_lights`: for ``PLASTIC`` (a closure), whose coat's mirror branch (Fresnel of the
  coat IOR) is a child and whose diffuse base is returned as radiance at once: ``(1 - R)
  albedo (E_env(n) + sum_l V_l E_l max(0, n.l) / pi)`` with ``E_env`` the environment's
  cosine-weighted irradiance over pi (a prefiltered map in the environment's own layout, white
  1 in a white environment; the scene's own occlusion of the environment is ignored) and
  ``V_l`` the transmittance of one shadow ray towards each distant light (the labels'
  :func:`~engine.tracer.kernels.labels.shadow`, so closure parts block it, labels block it by
  alpha, glass and liquid pass ``1 - R`` per interface and media absorb; a light behind the
  geometric surface is hidden by the part itself). The light that the base sends back out
  through the coat is not reduced by the coat's exit Fresnel (a small over-estimate that stays
  below 1 in a white furnace without lights).

The finish tables (:class:`~engine.tracer.kernels.records.FinishTables`, built by
:mod:`engine.tracer.tables.finishes`): each object's first row and count (int64), kinds (int64),
parameter rows (``P_COLS``), the relief atlas (float32), the closure's irradiance table (float32)
and lights (``(L, 6)``: unit direction towards the light, RGB irradiance), then the albedo tables
of :mod:`~engine.tracer.kernels.microfacet`. Units mm.
"""
from __future__ import annotations

import math

from numba import njit

import numpy as np

from .bumps import FROSTED, P_ALPHA, P_V0, P_V1, perturb_normal, surface_slope
from .intersect import F_COS, F_SIN, O_KIND, O_XS, PLANE, REVOLVED, SWEPT
from .labels import shadow
from .outlines import OUTLINE
from .plans import TWO_PI, plan_girth
from .profile import wall_r
from .revolved import segment_v
from .jit import INLINE, JIT
from .roots import hypot2

#: Streams of a branch's seed the frosted microfacet draws from (the integrator's Russian
#: roulette uses stream 0 of each child's seed).
FROST_STREAM = 7


@njit(**INLINE)
def _girth_frame(geom, k, part, px, py, pz):
    """``(theta, rho, ex, ey)`` of a point on the wall of an outline bottle (swept object ``k``,
    slab row ``part``): the girth fraction as an angle ``2 pi l / L`` (rad) and the equivalent
    radius ``L / 2 pi`` (mm) of :func:`~.plans.plan_girth`, so a tile's ``u = theta R`` runs
    along the outline's arc length (``du/ds = R / rho`` as on a round wall), and the section's
    outward unit normal ``(ex, ey)`` (world), across which ``t_u`` runs."""
    cos_r, sin_r = geom.obj_f[k, F_COS], geom.obj_f[k, F_SIN]
    rows = geom.slab_i[part]
    core, grow = wall_r(geom.seg, rows[0], pz), wall_r(geom.seg, rows[1], pz)
    x, y = cos_r * px + sin_r * py, -sin_r * px + cos_r * py
    length, total, gx, gy = plan_girth(geom.plan, core, grow, x, y)
    if not total > 0.0:
        return 0.0, 0.0, cos_r * gx - sin_r * gy, sin_r * gx + cos_r * gy
    return TWO_PI * length / total, total / TWO_PI, cos_r * gx - sin_r * gy, sin_r * gx + cos_r * gy


@njit(**JIT)
def shading_frame(fin, geom, k, part, px, py, pz, nx, ny, nz):
    """``(sx, sy, sz, alpha)``: the relief-bent unit shading normal (same orientation as the
    object's oriented normal ``n``) and the largest frosted roughness whose band holds the hit
    (0: smooth) at point ``p`` of object ``k`` of ``geom`` (its segment or slab row ``part``).
    Around a round wall ``u`` follows the polar angle; around an outline its arc length
    (:func:`_girth_frame`)."""
    obj_rows, kinds, params, atlas = fin.obj_rows, fin.kinds, fin.params, fin.atlas
    first, count = obj_rows[k, 0], obj_rows[k, 1]
    rho = hypot2(px, py)
    ex, ey = (px / rho, py / rho) if rho > 0.0 else (1.0, 0.0)
    okind = geom.obj_i[k, O_KIND]
    theta = math.atan2(py, px)
    if okind == REVOLVED:
        v = segment_v(geom.seg, part, px, py, pz)
    elif okind == PLANE:
        v = rho
    else:
        v = pz
        if okind == SWEPT and geom.obj_i[k, O_XS] == OUTLINE:
            theta, rho, ex, ey = _girth_frame(geom, k, part, px, py, pz)
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
    # t_u across the section's outward normal e, t_v along the meridian towards increasing v
    tvx, tvy, tvz = -nz * ex, -nz * ey, nx * ex + ny * ey
    sx, sy, sz = perturb_normal(nx, ny, nz, -ey, ex, 0.0, tvx, tvy, tvz, su, sv)
    return sx, sy, sz, alpha


@njit(**JIT)
def lit_by_lights(tables, lights, it, medium, frame, scratch):
    """Irradiance over pi ``(r, g, b, bits)`` of the distant ``lights`` on the diffuse point of
    interaction ``it`` (its object, point and oriented normal ``n``) seen from ``medium``;
    ``frame`` is ``(f, s)``: the geometric and the shading normal, both facing the seen side. Each light in front of both normals casts
    one shadow ray (:func:`~engine.tracer.kernels.labels.shadow`; ``bits`` the labels it
    consulted, for the sample's object mask)."""
    sc, lab = tables.scene, tables.labels
    px, py, pz, nx, ny, nz, k = it.px, it.py, it.pz, it.nx, it.ny, it.nz, it.obj
    fx, fy, fz, sx, sy, sz = frame
    er = eg = eb = 0.0
    bits = np.int64(0)
    for q in range(lights.shape[0]):
        lx, ly, lz = lights[q, 0], lights[q, 1], lights[q, 2]
        c = sx * lx + sy * ly + sz * lz
        if c <= 0.0 or fx * lx + fy * ly + fz * lz <= 0.0:  # behind the part itself
            continue
        side = 1 if nx * lx + ny * ly + nz * lz >= 0.0 else -1
        tr, tg, tb, b = shadow(sc, lab, px, py, pz, lx, ly, lz, medium, k, side, scratch)
        bits |= b
        c /= math.pi
        er += c * tr * lights[q, 3]
        eg += c * tg * lights[q, 4]
        eb += c * tb * lights[q, 5]
    return er, eg, eb, bits
