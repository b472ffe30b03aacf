"""Exact hits on section segments revolved about the z axis (round walls, punts), compiled.

Design rule: one row of the segment table (:mod:`~engine.tracer.kernels.profile`) is one
meridian segment in its own (r, z) plane, in mm. Lines are cones
(:func:`~engine.tracer.kernels.roots.cone_roots`), circle and ellipse arcs are tori or
spheroids, both restricted to the segment's extent: an arc on the outer side of its tube
(convex shoulders, heels, bulbs; every point at least its centre's radius from the axis)
through :func:`~engine.tracer.kernels.roots.convex_sheet_roots`, which needs no quartic
(measured on public_4, 0.82x the frame's time), an arc on the side of its tube facing the axis
(waists, shoulders running into a neck) through
:func:`~engine.tracer.kernels.roots.hole_sheet_roots`, which needs none either (0.94-0.97x),
and an arc reaching its tube's pole through :func:`~engine.tracer.kernels.roots.torus_roots`;
the inner wall of an ellipse arc (its exact offset, a degree-8 curve) is found piece by piece
along its monotone table (:func:`offset_roots`). Every segment is first culled by its revolved bounding box (two
cylinders, two planes), which is exact and conservative; the ray's share of that test
(:func:`ray_axis`) is computed once per ray.
Normals are the segment's outward meridian normal ``n = (T_z, -T_r)`` revolved to world space.
A straight piece raised by a screw thread (``HELIX``) is handed to :mod:`.helix`.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .bands import annulus_bands, subtract
from .helix import MAX_ROOTS, helix_normal, helix_roots, helix_v
from .profile import (HELIX, LINE, OFFSET, S_A0, S_AR, S_AXIS, S_AZ, S_CR, S_CZ, S_DIR, S_KIND, S_LEN, S_R0,
                      S_R1, S_RMAX, S_RMIN, S_SIDE, S_SWEEP, S_ZMAX, S_ZMIN, S_TAB0, S_TABN, S_V0, S_Z0, S_Z1,
                      TWO_PI, _offset_at, in_sweep, offset_at_between, offset_point, offset_rz)
from .records import OffsetPiece, Ray
from .jit import INLINE, JIT
from .roots import (HOLE_POLE, SHEET_SLACK, cone_roots, convex_sheet_roots, disc_interval, hole_sheet_roots, hypot2,
                    illinois_done, illinois_point, illinois_update, sort_small, torus_roots)

#: Band contraction on an offset arc stops at this fraction of the segment's length: only a
#: pair of crossings closer than that can be missed (a graze of well under 1e-6 mm).
OFFSET_LEAF = 1e-5
#: :func:`offset_roots` writes the base angle of its root ``q`` at ``out[PARAM_SLOT + q]`` (nan
#: where it is not known), so a hit's normal needs no second solve for it (public_4's frame
#: 0.92-0.94x); it reports at most this many roots, and ``out`` has twice as many slots.
PARAM_SLOT = 8


@njit(**INLINE)
def ray_axis(ox, oy, dx, dy, dz):
    """The ray's constants for :func:`ray_box_from`, computed once per ray rather than once per
    box: ``(1/dz, s, m2, 1/E)``, ``s`` its distance (mm) to its closest approach to the z axis,
    ``m2`` that distance's square from the axis, ``E = dx^2 + dy^2`` (a reciprocal is 0 where
    its denominator is)."""
    E = dx * dx + dy * dy
    inv_dz = 1.0 / dz if dz != 0.0 else 0.0
    if E > 0.0:
        s = -(ox * dx + oy * dy) / E
        mx, my = ox + s * dx, oy + s * dy
        return inv_dz, s, mx * mx + my * my, 1.0 / E
    return inv_dz, 0.0, ox * ox + oy * oy, 0.0


@njit(**INLINE)
def ray_box_from(axis, ray, rmin, rmax, zmin, zmax, tlo, thi):
    """:func:`ray_box` from the ray's constants ``axis`` (:func:`ray_axis`)."""
    ox, oy, oz, dx, dy, dz = ray
    inv_dz, s_axis, m2, inv_E = axis
    if dz != 0.0:
        ta = (zmin - oz) * inv_dz
        tb = (zmax - oz) * inv_dz
        lo = min(ta, tb)
        hi = max(ta, tb)
    else:
        if oz < zmin or oz > zmax:
            return 1.0, -1.0
        lo, hi = -np.inf, np.inf
    lo = max(lo, tlo)
    hi = min(hi, thi)
    if lo > hi:
        return 1.0, -1.0
    h2 = rmax * rmax - m2
    if h2 < 0.0:  # the ray never comes within rmax of the axis
        return 1.0, -1.0
    if inv_E > 0.0:  # inside the cylinder rho <= rmax, from the closest approach to the axis
        h = math.sqrt(h2 * inv_E)
        lo = max(lo, s_axis - h)
        hi = min(hi, s_axis + h)
        if lo > hi:
            return 1.0, -1.0
    if rmin > 0.0:  # rho^2 is convex along the ray: inside rmin at both ends, inside throughout
        xa, ya, xb, yb = ox + lo * dx, oy + lo * dy, ox + hi * dx, oy + hi * dy
        if max(xa * xa + ya * ya, xb * xb + yb * yb) < rmin * rmin:
            return 1.0, -1.0
    return lo, hi


@njit(**INLINE)
def ray_box(ray, rmin, rmax, zmin, zmax, tlo, thi):
    """Part ``[lo, hi]`` of ``tlo < t < thi`` where the ray may be inside the revolved box
    ``rmin <= rho <= rmax, zmin <= z <= zmax`` (mm); ``lo > hi`` when it cannot.

    Exact for the slab in z and the cylinder ``rho <= rmax``; the inner cylinder only rejects
    (``rho(t)^2`` is convex: the interval is not split where it dips inside ``rmin``).
    """
    ox, oy, oz, dx, dy, dz = ray
    return ray_box_from(ray_axis(ox, oy, dx, dy, dz), ray, rmin, rmax, zmin, zmax,
                        tlo, thi)


@njit(**JIT)
def _piece_f(piece, ray, t):
    """Residual of offset arc row ``i`` at ray distance ``t``, its curve solved on table piece
    ``k`` (a :class:`~.records.OffsetPiece`: rows ``k, k + 1``, whose key coordinates bracket the solve without evaluating the
    curve there): wall ``rho - r(z)``, base ``z - z(rho)``."""
    ox, oy, oz, dx, dy, dz = ray
    seg, tab, k, i, axis, _, _ = piece
    x, y, z = ox + t * dx, oy + t * dy, oz + t * dz
    rho = math.sqrt(x * x + y * y)
    ka, kb = (k, k + 1) if tab[k, 2] <= tab[k + 1, 2] else (k + 1, k)  # rising in the parameter
    value = z if axis == 1 else rho
    s = offset_at_between(seg, i, axis, value, tab[ka, 2], tab[kb, 2], tab[ka, axis] - value, tab[kb, axis] - value)
    if axis == 1:
        return rho - offset_point(seg, i, s)[0]
    return z - offset_point(seg, i, s)[1]


@njit(**JIT)
def _piece_newton(piece, ray, a, b, t, s):
    """The crossing ``(t, s)`` in ``[a, b]`` by Newton on the 2-D system
    ``(rho(t), z(t)) = (R(s), Z(s))`` in the ray distance ``t`` and the curve's base angle ``s``
    (one curve evaluation per step), from the guess ``(t, s)``; ``t`` is ``nan`` when an iterate
    leaves the bracket or the piece."""
    ox, oy, oz, dx, dy, dz = ray
    seg, _, _, i, _, x0, x1 = piece
    a0, sw = seg[i, S_A0], seg[i, S_SWEEP]
    s_lo, s_hi = a0 + min(x0, x1) * sw, a0 + max(x0, x1) * sw
    if s_lo > s_hi:
        s_lo, s_hi = s_hi, s_lo
    slack = 1e-9 * (s_hi - s_lo) + 1e-15
    for _ in range(12):
        x, y, z = ox + t * dx, oy + t * dy, oz + t * dz
        rho = math.sqrt(x * x + y * y)
        R, dR, Z, dZ = offset_rz(seg, i, s)
        g1, g2 = rho - R, z - Z
        drho = (x * dx + y * dy) / rho if rho > 0.0 else 0.0
        det = -drho * dZ + dR * dz  # [[drho, -dR], [dz, -dZ]]
        if det == 0.0:
            return np.nan, s
        dt = (-dZ * g1 + dR * g2) / det
        ds = (-dz * g1 + drho * g2) / det
        t -= dt
        s -= ds
        if not (t >= a and t <= b and s >= s_lo - slack and s <= s_hi + slack):
            return np.nan, s
        if abs(dt) <= 1e-14 * (abs(t) + 1.0):
            return t, s
    return np.nan, s


@njit(**INLINE)
def _chord_v(nr, nz, r0, z0, ray, t):
    """Signed distance ``n . (p - P0)`` (mm) of the ray's point at ``t``, in its meridian
    plane, from the chord through ``P0 = (r0, z0)`` with unit normal ``n = (nr, nz)``."""
    ox, oy, oz, dx, dy, dz = ray
    x, y = ox + t * dx, oy + t * dy
    return nr * (math.sqrt(x * x + y * y) - r0) + nz * (oz + t * dz - z0)


@njit(**INLINE)
def _band_side(v, band, eps, sgn_pos):
    """Sign of the residual at a point whose distance from the piece's chord is ``v``
    (:func:`_chord_v`) when it lies outside the band beside the chord (``v`` beyond
    ``[min(0, band), max(0, band)]`` by ``eps``): ``sgn_pos`` on the positive side,
    ``-sgn_pos`` on the negative one; 0 inside (unknown)."""
    if v > max(0.0, band) + eps:
        return sgn_pos
    if v < min(0.0, band) - eps:
        return -sgn_pos
    return 0.0


@njit(**INLINE)
def _chord_extreme(nr, nz, ox, oy, dx, dy, dz, a, b):
    """The ray distance in ``(a, b)`` where ``v(t) = nr rho(t) + nz z(t)`` (the distance from
    a chord with unit normal ``(nr, nz)``, up to a constant) is stationary, or nan.

    ``rho(t)`` is convex, so ``v`` is convex (``nr > 0``) or concave and has at most one
    stationary point: with ``rho^2 = E tau^2 + m^2`` (``tau`` from the closest approach to
    the axis), ``nr E tau = -nz dz rho`` gives ``tau`` in closed form."""
    E = dx * dx + dy * dy
    if E == 0.0 or nr == 0.0:
        return np.nan
    ts = -(ox * dx + oy * dy) / E
    mx, my = ox + ts * dx, oy + ts * dy
    m2 = mx * mx + my * my
    c = nz * dz
    den = E * (nr * nr * E - c * c)
    if not den > 0.0:
        return np.nan  # v is monotone
    tau = abs(c) * math.sqrt(m2 / den)
    if nr * c > 0.0:
        tau = -tau
    t = ts + tau
    return t if a < t < b else np.nan


@njit(**JIT)
def _piece_solve(piece, chord, ray, a, b, va, vb):
    """The crossing in ``[a, b]`` of table piece ``k`` (``chord`` = ``(nr, nz, length, band)``:
    its chord's unit normal ``n``, ``length`` mm, the band's width), whose residual changes sign there: Newton from where the ray crosses the middle of
    the piece's band (linear in the distances ``va, vb`` of the ends from the chord), the
    curve's parameter from the chord's fraction there; Illinois false position on the curve
    if Newton leaves the bracket (slower, sure). Returns ``(t, s)``, the root and its base
    angle (``nan`` after false position)."""
    ox, oy, oz, dx, dy, dz = ray
    seg, tab, k, i, _, _, _ = piece
    nr, nz, length, band = chord
    pr, pz = tab[k, 0], tab[k, 1]
    er, ez = -nz, nr
    root, s = np.nan, np.nan
    if length > 0.0:
        mid = 0.5 * band if math.isfinite(band) else 0.0
        t = a if va == vb else a + (b - a) * min(1.0, max(0.0, (mid - va) / (vb - va)))
        x, y, z = ox + t * dx, oy + t * dy, oz + t * dz
        u = min(1.0, max(0.0, ((math.sqrt(x * x + y * y) - pr) * er + (z - pz) * ez) / length))
        s = seg[i, S_A0] + (tab[k, 2] + u * (tab[k + 1, 2] - tab[k, 2])) * seg[i, S_SWEEP]
        root, s = _piece_newton(piece, ray, a, b, t, s)
    if not math.isfinite(root):
        fa = _piece_f(piece, ray, a)
        fb = _piece_f(piece, ray, b)
        root, s = _illinois_piece(piece, ray, a, b, fa, fb), np.nan
    return root, s


@njit(**JIT)
def _piece_root(piece, box, ray, a, b, out, n):
    """The crossings of table piece ``k`` (rows ``k, k + 1``) inside ``[a, b]``, appended to
    ``out`` when they lie on the piece (``box`` = ``(r0, r1, z0, z1, pad)``, its extent in mm
    and padding) (their base angles at :data:`PARAM_SLOT` on).

    The residual's sign at a point comes from the piece's band beside its chord when the point
    lies outside it (no curve to solve: most ends, the band being micrometres wide), else from
    the curve. Ends of one sign hide a pair of crossings only if the ray dips towards the other
    side between them: then the sign where the ray's distance from the chord is extreme
    (:func:`_chord_extreme`) splits the interval. Each crossing: :func:`_piece_solve`."""
    ox, oy, oz, dx, dy, dz = ray
    tab, k, axis = piece.tab, piece.k, piece.axis
    r0, r1, z0, z1, pad = box
    pr, pz = tab[k, 0], tab[k, 1]
    er, ez = tab[k + 1, 0] - pr, tab[k + 1, 1] - pz
    length = hypot2(er, ez)
    band = tab[k, 3]
    nr, nz = 0.0, 0.0
    if length > 0.0:
        nr, nz = ez / length, -er / length
    # a point beyond the band on its positive side is outside the curve (residual > 0) when the
    # normal leans that way in the residual's coordinate (rho for a wall, z for a base)
    lean = nr if axis == 1 else nz
    use_band = math.isfinite(band) and lean != 0.0
    sgn_pos = 1.0 if lean > 0.0 else -1.0
    eps = 1e-12 * (r1 + abs(z1) + 1.0)
    chord = (nr, nz, length, band)
    va = _chord_v(nr, nz, pr, pz, ray, a)
    vb = _chord_v(nr, nz, pr, pz, ray, b)
    fa = _band_side(va, band, eps, sgn_pos) if use_band else 0.0
    fb = _band_side(vb, band, eps, sgn_pos) if use_band else 0.0
    if fa == 0.0:
        fa = _piece_f(piece, ray, a)
    if fb == 0.0:
        fb = _piece_f(piece, ray, b)
    roots_lo, roots_hi = np.nan, np.nan
    s_lo = s_hi = np.nan
    if fa == 0.0:
        roots_lo = a
    elif (fa > 0.0) != (fb > 0.0) and fb != 0.0:
        roots_lo, s_lo = _piece_solve(piece, chord, ray, a, b, va, vb)
    elif fb != 0.0:  # one sign at both ends: a pair only if the ray dips to the other side
        tm = _chord_extreme(nr, nz, ox, oy, dx, dy, dz, a, b)
        if math.isfinite(tm):
            vm = _chord_v(nr, nz, pr, pz, ray, tm)
            fm = _band_side(vm, band, eps, sgn_pos) if use_band else 0.0
            if fm != 0.0 and (fm > 0.0) == (fa > 0.0):
                return n
            if fm == 0.0:
                fm = _piece_f(piece, ray, tm)
            if fm != 0.0 and (fm > 0.0) != (fa > 0.0):
                roots_lo, s_lo = _piece_solve(piece, chord, ray, a, tm, va, vm)
                roots_hi, s_hi = _piece_solve(piece, chord, ray, tm, b, vm, vb)
    for j in range(2):
        root = roots_lo if j == 0 else roots_hi
        if not math.isfinite(root):
            continue
        px, py, qz = ox + root * dx, oy + root * dy, oz + root * dz
        rho = math.sqrt(px * px + py * py)
        if r0 - pad <= rho <= r1 + pad and z0 - pad <= qz <= z1 + pad and n < PARAM_SLOT:
            if n == 0 or abs(root - out[n - 1]) > 1e-12 * (abs(root) + 1.0):
                out[n] = root
                out[PARAM_SLOT + n] = s_lo if j == 0 else s_hi
                n += 1
    return n


@njit(**JIT)
def _illinois_piece(piece, ray, a, b, fa, fb):
    """The crossing in ``[a, b]`` of the piece's exact residual by Illinois false position
    (``a`` itself when the residual does not change sign there, a rounding-level case)."""
    if fa == 0.0 or (fa > 0.0) == (fb > 0.0):
        return a if abs(fa) <= abs(fb) else b
    last = 0
    root = a
    for _ in range(100):
        root = illinois_point(a, b, fa, fb)
        fr = _piece_f(piece, ray, root)
        if illinois_done(a, b, fr):
            break
        a, b, fa, fb, last = illinois_update(a, b, fa, fb, root, fr, last)
    return root


@njit(**JIT)
def _offset_pieces(seg, tab, i, axis, ray, lo, hi, out, n):
    """Crossings of offset arc row ``i`` with the ray for ``t`` in ``[lo, hi]``, appended to
    ``out`` from index ``n`` in table order: the pieces whose key coordinate (z for a wall, r
    for a base) the ray's range of it meets (:func:`offset_roots`)."""
    ox, oy, oz, dx, dy, dz = ray
    first, count = int(seg[i, S_TAB0]), int(seg[i, S_TABN])
    # the rows rise in the key coordinate: visit only the pieces the ray's range of it meets
    if axis == 1:
        za, zb = oz + lo * dz, oz + hi * dz
        v_lo, v_hi = min(za, zb), max(za, zb)
    else:
        E = dx * dx + dy * dy
        sa = -(ox * dx + oy * dy) / E if E > 0.0 else lo
        sn = min(max(sa, lo), hi)
        v_lo = hypot2(ox + sn * dx, oy + sn * dy)
        v_hi = max(hypot2(ox + lo * dx, oy + lo * dy), hypot2(ox + hi * dx, oy + hi * dy))
    # the pieces' boxes are padded (below): so is the range (a ray down the axis meets a dome
    # whose apex row computed a radius of 1e-15)
    slack = 1e-9 * (seg[i, S_RMAX] + abs(seg[i, S_ZMAX]) + 1.0)
    v_lo, v_hi = v_lo - slack, v_hi + slack
    k0, k1 = first, first + count - 1
    while k0 < k1:  # first row whose key reaches v_lo
        m = (k0 + k1) // 2
        if tab[m, axis] < v_lo:
            k0 = m + 1
        else:
            k1 = m
    for k in range(max(first, k0 - 1), first + count - 1):
        if tab[k, axis] > v_hi:
            break
        r0, r1 = min(tab[k, 0], tab[k + 1, 0]), max(tab[k, 0], tab[k + 1, 0])
        z0, z1 = min(tab[k, 1], tab[k + 1, 1]), max(tab[k, 1], tab[k + 1, 1])
        pad = 1e-9 * (r1 + abs(z1) + 1.0)
        a, b = ray_box(ray, max(r0 - pad, 0.0), r1 + pad, z0 - pad, z1 + pad, lo, hi)
        if a > b:
            continue
        x0, x1 = min(tab[k, 2], tab[k + 1, 2]), max(tab[k, 2], tab[k + 1, 2])
        piece = OffsetPiece(seg, tab, k, i, axis, x0, x1)
        # only where the ray's radius is within the piece's (an annulus: up to two intervals) can
        # it cross the piece; there a base piece (a graph over r) has an unclamped residual, and
        # a ray leaving the piece is not confused by its own start on the far side
        l0, h0, l1, h1 = a, b, 1.0, -1.0
        if r0 - pad > 0.0:
            i0, i1 = disc_interval(ox, oy, dx, dy, 0.0, 0.0, r0 - pad)
            l0, h0, l1, h1 = subtract(a, b, i0, i1, a, b)
        for part in range(2):
            a, b = (l0, h0) if part == 0 else (l1, h1)
            if a > b:
                continue
            n = _piece_root(piece, (r0, r1, z0, z1, pad), ray, a, b, out, n)
    return n


@njit(**JIT)
def offset_roots(seg, tab, i, ray, lo, hi, out):
    """Crossings (ascending, in ``[lo, hi]``) of the ray with offset arc row ``i`` revolved.

    The arc's table cuts it into pieces along which both r and z are monotone, so the two rows
    of a piece bound it (a revolved box, :func:`ray_box`). In each box the ray meets, the
    residual changes sign where the ray crosses the piece (read from the piece's band beside
    its chord where the ray's end lies outside it, :func:`_piece_root`); that crossing is
    solved by Newton in the ray distance and the curve's parameter. Only a pair of crossings
    of one short piece (a graze within its band, a few micrometres) can be missed. At most
    :data:`PARAM_SLOT` roots; their base angles (rad, ``nan`` where unknown) follow from
    ``out[PARAM_SLOT]`` on, in the same order."""
    ox, oy, oz, dx, dy, dz = ray
    axis = int(seg[i, S_AXIS])
    if axis == 0:  # a base: [lo, hi] is already within its heights, the key is the radius
        n = _offset_pieces(seg, tab, i, axis, ray, lo, hi, out, 0)
    else:  # a wall: only where the ray's radius is within the row's can it meet a piece
        l0, h0, l1, h1 = annulus_bands(ox, oy, dx, dy, seg[i, S_RMIN], seg[i, S_RMAX], lo, hi)
        n = 0
        if l0 <= h0:
            n = _offset_pieces(seg, tab, i, axis, ray, l0, h0, out, n)
        if l1 <= h1:
            n = _offset_pieces(seg, tab, i, axis, ray, l1, h1, out, n)
    sort_small(out, n, PARAM_SLOT)  # pieces come in table order, not ray order (angles alongside)
    return n


@njit(**JIT)
def segment_hits(seg, tab, i, ray, tlo, thi, lo, hi, out, crit, stack):
    """Hits (mm, ascending, in ``(tlo, thi)``) of the ray with segment row ``i`` revolved;
    returns their number (written to ``out``). ``[lo, hi]`` is the ray's part inside the
    segment's revolved box (:func:`ray_box`, which the caller has checked is not empty)."""
    ox, oy, oz, dx, dy, dz = ray
    kind = int(seg[i, S_KIND])
    if kind == LINE:
        n = cone_roots(ray, seg[i, S_R0], seg[i, S_Z0], seg[i, S_R1],
                       seg[i, S_Z1], tlo, out)
    elif kind == OFFSET:
        return offset_roots(seg, tab, i, ray, max(lo, tlo), min(hi, thi), out)
    elif kind == HELIX:
        return helix_roots(seg, i, ray, max(lo, tlo), min(hi, thi), out, MAX_ROOTS)
    else:
        cr, cz, ar, az = seg[i, S_CR], seg[i, S_CZ], seg[i, S_AR], seg[i, S_AZ]
        convex = cr < 0.0 or seg[i, S_RMIN] >= cr - 0.5 * SHEET_SLACK * ar  # no quartic needed
        clear = max(abs(seg[i, S_ZMIN] - cz), abs(seg[i, S_ZMAX] - cz)) <= HOLE_POLE * az  # of the poles
        if convex and abs(cr) >= 1e-9 * ar:  # (a spheroid keeps torus_roots' closed form)
            m = convex_sheet_roots(Ray(ox, oy, oz - cz, dx, dy, dz), abs(cr), ar, az, cr < 0.0, max(tlo, lo),
                                   min(thi, hi), out)
        elif cr >= 1e-9 * ar and clear:  # on the side of its tube facing the axis
            m = hole_sheet_roots(Ray(ox, oy, oz - cz, dx, dy, dz), cr, ar, az, max(tlo, lo), min(thi, hi), out)
        else:
            m = torus_roots(Ray(ox, oy, oz - cz, dx, dy, dz), abs(cr), ar, az, cr < 0.0, max(tlo, lo), out, crit,
                            min(thi, hi))
        n = 0
        side = seg[i, S_SIDE]
        r0, z0 = seg[i, S_R0], seg[i, S_Z0]
        er, ez = seg[i, S_R1] - r0, seg[i, S_Z1] - z0
        # the arc is the part of its ellipse on one side of its chord (S_SIDE); at the chord's
        # ends a slack of 1e-9 of the ellipse's size, as the angle test's 1e-9 of the sweep
        slack = 1e-9 * (ar + az) * hypot2(er, ez)
        for j in range(m):  # keep the roots on the arc, in order
            t = out[j]
            x, y, z = ox + t * dx, oy + t * dy, oz + t * dz
            rho = hypot2(x, y)
            if side != 0.0:
                on_arc = side * (er * (z - z0) - ez * (rho - r0)) >= -slack
            else:
                on_arc = in_sweep(math.atan2((z - cz) / az, (rho - cr) / ar), seg[i, S_A0], seg[i, S_SWEEP])
            if on_arc:
                out[n] = t
                n += 1
    k = 0
    for j in range(n):
        if out[j] < thi:
            out[k] = out[j]
            k += 1
    return k


@njit(**JIT)
def segment_normal(seg, i, px, py, pz, param=np.nan):
    """Outward unit normal (world, ``n = (T_z, -T_r)`` revolved) of segment row ``i`` at the
    point ``p`` (mm) on it; ``param`` is the point's base angle on an offset arc when known
    (:func:`offset_roots`), else ``nan`` (solved for from ``p``)."""
    rho = hypot2(px, py)
    if rho > 0.0:
        ex, ey = px / rho, py / rho
    else:
        ex, ey = 1.0, 0.0
    kind = int(seg[i, S_KIND])
    if kind == HELIX:
        return helix_normal(seg, i, px, py, pz)
    if kind == LINE:
        dr, dz = seg[i, S_R1] - seg[i, S_R0], seg[i, S_Z1] - seg[i, S_Z0]
        L = hypot2(dr, dz)
        nr, nz = dz / L, -dr / L
    elif kind == OFFSET:
        s = param
        if not math.isfinite(s):
            axis = int(seg[i, S_AXIS])
            s = _offset_at(seg, i, axis, pz if axis == 1 else rho)
        _, _, tr, tz = offset_point(seg, i, s)
        nr, nz = tz, -tr
    else:
        ar, az = seg[i, S_AR], seg[i, S_AZ]
        sgn = seg[i, S_DIR]
        nr = sgn * (rho - seg[i, S_CR]) / (ar * ar)
        nz = sgn * (pz - seg[i, S_CZ]) / (az * az)
        h = hypot2(nr, nz)
        nr, nz = nr / h, nz / h
    return nr * ex, nr * ey, nz


@njit(**JIT)
def segment_v(seg, i, px, py, pz):
    """Arc length (mm) along the section from its start to the point on segment row ``i``
    (exact for lines and circle arcs; the parameter fraction of the length otherwise)."""
    rho = hypot2(px, py)
    kind = int(seg[i, S_KIND])
    if kind == LINE:
        return seg[i, S_V0] + hypot2(rho - seg[i, S_R0], pz - seg[i, S_Z0])
    if kind == HELIX:    # the base line's v at that height (the ridge stands off it)
        return helix_v(seg, i, pz)
    if kind == OFFSET:
        axis = int(seg[i, S_AXIS])
        s = _offset_at(seg, i, axis, pz if axis == 1 else rho)
        frac = (s - seg[i, S_A0]) / seg[i, S_SWEEP]
    else:
        ang = math.atan2((pz - seg[i, S_CZ]) / seg[i, S_AZ], (rho - seg[i, S_CR]) / seg[i, S_AR])
        sgn = 1.0 if seg[i, S_SWEEP] >= 0.0 else -1.0
        frac = (((ang - seg[i, S_A0]) * sgn) % TWO_PI) / abs(seg[i, S_SWEEP])
        if frac > 1.0 + 1e-6:
            frac = 0.0
    return seg[i, S_V0] + min(max(frac, 0.0), 1.0) * seg[i, S_LEN]
