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
  takes the direction the smooth geometric surface would give it (:func:`keep_sides`). Its
  weight is kept, so energy is conserved and a relief can never make a branch travel inside a
  medium it is not in (no leak, no mismatch).
* **Frosted** rows make the glass a rough dielectric (GGX, roughness ``alpha``): one microfacet
  normal ``m`` is drawn from the distribution of *visible* normals seen from the incident
  direction (Heitz 2018), from the branch's own stream (``uniform01(seed, 7 / 8)``:
  deterministic), and both branches go through it: reflection with weight ``F(m) G1(o_r)`` and
  refraction with ``(1 - F(m)) G1(o_t)``. With visible-normal sampling ``f cos / pdf`` of each
  lobe reduces to exactly that (the ``D``, ``|i.m|`` and Jacobian terms cancel; separable
  Smith ``G2 = G1(i) G1(o)``), so each branch is an unbiased one-sample estimate of its lobe of
  the single-scattering BSDF and their sum never exceeds 1 (what multiple scattering between
  microfacets would return is lost: an etched bottle is a few per cent dark, never bright).
* A frosted row on a closure part (its material's roughness) makes a metal or a plastic coat
  glossy the same way: its mirror branch goes through one visible microfacet with weight
  ``F(m) G1(o)`` (:func:`rough_mirror`).
* ``PLASTIC`` (a closure): the coat's mirror branch (Fresnel of the coat IOR) plus the diffuse
  base returned as radiance at once: ``(1 - R) albedo (E_env(n) + sum_l E_l max(0, n.l) / pi)``
  with ``E_env`` the environment's cosine-weighted irradiance over pi (a prefiltered map in the
  environment's own layout, white 1 in a white environment) and the design's distant lights
  unshadowed. The light that the base sends back out through the coat is not reduced by the
  coat's exit Fresnel (a small over-estimate that stays below 1 in a white furnace without
  lights).

The finish tuple (:mod:`engine.tracer.finishes`): ``(obj_rows (n_obj, 2) int64 first/count
of each object's rows, kinds (n,) int64, params (n, P_COLS), atlas (m, 3) float32, irradiance
(h, w, 3) float32, lights (L, 6) float64 direction towards the light (unit) and RGB
irradiance)``. Units mm.
"""
from __future__ import annotations

import math

from numba import njit

from .bumps import (FROSTED, P_ALPHA, P_V0, P_V1, consistent_normal, ggx_g1, onb, perturb_normal,
                    surface_slope)
from .intersect import O_KIND, PLANE, REVOLVED
from .materials import (CONDUCTOR, K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, M_KIND, MF_ALBEDO,
                        MF_COAT_IOR, MF_K, MF_N, MF_TINT, PLASTIC, SMOOTH_DIELECTRIC, coat, conductor,
                        fresnel_conductor, fresnel_dielectric, smooth_dielectric)
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
def rough_dielectric(alpha, dx, dy, dz, sx, sy, sz, eta, u1, u2, kids):
    """Both branches through one visible microfacet of a GGX interface (module doc) into
    ``kids``; ``s`` the shading normal facing the incident side (``d . s < 0``), ``eta`` the
    index ratio transmitted / incident. Returns the number of children (1 under total internal
    reflection at the microfacet, else 2)."""
    mx, my, mz, cos_im = visible_microfacet(alpha, dx, dy, dz, sx, sy, sz, u1, u2)
    refl, cos_t = fresnel_dielectric(cos_im, eta)
    rx, ry, rz = dx + 2.0 * cos_im * mx, dy + 2.0 * cos_im * my, dz + 2.0 * cos_im * mz
    g = ggx_g1(alpha, rx * sx + ry * sy + rz * sz, rx * mx + ry * my + rz * mz)
    kids[0, KD_X], kids[0, KD_Y], kids[0, KD_Z] = rx, ry, rz
    kids[0, KW_R] = kids[0, KW_G] = kids[0, KW_B] = refl * g
    kids[0, K_SIDE] = 0.0
    if refl >= 1.0:
        return 1
    q = cos_im / eta - cos_t
    tx, ty, tz = dx / eta + q * mx, dy / eta + q * my, dz / eta + q * mz
    h = math.sqrt(tx * tx + ty * ty + tz * tz)
    tx, ty, tz = tx / h, ty / h, tz / h
    g = ggx_g1(alpha, tx * sx + ty * sy + tz * sz, tx * mx + ty * my + tz * mz)
    kids[1, KD_X], kids[1, KD_Y], kids[1, KD_Z] = tx, ty, tz
    kids[1, KW_R] = kids[1, KW_G] = kids[1, KW_B] = (1.0 - refl) * g
    kids[1, K_SIDE] = 1.0
    return 2


@njit(**JIT)
def rough_mirror(alpha, dx, dy, dz, sx, sy, sz, u1, u2, kids, mat_f, mat, coat_ior):
    """Replace the mirror child ``kids[0]`` of a conductor (``coat_ior < 0``) or of a plastic
    coat of index ``coat_ior`` by its GGX counterpart: reflection about one visible microfacet
    ``m`` (module doc), weight ``F(m) G1(o)`` (per RGB channel for the metal, times its tint)."""
    mx, my, mz, cos_im = visible_microfacet(alpha, dx, dy, dz, sx, sy, sz, u1, u2)
    rx, ry, rz = dx + 2.0 * cos_im * mx, dy + 2.0 * cos_im * my, dz + 2.0 * cos_im * mz
    g = ggx_g1(alpha, rx * sx + ry * sy + rz * sz, rx * mx + ry * my + rz * mz)
    kids[0, KD_X], kids[0, KD_Y], kids[0, KD_Z] = rx, ry, rz
    if coat_ior < 0.0:
        for c in range(3):
            kids[0, KW_R + c] = g * mat_f[mat, MF_TINT + c] * fresnel_conductor(cos_im, mat_f[mat, MF_N + c],
                                                                                 mat_f[mat, MF_K + c])
    else:
        refl, _ = fresnel_dielectric(cos_im, coat_ior)
        kids[0, KW_R] = kids[0, KW_G] = kids[0, KW_B] = g * refl


@njit(**JIT)
def keep_sides(kids, nk, dx, dy, dz, fx, fy, fz, eta):
    """Send every child whose direction is on the wrong side of the geometric surface (normal
    ``f``, facing the incident side; ``eta`` transmitted / incident index) for its medium the
    way the smooth geometric surface would: a reflection along the geometric mirror direction,
    a refraction along the geometric refraction (mirrored across the tangent plane where the
    geometric surface reflects totally). Weights are kept (module doc). Mirroring a bent
    direction instead leaves rays that creep along the wall at grazing angles until a hit is
    lost to rounding."""
    cos_i = -(dx * fx + dy * fy + dz * fz)
    for c in range(nk):
        x, y, z = kids[c, KD_X], kids[c, KD_Y], kids[c, KD_Z]
        d = x * fx + y * fy + z * fz
        want = 1.0 if kids[c, K_SIDE] < 0.5 else -1.0
        if d * want > 0.0:
            continue
        if want > 0.0:
            x, y, z = dx + 2.0 * cos_i * fx, dy + 2.0 * cos_i * fy, dz + 2.0 * cos_i * fz
        else:
            _, cos_t = fresnel_dielectric(cos_i, eta)
            if cos_t > 0.0:
                q = cos_i / eta - cos_t
                x, y, z = dx / eta + q * fx, dy / eta + q * fy, dz / eta + q * fz
            elif d != 0.0:
                x, y, z = x - 2.0 * d * fx, y - 2.0 * d * fy, z - 2.0 * d * fz
            else:
                x, y, z = x - 1e-9 * fx, y - 1e-9 * fy, z - 1e-9 * fz
        h = math.sqrt(x * x + y * y + z * z)
        kids[c, KD_X], kids[c, KD_Y], kids[c, KD_Z] = x / h, y / h, z / h


@njit(**JIT)
def finish_hit(fin, seg, obj_i, mat_i, mat_f, media, k, part, mat, px, py, pz, nx, ny, nz,
               dx, dy, dz, inc, trn, bseed, kids, tex, env_p):
    """Children of a branch meeting object ``k`` (material ``mat``) at ``p`` with oriented
    geometric normal ``n``, or ``-1`` when no finish applies (module doc). Returns
    ``(children, r, g, b)``: the radiance factors ``(r, g, b)`` the hit sends back at once (a
    diffuse base; multiply by the branch's weight)."""
    kind = mat_i[mat, M_KIND]
    if fin[0][k, 1] == 0 and kind != PLASTIC:
        return -1, 0.0, 0.0, 0.0
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
    if kind == SMOOTH_DIELECTRIC:
        if alpha > 0.0:
            nk = rough_dielectric(alpha, dx, dy, dz, sx, sy, sz, eta, uniform01(bseed, FROST_STREAM),
                                  uniform01(bseed, FROST_STREAM + 1), kids)
        else:
            nk = smooth_dielectric(dx, dy, dz, sx, sy, sz, cos_i, eta, 1.0, kids, 0)
    elif kind == CONDUCTOR:
        nk = conductor(mat_f, mat, dx, dy, dz, sx, sy, sz, cos_i, 1.0, kids, 0)
        if alpha > 0.0:
            rough_mirror(alpha, dx, dy, dz, sx, sy, sz, uniform01(bseed, FROST_STREAM),
                         uniform01(bseed, FROST_STREAM + 1), kids, mat_f, mat, -1.0)
    elif kind == PLASTIC:
        base = coat(mat_f[mat, MF_COAT_IOR], dx, dy, dz, sx, sy, sz, cos_i, 1.0, kids, 0)
        nk = 1
        if alpha > 0.0:
            rough_mirror(alpha, dx, dy, dz, sx, sy, sz, uniform01(bseed, FROST_STREAM),
                         uniform01(bseed, FROST_STREAM + 1), kids, mat_f, mat, mat_f[mat, MF_COAT_IOR])
        ir, ig, ib = env_lookup(fin[4], env_p[0], env_p[1], sx, sy, sz)
        lights = fin[5]
        for q in range(lights.shape[0]):
            c = max(0.0, sx * lights[q, 0] + sy * lights[q, 1] + sz * lights[q, 2]) / math.pi
            ir += c * lights[q, 3]
            ig += c * lights[q, 4]
            ib += c * lights[q, 5]
        er = base * mat_f[mat, MF_ALBEDO] * ir
        eg = base * mat_f[mat, MF_ALBEDO + 1] * ig
        eb = base * mat_f[mat, MF_ALBEDO + 2] * ib
    else:
        nk = 0
    keep_sides(kids, nk, dx, dy, dz, fx, fy, fz, eta)
    return nk, er, eg, eb
