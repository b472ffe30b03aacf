"""Horizontal outlines (cross-sections at one height) as the kernels evaluate them.

Design rule: an outline is a circle ``(r)``, an oval ``(a, b)``, a rounded rectangle
``(a, b, c)`` (a rounded square ``(u, v)`` is the rounded rectangle ``(u, u, q)``) or a free
plan outline's section ``(k, r)`` (``OUTLINE``, evaluated by :mod:`.plans` on the plan's
table, which every call here takes and the fixed kinds ignore), in the bottle's own frame, in
mm, as in :mod:`engine.geometry.crosssection`. Three things are asked
of it: a signed value (negative inside; the exact distance for the rounded shapes, ``S - 1`` for
the oval) with its derivatives in the radii, the interval along a 2-D line that lies inside it
(closed form: the rounded rectangle is its bounding box cut at the corners by four discs), and
for the rounded rectangle the range of its unit gradients over ranges of points and sizes (the
monotonicity certificate of :mod:`~engine.tracer.kernels.bands`).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .jit import INLINE, JIT
from .plans import plan_interval, plan_value
from .roots import disc_interval, interval_hull

#: ``OUTLINE``: a free plan outline (:mod:`.plans`), radii ``(k, r)``: its core scale and growth
CIRCLE, RRECT, RSQUARE, OVAL, OUTLINE = 0, 1, 2, 3, 4
SQRT2 = math.sqrt(2.0)
DQ_DU, DQ_DV = (SQRT2 + 1.0) * SQRT2, -(SQRT2 + 1.0)


@njit(**INLINE)
def square_corner(u, v):
    """Corner radius ``q`` (mm) of the rounded square with half-width ``u``, diagonal ``v``."""
    return (SQRT2 + 1.0) * (SQRT2 * u - v)


@njit(**INLINE)
def rrect_sd(x, y, a, b, c):
    """Signed distance (mm) to the rounded rectangle ``(a, b, c)`` and its derivatives
    ``(sd, gx, gy, d_a, d_b, d_c)`` (gradient unit)."""
    sx = -1.0 if x < 0.0 else 1.0
    sy = -1.0 if y < 0.0 else 1.0
    dx = abs(x) - (a - c)
    dy = abs(y) - (b - c)
    ox, oy = max(dx, 0.0), max(dy, 0.0)
    out = math.sqrt(ox * ox + oy * oy)
    if out > 0.0:
        gpx, gpy = ox / out, oy / out
    elif dx > dy:
        gpx, gpy = 1.0, 0.0
    else:
        gpx, gpy = 0.0, 1.0
    sd = out + min(max(dx, dy), 0.0) - c
    return sd, sx * gpx, sy * gpy, -gpx, -gpy, gpx + gpy - 1.0


@njit(**JIT)
def xs_eval(plan, kind, r0, r1, r2, x, y):
    """``(f, gx, gy, d0, d1, d2)``: the swept kind's signed value at section radii ``r0..r2``
    (RSQUARE ``(u, v)``, RRECT ``(a, b, c)``, OVAL ``(a, b)``, CIRCLE ``(r)``, OUTLINE ``(k, r)``
    of the outline ``plan``), its (x, y) gradient and its derivatives in the radii. Decreasing in
    every radius but a rectangle's corner; |d/d radius| <= 1 for the rounded shapes."""
    if kind == OUTLINE:
        f, gx, gy, dk = plan_value(plan, r0, r1, x, y)
        return f, gx, gy, dk, -1.0, 0.0
    if kind == RSQUARE:
        sd, gx, gy, da, db, dc = rrect_sd(x, y, r0, r0, square_corner(r0, r1))
        return sd, gx, gy, da + db + dc * DQ_DU, dc * DQ_DV, 0.0
    if kind == RRECT:
        return rrect_sd(x, y, r0, r1, r2)
    if kind == CIRCLE:
        rho = math.sqrt(x * x + y * y)
        if rho == 0.0:
            return -r0, 1.0, 0.0, -1.0, 0.0, 0.0
        return rho - r0, x / rho, y / rho, -1.0, 0.0, 0.0
    s = math.sqrt((x / r0) ** 2 + (y / r1) ** 2)
    if s == 0.0:
        return -1.0, 1.0, 0.0, 0.0, 0.0, 0.0
    return (s - 1.0, x / (r0 * r0 * s), y / (r1 * r1 * s), -x * x / (r0 ** 3 * s),
            -y * y / (r1 ** 3 * s), 0.0)


@njit(**INLINE)
def box_direction(dx, dy, x_first):
    """Unit gradient ``(g_x, g_y)`` (first quadrant) of a rounded rectangle at a point whose
    offsets from its inner box are ``(dx, dy) = (|x| - (a - c), |y| - (b - c))`` (mm), as
    :func:`rrect_sd` takes it; on the inner diagonal (``dx = dy <= 0``, where both axes are
    subgradients) ``x_first`` picks the x axis."""
    ox, oy = max(dx, 0.0), max(dy, 0.0)
    h = math.sqrt(ox * ox + oy * oy)
    if h > 0.0:
        return ox / h, oy / h
    if dx > dy or (x_first and dx == dy):
        return 1.0, 0.0
    return 0.0, 1.0


@njit(**JIT)
def rrect_directions(ax_lo, ax_hi, ay_lo, ay_hi, hx_lo, hx_hi, hy_lo, hy_hi):
    """The arc of unit gradients (first quadrant) of rounded rectangles with inner box half
    sizes ``a - c`` in ``[hx_lo, hx_hi]``, ``b - c`` in ``[hy_lo, hy_hi]`` at points with
    ``|x|`` in ``[ax_lo, ax_hi]``, ``|y|`` in ``[ay_lo, ay_hi]`` (mm): ``(c1, s1, c2, s2)``,
    its ends nearest the x axis and nearest the y axis. The gradient's angle grows with ``dy``
    and falls with ``dx`` (:func:`box_direction`), so the corners of the box bound it."""
    c1, s1 = box_direction(ax_hi - hx_lo, ay_lo - hy_hi, True)
    c2, s2 = box_direction(ax_lo - hx_hi, ay_hi - hy_lo, False)
    return c1, s1, c2, s2


@njit(**JIT)
def gradient_span(x, y, qx, qy, hx_lo, hx_hi, hy_lo, hy_hi):
    """``(min, max)`` of ``g . q`` over the unit gradients (and subgradients) ``g`` at
    ``(x, y)`` (mm, neither 0) of the rounded rectangles whose inner box half sizes lie in
    ``[hx_lo, hx_hi] x [hy_lo, hy_hi]``: the dot product along the arc of gradients
    (:func:`rrect_directions`) peaks inside it only where ``q`` points into it."""
    sx = -1.0 if x < 0.0 else 1.0
    sy = -1.0 if y < 0.0 else 1.0
    ux, uy = sx * qx, sy * qy  # q seen from the first quadrant
    c1, s1, c2, s2 = rrect_directions(abs(x), abs(x), abs(y), abs(y), hx_lo, hx_hi, hy_lo, hy_hi)
    e1, e2 = ux * c1 + uy * s1, ux * c2 + uy * s2
    lo, hi = min(e1, e2), max(e1, e2)
    w1, w2 = uy * c1 - ux * s1, uy * c2 - ux * s2  # d/d angle at the ends
    if w1 > 0.0 and w2 < 0.0:
        hi = math.sqrt(ux * ux + uy * uy)
    if w1 < 0.0 and w2 > 0.0:
        lo = -math.sqrt(ux * ux + uy * uy)
    return lo, hi


@njit(**JIT)
def outline_sd(plan, kind, p0, p1, p2, x, y):
    """Signed value of a fixed outline (CIRCLE, RRECT, OVAL or OUTLINE parameters) at ``(x, y)``."""
    return xs_eval(plan, kind, p0, p1, p2, x, y)[0]


@njit(**INLINE)
def _box_interval(px, py, qx, qy, hx, hy):
    """Parameters ``t`` where ``p + t q`` lies in the box ``|x| <= hx, |y| <= hy``."""
    lo, hi = -np.inf, np.inf
    for k in range(2):
        c, dc, h = (px, qx, hx) if k == 0 else (py, qy, hy)
        if dc == 0.0:
            if abs(c) > h:
                return 1.0, -1.0
        else:
            t0 = (-h - c) / dc
            t1 = (h - c) / dc
            if t0 > t1:
                t0, t1 = t1, t0
            lo, hi = max(lo, t0), min(hi, t1)
    return lo, hi


@njit(**JIT)
def _rrectinterval_hull(a, b, c, px, py, qx, qy):
    """:func:`outline_interval` of the rounded rectangle as the union of its two boxes and
    four corner discs."""
    lo, hi = _box_interval(px, py, qx, qy, a, b - c)
    l2, h2 = _box_interval(px, py, qx, qy, a - c, b)
    lo, hi = interval_hull(lo, hi, l2, h2)
    for k in range(4):
        sx = 1.0 if k & 1 else -1.0
        sy = 1.0 if k & 2 else -1.0
        l3, h3 = disc_interval(px, py, qx, qy, sx * (a - c), sy * (b - c), c)
        lo, hi = interval_hull(lo, hi, l3, h3)
    return lo, hi


@njit(**INLINE)
def _corner_disc(px, py, qx, qy, t, hx, hy, c):
    """``(True, t_in, t_out)``: the line's interval in the corner disc (centre ``(+-hx, +-hy)``,
    radius ``c``) whose corner square holds the point at ``t``; ``(False, 0, 0)`` when the
    point lies in none (``|x| <= hx`` or ``|y| <= hy``)."""
    x, y = px + t * qx, py + t * qy
    if abs(x) > hx and abs(y) > hy:
        l2, h2 = disc_interval(px, py, qx, qy, math.copysign(hx, x), math.copysign(hy, y), c)
        return True, l2, h2
    return False, 0.0, 0.0


@njit(**INLINE)
def _rrect_interval(a, b, c, px, py, qx, qy):
    """:func:`outline_interval` of the rounded rectangle ``(a, b, c)`` from its bounding box:
    where the line enters (leaves) the box inside a corner square (``|x| > a - c`` and
    ``|y| > b - c``) it enters (leaves) the outline on that corner's disc, since the square's
    inner edges lie in the disc. A line missing that disc meets no more than the corner square
    (it could only leave it through the box's faces); that rare case, and a point (``q = 0``),
    take the union of the pieces."""
    if qx == 0.0 and qy == 0.0:  # a point: no ends to look at
        return _rrectinterval_hull(a, b, c, px, py, qx, qy)
    lo, hi = _box_interval(px, py, qx, qy, a, b)
    if lo > hi or c <= 0.0:
        return lo, hi
    hx, hy = a - c, b - c
    corner, l2, h2 = _corner_disc(px, py, qx, qy, lo, hx, hy, c)
    if corner:
        if l2 > h2:
            return _rrectinterval_hull(a, b, c, px, py, qx, qy)
        lo = max(lo, l2)
    corner, l2, h2 = _corner_disc(px, py, qx, qy, hi, hx, hy, c)
    if corner:
        if l2 > h2:
            return _rrectinterval_hull(a, b, c, px, py, qx, qy)
        hi = min(hi, h2)
    return lo, hi


@njit(**JIT)
def outline_interval(plan, kind, p0, p1, p2, px, py, qx, qy):
    """``(t_in, t_out)``: where the 2-D line ``p + t q`` is inside the convex outline
    (CIRCLE ``(r)``, OVAL ``(a, b)``, RRECT ``(a, b, c)``, ``0 <= c <= min(a, b)``, OUTLINE
    ``(k, r)`` of ``plan``); ``t_in > t_out`` when it never is."""
    if kind == OUTLINE:
        return plan_interval(plan, p0, p1, px, py, qx, qy)
    if kind == CIRCLE:
        return disc_interval(px, py, qx, qy, 0.0, 0.0, p0)
    if kind == OVAL:
        return disc_interval(px / p0, py / p1, qx / p0, qy / p1, 0.0, 0.0, 1.0)
    return _rrect_interval(p0, p1, p2, px, py, qx, qy)
