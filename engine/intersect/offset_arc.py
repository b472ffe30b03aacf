"""Rays against the inner wall of an elliptic arc (an :class:`OffsetEllipseArc`) revolved about z.

Design rule: the offset of an ellipse is a degree-8 curve with no practical closed-form
intersection, so hits are bracketed along the curve's own parameter ``t`` and refined to full
precision. A ray's trace in the meridian half-plane is a hyperbola branch pair met twice per
point (before and after the ray's closest approach to the axis); each branch gets its own
residual, both meet where ``rho = rho_min``. Pairs of hits that could hide inside one sample
step (dips of the residual, the branches' meeting point, extrema of the curve) are searched
explicitly, so only rays within a hair of tangency can lose a pair. Units: mm.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from .quadric import rays_touching_bounds

_OFFSET_SAMPLES = 64
_MAX_REFINE = 60
_EDGE_SUBSAMPLES = 8


def _offset_curve(seg):
    """Fast evaluator ``t -> (..., 2)`` of an offset arc's meridian points (mm).

    Same formula as ``OffsetEllipseArc.point`` (``P(s) - w n(s)`` on the base ellipse), written
    with a handful of array operations because it sits inside the root-refinement loop.
    """
    base = seg.base
    cr, cz = base.center
    ar, az = base.radius_r, base.radius_z
    a0, sweep, w = base.angle0, base.sweep, seg.w
    sign = 1.0 if base.direction == "ccw" else -1.0

    def point(t):
        s = a0 + np.asarray(t, dtype=float) * sweep
        c, sn = np.cos(s), np.sin(s)
        nr, nz = az * c, ar * sn  # outward normal of a ccw arc, unnormalised
        scale = sign * w / np.hypot(nr, nz)
        return np.stack([cr + ar * c - scale * nr, cz + az * sn - scale * nz], axis=-1)

    return point


def _refine(fun, lo, hi, f_lo, f_hi):
    """Vectorised Illinois (false position) on brackets ``[lo, hi]`` of opposite signs.

    Converges superlinearly; stops per bracket when it is 4 ulps wide or the value is 0.
    """
    lo, hi, f_lo, f_hi = (np.array(v, dtype=float) for v in (lo, hi, f_lo, f_hi))
    out = np.empty(lo.shape)
    slot = np.arange(lo.size)
    last = np.zeros(lo.size)
    for _ in range(_MAX_REFINE):
        with np.errstate(invalid="ignore", divide="ignore"):
            x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        x = np.where((x > lo) & (x < hi), x, 0.5 * (lo + hi))
        fx = fun(x, slot)
        move_lo = (fx <= 0.0) == (f_lo <= 0.0)
        f_hi = np.where(move_lo & (last > 0), 0.5 * f_hi, f_hi)
        f_lo = np.where(~move_lo & (last < 0), 0.5 * f_lo, f_lo)
        lo, f_lo = np.where(move_lo, x, lo), np.where(move_lo, fx, f_lo)
        hi, f_hi = np.where(move_lo, hi, x), np.where(move_lo, f_hi, fx)
        last = np.where(move_lo, 1.0, -1.0)
        done = (fx == 0.0) | (hi - lo <= 4e-16 * np.maximum(np.abs(lo), np.abs(hi)) + 1e-300)
        out[slot[done]] = x[done]
        keep = ~done
        if not keep.any():
            return out
        slot, lo, hi, f_lo, f_hi, last = (v[keep] for v in (slot, lo, hi, f_lo, f_hi, last))
    out[slot] = 0.5 * (lo + hi)
    return out


_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def _split_at_extremum(fun, r, lo, hi, sgn):
    """Golden-section search of the extremum of ``fun`` on ``[lo, hi]`` for rows ``r``.

    ``sgn`` is the sign ``fun`` has at both ends. Where the extremum has crossed zero, the
    two halves are brackets; returns ``(rows, lo, hi, f_lo, f_hi)`` with two entries per pair.
    """
    a, b = lo.copy(), hi.copy()
    x1, x2 = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    f1, f2 = sgn * fun(x1, r), sgn * fun(x2, r)
    for _ in range(40):
        left = f1 < f2
        b = np.where(left, x2, b)
        a = np.where(left, a, x1)
        x2n = np.where(left, x1, a + _GOLDEN * (b - a))
        x1n = np.where(left, b - _GOLDEN * (b - a), x2)
        fnew = sgn * fun(np.where(left, x1n, x2n), r)
        f2, f1 = np.where(left, f1, fnew), np.where(left, fnew, f2)
        x1, x2 = x1n, x2n
    tm = 0.5 * (x1 + x2)
    fm = fun(tm, r)
    crossed = np.sign(fm) == -sgn
    r, lo, hi, tm, fm = r[crossed], lo[crossed], hi[crossed], tm[crossed], fm[crossed]
    f_left, f_right = fun(lo, r), fun(hi, r)
    return (np.concatenate([r, r]), np.concatenate([lo, tm]), np.concatenate([tm, hi]),
            np.concatenate([f_left, fm]), np.concatenate([fm, f_right]))


def _dip_candidates(phi, grid):
    """Rows and search intervals where sampled ``phi`` (n, K+1) may dip across zero unseen.

    A sample nearer zero than both neighbours (ends and samples next to an undefined one:
    than their one neighbour) whose value is
    within a quarter of the neighbours' differences: for a parabola whose vertex crossed zero
    between samples the centre value is at most an eighth of them.
    """
    a = np.column_stack([np.full(len(phi), np.nan), phi[:, :-1]])
    c = np.column_stack([phi[:, 1:], np.full(len(phi), np.nan)])
    b = phi
    # next to the branches' meeting point the residual behaves like a square root, not a
    # parabola: those samples are searched whenever they are nearer zero than the neighbour
    at_edge = np.zeros(phi.shape, bool)
    at_edge[:, 1:] |= np.isnan(phi[:, :-1])
    at_edge[:, :-1] |= np.isnan(phi[:, 1:])
    # the search stays inside the branch's domain and the curve: an end, or a neighbour
    # where the residual is undefined, is compared through the other neighbour only
    has_a, has_c = ~np.isnan(a), ~np.isnan(c)
    a, c = np.where(has_a, a, c), np.where(has_c, c, a)
    with np.errstate(invalid="ignore"):
        same = (np.sign(a) == np.sign(b)) & (np.sign(c) == np.sign(b)) & (b != 0.0)
        cand = same & (np.abs(b) <= np.abs(a)) & (np.abs(b) <= np.abs(c)) \
            & ((np.abs(b) <= 0.25 * (np.abs(a - b) + np.abs(c - b))) | at_edge)
    r, k = np.nonzero(cand)
    lo = grid[np.where(has_a[r, k], k - 1, k)]
    hi = grid[np.where(has_c[r, k], k + 1, k)]
    return r, lo, hi, np.sign(b[r, k])


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


@functools.lru_cache(maxsize=256)
def _offset_grid(seg):
    """Sample parameters for an offset arc: a uniform grid plus every extremum of r and z.

    A ray meets the curve twice within one step only near tangency, or where the curve
    pokes past the ray's closest approach to the axis (a local maximum of r) or past its
    height (a local extremum of z); putting those extrema on the grid leaves only true
    near-tangent pairs between samples.
    """
    curve = _offset_curve(seg)
    fine = np.linspace(0.0, 1.0, 4097)
    q = curve(fine)
    extra = []
    for axis in (0, 1):
        v = q[:, axis]
        inner = np.nonzero(((v[1:-1] - v[:-2]) * (v[2:] - v[1:-1])) <= 0.0)[0] + 1
        for i in inner:
            lo, hi = fine[i - 1], fine[i + 1]
            sgn = 1.0 if v[i] >= v[i - 1] else -1.0  # maximise where it rose into i
            for _ in range(60):
                m1, m2 = hi - _GOLDEN * (hi - lo), lo + _GOLDEN * (hi - lo)
                if sgn * curve(m1)[axis] > sgn * curve(m2)[axis]:
                    hi = m2
                else:
                    lo = m1
            extra.append(0.5 * (lo + hi))
    return np.unique(np.concatenate([np.linspace(0.0, 1.0, _OFFSET_SAMPLES + 1), extra]))


def ray_offset_arc_hits(origins, directions, seg, tmin=None):
    """Hits (N, 4) of rays with an :class:`OffsetEllipseArc` revolved about z (mm).

    The residual of each trace branch is sampled at 65 values of the curve parameter; each
    sign change (and each crossing of ``rho = rho_min``, where the branches meet) is refined
    by Illinois false position to full precision. Two hits closer together along the curve than 1/64 of
    its parameter range (a ray within a hair of tangency) may be missed as a pair.
    """
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    out = np.full((o.shape[0], 4), np.nan)
    bounds = offset_arc_bounds(seg)
    size = seg.length + bounds[1]
    tmin = 1e-9 * size if tmin is None else float(tmin)
    idx = np.nonzero(rays_touching_bounds(o, d, bounds, tmin=tmin))[0]
    if idx.size == 0:
        return out
    trace = _MeridianTrace(o[idx], d[idx])
    curve = _offset_curve(seg)
    grid = _offset_grid(seg)
    q_grid = curve(grid)
    n = idx.size
    rows = np.arange(n)[:, None]
    valid = (q_grid[None, :, 0] >= trace.rho_min[:, None]) | trace.vertical[:, None]
    # Where the curve crosses rho = rho_min inside a step, find that parameter: both
    # branches meet there, so it closes the brackets on the valid side.
    cross_r, cross_k = np.nonzero(valid[:, :-1] != valid[:, 1:])
    t_edge = np.full((n, grid.size - 1), np.nan)
    if cross_r.size:
        lo, hi = grid[cross_k], grid[cross_k + 1]
        rmin = trace.rho_min[cross_r]
        t_edge[cross_r, cross_k] = _refine(lambda t, k: curve(t)[:, 0] - rmin[k], lo, hi,
                                           curve(lo)[:, 0] - rmin, curve(hi)[:, 0] - rmin)
    found_s, found_r = [], []
    for sigma in (1.0, -1.0):
        phi = trace.residual(rows, q_grid[None], sigma)
        lo = np.where(valid[:, :-1], grid[None, :-1], t_edge)
        hi = np.where(valid[:, 1:], grid[None, 1:], t_edge)
        f_lo = np.where(valid[:, :-1], phi[:, :-1], np.nan)
        f_hi = np.where(valid[:, 1:], phi[:, 1:], np.nan)
        edge_phi = np.full(t_edge.shape, np.nan)
        if cross_r.size:
            edge_phi[cross_r, cross_k] = trace.residual(cross_r, curve(t_edge[cross_r, cross_k]), sigma)
        f_lo = np.where(valid[:, :-1], f_lo, edge_phi)
        f_hi = np.where(valid[:, 1:], f_hi, edge_phi)
        usable = (valid[:, :-1] | valid[:, 1:]) & ~(trace.vertical[:, None] & (sigma < 0))
        change = usable & ((f_lo <= 0.0) != (f_hi <= 0.0)) & np.isfinite(f_lo) & np.isfinite(f_hi)
        br, bk = np.nonzero(change)
        b_lo, b_hi, b_flo, b_fhi = lo[br, bk], hi[br, bk], f_lo[br, bk], f_hi[br, bk]
        # Pairs of roots hidden inside one step: dips of the sampled residual, and steps
        # closed by the branch meeting point (near the ray's closest approach to the axis).
        dr, dlo, dhi, dsg = _dip_candidates(np.where(valid, phi, np.nan), grid)
        er, ek = np.nonzero(usable & ~change & (valid[:, :-1] != valid[:, 1:])
                            & np.isfinite(f_lo) & np.isfinite(f_hi))
        if er.size:
            # Near the meeting point the residual varies like sqrt(t - t_edge): resample
            # those steps uniformly in sqrt(t - t_edge) and bracket every sign change.
            t_e = t_edge[er, ek]
            t_v = np.where(valid[er, ek], lo[er, ek], hi[er, ek])
            frac = (np.arange(_EDGE_SUBSAMPLES + 1) / _EDGE_SUBSAMPLES) ** 2
            t_sub = t_e[:, None] + (t_v - t_e)[:, None] * frac[None, :]
            f_sub = trace.residual(er[:, None], curve(t_sub), sigma)
            cr_, ck_ = np.nonzero((f_sub[:, :-1] <= 0.0) != (f_sub[:, 1:] <= 0.0))
            br = np.concatenate([br, er[cr_]])
            a_t, b_t = t_sub[cr_, ck_], t_sub[cr_, ck_ + 1]
            b_lo = np.concatenate([b_lo, np.minimum(a_t, b_t)])
            b_hi = np.concatenate([b_hi, np.maximum(a_t, b_t)])
            fa, fb = f_sub[cr_, ck_], f_sub[cr_, ck_ + 1]
            b_flo = np.concatenate([b_flo, np.where(a_t < b_t, fa, fb)])
            b_fhi = np.concatenate([b_fhi, np.where(a_t < b_t, fb, fa)])
        live = ~(trace.vertical[dr] & (sigma < 0)) & (dsg != 0)
        if live.any():
            pairs = _split_at_extremum(lambda t, k: trace.residual(k, curve(t), sigma),
                                       dr[live], dlo[live], dhi[live], dsg[live])
            br = np.concatenate([br, pairs[0]])
            b_lo, b_hi, b_flo, b_fhi = (np.concatenate([v, w]) for v, w in
                                        zip((b_lo, b_hi, b_flo, b_fhi), pairs[1:]))
        if br.size == 0:
            continue
        t_root = _refine(lambda t, k: trace.residual(br[k], curve(t), sigma), b_lo, b_hi, b_flo, b_fhi)
        found_s.append(trace.distance(br, curve(t_root), sigma))
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
    started from the nearest of 65 curve samples.
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


def offset_arc_bounds(seg):
    """``(rmin, rmax, zmin, zmax)`` (mm) holding the offset arc ``seg``.

    From 1025 samples, widened by the largest sample spacing (a bound on how far the curve
    can bulge between samples), so the box always contains the curve.
    """
    pts = _offset_curve(seg)(np.linspace(0.0, 1.0, 1025))
    pad = float(np.max(np.hypot(*np.diff(pts, axis=0).T)))
    return (max(float(pts[:, 0].min()) - pad, 0.0), float(pts[:, 0].max()) + pad,
            float(pts[:, 1].min()) - pad, float(pts[:, 1].max()) + pad)
