"""Exact hits on the walls of non-round bottles (rounded square, rounded rectangle, oval).

Design rule: such a wall is the implicit surface ``g(x, y, z) = sd(x, y; radii(z)) = 0``
(../shared/oracle/SPEC.md section 4.3; :mod:`engine.geometry.crosssection` and
:meth:`engine.geometry.body.BottleBody.wall_implicit` in numpy), the radii being the sections'
r(z). It has no closed form; its crossings along a ray come from the certified bands of
:mod:`~engine.tracer.kernels.bands` (monotone in the radii, closed-form 2-D outlines), which
need no slope bound, so a heel leaving the standing plane horizontally is no special case.
The wall is cut into *slabs* between the sections' joint heights, so that in each slab every
section is one segment row. The normal is the normalised gradient of ``g``, with
``dg/dz = sum_k dsd/dr_k * T_r,k / T_z,k`` multiplied through by the ``T_z`` (finite where a
section turns horizontal). Units: mm; outlines in the bottle frame (world turned by
``-rotation_deg`` about z).
"""
from __future__ import annotations

import math

from numba import njit

from .bands import band_roots
from .outlines import OUTLINE, RSQUARE, rrect_sd, square_corner, xs_eval
from .profile import S_R0, S_R1, S_Z0, S_Z1, wall_state
from .jit import INLINE, JIT
from .records import Wall
from .roots import quadratic, sort_small

#: Columns of the slab table (``slab_f``): the slab's heights, its circumradius (mm), whether
#: it is ruled (1.0) and, for a ruled slab, :func:`ruled_coefficients`.
SL_Z0, SL_Z1, SL_RMAX, SL_RULED, SL_A0, SL_KA, SL_B0, SL_KB, SL_C0, SL_KC = range(10)
SL_COLS = 10


@njit(**INLINE)
def swept_wall(seg, tab, slab_seg, kind, nsec, rot, plan):
    """The :class:`~.records.Wall` of one slab: sections of cross-section ``kind`` on segment
    rows ``slab_seg`` (``nsec`` of them), the bottle turned by ``rot = (cos, sin)``, a free
    outline's pieces ``plan`` (:mod:`.plans`)."""
    r1 = slab_seg[1] if nsec > 1 else slab_seg[0]
    r2 = slab_seg[2] if nsec > 2 else slab_seg[0]
    return Wall(seg, tab, slab_seg[0], r1, r2, nsec, kind, rot[0], rot[1], plan)


@njit(**JIT)
def swept_roots(wall, ray, lo, hi, leaf, out, stack):
    """Crossings (mm, ascending, at most ``len(out)``) of the ray with the swept ``wall`` of one
    slab (:func:`swept_wall`), for ``t`` in ``[lo, hi]``."""
    return band_roots(wall, ray, lo, hi, leaf, out, 0, stack)


@njit(**JIT)
def swept_normal(wall, px, py, pz):
    """Unit gradient (world) of the swept ``wall``'s residual (a :class:`~.records.Wall`,
    :func:`swept_wall`) at ``p`` (mm): points out of the outline."""
    seg, _, s0, s1, s2, nsec, kind, cos_r, sin_r, plan = wall
    x, y = cos_r * px + sin_r * py, -sin_r * px + cos_r * py
    r0, tr0, tz0 = wall_state(seg, s0, pz)
    r1, tr1, tz1, r2, tr2, tz2 = 0.0, 0.0, 1.0, 0.0, 0.0, 1.0
    if nsec > 1:
        r1, tr1, tz1 = wall_state(seg, s1, pz)
    if nsec > 2:
        r2, tr2, tz2 = wall_state(seg, s2, pz)
    _, gx, gy, d0, d1, d2 = xs_eval(plan, kind, r0, r1, r2, x, y)
    tz0, tz1, tz2 = max(tz0, 1e-300), max(tz1, 1e-300), max(tz2, 1e-300)
    gz = d0 * tr0 * tz1 * tz2 + d1 * tr1 * tz0 * tz2 + d2 * tr2 * tz0 * tz1
    prod = tz0 * tz1 * tz2
    wx = (cos_r * gx - sin_r * gy) * prod
    wy = (sin_r * gx + cos_r * gy) * prod
    h = math.sqrt(wx * wx + wy * wy + gz * gz)
    return wx / h, wy / h, gz / h


@njit(**INLINE)
def _ruled_roots(cone, sx, sy, foot, lo, hi, out, n):
    """Crossings with one corner of a rounded-rectangle wall whose corner centre
    ``(sx hx(z), sy hy(z))`` and radius ``c(z)`` are linear in the height (a slanted circular
    cone), kept where the point lies in that corner's quadrant; appended to ``out``. Asked only
    for a corner the ray is in at an end of its box interval, so the quadratic is always solved.
    ``cone`` = ``(cx0, cx1, cy0, cy1, r0, r1)``: ``hx = cx0 + cx1 t``, ``hy``, ``c`` likewise
    along the ray; ``foot`` = ``(px, py, qx, qy)``, the ray's footprint ``p + t q``."""
    cx0, cx1, cy0, cy1, r0, r1 = cone
    px, py, qx, qy = foot
    # along the ray: hx = cx0 + cx1 t etc. (t measured from the ray origin)
    ux0, ux1 = px - sx * cx0, qx - sx * cx1
    uy0, uy1 = py - sy * cy0, qy - sy * cy1
    A = ux1 * ux1 + uy1 * uy1 - r1 * r1
    B = ux0 * ux1 + uy0 * uy1 - r0 * r1
    C = ux0 * ux0 + uy0 * uy0 - r0 * r0
    k, t0, t1 = quadratic(A, B, C)
    for j in range(k):
        t = t0 if j == 0 else t1
        if not (t >= lo and t <= hi) or r0 + r1 * t < 0.0:
            continue
        x, y = px + t * qx, py + t * qy
        if sx * x >= cx0 + cx1 * t and sy * y >= cy0 + cy1 * t and n < out.shape[0]:
            out[n] = t
            n += 1
    return n


@njit(**JIT)
def ruled_roots(sl, cos_r, sin_r, ray, lo, hi, out):
    """Exact crossings (ascending) in ``[lo, hi]`` with a rounded-square or rounded-rectangle
    wall in a ruled slab (``sl``, its row of the slab table: every section a straight line, so
    the outline's half extents and corner radius are linear in z, ``SL_A0..SL_KC``): the four
    sides are planes and the four corners slanted circular cones.

    The slab's solid is convex (at each height a rectangle grown by a disc, both linear in z: a
    Minkowski combination of its end outlines), so a ray crosses the wall at most twice. Its
    interval in the outline's bounding box (the four side planes) comes first: an end of that
    interval on a side's flat part is a crossing (where the box's face is the wall), an end in a
    corner's quadrant asks that corner's cone (one quadratic), and a ray missing the box misses
    the wall. Outside the corners' quadrants the box is inside the wall, and the parts of the
    box outside the wall are the four corner pieces, which the wall's flat bands keep apart:
    so the ray enters and leaves the wall in the quadrants where it enters and leaves the box."""
    ox, oy, oz, dx, dy, dz = ray
    # from the slab entry, so that far origins lose no digits
    ox, oy, oz = ox + lo * dx, oy + lo * dy, oz + lo * dz
    base, hi, lo = lo, hi - lo, 0.0
    px, py = cos_r * ox + sin_r * oy, -sin_r * ox + cos_r * oy
    qx, qy = cos_r * dx + sin_r * dy, -sin_r * dx + cos_r * dy
    ea0, eka, eb0, ekb, c0, kc = sl[SL_A0], sl[SL_KA], sl[SL_B0], sl[SL_KB], sl[SL_C0], sl[SL_KC]
    ha0, hka, hb0, hkb = ea0 - c0, eka - kc, eb0 - c0, ekb - kc
    # the box: sides sgn x <= a(z) and sgn y <= b(z), each g0 + g1 t <= 0 along the ray
    t_in, t_out = lo, hi
    for side in range(4):
        sgn = 1.0 if side % 2 == 0 else -1.0
        if side < 2:
            g0, g1 = sgn * px - ea0 - eka * oz, sgn * qx - eka * dz
        else:
            g0, g1 = sgn * py - eb0 - ekb * oz, sgn * qy - ekb * dz
        if g1 > 0.0:
            t_out = min(t_out, -g0 / g1)
        elif g1 < 0.0:
            t_in = max(t_in, -g0 / g1)
        elif g0 > 0.0:  # parallel to a side, outside it
            return 0
    if t_in > t_out:
        return 0
    n = 0
    solved = -1  # the corner whose cone has been asked
    for end in range(2):
        t = t_in if end == 0 else t_out
        x, y, z = px + t * qx, py + t * qy, oz + t * dz
        hx, hy = ha0 + hka * z, hb0 + hkb * z
        if abs(x) > hx and abs(y) > hy:  # in a corner's quadrant: its cone decides
            corner = (1 if x > 0.0 else 0) | (2 if y > 0.0 else 0)
            if corner != solved:
                solved = corner
                n = _ruled_roots((ha0 + hka * oz, hka * dz, hb0 + hkb * oz, hkb * dz, c0 + kc * oz, kc * dz),
                                 1.0 if corner & 1 else -1.0, 1.0 if corner & 2 else -1.0,
                                 (px, py, qx, qy), lo, hi, out, n)
        elif (t > lo if end == 0 else t < hi) and n < out.shape[0]:  # the box's face is the wall
            out[n] = t
            n += 1
    for i in range(n):
        out[i] += base
    sort_small(out, n)  # at most 4
    return n


@njit(**JIT)
def ruled_normal(sl, cos_r, sin_r, px, py, pz):
    """:func:`swept_normal` in a ruled slab (``sl``, as :func:`ruled_roots`): the outline's
    radii are linear in z, so the gradient's z part is their slopes times the outline's
    derivatives in them (no section evaluated)."""
    x, y = cos_r * px + sin_r * py, -sin_r * px + cos_r * py
    ka, kb, kc = sl[SL_KA], sl[SL_KB], sl[SL_KC]
    _, gx, gy, da, db, dc = rrect_sd(x, y, sl[SL_A0] + ka * pz, sl[SL_B0] + kb * pz, sl[SL_C0] + kc * pz)
    gz = da * ka + db * kb + dc * kc
    wx, wy = cos_r * gx - sin_r * gy, sin_r * gx + cos_r * gy
    h = math.sqrt(wx * wx + wy * wy + gz * gz)
    return wx / h, wy / h, gz / h


def ruled_coefficients(kind, rows):
    """``(A0, KA, B0, KB, C0, KC)``: the outline's half extents ``a = A0 + KA z``, ``b = B0 +
    KB z`` and corner radius ``c = C0 + KC z`` (mm) in a slab whose sections are the straight
    segment rows ``rows`` (``(seg row, ...)`` of :mod:`.profile`, one per section) of a rounded
    square (sections ``u, v``) or rounded rectangle (half width, half depth, corner); for a free
    outline (``OUTLINE``) its core and growth, ``(K0, K1, R0, R1, 0, 0)``."""
    lines = []
    for r in rows:
        k = (r[S_R1] - r[S_R0]) / (r[S_Z1] - r[S_Z0])
        lines.append((r[S_R0] - k * r[S_Z0], k))
    (a0, ka), (b0, kb) = lines[0], lines[1]
    if kind == OUTLINE:  # the core and the growth (:func:`.plans.plan_ruled_roots`)
        return a0, ka, b0, kb, 0.0, 0.0
    if kind == RSQUARE:  # u = a = b, the corner q(u, v), linear in both
        return a0, ka, a0, ka, square_corner(a0, b0), square_corner(ka, kb)
    c0, kc = lines[2]
    return a0, ka, b0, kb, c0, kc
