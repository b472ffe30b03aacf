"""Wall curves of a section as functions of height: r(z) and dr/dz, for exact normals.

Design rule: a :class:`WallCurve` is a chain of segment pieces ``(segment, t0, t1)`` whose
height ``z`` strictly increases with ``t`` (SPEC 4.1 rule 4), so the curve is the graph of a
radius ``r(z)``. The outer wall is the section's segments 1..n; the inner wall is their inward
offsets by the wall thickness (``Segment.offset``: lines, concentric arcs, exact ellipse
offsets) clipped below at the inner base ``z_ib``. Units: mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import WallError

_TABLE = 2049  # samples per piece of the t(z) table: one Newton step then reaches ~1e-12 mm


@dataclass(frozen=True, eq=False)
class WallCurve:
    """Pieces ``(segment, t0, t1)`` (mm), z rising; evaluate with :meth:`radius_at`."""

    pieces: tuple

    def __post_init__(self):
        z_starts, tables = [], []
        for seg, t0, t1 in self.pieces:
            t = np.linspace(t0, t1, _TABLE)
            z = seg.point(t)[:, 1]
            z_starts.append(z[0])
            tables.append((t, np.maximum.accumulate(z)))
        object.__setattr__(self, "_z_starts", np.array(z_starts))
        object.__setattr__(self, "_tables", tables)

    @property
    def z_min(self) -> float:
        """Height of the first point (mm)."""
        return float(self._tables[0][1][0])

    @property
    def z_max(self) -> float:
        """Height of the last point (mm)."""
        return float(self._tables[-1][1][-1])

    def radius_at(self, z):
        """Radius ``r(z)`` (mm) and slope ``dr/dz`` at heights ``z`` (clamped into the curve).

        Newton on ``z(t) = z`` seeded from a table, per piece; exact to ~1e-12 mm.
        """
        z = np.clip(np.asarray(z, dtype=float), self.z_min, self.z_max)
        piece = np.clip(np.searchsorted(self._z_starts, z, side="right") - 1, 0, len(self.pieces) - 1)
        r = np.empty_like(z)
        slope = np.empty_like(z)
        for k, (seg, t0, t1) in enumerate(self.pieces):
            sel = piece == k
            if not np.any(sel):
                continue
            zk = z[sel]
            closed = _closed_form(seg, t0, t1, zk)
            if closed is not None:
                r[sel], slope[sel] = closed
                continue
            tt, zt = self._tables[k]
            t = np.interp(zk, zt, tt)
            h = 1e-7 * max(abs(t1 - t0), 1e-12)
            for _ in range(1):
                zc = seg.point(t)[:, 1]
                dz = (seg.point(t + h)[:, 1] - seg.point(t - h)[:, 1]) / (2 * h)
                step = np.where(np.abs(dz) > 1e-300, (zc - zk) / np.where(dz == 0, 1.0, dz), 0.0)
                t = np.clip(t - step, min(t0, t1), max(t0, t1))
            tan = seg.tangent(t)
            r[sel] = seg.point(t)[:, 0]
            slope[sel] = tan[:, 0] / np.maximum(tan[:, 1], 1e-12)
        return r, slope

    def ring_heights(self, max_turn_deg: float) -> np.ndarray:
        """Heights (mm) where rings should go so the tangent turns at most ``max_turn_deg``
        between neighbours; includes every piece's ends."""
        zs = []
        for seg, t0, t1 in self.pieces:
            a = seg.tangent(np.linspace(t0, t1, 65))
            ang = np.unwrap(np.arctan2(a[:, 1], a[:, 0]))
            turn = float(np.max(ang) - np.min(ang))
            n = max(1, int(math.ceil(math.degrees(turn) / max_turn_deg)))
            if getattr(seg, "kind", "") in ("ellipse_arc", "ellipse_offset"):
                n *= 2  # equal steps in t are not equal turning on an ellipse
            zs.append(seg.point(np.linspace(t0, t1, n + 1))[:, 1])
        return np.concatenate(zs)


def _closed_form(seg, t0, t1, z):
    """``(r, dr/dz)`` on lines, circle arcs and ellipse arcs solved in closed form, else None.

    On a z-rising piece of a circle or ellipse the curve stays on one side of the centre's
    vertical (crossing it would need a horizontal tangent), so ``r`` is one square-root branch.
    """
    kind = getattr(seg, "kind", "")
    if kind == "line":
        (r0, z0), (r1, z1) = seg.p0, seg.p1
        k = (r1 - r0) / (z1 - z0)
        return r0 + (z - z0) * k, np.full_like(z, k)
    if kind in ("arc", "ellipse_arc"):
        a, b = (seg.radius, seg.radius) if kind == "arc" else (seg.radius_r, seg.radius_z)
        cr, cz = seg.center
        side = 1.0 if seg.point(0.5 * (t0 + t1))[0] >= cr else -1.0
        s = np.clip((z - cz) / b, -1.0, 1.0)
        c = np.maximum(np.sqrt(np.maximum(1.0 - s * s, 0.0)), 1e-12)  # horizontal tangent: slope 1e12
        return cr + side * a * c, -side * (a / b) * s / c
    return None


def _clip_below(pieces, z_cut: float):
    """Drop what lies below ``z_cut`` from a z-rising chain of pieces (bisection on t)."""
    out = []
    for seg, t0, t1 in pieces:
        z0, z1 = seg.point(t0)[1], seg.point(t1)[1]
        if z1 <= z_cut:
            continue
        if z0 < z_cut:
            lo, hi = t0, t1
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if seg.point(mid)[1] < z_cut:
                    lo = mid
                else:
                    hi = mid
            t0 = hi
        out.append((seg, t0, t1))
    if not out:
        raise WallError(f"the inner base at {z_cut} mm is above the mouth")
    return out


def wall_curves(section, wall: float, z_ib: float):
    """Outer and inner :class:`WallCurve` of one section (SPEC 4.2).

    Parameters
    ----------
    section : engine.section.Section
        Valid section: segment 0 the flat base, then z strictly rising to the mouth.
    wall : float
        Wall thickness (mm, > 0, below every convex curvature radius).
    z_ib : float
        Height of the inner base (mm, >= wall).
    """
    segs = section.segments[1:]
    outer = WallCurve(tuple((s, 0.0, 1.0) for s in segs))
    inner = WallCurve(tuple(_clip_below([(s.offset(wall), 0.0, 1.0) for s in segs], z_ib)))
    return outer, inner
