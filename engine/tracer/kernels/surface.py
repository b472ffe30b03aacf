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
  (:func:`engine.tracer.kernels.finish.shading_frame`, set once on the interaction by
  :func:`interaction`), frosting makes the nested material rough, and afterwards every child is kept on its side of the *geometric* surface
  (:func:`_facing` and :func:`~engine.tracer.kernels.materials.keep_sides`, the one place that
  rule is written): the geometric normal alone decides media, so a relief never sends a branch
  into a medium it is not in;
* **the materials** (:mod:`.materials`, :mod:`.microfacet`): the smooth dielectric, the conductor,
  the coated diffuse base, the stage's ground (:func:`.ground.ground`) and its backdrop sweep
  (:func:`.backdrop.backdrop`).

The ground's material and its light are :mod:`.ground`'s.

A design without labels, relief or closures takes the plain materials exactly as the tracer did
before these layers (one table-length test per hit each), so such images are bit for bit the
same. The plain path (:func:`_material`) and the bump adapter share one dispatch on the
material's kind (:func:`_nested`), as Mitsuba's ``bumpmap`` wraps any BSDF without knowing it:
adding a material means one more branch there and a row builder in :mod:`engine.tracer.tables`.
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
from .intersect import O_MAT, object_media
from .records import Interaction, Scattered
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


@njit(**INLINE)
def interaction(tables, ray, hit, sidx, pseed):
    """The surface interaction (:class:`~.records.Interaction`) of ``ray`` at ``hit`` (a
    :class:`~.records.Hit`, object >= 0): the point, the media on the ray's and the far side (by
    the side of the oriented normal the ray meets), and the shading geometry, set here once for
    every layer (pbrt's ``SetShadingGeometry``): the relief-bent normal and the frosted roughness
    (:func:`~.finish.shading_frame`), ``s = n`` and 0 on an object without finish rows."""
    sc, fin = tables.scene, tables.finishes
    t, k, part, nx, ny, nz = hit
    ox, oy, oz, dx, dy, dz = ray
    px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
    front, back = object_media(sc.geom.obj_i, sc.geom.obj_f, k, pz)
    inc, trn = (front, back) if nx * dx + ny * dy + nz * dz < 0.0 else (back, front)
    sx, sy, sz, rough = nx, ny, nz, 0.0
    if fin.obj_rows[k, 1] > 0:
        sx, sy, sz, rough = shading_frame(fin, sc.geom, k, part, px, py, pz, nx, ny, nz)
    return Interaction(px, py, pz, nx, ny, nz, dx, dy, dz, k, part, sc.geom.obj_i[k, O_MAT], inc, trn, sidx,
                       pseed, sx, sy, sz, rough)


@njit(**INLINE)
def _nested(tables, it, frame, cos_i, bseed, kids, scratch):
    """The object's own material (the nested BSDF) about the shading normal: the one dispatch on
    the material's kind that the bump adapter and the plain path share. ``frame`` is
    ``(f, s)``: the geometric and the shading normal, both facing the incoming direction,
    ``cos_i`` the cosine of incidence on ``s``. Returns ``(children, r, g, b, bits)``: the
    radiance factors a diffuse base sends back at once (times the branch's weight) and the label
    bits its shadow rays consulted. Inlined: the plain path's smooth materials cost no call."""
    sc, fin, env_p = tables.scene, tables.finishes, tables.env
    mat_f, mat, alpha = sc.mat_f, it.mat, it.rough
    dx, dy, dz = it.dx, it.dy, it.dz
    _, _, _, sx, sy, sz = frame
    kind = sc.mat_i[mat, M_KIND]
    bits = np.int64(0)
    er = eg = eb = 0.0
    eta = sc.media[it.trn, 0] / sc.media[it.inc, 0]
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
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, alpha, (dx, dy, dz), (sx, sy, sz), u1, u2, kids, mat_f,
                         mat, -1.0)
    elif kind == PLASTIC:
        base = coat(mat_f[mat, MF_COAT_IOR], dx, dy, dz, sx, sy, sz, cos_i, 1.0, kids, 0)
        nk = 1
        if alpha > 0.0:
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, alpha, (dx, dy, dz), (sx, sy, sz), u1, u2, kids, mat_f,
                         mat, mat_f[mat, MF_COAT_IOR])
        ir, ig, ib = env_lookup(fin.irradiance, env_p[0], env_p[1], sx, sy, sz)
        if fin.lights.shape[0] > 0:
            lr, lg, lb, bits = lit_by_lights(tables, fin.lights, it, it.inc, frame, scratch)
            ir, ig, ib = ir + lr, ig + lg, ib + lb
        er = base * mat_f[mat, MF_ALBEDO] * ir
        eg = base * mat_f[mat, MF_ALBEDO + 1] * ig
        eb = base * mat_f[mat, MF_ALBEDO + 2] * ib
    else:
        nk = 0
    return nk, er, eg, eb, bits


@njit(**JIT)
def _bumped(tables, it, bseed, kids, scratch):
    """The bump adapter around the object's material (module rule): the nested material about
    the shading normal, then every child kept on its side of the geometric surface.
    Returns what :func:`_nested` does."""
    dx, dy, dz = it.dx, it.dy, it.dz
    frame = _facing(it.nx, it.ny, it.nz, it.sx, it.sy, it.sz, dx, dy, dz)
    fx, fy, fz, sx, sy, sz = frame
    nk, er, eg, eb, bits = _nested(tables, it, frame, -(dx * sx + dy * sy + dz * sz), bseed, kids, scratch)
    eta = tables.scene.media[it.trn, 0] / tables.scene.media[it.inc, 0]
    keep_sides(kids, nk, dx, dy, dz, fx, fy, fz, eta)
    return nk, er, eg, eb, bits


@njit(**INLINE)
def _material(tables, it, bseed, kids, scratch):
    """The object's own material on a smooth surface without finish: its children (the nested
    dispatch with ``s = f``, the normal facing the ray; no side rule is needed)."""
    dn = it.nx * it.dx + it.ny * it.dy + it.nz * it.dz
    fx, fy, fz = (it.nx, it.ny, it.nz) if dn < 0.0 else (-it.nx, -it.ny, -it.nz)
    return _nested(tables, it, (fx, fy, fz, fx, fy, fz), abs(dn), bseed, kids, scratch)[0]


@njit(**INLINE)
def _glass_beneath(sc, it, weight, kids, nk):
    """The wall's glass under the uncovered fraction ``weight`` of a label's texel: its two
    branches after the ``nk`` children in ``kids``, about the smooth surface, or where a relief
    bends the shading normal ``s`` through the bump adapter's frame and side rule. Returns the
    count."""
    dx, dy, dz, nx, ny, nz = it.dx, it.dy, it.dz, it.nx, it.ny, it.nz
    bx, by, bz = it.sx, it.sy, it.sz
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
def _closure_beneath(tables, it, bseed, kids, nk, rest, scratch):
    """The closure's own material under the uncovered fraction ``rest`` of a print's texel:
    its children (weights times ``rest``) go before the print's ``nk`` children in ``kids``.
    Returns ``(children, r, g, b, bits)``: the radiance factors of its diffuse base times
    ``rest`` and the object-mask bits of the labels its shadow rays consulted."""
    sc = tables.scene
    end = kids.shape[0] - nk  # the print's children wait in the last rows
    for c in range(nk - 1, -1, -1):
        for j in range(KID_COLS):
            kids[end + c, j] = kids[c, j]
    er = eg = eb = 0.0
    bits = np.int64(0)
    if tables.finishes.obj_rows[it.obj, 1] > 0 or sc.mat_i[it.mat, M_KIND] == PLASTIC:
        m, er, eg, eb, bits = _bumped(tables, it, bseed, kids, scratch)
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
def scatter(tables, it, wr, wg, wb, bseed, kids, scratch):
    """What the surface at interaction ``it`` does to a branch of weight ``w`` (module rule):
    a :class:`~.records.Scattered` whose children are in ``kids``. Inlined into the integrator:
    a call passing the scene's, labels' and finishes' tables (some forty arrays) at every hit
    doubled a frame's time; the layers it calls for labels and finishes are calls, as before."""
    sc, lab, fin = tables.scene, tables.labels, tables.finishes
    bits = np.int64(0)
    if lab.rows.shape[0] > 0 and (lab.objects[0] >> np.int64(it.obj)) & 1:
        nk, ar, ag, ab, lbits, rest, guide = label_hit(tables, it, wr, wg, wb, kids, scratch)
        if nk >= 0:
            er = eg = eb = 0.0
            if rest > 0.0 and it.obj == 0:  # the wall's glass shows through the uncovered part
                nk = _glass_beneath(sc, it, rest, kids, nk)
            elif rest > 0.0:  # a closure shows through the print's uncovered part
                nk, er, eg, eb, bits = _closure_beneath(tables, it, bseed, kids, nk, rest, scratch)
            return Scattered(nk, er, eg, eb, ar, ag, ab, bits | lbits, lbits, guide[0], guide[1], guide[2])
        bits = lbits
    if sc.mat_i[it.mat, M_KIND] == GROUND:
        nk, er, eg, eb, gbits = ground(tables, it, bseed, kids, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | gbits, np.int64(0), -1.0, -1.0, -1.0)
    if sc.mat_i[it.mat, M_KIND] == BACKDROP:
        nk, er, eg, eb, gbits = backdrop(tables, it, bseed, kids, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | gbits, np.int64(0), -1.0, -1.0, -1.0)
    if fin.obj_rows[it.obj, 1] > 0 or sc.mat_i[it.mat, M_KIND] == PLASTIC:
        nk, er, eg, eb, fbits = _bumped(tables, it, bseed, kids, scratch)
        return Scattered(nk, er, eg, eb, 0.0, 0.0, 0.0, bits | fbits, np.int64(0), -1.0, -1.0, -1.0)
    return Scattered(_material(tables, it, bseed, kids, scratch), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, bits, np.int64(0),
                     -1.0, -1.0, -1.0)
