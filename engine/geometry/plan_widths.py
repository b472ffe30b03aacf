"""The widths designers quote of an outline bottle's body: across the flats and across the corners.

Design rule: the width of the section ``O = k P (+) disc(c)`` between two parallel planes
normal to the plan direction ``psi`` is ``k (h(psi) + h(psi + pi)) + 2 c`` (``h`` the support
function of ``P``). *Across the flats* is its least value over the directions, *across the
corners* its largest (the section's diameter): for a regular ``n``-gon of circumradius 1 with
``n`` even, ``2 k cos(pi/n) + 2 c`` and ``2 k + 2 c``. Both are found exactly for polygons
(the least width of a convex polygon lies across one of its sides, its diameter joins two of its
joints: both kinds of direction are candidates) and to ``1e-12`` for arcs (a grid refined by
Brent's method). They are quoted at the *widest core*: the height where ``k`` is largest (of
those, where ``c`` is). Pure numpy; no Qt.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .chain import radius_at

#: Directions of the grid the widths' search starts from (over half a turn).
GRID = 2048
#: Samples per segment of the core and rounding sections in the search for the widest core.
SAMPLES = 129


@dataclass(frozen=True)
class Widths:
    """Least and largest width (mm) of a plan section and the directions (deg, ccw from +x, in
    ``[0, 180)``, the bottle's own frame) they are measured along."""

    flats: float
    flats_deg: float
    corners: float
    corners_deg: float


@dataclass(frozen=True)
class WidestCore:
    """The height ``z`` (mm) of the widest core, its core scale ``k`` and rounding ``c`` (mm)."""

    z: float
    k: float
    c: float


def _width(plan, psi):
    psi = np.asarray(psi, float)
    return plan.support(psi) + plan.support(psi + math.pi)


def _candidates(plan) -> np.ndarray:
    """Directions (rad) where a polygon's extreme widths lie, and a grid between them."""
    segs = plan.segments
    out = [np.linspace(0.0, math.pi, GRID, endpoint=False)]
    out.append(np.array([math.atan2(*s.normal[::-1]) for s in segs if s.kind == "line"]))
    pts = np.array([s.p0 for s in segs])
    if len(pts) <= 128:
        d = pts[:, None, :] - pts[None, :, :]
        out.append(np.arctan2(d[..., 1], d[..., 0]).ravel())
    return np.concatenate(out) % math.pi


def _refined(plan, psi0: float, sign: float) -> tuple[float, float]:
    """``(psi, width)`` of the least (``sign`` +1) or largest (-1) width near ``psi0``."""
    from scipy.optimize import minimize_scalar

    step = math.pi / GRID
    best = (psi0, float(_width(plan, psi0)))
    res = minimize_scalar(lambda p: sign * float(_width(plan, p)), bounds=(psi0 - step, psi0 + step),
                          method="bounded", options={"xatol": 1e-13})
    if res.fun < sign * best[1]:
        best = (float(res.x), sign * float(res.fun))
    return best


def plan_widths(plan, k: float, c: float) -> Widths:
    """Across flats and across corners (mm) of ``k P (+) disc(c)`` (:class:`Widths`)."""
    psi = _candidates(plan)
    w = _width(plan, psi)
    (p_min, w_min), (p_max, w_max) = (_refined(plan, float(psi[np.argmin(w)]), 1.0),
                                      _refined(plan, float(psi[np.argmax(w)]), -1.0))
    return Widths(k * w_min + 2 * c, math.degrees(p_min % math.pi), k * w_max + 2 * c, math.degrees(p_max % math.pi))


def widest_core(shape) -> WidestCore:
    """The widest core of an outline bottle ``shape`` (:class:`WidestCore`): where the core
    section ``k(z)`` is largest, refined between samples, and of such heights (a vertical wall)
    the one where the rounding ``c(z)`` is largest, then the lowest."""
    from scipy.optimize import minimize_scalar

    core, rnd = shape.section("core").segments[1:], shape.section("round").segments[1:]
    z = np.unique(np.concatenate([np.asarray(s.point(np.linspace(0.0, 1.0, SAMPLES)))[:, 1]
                                  for s in core + rnd]))
    k = radius_at(core, z)
    i = int(np.nanargmax(k))
    lo, hi = z[max(i - 1, 0)], z[min(i + 1, len(z) - 1)]
    if hi > lo:
        res = minimize_scalar(lambda t: -float(radius_at(core, np.array([t]))[0]), bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-10})
        if -res.fun > k[i] + 1e-9:
            z_best = float(res.x)
            return WidestCore(z_best, -float(res.fun), float(radius_at(rnd, np.array([z_best]))[0]))
    tol = 1e-9 * max(1.0, float(k[i]))
    flat = np.flatnonzero(k >= k[i] - tol)
    c = radius_at(rnd, z[flat])
    j = flat[int(np.flatnonzero(c >= np.nanmax(c) - tol)[0])]  # why the first: z is sorted, the lowest
    return WidestCore(float(z[j]), float(k[j]), float(radius_at(rnd, np.array([z[j]]))[0]))
