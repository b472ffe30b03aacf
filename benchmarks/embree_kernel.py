"""Embree called one ray at a time from compiled code: the other way to time raw Embree.

``benchmarks.tracer`` times raw Embree through embreex's batch API (numpy arrays of rays in,
arrays of hits out), the binding the stack names. A tracer that used Embree inside its compiled
kernels would call the library per ray instead (``rtcIntersect1``), without the batch's array
conversions. This module builds an Embree 4 scene through ``ctypes`` on the ``libembree4`` that
embreex ships, and casts rays from a numba kernel that releases the GIL, so both ways are
measured on the same rays and the same triangles.

Units: whatever the vertices are in (mm here); hits are ``t`` along unit directions, float32
as Embree computes them. Benchmarks only: the engine does not use it.
"""
from __future__ import annotations

import ctypes
import glob
import os

import numpy as np
from numba import njit

from engine.tracer.kernels.intersect import (F_COS, F_LEAF, F_SIN, O_KIND, O_NSEC, O_XS, REVOLVED, SL_RULED,
                                             object_normal, ruled_roots, segment_hits, swept_roots)

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
_INTERSECT1 = _LIB.rtcIntersect1


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
        raw = np.zeros(2 * _WORDS, np.uint32)  # RTCRayHit must sit on 16 bytes
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
    scratch of 32 words."""
    f = buf.view(np.float32)
    addr = buf.ctypes.data
    for i in range(o.shape[0]):
        f[0], f[1], f[2], f[3] = o[i, 0], o[i, 1], o[i, 2], tnear
        f[4], f[5], f[6], f[7] = d[i, 0], d[i, 1], d[i, 2], 0.0
        f[_W_TFAR] = np.inf
        buf[_W_MASK], buf[_W_MASK + 1], buf[_W_MASK + 2] = _INVALID_ID, 0, 0
        buf[_W_PRIM], buf[_W_GEOM] = _INVALID_ID, _INVALID_ID
        _INTERSECT1(scene, addr, 0)
        hit = buf[_W_GEOM] != _INVALID_ID
        out_t[i] = f[_W_TFAR] if hit else np.inf
        out_prim[i] = buf[_W_PRIM]


def refine_onto_parts(geometry, o, d, t_mesh, objects, parts, delta):
    """The exact crossings (mm) near mesh hits: for each ray ``o[i] + t d[i]`` (float64, unit),
    the first root of the render object ``objects[i]``'s part ``parts[i]`` (segment or slab
    row) within ``delta`` mm of ``t_mesh[i]``, found by the tracer's own root solvers; inf where
    there is none (or no mesh hit, or a plane). Benchmarks time it as the refinement step of
    an Embree tracer given the part its triangle belongs to (here: the analytic answer's part,
    so a lower bound: an Embree tracer would also map the triangle to the part, and query again
    where the root is not there)."""
    g = geometry
    out = np.full(len(o), np.inf)
    _refine(g.seg, g.tab, g.slab_f, g.slab_i, g.obj_i, g.obj_f, np.ascontiguousarray(o, float),
            np.ascontiguousarray(d, float), np.ascontiguousarray(t_mesh, float),
            np.ascontiguousarray(objects, np.int64), np.ascontiguousarray(parts, np.int64), float(delta), out,
            np.zeros(16), np.zeros(5), np.zeros((64, 2)))
    return out


@njit(nogil=True)
def _refine(seg, tab, slab_f, slab_i, obj_i, obj_f, o, d, te, k, part, delta, out, roots, crit, stack):
    for i in range(o.shape[0]):
        kk, j = k[i], part[i]
        if kk < 0 or not np.isfinite(te[i]) or (obj_i[kk, O_KIND] != REVOLVED and j < 0):
            continue
        ox, oy, oz, dx, dy, dz = o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2]
        a, b = max(te[i] - delta, 0.0), te[i] + delta
        if obj_i[kk, O_KIND] == REVOLVED:
            n = segment_hits(seg, tab, j, ox, oy, oz, dx, dy, dz, a, b, a, b, roots, crit, stack)
        elif slab_f[j, SL_RULED] > 0.5:
            n = ruled_roots(slab_f[j], obj_f[kk, F_COS], obj_f[kk, F_SIN], ox, oy, oz, dx, dy, dz, a, b, roots)
        else:
            n = swept_roots(seg, tab, slab_i[j], obj_i[kk, O_XS], obj_i[kk, O_NSEC], obj_f[kk, F_COS],
                            obj_f[kk, F_SIN], ox, oy, oz, dx, dy, dz, a, b, obj_f[kk, F_LEAF], roots, stack)
        if n > 0:  # the normal too: a hit is a point and its normal
            t = roots[0]
            nx, ny, nz = object_normal(seg, slab_f, slab_i, obj_i, obj_f, kk, j, ox + t * dx, oy + t * dy, oz + t * dz)
            out[i] = t if nx * nx + ny * ny + nz * nz > 0.0 else np.inf
