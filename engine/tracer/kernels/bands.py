"""Certified bands: where along a ray a wall with a varying cross-section can be crossed.

Design rule: over a ray interval ``[a, b]`` the heights ``z`` span a range, so every section's
radius spans a range ``[r_lo, r_hi]`` (exact for lines and arcs, from a monotone table for the
offset of an ellipse). Cross-section functions are monotone in the radii, so the surface can
only be crossed where the ray's footprint is inside the *outer* outline (largest radii) and
outside the *inner* one (smallest): a closed-form 2-D problem (a ray against circles, ellipses
and rounded rectangles) giving at most two *bands*. Restricting to a band narrows the height
range, hence the radii, hence the bands: the iteration contracts onto the crossings; where it
stalls the interval is halved. A band narrower than the leaf length is solved on the exact
surface. This is a proof, not a sampling: no crossing outside the bands is possible.
Units: mm; outlines in the bottle frame.
"""
from __future__ import annotations

import math

from numba import njit

from .outlines import CIRCLE, OVAL, RRECT, RSQUARE, disc_interval, outline_interval, square_corner, xs_eval
from .profile import base_range, base_z, wall_r, wall_range
from .roots import INLINE, JIT



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
def _illinois(f_kind, seg, tab, r0, r1, r2, nsec, kind, c, s, ox, oy, oz, dx, dy, dz, a, b, fa, fb):
    """The crossing inside ``[a, b]`` (``fa``, ``fb`` of opposite signs): Illinois false position."""
    x = a
    last = 0
    for _ in range(100):
        x = (a * fb - b * fa) / (fb - fa)
        if not (x > a and x < b):
            x = 0.5 * (a + b)
        fx = residual(f_kind, seg, tab, r0, r1, r2, nsec, kind, c, s, ox, oy, oz, dx, dy, dz, x)
        if fx == 0.0 or b - a <= 4e-16 * max(abs(a), abs(b)) + 1e-300:
            break
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
    return x


# residual kinds
F_WALL, F_BASE = 0, 1


@njit(**JIT)
def residual(f_kind, seg, tab, r0, r1, r2, nsec, kind, c, s, ox, oy, oz, dx, dy, dz, t):
    """Signed residual of the wall at ray distance ``t``: positive outside the outline.

    ``F_WALL``: cross-section ``kind`` at radii ``r(z)`` of segment rows ``r0..r2`` (a CIRCLE
    wall is ``rho - r(z)``); ``F_BASE``: ``z - Z(rho)`` of the r-rising curve row ``r0``."""
    x, y, z = ox + t * dx, oy + t * dy, oz + t * dz
    if f_kind == F_BASE:
        return z - base_z(seg, r0, math.sqrt(x * x + y * y))
    ra = wall_r(seg, r0, z)
    if kind == CIRCLE:
        return math.sqrt(x * x + y * y) - ra
    rb = wall_r(seg, r1, z) if nsec > 1 else 0.0
    rc = wall_r(seg, r2, z) if nsec > 2 else 0.0
    xb, yb = c * x + s * y, -s * x + c * y
    return xs_eval(kind, ra, rb, rc, xb, yb)[0]


@njit(**JIT)
def band_roots(f_kind, seg, tab, r0, r1, r2, nsec, kind, c, s, ox, oy, oz, dx, dy, dz, lo, hi, leaf,
               out, n, stack):
    """Crossings (ascending, appended to ``out`` from index ``n``) of the ray with a wall in
    ``[lo, hi]``: bands contracted (module doc) down to ``leaf`` (mm), then solved exactly.

    ``f_kind`` F_WALL: a z-rising wall whose sections are segment rows ``r0..r2`` (``nsec`` of
    them) of cross-section ``kind``, turned by ``(c, s) = (cos, sin)`` of the bottle's rotation;
    F_BASE: the revolved r-rising curve row ``r0`` (a punt's offset). Only a pair of crossings
    closer than ``leaf`` can be missed (a graze). ``stack`` is ``(64, 2)`` scratch.
    """
    # the ray's footprint in the bottle frame (outlines are not turned)
    px, py = c * ox + s * oy, -s * ox + c * oy
    qx, qy = c * dx + s * dy, -s * dx + c * dy
    top = 0
    stack[0, 0], stack[0, 1] = lo, hi
    top = 1
    budget = BUDGET
    n0 = n
    while top > 0 and n < out.shape[0]:
        top -= 1
        a, b = stack[top, 0], stack[top, 1]
        empty = False
        while budget > 0:
            budget -= 1
            if b - a <= leaf:
                break
            za, zb = oz + a * dz, oz + b * dz
            z_lo, z_hi = min(za, zb), max(za, zb)
            if f_kind == F_BASE:
                # z(t) must lie within the curve's height range over the ray's radius range
                E = dx * dx + dy * dy
                sa = -(ox * dx + oy * dy) / E if E > 0.0 else a
                sn = min(max(sa, a), b)
                rho_lo = math.sqrt((ox + sn * dx) ** 2 + (oy + sn * dy) ** 2)
                rho_hi = max(math.sqrt((ox + a * dx) ** 2 + (oy + a * dy) ** 2),
                             math.sqrt((ox + b * dx) ** 2 + (oy + b * dy) ** 2))
                h_lo, h_hi = base_range(seg, tab, r0, rho_lo, rho_hi)
                if dz == 0.0:
                    if oz < h_lo or oz > h_hi:
                        empty = True
                        break
                    l0, h0, l1, h1 = a, b, 1.0, -1.0
                else:
                    t0, t1 = (h_lo - oz) / dz, (h_hi - oz) / dz
                    l0, h0 = max(a, min(t0, t1)), min(b, max(t0, t1))
                    l1, h1 = 1.0, -1.0
            else:
                a_lo, a_hi = wall_range(seg, tab, r0, z_lo, z_hi)
                b_lo, b_hi, c_lo, c_hi = 0.0, 0.0, 0.0, 0.0
                if nsec > 1:
                    b_lo, b_hi = wall_range(seg, tab, r1, z_lo, z_hi)
                if nsec > 2:
                    c_lo, c_hi = wall_range(seg, tab, r2, z_lo, z_hi)
                if kind == CIRCLE:
                    l0, h0, l1, h1 = annulus_bands(ox, oy, dx, dy, a_lo, a_hi, a, b)
                else:
                    ok_in = True
                    if kind == RSQUARE:  # q <= u holds exactly (v >= u); clamp the rounding
                        ko, o0, o1, o2 = RRECT, a_hi, a_hi, min(a_hi, max(0.0, square_corner(a_hi, b_hi)))
                        ki, i0, i1, i2 = RRECT, a_lo, a_lo, min(a_lo, max(0.0, square_corner(a_lo, b_lo)))
                    elif kind == RRECT:
                        ko, o0, o1, o2 = RRECT, a_hi, b_hi, c_lo
                        ki, i0, i1, i2 = RRECT, a_lo, b_lo, c_hi
                        ok_in = c_hi <= min(a_lo, b_lo)
                    else:
                        ko, o0, o1, o2 = OVAL, a_hi, b_hi, 0.0
                        ki, i0, i1, i2 = OVAL, a_lo, b_lo, 0.0
                    e0, e1 = outline_interval(ko, o0, o1, o2, px, py, qx, qy)
                    n0, n1 = (outline_interval(ki, i0, i1, i2, px, py, qx, qy) if ok_in else (1.0, -1.0))
                    l0, h0, l1, h1 = subtract(e0, e1, n0, n1, a, b)
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
        # a band's ends lie on the bounding outlines, which a crossing may touch: widen by a
        # rounding-level margin (nothing lies outside the bands) before testing the sign
        eps = 1e-13 * (abs(a) + abs(b)) + 1e-3 * leaf
        a, b = max(lo, a - eps), min(hi, b + eps)
        fa = residual(f_kind, seg, tab, r0, r1, r2, nsec, kind, c, s, ox, oy, oz, dx, dy, dz, a)
        fb = residual(f_kind, seg, tab, r0, r1, r2, nsec, kind, c, s, ox, oy, oz, dx, dy, dz, b)
        if fa == 0.0:
            root = a
        elif (fa > 0.0) != (fb > 0.0):
            root = _illinois(f_kind, seg, tab, r0, r1, r2, nsec, kind, c, s, ox, oy, oz, dx, dy, dz, a, b, fa, fb)
        else:
            continue
        if n == n0 or root > out[n - 1] + 2.0 * eps:  # neighbouring bands may share a crossing
            out[n] = root
            n += 1
    return n
