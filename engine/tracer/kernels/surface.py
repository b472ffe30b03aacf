"""The surface layer: what a branch meeting a surface turns into, in one call.

Design rule: :func:`scatter` is the only thing the integrator asks of a surface. Given the
surface interaction (:class:`~.records.Interaction`: point, oriented geometric normal, incoming
direction, object, material, the media on both sides) it writes the branch's children into the
work's ``kids`` and returns what the surface sends back at once (:class:`~.records.Scattered`).
It composes three kinds of layer, as Mitsuba's ``mask`` and ``bumpmap`` wrap a nested BSDF:

* **a mask** (labels and prints, :func:`engine.tracer.kernels.labels.label_hit`): where a label
  covers the point it answers for its covered fraction ``alpha`` and hands the rest ``1 - alpha``
  to what lies beneath: the wall's glass (:func:`_glass_beneath`) or a closure's own material
  (:func:`_closure_beneath`);
* **a bump adapter** (:func:`_bumped`): relief bends the *shading* normal
  (:func:`engine.tracer.kernels.finish.shading_frame`), frosting makes the nested material
  rough, and afterwards every child is kept on its side of the *geometric* surface
  (:func:`_facing` and :func:`~engine.tracer.kernels.materials.keep_sides`, the one place that
  rule is written): the geometric normal alone decides media, so a relief never sends a branch
  into a medium it is not in;
* **the materials** (:mod:`.materials`, :mod:`.microfacet`): the smooth dielectric, the conductor,
  the coated diffuse base, and the stage's ground (:func:`_ground`).

The ground is Lambertian (optionally under a clear coat, or a tinted mirror, or a shadow
catcher), so its light is an integral over the sky above it, through the glass and the liquid
where the bottle stands in the way: the caustic and the coloured shadow are that light. It is
estimated with a control variate whose mean is known exactly: the environment's irradiance
``E_up`` of an upward surface with nothing in the way (``env_p[3:6]``, computed once per
environment). Where nothing is in the way, what arrives along a direction is the environment
itself, so only the directions towards the upright cylinder that holds the bottle and its
closure (``MG_BOUND_*``) can differ: a hit sends back ``albedo (E_up - F L_env(w))`` at once and
one child along a direction ``w`` drawn cosine-distributed within the azimuth and elevation that
cylinder spans from the hit (a share ``F`` of the cosine-weighted sky), with weight ``albedo F``,
whose subtree brings back what really arrives along ``w``. Open ground is exact and noise-free,
and every sample of ground near the bottle probes the bottle. A shadow catcher is the
same ground with the albedo ``L_env(d) / E_up`` of the background ``d`` shows there, so where
nothing is in the way it shows the environment itself.

A design without labels, relief or closures takes the plain materials exactly as the tracer did
before these layers (one table-length test per hit each), so such images are bit for bit the
same. Adding a material means one more branch in :func:`_material` (smooth) and in
:func:`_bumped` (with relief or frosting) and a row builder in :mod:`engine.tracer.tables`.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .bumps import consistent_normal
from .finish import FROST_STREAM, lit_by_lights, shading_frame
from .jit import INLINE, JIT
from .labels import label_hit
from .materials import (CONDUCTOR, GROUND, K_SIDE, KD_X, KD_Y, KD_Z, KID_COLS, KW_B, KW_G, KW_R, M_KIND,
                        MF_ALBEDO, MF_COAT_IOR, MG_ALBEDO, MG_ALPHA, MG_BOUND_R, MG_BOUND_Z, MG_COAT_IOR, MG_MIRROR,
                        MG_SHADOW, PLASTIC, SMOOTH_DIELECTRIC, coat, conductor, keep_sides, smooth_dielectric)
from .microfacet import frosted_glass, rough_mirror
from .records import Scattered
from .sampling import env_lookup, uniform01

AIR = 0
#: Streams of a branch's seed the ground's direction draws from (frosting uses 7 and 8).
GROUND_STREAM = 9


@njit(**INLINE)
def _facing(nx, ny, nz, sx, sy, sz, dx, dy, dz):
    """The bump adapter's frame ``(f, s)``: the geometric normal ``f`` and the shading normal
    ``s`` turned to face the incoming direction ``d`` (by the geometric side), ``s`` made
    consistent with the ray (:func:`~engine.tracer.kernels.bumps.consistent_normal`)."""
    if nx * dx + ny * dy + nz * dz < 0.0:
        fx, fy, fz = nx, ny, nz
    else:
        fx, fy, fz, sx, sy, sz = -nx, -ny, -nz, -sx, -sy, -sz
    sx, sy, sz = consistent_normal(sx, sy, sz, fx, fy, fz, dx, dy, dz)
    return fx, fy, fz, sx, sy, sz


@njit(**JIT)
def _bumped(fin, sc, lab, it, bseed, kids, env_p, scratch):
    """The bump adapter around the object's material: ``(children, r, g, b, bits)``, the
    radiance factors a diffuse base sends back at once (times the branch's weight) and the
    label bits its shadow rays consulted (module rule)."""
    media, mat_i, mat_f = sc.media, sc.mat_i, sc.mat_f
    px, py, pz, nx, ny, nz, dx, dy, dz = it.px, it.py, it.pz, it.nx, it.ny, it.nz, it.dx, it.dy, it.dz
    mat, inc, trn = it.mat, it.inc, it.trn
    kind = mat_i[mat, M_KIND]
    bits = np.int64(0)
    sx, sy, sz, alpha = shading_frame(fin, sc.geom.seg, sc.geom.obj_i, it.obj, it.part, px, py, pz, nx, ny, nz)
    fx, fy, fz, sx, sy, sz = _facing(nx, ny, nz, sx, sy, sz, dx, dy, dz)
    cos_i = -(dx * sx + dy * sy + dz * sz)
    er = eg = eb = 0.0
    eta = media[trn, 0] / media[inc, 0]
    u1, u2 = uniform01(bseed, FROST_STREAM), uniform01(bseed, FROST_STREAM + 1)
    if kind == SMOOTH_DIELECTRIC:
        if alpha > 0.0:
            nk = frosted_glass(fin.glass_albedo, alpha, dx, dy, dz, sx, sy, sz, eta, u1, u2, kids)
        else:
            nk = smooth_dielectric(dx, dy, dz, sx, sy, sz, cos_i, eta, 1.0, kids, 0)
    elif kind == CONDUCTOR:
        nk = conductor(mat_f, mat, dx, dy, dz, sx, sy, sz, cos_i, 1.0, kids, 0)
        if alpha > 0.0:
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, alpha, dx, dy, dz, sx, sy, sz, u1, u2, kids, mat_f,
                         mat, -1.0)
    elif kind == PLASTIC:
        base = coat(mat_f[mat, MF_COAT_IOR], dx, dy, dz, sx, sy, sz, cos_i, 1.0, kids, 0)
        nk = 1
        if alpha > 0.0:
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, alpha, dx, dy, dz, sx, sy, sz, u1, u2, kids, mat_f,
                         mat, mat_f[mat, MF_COAT_IOR])
        ir, ig, ib = env_lookup(fin.irradiance, env_p[0], env_p[1], sx, sy, sz)
        if fin.lights.shape[0] > 0:
            lr, lg, lb, bits = lit_by_lights(sc, lab, fin.lights, it.obj, inc, px, py, pz, nx, ny, nz, sx, sy,
                                             sz, fx, fy, fz, scratch)
            ir, ig, ib = ir + lr, ig + lg, ib + lb
        er = base * mat_f[mat, MF_ALBEDO] * ir
        eg = base * mat_f[mat, MF_ALBEDO + 1] * ig
        eb = base * mat_f[mat, MF_ALBEDO + 2] * ib
    else:
        nk = 0
    keep_sides(kids, nk, dx, dy, dz, fx, fy, fz, eta)
    return nk, er, eg, eb, bits


@njit(**JIT)
def _ground(sc, lab, fin, env_p, tex, it, bseed, kids, scratch):
    """The stage's ground at interaction ``it`` (module rule): ``(children, r, g, b, bits)``,
    the radiance factors sent back at once (times the branch's weight; negative where the
    control variate takes back what the child will bring) and the label bits the lights' shadow
    rays consulted. Black from below. The design's distant lights reach the diffuse base through
    one straight shadow ray each (:func:`~engine.tracer.kernels.finish.lit_by_lights`: the glass
    dims and colours their light but does not bend it, so a light's own caustic is not drawn)."""
    mat_f, mat = sc.mat_f, it.mat
    bits = np.int64(0)
    if it.dz >= 0.0:  # its lower side absorbs (a ray from below the stage ends there)
        return 0, 0.0, 0.0, 0.0, bits
    scale, rot = env_p[0] * env_p[2], env_p[1]
    ar, ag, ab = mat_f[mat, MG_ALBEDO], mat_f[mat, MG_ALBEDO + 1], mat_f[mat, MG_ALBEDO + 2]
    if mat_f[mat, MG_MIRROR] > 0.5:  # a tinted mirror: one branch
        kids[0, KD_X], kids[0, KD_Y], kids[0, KD_Z] = it.dx, it.dy, -it.dz
        kids[0, KW_R], kids[0, KW_G], kids[0, KW_B] = ar, ag, ab
        kids[0, K_SIDE] = 0.0
        return 1, 0.0, 0.0, 0.0, bits
    if mat_f[mat, MG_SHADOW] > 0.5:  # the background seen here, over what an open sky gives
        br, bg, bb = env_lookup(tex, scale, rot, it.dx, it.dy, it.dz)
        ar = br / env_p[3] if env_p[3] > 0.0 else 1.0
        ag = bg / env_p[4] if env_p[4] > 0.0 else 1.0
        ab = bb / env_p[5] if env_p[5] > 0.0 else 1.0
    nk, base = 0, 1.0
    ior = mat_f[mat, MG_COAT_IOR]
    if ior > 0.0:  # a clear coat: its mirror branch, and what reaches the base
        cos_i = -it.dz
        base = coat(ior, it.dx, it.dy, it.dz, 0.0, 0.0, 1.0, cos_i, 1.0, kids, 0)
        if mat_f[mat, MG_ALPHA] > 0.0:
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, mat_f[mat, MG_ALPHA], it.dx, it.dy, it.dz, 0.0, 0.0,
                         1.0, uniform01(bseed, FROST_STREAM), uniform01(bseed, FROST_STREAM + 1), kids, mat_f, mat,
                         ior)
        nk = 1
    # the diffuse base: a cosine-distributed direction towards the bottle's cylinder, less the open
    # sky's light along it (module rule). s = cos(theta)^2 is uniform under the cosine measure.
    u1, u2 = uniform01(bseed, GROUND_STREAM), uniform01(bseed, GROUND_STREAM + 1)
    rho, bound_r = math.sqrt(it.px * it.px + it.py * it.py), mat_f[mat, MG_BOUND_R]
    if rho > bound_r:
        half_az = math.asin(bound_r / rho)
        elev = math.atan2(mat_f[mat, MG_BOUND_Z] - it.pz, rho - bound_r)
        s_max = math.sin(elev) ** 2
        share = s_max * half_az / math.pi
        s, phi = u1 * s_max, math.atan2(-it.py, -it.px) + (2.0 * u2 - 1.0) * half_az
    else:  # under the bottle's cylinder: the whole sky
        share, s, phi = 1.0, u1, 2.0 * math.pi * u2
    r = math.sqrt(max(0.0, 1.0 - s))
    wx, wy, wz = r * math.cos(phi), r * math.sin(phi), math.sqrt(s)
    ar, ag, ab = base * ar, base * ag, base * ab
    kids[nk, KD_X], kids[nk, KD_Y], kids[nk, KD_Z] = wx, wy, wz
    kids[nk, KW_R], kids[nk, KW_G], kids[nk, KW_B] = ar * share, ag * share, ab * share
    kids[nk, K_SIDE] = 0.0
    lr, lg, lb = env_lookup(tex, scale, rot, wx, wy, wz)
    er, eg, eb = env_p[3] - share * lr, env_p[4] - share * lg, env_p[5] - share * lb
    if fin.lights.shape[0] > 0:
        dr, dg, db, bits = lit_by_lights(sc, lab, fin.lights, it.obj, AIR, it.px, it.py, it.pz, 0.0, 0.0, 1.0,
                                         0.0, 0.0, 1.0, 0.0, 0.0, 1.0, scratch)
        er, eg, eb = er + dr, eg + dg, eb + db
    return nk + 1, ar * er, ag * eg, ab * eb, bits


@njit(**INLINE)
def _material(sc, it, kids):
    """The object's own material on a smooth surface without finish: its children."""
    kind = sc.mat_i[it.mat, M_KIND]
    dn = it.nx * it.dx + it.ny * it.dy + it.nz * it.dz
    fx, fy, fz = (it.nx, it.ny, it.nz) if dn < 0.0 else (-it.nx, -it.ny, -it.nz)
    if kind == SMOOTH_DIELECTRIC:
        return smooth_dielectric(it.dx, it.dy, it.dz, fx, fy, fz, abs(dn),
                                 sc.media[it.trn, 0] / sc.media[it.inc, 0], 1.0, kids, 0)
    if kind == CONDUCTOR:
        return conductor(sc.mat_f, it.mat, it.dx, it.dy, it.dz, fx, fy, fz, abs(dn), 1.0, kids, 0)
    return 0


@njit(**INLINE)
def _glass_beneath(sc, it, bx, by, bz, weight, kids, nk):
    """The wall's glass under the uncovered fraction ``weight`` of a label's texel: its two
    branches after the ``nk`` children in ``kids``, about the smooth surface, or where a relief
    bends the shading normal to ``b`` through the bump adapter's frame and side rule. Returns the
    count."""
    dx, dy, dz, nx, ny, nz = it.dx, it.dy, it.dz, it.nx, it.ny, it.nz
    eta = sc.media[it.trn, 0] / sc.media[it.inc, 0]
    if bx == nx and by == ny and bz == nz:
        fx, fy, fz = (nx, ny, nz) if it.inc == AIR else (-nx, -ny, -nz)
        cos_g = abs(dx * nx + dy * ny + dz * nz)
        return nk + smooth_dielectric(dx, dy, dz, fx, fy, fz, cos_g, eta, weight, kids, nk)
    fx, fy, fz, sx, sy, sz = _facing(nx, ny, nz, bx, by, bz, dx, dy, dz)
    nk += smooth_dielectric(dx, dy, dz, sx, sy, sz, -(dx * sx + dy * sy + dz * sz), eta, weight, kids, nk)
    keep_sides(kids, nk, dx, dy, dz, fx, fy, fz, eta)
    return nk


@njit(**JIT)
def _closure_beneath(fin, sc, lab, it, bseed, kids, nk, rest, env_p, scratch):
    """The closure's own material under the uncovered fraction ``rest`` of a print's texel:
    its children (weights times ``rest``) go before the print's ``nk`` children in ``kids``.
    Returns ``(children, r, g, b, bits)``: the radiance factors of its diffuse base times
    ``rest`` and the object-mask bits of the labels its shadow rays consulted."""
    end = kids.shape[0] - nk  # the print's children wait in the last rows
    for c in range(nk - 1, -1, -1):
        for j in range(KID_COLS):
            kids[end + c, j] = kids[c, j]
    er = eg = eb = 0.0
    bits = np.int64(0)
    if fin.obj_rows[it.obj, 1] > 0 or sc.mat_i[it.mat, M_KIND] == PLASTIC:
        m, er, eg, eb, bits = _bumped(fin, sc, lab, it, bseed, kids, env_p, scratch)
    else:  # a closure's outside faces the air: the ray meets it against its normal
        m = conductor(sc.mat_f, it.mat, it.dx, it.dy, it.dz, it.nx, it.ny, it.nz,
                      -(it.nx * it.dx + it.ny * it.dy + it.nz * it.dz), 1.0, kids, 0)
    for c in range(m):
        kids[c, KW_R] *= rest
        kids[c, KW_G] *= rest
        kids[c, KW_B] *= rest
    for c in range(nk):
        for j in range(KID_COLS):
            kids[m + c, j] = kids[end + c, j]
    return m + nk, rest * er, rest * eg, rest * eb, bits


@njit(**INLINE)
def scatter(sc, lab, fin, env_p, tex, it, wr, wg, wb, bseed, kids, scratch):
    """What the surface at interaction ``it`` does to a branch of weight ``w`` (module rule):
    a :class:`~.records.Scattered` whose children are in ``kids``. Inlined into the integrator:
    a call passing the scene's, labels' and finishes' tables (some forty arrays) at every hit
    doubled a frame's time; the layers it calls for labels and finishes are calls, as before."""
    bits = np.int64(0)
    if lab.rows.shape[0] > 0 and (lab.objects[0] >> np.int64(it.obj)) & 1:
        bx, by, bz = it.nx, it.ny, it.nz
        if fin.obj_rows[it.obj, 1] > 0:  # relief under the label bends its shading normal too
            bx, by, bz, _ = shading_frame(fin, sc.geom.seg, sc.geom.obj_i, it.obj, it.part, it.px, it.py, it.pz,
                                          it.nx, it.ny, it.nz)
        nk, ar, ag, ab, lbits, rest = label_hit(lab, sc, env_p, it, bx, by, bz, wr, wg, wb, kids, scratch)
        if nk >= 0:
            er = eg = eb = 0.0
            if rest > 0.0 and it.obj == 0:  # the wall's glass shows through the uncovered part
                nk = _glass_beneath(sc, it, bx, by, bz, rest, kids, nk)
            elif rest > 0.0:  # a closure shows through the print's uncovered part
                nk, er, eg, eb, bits = _closure_beneath(fin, sc, lab, it, bseed, kids, nk, rest, env_p, scratch)
            return Scattered(nk, er, eg, eb, ar, ag, ab, bits | lbits, lbits)
        bits = lbits
    if sc.mat_i[it.mat, M_KIND] == GROUND:
        nk, er, eg, eb, gbits = _ground(sc, lab, fin, env_p, tex, it, bseed, kids, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | gbits, np.int64(0))
    if fin.obj_rows[it.obj, 1] > 0 or sc.mat_i[it.mat, M_KIND] == PLASTIC:
        nk, er, eg, eb, fbits = _bumped(fin, sc, lab, it, bseed, kids, env_p, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | fbits, np.int64(0))
    return Scattered(_material(sc, it, kids), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, bits, np.int64(0))
