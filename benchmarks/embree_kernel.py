"""Embree called one ray at a time from compiled code: the other way to time raw Embree.

``benchmarks.tracer`` times raw Embree through embreex's batch API (numpy arrays of rays in,
arrays of hits out), the binding the stack names. A tracer that used Embree inside its compiled
kernels would call the library per ray instead (``rtcIntersect1``), without the batch's array
conversions. This module builds an Embree 4 scene through ``ctypes`` on the ``libembree4`` that
embreex ships, and casts rays from a numba kernel that releases the GIL, so both ways are
measured on the same rays and the same triangles.

On it, :class:`EmbreeSearch` is the whole nearest-hit search an Embree tracer would run inside
its kernels (Embree's hit, the triangle's part, the exact root near it, the tracer's acceptance
rules, a fallback), on every surface or only on some, so that the analytic search can be
weighed against it per shape kind on the queries a frame really asks.

Units: whatever the vertices are in (mm here); hits are ``t`` along unit directions, float32
as Embree computes them. Benchmarks only: the engine does not use it.
"""
from __future__ import annotations

import ctypes
import glob
import os

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from engine.tracer.kernels.records import Geometry, Ray, Scratch
from engine.tracer.kernels.intersect import (F_COS, F_EDGE, F_LEAF, F_PNZ, F_SIN, F_ZMAX, F_ZMIN, O_BACK_HI,
                                             O_BACK_LO, O_COUNT, O_FIRST, O_FRONT_HI, O_FRONT_LO, O_KIND,
                                             O_NSEC, O_XS, PLANE, REVOLVED, SL_RULED, START_FRACTION,
                                             nearest_hit, object_normal, root_param, segment_hits,
                                             swept_roots, _accept, _plane_hit, _ruled)
from engine.tracer.kernels.profile import S_RMAX, S_RMIN, S_ZMAX, S_ZMIN
from engine.tracer.kernels.revolved import ray_axis, ray_box_from
from engine.tracer.kernels.swept import SL_RMAX, SL_Z0, SL_Z1, swept_wall

#: Embree 4 enums (rtcore_geometry.h, rtcore_buffer.h, rtcore_common.h)
_GEOMETRY_TRIANGLE = 0
_BUFFER_INDEX, _BUFFER_VERTEX = 0, 1
_FORMAT_UINT3, _FORMAT_FLOAT3 = 0x5003, 0x9003
_INVALID_ID = 0xFFFFFFFF
#: ``RTCRayHit`` as 32-bit words: the ray (org, tnear, dir, time, tfar, mask, id, flags) then
#: the hit (Ng, u, v, primID, geomID, instID...); 32 words leave room for the instance arrays
_W_TFAR, _W_MASK, _W_PRIM, _W_GEOM = 8, 9, 17, 18
_WORDS = 32


def _library():
    """The ``libembree4`` embreex ships, with the argument types this module calls it with."""
    import embreex

    here = os.path.dirname(embreex.__file__)
    found = sorted(glob.glob(os.path.join(here, "..", "embreex.libs", "libembree4*.so*")))
    if not found:
        raise RuntimeError(f"no libembree4 beside embreex in {os.path.dirname(here)}")
    import llvmlite.binding as llb

    llb.load_library_permanently(found[0])  # compiled kernels call rtcIntersect1 by name (:func:`cast1`)
    lib = ctypes.CDLL(found[0])
    h = ctypes.c_size_t  # handles and pointers travel as integers (x86-64 and arm64 ABIs)
    for name, res, args in (("rtcNewDevice", h, [ctypes.c_char_p]), ("rtcNewScene", h, [h]),
                            ("rtcNewGeometry", h, [h, ctypes.c_int]),
                            ("rtcSetNewGeometryBuffer", h, [h, ctypes.c_int, ctypes.c_uint, ctypes.c_int, h, h]),
                            ("rtcCommitGeometry", None, [h]), ("rtcAttachGeometry", ctypes.c_uint, [h, h]),
                            ("rtcReleaseGeometry", None, [h]), ("rtcCommitScene", None, [h]),
                            ("rtcReleaseScene", None, [h]), ("rtcReleaseDevice", None, [h]),
                            ("rtcGetDeviceError", ctypes.c_int, [h]), ("rtcIntersect1", None, [h, h, h])):
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    return lib


_LIB = _library()
#: ``rtcIntersect1`` through ctypes: the timing kernel :func:`cast` calls it so (4-6 % faster than
#: :func:`cast1`'s call by name, measured; compiled code holding its address cannot be cached)
_INTERSECT1 = _LIB.rtcIntersect1


@intrinsic
def _rtc_intersect1(typingctx, scene, rayhit):
    """``rtcIntersect1(scene, rayhit, NULL)``: ``scene`` an address, ``rayhit`` float32*. Named,
    not an embedded address, so that kernels calling it can be cached."""
    sig = types.void(types.uintp, types.CPointer(types.float32))

    def codegen(context, builder, signature, args):
        i8p = ir.IntType(8).as_pointer()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [i8p, i8p, i8p]),
                                            "rtcIntersect1")
        builder.call(fn, [builder.inttoptr(args[0], i8p), builder.bitcast(args[1], i8p), ir.Constant(i8p, None)])
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def _rayhit(typingctx):
    """A 16-byte aligned ``RTCRayHit`` of 32 floats on the calling function's stack."""
    sig = types.CPointer(types.float32)()

    def codegen(context, builder, signature, args):
        arr = cgutils.alloca_once(builder, ir.ArrayType(ir.FloatType(), _WORDS))
        arr.align = 16
        return builder.bitcast(arr, ir.FloatType().as_pointer())

    return sig, codegen


@intrinsic
def _as_words(typingctx, ptr):
    """The same record as uint32 words."""
    sig = types.CPointer(types.uint32)(ptr)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(32).as_pointer())

    return sig, codegen


@njit(nogil=True, error_model="numpy", inline="always")
def _ray(f, w, ox, oy, oz, dx, dy, dz, tnear, tfar):
    """Fill an ``RTCRayHit`` (``f`` its floats, ``w`` the same as uint32 words; arrays or
    pointers) for one cast of ``o + t d`` with ``tnear <= t <= tfar``."""
    f[0], f[1], f[2], f[3] = ox, oy, oz, tnear
    f[4], f[5], f[6], f[7] = dx, dy, dz, 0.0
    f[_W_TFAR] = tfar
    w[_W_MASK], w[_W_MASK + 1], w[_W_MASK + 2] = _INVALID_ID, 0, 0
    w[_W_PRIM], w[_W_GEOM] = _INVALID_ID, _INVALID_ID


@njit(nogil=True, error_model="numpy", inline="always")
def cast1(scene, ox, oy, oz, dx, dy, dz, tnear, tfar):
    """One ``rtcIntersect1`` on the Embree scene at address ``scene``: ``(t, triangle)`` of the
    nearest hit with ``tnear <= t <= tfar`` (mm) along ``o + t d`` (unit ``d``, cast in
    float32), ``(inf, -1)`` for none. The record lives on the caller's stack (thread-safe), and
    Embree is called by name: kernels that use this can be cached."""
    f = _rayhit()
    w = _as_words(f)
    _ray(f, w, ox, oy, oz, dx, dy, dz, tnear, tfar)
    _rtc_intersect1(np.uintp(scene), f)
    if w[_W_GEOM] == _INVALID_ID:
        return np.inf, np.int64(-1)
    return np.float64(f[_W_TFAR]), np.int64(w[_W_PRIM])


class Embree4Scene:
    """One committed Embree 4 scene of a triangle mesh: ``vertices (N, 3)``, ``faces (M, 3)``.
    ``handle`` is what :func:`cast` takes; ``close()`` releases the scene and its device."""

    def __init__(self, vertices, faces):
        v = np.ascontiguousarray(vertices, np.float32)
        f = np.ascontiguousarray(faces, np.uint32)
        if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3 or not len(f):
            raise ValueError("vertices (N, 3) and faces (M >= 1, 3) expected")
        if f.max() >= len(v):
            raise ValueError("a face indexes past the vertices")
        lib = _LIB
        self._device = lib.rtcNewDevice(None)
        self.handle = lib.rtcNewScene(self._device)
        geom = lib.rtcNewGeometry(self._device, _GEOMETRY_TRIANGLE)
        vb = lib.rtcSetNewGeometryBuffer(geom, _BUFFER_VERTEX, 0, _FORMAT_FLOAT3, 12, len(v))
        ctypes.memmove(vb, v.ctypes.data, v.nbytes)
        ib = lib.rtcSetNewGeometryBuffer(geom, _BUFFER_INDEX, 0, _FORMAT_UINT3, 12, len(f))
        ctypes.memmove(ib, f.ctypes.data, f.nbytes)
        lib.rtcCommitGeometry(geom)
        lib.rtcAttachGeometry(self.handle, geom)
        lib.rtcReleaseGeometry(geom)
        lib.rtcCommitScene(self.handle)
        err = lib.rtcGetDeviceError(self._device)
        if err:
            self.close()
            raise RuntimeError(f"Embree could not build the scene (error {err})")
        raw = np.zeros(2 * _WORDS, np.uint32)  # :func:`cast`'s RTCRayHit must sit on 16 bytes
        off = (-raw.ctypes.data % 16) // 4
        self.scratch = raw[off:off + _WORDS]

    def close(self):
        if self.handle:
            _LIB.rtcReleaseScene(self.handle)
            _LIB.rtcReleaseDevice(self._device)
            self.handle = 0

    def cast(self, origins, directions, tnear=0.0):
        """``(t (K,) float32, inf on a miss; primitive (K,) uint32)`` of the nearest hits past
        ``t = tnear`` (mm) of rays ``origins (K, 3)``, ``directions (K, 3)`` (float32, unit)."""
        o = np.ascontiguousarray(origins, np.float32)
        d = np.ascontiguousarray(directions, np.float32)
        t = np.empty(len(o), np.float32)
        prim = np.empty(len(o), np.uint32)
        cast(self.handle, o, d, float(tnear), t, prim, self.scratch)
        return t, prim


@njit(nogil=True)
def cast(scene, o, d, tnear, out_t, out_prim, buf):
    """Nearest hit past ``tnear`` of each ray ``o[i] + t d[i]``, one ``rtcIntersect1`` each,
    into ``out_t`` (inf on a miss) and ``out_prim``; ``buf`` is a 16-byte aligned uint32
    scratch of 32 words. The timing kernel (Embree's side of the benchmarks' ratios)."""
    f = buf.view(np.float32)
    addr = buf.ctypes.data
    for i in range(o.shape[0]):
        _ray(f, buf, o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2], tnear, np.inf)
        _INTERSECT1(scene, addr, 0)
        out_t[i] = f[_W_TFAR] if buf[_W_GEOM] != _INVALID_ID else np.inf
        out_prim[i] = buf[_W_PRIM]


def triangle_parts(geometry, vertices, faces, tol=0.02):
    """``(object (M,), part (M,))``: the render object and part (segment or slab row; -1 on a
    plane) whose exact surface each triangle of a mesh made at tolerance ``tol`` (mm)
    approximates, found by the tracer's own search: a probe ray from ``5 tol`` off the
    triangle's centroid back across it, along and against its normal, in every medium; the
    crossing nearest the centroid (within ``2.5 tol``) names the part. ``-1, -1`` where none
    does (the search then falls back to the analytic one). What an Embree tracer would store
    beside its mesh."""
    probe_mm, tol_mm = 5.0 * tol, 2.5 * tol
    from engine.tracer.context import nearest_hits

    v = np.asarray(vertices, float)[np.asarray(faces)]
    c = v.mean(axis=1)
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    obj_i = geometry.obj_i
    media = int(max(obj_i[:, O_FRONT_LO].max(), obj_i[:, O_BACK_LO].max(), obj_i[:, O_FRONT_HI].max(),
                    obj_i[:, O_BACK_HI].max())) + 1
    best = np.full(len(c), np.inf)
    obj, part = np.full(len(c), -1, np.int64), np.full(len(c), -1, np.int64)
    for m in range(media):
        for s in (1.0, -1.0):
            t, k, j, _ = nearest_hits(geometry, c - s * probe_mm * n, s * n, m)
            off = np.abs(t - probe_mm)
            better = (off < best) & (off <= tol_mm) & (k >= 0)
            best[better], obj[better], part[better] = off[better], k[better], j[better]
    return obj, part


class EmbreeSearch:
    """The nearest-hit search of an Embree tracer, complete, on every surface or on some.

    Embree's hit on the chordal mesh (past ``tnear`` mm of the ray's start, where a ray leaving
    a surface meets that surface's own triangles), the triangle's part (:func:`triangle_parts`)
    and then its neighbours on the same object refined onto their exact roots within ``bracket``
    mm of it by the tracer's solvers, the tracer's acceptance rules (medium, the side a ray left
    by); where that yields no hit (no part, no root in the bracket, a hit the rules refuse, or a
    miss by a ray that cannot leave its medium without a crossing), the analytic search again.
    What it cannot see is a crossing the mesh misses (a grazing ray past the chords, a hit
    within ``tnear``): it then answers a later one, which the benchmark counts against the
    analytic answers.

    Per surface: given masks over segment rows, slab rows and objects (planes), only those
    parts are meshed; the others keep the analytic search (on a copy of the tables where the
    meshed parts' boxes are empty, so it never visits them), asked first; Embree is then asked
    only up to its answer (plus the bracket) and the nearer wins. Without masks every part is
    meshed and the analytic search runs only as the fallback.
    """

    def __init__(self, geometry, vertices, faces, tnear=0.05, bracket=0.05, tol=0.02, masks=None):
        g = geometry
        self.geometry, self.tnear, self.bracket = g, float(tnear), float(bracket)
        tri_obj, tri_part = triangle_parts(g, vertices, faces, tol)
        self.seg, self.slab_f, self.obj_i = g.seg, g.slab_f, g.obj_i
        self.rest = masks is not None
        if self.rest:
            seg_mask, slab_mask, plane_mask = masks
            okind = np.where(tri_obj >= 0, g.obj_i[np.maximum(tri_obj, 0), O_KIND], -1)
            keep = (okind == REVOLVED) & seg_mask[np.clip(tri_part, 0, len(g.seg) - 1)]
            if len(g.slab_f):
                keep |= (okind != REVOLVED) & (okind != PLANE) & slab_mask[np.clip(tri_part, 0, len(g.slab_f) - 1)]
            keep |= (okind == PLANE) & plane_mask[np.maximum(tri_obj, 0)]
            keep &= tri_obj >= 0
            faces, tri_obj, tri_part = np.asarray(faces)[keep], tri_obj[keep], tri_part[keep]
            # the analytic side's tables: meshed parts get empty boxes, meshed planes no medium
            self.seg = g.seg.copy()
            self.seg[seg_mask, S_RMIN], self.seg[seg_mask, S_RMAX] = 1.0, -1.0
            self.slab_f = g.slab_f.copy()
            if len(self.slab_f):
                self.slab_f[slab_mask, SL_RMAX] = -1.0
            self.obj_i = g.obj_i.copy()
            for c in (O_FRONT_LO, O_BACK_LO, O_FRONT_HI, O_BACK_HI):
                self.obj_i[plane_mask, c] = -7
        self.triangles = len(faces)
        self.tri_obj, self.tri_part = np.ascontiguousarray(tri_obj), np.ascontiguousarray(tri_part)
        self.scene = Embree4Scene(vertices, faces) if len(faces) else None

    def close(self):
        if self.scene is not None:
            self.scene.close()
            self.scene = None

    def hits(self, o, d, medium, last, side):
        """``(t, object, part, fell_back)`` of rays ``o + t d`` (float64, unit ``d``; each in
        ``medium``, leaving ``last`` by ``side`` as :func:`engine.tracer.context.nearest_hits`)."""
        g = self.geometry
        n = len(o)
        out_t, out_k, out_j = np.empty(n), np.empty(n, np.int64), np.empty(n, np.int64)
        fell = np.zeros(n, np.bool_)
        handle = self.scene.handle if self.scene is not None else 0
        _search(handle, self.tri_obj, self.tri_part, g.seg, self.seg, g.tab, g.slab_f, self.slab_f, g.slab_i,
                g.obj_i, self.obj_i, g.obj_f, self.rest, np.ascontiguousarray(o, float), np.ascontiguousarray(d, float),
                np.ascontiguousarray(medium, np.int64), np.ascontiguousarray(last, np.int64),
                np.ascontiguousarray(side, np.int64), self.tnear, self.bracket, out_t, out_k, out_j, fell,
                np.zeros(16), np.zeros(5), np.zeros((64, 2)), g.plan)
        return out_t, out_k, out_j, fell


@njit(nogil=True, error_model="numpy")
def _part_roots(seg, tab, slab_f, slab_i, obj_i, obj_f, k, j, ox, oy, oz, dx, dy, dz, a, b, roots, crit, stack, plan):
    """Crossings of part ``j`` of object ``k`` in ``[a, b]`` (the tracer's solvers), within the
    part's own box as :func:`~engine.tracer.kernels.intersect.nearest_hit` asks them."""
    axis = ray_axis(ox, oy, dx, dy, dz)
    ray = Ray(ox, oy, oz, dx, dy, dz)
    if obj_i[k, O_KIND] == REVOLVED:
        lo, hi = ray_box_from(axis, ray, seg[j, S_RMIN], seg[j, S_RMAX], seg[j, S_ZMIN],
                              seg[j, S_ZMAX], a, b)
        if lo > hi:
            return 0
        return segment_hits(seg, tab, j, ray, a, b, lo, hi, roots, crit, stack)
    a, b = ray_box_from(axis, ray, 0.0, slab_f[j, SL_RMAX], slab_f[j, SL_Z0], slab_f[j, SL_Z1], a, b)
    if a > b:
        return 0
    if slab_f[j, SL_RULED] > 0.5:
        return _ruled(Geometry(seg, tab, slab_f, slab_i, obj_i, obj_f, plan), k, j, ray, a, b, roots)
    return swept_roots(swept_wall(seg, tab, slab_i[j], obj_i[k, O_XS], obj_i[k, O_NSEC], (obj_f[k, F_COS],
                                  obj_f[k, F_SIN]), plan), ray, a, b, obj_f[k, F_LEAF], roots, stack)


@njit(nogil=True, error_model="numpy")
def refine_hit(k, j, te, seg, tab, slab_f, slab_i, obj_i, obj_f, ox, oy, oz, dx, dy, dz, medium, last, side, bracket,
               best, roots, crit, stack, plan):
    """The crossing Embree's hit at ``te`` (mm) on a triangle of part ``j`` of object ``k``
    stands for: the first root of that part (then of its neighbours on the object) within
    ``bracket`` mm of ``te`` and before ``best`` that the tracer accepts (medium, the side the
    ray left ``last`` by). Returns ``(t, object, part, nx, ny, nz)`` (oriented unit normal);
    ``object = -1`` for none (or ``k = -1``, a triangle without a part)."""
    rt, rk, rj, rnx, rny, rnz = np.inf, -1, -1, 0.0, 0.0, 0.0
    if k >= 0:
        t0 = START_FRACTION * obj_f[k, F_EDGE] if k == last else 0.0
        a, b = max(te - bracket, t0), min(te + bracket, best)
        if obj_i[k, O_KIND] == PLANE:
            t = _plane_hit(Geometry(seg, tab, slab_f, slab_i, obj_i, obj_f, plan), k, Ray(ox, oy, oz, dx, dy, dz), a, b)
            nz = obj_f[k, F_PNZ]
            if t < b and _accept(obj_i, obj_f, k, t, 0.0 * dx + 0.0 * dy + nz * dz, oz + t * dz, medium, last, side):
                rt, rk, rnz = t, k, nz
        else:
            first, count = obj_i[k, O_FIRST], obj_i[k, O_COUNT]
            for step in range(3):  # the triangle's own part, then those either side
                jj = j if step == 0 else (j - 1 if step == 1 else j + 1)
                if rk >= 0 or jj < first or jj >= first + count:
                    continue
                n = _part_roots(seg, tab, slab_f, slab_i, obj_i, obj_f, k, jj, ox, oy, oz, dx, dy, dz, a, b, roots,
                                crit, stack, plan)
                for q in range(n):
                    t = roots[q]
                    pz = oz + t * dz
                    if not (t > t0 and t < b) or pz < obj_f[k, F_ZMIN] or pz > obj_f[k, F_ZMAX]:
                        continue
                    nx, ny, nz = object_normal(Geometry(seg, tab, slab_f, slab_i, obj_i, obj_f, plan), k, jj, ox + t * dx,
                                               oy + t * dy, pz, root_param(seg, obj_i, k, jj, roots, q))
                    if _accept(obj_i, obj_f, k, t, nx * dx + ny * dy + nz * dz, pz, medium, last, side):
                        rt, rk, rj, rnx, rny, rnz = t, k, jj, nx, ny, nz
                        break
    return rt, rk, rj, rnx, rny, rnz


@njit(nogil=True, error_model="numpy")
def _search(scene, tri_obj, tri_part, seg, seg_rest, tab, slab_f, slab_rest, slab_i, obj_i, obj_rest, obj_f, rest,
            o, d, medium, last, side, tnear, bracket, out_t, out_k, out_j, fell, roots, crit, stack, plan):
    geom = Geometry(seg, tab, slab_f, slab_i, obj_i, obj_f, plan)
    for i in range(o.shape[0]):
        ox, oy, oz, dx, dy, dz = o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2]
        best, best_k, best_j = np.inf, -1, -1
        if rest:  # the surfaces kept analytic first
            best, best_k, best_j, _, _, _ = nearest_hit(Geometry(seg_rest, tab, slab_rest, slab_i, obj_rest, obj_f, plan),
                                                        Ray(ox, oy, oz, dx, dy, dz), medium[i], last[i], side[i],
                                                        Scratch(roots, crit, stack))
        decided = True
        if scene != 0:
            te, p = cast1(scene, ox, oy, oz, dx, dy, dz, tnear, best + bracket)
            if p >= 0:
                # refine_hit written out: called here (inlined or not) it measured 25-30 % slower
                k, j = tri_obj[p], tri_part[p]
                found = False
                if k >= 0:
                    t0 = START_FRACTION * obj_f[k, F_EDGE] if k == last[i] else 0.0
                    a, b = max(te - bracket, t0), min(te + bracket, best)
                    if obj_i[k, O_KIND] == PLANE:
                        t = _plane_hit(geom, k, Ray(ox, oy, oz, dx, dy, dz), a, b)
                        if t < best and _accept(obj_i, obj_f, k, t, 0.0 * dx + 0.0 * dy + obj_f[k, F_PNZ] * dz,
                                                oz + t * dz, medium[i], last[i], side[i]):
                            best, best_k, best_j, found = t, k, -1, True
                    else:
                        first, count = obj_i[k, O_FIRST], obj_i[k, O_COUNT]
                        for step in range(3):  # the triangle's own part, then those either side
                            jj = j if step == 0 else (j - 1 if step == 1 else j + 1)
                            if found or jj < first or jj >= first + count:
                                continue
                            n = _part_roots(seg, tab, slab_f, slab_i, obj_i, obj_f, k, jj, ox, oy, oz, dx, dy, dz,
                                            a, min(b, best), roots, crit, stack, plan)
                            for q in range(n):
                                t = roots[q]
                                pz = oz + t * dz
                                if not (t > t0 and t < best) or pz < obj_f[k, F_ZMIN] or pz > obj_f[k, F_ZMAX]:
                                    continue
                                nx, ny, nz = object_normal(geom, k, jj, ox + t * dx,
                                                           oy + t * dy, pz, root_param(seg, obj_i, k, jj, roots, q))
                                if _accept(obj_i, obj_f, k, t, nx * dx + ny * dy + nz * dz, pz, medium[i], last[i], side[i]):
                                    best, best_k, best_j, found = t, k, jj, True
                                    break
                if not found and te < best - bracket:
                    decided = False  # the mesh is crossed clearly before the answer, the surface is not
        if best_k < 0 and medium[i] != 0:
            decided = False  # the ray cannot leave its medium without a crossing
        if not decided:
            fell[i] = True
            best, best_k, best_j, _, _, _ = nearest_hit(geom,
                                                        Ray(ox, oy, oz, dx, dy, dz), medium[i], last[i], side[i],
                                                        Scratch(roots, crit, stack))
        out_t[i], out_k[i], out_j[i] = best, best_k, best_j
