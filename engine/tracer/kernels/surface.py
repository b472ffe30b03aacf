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
  the coated diffuse base, the stage's ground (:func:`.ground.ground`) and its backdrop sweep
  (:func:`.backdrop.backdrop`).

The ground's material and its light are :mod:`.ground`'s.

A design without labels, relief or closures takes the plain materials exactly as the tracer did
before these layers (one table-length test per hit each), so such images are bit for bit the
same. Adding a material means one more branch in :func:`_material` (smooth) and in
:func:`_bumped` (with relief or frosting) and a row builder in :mod:`engine.tracer.tables`.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .backdrop import backdrop
from .bumps import consistent_normal
from .finish import FROST_STREAM, lit_by_lights, shading_frame
from .jit import INLINE, JIT
from .labels import label_hit
from .ground import ground
from .materials import (BACKDROP, CONDUCTOR, GROUND, KID_COLS, KW_B, KW_G, KW_R, M_KIND, MF_ALBEDO, MF_COAT_IOR, PLASTIC,
                        SMOOTH_DIELECTRIC, coat, conductor, keep_sides, smooth_dielectric)
from .microfacet import frosted_glass, rough_mirror
from .records import Scattered
from .sampling import env_lookup, padded_sobol2, uniform01

AIR = 0


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


@njit(**INLINE)
def lobe_uniforms(it, bseed):
    """The two uniforms a rough surface samples its lobe with at crossing ``it``: from a net over
    the pixel's anti-aliasing samples at this node of the tree (:func:`~.sampling.padded_sobol2`),
    or, for a centre sample or a probe (``it.sidx < 0``), from the branch's own stream. Why: a
    frosted or brushed surface's pixel is an integral over its lobe as much as over the pixel's
    area, and independent draws converge as ``1 / sqrt(n)`` where a net's do faster."""
    if it.sidx < 0:
        return uniform01(bseed, FROST_STREAM), uniform01(bseed, FROST_STREAM + 1)
    return padded_sobol2(it.sidx, it.pseed)


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
    u1 = u2 = 0.0
    if alpha > 0.0:  # (relief alone samples no lobe: its hits skip the net's hashing)
        u1, u2 = lobe_uniforms(it, bseed)
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
        nk, er, eg, eb, gbits = ground(sc, lab, fin, env_p, tex, it, bseed, kids, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | gbits, np.int64(0))
    if sc.mat_i[it.mat, M_KIND] == BACKDROP:
        nk, er, eg, eb, gbits = backdrop(sc, lab, fin, env_p, tex, it, bseed, kids, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | gbits, np.int64(0))
    if fin.obj_rows[it.obj, 1] > 0 or sc.mat_i[it.mat, M_KIND] == PLASTIC:
        nk, er, eg, eb, fbits = _bumped(fin, sc, lab, it, bseed, kids, env_p, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | fbits, np.int64(0))
    return Scattered(_material(sc, it, kids), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, bits, np.int64(0))
