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
of ``z``: a grid of heights in that window, then golden sections, gives it to about 1e-6 mm in height (the thickness, at its minimum, to rounding).

Where to look is bounded first. Along a plan direction ``u`` the wall's distance from the axis is
``rho_u(z) = k(z) h(u) + c(z)`` and ``D >= rho_u(z) - rho_u(z') + w``, so by the mean value theorem
``T >= w / sqrt(1 + s^2)``, ``s`` the largest slope ``|h k' + c'|`` within ``w`` of ``z`` (largest
at the plan's least or greatest support ``h``). Heights where that bound keeps
:data:`THIN_SHARE` of ``w`` are not searched; the others are, along each flat's normal (a flat
panel is equally thick along its length), across each arc's and corner's normals every
:data:`FAN_STEP_DEG` and at its farthest point (the steepest). The least over directions per
height marks the thin runs; their ends and their least are found again on finer and finer
grids of height. Units: mm, deg.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..geometry.body import chain_state
from ..geometry.chain import radius_at
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
#: Heights a window in ``z'`` is first sampled at, and the golden sections after (to 1e-6 mm).
GRID, GOLDEN = 9, 28
#: Heights a run's end or least is sampled at between two heights, and how often that zooms in
#: for the least (a 1 mm step resolved to 3e-5 mm) and for an end (to 1e-3 mm: it is quoted to
#: 0.1 mm), along the directions :data:`NEAR` thinnest there.
ZOOM, ZOOMS, END_ZOOMS, NEAR = 33, 3, 2, 4
_G = (math.sqrt(5.0) - 1.0) / 2.0


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
            return np.unique(np.argsort(each[[a, b]], axis=1)[:, :NEAR].ravel())
        lo = z[0] if i == 0 else wall.crossing(z[i - 1], z[i], near(i - 1, i))
        hi = z[-1] if j == len(z) - 1 else wall.crossing(z[j + 1], z[j], near(j, j + 1))
        m = i + int(np.argmin(least[i:j + 1]))
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
        near = np.abs(z[:, None] - dense[None, :]) <= 1.05 * self.w  # (a margin for the sampling)
        steep = np.max(np.where(near, slope[None, :], 0.0), axis=1) > 0.95 * s_max
        return steep | ((z > self.z_ib - THIN_SHARE * self.w) & (z < self.z_ib + self.w))

    def _outer_points(self, z, p, u):
        k, c = (radius_at(ch, np.clip(z, ch[0].p0[1], ch[-1].p1[1])) for ch in self.outer)
        return k * p[0] + c * u[0], k * p[1] + c * u[1]

    def _f(self, x, y, z, zp):
        """Squared distance (mm^2) from ``(x, y, z)`` to the inner wall's section at ``zp``."""
        k, t = (radius_at(ch, zp) for ch in self.inner)
        d = np.maximum(self.plan.distance(x, y, k, t), 0.0)
        return (z - zp) ** 2 + d * d

    def thickness(self, z, p, u):
        """``T`` (mm) at the outer points of heights ``z`` along plan normals ``u`` (broadcast;
        ``p`` the plan's points with those normals), by a grid and golden sections in ``z'``."""
        x, y = self._outer_points(z, p, u)
        x, y, z = np.broadcast_arrays(x, y, z)
        z0 = np.clip(z, self.z_ib, self.z_top)
        reach = np.sqrt(self._f(x, y, z, z0))
        lo, hi = np.maximum(z - reach, self.z_ib), np.minimum(z + reach, self.z_top)
        lo, hi = np.minimum(lo, z0), np.maximum(hi, z0)
        grid = lo[..., None] + (hi - lo)[..., None] * np.linspace(0.0, 1.0, GRID)
        f = self._f(x[..., None], y[..., None], z[..., None], grid)
        i = np.argmin(f, axis=-1)[..., None]
        a = np.take_along_axis(grid, np.maximum(i - 1, 0), -1)[..., 0]
        b = np.take_along_axis(grid, np.minimum(i + 1, GRID - 1), -1)[..., 0]
        m1, m2 = b - _G * (b - a), a + _G * (b - a)
        f1, f2 = self._f(x, y, z, m1), self._f(x, y, z, m2)
        for _ in range(GOLDEN):  # one new height an iteration: the kept one is the golden cut
            left = f1 <= f2
            a, b = np.where(left, a, m1), np.where(left, m2, b)
            m1, m2, f2 = np.where(left, b - _G * (b - a), m2), np.where(left, m1, a + _G * (b - a)), \
                np.where(left, f1, f2)
            new = self._f(x, y, z, np.where(left, m1, m2))
            f1, f2 = np.where(left, new, f2), np.where(left, f2, new)
        best = np.minimum(np.minimum(f1, f2), np.min(f, axis=-1))
        return np.sqrt(best)

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
                j = np.argmin(rows, axis=1)
                answer = rows[np.arange(len(zz)), j], np.arctan2(self.u[1][which][j], self.u[0][which][j])
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
            i = int(np.argmin(t))
            za, zb = z[max(i - 1, 0)], z[min(i + 1, ZOOM - 1)]
        return float(z[i]), float(t[i]), float(psi[i])


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
