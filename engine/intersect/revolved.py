"""One entry point for the tracer: rays against any section segment revolved about z.

Design rule: each segment kind is sent to its exact solver (lines to
:func:`~engine.intersect.quadric.ray_cone_hits`, circular and elliptic arcs to
:func:`~engine.intersect.torus.ray_torus_hits` or, with the centre on the axis, to
:func:`~engine.intersect.quadric.ray_spheroid_hits`), and hits are then restricted to the
segment's extent using the segment's own parameterisation. The inner wall of an elliptic arc
(:class:`~engine.segments.OffsetEllipseArc`, a degree-8 surface) has no practical closed form;
it is bracketed numerically along the curve parameter (see :func:`ray_offset_arc_hits`). Normals are analytic and follow the
segment's outward normal ``n = (T_z, -T_r)`` revolved to world space.
"""
from __future__ import annotations

import math

import numpy as np

from ..segments import Arc, EllipseArc, Line, OffsetEllipseArc
from .quadric import EXTENT_SLACK, ray_cone_hits, ray_spheroid_hits
from .torus import ray_torus_hits

TWO_PI = 2.0 * math.pi


def _pad4(hits):
    out = np.full((hits.shape[0], 4), np.nan)
    out[:, : hits.shape[1]] = hits[:, :4]
    return out


def in_sweep(angle, angle0, sweep):
    """True where ``angle`` (rad) lies on the arc from ``angle0`` sweeping ``sweep`` (signed).

    A slack of ``EXTENT_SLACK`` of the sweep at either end lets neighbouring segments
    overlap by a hair rather than leave cracks.
    """
    rel = np.mod((np.asarray(angle) - angle0) * (1.0 if sweep >= 0 else -1.0), TWO_PI)
    slack = EXTENT_SLACK * abs(sweep)
    return (rel <= abs(sweep) + slack) | (rel >= TWO_PI - slack)


def _arc_like_hits(o, d, center, ar, az, angle0, sweep, tmin):
    """Hits on the revolved ellipse ``((r-cr)/ar)^2 + ((z-cz)/az)^2 = 1`` within the sweep."""
    cr, cz = center
    shifted = o - np.array([0.0, 0.0, cz])
    if abs(cr) < 1e-9 * ar:
        hits = _pad4(ray_spheroid_hits(shifted, d, ar, az, tmin=tmin))
        cr = 0.0
    else:
        hits = ray_torus_hits(shifted, d, abs(cr), ar, az, tmin=tmin,
                              sheet="outer" if cr > 0 else "inner")
    pts = o[:, None, :] + hits[..., None] * d[:, None, :]
    rho = np.hypot(pts[..., 0], pts[..., 1])
    ang = np.arctan2((pts[..., 2] - cz) / az, (rho - cr) / ar)
    hits = np.where(in_sweep(ang, angle0, sweep), hits, np.nan)
    hits.sort(axis=1)
    return hits


_OFFSET_SAMPLES = 96
_BISECTIONS = 56


def _bisect(fun, lo, hi, f_lo):
    """Vectorised bisection of ``fun(t)`` on brackets ``[lo, hi]`` with ``fun(lo) = f_lo``."""
    neg_lo = f_lo <= 0.0
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        same = (fun(mid) <= 0.0) == neg_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return 0.5 * (lo + hi)


class _MeridianTrace:
    """A ray's trace in the meridian half-plane: ``rho(s)^2 = rho_min^2 + E (s - s*)^2``.

    Every point of the trace with ``rho > rho_min`` is met twice by the ray (branches
    ``sigma = +-1``: after or before the closest approach to the axis), so residuals are
    written per branch, ``phi = sqrt(E) (z - z*) - sigma dz sqrt(rho^2 - rho_min^2)``;
    both branches agree where ``rho = rho_min``. Rays parallel to the axis
    (``E = 0``) use ``phi = rho - rho_min`` on the single branch ``sigma = +1``.
    """

    def __init__(self, o, d):
        self.o, self.d = o, d
        self.E = d[:, 0] ** 2 + d[:, 1] ** 2
        self.sqE = np.sqrt(self.E)
        self.vertical = self.E == 0.0
        safe = np.where(self.vertical, 1.0, self.E)
        self.s_star = np.where(self.vertical, 0.0, -(o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]) / safe)
        # the perpendicular distance form has no cancellation for far-away origins
        self.rho_min = np.where(self.vertical, np.hypot(o[:, 0], o[:, 1]),
                                np.abs(o[:, 0] * d[:, 1] - o[:, 1] * d[:, 0]) / np.sqrt(safe))
        self.z_star = o[:, 2] + self.s_star * d[:, 2]

    def residual(self, rows, q, sigma):
        """Branch residual at meridian points ``q`` (..., 2) for trace ``rows``."""
        rad = (q[..., 0] - self.rho_min[rows]) * (q[..., 0] + self.rho_min[rows])
        phi = self.sqE[rows] * (q[..., 1] - self.z_star[rows]) \
            - sigma * self.d[rows, 2] * np.sqrt(np.maximum(rad, 0.0))
        return np.where(self.vertical[rows], q[..., 0] - self.rho_min[rows], phi)

    def distance(self, rows, q, sigma):
        """Ray distance ``s`` (mm) of the meridian point ``q`` on branch ``sigma``."""
        dz = self.d[rows, 2]
        steep = np.abs(dz) >= self.sqE[rows]
        rad = np.maximum((q[..., 0] - self.rho_min[rows]) * (q[..., 0] + self.rho_min[rows]), 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            by_z = (q[..., 1] - self.o[rows, 2]) / dz
            by_rho = self.s_star[rows] + sigma * np.sqrt(rad) / self.sqE[rows]
        return np.where(steep, by_z, by_rho)


def ray_offset_arc_hits(origins, directions, seg, tmin=None):
    """Hits (N, 4) of rays with an :class:`OffsetEllipseArc` revolved about z (mm).

    The residual of each trace branch is sampled at 97 values of the curve parameter; each
    sign change (and each crossing of ``rho = rho_min``, where the branches meet) is refined
    by bisection to full precision. Two hits closer together along the curve than 1/96 of
    its parameter range (a ray within a hair of tangency) may be missed as a pair.
    """
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    out = np.full((o.shape[0], 4), np.nan)
    bounds = segment_bounds(seg)
    size = seg.length + bounds[1]
    tmin = 1e-9 * size if tmin is None else float(tmin)
    idx = np.nonzero(rays_touching_bounds(o, d, bounds, tmin=tmin))[0]
    if idx.size == 0:
        return out
    trace = _MeridianTrace(o[idx], d[idx])
    grid = np.linspace(0.0, 1.0, _OFFSET_SAMPLES + 1)
    q_grid = seg.point(grid)
    n = idx.size
    rows = np.arange(n)[:, None]
    valid = (q_grid[None, :, 0] >= trace.rho_min[:, None]) | trace.vertical[:, None]
    # Where the curve crosses rho = rho_min inside a step, find that parameter: both
    # branches meet there, so it closes the brackets on the valid side.
    cross_r, cross_k = np.nonzero(valid[:, :-1] != valid[:, 1:])
    t_edge = np.full((n, _OFFSET_SAMPLES), np.nan)
    if cross_r.size:
        lo, hi = grid[cross_k], grid[cross_k + 1]
        rmin = trace.rho_min[cross_r]
        f_lo = seg.point(lo)[:, 0] - rmin
        t_edge[cross_r, cross_k] = _bisect(lambda t: seg.point(t)[:, 0] - rmin, lo, hi, f_lo)
    found_s, found_r = [], []
    for sigma in (1.0, -1.0):
        phi = trace.residual(rows, q_grid[None], sigma)
        lo = np.where(valid[:, :-1], grid[None, :-1], t_edge)
        hi = np.where(valid[:, 1:], grid[None, 1:], t_edge)
        f_lo = np.where(valid[:, :-1], phi[:, :-1], np.nan)
        f_hi = np.where(valid[:, 1:], phi[:, 1:], np.nan)
        edge_phi = trace.residual(rows, seg.point(np.nan_to_num(t_edge)), sigma)
        f_lo = np.where(valid[:, :-1], f_lo, edge_phi)
        f_hi = np.where(valid[:, 1:], f_hi, edge_phi)
        usable = (valid[:, :-1] | valid[:, 1:]) & ~(trace.vertical[:, None] & (sigma < 0))
        change = usable & ((f_lo <= 0.0) != (f_hi <= 0.0)) & np.isfinite(f_lo) & np.isfinite(f_hi)
        br, bk = np.nonzero(change)
        if br.size == 0:
            continue
        t_root = _bisect(lambda t: trace.residual(br, seg.point(t), sigma),
                         lo[br, bk], hi[br, bk], f_lo[br, bk])
        found_s.append(trace.distance(br, seg.point(t_root), sigma))
        found_r.append(br)
    # A ray along the axis meets a curve end lying on the axis where no residual changes
    # sign (the curve only touches rho = 0 there): add that end point explicitly.
    axis_tol = 1e-9 * size
    on_axis = np.nonzero(trace.vertical & (trace.rho_min <= axis_tol))[0]
    for t_end in (0.0, 1.0):
        q_end = seg.point(np.array([t_end]))
        if on_axis.size and abs(q_end[0, 0]) <= axis_tol:
            found_s.append(trace.distance(on_axis, np.broadcast_to(q_end, (on_axis.size, 2)), 1.0))
            found_r.append(on_axis)
    if found_s:
        s_all, r_all = np.concatenate(found_s), np.concatenate(found_r)
        keep = s_all > tmin
        s_all, r_all = s_all[keep], r_all[keep]
        order = np.lexsort((s_all, r_all))
        s_all, r_all = s_all[order], r_all[order]
        # the same end point may be found twice (by a sign change and by the axis rule)
        twin = np.zeros(s_all.size, bool)
        twin[1:] = (r_all[1:] == r_all[:-1]) & (np.diff(s_all) <= axis_tol)
        s_all, r_all = s_all[~twin], r_all[~twin]
        rank = np.arange(r_all.size) - np.searchsorted(r_all, r_all)
        first4 = rank < 4
        out[idx[r_all[first4]], rank[first4]] = s_all[first4]
    return out


def offset_arc_parameter(meridian_points, seg):
    """Curve parameter ``t`` (M,) of the foot of each meridian point (M, 2) on ``seg``.

    ``seg`` is an :class:`OffsetEllipseArc`; the point lies on the base ellipse's normal at
    its foot, found by Newton on ``(X - P(s)) . P'(s) = 0`` in the ellipse angle ``s``,
    started from the nearest of 97 curve samples.
    """
    X = np.asarray(meridian_points, dtype=float).reshape(-1, 2)
    base = seg.base
    grid = np.linspace(0.0, 1.0, _OFFSET_SAMPLES + 1)
    q = seg.point(grid)
    nearest = np.argmin(((X[:, None, :] - q[None]) ** 2).sum(-1), axis=1)
    ang = base.angle(grid[nearest])
    c = np.array(base.center)
    radii = np.array([base.radius_r, base.radius_z])
    for _ in range(8):
        cs = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
        rel = X - c - radii * cs                                # X - P(s)
        ps = radii * np.stack([-cs[:, 1], cs[:, 0]], axis=-1)   # P'(s)
        h = (rel * ps).sum(-1)
        dh = -(ps * ps).sum(-1) - (rel * radii * cs).sum(-1)    # P''(s) = -(P - c)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(dh != 0.0, h / dh, 0.0)
        ang = ang - np.clip(step, -0.1, 0.1)
    return np.clip((ang - base.angle0) / base.sweep, 0.0, 1.0)


def revolved_hits(origins, directions, seg, tmin=None):
    """Hit distances of rays with ``seg`` (a section segment) revolved about the z axis.

    Parameters
    ----------
    origins, directions : array_like, shape (N, 3)
        Ray origins (mm) and unit directions, world frame (z is the bottle axis).
    seg : Line | Arc | EllipseArc | OffsetEllipseArc
        The meridian segment (mm, ``r >= 0``).
    tmin : float, optional
        Hits at ``t <= tmin`` (mm) are dropped; by default a tiny fraction of the segment's
        own size (1e-6 of a tube radius for arcs, 1e-9 of the size for lines), so a
        secondary ray leaving the surface does not re-hit it at its start.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Hit distances (mm) ascending, NaN-padded, restricted to the segment's extent (for
        arcs: their angular range in their own parameterisation).
    """
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    if isinstance(seg, Line):
        return _pad4(ray_cone_hits(o, d, *seg.p0, *seg.p1, tmin=tmin))
    if isinstance(seg, Arc):
        return _arc_like_hits(o, d, seg.center, seg.radius, seg.radius, seg.angle0, seg.sweep, tmin)
    if isinstance(seg, EllipseArc):
        return _arc_like_hits(o, d, seg.center, seg.radius_r, seg.radius_z, seg.angle0, seg.sweep, tmin)
    if isinstance(seg, OffsetEllipseArc):
        return ray_offset_arc_hits(o, d, seg, tmin=tmin)
    raise TypeError(f"cannot intersect a {type(seg).__name__}")


def _meridian(points):
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    rho = np.hypot(p[:, 0], p[:, 1])
    # On the axis the radial direction is arbitrary; a valid section has n_r = 0 there.
    safe = np.where(rho > 0, rho, 1.0)
    er = np.where(rho[:, None] > 0, p[:, :2] / safe[:, None], np.array([1.0, 0.0]))
    return p, rho, er


def revolved_normals(points, seg):
    """Outward unit normals (N, 3) of ``seg`` revolved, at world ``points`` (mm) on it.

    The meridian normal is the segment's ``n = (T_z, -T_r)`` (outward from the glass for
    an outer wall), computed analytically from the point: constant for a line, radial
    about the centre for an arc (inverted for ``"cw"``), the ellipse gradient for an
    elliptic arc, and the base arc's normal at the foot parameter for an offset arc.
    """
    p, rho, er = _meridian(points)
    z = p[:, 2]
    if isinstance(seg, Line):
        (tr, tz) = seg.tangent(0.0)
        nr, nz = np.full_like(rho, tz), np.full_like(rho, -tr)
    elif isinstance(seg, (Arc, EllipseArc)):
        ar, az = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_r, seg.radius_z)
        sign = 1.0 if seg.direction == "ccw" else -1.0
        nr = sign * (rho - seg.center[0]) / (ar * ar)
        nz = sign * (z - seg.center[1]) / (az * az)
        norm = np.hypot(nr, nz)
        nr, nz = nr / norm, nz / norm
    elif isinstance(seg, OffsetEllipseArc):
        t = offset_arc_parameter(np.column_stack([rho, z]), seg)
        tan = seg.base.tangent(t)
        nr, nz = tan[:, 1], -tan[:, 0]
    else:
        raise TypeError(f"no normals for a {type(seg).__name__}")
    return np.column_stack([nr * er[:, 0], nr * er[:, 1], nz])


def segment_bounds(seg):
    """``(rmin, rmax, zmin, zmax)`` (mm) of ``seg``: a box in (r, z) holding all of it.

    Exact for lines and arcs (end points plus the axis-aligned extreme points inside the
    sweep); for an offset arc, from dense samples widened by the sample spacing.
    """
    if isinstance(seg, Line):
        rs, zs = [seg.p0[0], seg.p1[0]], [seg.p0[1], seg.p1[1]]
    elif isinstance(seg, (Arc, EllipseArc)):
        ar, az = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_r, seg.radius_z)
        cr, cz = seg.center
        rs, zs = [seg.p0[0], seg.p1[0]], [seg.p0[1], seg.p1[1]]
        for k in range(4):
            ang = k * math.pi / 2
            if in_sweep(ang, seg.angle0, seg.sweep):
                rs.append(cr + ar * math.cos(ang))
                zs.append(cz + az * math.sin(ang))
    elif isinstance(seg, OffsetEllipseArc):
        pts = seg.point(np.linspace(0.0, 1.0, 1025))
        pad = float(np.max(np.hypot(*np.diff(pts, axis=0).T)))
        return (max(float(pts[:, 0].min()) - pad, 0.0), float(pts[:, 0].max()) + pad,
                float(pts[:, 1].min()) - pad, float(pts[:, 1].max()) + pad)
    else:
        raise TypeError(f"no bounds for a {type(seg).__name__}")
    return (max(min(rs), 0.0), max(rs), min(zs), max(zs))


def rays_touching_bounds(origins, directions, bounds, tmin=0.0, tmax=np.inf):
    """Mask (N,) of rays whose part ``tmin < t < tmax`` can meet the revolved box ``bounds``.

    ``bounds = (rmin, rmax, zmin, zmax)`` (mm) describes the solid between two cylinders and
    two planes; the test is conservative (never culls a ray that meets it) and is meant to
    skip segments cheaply before calling :func:`revolved_hits`.
    """
    rmin, rmax, zmin, zmax = (float(v) for v in bounds)
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    pad = 1e-9 * (abs(rmax) + abs(zmax) + abs(zmin) + (zmax - zmin))
    zmin, zmax, rmin, rmax = zmin - pad, zmax + pad, max(rmin - pad, 0.0), rmax + pad
    with np.errstate(divide="ignore", invalid="ignore"):
        ta = (zmin - o[:, 2]) / d[:, 2]
        tb = (zmax - o[:, 2]) / d[:, 2]
    flat = d[:, 2] == 0.0
    inside_slab = (o[:, 2] >= zmin) & (o[:, 2] <= zmax)
    lo = np.where(flat, np.where(inside_slab, -np.inf, np.inf), np.minimum(ta, tb))
    hi = np.where(flat, np.where(inside_slab, np.inf, -np.inf), np.maximum(ta, tb))
    lo, hi = np.maximum(lo, tmin), np.minimum(hi, tmax)
    # rho^2 along the ray is a convex quadratic: its minimum on [lo, hi] is at the clamped
    # closest approach to the axis, its maximum at an end of the interval.
    E = d[:, 0] ** 2 + d[:, 1] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        s_axis = np.where(E > 0, -(o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]) / E, 0.0)
    s_near = np.clip(s_axis, lo, hi)

    def rho_at(s):
        with np.errstate(invalid="ignore"):
            x = o[:, 0] + np.where(np.isfinite(s), s, 0.0) * d[:, 0]
            y = o[:, 1] + np.where(np.isfinite(s), s, 0.0) * d[:, 1]
        return np.where(np.isfinite(s) | (E == 0), np.hypot(x, y), np.inf)

    rho_near = rho_at(s_near)
    rho_far = np.maximum(rho_at(lo), rho_at(hi))
    return (lo <= hi) & (rho_near <= rmax) & (rho_far >= rmin)
