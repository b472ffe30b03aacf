"""Robust real roots for ray-surface intersection, scalar and compiled.

Design rule: no bare closed-form root is trusted. Quadratics use the cancellation-free form;
the torus quartic is evaluated as the product of its two geometric factors (so its sign is
right to a few ulps of the geometry) and its roots are bracketed between the critical points
(the depressed cubic's roots) and then refined by Newton on the vanishing factor, safeguarded
by Illinois false position. This is the scalar twin of :func:`engine.intersect.torus.
ray_torus_hits` (the reference, tested on the shared hard cases) and keeps its conventions:
rays ``o + t d`` with unit ``d`` (mm), torus ``((hypot(x, y) - R)/a)^2 + (z/b)^2 = 1``.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .records import Ray
from .jit import INLINE, JIT

_MAX_ITER = 80
#: :func:`convex_sheet_roots` keeps outer-sheet roots down to this many tube radii inside
#: ``hypot(x, y) = R``: there its factor differs from the torus's by the slack squared
#: (1e-12 tube radii), and an arc's padded bounds may reach a hair inside its centre's radius.
SHEET_SLACK = 1e-6
_SQRT3_2 = 0.5 * math.sqrt(3.0)


@njit(**INLINE)
def disc_interval(px, py, qx, qy, cx, cy, r):
    """Parameters ``t`` where ``p + t q`` lies in the disc of radius ``r`` about ``c``."""
    ux, uy = px - cx, py - cy
    A = qx * qx + qy * qy
    if A == 0.0:
        return (-np.inf, np.inf) if ux * ux + uy * uy <= r * r else (1.0, -1.0)
    s = -(ux * qx + uy * qy) / A  # closest approach first: no cancellation far away
    mx, my = ux + s * qx, uy + s * qy
    h2 = r * r - (mx * mx + my * my)
    if h2 < 0.0:
        return 1.0, -1.0
    h = math.sqrt(h2 / A)
    return s - h, s + h


@njit(**INLINE)
def interval_hull(lo, hi, l2, h2):
    """The smallest interval holding ``[lo, hi]`` and ``[l2, h2]`` (either may be empty:
    ``lo > hi``)."""
    if l2 > h2:
        return lo, hi
    if lo > hi:
        return l2, h2
    return min(lo, l2), max(hi, h2)


@njit(**INLINE)
def hypot2(x, y):
    """``sqrt(x^2 + y^2)`` without libm's overflow guard (bottle-scale numbers, 4x faster)."""
    return math.sqrt(x * x + y * y)


@njit(**INLINE)
def illinois_point(a, b, fa, fb):
    """Next point of Illinois false position in the bracket ``[a, b]`` (residuals ``fa, fb``
    of opposite signs): the secant's zero, the midpoint if that falls outside."""
    x = (a * fb - b * fa) / (fb - fa)
    if not (x > a and x < b):
        x = 0.5 * (a + b)
    return x


@njit(**INLINE)
def illinois_done(a, b, fx):
    """Whether Illinois false position stops at a point of residual ``fx``: an exact zero, or
    a bracket ``[a, b]`` down to a few ulps."""
    return fx == 0.0 or b - a <= 4e-16 * max(abs(a), abs(b)) + 1e-300


@njit(**INLINE)
def illinois_update(a, b, fa, fb, x, fx, last):
    """The bracket ``(a, b, fa, fb, last)`` after a point ``x`` of residual ``fx``: ``x``
    replaces the end of its sign, and the other end's residual is halved when the same end
    moved twice in a row (``last``: +1 the low end moved, -1 the high one), which keeps false
    position from creeping from one side."""
    if (fx > 0.0) == (fa > 0.0):
        a, fa = x, fx
        if last > 0:
            fb *= 0.5
        last = 1
    else:
        b, fb = x, fx
        if last < 0:
            fa *= 0.5
        last = -1
    return a, b, fa, fb, last


@njit(**INLINE)
def sort_small(out, n, slot=0):
    """Sort ``out[:n]`` ascending in place (insertion sort: n is a handful of roots); with
    ``slot > 0`` each ``out[slot + j]`` (a value that belongs to root ``j``) moves with it."""
    for i in range(1, n):
        v = out[i]
        c = out[slot + i] if slot > 0 else 0.0
        j = i - 1
        while j >= 0 and out[j] > v:
            out[j + 1] = out[j]
            if slot > 0:
                out[slot + j + 1] = out[slot + j]
            j -= 1
        out[j + 1] = v
        if slot > 0:
            out[slot + j + 1] = c


@njit(**INLINE)
def quadratic(A, B, C):
    """Real roots of ``A t^2 + 2 B t + C = 0`` as ``(n, t0, t1)``, ``t0 <= t1`` (cancellation-free).

    ``A == 0`` leaves the single root ``-C / 2B``; ``n`` is the number of roots (0, 1 or 2).
    """
    if A == 0.0:
        if B == 0.0:
            return 0, np.nan, np.nan
        return 1, -C / (2.0 * B), np.nan
    disc = B * B - A * C
    if disc < 0.0:
        return 0, np.nan, np.nan
    sq = math.sqrt(disc)
    q = -(B + sq) if B >= 0.0 else -(B - sq)
    if q == 0.0:
        return 1, 0.0, np.nan
    t1, t2 = q / A, C / q
    if t1 > t2:
        t1, t2 = t2, t1
    return 2, t1, t2


@njit(**INLINE)
def _cbrt(x):
    """Real cube root of ``x >= 0`` (``np.cbrt``: libm's cube root, not ``pow``, 3x faster)."""
    return np.cbrt(x) if x > 0.0 else 0.0


@njit(**JIT)
def _cubic_critical(p, q, out):
    """Real roots of ``u^3 + (p/2) u + q/4`` into ``out[0:3]`` ascending (a single real root
    fills all three), each polished by two Newton steps."""
    P = 0.5 * p
    Q = 0.25 * q
    disc = (0.5 * Q) ** 2 + (P / 3.0) ** 3
    if disc > 0.0:
        A = 0.0
        if Q != 0.0:  # Cardano, written so that the two cube roots never cancel
            A = -math.copysign(_cbrt(0.5 * abs(Q) + math.sqrt(disc)), Q)
        r = A - P / (3.0 * A) if A != 0.0 else 0.0
        out[0] = r
        out[1] = r
        out[2] = r
    else:
        k = 2.0 * math.sqrt(-P / 3.0) if P < 0.0 else 0.0
        arg = 0.0
        if P != 0.0:
            arg = (3.0 * Q / (2.0 * P)) * math.sqrt(-3.0 / P)
        arg = min(1.0, max(-1.0, arg))
        phi = math.acos(arg) / 3.0
        # cos(phi - 2 pi j / 3) for j = 0, 1, 2 from one cosine and one sine (the angle
        # difference identity): two libm calls where there were three
        c, sn = math.cos(phi), math.sin(phi)
        out[0] = k * c
        out[1] = k * (-0.5 * c + _SQRT3_2 * sn)
        out[2] = k * (-0.5 * c - _SQRT3_2 * sn)
    for j in range(3):
        r = out[j]
        for _ in range(2):
            val = (r * r + P) * r + Q
            der = 3.0 * r * r + P
            if der != 0.0:
                step = val / der
                if math.isfinite(step):
                    r -= step
        out[j] = r
    # sort three
    if out[0] > out[1]:
        out[0], out[1] = out[1], out[0]
    if out[1] > out[2]:
        out[1], out[2] = out[2], out[1]
    if out[0] > out[1]:
        out[0], out[1] = out[1], out[0]


@njit(**INLINE)
def _factors(qx, qy, qz, Dx, Dy, Dz, Rn, u):
    """``(g_out, g_in)`` of the unit-tube torus at scaled distance ``u`` from the closest approach."""
    x = qx + u * Dx
    y = qy + u * Dy
    z = qz + u * Dz
    rho = hypot2(x, y)
    d = rho - Rn
    z2 = z * z
    return (d - 1.0) * (d + 1.0) + z2, (rho + Rn) ** 2 - 1.0 + z2


@njit(**JIT)
def _solve_piece(tube_ray, Rn, lo, hi, ends):
    """The single root of ``f = g_out g_in`` in ``[lo, hi]`` where ``f`` changes sign
    (Newton on the vanishing factor, safeguarded by Illinois false position), along
    ``tube_ray`` (``(q, D)`` in the unit-tube frame, :func:`_tube_frame`) about a centre circle
    of scaled radius ``Rn``. ``ends`` = ``(f_lo, f_hi, o_lo, o_hi, i_lo, i_hi)``: ``f`` and the
    factors at the ends: the first guess is false position on the one that changes sign (nearly
    linear there; the product is not, and costs Newton a step more)."""
    qx, qy, qz, Dx, Dy, Dz = tube_ray
    f_lo, f_hi, o_lo, o_hi, i_lo, i_hi = ends
    if (o_lo > 0.0) != (o_hi > 0.0):
        x = (lo * o_hi - hi * o_lo) / (o_hi - o_lo)
    elif (i_lo > 0.0) != (i_hi > 0.0):
        x = (lo * i_hi - hi * i_lo) / (i_hi - i_lo)
    else:
        x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
    if not (x > lo and x < hi):
        x = 0.5 * (lo + hi)
    last = 0
    for _ in range(_MAX_ITER):
        px = qx + x * Dx
        py = qy + x * Dy
        pz = qz + x * Dz
        rho = hypot2(px, py)
        d = rho - Rn
        g_out = (d - 1.0) * (d + 1.0) + pz * pz
        g_in = (rho + Rn) ** 2 - 1.0 + pz * pz
        f = g_out * g_in
        move_lo = (f > 0.0) == (f_lo > 0.0) and f != 0.0
        if move_lo:
            if last > 0:
                f_hi *= 0.5
            lo, f_lo, last = x, f, 1
        else:
            if last < 0:
                f_lo *= 0.5
            hi, f_hi, last = x, f, -1
        outer = abs(g_out) <= abs(g_in)
        drho = (px * Dx + py * Dy) / rho if rho > 0.0 else 0.0
        slope = 2.0 * (d if outer else rho + Rn) * drho + 2.0 * pz * Dz
        g_here = g_out if outer else g_in
        xn = x - g_here / slope if slope != 0.0 else np.nan
        if not (xn > lo and xn < hi):
            den = f_hi - f_lo
            xn = (lo * f_hi - hi * f_lo) / den if den != 0.0 else 0.5 * (lo + hi)
            if not (xn > lo and xn < hi):
                xn = 0.5 * (lo + hi)
        tol = 4e-16 * (abs(xn) + Rn + 1.0)
        size2 = (rho * abs(d) + d * d if outer else (rho + Rn) ** 2) + pz * pz + 1.0
        if abs(g_here) <= 8e-16 * size2:
            return x
        if abs(xn - x) <= tol or hi - lo <= tol:
            return xn
        x = xn
    return x


@njit(**INLINE)
def _tube_frame(ray, R, a, b):
    """The ray in the unit-tube frame (x, y over ``a``, z over ``b``): ``(q, D, speed, s0, Rn,
    B, q2)``, its point ``q`` closest to the centre, its unit direction ``D``, the frame's length
    of a mm of the ray, the scaled distance ``s0`` from the origin to ``q`` (a hit at scaled
    distance ``u`` from ``q`` is at ``t = (s0 + u) / speed`` mm), the scaled radius ``Rn`` of the
    tube's centre circle, the torus's scaled bounding radius ``B`` and ``|q|^2``."""
    ox, oy, oz, dx, dy, dz = ray
    qx, qy, qz = ox / a, oy / a, oz / b
    Dx, Dy, Dz = dx / a, dy / a, dz / b
    speed = math.sqrt(Dx * Dx + Dy * Dy + Dz * Dz)
    Dx, Dy, Dz = Dx / speed, Dy / speed, Dz / speed
    s0 = -(qx * Dx + qy * Dy + qz * Dz)
    qx, qy, qz = qx + s0 * Dx, qy + s0 * Dy, qz + s0 * Dz
    Rn = R / a
    return qx, qy, qz, Dx, Dy, Dz, speed, s0, Rn, Rn + 1.0, qx * qx + qy * qy + qz * qz


@njit(**JIT)
def torus_roots(ray, R, a, b, inner, tmin, out, crit, tmax=np.inf):
    """Hit distances (mm) of the ray ``o + t d`` (unit ``d``) with the torus about z
    ``((hypot(x,y) - R)/a)^2 + (z/b)^2 = 1`` (``inner``: the mirror sheet ``hypot + R``).

    Writes the roots with ``tmin < t <= tmax`` ascending into ``out[0:4]`` and returns how
    many; monotone pieces of the quartic outside that window are not solved at all (an arc's
    bounding box makes it short).
    ``crit`` is scratch of length 5. ``R >= 0``, ``a, b > 0``; ``R < 1e-9 a`` is a spheroid.
    Tangent touches (double roots) are not reported.
    """
    n = 0
    if R < 1e-9 * a:  # the tube centre on the axis: a spheroid, closed form
        _, _, _, _, _, _, speed, s0, _, _, m2 = _tube_frame(ray, 0.0, a, b)
        m = math.sqrt(m2)
        if m >= 1.0:
            return 0
        u = math.sqrt((1.0 - m) * (1.0 + m))
        for tt in ((s0 - u) / speed, (s0 + u) / speed):
            if tt > tmin:
                out[n] = tt
                n += 1
        return n
    qx, qy, qz, Dx, Dy, Dz, speed, s0, Rn, B, q2 = _tube_frame(ray, R, a, b)
    if q2 >= B * B * (1.0 + 1e-12):
        return 0
    E = Dx * Dx + Dy * Dy
    if E == 0.0:  # parallel to the axis: constant rho, closed form
        rho = hypot2(qx, qy)
        dr = rho + Rn if inner else rho - Rn
        h2 = (1.0 - dr) * (1.0 + dr)
        if not h2 > 0.0:
            return 0
        half = math.sqrt(h2)
        zs = 1.0 if Dz > 0.0 else -1.0
        for uu in (-half * zs - qz * zs, half * zs - qz * zs):
            tt = (s0 + uu) / speed
            if tt > tmin:
                out[n] = tt
                n += 1
        if n == 2 and out[0] > out[1]:
            out[0], out[1] = out[1], out[0]
        return n
    F = 2.0 * (qx * Dx + qy * Dy)
    C = q2 + Rn * Rn - 1.0
    p = 2.0 * C - 4.0 * Rn * Rn * E
    q = -4.0 * Rn * Rn * F
    half = math.sqrt(max(B * B - q2, 0.0)) * (1.0 + 1e-9) + 1e-12 * B
    _cubic_critical(p, q, crit)
    crit[4] = half
    for j in range(2, -1, -1):
        crit[j + 1] = min(half, max(-half, crit[j]))
    crit[0] = -half
    # the window in scaled units (a hair wider: roots at its ends stay inside their pieces)
    u_lo = tmin * speed - s0 if math.isfinite(tmin) else -np.inf
    u_hi = tmax * speed - s0 if math.isfinite(tmax) else np.inf
    pad = 1e-9 * (abs(u_lo) + abs(u_hi) + B) if math.isfinite(u_hi) and math.isfinite(u_lo) else 0.0
    u_lo, u_hi = u_lo - pad, u_hi + pad
    prev, o_prev, i_prev = np.nan, 0.0, 0.0  # the last piece's upper end: the next one's lower
    for j in range(4):
        lo, hi = max(crit[j], u_lo), min(crit[j + 1], u_hi)
        if not hi > lo:
            continue
        if lo == prev:
            o_lo, i_lo = o_prev, i_prev
        else:
            o_lo, i_lo = _factors(qx, qy, qz, Dx, Dy, Dz, Rn, lo)
        o_hi, i_hi = _factors(qx, qy, qz, Dx, Dy, Dz, Rn, hi)
        prev, o_prev, i_prev = hi, o_hi, i_hi
        f_lo, f_hi = o_lo * i_lo, o_hi * i_hi
        if f_lo == 0.0:
            u = lo
        elif (f_lo > 0.0) != (f_hi > 0.0) and f_hi != 0.0:
            u = _solve_piece(Ray(qx, qy, qz, Dx, Dy, Dz), Rn, lo, hi, (f_lo, f_hi, o_lo, o_hi, i_lo, i_hi))
        else:
            continue
        g_o, g_i = _factors(qx, qy, qz, Dx, Dy, Dz, Rn, u)
        keep = abs(g_i) <= abs(g_o) if inner else abs(g_o) <= abs(g_i)
        tt = (s0 + u) / speed
        if keep and tt > tmin and tt <= tmax:
            out[n] = tt
            n += 1
    return n


@njit(**INLINE)
def _scaled_window(speed, s0, B, q2, tmin, tmax):
    """``(lo, hi)``: the ray's window ``tmin < t <= tmax`` (mm) in the tube frame's scaled
    distances from the closest approach (:func:`_tube_frame`), cut to the torus's bounding
    sphere and widened a hair, so that roots at its ends stay inside; empty unless lo < hi."""
    half = math.sqrt(max(B * B - q2, 0.0)) * (1.0 + 1e-9) + 1e-12 * B
    u_lo = max(-half, tmin * speed - s0) if math.isfinite(tmin) else -half
    u_hi = min(half, tmax * speed - s0) if math.isfinite(tmax) else half
    pad = 1e-9 * (abs(u_lo) + abs(u_hi) + B)
    return u_lo - pad, u_hi + pad


@njit(**INLINE)
def _convex_factor(qx, qy, qz, Dx, Dy, Dz, Rn, inner, u):
    """``(g, dg/du, size)`` of the unit-tube torus factor that is convex along every ray, at scaled
    distance ``u`` from the closest approach: the mirror sheet's ``(rho + Rn)^2 + z^2 - 1``
    (``inner``) or the outer sheet's ``max(rho - Rn, 0)^2 + z^2 - 1``, which equals its factor
    ``g_out`` where ``rho >= Rn`` (a convex non-negative function squared, plus a square); and
    the size of the terms ``g`` is a difference of (its rounding is a few ulps of that)."""
    x = qx + u * Dx
    y = qy + u * Dy
    z = qz + u * Dz
    rho = hypot2(x, y)
    drho = (x * Dx + y * Dy) / rho if rho > 0.0 else 0.0
    d = rho + Rn if inner else max(rho - Rn, 0.0)
    return (d - 1.0) * (d + 1.0) + z * z, 2.0 * d * drho + 2.0 * z * Dz, rho * abs(d) + d * d + z * z + 1.0


@njit(**INLINE)
def _sheet_eval(hole, f, u):
    """``(g, dg/du, size)`` of a factor convex along the ray's piece being solved, at scaled
    distance ``u``: the torus sheet's of :func:`_convex_factor` (frame ``f = (qx, qy, qz, Dx, Dy,
    Dz, Rn, inner)``) or, for the side of the tube facing the axis (``hole``), ``c psi`` of
    :func:`_hole_factor` (frame ``f = (E, m2, off, zc, Dz, Rn, c, 1)``); ``|g|`` below
    ``8e-16 size`` is rounding."""
    if hole:
        psi, dpsi, size = _hole_factor(f[0], f[1], f[2], f[3], f[4], f[5], u, f[7])
        return f[6] * psi, f[6] * dpsi, 0.5 * size
    return _convex_factor(f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7] > 0.0, u)


@njit(**JIT)
def _sheet_root(hole, f, lo, hi, g_lo, g_hi, s_lo, s_hi):
    """The single root in ``[lo, hi]`` of a convex factor (:func:`_sheet_eval`) whose values
    ``g_lo, g_hi`` have opposite signs: Newton from the positive end, which a convex function's
    tangents never carry past the root, inside the bracket (Illinois false position if
    rounding does)."""
    Rn = f[6] if not hole else f[5]
    x, s = (lo, s_lo) if g_lo > 0.0 else (hi, s_hi)
    g = g_lo if g_lo > 0.0 else g_hi
    f_lo, f_hi = g_lo, g_hi
    last = 0
    for _ in range(_MAX_ITER):
        xn = x - g / s if s != 0.0 else np.nan
        if not (xn > lo and xn < hi):
            xn = illinois_point(lo, hi, f_lo, f_hi)
        tol = 4e-16 * (abs(xn) + Rn + 1.0)
        if abs(xn - x) <= tol:
            return xn
        x = xn
        g, s, size = _sheet_eval(hole, f, x)
        if abs(g) <= 8e-16 * size or illinois_done(lo, hi, g):
            return x
        lo, hi, f_lo, f_hi, last = illinois_update(lo, hi, f_lo, f_hi, x, g, last)
        if hi - lo <= tol:
            return x
    return x


@njit(**JIT)
def _sheet_pair(hole, f, a_, b_, ga, gb, sa, sb, B):
    """``(n, u0, u1)``: the pair of roots (``n = 2``) or none (``n = 0``) of a convex factor
    (:func:`_sheet_eval`) positive at both ends of ``[a_, b_]`` (slopes ``sa, sb``; ``B`` the
    scale of the distances): a pair only if its minimum dips below zero, which cutting planes
    from the tangents find or rule out (a tangent touch, a double root, is not reported)."""
    for _ in range(_MAX_ITER):
        if sa >= 0.0 or sb <= 0.0 or not b_ - a_ > 4e-16 * (abs(a_) + abs(b_) + B):
            break  # monotone on [a_, b_], or the minimum pinned to a touch: no crossing
        m = (gb - ga + sa * a_ - sb * b_) / (sa - sb)  # where the end tangents meet
        if not (m > a_ and m < b_):
            m = 0.5 * (a_ + b_)
        if ga + sa * (m - a_) > 0.0:
            break  # the tangents' lower bound stays above zero
        gm, sm, _ = _sheet_eval(hole, f, m)
        if gm < 0.0:
            return (2, _sheet_root(hole, f, a_, m, ga, gm, sa, sm),
                    _sheet_root(hole, f, m, b_, gm, gb, sm, sb))
        if sm > 0.0:
            b_, gb, sb = m, gm, sm
        else:
            a_, ga, sa = m, gm, sm
    return 0, np.nan, np.nan


@njit(**JIT)
def convex_sheet_roots(ray, R, a, b, inner, tmin, tmax, out):
    """Hit distances (mm, ascending, ``tmin < t <= tmax``) of the ray ``o + t d`` (unit ``d``)
    with the part of a torus sheet about z that is convex along every ray: the mirror sheet
    ``hypot(x, y) + R`` whole (``inner``), or the outer sheet where ``hypot(x, y) >= R``, the
    outer side of its tube (the only part an arc with ``rmin >= R`` lies on). Torus and units as
    :func:`torus_roots`; returns how many roots it wrote into ``out[0:2]``.

    Along a ray a convex factor has at most two roots, and its values and slopes at the
    window's ends settle most rays without a root at once: a sign change is one root; both
    ends negative, none; both positive, none unless the tangents' lower bound dips below zero,
    where cutting planes find the minimum (tangent touches, double roots, are not reported).
    No cubic, no quartic.
    """
    qx, qy, qz, Dx, Dy, Dz, speed, s0, Rn, B, q2 = _tube_frame(ray, R, a, b)
    if q2 >= B * B * (1.0 + 1e-12):
        return 0
    lo, hi = _scaled_window(speed, s0, B, q2, tmin, tmax)
    if not hi > lo:
        return 0
    f = (qx, qy, qz, Dx, Dy, Dz, Rn, 1.0 if inner else 0.0)
    g_lo, s_lo, _ = _sheet_eval(False, f, lo)
    g_hi, s_hi, _ = _sheet_eval(False, f, hi)
    n_u = 0
    u0 = u1 = 0.0
    if (g_lo > 0.0) != (g_hi > 0.0):
        u0 = _sheet_root(False, f, lo, hi, g_lo, g_hi, s_lo, s_hi)
        n_u = 1
    elif g_lo > 0.0:  # both ends outside: a pair of roots only if the minimum is below zero
        n_u, u0, u1 = _sheet_pair(False, f, lo, hi, g_lo, g_hi, s_lo, s_hi, B)
    n = 0
    for j in range(n_u):
        u = u0 if j == 0 else u1
        if not inner:  # on the outer side of the tube, with SHEET_SLACK
            x, y = qx + u * Dx, qy + u * Dy
            if hypot2(x, y) < Rn - SHEET_SLACK:
                continue
        tt = (s0 + u) / speed
        if tt > tmin and tt <= tmax:
            out[n] = tt
            n += 1
    return n


#: :func:`hole_sheet_roots` serves arcs whose heights keep within this fraction of the tube's
#: half-height (scaled ``|z| <= HOLE_POLE``): nearer its poles ``sqrt(1 - z^2)`` turns
#: infinitely steep along a ray, and such arcs keep :func:`torus_roots`.
HOLE_POLE = 0.999


@njit(**INLINE)
def _hole_factor(E, m2, off, zc, Dz, Rn, v, side):
    """``(psi, dpsi/dv, size)`` at scaled distance ``v`` along the ray from a point ``off``
    before its closest approach to the axis (horizontal speed squared ``E``, squared distance
    from the axis there ``m2``; height ``zc`` at ``v = 0``), where
    ``psi = rho + sqrt(1 - z^2) - Rn`` vanishes exactly on the side of the unit tube facing the
    axis (``rho <= Rn``, ``|z| <= 1``): negative nearer the axis, positive inside the tube and
    beyond. ``rho = sqrt(E (v + off)^2 + m2)`` loses no digits near the axis; on the axis
    itself (``m2 = 0, v = -off``, a kink) the slope is taken on ``side`` (+1 or -1). ``size``
    bounds the terms ``psi`` adds."""
    h = v + off
    rho = math.sqrt(E * h * h + m2)
    z = zc + v * Dz
    w = math.sqrt(max((1.0 - z) * (1.0 + z), 0.0))
    drho = E * h / rho if rho > 0.0 else side * math.sqrt(E)
    dw = -z * Dz / w if w > 0.0 else -math.copysign(1e300, z * Dz)
    return rho + w - Rn, drho + dw, rho + w + Rn


@njit(**JIT)
def _hole_piece(E, m2, off, zc, Dz, Rn, c, lo, hi):
    """``(n, v0, v1)``: the roots (ascending) in ``[lo, hi]`` of ``psi`` (:func:`_hole_factor`)
    where ``c psi`` is convex (``c = +1`` or ``-1``). A convex function has at most two roots:
    ends of opposite signs hold one; both positive hide a pair only if the minimum dips below
    zero, which cutting planes from the ends' tangents find or rule out (a touch, a double
    root, is not reported); both negative hold none. A root exactly at ``lo`` counts, one at
    ``hi`` belongs to the next piece."""
    f = (E, m2, off, zc, Dz, Rn, c, 1.0)
    p, s, _ = _hole_factor(E, m2, off, zc, Dz, Rn, lo, 1.0)  # at the ends, the slope inside the piece
    ga, sa = c * p, c * s
    p, s, _ = _hole_factor(E, m2, off, zc, Dz, Rn, hi, -1.0)
    gb, sb = c * p, c * s
    if ga == 0.0:
        return 1, lo, np.nan
    if gb != 0.0 and (ga > 0.0) != (gb > 0.0):
        return 1, _sheet_root(True, f, lo, hi, ga, gb, sa, sb), np.nan
    if not (ga > 0.0 and gb > 0.0):
        return 0, np.nan, np.nan
    return _sheet_pair(True, f, lo, hi, ga, gb, sa, sb, Rn + 1.0)


@njit(**JIT)
def hole_sheet_roots(ray, R, a, b, tmin, tmax, out):
    """Hit distances (mm, ascending, ``tmin < t <= tmax``) of the ray ``o + t d`` (unit ``d``)
    with the side of the torus's tube that faces its axis (``hypot(x, y) <= R``), where concave
    arcs lie (waists, shoulders running into a neck). Torus and units as :func:`torus_roots`
    (``R >= 1e-9 a``); returns how many roots it wrote into ``out[0:4]``. Meant for windows
    that keep clear of the tube's poles (:data:`HOLE_POLE`: the window is cut off a little beyond
    it); tangent touches are not reported.

    On that side ``rho = R - sqrt(1 - z^2)`` in the unit-tube frame, so its residual
    ``psi = rho + sqrt(1 - z^2) - R`` along the ray is a convex function plus a concave one,
    and ``psi''`` has the sign of ``Q = kappa (1 - z^2) - rho^2``, ``kappa = (X^2 / Dz^2)^(2/3)``
    (``X`` the horizontal cross product of the ray's point and direction): a quadratic in the
    distance, convex between its roots (a ray through the axis: its double root at the kink of
    ``rho`` there). They cut the window into at most three pieces of fixed convexity, each with
    at most two roots found as :func:`convex_sheet_roots` finds them. Distances are counted
    from that closest approach (or the window's end nearest it), where the quadratic's terms
    carry no cancellation. No cubic, no quartic, no trigonometry.
    """
    qx, qy, qz, Dx, Dy, Dz, speed, s0, Rn, B, q2 = _tube_frame(ray, R, a, b)
    if q2 >= B * B * (1.0 + 1e-12):
        return 0
    lo, hi = _scaled_window(speed, s0, B, q2, tmin, tmax)
    # distances from the point of the window nearest the ray's closest approach to the axis (a
    # vertical ray: its foot, at q), which is ``off`` before that approach
    E = Dx * Dx + Dy * Dy
    X = qx * Dy - qy * Dx
    ua, m2 = 0.0, qx * qx + qy * qy
    if E > 0.0:
        ua, m2 = -(qx * Dx + qy * Dy) / E, X * X / E
    uc = min(max(ua, lo), hi)
    off = uc - ua
    zc = qz + uc * Dz
    lo, hi = lo - uc, hi - uc
    # clear of the poles (the arcs served end by HOLE_POLE; a vertical tangent at |z| = 1
    # would stall the cutting planes)
    z_cap = 0.5 * (1.0 + HOLE_POLE)
    if Dz != 0.0:
        za, zb = (-z_cap - zc) / Dz, (z_cap - zc) / Dz
        lo, hi = max(lo, min(za, zb)), min(hi, max(za, zb))
    elif abs(zc) >= z_cap:
        return 0
    if not hi > lo:
        return 0
    # the pieces' ends: psi'' changes sign at the roots of Q (none when the ray is level,
    # Dz = 0: then rho alone curves, psi is convex). A ray through the axis (X = 0) makes Q
    # -rho^2, whose double root is the kink of rho there (an end, v = 0 exactly).
    p1 = p2 = np.nan
    kappa = np.inf
    if Dz != 0.0:
        r = _cbrt(abs(X) / abs(Dz))
        kappa = (r * r) * (r * r)
    if math.isfinite(kappa):
        _, p1, p2 = quadratic(-(kappa * Dz * Dz + E), -(kappa * zc * Dz + E * off),
                              kappa * (1.0 - zc) * (1.0 + zc) - (E * off * off + m2))
    p1 = p1 if lo < p1 < hi else np.inf  # the ends inside (lo, hi), ascending
    p2 = p2 if lo < p2 < hi else np.inf
    if p1 > p2:
        p1, p2 = p2, p1
    n = 0
    a_ = lo
    for j in range(3):
        b_ = min(p1 if j == 0 else (p2 if j == 1 else hi), hi)
        if not b_ > a_:
            continue
        c = 1.0
        if math.isfinite(kappa):  # the sign of Q (of psi'') in the middle of the piece
            vm = 0.5 * (a_ + b_)
            z = zc + vm * Dz
            if kappa * (1.0 - z) * (1.0 + z) - (E * (vm + off) ** 2 + m2) < 0.0:
                c = -1.0
        m, v0, v1 = _hole_piece(E, m2, off, zc, Dz, Rn, c, a_, b_)
        for k in range(m):
            tt = (s0 + uc + (v0 if k == 0 else v1)) / speed
            if tt > tmin and tt <= tmax and n < 4 and (n == 0 or tt > out[n - 1]):
                out[n] = tt
                n += 1
        a_ = b_
    return n

@njit(**INLINE)
def cone_roots(ray, r0, z0, r1, z1, tmin, out):
    """Hits (mm) of the ray with the segment ``(r0, z0) -> (r1, z1)`` revolved about z.

    A frustum (cylinder when ``r0 == r1``, annulus when ``z0 == z1``); only hits whose meridian
    point projects onto the segment (within 1e-9 of its length) count. The meridian line is
    ``n_r rho + n_z z = c``; squared it is a quadratic in ``t``, solved from the ray's closest
    approach to the segment's mid-height on the axis (no digits lost far away). The mirror
    nappe (``n_r rho`` and ``c - n_z z`` of opposite signs) is dropped by a sign test, and on
    the surface ``rho = (c - n_z z) / n_r`` needs no square root. Near a double root (a ray
    grazing the cone) one Newton step on the unsquared equation restores the lost digits.
    Writes up to two roots ``> tmin`` ascending into ``out`` and returns how many.
    """
    ox, oy, oz, dx, dy, dz = ray
    dr, dzs = r1 - r0, z1 - z0
    L2 = dr * dr + dzs * dzs
    length = math.sqrt(L2)
    zm = 0.5 * (z0 + z1)
    rz = oz - zm
    t0 = -(ox * dx + oy * dy + rz * dz)
    Px, Py, Pz = ox + t0 * dx, oy + t0 * dy, rz + t0 * dz
    n_r, n_z = dzs / length, -dr / length
    c = n_r * r0 + n_z * (z0 - zm)
    n = 0
    if n_r == 0.0:  # an annulus: one plane crossing
        if dz == 0.0:
            return 0
        s = (z0 - zm - Pz) / dz
        x, y = Px + s * dx, Py + s * dy
        rho = math.sqrt(x * x + y * y)
        along = (rho - r0) * dr / L2
        if along >= -1e-9 and along <= 1.0 + 1e-9 and t0 + s > tmin:
            out[0] = t0 + s
            return 1
        return 0
    w0 = c - n_z * Pz
    w1 = -n_z * dz
    nr2 = n_r * n_r
    A = nr2 * (dx * dx + dy * dy) - w1 * w1
    Bq = nr2 * (Px * dx + Py * dy) - w0 * w1
    Cq = nr2 * (Px * Px + Py * Py) - w0 * w0
    k, c0, c1 = quadratic(A, Bq, Cq)
    near_double = k == 2 and abs(c1 - c0) < 1e-6 * (abs(c0) + abs(c1) + length)
    for j in range(k):
        s = c0 if j == 0 else c1
        lin = w0 + w1 * s
        if lin * n_r < 0.0:
            continue  # the mirror nappe
        if near_double:  # one Newton step on h(s) = n_r rho(s) - w0 - w1 s
            x, y = Px + s * dx, Py + s * dy
            rho = math.sqrt(x * x + y * y)
            if rho > 0.0:
                dh = n_r * (x * dx + y * dy) / rho - w1
                if dh != 0.0:
                    step = (n_r * rho - lin) / dh
                    if abs(step) < 1e-3 * length:
                        s -= step
                        lin = w0 + w1 * s
        z = Pz + s * dz + zm
        rho = lin / n_r
        along = ((rho - r0) * dr + (z - z0) * dzs) / L2
        tt = t0 + s
        if along >= -1e-9 and along <= 1.0 + 1e-9 and tt > tmin:
            out[n] = tt
            n += 1
    if n == 2 and out[0] > out[1]:
        out[0], out[1] = out[1], out[0]
    return n
