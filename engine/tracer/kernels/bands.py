"""Certified bands: where along a ray a wall with a varying cross-section can be crossed.

Design rule: over a ray interval ``[a, b]`` the heights ``z`` span a range, so every section's
radius spans a range ``[r_lo, r_hi]`` (exact for lines and arcs, from a monotone table for the
offset of an ellipse). Cross-section functions are monotone in the radii, so the surface can
only be crossed where the ray's footprint is inside the *outer* outline (largest radii) and
outside the *inner* one (smallest): a closed-form 2-D problem (a ray against circles, ellipses,
rounded rectangles and free plan outlines, :mod:`.plans`) giving at most two *bands*. Restricting to a band narrows the height
range, hence the radii, hence the bands: the iteration contracts onto the crossings; where it
stalls the interval is halved. On a free plan outline the bounding solids are tighter: each
profile lies between two parallel lines along the band (its chord, widened by a bound second
order in the band's length), so the wall lies between two ruled solids whose traces are closed
forms, and the bands shrink quadratically (the flacon's shoulder). A band narrower than the leaf length is solved on the exact
surface: a sign change at its ends gives one crossing (safeguarded Newton). This is a proof, not a sampling: no crossing outside the bands is possible.

Rounded squares, rectangles and free plan outlines stop contracting earlier, as soon as the residual is *certified
monotone* on a band: then the band holds at most one crossing, found by the same Newton. Along
the ray, the residual's change is the outline's share, ``g . q`` (``g`` the unit gradient at
the footprint point, ``q`` the footprint direction), plus the radii's share,
``sum_k d residual / d r_k * dr_k/dz * dz/dt``. The outline is convex, so at fixed radii its
share only grows along the ray: over the band it is at most its value at the band's end (at
least its value at the start), bounded over the radius ranges by the arc of possible gradients
(:func:`~engine.tracer.kernels.outlines.gradient_span`). The radii's share is bounded by the
derivatives in the radii (in ``[-1, 0]``, a corner's in ``[0, sqrt2 - 1]``, from the arc of
gradients over the whole band) times the sections' slope ranges
(:func:`~engine.tracer.kernels.profile.wall_slopes`, exact for lines and arcs; one-sided where
a section turns horizontal). Ovals and punts are only contracted.
Units: mm; outlines in the bottle frame.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .outlines import (CIRCLE, OUTLINE, OVAL, RRECT, RSQUARE, SQRT2, gradient_span, outline_interval,
                       rrect_directions, square_corner, xs_eval)
from .plans import PL_HLOW, arc_dot_range, plan_directions, plan_trace
from .profile import wall_r, wall_range, wall_slopes, wall_state
from .roots import disc_interval
from .jit import INLINE, JIT


@njit(**INLINE)
def subtract(a0, a1, b0, b1, lo, hi):
    """``[a0, a1] minus (b0, b1)``, clipped to ``[lo, hi]``: up to two intervals
    ``(l0, h0, l1, h1)`` (empty ones have ``l > h``)."""
    a0, a1 = max(a0, lo), min(a1, hi)
    if a0 > a1:
        return 1.0, -1.0, 1.0, -1.0
    if b0 > b1 or b1 <= a0 or b0 >= a1:
        return a0, a1, 1.0, -1.0
    return a0, min(a1, b0), max(a0, b1), a1


@njit(**JIT)
def annulus_bands(ox, oy, dx, dy, r_lo, r_hi, lo, hi):
    """Where the ray's distance from the z axis lies in ``[r_lo, r_hi]``, within ``[lo, hi]``."""
    o0, o1 = disc_interval(ox, oy, dx, dy, 0.0, 0.0, r_hi)
    if r_lo > 0.0:
        i0, i1 = disc_interval(ox, oy, dx, dy, 0.0, 0.0, r_lo)
    else:
        i0, i1 = 1.0, -1.0
    return subtract(o0, o1, i0, i1, lo, hi)


#: A band that shrinks by less than this factor in one contraction is halved instead.
STALL = 0.5
#: Most contractions per call: past it (a ray running along a surface within a hair) the
#: remaining intervals are only checked for a sign change at their ends. Bounds the time.
BUDGET = 256


@njit(**JIT)
def residual(wall, ray, t):
    """Signed residual of the wall (a :class:`~.records.Wall`) at ray distance ``t``: positive
    outside the outline (cross-section ``kind`` at radii ``r(z)`` of segment rows ``r0..r2``; a
    CIRCLE wall is ``rho - r(z)``)."""
    seg, _, r0, r1, r2, nsec, kind, c, s, plan = wall
    ox, oy, oz, dx, dy, dz = ray
    x, y, z = ox + t * dx, oy + t * dy, oz + t * dz
    ra = wall_r(seg, r0, z)
    if kind == CIRCLE:
        return math.sqrt(x * x + y * y) - ra
    rb = wall_r(seg, r1, z) if nsec > 1 else 0.0
    rc = wall_r(seg, r2, z) if nsec > 2 else 0.0
    xb, yb = c * x + s * y, -s * x + c * y
    return xs_eval(plan, kind, ra, rb, rc, xb, yb)[0]


@njit(**JIT)
def wall_value_slope(wall, ray, t):
    """The residual of ``wall`` at ray distance ``t`` (mm) and its derivative in ``t``: the
    outline's gradient along the ray's footprint plus, through the radii, ``dr/dz dz/dt``
    from the sections' tangents (finite where the certificate below lets Newton run)."""
    seg, _, r0, r1, r2, nsec, kind, c, s, plan = wall
    ox, oy, oz, dx, dy, dz = ray
    x, y, z = ox + t * dx, oy + t * dy, oz + t * dz
    ra, tra, tza = wall_state(seg, r0, z)
    rb, trb, tzb, rc, trc, tzc = 0.0, 0.0, 1.0, 0.0, 0.0, 1.0
    if nsec > 1:
        rb, trb, tzb = wall_state(seg, r1, z)
    if nsec > 2:
        rc, trc, tzc = wall_state(seg, r2, z)
    f, gx, gy, d0, d1, d2 = xs_eval(plan, kind, ra, rb, rc, c * x + s * y, -s * x + c * y)
    qx, qy = c * dx + s * dy, -s * dx + c * dy
    return f, gx * qx + gy * qy + dz * (d0 * tra / tza + d1 * trb / tzb + d2 * trc / tzc)


@njit(**JIT)
def _newton(wall, ray, a, b, fa, fb):
    """A crossing of the wall inside ``[a, b]`` (``fa``, ``fb`` of opposite signs; the only one
    where the residual is certified monotone): Newton from the secant point, each step kept
    inside the shrinking bracket (else bisection), to a step of 2 ulps or to the residual's
    rounding noise."""
    x = (a * fb - b * fa) / (fb - fa)
    if not (x > a and x < b):
        x = 0.5 * (a + b)
    step = np.inf
    for _ in range(100):
        fx, df = wall_value_slope(wall, ray, x)
        if fx == 0.0:
            return x
        if (fx > 0.0) == (fa > 0.0):
            a = x
        else:
            b = x
        # (df is infinite where a section turns horizontal: no step from there)
        xn = x - fx / df if df != 0.0 and abs(df) < np.inf else np.nan
        newton = xn >= a and xn <= b
        if not newton:
            xn = 0.5 * (a + b)
        d = abs(xn - x)
        if d <= 4e-16 * abs(x) or b - a <= 4e-16 * max(abs(a), abs(b)):
            return xn
        # at the residual's rounding noise (far below a micrometre) the steps stop shrinking
        if newton and d > 0.5 * step and d <= 1e-13 * (abs(x) + 1.0):
            return xn
        step = d if newton else np.inf
        x = xn
    return x


@njit(**INLINE)
def _times(d, s):
    """``d s`` for a bound ``s`` that may be infinite, with ``0 * inf = 0`` (a factor ``d``
    that vanishes bounds the product by 0, however steep ``s``)."""
    return 0.0 if d == 0.0 else d * s


@njit(**INLINE)
def _product(d_lo, d_hi, s_lo, s_hi):
    """Range of ``d s`` over ``d`` in ``[d_lo, d_hi]`` (finite), ``s`` in ``[s_lo, s_hi]``."""
    p1, p2, p3, p4 = _times(d_lo, s_lo), _times(d_lo, s_hi), _times(d_hi, s_lo), _times(d_hi, s_hi)
    return min(min(p1, p2), min(p3, p4)), max(max(p1, p2), max(p3, p4))


@njit(**INLINE)
def _abs_range(x0, x1):
    """Range of ``|x|`` over the segment from ``x0`` to ``x1``."""
    if (x0 < 0.0) != (x1 < 0.0):
        return 0.0, max(abs(x0), abs(x1))
    return min(abs(x0), abs(x1)), max(abs(x0), abs(x1))


@njit(**JIT)
def monotone_sign(wall, foot, window, radii):
    """-1 if the rounded wall's residual provably decreases over the window, +1 if it provably
    increases, else 0 (module doc): then the window holds at most one crossing.

    ``wall`` a :class:`~.records.Wall` of kind RSQUARE or RRECT; ``foot`` = ``(px, py, qx, qy,
    dz)``: ``(px, py) + t (qx, qy)`` the ray's footprint in the bottle frame, ``dz`` its rise per
    mm; ``window`` = ``(a, b, z_lo, z_hi)``, the ray distances and heights (mm) of the window;
    ``radii`` = ``(a_lo, a_hi, b_lo, b_hi, c_lo, c_hi)``, the sections' radius ranges there (mm)."""
    seg, _, r0, r1, r2, _, kind, _, _, _ = wall
    px, py, qx, qy, dz = foot
    a, b, z_lo, z_hi = window
    a_lo, a_hi, b_lo, b_hi, c_lo, c_hi = radii
    if kind == RSQUARE:  # inner box half size u - q = (sqrt2 + 1)(v - u), both axes
        hx_lo = (SQRT2 + 1.0) * (b_lo - a_hi)
        hx_hi = (SQRT2 + 1.0) * (b_hi - a_lo)
        hy_lo, hy_hi = hx_lo, hx_hi
    else:
        hx_lo, hx_hi = a_lo - c_hi, a_hi - c_lo
        hy_lo, hy_hi = b_lo - c_hi, b_hi - c_lo
    # every section is a valid outline (corner <= half sizes, engine.geometry.crosssection)
    hx_lo, hy_lo = max(hx_lo, 0.0), max(hy_lo, 0.0)
    xa, ya, xb, yb = px + a * qx, py + a * qy, px + b * qx, py + b * qy
    # the gradients anywhere in the window (first quadrant): an arc from (c1, s1) to (c2, s2)
    ax_lo, ax_hi = _abs_range(xa, xb)
    ay_lo, ay_hi = _abs_range(ya, yb)
    c1, s1, c2, s2 = rrect_directions(ax_lo, ax_hi, ay_lo, ay_hi, hx_lo, hx_hi, hy_lo, hy_hi)
    sg_lo = min(c1 + s1, c2 + s2)  # sigma = g_x + g_y, sqrt2 on the diagonal
    sg_hi = SQRT2 if (s1 <= c1 and s2 >= c2) else max(c1 + s1, c2 + s2)
    # the radii's share of the slope: d residual / d radius times dr/dz dz/dt
    # (a section turning horizontal has an infinite slope at that end: the bound is one-sided)
    u_lo, u_hi = wall_slopes(seg, r0, z_lo, z_hi)
    u_lo, u_hi = _product(dz, dz, u_lo, u_hi)
    v_lo, v_hi = wall_slopes(seg, r1, z_lo, z_hi)
    v_lo, v_hi = _product(dz, dz, v_lo, v_hi)
    if kind == RSQUARE:
        # d/du = (1 + sqrt2) sigma - (2 + sqrt2) in [-1, 0] and d/dv = -1 - d/du
        d_lo = max(-1.0, (1.0 + SQRT2) * sg_lo - (2.0 + SQRT2))
        d_hi = min(0.0, (1.0 + SQRT2) * sg_hi - (2.0 + SQRT2))
        lo, hi = np.inf, -np.inf
        for d in (d_lo, d_hi):  # multilinear: its extremes are at the box's corners
            for su in (u_lo, u_hi):
                for sv in (v_lo, v_hi):
                    w = _times(d, su) - _times(1.0 + d, sv)
                    if w != w:
                        return 0  # opposite infinities
                    lo, hi = min(lo, w), max(hi, w)
    else:  # d/da = -g_x, d/db = -g_y, d/dc = sigma - 1
        w_lo, w_hi = wall_slopes(seg, r2, z_lo, z_hi)
        w_lo, w_hi = _product(dz, dz, w_lo, w_hi)
        lo, hi = _product(-c1, -c2, u_lo, u_hi)
        l2, h2 = _product(-s2, -s1, v_lo, v_hi)
        l3, h3 = _product(sg_lo - 1.0, sg_hi - 1.0, w_lo, w_hi)
        lo, hi = lo + l2 + l3, hi + h2 + h3  # lows are finite or -inf, highs finite or inf
    margin = 1e-9 * math.sqrt(qx * qx + qy * qy)  # far above the rounding of the bounds
    lo, hi = lo - margin, hi + margin
    # the outline's share: convex along the footprint, so its slope is largest at the end b
    if xb != 0.0 and yb != 0.0:
        g_lo, g_hi = gradient_span(xb, yb, qx, qy, hx_lo, hx_hi, hy_lo, hy_hi)
        if g_hi + hi < 0.0:
            return -1
    if xa != 0.0 and ya != 0.0:
        g_lo, g_hi = gradient_span(xa, ya, qx, qy, hx_lo, hx_hi, hy_lo, hy_hi)
        if g_lo + lo > 0.0:
            return 1
    return 0


@njit(**INLINE)
def _plan_gradient_span(plan, qx, qy, x, y, k_lo, k_hi):
    """Range of the outline's share ``g . q`` at the footprint point ``(x, y)`` over cores
    ``[k_lo, k_hi]`` (mm): ``g`` is the maximising direction of ``sd(., k P)``, which depends
    on ``(x, y) / k`` alone, so the cores move the point along a line through the axis. Along
    such a line the maximising direction turns one way only (outside ``P`` the nearest-point
    map is monotone; inside, the lower envelope of the pieces' distances is taken in order),
    so the directions between the two ends' form an arc. A third direction half-way checks
    that: off the arc, ``(-inf, inf)`` (no certificate)."""
    ax, ay, bx, by, mx, my = plan_directions(plan, k_lo, k_hi, 0.5 * (k_lo + k_hi), x, y)
    lo, hi = arc_dot_range(qx, qy, ax, ay, bx, by)
    if k_hi > k_lo and ax * by - ay * bx != 0.0:
        turn = ax * by - ay * bx
        if (ax * my - ay * mx) * turn < 0.0 or (mx * by - my * bx) * turn < 0.0:
            return -np.inf, np.inf
    return lo, hi


@njit(**JIT)
def outline_monotone_sign(wall, foot, window, radii):
    """:func:`monotone_sign` for a free plan outline (kind ``OUTLINE``, :mod:`.plans`).

    The residual ``sd(x, k P) - r`` changes along the ray by ``g . q - h(g) dk - dr``, ``h``
    the plan's support (in ``[h_low, 1]``: the plan reaches 1). At a fixed core the outline's
    share grows along the ray (``sd`` is convex), so it is bounded by its span over the cores
    at the window's ends (:func:`_plan_gradient_span`); the radii's share by the core's and
    rounding's slope ranges. ``radii`` = ``(k_lo, k_hi, r_lo, r_hi)`` (mm)."""
    seg, _, s0, s1, _, _, _, _, _, plan = wall
    px, py, qx, qy, dz = foot
    a, b, z_lo, z_hi = window
    k_lo, k_hi, _, _ = radii
    if k_lo < 0.0:
        return 0
    u_lo, u_hi = wall_slopes(seg, s0, z_lo, z_hi)
    u_lo, u_hi = _product(dz, dz, u_lo, u_hi)  # dk along the ray, per mm
    v_lo, v_hi = wall_slopes(seg, s1, z_lo, z_hi)
    v_lo, v_hi = _product(dz, dz, v_lo, v_hi)  # dr along the ray, per mm
    lo, hi = _product(-1.0, -plan[0, PL_HLOW], u_lo, u_hi)
    lo, hi = lo - v_hi, hi - v_lo
    if lo != lo or hi != hi:
        return 0  # opposite infinities
    margin = 1e-9 * math.sqrt(qx * qx + qy * qy)
    lo, hi = lo - margin, hi + margin
    g_lo, g_hi = _plan_gradient_span(plan, qx, qy, px + b * qx, py + b * qy, k_lo, k_hi)
    if g_hi + hi < 0.0:
        return -1
    g_lo, g_hi = _plan_gradient_span(plan, qx, qy, px + a * qx, py + a * qy, k_lo, k_hi)
    if g_lo + lo > 0.0:
        return 1
    return 0


@njit(**INLINE)
def _chord(seg, tab, row, za, zb, dz, length):
    """Segment row ``row``'s radius along a band of ``length`` mm of ray whose ends are at
    heights ``za``, ``zb`` (``dz`` the ray's rise per mm): ``(r0, m, dev, lo, hi)``, the radius
    within ``dev`` of the chord ``r0 + m t`` (mm, ``t`` from the band's start) and its range
    ``[lo, hi]`` over the band.

    Any function whose slope stays in ``[s_lo, s_hi]`` lies below both lines of slope ``s_hi``
    from its start and ``s_lo`` to its end, so it rises above its chord by at most
    ``(s_hi - m)(m - s_lo) L / (s_hi - s_lo)`` (and falls below it by as much): second order in
    the band's length, where the range is first order. ``dev`` is infinite where a slope is (a
    section turning horizontal). Where the slope keeps its sign the range is the ends'."""
    r0, r1 = wall_r(seg, row, za), wall_r(seg, row, zb)
    m = (r1 - r0) / length
    z_lo, z_hi = min(za, zb), max(za, zb)
    s_lo, s_hi = wall_slopes(seg, row, z_lo, z_hi)
    if s_lo >= 0.0 or s_hi <= 0.0:
        lo, hi = min(r0, r1), max(r0, r1)
    else:
        lo, hi = wall_range(seg, tab, row, z_lo, z_hi)
    s_lo, s_hi = _product(dz, dz, s_lo, s_hi)  # per mm of ray
    if not (s_lo > -np.inf and s_hi < np.inf):
        return r0, m, np.inf, lo, hi
    dev = 0.0
    if s_hi > s_lo:
        dev = max(0.0, s_hi - m) * max(0.0, m - s_lo) / (s_hi - s_lo) * length
    # (the chord's own rounding, far above the radii's)
    return r0, m, dev + 1e-13 * (abs(r0) + abs(r1)) + 1e-300, lo, hi


@njit(**INLINE)
def _ruled_bounds(plan, foot, a, length, core, grow):
    """The outer and inner traces ``(e0, e1, g0, g1)`` (ray distances, mm) on a band of an
    outline wall from its profiles' chords (:func:`_chord`: ``core`` and ``grow`` as it returns
    them for the core and the growth): with each profile between two parallel lines along the
    band, the wall lies between two ruled solids, convex, whose traces are closed forms
    (:func:`~.plans.plan_trace`). ``foot`` = ``(px, py, qx, qy)``; the band starts at ray
    distance ``a``. NaNs where a bound is not known: all four where a chord is not (a slope is
    infinite), ``g0, g1`` where the lower core line falls below 0."""
    k0, km, kd, _, _ = core
    r0, rm, rd, _, _ = grow
    if kd == np.inf or rd == np.inf:
        return np.nan, np.nan, np.nan, np.nan
    px, py, qx, qy = foot
    fx, fy = px + a * qx, py + a * qy  # from the band's start: far origins lose no digits
    e0, e1 = plan_trace(plan, (k0 + kd, km), (r0 + rd, rm), (fx, fy, qx, qy))
    if k0 - kd < 0.0 or k0 - kd + km * length < 0.0:
        return e0 + a, e1 + a, np.nan, np.nan
    g0, g1 = plan_trace(plan, (k0 - kd, km), (r0 - rd, rm), (fx, fy, qx, qy))
    return e0 + a, e1 + a, g0 + a, g1 + a


@njit(**JIT)
def band_roots(wall, ray, lo, hi, leaf, out, n, stack):
    """Crossings (ascending, appended to ``out`` from index ``n``) of the ray with a wall in
    ``[lo, hi]``: bands contracted (module doc) until certified monotone or down to ``leaf``
    (mm), then solved by Newton.

    ``wall`` (a :class:`~.records.Wall`): a z-rising wall whose sections are segment rows
    ``r0..r2`` (``nsec`` of them) of cross-section ``kind``, turned by ``(c, s) = (cos, sin)`` of
    the bottle's rotation. Only a pair of crossings closer than ``leaf`` can be missed (a
    graze). ``stack`` is ``(64, 2)`` scratch.
    """
    seg, tab, r0, r1, r2, nsec, kind, c, s, plan = wall
    ox, oy, oz, dx, dy, dz = ray
    # the ray's footprint in the bottle frame (outlines are not turned)
    px, py = c * ox + s * oy, -s * ox + c * oy
    qx, qy = c * dx + s * dy, -s * dx + c * dy
    certify = kind == RSQUARE or kind == RRECT or kind == OUTLINE
    stack[0, 0], stack[0, 1] = lo, hi
    top = 1
    budget = BUDGET
    first = n
    fresh = True  # the whole interval: it usually holds an entry and an exit, never monotone
    while top > 0 and n < out.shape[0]:
        top -= 1
        a, b = stack[top, 0], stack[top, 1]
        empty = False
        monotone = 0
        while budget > 0:
            budget -= 1
            if b - a <= leaf:
                break
            # a band's ends lie on the bounding outlines, which a crossing may touch: its heights
            # are taken a rounding-level margin wider (as the leaf's, below)
            eps = 1e-13 * (abs(a) + abs(b)) + 1e-3 * leaf
            wa, wb = max(lo, a - eps), min(hi, b + eps)
            za, zb = oz + wa * dz, oz + wb * dz
            z_lo, z_hi = min(za, zb), max(za, zb)
            b_lo, b_hi, c_lo, c_hi = 0.0, 0.0, 0.0, 0.0
            core = grow = (0.0, 0.0, 0.0, 0.0, 0.0)
            if kind == OUTLINE:  # the profiles' chords give their ranges and tighter bounds
                core = _chord(seg, tab, r0, za, zb, dz, wb - wa)
                grow = _chord(seg, tab, r1, za, zb, dz, wb - wa)
                a_lo, a_hi, b_lo, b_hi = core[3], core[4], grow[3], grow[4]
            else:
                a_lo, a_hi = wall_range(seg, tab, r0, z_lo, z_hi)
                if nsec > 1:
                    b_lo, b_hi = wall_range(seg, tab, r1, z_lo, z_hi)
                if nsec > 2:
                    c_lo, c_hi = wall_range(seg, tab, r2, z_lo, z_hi)
            if certify and not fresh and kind == OUTLINE:
                monotone = outline_monotone_sign(wall, (px, py, qx, qy, dz), (wa, wb, z_lo, z_hi),
                                                 (a_lo, a_hi, b_lo, b_hi))
            elif certify and not fresh:
                monotone = monotone_sign(wall, (px, py, qx, qy, dz), (wa, wb, z_lo, z_hi),
                                         (a_lo, a_hi, b_lo, b_hi, c_lo, c_hi))
            if monotone != 0:  # at most one crossing in [wa, wb]: no more contraction
                a, b = wa, wb
                break
            fresh = False
            if kind == CIRCLE:
                l0, h0, l1, h1 = annulus_bands(ox, oy, dx, dy, a_lo, a_hi, a, b)
            else:
                ok_in = True
                e0, e1, g0, g1 = np.nan, np.nan, np.nan, np.nan
                chorded = False  # the outer (and maybe inner) trace from the chords, below
                if kind == RSQUARE:  # q <= u holds exactly (v >= u); clamp the rounding
                    ko, o0, o1, o2 = RRECT, a_hi, a_hi, min(a_hi, max(0.0, square_corner(a_hi, b_hi)))
                    ki, i0, i1, i2 = RRECT, a_lo, a_lo, min(a_lo, max(0.0, square_corner(a_lo, b_lo)))
                elif kind == RRECT:
                    ko, o0, o1, o2 = RRECT, a_hi, b_hi, c_lo
                    ki, i0, i1, i2 = RRECT, a_lo, b_lo, c_hi
                    ok_in = c_hi <= min(a_lo, b_lo)
                elif kind == OUTLINE:  # monotone in the core and the growth: both decrease it
                    ko, o0, o1, o2 = OUTLINE, a_hi, b_hi, 0.0
                    ki, i0, i1, i2 = OUTLINE, a_lo, b_lo, 0.0
                    # tighter: the profiles between two parallel lines, a ruled solid each side
                    e0, e1, g0, g1 = _ruled_bounds(plan, (px, py, qx, qy), wa, wb - wa, core, grow)
                    chorded = e0 == e0
                else:
                    ko, o0, o1, o2 = OVAL, a_hi, b_hi, 0.0
                    ki, i0, i1, i2 = OVAL, a_lo, b_lo, 0.0
                # the outer interval a rounding margin wider and the inner one narrower: where the
                # two outlines coincide (a vertical wall: equal radii ranges) their computed ends
                # may cross by an ulp and leave no band around the crossing between them
                if not chorded:
                    e0, e1 = outline_interval(plan, ko, o0, o1, o2, px, py, qx, qy)
                e0, e1 = e0 - eps, e1 + eps
                if max(e0, a) > min(e1, b):  # never inside the outer outline: no band
                    empty = True
                    break
                if not chorded:
                    g0, g1 = (outline_interval(plan, ki, i0, i1, i2, px, py, qx, qy) if ok_in else (1.0, -1.0))
                elif g0 != g0:  # no line below the core that stays >= 0: the constant inner bound
                    g0, g1 = outline_interval(plan, OUTLINE, a_lo, b_lo, 0.0, px, py, qx, qy)
                g0, g1 = g0 + eps, g1 - eps
                l0, h0, l1, h1 = subtract(e0, e1, g0, g1, a, b)
            if l0 > h0 and l1 > h1:
                empty = True
                break
            if l0 > h0:
                l0, h0, l1, h1 = l1, h1, 1.0, -1.0
            if l1 <= h1 and top < stack.shape[0]:
                stack[top, 0], stack[top, 1] = l1, h1
                top += 1
            if h0 - l0 > STALL * (b - a) and top < stack.shape[0]:
                m = 0.5 * (l0 + h0)  # stalled: halve, the left half first
                stack[top, 0], stack[top, 1] = m, h0
                top += 1
                h0 = m
            a, b = l0, h0
        if empty:
            continue
        if monotone == 0:  # a leaf (or the budget spent): widened as above
            eps = 1e-13 * (abs(a) + abs(b)) + 1e-3 * leaf
            a, b = max(lo, a - eps), min(hi, b + eps)
        fa = residual(wall, ray, a)
        fb = residual(wall, ray, b)
        if fa == 0.0:
            root = a
        elif (fa > 0.0) == (fb > 0.0):
            continue
        else:  # (in a leaf not certified: some crossing of the bracket)
            root = _newton(wall, ray, a, b, fa, fb)
        if n == first or root > out[n - 1] + 2.0 * eps:  # neighbouring bands may share a crossing
            out[n] = root
            n += 1
    return n
