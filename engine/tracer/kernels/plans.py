"""Free plan outlines (convex chains of lines and arcs) as the kernels evaluate them.

Design rule: a bottle of cross-section kind ``OUTLINE`` (../shared/oracle/SPEC_outline.md) has
at height z the section ``{q : sd(q, k P) <= r}``: the plan outline ``P`` (normalised, its
farthest point at distance 1 from the axis) scaled by the core ``k(z)`` and grown by ``r(z)``
(the rounding ``c`` on the outer wall, ``c - w`` on the inner one, which may be negative: then
the section is ``k P`` eroded, with sharp inner corners). Everything here rests on one identity
of convex sets: with ``h(u)`` the support function of ``P``,

    sd(q, k P) - r  =  max over unit u of  ( q . u - k h(u) - r ),

true inside and outside (inside, the nearest boundary point lies on a supporting line), for
``r`` of either sign. ``P``'s normal fan is cut into *pieces*, one table row each
(:data:`PL_COLS` columns, built by :func:`engine.tracer.tables.plans.plan_table`):

==========  ==========================================================================
``FLAT``    a line of ``P``: outward unit normal ``n``, support value ``h``: one ``u``
``ROUND``   an arc of ``P`` (centre ``C``, radius ``rho``) or a sharp corner (``C`` the
            vertex, ``rho = 0``) over a wedge of normals ``u0 -> u1`` (ccw, at most 90 deg:
            longer arcs and corners come as several rows), ``h(u) = C . u + rho``
==========  ==========================================================================

so the value is a maximum of closed forms, its gradient the maximising ``u`` and its derivative
in ``k`` ``-h(u)`` (negative: the origin is inside ``P``), in ``r`` ``-1``. The section is the
intersection over pieces of ``{max over the piece's u of (...) <= 0}``: a half-plane per
``FLAT`` row, per ``ROUND`` row the two half-planes of its end normals and, where the grown
radius ``k rho + r`` is positive, the disc of that radius inside the wedge's cone (for a
negative one the two half-planes alone: the corner stays sharp). A line's interval in the
section is therefore the intersection of closed-form intervals (:func:`plan_interval`). Where
the core and the growth change linearly along a ray (a ruled slab: both profiles straight) every
piece's condition stays linear in the point and the height, so the slab's solid is convex and
the ray's trace through it is the same intersection with each disc become one nappe of a
slanted cone (:func:`plan_trace`, :func:`plan_ruled_roots`).
Units: mm for ``k``, ``r`` and points; ``P`` is unitless.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .jit import INLINE, JIT
from .roots import disc_interval, interval_hull

FLAT, ROUND = 0, 1
#: Columns of a plan row: kind, then ``FLAT``: normal, support value; ``ROUND``: centre,
#: radius, the wedge's end normals ``u0`` and ``u1``; then every row's girth terms
#: (:func:`plan_girth`): ``PL_GK`` and ``PL_GR``, the section's arc length at the row's start
#: is ``k GK + r GR`` (a ``FLAT`` row's ``GK`` already less its start's tangent coordinate), and
#: ``PL_PERIM``, the perimeter of ``P`` (the same in every row); ``PL_ENDS`` (``ROUND`` rows): 1
#: where an end normal of the wedge is not a neighbouring ``FLAT`` row's normal, 0 where both
#: are (a corner or an arc between two lines): then the end normals' conditions are the lines'
#: own, and :func:`plan_value` and :func:`plan_trace` skip them. ``PL_HLOW``: the plan's
#: :func:`plan_support_low` (the same in every row; the certificates ask it for every band).
(PL_KIND, PL_NX, PL_NY, PL_H, PL_CX, PL_CY, PL_RHO, PL_U0X, PL_U0Y, PL_U1X, PL_U1Y,
 PL_GK, PL_GR, PL_PERIM, PL_ENDS, PL_HLOW) = range(16)
PL_COLS = 16
TWO_PI = 2.0 * math.pi


@njit(**INLINE)
def _in_wedge(row, vx, vy):
    """Whether the direction of ``v`` (not zero) lies in the row's wedge ``u0 -> u1``."""
    return (row[PL_U0X] * vy - row[PL_U0Y] * vx >= 0.0) and (vx * row[PL_U1Y] - vy * row[PL_U1X] >= 0.0)


@njit(**JIT)
def plan_value(plan, k, r, x, y):
    """``(f, gx, gy, dk)``: ``f = sd((x, y), k P) - r`` (mm, negative inside the section), its
    unit gradient (a subgradient where pieces tie: the first maximum) and ``df/dk`` (``df/dr``
    is -1). ``plan``: the table of pieces (module doc)."""
    best, gx, gy, dk = -np.inf, 1.0, 0.0, 0.0
    for i in range(plan.shape[0]):
        row = plan[i]
        if row[PL_KIND] == FLAT:
            v = x * row[PL_NX] + y * row[PL_NY] - k * row[PL_H] - r
            if v > best:
                best, gx, gy, dk = v, row[PL_NX], row[PL_NY], -row[PL_H]
            continue
        cx, cy, rho = row[PL_CX], row[PL_CY], row[PL_RHO]
        vx, vy = x - k * cx, y - k * cy
        if (vx != 0.0 or vy != 0.0) and _in_wedge(row, vx, vy):
            d = math.sqrt(vx * vx + vy * vy)
            v = d - k * rho - r
            if v > best:
                ux, uy = vx / d, vy / d
                best, gx, gy, dk = v, ux, uy, -(cx * ux + cy * uy + rho)
            continue
        if row[PL_ENDS] == 0.0:  # its end normals are its neighbouring lines'
            continue
        for e in range(2):  # outside the wedge: the largest of its end normals
            ux, uy = (row[PL_U0X], row[PL_U0Y]) if e == 0 else (row[PL_U1X], row[PL_U1Y])
            v = vx * ux + vy * uy - k * rho - r
            if v > best:
                best, gx, gy, dk = v, ux, uy, -(cx * ux + cy * uy + rho)
    return best, gx, gy, dk


@njit(**JIT)
def plan_directions(plan, k_a, k_b, k_c, x, y):
    """``(ax, ay, bx, by, cx, cy)``: the unit gradients of :func:`plan_value` at ``(x, y)`` with
    growth 0 and cores ``k_a``, ``k_b``, ``k_c`` (mm), in one pass over the pieces: the same
    values, ties and order as three calls (the first maximum wins in each)."""
    ba = bb = bc = -np.inf
    ax, ay, bx, by, cx_, cy_ = 1.0, 0.0, 1.0, 0.0, 1.0, 0.0
    for i in range(plan.shape[0]):
        row = plan[i]
        if row[PL_KIND] == FLAT:
            nx, ny, h = row[PL_NX], row[PL_NY], row[PL_H]
            d = x * nx + y * ny
            va, vb, vc = d - k_a * h, d - k_b * h, d - k_c * h
            if va > ba:
                ba, ax, ay = va, nx, ny
            if vb > bb:
                bb, bx, by = vb, nx, ny
            if vc > bc:
                bc, cx_, cy_ = vc, nx, ny
            continue
        ends = row[PL_ENDS] != 0.0
        for j in range(3):
            k = k_a if j == 0 else (k_b if j == 1 else k_c)
            best = ba if j == 0 else (bb if j == 1 else bc)
            vx, vy = x - k * row[PL_CX], y - k * row[PL_CY]
            found, v, ux, uy = False, best, 0.0, 0.0
            if (vx != 0.0 or vy != 0.0) and _in_wedge(row, vx, vy):
                d = math.sqrt(vx * vx + vy * vy)
                w = d - k * row[PL_RHO]
                if w > best:
                    found, v, ux, uy = True, w, vx / d, vy / d
            elif ends:
                for e in range(2):
                    ex, ey = (row[PL_U0X], row[PL_U0Y]) if e == 0 else (row[PL_U1X], row[PL_U1Y])
                    w = vx * ex + vy * ey - k * row[PL_RHO]
                    if w > v:
                        found, v, ux, uy = True, w, ex, ey
            if found:
                if j == 0:
                    ba, ax, ay = v, ux, uy
                elif j == 1:
                    bb, bx, by = v, ux, uy
                else:
                    bc, cx_, cy_ = v, ux, uy
    return ax, ay, bx, by, cx_, cy_


@njit(**JIT)
def plan_girth(plan, k, r, x, y):
    """``(l, L, gx, gy)``: the girth length ``l`` (mm, in ``[0, L)``) of the point ``(x, y)`` on
    the boundary of the section ``k P (+) disc(r)`` (``r >= 0``: the outer wall), ``L`` its
    perimeter (Steiner: ``k perim(P) + 2 pi r``) and its outward unit normal ``g``. ``l`` is
    the arc length counter-clockwise from the boundary point whose normal points along +x
    (a flat facing +x: the foot of the perpendicular from the axis), so it is exact and
    continuous along the boundary and the same formula at every height. A point off the
    boundary takes the length of its nearest boundary point's piece (its projection)."""
    best, row_i, ux, uy = -np.inf, 0, 1.0, 0.0
    for i in range(plan.shape[0]):
        row = plan[i]
        if row[PL_KIND] == FLAT:
            v = x * row[PL_NX] + y * row[PL_NY] - k * row[PL_H]
            if v > best:
                best, row_i, ux, uy = v, i, row[PL_NX], row[PL_NY]
            continue
        vx, vy = x - k * row[PL_CX], y - k * row[PL_CY]
        d = math.sqrt(vx * vx + vy * vy)
        if d > 0.0 and _in_wedge(row, vx, vy):
            v = d - k * row[PL_RHO]
            if v > best:
                best, row_i, ux, uy = v, i, vx / d, vy / d
    row = plan[row_i]
    length = k * row[PL_GK] + r * row[PL_GR]
    if row[PL_KIND] == FLAT:   # the tangent coordinate along the line (ccw tangent (-n_y, n_x))
        length += y * row[PL_NX] - x * row[PL_NY]
    else:                      # the angle turned from the wedge's first normal
        c = row[PL_U0X] * ux + row[PL_U0Y] * uy
        s = row[PL_U0X] * uy - row[PL_U0Y] * ux
        length += (k * row[PL_RHO] + r) * math.atan2(s, c)
    total = k * row[PL_PERIM] + TWO_PI * r
    if total > 0.0:
        length -= total * math.floor(length / total)
    return length, total, ux, uy


@njit(**JIT)
def plan_support_low(plan):
    """A lower bound of the support function ``h(u)`` of ``P`` over every direction (unitless,
    positive: the origin is inside ``P``): a line's value, an arc's least ``C . u + rho`` over
    its wedge (at an end, or ``rho - |C|`` where the wedge holds ``-C``)."""
    low = np.inf
    for i in range(plan.shape[0]):
        row = plan[i]
        if row[PL_KIND] == FLAT:
            low = min(low, row[PL_H])
            continue
        cx, cy, rho = row[PL_CX], row[PL_CY], row[PL_RHO]
        low = min(low, cx * row[PL_U0X] + cy * row[PL_U0Y] + rho, cx * row[PL_U1X] + cy * row[PL_U1Y] + rho)
        if (cx != 0.0 or cy != 0.0) and _in_wedge(row, -cx, -cy):
            low = min(low, rho - math.sqrt(cx * cx + cy * cy))
    return max(low, 0.0)


@njit(**INLINE)
def arc_dot_range(qx, qy, ax, ay, bx, by):
    """Range of ``q . u`` (mm) over the unit directions ``u`` on the shorter arc from ``a`` to
    ``b`` (unit; ``(-inf, inf)`` where they are half a turn apart or more: no shorter arc)."""
    if ax * bx + ay * by <= 0.0:
        return -np.inf, np.inf
    da, db = qx * ax + qy * ay, qx * bx + qy * by
    lo, hi = min(da, db), max(da, db)
    turn = ax * by - ay * bx  # the arc's sense: q (or -q) is on it if a -> q -> b turn that way
    if turn != 0.0:
        n = math.sqrt(qx * qx + qy * qy)
        if (ax * qy - ay * qx) * turn >= 0.0 and (qx * by - qy * bx) * turn >= 0.0:
            hi = n
        if (ay * qx - ax * qy) * turn >= 0.0 and (qy * bx - qx * by) * turn >= 0.0:
            lo = -n
    return lo, hi


@njit(**INLINE)
def _half_plane(g0, g1, lo, hi):
    """``[lo, hi]`` cut to where ``g0 + g1 t <= 0`` (empty: ``lo > hi``)."""
    if g1 > 0.0:
        hi = min(hi, -g0 / g1)
    elif g1 < 0.0:
        lo = max(lo, -g0 / g1)
    elif g0 > 0.0:
        return 1.0, -1.0
    return lo, hi


@njit(**INLINE)
def _cone(v0x, v0y, wx, wy, r0, r1):
    """``(t0, t1)``: where ``|v0 + t w| <= r0 + r1 t`` (mm): a disc's trace for ``r1 = 0``, else
    one nappe of a cone's (the side where the radius is not negative). A convex set of ``t``:
    one interval, maybe unbounded, maybe empty (``t0 > t1``)."""
    if r1 == 0.0:
        if r0 < 0.0:
            return 1.0, -1.0
        return disc_interval(v0x, v0y, wx, wy, 0.0, 0.0, r0)
    a = wx * wx + wy * wy - r1 * r1
    b = v0x * wx + v0y * wy - r0 * r1
    c = v0x * v0x + v0y * v0y - r0 * r0
    apex = -r0 / r1  # the radius is 0 there: the set lies on the side where it grows
    side0, side1 = (apex, np.inf) if r1 > 0.0 else (-np.inf, apex)
    if a == 0.0:  # the ray runs along the cone's slope: one linear condition
        if b == 0.0:
            return (side0, side1) if c <= 0.0 else (1.0, -1.0)
        t = -c / (2.0 * b)
        lo, hi = (-np.inf, t) if b > 0.0 else (t, np.inf)
        return max(lo, side0), min(hi, side1)
    disc = b * b - a * c
    if disc < 0.0:  # no crossing: everywhere inside (a < 0) or nowhere
        return (side0, side1) if a < 0.0 else (1.0, -1.0)
    h = math.sqrt(disc)
    t1, t2 = (-b - h) / a, (-b + h) / a
    t1, t2 = min(t1, t2), max(t1, t2)
    if a > 0.0:
        return max(t1, side0), min(t2, side1)
    # (a < 0: inside beyond either root; only the half-line on the growing side is the cone)
    return (t2, np.inf) if r1 > 0.0 else (-np.inf, t1)


@njit(**INLINE)
def _round_interval(row, core, grow, foot, lo, hi):
    """``[lo, hi]`` cut to a ``ROUND`` row's part of the section (module doc): its end normals'
    half-planes, and inside its cone the grown disc. ``core = (k0, k1)``, ``grow = (r0, r1)``:
    the core and growth ``k0 + k1 t``, ``r0 + r1 t`` along the line ``foot = (px, py, qx, qy)``
    (constant ones: a plane section; linear ones: a ruled slab, where the disc is a cone)."""
    k0, k1 = core
    r0, r1 = grow
    px, py, qx, qy = foot
    cx, cy, rho = row[PL_CX], row[PL_CY], row[PL_RHO]
    # the point relative to the moving centre, v0 + t w, and the grown radius rad0 + t rad1
    v0x, v0y = px - k0 * cx, py - k0 * cy
    wx, wy = qx - k1 * cx, qy - k1 * cy
    rad0, rad1 = k0 * rho + r0, k1 * rho + r1
    ux, uy, zx, zy = row[PL_U0X], row[PL_U0Y], row[PL_U1X], row[PL_U1Y]
    if row[PL_ENDS] != 0.0:  # (else they are the neighbouring lines' half-planes, cut already)
        lo, hi = _half_plane(v0x * ux + v0y * uy - rad0, wx * ux + wy * uy - rad1, lo, hi)
        lo, hi = _half_plane(v0x * zx + v0y * zy - rad0, wx * zx + wy * zy - rad1, lo, hi)
        if lo > hi:
            return lo, hi
    # the cone of the wedge from the centre: cross(u0, v) >= 0 and cross(v, u1) >= 0
    c0, c1 = _half_plane(-(ux * v0y - uy * v0x), -(ux * wy - uy * wx), -np.inf, np.inf)
    c0, c1 = _half_plane(-(v0x * zy - v0y * zx), -(wx * zy - wy * zx), c0, c1)
    c0, c1 = max(c0, lo), min(c1, hi)
    if c0 > c1:  # the line misses the cone within [lo, hi]: the half-planes decide
        return lo, hi
    d0, d1 = _cone(v0x, v0y, wx, wy, rad0, rad1)
    # allowed: [lo, hi] outside the cone, and the cone's part inside the disc (their hull: the
    # section is convex, so its trace on the line is one interval)
    a0, a1 = 1.0, -1.0
    if lo < c0:
        a0, a1 = lo, c0
    if c1 < hi:
        a0, a1 = interval_hull(a0, a1, c1, hi)
    a0, a1 = interval_hull(a0, a1, max(c0, d0), min(c1, d1))
    return a0, a1


@njit(**JIT)
def plan_trace(plan, core, grow, foot):
    """``(t_in, t_out)``: where the point ``(px, py) + t (qx, qy)`` (``foot``) lies in the section
    ``sd(., k P) <= r`` whose core and growth change along it as ``core = (k0, k1)``, ``grow =
    (r0, r1)`` (``k = k0 + k1 t``, mm): the section's trace on a line (constant ones) or a ruled
    slab's solid's on a ray (the solid is convex: every piece's condition is linear in the point
    and the height). ``t_in > t_out`` when it never is."""
    k0, k1 = core
    r0, r1 = grow
    px, py, qx, qy = foot
    lo, hi = -np.inf, np.inf
    for i in range(plan.shape[0]):  # the lines first: cheap, and most misses end here
        row = plan[i]
        if row[PL_KIND] == FLAT:
            nx, ny, h = row[PL_NX], row[PL_NY], row[PL_H]
            lo, hi = _half_plane(px * nx + py * ny - k0 * h - r0, qx * nx + qy * ny - k1 * h - r1, lo, hi)
            if lo > hi:
                return 1.0, -1.0
    for i in range(plan.shape[0]):
        row = plan[i]
        if row[PL_KIND] != FLAT:
            lo, hi = _round_interval(row, core, grow, foot, lo, hi)
            if lo > hi:
                return 1.0, -1.0
    return lo, hi


@njit(**JIT)
def plan_interval(plan, k, r, px, py, qx, qy):
    """``(t_in, t_out)``: where the 2-D line ``p + t q`` lies in the section ``sd(., k P) <= r``
    (``t_in > t_out`` when it never does); ``q = 0`` asks about the point ``p`` (``(-inf, inf)``
    or empty)."""
    return plan_trace(plan, (k, 0.0), (r, 0.0), (px, py, qx, qy))


@njit(**JIT)
def plan_ruled_roots(plan, coeffs, rot, ray, lo, hi, out):
    """Exact crossings (ascending, at most 2, into ``out``) in ``[lo, hi]`` of the ray with an
    outline wall in a ruled slab: core ``k = K0 + K1 z`` and growth ``r = R0 + R1 z`` (mm,
    ``coeffs = (K0, K1, R0, R1)``), the bottle turned by ``rot = (cos, sin)``. The slab's solid
    is convex (:func:`plan_trace`), so the ray enters and leaves it once: an end of its trace
    strictly inside ``[lo, hi]`` is a crossing of the wall (ends at ``lo`` or ``hi`` are the
    slab's own planes)."""
    K0, K1, R0, R1 = coeffs
    c, s = rot
    ox, oy, oz, dx, dy, dz = ray
    # from the slab entry, so that far origins lose no digits
    ox, oy, oz = ox + lo * dx, oy + lo * dy, oz + lo * dz
    px, py = c * ox + s * oy, -s * ox + c * oy
    qx, qy = c * dx + s * dy, -s * dx + c * dy
    t0, t1 = plan_trace(plan, (K0 + K1 * oz, K1 * dz), (R0 + R1 * oz, R1 * dz), (px, py, qx, qy))
    n = 0
    if t0 > t1:
        return 0
    span = hi - lo
    for t in (t0, t1):
        if t > 0.0 and t < span and n < out.shape[0]:
            out[n] = t + lo
            n += 1
    return n
