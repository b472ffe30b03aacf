"""Screw threads as true geometry: the helical ridge on a straight piece of a round neck.

Design rule: a ``HELIX`` row of the segment table (:mod:`.profile`, columns ``H_*``) is a
line row of the outer wall, the cone ``r = L(z)``, raised on its band ``H_Z0 <= z <= H_Z1``
by the thread's ridge into the surface

    F(p) = rho - L(z) - h(u, v) = 0,    glass where F < 0, air where F > 0,

with ``rho`` the distance from the axis, ``u = (theta - phase) R_ref`` the arc length around
the girth at the reference radius, ``v = V0 + (z - Z0) LEN / (Z1 - Z0)`` the section's arc
length, and ``h`` exactly the relief of a thread tile (:func:`.bumps.thread_profile`, the
same function the bump shades with), measured radially. ``h`` vanishes beyond the thread's
turns (a band's first and last 0.05 pitch are always bare), so the surface meets the plain
cone with the same radius and normal: the ridge is glass continuous with the wall, and the
outer wall stays one render object with its media and material. The geometric normal is
``grad F / |grad F|``, exact and pointing to the air like every outer-wall normal.

Hits: outside the band the row is its cone (closed form, :func:`.roots.cone_roots`). On the
band the ray is restricted (closed form) to the shell ``r_in <= rho <= r_out`` that holds
the ridge (``F < 0`` inside ``r_in``, ``F > 0`` outside ``r_out``), at most two intervals.
On each, :func:`_march` steps by ``|F| / lip`` (:func:`helix_lipschitz` bounds ``|dF/dt|``
along a unit ray, so no crossing lies within such a step) but at least ``1 / MAX_STEPS`` of
the interval; a step where the bound cannot exclude a pair of crossings (``|F(a)| + |F(b)| <
lip (b - a)``, ``F`` first falling then rising in size) is searched for the turn of ``F``
(:func:`_dip`). Each bracket is refined by safeguarded Newton to ``ROOT_TOL``. Bounded per
ray and row: at most ``2 (MAX_STEPS + 1)`` marching evaluations, ``DIP_ITERATIONS`` per step
searched, ``REFINE_ITERATIONS`` per root and ``MAX_ROOTS`` roots. What can be
missed: a pair of crossings inside one short step with more than one turn of ``F`` between
them (a graze of the ridge far shallower than ``lip`` times a step).
Units mm.
"""
from __future__ import annotations

import math

from numba import njit

from .bumps import thread_profile
from .profile import (H_DEPTH, H_FLANK_HI, H_FLANK_LO, H_PHASE, H_PITCH, H_REF, H_RUNOUT, H_START,
                      H_STARTS, H_TURNS, H_Z0, H_Z1, S_LEN, S_R0, S_R1, S_V0, S_Z0, S_Z1, TWO_PI)
from .jit import INLINE, JIT
from .roots import cone_roots, hypot2, sort_small

#: Marching steps per shell interval at most (each step is at least this fraction of it).
MAX_STEPS = 256
#: Bisections of the slope when a step may hide a pair of crossings.
DIP_ITERATIONS = 40
#: Safeguarded Newton iterations per root at most.
REFINE_ITERATIONS = 64
#: Roots on the band returned per ray and row at most (the caller takes the first it accepts).
MAX_ROOTS = 6
#: A root is refined until its bracket is this narrow (mm).
ROOT_TOL = 1e-10
#: The shell holding the ridge is widened by this much (mm) on each side.
SHELL_PAD = 1e-6
#: Largest slope of the quintic fade of :func:`.bumps._window`'s each end (15/8), doubled for
#: a window short enough that both ends overlap.
_RAMP_SLOPE = 3.75


@njit(**INLINE)
def helix_relief(seg, i, theta, v):
    """``(h, dh/du, dh/dv)`` of HELIX row ``i``'s ridge at polar angle ``theta`` (rad) and
    section coordinate ``v`` (mm): the thread tile's relief (:mod:`.bumps` conventions)."""
    R = seg[i, H_REF]
    n = seg[i, H_STARTS]
    depth = seg[i, H_DEPTH]
    pitch = seg[i, H_PITCH]
    circ = TWO_PI * R
    uu = theta * R - seg[i, H_PHASE] * R
    e, de, prof, dprof = thread_profile(uu, v, circ, n, pitch, seg[i, H_START], seg[i, H_FLANK_LO],
                                        seg[i, H_FLANK_HI], seg[i, H_TURNS], seg[i, H_RUNOUT])
    hh = depth * e * prof
    hu = depth * (de / circ * prof - e * dprof * n / circ)
    return hh, hu, depth * e * dprof / pitch


@njit(**INLINE)
def helix_v(seg, i, z):
    """Section arc length ``v`` (mm) at height ``z`` on HELIX row ``i`` (its base line's)."""
    return seg[i, S_V0] + (z - seg[i, S_Z0]) * (seg[i, S_LEN] / (seg[i, S_Z1] - seg[i, S_Z0]))


@njit(**JIT)
def helix_field(seg, i, x, y, z):
    """``(F, dF/dx, dF/dy, dF/dz)`` of HELIX row ``i`` at the point ``(x, y, z)`` (mm)."""
    z0, z1 = seg[i, S_Z0], seg[i, S_Z1]
    slope = (seg[i, S_R1] - seg[i, S_R0]) / (z1 - z0)
    vscale = seg[i, S_LEN] / (z1 - z0)
    rho = hypot2(x, y)
    if rho > 0.0:
        ex, ey = x / rho, y / rho
    else:
        ex, ey, rho = 1.0, 0.0, 1e-300
    h, hu, hv = helix_relief(seg, i, math.atan2(y, x), helix_v(seg, i, z))
    f = rho - (seg[i, S_R0] + (z - z0) * slope) - h
    ht = hu * seg[i, H_REF] / rho       # dh per mm along e_theta = (-ey, ex)
    return f, ex + ht * ey, ey - ht * ex, -slope - hv * vscale


@njit(**JIT)
def helix_normal(seg, i, px, py, pz):
    """Outward unit normal ``grad F / |grad F|`` of HELIX row ``i`` at ``p`` (mm)."""
    _, gx, gy, gz = helix_field(seg, i, px, py, pz)
    g = math.sqrt(gx * gx + gy * gy + gz * gz)
    return gx / g, gy / g, gz / g


@njit(**INLINE)
def _shell(seg, i):
    """``(r_in, r_out)`` (mm): radii between which row ``i``'s band surface lies."""
    z0, z1 = seg[i, S_Z0], seg[i, S_Z1]
    slope = (seg[i, S_R1] - seg[i, S_R0]) / (z1 - z0)
    ra = seg[i, S_R0] + (seg[i, H_Z0] - z0) * slope
    rb = seg[i, S_R0] + (seg[i, H_Z1] - z0) * slope
    depth = seg[i, H_DEPTH]
    return min(ra, rb) + min(depth, 0.0) - SHELL_PAD, max(ra, rb) + max(depth, 0.0) + SHELL_PAD


@njit(**JIT)
def helix_lipschitz(seg, i, r_in):
    """A bound of ``|dF/dt|`` along any unit ray in row ``i``'s shell (``rho >= r_in``):
    ``grad F`` has the orthogonal parts ``1`` (radial), ``dh/du R_ref / rho`` (around) and
    ``dL/dz + dh/dv dv/dz`` (along the axis), each slope bounded by the largest slopes of the
    bell across the ridge (``pi / (2 flank)`` per pitch) and of the run-out's fade
    (``3.75 / runout`` per turn); 5 % to spare."""
    z0, z1 = seg[i, S_Z0], seg[i, S_Z1]
    slope = abs(seg[i, S_R1] - seg[i, S_R0]) / (z1 - z0)
    vscale = seg[i, S_LEN] / (z1 - z0)
    depth = abs(seg[i, H_DEPTH])
    R = seg[i, H_REF]
    bell = 0.5 * math.pi / min(seg[i, H_FLANK_LO], seg[i, H_FLANK_HI])
    hu = depth * (_RAMP_SLOPE / seg[i, H_RUNOUT] + seg[i, H_STARTS] * bell) / (TWO_PI * R)
    hv = depth * bell / seg[i, H_PITCH]
    around = hu * R / max(r_in, 1e-9)
    axial = slope + hv * vscale
    return 1.05 * math.sqrt(1.0 + around * around + axial * axial)


@njit(**INLINE)
def _along(seg, i, ray, t):
    """``(F, dF/dt)`` on the ray ``o + t d`` (unit ``d``)."""
    ox, oy, oz, dx, dy, dz = ray
    f, gx, gy, gz = helix_field(seg, i, ox + t * dx, oy + t * dy, oz + t * dz)
    return f, gx * dx + gy * dy + gz * dz


@njit(**JIT)
def _refine(seg, i, ray, a, b, fa):
    """The crossing of ``F`` in the bracket ``[a, b]`` (``F(a) = fa`` and ``F(b)`` of opposite
    signs): Newton steps while they land inside the bracket and shrink it fast, else
    bisection; at most :data:`REFINE_ITERATIONS`."""
    neg_a = fa < 0.0
    x = 0.5 * (a + b)
    last = b - a
    for _ in range(REFINE_ITERATIONS):
        f, g = _along(seg, i, ray, x)
        if f == 0.0:
            return x
        if (f < 0.0) == neg_a:
            a = x
        else:
            b = x
        if b - a <= ROOT_TOL:
            break
        xn = x - f / g if g != 0.0 else a - 1.0
        if xn > a and xn < b and abs(xn - x) < 0.5 * last:
            last = abs(xn - x)
            x = xn
        else:
            last = b - a
            x = 0.5 * (a + b)
    return 0.5 * (a + b) if b - a <= ROOT_TOL else x


@njit(**JIT)
def _dip(seg, i, ray, a, b, fa, fb, lip):
    """Where ``F`` changes sign inside ``[a, b]`` though ``F(a) = fa`` and ``F(b) = fb`` share
    one (``F`` moves towards zero at ``a`` and away from it at ``b``): bisects the slope
    for its zero, stopping as soon as ``lip`` proves ``|F| > 0`` around it. Returns the point
    of opposite sign, or ``nan`` when there is none."""
    sa = 1.0 if fa > 0.0 else -1.0
    for _ in range(DIP_ITERATIONS):
        if abs(fa) + abs(fb) > lip * (b - a):
            return math.nan
        c = 0.5 * (a + b)
        fc, gc = _along(seg, i, ray, c)
        if fc * sa <= 0.0:
            return c
        if gc * sa < 0.0:    # still moving towards zero: the turn lies beyond c
            a, fa = c, fc
        else:
            b, fb = c, fc
    return math.nan


@njit(**JIT)
def _march(seg, i, ray, a, b, lip, out, n, stop):
    """Crossings of ``F`` on ``[a, b]``, ascending, appended to ``out`` from ``n`` until there
    are ``stop`` (module doc); ``lip`` bounds ``|dF/dt|``. Returns the new count."""
    hmin = (b - a) / MAX_STEPS
    t = a
    f, g = _along(seg, i, ray, t)
    for _ in range(MAX_STEPS + 1):
        if not t < b or n >= stop:
            break
        t1 = min(t + max(abs(f) / lip, hmin), b)
        f1, g1 = _along(seg, i, ray, t1)
        if (f < 0.0) != (f1 < 0.0):
            out[n] = _refine(seg, i, ray, t, t1, f)
            n += 1
        elif abs(f) + abs(f1) < lip * (t1 - t) and g * f < 0.0 and g1 * f1 > 0.0:
            c = _dip(seg, i, ray, t, t1, f, f1, lip)
            if not math.isnan(c):
                out[n] = _refine(seg, i, ray, t, c, f)
                n += 1
                if n < stop:
                    out[n] = _refine(seg, i, ray, c, t1, -f)
                    n += 1
        t, f, g = t1, f1, g1
    return n


@njit(**JIT)
def helix_roots(seg, i, ray, tlo, thi, out, need):
    """Crossings (mm, ascending, in ``(tlo, thi)``) of the ray ``o + t d`` (unit ``d``) with
    HELIX row ``i``: its cone off the band, and the first ``need`` (at most ``MAX_ROOTS``) on
    the band, where they cost most (the nearest-hit search takes the first it accepts and asks
    for no more); returns their number (written to ``out``, which holds at least
    ``MAX_ROOTS + 2``)."""
    ox, oy, oz, dx, dy, dz = ray
    hz0, hz1 = seg[i, H_Z0], seg[i, H_Z1]
    m = cone_roots(ray, seg[i, S_R0], seg[i, S_Z0], seg[i, S_R1], seg[i, S_Z1], tlo, out)
    n = 0
    for j in range(m):  # the plain cone's crossings off the band
        z = oz + out[j] * dz
        if out[j] < thi and (z < hz0 or z > hz1):
            out[n] = out[j]
            n += 1
    if dz != 0.0:
        ta, tb = (hz0 - oz) / dz, (hz1 - oz) / dz
        lo, hi = max(min(ta, tb), tlo), min(max(ta, tb), thi)
    elif oz < hz0 or oz > hz1:
        return n
    else:
        lo, hi = tlo, thi
    if not lo < hi:
        return n
    rin, rout = _shell(seg, i)
    lip = helix_lipschitz(seg, i, rin)
    first = n
    stop = n + min(need, MAX_ROOTS)
    E = dx * dx + dy * dy
    if E == 0.0:                  # along the axis: rho is constant
        rho = hypot2(ox, oy)
        if rho >= rin and rho <= rout:
            n = _march(seg, i, ray, lo, hi, lip, out, n, stop)
    else:
        s = -(ox * dx + oy * dy) / E  # closest approach to the axis
        mx, my = ox + s * dx, oy + s * dy
        m2 = mx * mx + my * my
        h2 = rout * rout - m2
        if h2 > 0.0:
            h = math.sqrt(h2 / E)
            a, b = max(lo, s - h), min(hi, s + h)
            g2 = rin * rin - m2
            if g2 <= 0.0:           # the ray never dips inside r_in: one interval
                if a < b:
                    n = _march(seg, i, ray, a, b, lip, out, n, stop)
            else:                   # in through the shell, across the bore side, out again
                g = math.sqrt(g2 / E)
                if a < min(b, s - g):
                    n = _march(seg, i, ray, a, min(b, s - g), lip, out, n, stop)
                if max(a, s + g) < b and n < stop:
                    n = _march(seg, i, ray, max(a, s + g), b, lip, out, n, stop)
    if n > first and first > 0:
        sort_small(out, n)
    return n
