"""Z-monotone chains of segments: sub-segments, the parameter at a height, locating heights.

Design rule: pure, vectorised functions of segments (mm) that every derived-geometry module
shares (offsets, validation, bodies, tessellation, capacities). Each is linear in the points it
is asked about plus the segments of the chain: points are grouped by segment once
(:func:`by_segment`), never masked once per segment. Heights outside a chain get index -1 and
NaN; chains may rise or descend in z.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from .segments import Arc, EllipseArc, Line, OffsetEllipseArc, Segment

#: Height tolerance (mm) for "at z = 0" and for snapping clip heights onto joints.
Z_TOL_MM = 1e-6
#: Up to this many heights :func:`radius_at` evaluates every segment's formula at every height
#: (no sort: fastest for the many small calls of a root search); beyond, by segment (less work).
TABLE_POINTS = 8192


def subsegment(seg: Segment, t0: float, t1: float) -> Segment:
    """The part of ``seg`` for parameters ``t0 <= t <= t1`` (0 <= t0 < t1 <= 1), same kind.

    The new segment's parameter maps linearly onto ``[t0, t1]`` of the old one (every kind here is
    parameterised linearly in angle or length), so ``sub.point(s) == seg.point(t0 + s (t1 - t0))``.
    """
    if not (0.0 <= t0 < t1 <= 1.0) or t1 - t0 < 1e-13:
        raise ValueError(f"sub-range [{t0}, {t1}] is not a proper part of [0, 1]")
    if isinstance(seg, OffsetEllipseArc):
        return OffsetEllipseArc(subsegment(seg.base, t0, t1), seg.w)
    p0 = tuple(float(v) for v in seg.point(t0))
    p1 = tuple(float(v) for v in seg.point(t1))
    if isinstance(seg, Line):
        return Line(p0, p1)
    if isinstance(seg, Arc):
        return Arc(seg.center, seg.radius, p0, p1, seg.direction)
    if isinstance(seg, EllipseArc):
        return EllipseArc(seg.center, seg.radius_r, seg.radius_z, p0, p1, seg.direction)
    raise TypeError(f"unknown segment type {type(seg).__name__}")


def param_at_z(seg: Segment, z) -> np.ndarray:
    """Parameter(s) ``t`` where the z-monotone segment ``seg`` is at height ``z`` (mm).

    Exact for lines, arcs and ellipse arcs (inverse trigonometry on the half that the arc lies
    in); a bracketed Newton iteration for offset ellipse arcs. ``z`` outside the segment's range
    gives the nearer end. The segment must be monotone in z (wall and base parts are).
    """
    z = np.asarray(z, dtype=float)
    z0, z1 = seg.p0[1], seg.p1[1]
    if isinstance(seg, Line):
        return np.zeros_like(z) if z1 == z0 else np.clip((z - z0) / (z1 - z0), 0.0, 1.0)
    if isinstance(seg, (Arc, EllipseArc)):
        rz = seg.radius if isinstance(seg, Arc) else seg.radius_z
        s = np.arcsin(np.clip((z - seg.center[1]) / rz, -1.0, 1.0))
        mid = float(seg.angle(0.5))
        if math.cos(mid) < 0.0:  # the arc lies on the half nearer the axis
            s = math.pi - s
        d = np.mod((s - seg.angle0) * math.copysign(1.0, seg.sweep) + math.pi, 2 * math.pi) - math.pi
        return np.clip(d / abs(seg.sweep), 0.0, 1.0)  # angle past the start, as a fraction
    if isinstance(seg, OffsetEllipseArc):
        return _offset_param_at_z(seg, z)
    raise TypeError(f"unknown segment type {type(seg).__name__}")


def _offset_param_at_z(seg: OffsetEllipseArc, z) -> np.ndarray:
    """Bracketed Newton solve of ``z(t) = z`` on an offset ellipse arc (monotone in z)."""
    b = seg.base
    zlo, zhi = seg.p0[1], seg.p1[1]
    sign = 1.0 if zhi >= zlo else -1.0
    target = sign * np.clip(z, min(zlo, zhi), max(zlo, zhi))
    lo, hi = np.zeros_like(target), np.ones_like(target)
    t = np.clip((target - sign * zlo) / max(abs(zhi - zlo), 1e-300), 0.0, 1.0)
    for _ in range(60):
        f = sign * seg.point(t)[..., 1] - target
        done = np.abs(f) <= 1e-12 * max(1.0, abs(zhi), abs(zlo))
        if np.all(done):
            return t
        lo = np.where(f < 0, t, lo)
        hi = np.where(f > 0, t, hi)
        s = b.angle(t)
        speed = abs(b.sweep) * np.hypot(b.radius_r * np.sin(s), b.radius_z * np.cos(s))
        dzdt = sign * speed * (1.0 - seg.w * b.curvature(t)) * b.tangent(t)[..., 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            t_new = t - f / dzdt
        bad = ~np.isfinite(t_new) | (t_new < lo) | (t_new > hi)
        t_new = np.where(done, t, np.where(bad, 0.5 * (lo + hi), t_new))
        if np.all(np.abs(t_new - t) < 1e-16):
            return t_new
        t = t_new
    return t


def by_segment(idx):
    """``(i, positions)`` for each distinct value ``i`` of the integer array ``idx``, where
    ``positions`` index ``idx.ravel()``: one sort, so the loops that evaluate each segment on its
    own points stay linear in points plus segments (a mask per segment would be their product)."""
    flat = np.ravel(idx)
    order = np.argsort(flat, kind="stable")
    cuts = np.flatnonzero(np.diff(flat[order])) + 1
    for part in np.split(order, cuts):
        if len(part):
            yield int(flat[part[0]]), part


def locate(segments, z):
    """``(index, t)`` shaped like ``z``: segment holding height ``z`` (mm) and its parameter, on a
    chain rising or descending in z; heights outside its range get index -1 and ``t = nan``."""
    z = np.asarray(z, dtype=float)
    idx = _holding(segments, z)
    t = np.full(z.shape, np.nan)
    t_flat, z_flat = t.reshape(-1), z.reshape(-1)
    for i, part in by_segment(idx):
        if i >= 0:
            t_flat[part] = param_at_z(segments[i], z_flat[part])
    return idx, t


def _holding(segments, z) -> np.ndarray:
    """The index of the segment holding each height ``z`` (mm; an array), -1 outside the chain's
    range (beyond :data:`Z_TOL_MM`); at a joint the lower segment of a rising chain."""
    try:
        bounds = _bounds(tuple(segments))
    except TypeError:  # unhashable segments: none of the kinds here
        bounds = _bounds.__wrapped__(tuple(segments))
    return _held(bounds, z)


def _held(bounds, z, first: int = 0) -> np.ndarray:
    """:func:`_holding` from a chain's :func:`_bounds`, its indices counted from ``first``."""
    tops, rising, z_lo, z_hi = bounds
    last = len(tops) - 1
    pos = np.minimum(np.searchsorted(tops, z, side="left"), last)
    idx = first + pos if rising else first + last - pos
    return np.where((z < z_lo - Z_TOL_MM) | (z > z_hi + Z_TOL_MM), -1, idx)


@lru_cache(maxsize=256)
def _bounds(segments):
    """``(tops, rising, z_lo, z_hi)`` of a chain for :func:`_holding` (cached: a root search
    asks one chain again and again): each segment's top (mm) from the chain's lowest segment up,
    whether the chain rises, and its height range (mm)."""
    n = len(segments)
    rising = segments[-1].p1[1] >= segments[0].p0[1]
    order = range(n) if rising else range(n - 1, -1, -1)
    tops = np.array([max(segments[i].p0[1], segments[i].p1[1]) for i in order])
    z_lo, z_hi = sorted((segments[0].p0[1], segments[-1].p1[1]))
    return tops, rising, z_lo, z_hi


def radius_at(segments, z) -> np.ndarray:
    """Radius r(z) (mm) of a z-monotone chain of segments at heights ``z`` (mm), vectorised;
    ``nan`` outside the chain's z range. Exact up to rounding (see :func:`param_at_z`). A chain
    of lines, arcs and ellipse arcs is evaluated from a table of its segments
    (:func:`_radius_table`) with no loop or sort over them: the same operations on the same
    numbers as :func:`param_at_z` and each segment's ``point``, so the same radii bit for bit."""
    return radii_at((segments,), (z,))[0]


def radii_at(chains, zs) -> list:
    """``[radius_at(chain, z) for chain, z in zip(chains, zs)]`` (mm; the heights ``zs`` of one
    shape), in one pass over one table of every chain's segments: the same radii bit for bit, at
    the cost of one call (a root search asks a section's two or three chains again and again)."""
    zs = [np.asarray(z, dtype=float) for z in zs]
    tables = None
    if max(z.size for z in zs) <= TABLE_POINTS:
        try:
            tables = _radius_tables(tuple(ch if isinstance(ch, tuple) else tuple(ch) for ch in chains))
        except TypeError:  # unhashable segments: none of the kinds here
            pass
    if tables is None:
        return [_radius_by_segment(ch, z) for ch, z in zip(chains, zs)]
    (cols, has_line, has_arc), held = tables
    if len(zs) == 1:
        z, idx = zs[0], _held(held[0][0], zs[0])
    else:
        z, idx = np.stack(zs), np.stack([_held(b, zc, first) for (b, first), zc in zip(held, zs)])
    line, z0, dz, r0, dr, cz, rz, flip, a0, sign, sweep, cr, rr = cols[:, np.maximum(idx, 0)]
    with np.errstate(divide="ignore", invalid="ignore"):
        if has_line:
            r_line = r0 + np.where(dz != 0, np.clip((z - z0) / dz, 0.0, 1.0), 0.0) * dr
        if has_arc:
            s = np.arcsin(np.clip((z - cz) / rz, -1.0, 1.0))
            s = np.where(flip != 0, math.pi - s, s)
            d = np.fmod((s - a0) * sign + math.pi, 2 * math.pi)  # then + 2 pi where < 0: np.mod's value
            d = np.where(d < 0, d + 2 * math.pi, d) - math.pi
            r_arc = cr + rr * np.cos(a0 + np.clip(d / np.abs(sweep), 0.0, 1.0) * sweep)
    # a chain of lines alone (or arcs alone) skips the other kind's formula, which every height drops
    r = np.where(idx < 0, np.nan, r_arc if not has_line else r_line if not has_arc else
                 np.where(line != 0, r_line, r_arc))
    return [r] if len(zs) == 1 else [r[i] for i in range(len(zs))]


@lru_cache(maxsize=256)
def _radius_tables(chains):
    """``(table, held)`` of chains of lines, arcs and ellipse arcs: :func:`_radius_table` of all
    their segments in turn, and per chain its :func:`_bounds` and the column its first segment
    has there; ``None`` if a chain has other kinds."""
    table = _radius_table(tuple(seg for ch in chains for seg in ch))
    if table is None:
        return None
    firsts = np.cumsum([0] + [len(ch) for ch in chains[:-1]])
    return table, tuple((_bounds(ch), int(first)) for ch, first in zip(chains, firsts))


@lru_cache(maxsize=256)
def _radius_table(segments):
    """``(columns, has_line, has_arc)`` of a chain of lines, arcs and ellipse arcs: per segment
    a column, whether a line (1), its ``z0``, ``z1 - z0``, ``r0``, ``r1 - r0`` (a line's), and an
    arc's centre height, radius in z, whether it lies on the half nearer the axis (1), start
    angle, direction (+-1), sweep, centre radius and radius in r (:func:`param_at_z`, ``point``);
    and whether the chain has lines, arcs. ``None`` for a chain of other kinds."""
    rows = []
    for seg in segments:
        if isinstance(seg, Line):
            rows.append((True, seg.p0[1], seg.p1[1] - seg.p0[1], seg.p0[0], seg.p1[0] - seg.p0[0],
                         0.0, 1.0, False, 0.0, 1.0, 1.0, 0.0, 0.0))
        elif isinstance(seg, (Arc, EllipseArc)):
            rz, rr = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_z, seg.radius_r)
            rows.append((False, 0.0, 0.0, 0.0, 0.0, seg.center[1], rz, math.cos(float(seg.angle(0.5))) < 0.0,
                         seg.angle0, math.copysign(1.0, seg.sweep), seg.sweep, seg.center[0], rr))
        else:
            return None
    cols = np.array(rows, float).T
    return cols, bool(cols[0].any()), not bool(cols[0].all())


def _radius_by_segment(segments, z) -> np.ndarray:
    """:func:`radius_at` for any chain: the heights grouped by segment, each segment's own
    :func:`param_at_z` and ``point``."""
    r = np.full(z.shape, np.nan)
    r_flat, z_flat = r.reshape(-1), z.reshape(-1)
    for i, part in by_segment(_holding(segments, z)):
        if i >= 0:
            r_flat[part] = segments[i].point(param_at_z(segments[i], z_flat[part]))[..., 0]
    return r


def z_breaks(chains, z_lo, z_hi, extra=()) -> np.ndarray:
    """Heights (mm) where any chain has a joint, and the ``extra`` heights, within
    ``z_lo .. z_hi`` (both included; heights closer than 1e-6 mm merge)."""
    zs = [z_lo, z_hi, *extra] + [p[1] for c in chains for s in c for p in (s.p0, s.p1)]
    z = np.unique(np.clip(np.round(zs, 9), z_lo, z_hi))
    return z[np.concatenate([[True], np.diff(z) > 1e-6])]


def segment_between(chain, za: float, zb: float) -> Segment:
    """The part of the z-rising ``chain`` between heights ``za < zb`` (mm), which must lie
    within one of its segments (cut the chain at its joints first: :func:`z_breaks`)."""
    seg = chain[int(locate(chain, np.array([0.5 * (za + zb)]))[0][0])]
    t0, t1 = (float(param_at_z(seg, z)) for z in (za, zb))
    return seg if (t0 <= 1e-12 and t1 >= 1.0 - 1e-12) else subsegment(seg, t0, t1)
