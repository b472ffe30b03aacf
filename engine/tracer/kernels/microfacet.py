"""Rough (GGX) surfaces, compiled: one visible microfacet per hit, and the energy its single
scattering loses given back.

Design rule: a rough surface draws one microfacet normal ``m`` from the distribution of GGX
normals *visible* from the incident direction (Heitz 2018), from the branch's own random
stream (deterministic), and sends its branches through it:

* a **rough dielectric** (frosted glass) both branches: reflection with weight ``F(m) G1(o_r)``
  and refraction with ``(1 - F(m)) G1(o_t)``; with visible-normal sampling ``f cos / pdf`` of
  each lobe reduces to exactly that (``D``, ``|i.m|`` and the Jacobian cancel; separable Smith
  ``G2 = G1(i) G1(o)``);
* a **rough mirror** (a metal, or a plastic's coat) the reflection, weight ``F(m) G1(o_r)``.

That is an unbiased one-sample estimate of the *single-scattering* BSDF, whose albedo ``E`` is
below 1: light that a microfacet sends into a neighbour (the ``1 - G1`` part) is lost: a
quarter at alpha 0.5 leaving glass head-on, 40 % at grazing. The multiple scattering between
microfacets gives it back (energy compensation; tables of ``E`` from
:mod:`engine.tracer.tables.ggx_albedo`, built by :func:`glass_albedo` / :func:`mirror_albedo` from the
very weights drawn here, so they agree):

* glass: both weights are divided by ``E(cos_i, alpha, eta)``, the albedo (reflection plus
  transmission) of that side of the interface (Turquin 2019 for dielectrics). A white furnace
  then returns 1 on average from either side (within the tables' interpolation, < 1 % near
  grazing, ~1e-3 elsewhere), total internal reflection included, and
  reflection and transmission keep the single-scattering split (what multiple scattering adds
  is shared as the single bounce shares it: plausible, not reciprocal in transmission);
* a mirror: each channel's weight is scaled by ``1 + k (1 - E) / E`` with ``E`` the albedo of
  the same surface with ``F = 1`` and ``k = F_avg E_avg / (1 - F_avg (1 - E_avg))`` (Kulla &
  Conty 2017's Fresnel of the multiple bounces over ``F_avg``; ``F_avg`` the cosine-weighted
  mean Fresnel of the material, tint included, ``E_avg`` that of ``E``): exactly 1 on average
  where ``F = 1``, and a coloured metal gains the more saturated colour of its repeated
  bounces, never more than the white one.

Tables (``engine.tracer.tables.ggx_albedo.albedo_tables``): ``glass (2, N_X, N_ALPHA, N_MU)`` (side 0
entering the denser medium, ``eta = n``; side 1 leaving it, ``eta = 1 / n``), ``mirror
(N_ALPHA, N_MU)`` and ``mirror_avg (N_ALPHA,)``, on uniform grids of ``cos_i`` in [0, 1], alpha
in [0, :data:`ALPHA_MAX`] and ``x = (n - 1) / (n + 1)`` in [0, :data:`X_MAX`] (n up to 3;
larger ratios and roughnesses use the last entry), looked up (multi)linearly.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .bumps import ggx_g1, onb
from .materials import (K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, MF_K, MF_N, MF_TINT,
                        fresnel_conductor, fresnel_dielectric)
from .jit import INLINE, JIT, JIT_NRT

#: Grid of the albedo tables: cos(theta_i), GGX alpha, x = (n - 1) / (n + 1) of the index ratio.
N_MU, N_ALPHA, N_X = 33, 26, 26
ALPHA_MAX, X_MAX = 0.5, 0.5
#: ``mat_f`` columns (CONDUCTOR and PLASTIC) of the material's mean Fresnel ``F_avg`` (RGB).
MF_FAVG = 9
#: The smallest albedo divided by: weights grow at most 4-fold. Only an interface of nearly
#: matched indices (n < 1.1) at grazing incidence has less (its refraction masked at the
#: horizon); there the compensation falls short rather than send out rare huge weights.
E_FLOOR = 0.25


@njit(**JIT)
def vndf_sample(alpha, wx, wy, wz, u1, u2):
    """Visible GGX microfacet normal (local frame, ``z`` the shading normal) for the unit
    direction ``w`` (``wz > 0``, pointing away from the surface), from uniforms ``u1, u2``
    (Heitz 2018, isotropic): ``m . w > 0`` always."""
    hx, hy, hz = alpha * wx, alpha * wy, wz
    h = math.sqrt(hx * hx + hy * hy + hz * hz)
    hx, hy, hz = hx / h, hy / h, hz / h
    lensq = hx * hx + hy * hy
    if lensq > 0.0:
        il = 1.0 / math.sqrt(lensq)
        t1x, t1y, t1z = -hy * il, hx * il, 0.0
    else:
        t1x, t1y, t1z = 1.0, 0.0, 0.0
    t2x, t2y, t2z = hy * t1z - hz * t1y, hz * t1x - hx * t1z, hx * t1y - hy * t1x
    r = math.sqrt(u1)
    phi = 2.0 * math.pi * u2
    a, b = r * math.cos(phi), r * math.sin(phi)
    s = 0.5 * (1.0 + hz)
    b = (1.0 - s) * math.sqrt(max(0.0, 1.0 - a * a)) + s * b
    c = math.sqrt(max(0.0, 1.0 - a * a - b * b))
    mx = a * t1x + b * t2x + c * hx
    my = a * t1y + b * t2y + c * hy
    mz = a * t1z + b * t2z + c * hz
    mx, my, mz = alpha * mx, alpha * my, max(mz, 1e-12)
    lm = math.sqrt(mx * mx + my * my + mz * mz)
    return mx / lm, my / lm, mz / lm


@njit(**JIT)
def visible_microfacet(alpha, dx, dy, dz, sx, sy, sz, u1, u2):
    """``(m, cos_im)``: a visible GGX microfacet normal (world) for the ray direction ``d``
    meeting shading normal ``s`` (facing the incident side), and ``-d . m`` (>= 0)."""
    (b1x, b1y, b1z), (b2x, b2y, b2z) = onb(sx, sy, sz)
    wx = -(dx * b1x + dy * b1y + dz * b1z)
    wy = -(dx * b2x + dy * b2y + dz * b2z)
    wz = max(-(dx * sx + dy * sy + dz * sz), 1e-9)
    lx, ly, lz = vndf_sample(alpha, wx, wy, wz, u1, u2)
    mx = lx * b1x + ly * b2x + lz * sx
    my = lx * b1y + ly * b2y + lz * sy
    mz = lx * b1z + ly * b2z + lz * sz
    cos_im = max(-(dx * mx + dy * my + dz * mz), 0.0)
    return mx, my, mz, cos_im


@njit(**JIT)
def visible_reflection(alpha, dx, dy, dz, sx, sy, sz, u1, u2):
    """``(r, cos_im, g)``: the reflection ``r`` of ``d`` about one visible microfacet (module
    rule), ``-d . m`` and the masking ``G1(r)`` of the reflected direction."""
    mx, my, mz, cos_im = visible_microfacet(alpha, dx, dy, dz, sx, sy, sz, u1, u2)
    rx, ry, rz = dx + 2.0 * cos_im * mx, dy + 2.0 * cos_im * my, dz + 2.0 * cos_im * mz
    g = ggx_g1(alpha, rx * sx + ry * sy + rz * sz, rx * mx + ry * my + rz * mz)
    return rx, ry, rz, cos_im, g


@njit(**JIT)
def rough_dielectric(alpha, dx, dy, dz, sx, sy, sz, eta, u1, u2, scale, kids):
    """Both branches through one visible microfacet of a GGX interface (module rule), their
    weights times ``scale``, into ``kids``; ``s`` the shading normal facing the incident side
    (``d . s < 0``), ``eta`` the index ratio transmitted / incident. Returns the number of
    children (1 under total internal reflection at the microfacet, else 2)."""
    mx, my, mz, cos_im = visible_microfacet(alpha, dx, dy, dz, sx, sy, sz, u1, u2)
    refl, cos_t = fresnel_dielectric(cos_im, eta)
    rx, ry, rz = dx + 2.0 * cos_im * mx, dy + 2.0 * cos_im * my, dz + 2.0 * cos_im * mz
    g = ggx_g1(alpha, rx * sx + ry * sy + rz * sz, rx * mx + ry * my + rz * mz)
    kids[0, KD_X], kids[0, KD_Y], kids[0, KD_Z] = rx, ry, rz
    kids[0, KW_R] = kids[0, KW_G] = kids[0, KW_B] = refl * g * scale
    kids[0, K_SIDE] = 0.0
    if refl >= 1.0:
        return 1
    q = cos_im / eta - cos_t
    tx, ty, tz = dx / eta + q * mx, dy / eta + q * my, dz / eta + q * mz
    h = math.sqrt(tx * tx + ty * ty + tz * tz)
    tx, ty, tz = tx / h, ty / h, tz / h
    g = ggx_g1(alpha, tx * sx + ty * sy + tz * sz, tx * mx + ty * my + tz * mz)
    kids[1, KD_X], kids[1, KD_Y], kids[1, KD_Z] = tx, ty, tz
    kids[1, KW_R] = kids[1, KW_G] = kids[1, KW_B] = (1.0 - refl) * g * scale
    kids[1, K_SIDE] = 1.0
    return 2


# ------------------------------------------------------------------ albedo tables: lookup
@njit(**INLINE)
def _cell(v, v_max, n):
    """``(i, w)``: ``v`` in [0, v_max] (clamped) lies ``w`` of the way from grid node ``i``
    to ``i + 1`` of ``n`` uniform nodes."""
    f = min(max(v / v_max, 0.0), 1.0) * (n - 1)
    i = min(int(f), n - 2)
    return i, f - i


@njit(**JIT)
def _bilinear(t, ia, wa, im, wm):
    """Bilinear value of the ``(alpha, mu)`` table ``t`` in cell ``(ia, im)``."""
    lo = t[ia, im] * (1.0 - wm) + t[ia, im + 1] * wm
    hi = t[ia + 1, im] * (1.0 - wm) + t[ia + 1, im + 1] * wm
    return lo * (1.0 - wa) + hi * wa


@njit(**JIT)
def glass_albedo_at(glass, alpha, cos_i, eta):
    """Single-scattering albedo (reflection + transmission) of a GGX interface of roughness
    ``alpha`` met at ``cos_i`` (to the shading normal), ``eta`` transmitted / incident."""
    n = eta if eta >= 1.0 else 1.0 / eta
    side = 0 if eta >= 1.0 else 1
    ix, wx = _cell((n - 1.0) / (n + 1.0), X_MAX, N_X)
    ia, wa = _cell(alpha, ALPHA_MAX, N_ALPHA)
    im, wm = _cell(cos_i, 1.0, N_MU)
    return (_bilinear(glass[side, ix], ia, wa, im, wm) * (1.0 - wx)
            + _bilinear(glass[side, ix + 1], ia, wa, im, wm) * wx)


@njit(**JIT)
def frosted_glass(glass, alpha, dx, dy, dz, sx, sy, sz, eta, u1, u2, kids):
    """:func:`rough_dielectric` with its energy given back (module rule: weights over the
    side's albedo), so that on average the two branches carry exactly the incident weight."""
    cos_i = -(dx * sx + dy * sy + dz * sz)
    e = glass_albedo_at(glass, alpha, cos_i, eta)
    return rough_dielectric(alpha, dx, dy, dz, sx, sy, sz, eta, u1, u2, 1.0 / max(e, E_FLOOR), kids)


@njit(**JIT)
def rough_mirror(mirror, mirror_avg, alpha, d, s, u1, u2, kids, mat_f, mat, coat_ior):
    """Replace the mirror child ``kids[0]`` of a conductor (``coat_ior < 0``) or of a plastic
    coat of index ``coat_ior``, met along unit direction ``d`` about the shading normal ``s``
    (facing ``d``; both 3-tuples), by its GGX counterpart: reflection about one visible microfacet
    ``m``, weight ``F(m) G1(o)`` (per RGB channel for the metal, times its tint), times the
    multiple-scattering factor of each channel (module rule, ``F_avg`` from ``mat_f``)."""
    dx, dy, dz = d
    sx, sy, sz = s
    rx, ry, rz, cos_im, g = visible_reflection(alpha, dx, dy, dz, sx, sy, sz, u1, u2)
    ia, wa = _cell(alpha, ALPHA_MAX, N_ALPHA)
    im, wm = _cell(-(dx * sx + dy * sy + dz * sz), 1.0, N_MU)
    e = max(_bilinear(mirror, ia, wa, im, wm), E_FLOOR)
    e_avg = mirror_avg[ia] * (1.0 - wa) + mirror_avg[ia + 1] * wa
    kids[0, KD_X], kids[0, KD_Y], kids[0, KD_Z] = rx, ry, rz
    refl = 0.0
    if coat_ior >= 0.0:
        refl, _ = fresnel_dielectric(cos_im, coat_ior)
    for c in range(3):
        f_avg = mat_f[mat, MF_FAVG + c]
        k = f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
        f = refl
        if coat_ior < 0.0:
            f = mat_f[mat, MF_TINT + c] * fresnel_conductor(cos_im, mat_f[mat, MF_N + c], mat_f[mat, MF_K + c])
        kids[0, KW_R + c] = g * f * (1.0 + k * (1.0 - e) / e)


# ------------------------------------------------------------------ albedo tables: building
#: The quadrature's substitution ``1 - u1 = (1 - v)^TAIL_POWER``: steep microfacets (GGX's long
#: tail, where reflections go below the horizon) lie within about ``alpha^2`` of ``u1 = 1``,
#: and a uniform grid in ``u1`` would step over them at small alpha.
TAIL_POWER = 4


@njit(**JIT)
def _tail_node(i, q):
    """``(u1, weight)`` of node ``i`` of the ``q``-node midpoint rule in ``v`` (``u1 = 1 - (1 -
    v)^TAIL_POWER``, weight ``du1 / dv / q``)."""
    v = (i + 0.5) / q
    return 1.0 - (1.0 - v) ** TAIL_POWER, TAIL_POWER * (1.0 - v) ** (TAIL_POWER - 1) / q


@njit(**JIT_NRT)  # allocates its children's scratch
def _mean_weight(alpha, cos_i, eta, q):
    """Mean weight of one draw met at ``cos_i`` by a ``q x q`` midpoint rule over its two
    uniforms (the first one substituted, :data:`TAIL_POWER`): both branches of
    :func:`rough_dielectric` (unscaled) for ``eta > 0``, the masking ``G1(o)`` of
    :func:`visible_reflection` (a mirror with ``F = 1``) for ``eta = 0``."""
    kids = np.zeros((2, 8))
    sin_i = math.sqrt(max(0.0, 1.0 - cos_i * cos_i))
    total = 0.0
    for i in range(q):
        u1, w = _tail_node(i, q)
        row = 0.0
        for j in range(q):
            u2 = (j + 0.5) / q
            if eta == 0.0:
                row += visible_reflection(alpha, sin_i, 0.0, -cos_i, 0.0, 0.0, 1.0, u1, u2)[4]
                continue
            nk = rough_dielectric(alpha, sin_i, 0.0, -cos_i, 0.0, 0.0, 1.0, eta, u1, u2, 1.0, kids)
            row += kids[0, KW_R]
            if nk == 2:
                row += kids[1, KW_R]
        total += w * row / q
    return total


@njit(**JIT_NRT)
def glass_albedo(alpha, cos_i, eta, q):
    """Single-scattering albedo (reflection + transmission) of :func:`rough_dielectric` met
    at ``cos_i``, ``eta`` transmitted / incident (quadrature of :func:`_mean_weight`)."""
    return _mean_weight(alpha, cos_i, eta, q)


@njit(**JIT_NRT)
def mirror_albedo(alpha, cos_i, q):
    """Albedo of a GGX mirror with ``F = 1`` met at ``cos_i``: the mean ``G1(o)`` of
    :func:`visible_reflection` (quadrature of :func:`_mean_weight`)."""
    return _mean_weight(alpha, cos_i, 0.0, q)
