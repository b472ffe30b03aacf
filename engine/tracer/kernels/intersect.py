"""Nearest hit over the render objects: the surface interaction of a ray.

Design rule: a render object (one row of ``obj_i`` / ``obj_f``, :mod:`engine.tracer.
render_objects`) is a surface with an exact intersector (revolved chain, swept wall, plane
region or the stage's backdrop sweep), the medium on each side of its oriented normal (switching at a height for the inner
wall, which is wet below the fill line) and a material. :func:`nearest_hit` returns the first
true crossing along a ray and never the crossing the ray started from: a hit on the object
the ray just left counts only when it crosses back from the side the ray went to (a ray on
one side of a surface can only cross it towards the other), and a hit at a rounding-level
distance on a *neighbouring* object counts only when its media agree with the ray's medium
(a ray leaving an edge). No origin offsets, no epsilon along the normal. The objects
partition space into media, so only those bounding the ray's medium are searched.

A hit is ``(t, object, part, geometric normal)``: the geometric normal decides the media;
what lies on the surface there (a label's decal, a finish's shading normal from its surface
coordinates, :func:`engine.tracer.kernels.finish.shading_frame`) is looked up from it by the
appearance kernels.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .helix import helix_roots
from .outlines import OUTLINE, outline_sd
from .plans import plan_ruled_roots
from .profile import HELIX, LINE, OFFSET, S_KIND, S_R0, S_R1, S_RMAX, S_RMIN, S_Z0, S_Z1, S_ZMAX, S_ZMIN
from .revolved import PARAM_SLOT, ray_axis, ray_box_from, segment_hits, segment_normal
from .jit import INLINE, JIT
from .records import Hit
from .roots import cone_roots
from .swept import (SL_A0, SL_B0, SL_KA, SL_KB, SL_RMAX, SL_RULED, SL_Z0, SL_Z1, ruled_normal, ruled_roots,
                    swept_normal, swept_roots, swept_wall)

# object kinds
REVOLVED, SWEPT, PLANE, SWEEP = 0, 1, 2, 3
# obj_i columns
(O_KIND, O_FIRST, O_COUNT, O_XS, O_XS_IN, O_NSEC, O_FRONT_LO, O_BACK_LO, O_FRONT_HI, O_BACK_HI, O_MAT,
 O_ZSORT) = range(12)
O_COLS = 12
# obj_f columns
(F_NSIGN, F_ZSPLIT, F_RMAX, F_ZMIN, F_ZMAX, F_PZ, F_PNZ, F_OUT0, F_OUT1, F_OUT2, F_IN0, F_IN1,
 F_IN2, F_COS, F_SIN, F_LEAF, F_EDGE) = range(17)
F_COLS = 17
#: A backdrop sweep's (``SWEEP``) numbers in its ``obj_f`` row: the floor's height (mm) in
#: ``F_PZ``, its facing (``F_COS``, ``F_SIN``: the unit horizontal direction from the bottle
#: towards the wall), and these: where the curve leaves the floor (distance from the axis),
#: the curve's radius, the wall's half width and its top (mm; :func:`_sweep_hit`).
F_SW_START, F_SW_RADIUS, F_SW_HALF, F_SW_TOP = F_OUT0, F_OUT1, F_OUT2, F_IN0
#: A sweep's parts: the quarter cylinder rising from the floor, and the vertical wall above it.
SWEEP_CURVE, SWEEP_WALL = 0, 1
#: The object a ray leaves is searched from this fraction of the edge distance on (1e-9 of the
#: bottle's size): below the noise of any root, far below any legitimate re-hit.
START_FRACTION = 1e-2

@njit(**JIT)
def object_media(obj_i, obj_f, k, z):
    """``(front, back)`` medium ids of object ``k`` at height ``z`` (mm)."""
    if z < obj_f[k, F_ZSPLIT]:
        return obj_i[k, O_FRONT_LO], obj_i[k, O_BACK_LO]
    return obj_i[k, O_FRONT_HI], obj_i[k, O_BACK_HI]


@njit(**JIT)
def object_normal(geom, k, part, px, py, pz, param=np.nan):
    """Oriented unit normal of object ``k`` of ``geom`` (a :class:`~.records.Geometry`) at its
    point ``p``; ``part`` is the segment row (revolved) or slab row (swept) the hit was found on,
    ``param`` the point's base angle on an offset arc when its root solve knows it (else
    ``nan``)."""
    seg, tab, slab_f, slab_i, obj_i, obj_f, plan = geom
    kind = obj_i[k, O_KIND]
    sgn = obj_f[k, F_NSIGN]
    if kind == PLANE:
        return 0.0, 0.0, obj_f[k, F_PNZ]
    if kind == SWEEP:
        return _sweep_normal(obj_f, k, part, px, py, pz)
    if kind == REVOLVED:
        nx, ny, nz = segment_normal(seg, part, px, py, pz, param)
    elif slab_f[part, SL_RULED] > 0.5 and obj_i[k, O_XS] != OUTLINE:
        nx, ny, nz = ruled_normal(slab_f[part], obj_f[k, F_COS], obj_f[k, F_SIN], px, py, pz)
    else:
        nx, ny, nz = swept_normal(_wall(geom, k, part), px, py, pz)
    return sgn * nx, sgn * ny, sgn * nz


@njit(**INLINE)
def root_param(seg, obj_i, k, part, roots, q):
    """Root ``q``'s base angle (rad) on ``part`` of object ``k`` when its solve knows it (an
    offset arc's, written beside the roots at :data:`~.revolved.PARAM_SLOT`), else ``nan``:
    what :func:`object_normal` takes to skip solving for it again."""
    if obj_i[k, O_KIND] == REVOLVED and seg[part, S_KIND] == OFFSET:
        return roots[PARAM_SLOT + q]
    return np.nan


@njit(**JIT)
def _accept(obj_i, obj_f, k, t, dn, pz, medium, last_obj, last_side):
    """Whether a crossing of object ``k`` at ``t`` and height ``pz`` (mm), where the ray meets
    the oriented normal with ``dn = n . d``, is a true next hit (module doc)."""
    side = 1 if dn >= 0.0 else -1
    if k == last_obj and side == last_side:
        return False
    if t < obj_f[k, F_EDGE]:
        front, back = object_media(obj_i, obj_f, k, pz)
        inc = front if dn < 0.0 else back
        if inc != medium:
            return False
    return True


@njit(**INLINE)
def _wall(geom, k, part):
    """The :class:`~.records.Wall` of swept object ``k`` in its slab row ``part``."""
    return swept_wall(geom.seg, geom.tab, geom.slab_i[part], geom.obj_i[k, O_XS], geom.obj_i[k, O_NSEC],
                      (geom.obj_f[k, F_COS], geom.obj_f[k, F_SIN]), geom.plan)


@njit(**INLINE)
def _ruled(geom, k, j, ray, a, b, roots):
    """Crossings in ``[a, b]`` of swept object ``k`` in its ruled slab row ``j`` (closed form)."""
    sl, obj_f = geom.slab_f[j], geom.obj_f
    if geom.obj_i[k, O_XS] == OUTLINE:
        return plan_ruled_roots(geom.plan, (sl[SL_A0], sl[SL_KA], sl[SL_B0], sl[SL_KB]),
                                (obj_f[k, F_COS], obj_f[k, F_SIN]), ray, a, b, roots)
    return ruled_roots(sl, obj_f[k, F_COS], obj_f[k, F_SIN], ray, a, b, roots)


@njit(**JIT)
def _plane_hit(geom, k, ray, tlo, thi):
    """Distance to plane object ``k`` of ``geom`` inside its outline region, or ``inf``."""
    obj_i, obj_f, plan = geom.obj_i, geom.obj_f, geom.plan
    ox, oy, oz, dx, dy, dz = ray
    if dz == 0.0:
        return np.inf
    t = (obj_f[k, F_PZ] - oz) / dz
    if not (t > tlo and t < thi):
        return np.inf
    x, y = ox + t * dx, oy + t * dy
    c, s = obj_f[k, F_COS], obj_f[k, F_SIN]
    xb, yb = c * x + s * y, -s * x + c * y
    if outline_sd(plan, obj_i[k, O_XS], obj_f[k, F_OUT0], obj_f[k, F_OUT1], obj_f[k, F_OUT2], xb, yb) > 0.0:
        return np.inf
    if obj_i[k, O_XS_IN] >= 0:
        if outline_sd(plan, obj_i[k, O_XS_IN], obj_f[k, F_IN0], obj_f[k, F_IN1], obj_f[k, F_IN2], xb, yb) < 0.0:
            return np.inf
    return t


@njit(**INLINE)
def _sweep_normal(obj_f, k, part, px, py, pz):
    """Unit normal of sweep object ``k`` at its point ``p`` on ``part``, facing the bottle: on
    the curve towards its axis, on the wall back towards the bottle."""
    c, s = obj_f[k, F_COS], obj_f[k, F_SIN]
    if part == SWEEP_WALL:
        return -c, -s, 0.0
    r = obj_f[k, F_SW_RADIUS]
    nv = (obj_f[k, F_SW_START] - (c * px + s * py)) / r
    nz = (obj_f[k, F_PZ] + r - pz) / r
    h = 1.0 / np.sqrt(nv * nv + nz * nz)
    return c * nv * h, s * nv * h, nz * h


@njit(**JIT)
def _sweep_hit(obj_f, k, ray, tlo, thi, roots):
    """Crossings of the ray with sweep object ``k`` in ``(tlo, thi)``, nearest first, written
    into ``roots`` as ``t`` and into ``roots[4:]`` as their parts; returns how many (at most 3).

    In the sweep's vertical plane of depth ``v`` (along its facing, from the axis) and height
    ``z`` the surface is a quarter circle of radius ``R`` about ``(v0, z0 + R)`` from the floor
    point ``(v0, z0)`` to ``(v0 + R, z0 + R)``, then the line ``v = v0 + R`` up to the top,
    extruded across ``|u| <= half width``: a circle and a line in 2D, solved in closed form."""
    ox, oy, oz, dx, dy, dz = ray
    c, s = obj_f[k, F_COS], obj_f[k, F_SIN]
    v0, r, half, top, z0 = obj_f[k, F_SW_START], obj_f[k, F_SW_RADIUS], obj_f[k, F_SW_HALF], obj_f[k, F_SW_TOP], \
        obj_f[k, F_PZ]
    ov, ou, dv, du = c * ox + s * oy, -s * ox + c * oy, c * dx + s * dy, -s * dx + c * dy
    n = 0
    # the curve: |(ov - v0 + t dv, oz - zc + t dz)| = r, solved from the ray's closest approach
    # to the circle's centre in the plane (a far origin's large terms cancel there first: a
    # ray skimming the floor from 100 m keeps its hit to the rounding of its own origin)
    zc = z0 + r
    pv, pz = ov - v0, oz - zc
    a = dv * dv + dz * dz
    if a > 0.0:
        tc = -(pv * dv + pz * dz) / a
        qv, qz = pv + tc * dv, pz + tc * dz
        q = math.sqrt(qv * qv + qz * qz)
        if q <= r:
            dt = math.sqrt((r - q) * (r + q) / a)
            for t in (tc - dt, tc + dt):
                if t > tlo and t < thi and pv + t * dv >= 0.0 and pz + t * dz <= 0.0 and abs(ou + t * du) <= half:
                    roots[n], roots[4 + n] = t, SWEEP_CURVE
                    n += 1
    if dv != 0.0:  # the wall
        t = (v0 + r - ov) / dv
        z = oz + t * dz
        if t > tlo and t < thi and z > zc and z <= top and abs(ou + t * du) <= half:
            roots[n], roots[4 + n] = t, SWEEP_WALL
            n += 1
    for i in range(1, n):  # nearest first (the curve's two already are)
        j = i
        while j > 0 and roots[j] < roots[j - 1]:
            roots[j], roots[j - 1], roots[4 + j], roots[3 + j] = roots[j - 1], roots[j], roots[3 + j], roots[4 + j]
            j -= 1
    return n


@njit(**INLINE)
def _first_reaching(seg, slab_f, revolved, j0, j1, z):
    """First part in ``[j0, j1)`` (rising in z) whose top is at or above ``z`` (binary search)."""
    while j0 < j1:
        m = (j0 + j1) // 2
        top = seg[m, S_ZMAX] if revolved else slab_f[m, SL_Z1]
        if top < z:
            j0 = m + 1
        else:
            j1 = m
    return j0


@njit(**JIT)
def nearest_hit(geom, ray, medium, last_obj, last_side, scratch):
    """First true crossing of the ray ``o + t d`` (mm, unit ``d``, ``t > 0``) with any object of
    ``geom`` (a :class:`~.records.Geometry`), for a ray in ``medium`` that left ``last_obj`` with
    ``d . n`` of sign ``last_side`` (``-1`` / ``0`` for a fresh ray).

    Returns a :class:`~.records.Hit`: ``obj = -1`` (and ``t = inf``) for a miss; ``part`` the
    segment or slab row; ``n`` the object's oriented unit normal there. ``scratch`` is the
    worker's :class:`~.records.Scratch`.
    """
    ox, oy, oz, dx, dy, dz = ray
    seg, tab, slab_f, slab_i, obj_i, obj_f, _ = geom
    roots, crit, stack = scratch
    best = np.inf
    best_k, best_part = -1, -1
    best_param = np.nan  # the best crossing's base angle on an offset arc (its normal's)
    bnx, bny, bnz = 0.0, 0.0, 0.0
    pending = False  # the best crossing's normal is still to compute
    axis = ray_axis(ox, oy, dx, dy, dz)
    n_obj = obj_i.shape[0]
    for step in range(n_obj + 1):
        # the object the ray leaves comes last: it is rarely met again, and a crossing found on
        # another first bounds its search (3-8 % of the search's time on the frames' queries)
        k = step if step < n_obj else last_obj
        if k < 0 or (step < n_obj and k == last_obj):
            continue
        # the objects partition space into media: a ray meets only surfaces that bound its
        # medium (a ray in the liquid never tests the outer wall, the bottom or the rim)
        if (obj_i[k, O_FRONT_LO] != medium and obj_i[k, O_BACK_LO] != medium and obj_i[k, O_FRONT_HI] != medium
                and obj_i[k, O_BACK_HI] != medium):
            continue
        # on the object the ray leaves, search from a hair past its start: the start itself is a
        # root, whose computed sign is rounding noise and would fool every sign test there
        t0 = START_FRACTION * obj_f[k, F_EDGE] if k == last_obj else 0.0
        lo, hi = ray_box_from(axis, ray, 0.0, obj_f[k, F_RMAX], obj_f[k, F_ZMIN],
                              obj_f[k, F_ZMAX], t0, best)
        if lo > hi:
            continue
        kind = obj_i[k, O_KIND]
        if kind == PLANE:
            t = _plane_hit(geom, k, ray, t0, best)
            if t < best:
                pz = oz + t * dz
                nz = obj_f[k, F_PNZ]
                if _accept(obj_i, obj_f, k, t, 0.0 * dx + 0.0 * dy + nz * dz, pz, medium, last_obj, last_side):
                    best, best_k, best_part, pending = t, k, -1, False
                    bnx, bny, bnz = 0.0, 0.0, nz
                    best_param = np.nan
            continue
        if kind == SWEEP:
            n = _sweep_hit(obj_f, k, ray, t0, best, roots)
            for q in range(n):
                t, part = roots[q], int(roots[4 + q])
                px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
                nx, ny, nz = _sweep_normal(obj_f, k, part, px, py, pz)
                if _accept(obj_i, obj_f, k, t, nx * dx + ny * dy + nz * dz, pz, medium, last_obj, last_side):
                    best, best_k, best_part, pending = t, k, part, False
                    bnx, bny, bnz = nx, ny, nz
                    best_param = np.nan
                    break
            continue
        first, count = obj_i[k, O_FIRST], obj_i[k, O_COUNT]
        j0, j1 = first, first + count
        if obj_i[k, O_ZSORT] != 0:  # parts rise in z: visit only those the ray's heights meet
            za, zb = oz + lo * dz, oz + hi * dz
            z_lo, z_hi = min(za, zb), max(za, zb)
            j0 = _first_reaching(seg, slab_f, kind == REVOLVED, first, first + count, z_lo)
        for j in range(j0, j1):
            if kind == REVOLVED:
                if obj_i[k, O_ZSORT] != 0 and seg[j, S_ZMIN] > z_hi:
                    break
                a, b = ray_box_from(axis, ray, seg[j, S_RMIN], seg[j, S_RMAX],
                                    seg[j, S_ZMIN], seg[j, S_ZMAX], t0, best)
                if a > b:
                    continue
                if seg[j, S_KIND] == LINE:  # the common case, without a call
                    n = cone_roots(ray, seg[j, S_R0], seg[j, S_Z0], seg[j, S_R1],
                                   seg[j, S_Z1], t0, roots)
                elif seg[j, S_KIND] == HELIX:
                    # a true thread: its first crossing only, the one the loop below takes, unless
                    # it lies within the edge distance, where _accept may refuse it (the start
                    # found again, an edge's rounding): then the second too
                    n = helix_roots(seg, j, ray, max(a, t0), min(b, best), roots, 1)
                    if n > 0 and roots[0] < obj_f[k, F_EDGE]:
                        n = helix_roots(seg, j, ray, max(a, t0), min(b, best), roots, 2)
                else:
                    n = segment_hits(seg, tab, j, ray, t0, best, a, b, roots, crit, stack)
            else:
                if slab_f[j, SL_Z0] > z_hi:
                    break
                a, b = ray_box_from(axis, ray, 0.0, slab_f[j, SL_RMAX], slab_f[j, SL_Z0],
                                    slab_f[j, SL_Z1], t0, best)
                if a > b:
                    continue
                if slab_f[j, SL_RULED] > 0.5:  # straight sections: planes and slanted cones, closed form
                    n = _ruled(geom, k, j, ray, a, b, roots)
                else:
                    n = swept_roots(_wall(geom, k, j), ray, a, b, obj_f[k, F_LEAF], roots, stack)
            for q in range(n):
                t = roots[q]
                if not (t > t0 and t < best):
                    continue
                pz = oz + t * dz
                if pz < obj_f[k, F_ZMIN] or pz > obj_f[k, F_ZMAX]:
                    continue
                param = root_param(seg, obj_i, k, j, roots, q)
                if k != last_obj and t >= obj_f[k, F_EDGE]:
                    # _accept takes any such crossing whatever its normal: the normal waits
                    # until the nearest is known (a nearer object or slab often replaces it)
                    best, best_k, best_part, pending, best_param = t, k, j, True, param
                    break
                px, py = ox + t * dx, oy + t * dy
                nx, ny, nz = object_normal(geom, k, j, px, py, pz, param)
                if _accept(obj_i, obj_f, k, t, nx * dx + ny * dy + nz * dz, pz, medium, last_obj, last_side):
                    best, best_k, best_part, pending = t, k, j, False
                    bnx, bny, bnz = nx, ny, nz
                    break
    if pending:
        bnx, bny, bnz = object_normal(geom, best_k, best_part, ox + best * dx, oy + best * dy, oz + best * dz,
                                      best_param)
    return Hit(best, best_k, best_part, bnx, bny, bnz)
