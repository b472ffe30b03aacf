"""Section segments as the kernels evaluate them: radius at a height, ranges, tangents.

Design rule: one row of the segment table (columns ``S_*``, built by
:mod:`engine.tracer.tables.render_objects`) is one meridian segment in its own (r, z) plane, in mm:
a line, a circle or ellipse arc, or the exact inward offset of an ellipse arc (a degree-8
curve, evaluated through its base ellipse). Walls rise in z, so a wall segment is a graph
``r(z)``; a punt's base curve is a graph ``z(r)``. Ranges over an interval of heights (or
radii) are exact for lines and arcs and come from a monotone table for offset arcs (its rows
bracket the curve: r is monotone between consecutive rows, whose extremes are rows), which
is what the certified bands of :mod:`~engine.tracer.kernels.bands` need.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .jit import INLINE, JIT
from .roots import hypot2

# segment kinds (HELIX: a straight wall piece raised by a screw thread, kernels.helix)
LINE, ARC, ELLIPSE, OFFSET, HELIX = 0, 1, 2, 3, 4
# segment table columns
S_KIND, S_R0, S_Z0, S_R1, S_Z1, S_CR, S_CZ, S_AR, S_AZ, S_A0, S_SWEEP, S_DIR, S_W = range(13)
(S_RMIN, S_RMAX, S_ZMIN, S_ZMAX, S_V0, S_LEN, S_SPLIT, S_AXIS, S_HALF, S_TAB0, S_TABN) = range(13, 24)
# S_SIDE (arcs): the side of the chord from (R0, Z0) to (R1, Z1) the arc lies on, the sign of
# (P1 - P0) x (Q - P0) for its points Q (an ellipse lies on both sides of any chord, one arc
# on each); 0 where the chord cannot tell (a full ellipse): the angle decides
S_SIDE = 24
S_COLS = 25
# A HELIX row is a line row (its base cone r = L(z) from (R0, Z0) to (R1, Z1), V0, LEN,
# bounds widened by the ridge) whose thread lies on the band of heights [H_Z0, H_Z1]; the
# thread sits in the columns only arcs use: the reference radius (mm), starts, phase (rad),
# depth (mm), pitch (mm), turns per start, flank half-widths (fractions of the pitch),
# run-out (turns) and the first ridge's centre (v, mm). See kernels.helix.
(H_REF, H_STARTS, H_PHASE, H_DEPTH, H_PITCH, H_TURNS, H_FLANK_LO, H_FLANK_HI, H_RUNOUT, H_START,
 H_Z0, H_Z1) = (S_CR, S_CZ, S_AR, S_AZ, S_A0, S_SWEEP, S_DIR, S_W, S_SPLIT, S_HALF, S_TAB0, S_TABN)
TWO_PI = 2.0 * math.pi


@njit(**INLINE)
def in_sweep(angle, angle0, sweep):
    """Whether ``angle`` (rad) lies on the arc from ``angle0`` sweeping ``sweep`` (signed),
    with a slack of 1e-9 of the sweep at either end (neighbours overlap by a hair)."""
    sgn = 1.0 if sweep >= 0.0 else -1.0
    rel = ((angle - angle0) * sgn) % TWO_PI
    slack = 1e-9 * abs(sweep)
    return rel <= abs(sweep) + slack or rel >= TWO_PI - slack


@njit(**JIT)
def offset_point(seg, i, s):
    """Point ``(r, z)`` and unit base tangent ``(T_r, T_z)`` of offset arc row ``i`` at base
    angle ``s`` (rad): ``P(s) - w n(s)`` on the base ellipse, ``n`` its outward normal."""
    cr, cz, ar, az = seg[i, S_CR], seg[i, S_CZ], seg[i, S_AR], seg[i, S_AZ]
    sign, w = seg[i, S_DIR], seg[i, S_W]
    c, sn = math.cos(s), math.sin(s)
    nr, nz = az * c, ar * sn  # outward normal of a ccw ellipse, unnormalised
    h = hypot2(nr, nz)
    # walking direction: ccw -> angle increasing; tangent of (ar cos, az sin) is (-ar sin, az cos)
    tr, tz = -ar * sn * sign, az * c * sign
    tl = hypot2(tr, tz)
    k = sign * w / h
    return cr + ar * c - k * nr, cz + az * sn - k * nz, tr / tl, tz / tl


@njit(**INLINE)
def offset_rz(seg, i, s):
    """Both coordinates ``(R, dR/ds, Z, dZ/ds)`` of offset arc row ``i`` at base angle ``s``
    (rad, mm): the offset moves parallel to its base, ``dQ/ds = P'(s) (1 - sign w kappa(s))``
    with ``kappa`` the base ellipse's curvature."""
    cr, cz, ar, az = seg[i, S_CR], seg[i, S_CZ], seg[i, S_AR], seg[i, S_AZ]
    sign, w = seg[i, S_DIR], seg[i, S_W]
    c, sn = math.cos(s), math.sin(s)
    nr, nz = az * c, ar * sn
    h2 = nr * nr + nz * nz
    h = math.sqrt(h2)
    k = sign * w / h
    scale = 1.0 - sign * w * ar * az / (h2 * h)
    return cr + ar * c - k * nr, -ar * sn * scale, cz + az * sn - k * nz, az * c * scale


@njit(**JIT)
def _offset_coord(seg, i, axis, s):
    """Coordinate ``axis`` (0 = r, 1 = z) of offset arc row ``i`` at base angle ``s`` and its
    derivative in ``s`` (:func:`offset_rz`)."""
    R, dR, Z, dZ = offset_rz(seg, i, s)
    if axis == 1:
        return Z, dZ
    return R, dR


@njit(**INLINE)
def _sweep_fraction(angle, a0, sweep):
    """Fraction of the arc from ``a0`` sweeping ``sweep`` (rad, signed) at ``angle``: in
    ``[0, 1]`` on the arc, above 1 off it."""
    sgn = 1.0 if sweep >= 0.0 else -1.0
    return (((angle - a0) * sgn) % TWO_PI) / abs(sweep)


@njit(**JIT)
def _offset_at(seg, i, axis, value):
    """Base angle where offset arc ``i`` (monotone in coordinate ``axis``: 0 = r, 1 = z) has
    that coordinate equal to ``value`` (clamped to the arc).

    The first guess is the angle on the ellipse with semi-axes shortened by the offset (exact
    for a circle arc and at an ellipse's vertices), on the branch the arc covers; the ends'
    coordinates are the row's end points, so a solve costs 2-3 curve evaluations."""
    a0, sw = seg[i, S_A0], seg[i, S_SWEEP]
    shrink = seg[i, S_DIR] * seg[i, S_W]
    if axis == 1:
        f_lo, f_hi = seg[i, S_Z0] - value, seg[i, S_Z1] - value
        u = min(1.0, max(-1.0, (value - seg[i, S_CZ]) / (seg[i, S_AZ] - shrink)))
        c0 = math.asin(u)
        c1 = math.pi - c0
    else:
        f_lo, f_hi = seg[i, S_R0] - value, seg[i, S_R1] - value
        u = min(1.0, max(-1.0, (value - seg[i, S_CR]) / (seg[i, S_AR] - shrink)))
        c0 = math.acos(u)
        c1 = -c0
    x = _sweep_fraction(c0, a0, sw)
    if not x <= 1.0:
        x = _sweep_fraction(c1, a0, sw)
    return _offset_solve(seg, i, axis, value, 0.0, 1.0, f_lo, f_hi, x)


@njit(**JIT)
def offset_at_between(seg, i, axis, value, x0, x1, f_lo, f_hi):
    """Base angle where offset arc ``i`` has coordinate ``axis`` equal to ``value``, searched
    between parameter fractions ``x0 < x1`` (clamped to them), whose residuals (coordinate
    minus ``value``) are ``f_lo, f_hi`` (a table piece's rows: no curve evaluation for them),
    from the linear guess (:func:`_offset_solve`); a tight bracket (a table step) takes 2-3
    steps."""
    return _offset_solve(seg, i, axis, value, x0, x1, f_lo, f_hi, np.nan)


@njit(**JIT)
def _offset_solve(seg, i, axis, value, x0, x1, f_lo, f_hi, x):
    """Newton from the fraction ``x`` (the linear guess if it is not inside ``(x0, x1)``) for
    the base angle where coordinate ``axis`` of offset arc ``i`` equals ``value``, safeguarded
    by bisection on the bracket ``[x0, x1]`` whose residuals are ``f_lo, f_hi``; clamped to
    the bracket's nearer end when ``value`` is outside it."""
    a0, sw = seg[i, S_A0], seg[i, S_SWEEP]
    if (f_lo > 0.0) == (f_hi > 0.0) or f_lo == 0.0 or f_hi == 0.0:
        return a0 + (x0 if abs(f_lo) <= abs(f_hi) else x1) * sw
    lo, hi = x0, x1
    inc = f_hi > f_lo  # coordinate increasing along the arc
    if not (x > x0 and x < x1):
        x = x0 + (x1 - x0) * f_lo / (f_lo - f_hi)
    for _ in range(60):
        f, df = _offset_coord(seg, i, axis, a0 + x * sw)
        f -= value
        if f == 0.0:  # (a zero step would fail the safeguard below and bisect on)
            return a0 + x * sw
        if (f < 0.0) == inc:
            lo = x
        else:
            hi = x
        df *= sw
        xn = x - f / df if df != 0.0 else 0.5 * (lo + hi)
        if not (xn > lo and xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-15 or hi - lo <= 1e-15:
            return a0 + xn * sw
        x = xn
    return a0 + x * sw


@njit(**JIT)
def wall_state(seg, i, z):
    """Radius ``r(z)`` (mm) and unit walking tangent ``(T_r, T_z)`` of the z-rising wall
    segment row ``i`` at height ``z`` (clamped to the segment)."""
    z = min(max(z, seg[i, S_Z0]), seg[i, S_Z1])
    kind = int(seg[i, S_KIND])
    if kind == LINE:
        r0, z0, r1, z1 = seg[i, S_R0], seg[i, S_Z0], seg[i, S_R1], seg[i, S_Z1]
        L = hypot2(r1 - r0, z1 - z0)
        return r0 + (z - z0) / (z1 - z0) * (r1 - r0), (r1 - r0) / L, (z1 - z0) / L
    if kind == OFFSET:
        s = _offset_at(seg, i, 1, z)
        r, _, tr, tz = offset_point(seg, i, s)
        return r, tr, tz
    ar, az, hs = seg[i, S_AR], seg[i, S_AZ], seg[i, S_HALF]
    u = min(1.0, max(-1.0, (z - seg[i, S_CZ]) / az))
    c = math.sqrt((1.0 - u) * (1.0 + u))
    tr, tz = -hs * ar * u / az, c  # proportional to (dr/dz, 1) times c
    h = hypot2(tr, tz)
    return seg[i, S_CR] + hs * ar * c, tr / h, tz / h


@njit(**INLINE)
def wall_r(seg, i, z):
    """Radius ``r(z)`` (mm) of the z-rising wall segment row ``i`` (clamped to it); the cheap
    half of :func:`wall_state`."""
    z = min(max(z, seg[i, S_Z0]), seg[i, S_Z1])
    kind = int(seg[i, S_KIND])
    if kind == LINE:
        z0 = seg[i, S_Z0]
        return seg[i, S_R0] + (z - z0) / (seg[i, S_Z1] - z0) * (seg[i, S_R1] - seg[i, S_R0])
    if kind == OFFSET:
        return offset_point(seg, i, _offset_at(seg, i, 1, z))[0]
    u = min(1.0, max(-1.0, (z - seg[i, S_CZ]) / seg[i, S_AZ]))
    return seg[i, S_CR] + seg[i, S_HALF] * seg[i, S_AR] * math.sqrt((1.0 - u) * (1.0 + u))


@njit(**JIT)
def table_range(tab, first, count, v_lo, v_hi, key):
    """Range of the other coordinate over ``tab[first:first+count, key]`` in ``[v_lo, v_hi]``
    (column ``key`` ascending): the rows bracketing the interval bound the curve. Returns
    ``(lo, hi, steps)``, ``steps`` the number of table steps the bracket spans."""
    other = 1 - key
    last = first + count - 1
    a, b = first, last
    while a < b:  # first row with key >= v_lo
        m = (a + b) // 2
        if tab[m, key] < v_lo:
            a = m + 1
        else:
            b = m
    lo_i = max(first, a - 1)
    a, b = lo_i, last
    while a < b:  # last row with key <= v_hi
        m = (a + b + 1) // 2
        if tab[m, key] > v_hi:
            b = m - 1
        else:
            a = m
    hi_i = min(last, a + 1)
    lo, hi = np.inf, -np.inf
    for k in range(lo_i, hi_i + 1):
        lo = min(lo, tab[k, other])
        hi = max(hi, tab[k, other])
    return lo, hi, hi_i - lo_i


@njit(**JIT)
def _offset_range(seg, tab, i, axis, v_lo, v_hi):
    """Range of the other coordinate of offset-arc row ``i`` over ``axis`` values in
    ``[v_lo, v_hi]``: from its table, exact (monotone between rows) within two table steps."""
    lo, hi, steps = table_range(tab, int(seg[i, S_TAB0]), int(seg[i, S_TABN]), v_lo, v_hi, axis)
    if steps > 2:
        return lo, hi
    other = 1 - axis
    pa = offset_point(seg, i, _offset_at(seg, i, axis, v_lo))
    pb = offset_point(seg, i, _offset_at(seg, i, axis, v_hi))
    elo, ehi = min(pa[other], pb[other]), max(pa[other], pb[other])
    first = int(seg[i, S_TAB0])
    for k in range(first, first + int(seg[i, S_TABN])):  # rows strictly inside (an extreme)
        if v_lo < tab[k, axis] < v_hi:
            elo, ehi = min(elo, tab[k, other]), max(ehi, tab[k, other])
    return max(lo, elo), min(hi, ehi)


@njit(**JIT)
def wall_range(seg, tab, i, z_lo, z_hi):
    """Range ``(r_lo, r_hi)`` (mm) of wall segment row ``i`` over heights ``[z_lo, z_hi]``."""
    kind = int(seg[i, S_KIND])
    if kind == OFFSET:
        return _offset_range(seg, tab, i, 1, z_lo, z_hi)
    ra = wall_r(seg, i, z_lo)
    rb = wall_r(seg, i, z_hi)
    lo, hi = min(ra, rb), max(ra, rb)
    if kind != LINE:
        cz = seg[i, S_CZ]
        if z_lo < cz < z_hi and seg[i, S_Z0] < cz < seg[i, S_Z1]:
            re = seg[i, S_CR] + seg[i, S_HALF] * seg[i, S_AR]
            lo, hi = min(lo, re), max(hi, re)
    return lo, hi


@njit(**JIT)
def wall_slopes(seg, i, z_lo, z_hi):
    """Range ``(lo, hi)`` of the slope ``dr/dz`` of wall segment row ``i`` over heights
    ``[z_lo, z_hi]`` (mm/mm; 0 beyond the segment's ends, where :func:`wall_r` clamps).

    Exact for lines and arcs: on an arc ``dr/dz = k u / sqrt(1 - u^2)`` with
    ``u = (z - z_c) / a_z`` is monotone in ``u``, so its extremes are at the ends; an end where
    the arc turns horizontal (``|u| = 1``) gives a signed infinity. ``(-inf, inf)`` for an
    offset arc (no bound known)."""
    kind = int(seg[i, S_KIND])
    z0, z1 = seg[i, S_Z0], seg[i, S_Z1]
    if kind == LINE:
        sa = sb = (seg[i, S_R1] - seg[i, S_R0]) / (z1 - z0)
    elif kind == ARC or kind == ELLIPSE:
        az = seg[i, S_AZ]
        k = -seg[i, S_HALF] * seg[i, S_AR] / az
        sa = _arc_slope(k, (min(max(z_lo, z0), z1) - seg[i, S_CZ]) / az)
        sb = _arc_slope(k, (min(max(z_hi, z0), z1) - seg[i, S_CZ]) / az)
    else:
        return -np.inf, np.inf
    lo, hi = min(sa, sb), max(sa, sb)
    if z_lo < z0 or z_hi > z1:
        lo, hi = min(lo, 0.0), max(hi, 0.0)
    return lo, hi


@njit(**INLINE)
def _arc_slope(k, u):
    """``k u / sqrt(1 - u^2)``, a signed infinity at ``|u| >= 1``."""
    if abs(u) >= 1.0:
        return np.inf if k * u > 0.0 else -np.inf
    return k * u / math.sqrt((1.0 - u) * (1.0 + u))


@njit(**JIT)
def base_z(seg, i, rho):
    """Height (mm) of the r-rising offset-arc row ``i`` (a punt's inner base) at radius ``rho``."""
    return offset_point(seg, i, _offset_at(seg, i, 0, rho))[1]


@njit(**JIT)
def base_range(seg, tab, i, r_lo, r_hi):
    """Range of heights of the r-rising offset-arc row ``i`` over radii ``[r_lo, r_hi]``."""
    return _offset_range(seg, tab, i, 0, r_lo, r_hi)
