"""The views of an outline (free plan) bottle as exact curves, and what its plan is measured across.

Design rule: nothing here is sampled but by the page writer. The section at height ``z`` is
``{q : sd(q, k(z) P) <= r(z)}`` (:mod:`engine.geometry.plan`; ``r`` the rounding ``c`` outside,
``c - w`` in the cavity). Its reach towards plan direction ``psi``, the silhouette an elevation
shows on that side, is the section's support function: ``k h_P(psi) + r`` where ``r >= 0``,
:meth:`~engine.geometry.plan.PlanOutline.section_support` where the cavity's corners are sharp.
Over each band of the wall (:mod:`engine.geometry.outline_bands`) the silhouette is drawn as the
:class:`~engine.geometry.segments.Line`, ``Arc`` or ``EllipseArc`` it is (both profiles
straight, or one of them constant, on a grown band), else as a :class:`Silhouette` evaluated
exactly wherever it is sampled. The plan view is the section's own pieces
(:meth:`~engine.geometry.plan.PlanOutline.outer_pieces`): a line stays a line, an arc an arc.
The widths the plan is dimensioned with are differences of the support function between points
of the section (across flats ``k (h_i + h_j) + 2c`` between two parallel lines of ``P``, across
corners between two opposite sharp corners), its radii those of its arc pieces.

Directions ``psi`` are radians counter-clockwise from the bottle's own +x axis (before
``rotation_deg``); lengths are mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from ..geometry.capacity import area_breaks  # where the cavity's rounding passes 0
from ..geometry.capacity import section_radii_at
from ..geometry.offset import SectionProfile, shifted
from ..geometry.outline_bands import Band, band_radii, bands
from ..geometry.plan_widths import plan_widths as quoted_widths
from ..geometry.segments import Arc, EllipseArc, EndsFromPoint, Line
from ..geometry.validate import body_profile
from .drawing_page import Circle, SegmentCurve

TWO_PI = 2.0 * math.pi
#: A profile segment whose radius changes by less than this (mm) is constant.
CONSTANT_MM = 1e-12
#: Directions (rad) and support values agreeing to this are the same (flats, corners, mirrors).
SAME = 1e-9
#: Radii (mm) closer than this are one radius on the drawing.
SAME_RADIUS_MM = 1e-6
#: Most radii one plan is dimensioned with (a free outline may have many arcs).
MAX_RADII = 3
#: The plan's extra widths stand off its upper right, nearest this direction (mod pi).
OBLIQUE = 0.75 * math.pi
#: The radii are marked on the arc nearest this direction (lower right, clear of the widths)
#: and no nearer an arc's end than this share of its sweep.
RADIUS_AT, END_SHARE = -0.25 * math.pi, 0.1


# ------------------------------------------------------------------------- silhouettes
@dataclass(frozen=True)
class Silhouette(EndsFromPoint):
    """The reach (mm) of the sections of ``band`` towards plan direction ``psi`` as a curve
    ``(reach, z)`` from ``band.za`` (``t = 0``) to ``band.zb`` (``t = 1``), exact at every ``t``:
    a segment for :class:`~.drawing_page.SegmentCurve` where no line, arc or ellipse is one."""

    plan: object
    band: Band
    psi: float
    kind = "silhouette"

    def point(self, t):
        """Point(s) ``(..., 2)`` (mm) at parameter(s) ``t`` (height linear in ``t``)."""
        z = self.band.za + np.asarray(t, float) * (self.band.zb - self.band.za)
        x = self.plan.section_support(self.psi, *band_radii(self.band, z))
        return np.stack(np.broadcast_arrays(x, z), axis=-1)


def _constant(seg) -> float | None:
    """The radius (mm) of a vertical line, ``None`` for any other segment."""
    if isinstance(seg, Line) and abs(seg.p1[0] - seg.p0[0]) <= CONSTANT_MM:
        return seg.p0[0]
    return None


def _stretched(seg, a: float, dx: float):
    """``seg`` (an arc or ellipse arc) with its radius ``x`` mapped to ``a x + dx`` (``a > 0``):
    an ellipse arc (an arc where ``a`` is 1); the parameter angle and the direction stay."""
    rr, rz = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_r, seg.radius_z)
    centre, p0, p1 = ((a * p[0] + dx, p[1]) for p in (seg.center, seg.p0, seg.p1))
    if isinstance(seg, Arc) and a == 1.0:
        return Arc(centre, rr, p0, p1, seg.direction)
    return EllipseArc(centre, a * rr, rz, p0, p1, seg.direction)


def _exact(band: Band, a: float):
    """The silhouette ``a k + r`` of a grown band (``a = h_P(psi)``) as the Line, Arc or
    EllipseArc it is, or ``None`` where it is none of them."""
    k, r = band.k, band.r
    if isinstance(k, Line) and isinstance(r, Line):
        return Line((a * k.p0[0] + r.p0[0], band.za), (a * k.p1[0] + r.p1[0], band.zb))
    k0, r0 = _constant(k), _constant(r)
    if k0 is not None and isinstance(r, (Arc, EllipseArc)):
        return shifted(r, a * k0)
    if r0 is not None and isinstance(k, (Arc, EllipseArc)):
        return _stretched(k, a, r0)
    return None


def silhouette(plan, chains, z_lo: float, z_hi: float, crossings, psi: float) -> tuple:
    """The reach towards ``psi`` of the wall whose core and rounding are ``chains``, from
    ``z_lo`` to ``z_hi`` (mm), as a z-rising chain of segments (one per band)."""
    a = float(plan.support(psi))
    return tuple((band.grown and _exact(band, a)) or Silhouette(plan, band, psi)
                 for band in bands(chains, z_lo, z_hi, crossings))


def _walls(prof, which: str):
    return [sp.outer_wall if which == "outer" else sp.inner_wall for sp in prof.sections]


@lru_cache(maxsize=64)
def elevation(shape, psi: float) -> SectionProfile:
    """What an outline bottle shows towards plan direction ``psi`` (rad), as a section profile
    in (reach, z) mm: the outer silhouette from the standing line to the mouth, the cavity's
    from its floor; the bases are the flat lines out to them."""
    prof, plan = body_profile(shape), shape.plan
    top, floor = float(prof.z_top), float(prof.z_ib)
    outer = silhouette(plan, _walls(prof, "outer"), 0.0, top, area_breaks(prof, "outer"), psi)
    inner = silhouette(plan, _walls(prof, "inner"), floor, top, area_breaks(prof, "inner"), psi)
    return SectionProfile(f"silhouette towards {math.degrees(psi):g} deg",
                          (Line((0.0, 0.0), (outer[0].p0[0], 0.0)),), outer,
                          (Line((0.0, floor), (inner[0].p0[0], floor)),), inner)


def reach(shape, z, psi: float, which: str = "outer") -> np.ndarray:
    """The outer (or cavity's) reach (mm) towards ``psi`` at heights ``z`` (mm; a wall's ends
    held beyond it): the section's support function."""
    (k, r), _ = section_radii_at(body_profile(shape), np.asarray(z, float), which)
    return shape.xs.support((np.maximum(k, 0.0), r), psi)


def section_at(shape, z: float) -> tuple[float, float]:
    """``(k, c)`` (mm): the core and the rounding of the outer section at height ``z`` (mm)."""
    (k, c), _ = section_radii_at(body_profile(shape), np.array(float(z)), "outer")
    return max(float(k), 0.0), float(c)


def symmetric_about_x(plan) -> bool:
    """Whether ``P`` is its own mirror image in the x axis, segment for segment (then every
    section is, and the front view's silhouettes are the cut through the axis)."""
    def row(s, flip: float):
        centre, radius = (s.center, s.radius) if s.kind == "arc" else ((0.0, 0.0), 0.0)
        p0, p1 = (s.p1, s.p0) if flip < 0 else (s.p0, s.p1)   # why: a mirror walks backwards
        return [s.kind == "arc", p0[0], flip * p0[1], p1[0], flip * p1[1], centre[0], flip * centre[1], radius]
    own = np.array([row(s, 1.0) for s in plan.segments], float)
    mirror = np.array([row(s, -1.0) for s in reversed(plan.segments)], float)
    return any(np.max(np.abs(np.roll(mirror, j, axis=0) - own)) <= SAME for j in range(len(own)))


# ------------------------------------------------------------------------- the plan
def section_curves(plan, k: float, c: float, center, layer: str, style: str) -> list:
    """The outer section with core ``k`` and rounding ``c > 0`` (mm) centred at ``center``
    (model mm) as its exact pieces: lines and arcs, a circle where the core has vanished."""
    cx, cy = center
    out = []
    for p in plan.outer_pieces(k, c):
        if p.kind == "line":
            seg = Line(p.p0, p.p1)
        elif p.theta1 - p.theta0 >= TWO_PI - SAME:
            out.append(Circle((cx + p.center[0], cy + p.center[1]), p.radius, layer, style))
            continue
        else:
            seg = Arc(p.center, p.radius, p.p0, p.p1, "ccw")
        out.append(SegmentCurve(seg, layer, style, 1.0, cx, cy))
    return out


@dataclass(frozen=True)
class Across:
    """A width of a section (mm) measured along plan direction ``psi`` between its points
    ``lo`` (farthest towards ``psi + pi``) and ``hi`` (towards ``psi``); ``across`` is
    ``"flats"`` or ``"corners"`` where it is the width the Plan tab quotes so, else ``""``.
    ``tag`` names it on the drawing."""

    tag: str
    psi: float
    lo: tuple
    hi: tuple
    across: str = ""

    @property
    def mm(self) -> float:
        return float(np.subtract(self.hi, self.lo) @ _unit(self.psi))


@dataclass(frozen=True)
class Radius:
    """An arc piece of a section to dimension: its centre and the point marked (mm)."""

    centre: tuple
    point: tuple
    radius: float


def _unit(psi: float) -> np.ndarray:
    return np.array([math.cos(psi), math.sin(psi)])


def _flat(plan, psi: float):
    """The line of ``P`` facing ``psi`` (its outward normal), or ``None``."""
    u = _unit(psi)
    return next((s for s in plan.segments if s.kind == "line" and np.dot(s.normal, u) >= 1.0 - SAME), None)


def _farthest(plan, psi: float) -> list[np.ndarray]:
    """The points of ``P`` farthest along ``psi`` (normalised): a line's two ends where it faces
    ``psi``, else the one joint or arc point."""
    flat = _flat(plan, psi)
    if flat is not None:
        return [np.array(flat.p0), np.array(flat.p1)]
    u = _unit(psi)
    cands = [np.array(s.p0) for s in plan.segments]
    cands += [np.array(s.center) + s.radius * u for s in plan.segments
              if s.kind == "arc" and (psi - s.theta0) % TWO_PI <= s.sweep]
    return [max(cands, key=lambda p: float(p @ u))]


def _across(plan, k: float, c: float, psi: float, tag: str, aligned: bool = False) -> Across | None:
    """The width along ``psi`` between points of the section farthest each way: the middles of
    the farthest parts (a line's middle where one faces that way) or, ``aligned``, points on one
    line along ``psi`` (the middle of where the two farthest parts overlap across it); ``None``
    where they do not overlap."""
    u = _unit(psi)
    t = np.array([-u[1], u[0]])
    (lo_t, lo_h), (hi_t, hi_h) = (
        (sorted(k * float(p @ t) for p in far), k * float(far[0] @ _unit(a)) + c)
        for a, far in ((psi + math.pi, _farthest(plan, psi + math.pi)), (psi, _farthest(plan, psi))))
    if aligned:
        a, b = max(lo_t[0], hi_t[0]), min(lo_t[-1], hi_t[-1])
        if b < a - SAME * max(1.0, k):
            return None
        lo_t = hi_t = [0.5 * (a + b)]
    mid = (0.5 * (lo_t[0] + lo_t[-1]), 0.5 * (hi_t[0] + hi_t[-1]))
    return Across(tag, psi, tuple(mid[0] * t - lo_h * u), tuple(mid[1] * t + hi_h * u))


def _off(a: float, b: float) -> float:
    """Angle (rad) between the lines along ``a`` and ``b`` (mod pi)."""
    d = (a - b) % math.pi
    return min(d, math.pi - d)


def _directions(plan, kind: str, quoted_deg: float) -> np.ndarray:
    """Where a width the Plan tab quotes may lie besides its own direction (rad): along a
    line's normal (flats), along the line through two joints (corners)."""
    if kind == "flats":
        dirs = [math.atan2(s.normal[1], s.normal[0]) for s in plan.segments if s.kind == "line"]
    else:
        pts = np.array([s.p0 for s in plan.segments])
        d = pts[:, None, :] - pts[None, :, :]
        dirs = list(np.arctan2(d[..., 1], d[..., 0]).ravel())
    return np.unique(np.round(np.mod([math.radians(quoted_deg), *dirs], math.pi), 12))


def plan_widths(plan, k: float, c: float) -> list[Across]:
    """The widths the plan of the section ``(k, c)`` is dimensioned with: the overall width (x)
    and depth (y); where ``P`` has straight sides, the Plan tab's across flats (the least width)
    and across corners (the largest, :func:`engine.geometry.plan_widths.plan_widths`), each the
    width or the depth where it is one, else along its own direction (of those with the same
    width, the one nearest :data:`OBLIQUE`) between points of the section on one line."""
    out = [_across(plan, k, c, 0.0, "plan-width"), _across(plan, k, c, 0.5 * math.pi, "plan-depth")]
    if k <= 0 or not any(s.kind == "line" for s in plan.segments):
        return out   # (a circle, or a flask of arcs: its width and depth say it all)
    quoted = quoted_widths(plan, k, c)
    for kind, value, deg in (("flats", quoted.flats, quoted.flats_deg), ("corners", quoted.corners, quoted.corners_deg)):
        tol = SAME * max(1.0, value)
        same = [j for j, w in enumerate(out[:2]) if abs(w.mm - value) <= tol]
        for j in same:
            out[j] = replace(out[j], across=kind)
        if same:
            continue
        dirs = _directions(plan, kind, deg)
        dirs = dirs[np.abs(k * (plan.support(dirs) + plan.support(dirs + math.pi)) + 2 * c - value) <= tol]
        cands = [w for w in (_across(plan, k, c, float(a), kind, aligned=True) for a in dirs) if w is not None]
        if cands:
            out.append(replace(min(cands, key=lambda w: _off(w.psi, OBLIQUE)), across=kind))
    return out


def _mark(p) -> tuple[float, float]:
    """``(angle, miss)`` (rad): the angle on the arc piece ``p`` nearest :data:`RADIUS_AT`,
    kept off its ends by :data:`END_SHARE` of its sweep (a leader at a joint would point at two
    arcs), and how far it is from :data:`RADIUS_AT`."""
    sweep = p.theta1 - p.theta0
    lo, span = p.theta0 + END_SHARE * sweep, (1.0 - 2.0 * END_SHARE) * sweep
    d = (RADIUS_AT - lo) % TWO_PI
    if d <= span:
        return lo + d, 0.0
    return (lo + span, d - span) if d - span <= TWO_PI - d else (lo, TWO_PI - d)


def plan_radii(plan, k: float, c: float) -> list[Radius]:
    """One mark per distinct radius of the section's arc pieces (smallest first, at most
    :data:`MAX_RADII`), each on the arc that comes nearest :data:`RADIUS_AT`."""
    arcs = [p for p in plan.outer_pieces(k, c) if p.kind == "arc"]
    groups: list[list] = []
    for p in sorted(arcs, key=lambda p: p.radius):
        if groups and p.radius - groups[-1][0].radius <= SAME_RADIUS_MM:
            groups[-1].append(p)
        else:
            groups.append([p])
    out = []
    for group in groups[:MAX_RADII]:
        p = min(group, key=lambda p: _mark(p)[1])
        out.append(Radius(p.center, p.point(_mark(p)[0]), p.radius))
    return out
