"""Curve pieces the section edits are built from: moved, deformed and tangent segments.

Design rule: pure functions of frozen segments (mm), no Qt and no validation. A deformation keeps
the segment's start and, where asked, its end tangents; it raises ``ValueError`` only when the
requested geometry does not exist (an arc shrunk to nothing, a negative radius).
"""
from __future__ import annotations

import math

import numpy as np

from ..section import Section
from ..segments import Arc, EllipseArc, Line

Vec = tuple[float, float]


def _add(p, d) -> Vec:
    return (p[0] + d[0], p[1] + d[1])


def _unit(v):
    n = math.hypot(v[0], v[1])
    if n < 1e-12:
        raise ValueError("degenerate direction")
    return (v[0] / n, v[1] / n)


def translated(seg, d: Vec):
    """``seg`` moved by ``d`` (mm)."""
    if isinstance(seg, Line):
        return Line(_add(seg.p0, d), _add(seg.p1, d))
    if isinstance(seg, Arc):
        return Arc(_add(seg.center, d), seg.radius, _add(seg.p0, d), _add(seg.p1, d), seg.direction)
    return EllipseArc(_add(seg.center, d), seg.radius_r, seg.radius_z, _add(seg.p0, d),
                      _add(seg.p1, d), seg.direction)


def _tangent(seg, t: float) -> Vec:
    return tuple(float(v) for v in seg.tangent(t))


def arc_tangent_at(a: Vec, tangent: Vec, b: Vec, tangent_at_start: bool) -> Arc:
    """The circular arc tangent to ``tangent`` at ``a`` that passes through ``b``.

    ``tangent_at_start`` says whether ``a`` is the arc's start (``p0``) or its end (``p1``).
    The centre lies on the left of the walking direction for a ccw (convex) arc.
    """
    left = (-tangent[1], tangent[0])
    ab = (b[0] - a[0], b[1] - a[1])
    denom = 2.0 * (left[0] * ab[0] + left[1] * ab[1])
    if abs(denom) < 1e-9 * max(1.0, ab[0] ** 2 + ab[1] ** 2):
        raise ValueError("the arc would be straight; convert it to a line instead")
    s = (ab[0] ** 2 + ab[1] ** 2) / denom
    centre = (a[0] + s * left[0], a[1] + s * left[1])
    direction = "ccw" if s > 0 else "cw"
    p0, p1 = (a, b) if tangent_at_start else (b, a)
    return Arc(centre, abs(s), p0, p1, direction)


def _arc_on_bisector(seg: Arc, p0: Vec, p1: Vec) -> Arc:
    """The arc through ``p0``, ``p1`` whose centre is nearest the old centre."""
    mid = ((p0[0] + p1[0]) / 2, (p0[1] + p1[1]) / 2)
    chord = _unit((p1[0] - p0[0], p1[1] - p0[1]))
    perp = (-chord[1], chord[0])
    k = (seg.center[0] - mid[0]) * perp[0] + (seg.center[1] - mid[1]) * perp[1]
    centre = (mid[0] + k * perp[0], mid[1] + k * perp[1])
    return Arc(centre, math.dist(centre, p0), p0, p1, seg.direction)


def deform_end(seg, new_p1: Vec, keep_start_tangent: bool, keep_end_tangent: bool,
               project: bool = True):
    """``seg`` with its end moved towards ``new_p1``, its start fixed.

    With ``project`` the motion is limited to what keeps the requested tangents; without it the
    end goes exactly to ``new_p1`` and only the start tangent is kept. Returns the new segment.
    """
    p0, p1 = seg.p0, seg.p1
    d = (new_p1[0] - p1[0], new_p1[1] - p1[1])
    if isinstance(seg, Line):
        if project and (keep_start_tangent or keep_end_tangent):
            u = _unit((p1[0] - p0[0], p1[1] - p0[1]))
            k = d[0] * u[0] + d[1] * u[1]
            d = (k * u[0], k * u[1])
        return Line(p0, _add(p1, d))
    if isinstance(seg, Arc):
        if project and keep_start_tangent and keep_end_tangent:
            chord = (p1[0] - p0[0], p1[1] - p0[1])
            u = _unit(chord)
            scale = 1.0 + (d[0] * u[0] + d[1] * u[1]) / math.hypot(*chord)
            if scale <= 1e-3:
                raise ValueError("the arc would shrink to nothing")
            c = (p0[0] + scale * (seg.center[0] - p0[0]), p0[1] + scale * (seg.center[1] - p0[1]))
            return Arc(c, seg.radius * scale, p0, (p0[0] + scale * chord[0], p0[1] + scale * chord[1]),
                       seg.direction)
        target = _add(p1, d)
        if keep_start_tangent:
            return arc_tangent_at(p0, _tangent(seg, 0.0), target, tangent_at_start=True)
        if project and keep_end_tangent:
            return arc_tangent_at(target, _tangent(seg, 1.0), p0, tangent_at_start=False)
        return _arc_on_bisector(seg, p0, target)
    # Ellipse: keep both parameter angles, solve centre and radii (linear in them). When both
    # ends must stay tangent the radii scale together (the ratio fixes the end tangents).
    s0, s1 = seg.angle0, seg.angle0 + seg.sweep
    if project and keep_start_tangent and keep_end_tangent:
        chord = (p1[0] - p0[0], p1[1] - p0[1])
        u = _unit(chord)
        d = tuple((d[0] * u[0] + d[1] * u[1]) * x for x in u)
    target = _add(p1, d)
    dc, ds = math.cos(s1) - math.cos(s0), math.sin(s1) - math.sin(s0)
    a = seg.radius_r if abs(dc) < 1e-9 else (target[0] - p0[0]) / dc
    b = seg.radius_z if abs(ds) < 1e-9 else (target[1] - p0[1]) / ds
    if a <= 1e-6 or b <= 1e-6:
        raise ValueError("the ellipse radii would not stay positive")
    c = (p0[0] - a * math.cos(s0), p0[1] - b * math.sin(s0))
    end = (c[0] + a * math.cos(s1), c[1] + b * math.sin(s1))
    return EllipseArc(c, a, b, p0, end, seg.direction)


def deform_start(seg, new_p0: Vec, keep_start_tangent: bool, keep_end_tangent: bool,
                 project: bool = True):
    """Mirror of :func:`deform_end`: ``seg`` with its start moved, its end fixed."""
    moved = deform_end(seg.reversed(), new_p0, keep_end_tangent, keep_start_tangent, project)
    return moved.reversed()


def section_polyline(section_or_segments, samples: int = 24) -> np.ndarray:
    """Points (N, 2) along the segments, for drawing."""
    segs = getattr(section_or_segments, "segments", section_or_segments)
    pts = []
    for seg in segs:
        n = 2 if isinstance(seg, Line) else samples
        pts.append(np.atleast_2d(seg.point(np.linspace(0.0, 1.0, n))))
    return np.concatenate(pts, axis=0) if pts else np.zeros((0, 2))


def scaled_radially(section: Section, factor: float) -> Section:
    """``section`` with every radius multiplied by ``factor`` > 0 (arcs become ellipses)."""
    return Section(mapped_radially(section.segments, factor), section.smooth)


def mapped_radially(segments, factor: float, about: float = 0.0, to: float = 0.0) -> tuple:
    """``segments`` with every radius ``r`` mapped to ``to + factor (r - about)`` (mm), heights
    kept. The map is affine, so tangent joints stay tangent and corners stay corners; an arc
    becomes an ellipse arc unless ``|factor| = 1``, and a negative factor mirrors each segment
    (``ccw`` <-> ``cw``). ``ValueError`` for a zero factor (every segment would be flattened)."""
    if not (math.isfinite(factor) and factor != 0.0):
        raise ValueError(f"a radial map needs a finite non-zero factor, got {factor!r}")
    flip = {"ccw": "cw", "cw": "ccw"} if factor < 0 else {"ccw": "ccw", "cw": "cw"}

    def sp(p):
        return (to + factor * (p[0] - about), p[1])
    segs = []
    for seg in segments:
        if isinstance(seg, Line):
            segs.append(Line(sp(seg.p0), sp(seg.p1)))
        elif isinstance(seg, Arc) and abs(factor) == 1.0:
            segs.append(Arc(sp(seg.center), seg.radius, sp(seg.p0), sp(seg.p1), flip[seg.direction]))
        else:
            rr, rz = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_r, seg.radius_z)
            segs.append(EllipseArc(sp(seg.center), rr * abs(factor), rz, sp(seg.p0), sp(seg.p1),
                                   flip[seg.direction]))
    return tuple(segs)
