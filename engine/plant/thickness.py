"""The glass's thickness along the wall's normal where an outline bottle's wall slopes (issue 41).

Design rule: an outline bottle's cavity section is the outer section's plan offset at the *same
height* (SPEC_outline 5: radii ``(k, c - w)``), not the 3-D offset of the outer surface. On a
vertical wall the two agree; where the wall slopes (a shoulder, a heel) the glass measured along
the surface normal is thinner than the wall ``w``: ``w cos(beta)`` on a straight cone whose
normal leans ``beta`` from the horizontal (``w / sqrt2`` on a 45-degree shoulder). This module
finds where it falls under :data:`THIN_SHARE` of ``w`` and by how much; the plant sheet turns
that into a warning.

The thickness at an outer point ``X = (q, z)`` is its distance to the cavity's surface,

    T(X) = min over z' of sqrt((z - z')^2 + D(q, z')^2),   D = max(sd(q, k(z') P) - t(z'), 0)

with ``z'`` over the inner wall's heights ``[z_ib, z_top]`` (the inner base is the face at
``z_ib``) and ``sd`` the plan's signed distance (:meth:`engine.geometry.plan.PlanOutline.signed_distance`:
exact Euclidean where the rounding ``t >= 0``; near a sharp inner corner, ``t < 0``, the largest
distance to its sides' lines, which errs thin). The minimiser lies within ``T(q, z) <= D(q, z)``
of ``z``: a grid of heights in that window picks the basin, then Brent's method (parabolas
through the three best heights, golden sections where they do not help) finds it to
:data:`XTOL_MM` in height, every point at once, each left alone once it has converged; where
it converged next to a joint of the inner profile (a knee: ``T`` has a kink there, and the
least is the knee itself) the joint is tried too. The thickness, at a smooth minimum, comes out
to rounding; at a knee exact.

Where to look is bounded first. Along a plan direction ``u`` the wall's distance from the axis is
``rho_u(z) = k(z) h(u) + c(z)`` and ``D >= rho_u(z) - rho_u(z') + w``, so by the mean value theorem
``T >= w / sqrt(1 + s^2)``, ``s`` the largest slope ``|h k' + c'|`` within ``w`` of ``z`` (largest
at the plan's least or greatest support ``h``). Heights where that bound keeps
:data:`THIN_SHARE` of ``w`` are not searched; the others are, along each flat's normal (a flat
panel is equally thick along its length), across each arc's and corner's normals every
:data:`FAN_STEP_DEG` and at its farthest point (the steepest). The least over directions per
height marks the thin runs; their ends and their least are found again on finer and finer
grids of height. Directions or heights whose thickness agrees within :data:`TIE` of the wall
(a symmetric plan's equal corners, a cone's equal heights) count as equal: the first in the
probes' order, the lowest height, is taken, so which one is quoted does not hang on rounding.
Units: mm, deg.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..geometry.body import chain_state
from ..geometry.chain import radii_at, radius_at
from ..geometry.validate import body_profile

#: The share of the wall below which the sheet warns. A plant gauges the glass along its normal;
#: a shoulder that keeps 90 % of the drawn wall slopes at most 26 deg from the vertical, and a
#: tenth is within what blowing varies a wall anyway; steeper shoulders lose more than a
#: designer who drew a uniform wall expects.
THIN_SHARE = 0.9
#: Heights a piece between the outer walls' joints where the thickness is looked at.
NODES = 16
#: The largest step (deg) between the plan directions looked at across an arc or a corner.
FAN_STEP_DEG = 10.0
#: Heights a window in ``z'`` is first sampled at (the basin of the least).
GRID = 9
#: Brent's tolerance (mm) on the height ``z'`` of the nearest inner point; at a smooth minimum the
#: thickness is then exact to rounding (its error is the square of this over the wall), at a
#: knee within this of it before the knee itself is tried. Near ``1e-8 z'``, rounding's floor.
XTOL_MM = 3e-8
#: Brent's golden share, ``(3 - sqrt 5) / 2``, and its cap on steps (never met: 40 golden steps
#: shrink a window of the wall to far below :data:`XTOL_MM`).
_CG, BRENT_STEPS = (3.0 - math.sqrt(5.0)) / 2.0, 200
#: Brent's last step under this many tolerances, the parabola refused next: the least is beside it.
CLOSE = 10.0
#: Thicknesses within this share of the wall are equal (module rule): far above rounding (the
#: search's error where the least is smooth or at a knee), far below anything a gauge sees.
TIE = 1e-12
#: A height is better than Brent's best only by more than this share of its value (a few
#: roundings of the squared distance): else steps within rounding of the least wander on.
NOISE = 1e-14
#: Heights a run's end or least is sampled at between two heights, and how often that zooms in
#: for the least (a 1 mm step resolved to 3e-5 mm) and for an end (to 1e-3 mm: it is quoted to
#: 0.1 mm), along the directions :data:`NEAR` thinnest there.
ZOOM, ZOOMS, END_ZOOMS, NEAR = 33, 3, 2, 4


@lru_cache(maxsize=32)
def thin_walls(shape) -> tuple[dict, ...]:
    """The runs of height where the glass is thinner along its normal than :data:`THIN_SHARE`
    of the wall (module rule), lowest first: ``{"z_from_mm", "z_to_mm", "least_mm",
    "at_z_mm", "direction_deg", "share"}`` (``direction_deg`` the plan direction of the outer
    normal there, the bottle's own frame; ``share`` the least over the wall). Empty for a kind
    whose cavity is the 3-D offset of its outer surface (every fixed kind)."""
    if not shape.xs.plan_offset_wall:
        return ()
    wall = _Wall(shape)
    z = wall.heights()
    look = wall.worth_looking(z)
    each = np.full((len(z), len(wall.u[0])), np.inf)  # per height and direction
    if look.any():
        each[look] = wall.thickness(z[look][:, None], wall.p, wall.u)
    least = each.min(axis=1)
    thin = least < THIN_SHARE * wall.w
    found = []  # per run: its ends' and its least's searches, run together (module rule)
    for i, j in _runs(thin):
        def near(a, b):  # the directions thinnest at either height: where the least will be
            return np.unique(_thinnest(each[[a, b]], wall.w)[:, :NEAR].ravel())
        lo = z[0] if i == 0 else wall.crossing(z[i - 1], z[i], near(i - 1, i))
        hi = z[-1] if j == len(z) - 1 else wall.crossing(z[j + 1], z[j], near(j, j + 1))
        m = i + _first_least(least[i:j + 1], wall.w)
        a, b = max(m - 1, 0), min(m + 1, len(z) - 1)
        found.append((lo, hi, wall.refined(z[a], z[b], near(a, b))))
    results = iter(wall.together([g for f in found for g in f if not isinstance(g, float)]))
    runs = []
    for run in found:
        lo, hi, (at, t, psi) = (g if isinstance(g, float) else next(results) for g in run)
        runs.append({"z_from_mm": float(lo), "z_to_mm": float(hi), "least_mm": t, "at_z_mm": at,
                     "direction_deg": math.degrees(psi) % 360.0, "share": t / wall.w})
    return tuple(runs)


def warnings(runs, wall_mm: float) -> list[str]:
    """The sheet's warning (one line) for each run of :func:`thin_walls`."""
    return [f"Sloped wall from z = {r['z_from_mm']:.1f} to {r['z_to_mm']:.1f} mm: the glass is "
            f"{r['least_mm']:.2f} mm thick along its normal (at z = {r['at_z_mm']:.1f} mm), "
            f"{r['share']:.0%} of the {wall_mm:g} mm wall: an outline's cavity keeps the wall "
            f"across the plan, not along the slope" for r in runs]


def _thinnest(t, wall_mm: float) -> np.ndarray:
    """Per row of thicknesses ``t`` (mm), the column indices thinnest first, thicknesses within
    :data:`TIE` of the wall ``wall_mm`` of one another counted equal and taken in column order
    (module rule)."""
    order = np.argsort(t, axis=1, kind="stable")
    ranked = np.take_along_axis(t, order, axis=1)
    gap = np.diff(ranked, axis=1) > TIE * wall_mm  # where a new group of equals starts
    group = np.concatenate([np.zeros((len(t), 1), int), np.cumsum(gap, axis=1)], axis=1)
    key = np.empty_like(group)
    np.put_along_axis(key, order, group, axis=1)
    return np.argsort(key, axis=1, kind="stable")


def _first_least(t, wall_mm: float) -> int:
    """The first index of ``t`` (mm) within :data:`TIE` of the wall ``wall_mm`` of its least."""
    return int(np.argmax(t <= np.min(t) + TIE * wall_mm))


def _runs(mask):
    """``(first, last)`` index of each run of ``True`` in ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0] - 1))


class _Wall:
    """An outline bottle's outer and inner walls, and the plan directions looked along."""

    def __init__(self, shape):
        prof = body_profile(shape)
        self.plan, self.w = shape.plan, shape.wall_thickness
        self.outer = [sp.outer_wall for sp in prof.sections]
        self.inner = [sp.inner_wall for sp in prof.sections]
        self.z_ib, self.z_top = prof.z_ib, prof.z_top
        joints = [p[1] for ch in self.inner for s in ch for p in (s.p0, s.p1)]
        self.knees = np.unique(np.clip(joints, self.z_ib, self.z_top))
        self.p, self.u = _probes(shape.plan)
        # P's least support is the origin's distance to its edge; its farthest point is at 1
        self.h_range = (-float(shape.plan.signed_distance(0.0, 0.0, 1.0, 0.0)[0]), 1.0)

    def heights(self) -> np.ndarray:
        """:data:`NODES` heights (mm) a piece between the outer walls' joints, ends included."""
        joints = np.unique([p[1] for ch in self.outer for s in ch for p in (s.p0, s.p1)])
        u = np.linspace(0.0, 1.0, NODES + 1)[:-1]
        return np.append((joints[:-1, None] + np.diff(joints)[:, None] * u).ravel(), joints[-1])

    def worth_looking(self, z) -> np.ndarray:
        """Where the slope bound (module rule) does not keep :data:`THIN_SHARE` of the wall, or
        the inner base may be nearer than the wall (within ``w`` above it, the share below)."""
        s_max = math.sqrt(1.0 / THIN_SHARE ** 2 - 1.0)
        dense = np.unique(np.concatenate([z, np.linspace(z[0], z[-1], 64 * len(z))]))
        slope = np.zeros(dense.shape)
        for above in (False, True):  # why both: at a joint the wall may turn
            (_, kr, kz), (_, cr, cz) = (chain_state(ch, dense, above) for ch in self.outer)
            with np.errstate(divide="ignore", invalid="ignore"):
                kd, cd = kr / kz, cr / cz  # a horizontal piece (a heel) is infinitely steep
            for h in self.h_range:
                slope = np.maximum(slope, np.nan_to_num(np.abs(h * kd + cd), nan=np.inf))
        reach = 1.05 * self.w  # (a margin for the sampling)
        lo, hi = np.searchsorted(dense, z - 2.0 * reach), np.searchsorted(dense, z + 2.0 * reach, "right")
        steep = np.array([np.max(np.where(np.abs(zi - dense[i:j]) <= reach, slope[i:j], 0.0), initial=0.0)
                          for zi, i, j in zip(z, lo, hi)]) > 0.95 * s_max  # each height's own stretch
        return steep | ((z > self.z_ib - THIN_SHARE * self.w) & (z < self.z_ib + self.w))

    def _outer_points(self, z, p, u):
        k, c = (radius_at(ch, np.clip(z, ch[0].p0[1], ch[-1].p1[1])) for ch in self.outer)
        return k * p[0] + c * u[0], k * p[1] + c * u[1]

    def _f(self, x, y, z, zp):
        """Squared distance (mm^2) from ``(x, y, z)`` to the inner wall's section at ``zp``."""
        k, t = radii_at(self.inner, (zp, zp))
        d = np.maximum(self.plan.distance(x, y, k, t), 0.0)
        return (z - zp) ** 2 + d * d

    def thickness(self, z, p, u):
        """``T`` (mm) at the outer points of heights ``z`` along plan normals ``u`` (broadcast;
        ``p`` the plan's points with those normals): the least of :meth:`_least`."""
        x, y, z = np.broadcast_arrays(*self._outer_points(z, p, u), z)
        shape = z.shape
        x, y, z = (np.ravel(v) for v in (x, y, z))

        def f(rows, zp):
            return self._f(x[rows], y[rows], z[rows], zp)
        z0 = np.clip(z, self.z_ib, self.z_top)
        reach = np.sqrt(self._f(x, y, z, z0))
        return np.sqrt(self._least(f, z, z0, reach)).reshape(shape)

    def _least(self, f, z, z0, reach):
        """The least (mm^2) about each outer height ``z`` (mm; ``z0`` it within the inner wall,
        ``reach`` the distance there) of the function ``f(rows, zp)`` (squared distances, mm^2,
        of the rows ``rows`` at heights ``zp``): a grid in ``z'`` over the reach, the knee in the
        best grid height's two intervals, Brent's method on the smooth side of it, the knee Brent
        ended next to (module rule)."""
        rows = np.arange(len(z))
        lo, hi = np.maximum(z - reach, self.z_ib), np.minimum(z + reach, self.z_top)
        lo, hi = np.minimum(lo, z0), np.maximum(hi, z0)
        grid = lo[:, None] + (hi - lo)[:, None] * np.linspace(0.0, 1.0, GRID)
        fg = f(rows[:, None], grid)
        i = np.argmin(fg, axis=-1)[:, None]
        a, m, b = (np.take_along_axis(grid, j, -1)[:, 0]
                   for j in (np.maximum(i - 1, 0), i, np.minimum(i + 1, GRID - 1)))
        at, best = _brent(f, *self._beside_knee(f, a, b, m, np.take_along_axis(fg, i, -1)[:, 0]))
        knee = self._nearest_knee(at)  # Brent ended within a tolerance of another knee: try it
        rows = np.nonzero(np.abs(knee - at) <= 4.0 * XTOL_MM)[0]
        best[rows] = np.minimum(best[rows], f(rows, knee[rows]))
        return best

    def _beside_knee(self, f, a, b, m, fm):
        """Brent's windows and starts ``(a, b, x, f(x))`` for the windows ``[a, b]`` (mm) whose
        best grid height is ``m`` (``fm`` its value; ``f`` as :func:`_brent`'s): where the knee
        nearest ``m`` lies in the window, it and :data:`XTOL_MM` either side are tried. The least
        of those and ``m`` says where the least lies: the knee itself (a window of one height,
        a kink's minimum found exactly) or the side of it holding that best height, where the
        function is smooth and Brent's parabolas converge fast."""
        knee = self._nearest_knee(m)
        rows = np.nonzero((knee >= a) & (knee <= b))[0]
        if not len(rows):
            return a, b, m, fm
        a, b, m, fm = (v.copy() for v in (a, b, m, fm))
        k = knee[rows]
        tried = np.stack([k, np.maximum(k - XTOL_MM, self.z_ib), np.minimum(k + XTOL_MM, self.z_top), m[rows]],
                         axis=1)
        ft = f(rows[:, None], tried[:, :3])
        ft = np.concatenate([ft, fm[rows, None]], axis=1)
        j = np.argmin(ft, axis=1)  # the knee first among equals
        here = np.arange(len(rows))
        side_below = (j == 1) | ((j == 3) & (m[rows] < k))
        side_above = (j == 2) | ((j == 3) & (m[rows] > k))
        a[rows] = np.where(side_above, tried[:, 2], np.where(side_below, a[rows], k))
        b[rows] = np.where(side_below, tried[:, 1], np.where(side_above, b[rows], k))
        m[rows], fm[rows] = tried[here, j], ft[here, j]
        return a, b, m, fm

    def _nearest_knee(self, zp):
        """The joint of the inner profile (mm; its ends included) nearest each height ``zp``."""
        j = np.searchsorted(self.knees, zp)
        below, above = self.knees[np.maximum(j - 1, 0)], self.knees[np.minimum(j, len(self.knees) - 1)]
        return np.where(zp - below <= above - zp, below, above)

    def together(self, searches) -> list:
        """The results of the generator ``searches`` (:meth:`crossing`, :meth:`refined`), run in
        step: each round one :meth:`thickness` call answers every ``(z, which)`` (heights mm,
        direction indices) they ask with ``(T, psi)``, the least thickness (mm) over ``which`` at
        each height and the plan direction (rad) of its outer normal. Row for row the same
        arithmetic as a call per search (every step of :meth:`thickness` is per row), in fewer,
        larger calls."""
        out, asks = [None] * len(searches), {}
        for n, search in enumerate(searches):
            asks[n] = next(search)
        while asks:
            z = np.concatenate([np.repeat(zz, len(which)) for zz, which in asks.values()])
            pick = np.concatenate([np.tile(which, len(zz)) for zz, which in asks.values()])
            t = self.thickness(z, *((v[0][pick], v[1][pick]) for v in (self.p, self.u)))
            start = 0
            for n, (zz, which) in list(asks.items()):
                rows = t[start:start + len(zz) * len(which)].reshape(len(zz), len(which))
                start += rows.size
                j = _thinnest(rows, self.w)[:, 0]
                answer = rows.min(axis=1), np.arctan2(self.u[1][which][j], self.u[0][which][j])
                try:
                    asks[n] = searches[n].send(answer)
                except StopIteration as done:
                    out[n] = done.value
                    del asks[n]
        return out

    def crossing(self, za: float, zb: float, which):
        """(A search for :meth:`together`.) The height (mm) between ``za`` (thick enough) and
        ``zb`` (thin) where the least thickness passes :data:`THIN_SHARE` of the wall: the first
        thin one of :data:`ZOOM` heights, then again between it and the one before,
        :data:`END_ZOOMS` times."""
        for _ in range(END_ZOOMS):
            z = np.linspace(za, zb, ZOOM)
            t, _ = yield z, which
            i = max(int(np.argmax(t < THIN_SHARE * self.w)), 1)
            za, zb = z[i - 1], z[i]
        return 0.5 * (za + zb)

    def refined(self, za: float, zb: float, which):
        """(A search for :meth:`together`.) ``(z, T, psi)``: the least thickness between heights
        ``za`` and ``zb`` (mm): the least of :data:`ZOOM` heights, then again between its
        neighbours, :data:`ZOOMS` times."""
        for _ in range(ZOOMS):
            z = np.linspace(za, zb, ZOOM)
            t, psi = yield z, which
            i = _first_least(t, self.w)
            za, zb = z[max(i - 1, 0)], z[min(i + 1, ZOOM - 1)]
        return float(z[i]), float(t[i]), float(psi[i])


def _brent(f, a, b, x, fx):
    """Brent's minimisation of every row's function on its window ``[a, b]`` (mm) from ``x`` in
    it (``fx`` its value), all rows in step: ``(x, f(x))`` at the least found, to
    :data:`XTOL_MM`. ``f(rows, zp)`` gives the functions of the rows ``rows`` (indices) at the
    heights ``zp``; a converged row is left alone. Each step is Brent's (Numerical Recipes'
    ``brent``): the parabola through the three best heights ``x, w, v`` where it falls inside
    the window and moves less than half the step before last, else a golden section into the
    larger part; never closer than the tolerance to a height already tried. Two changes for
    rows in step, where the slowest sets the pace: a height counts as better only by more than
    :data:`NOISE`, and a row whose parabola has settled (its last step under :data:`CLOSE`
    tolerances, the next refused) looks one tolerance beside its best toward the window's far
    end, which closes the window in a step or two instead of golden sections creeping back from
    that end."""
    a, b, x, fx = (np.array(q, float) for q in (a, b, x, fx))
    x_out, f_out = x.copy(), fx.copy()
    w, v, fw, fv, d, e = x.copy(), x.copy(), fx.copy(), fx.copy(), np.full(x.shape, np.inf), np.zeros(x.shape)
    live = np.arange(len(x))
    for _ in range(BRENT_STEPS):
        xm, tol = 0.5 * (a + b), XTOL_MM + 1e-12 * np.abs(x)
        done = np.abs(x - xm) <= 2.0 * tol - 0.5 * (b - a)
        if done.any():
            x_out[live[done]], f_out[live[done]] = x[done], fx[done]
            keep = ~done
            live, a, b, x, w, v, fx, fw, fv, d, e, xm, tol = (
                q[keep] for q in (live, a, b, x, w, v, fx, fw, fv, d, e, xm, tol))
            if not len(live):
                break
        r, q = (x - w) * (fx - fv), (x - v) * (fx - fw)
        p, q = (x - v) * q - (x - w) * r, 2.0 * (q - r)
        p, q = np.where(q > 0.0, -p, p), np.abs(q)
        golden = np.where(x >= xm, a - x, b - x)
        with np.errstate(divide="ignore", invalid="ignore"):
            parabola = (np.abs(e) > tol) & (np.abs(p) < np.abs(0.5 * q * e)) & (p > q * (a - x)) & (p < q * (b - x))
            step = p / q
        near_end = (x + step - a < 2.0 * tol) | (b - x - step < 2.0 * tol)
        step = np.where(near_end, np.copysign(tol, xm - x), step)
        # settled (a parabola's small step, the next refused): look just beside it, toward the far
        # end, not a golden section into that end (which would creep back from it at 0.62 a step)
        close = ~parabola & (np.abs(d) < CLOSE * tol)
        e, d = np.where(parabola, d, np.where(close, b - a, golden)), \
            np.where(parabola, step, np.where(close, np.copysign(tol, xm - x), _CG * golden))
        u = x + np.where(np.abs(d) >= tol, d, np.copysign(tol, xm - x))
        fu = f(live, u)
        better = fu < fx - NOISE * fx  # why not by less: rounding's walk would keep one window end far
        a = np.where(better, np.where(u >= x, x, a), np.where(u < x, u, a))
        b = np.where(better, np.where(u >= x, b, x), np.where(u < x, b, u))
        to_w = ~better & ((fu <= fw) | (w == x))
        to_v = ~better & ~to_w & ((fu <= fv) | (v == x) | (v == w))
        v, fv = np.where(better | to_w, w, np.where(to_v, u, v)), np.where(better | to_w, fw, np.where(to_v, fu, fv))
        w, fw = np.where(better, x, np.where(to_w, u, w)), np.where(better, fx, np.where(to_w, fu, fw))
        x, fx = np.where(better, u, x), np.where(better, fu, fx)
    x_out[live], f_out[live] = x, fx
    return x_out, f_out


def _probes(plan):
    """The plan's points and outward normals looked along (normalised): each line's midpoint
    and normal; across each arc's and corner's normal range, every :data:`FAN_STEP_DEG` and
    where its support is largest (its centre's direction, if the range holds it)."""
    points, normals = [], []
    fans = [(s.center, s.radius, s.theta0, s.sweep) for s in plan.segments if s.kind == "arc"]
    fans += [(c.vertex, 0.0, math.atan2(c.n_in[1], c.n_in[0]), c.alpha) for c in plan.corners]
    for s in plan.segments:
        if s.kind == "line":
            points.append((0.5 * (s.p0[0] + s.p1[0]), 0.5 * (s.p0[1] + s.p1[1])))
            normals.append(s.normal)
    for (cx, cy), rho, th0, sweep in fans:
        angles = list(th0 + sweep * np.linspace(0.0, 1.0, max(2, math.ceil(math.degrees(sweep) / FAN_STEP_DEG)) + 1))
        far = (math.atan2(cy, cx) - th0) % (2 * math.pi)
        if math.hypot(cx, cy) > 0 and far <= sweep:
            angles.append(th0 + far)
        points += [(cx + rho * math.cos(a), cy + rho * math.sin(a)) for a in angles]
        normals += [(math.cos(a), math.sin(a)) for a in angles]
    return tuple(np.array(points).T), tuple(np.array(normals).T)
