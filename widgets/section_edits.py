"""Geometric edits of one Section, as the section editor offers them (no Qt here).

Design rule: every edit is a pure function ``Section -> Section`` that keeps the chain connected
and, where the designer asked for tangency (``Section.smooth``), keeps it by construction when it
can. Whether the result is a valid bottle is for :mod:`engine.geometry.validate` to say; these functions
raise ``ValueError`` only when the requested geometry does not exist (a negative radius).

Dragging a joint *stretches* the section: the segment below the joint deforms (its free
directions are limited so that its smooth ends keep their tangents) and everything above the
joint moves rigidly with it, so the neck follows the shoulder and tangents stay tangent. The
*local* mode moves only the joint and refits both neighbours.
"""
from __future__ import annotations

import math

import numpy as np

from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc, Line

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


def _smooth(section: Section, joint: int) -> bool:
    return 0 <= joint < len(section.smooth) and section.smooth[joint]


def _with_tail_moved(section: Section, segs: list, first_moved: int, delta: Vec) -> Section:
    for k in range(first_moved, len(segs)):
        segs[k] = translated(segs[k], delta)
    return Section(tuple(segs), section.smooth)


def move_joint(section: Section, joint: int, delta: Vec, mode: str = "stretch") -> Section:
    """Move the end of segment ``joint`` (the joint between it and the next) by ``delta`` mm.

    ``mode="stretch"``: the segment deforms keeping its smooth tangents and everything above
    moves with the joint. ``"exact"``: as stretch but the joint lands exactly on the target
    (only the start tangent is kept). ``"local"``: only the joint moves, both neighbours refit.
    The base segment stays on z = 0 from the axis.
    """
    segs = list(section.segments)
    seg = segs[joint]
    if joint == 0:
        delta = (delta[0], 0.0)
    target = _add(seg.p1, delta)
    keep0 = joint == 0 or _smooth(section, joint - 1)
    keep1 = _smooth(section, joint)
    if mode == "local":
        segs[joint] = deform_end(seg, target, keep0, False, project=False) if joint else Line((0, 0), target)
        if joint + 1 < len(segs):
            segs[joint + 1] = deform_start(segs[joint + 1], target, False,
                                           _smooth(section, joint + 1), project=False)
        return Section(tuple(segs), section.smooth)
    new_seg = Line((0.0, 0.0), target) if joint == 0 else \
        deform_end(seg, target, keep0, keep1, project=(mode == "stretch"))
    segs[joint] = new_seg
    moved = (new_seg.p1[0] - seg.p1[0], new_seg.p1[1] - seg.p1[1])
    return _with_tail_moved(section, segs, joint + 1, moved)


def set_arc_radius(section: Section, index: int, radius: float) -> Section:
    """Arc ``index`` with a new radius, its start and start tangent fixed, the rest following."""
    seg = section.segments[index]
    if radius <= 1e-6:
        raise ValueError("an arc radius must be positive")
    n = _unit((seg.center[0] - seg.p0[0], seg.center[1] - seg.p0[1]))
    c = (seg.p0[0] + radius * n[0], seg.p0[1] + radius * n[1])
    u1 = _unit((seg.p1[0] - seg.center[0], seg.p1[1] - seg.center[1]))
    end = (c[0] + radius * u1[0], c[1] + radius * u1[1])
    segs = list(section.segments)
    segs[index] = Arc(c, radius, seg.p0, end, seg.direction)
    return _with_tail_moved(section, segs, index + 1, (end[0] - seg.p1[0], end[1] - seg.p1[1]))


def move_arc_centre(section: Section, index: int, delta: Vec) -> Section:
    """Drag an arc's centre: it slides along the start normal, so the radius changes."""
    seg = section.segments[index]
    n = _unit((seg.center[0] - seg.p0[0], seg.center[1] - seg.p0[1]))
    return set_arc_radius(section, index, seg.radius + delta[0] * n[0] + delta[1] * n[1])


def set_ellipse_radii(section: Section, index: int, radius_r: float, radius_z: float) -> Section:
    """Ellipse ``index`` with new radii, its start and parameter angles fixed."""
    seg = section.segments[index]
    if radius_r <= 1e-6 or radius_z <= 1e-6:
        raise ValueError("ellipse radii must be positive")
    s0, s1 = seg.angle0, seg.angle0 + seg.sweep
    c = (seg.p0[0] - radius_r * math.cos(s0), seg.p0[1] - radius_z * math.sin(s0))
    end = (c[0] + radius_r * math.cos(s1), c[1] + radius_z * math.sin(s1))
    segs = list(section.segments)
    segs[index] = EllipseArc(c, radius_r, radius_z, seg.p0, end, seg.direction)
    return _with_tail_moved(section, segs, index + 1, (end[0] - seg.p1[0], end[1] - seg.p1[1]))


def split_segment(section: Section, index: int) -> Section:
    """Segment ``index`` cut in two at its parameter midpoint (a smooth joint)."""
    seg = section.segments[index]
    mid = tuple(float(v) for v in seg.point(0.5))
    if isinstance(seg, Line):
        parts = (Line(seg.p0, mid), Line(mid, seg.p1))
    elif isinstance(seg, Arc):
        parts = (Arc(seg.center, seg.radius, seg.p0, mid, seg.direction),
                 Arc(seg.center, seg.radius, mid, seg.p1, seg.direction))
    else:
        parts = tuple(EllipseArc(seg.center, seg.radius_r, seg.radius_z, a, b, seg.direction)
                      for a, b in ((seg.p0, mid), (mid, seg.p1)))
    segs = list(section.segments)
    segs[index:index + 1] = parts
    smooth = list(section.smooth)
    smooth.insert(index, True)
    return Section(tuple(segs), tuple(smooth))


def delete_segment(section: Section, index: int) -> Section:
    """Remove segment ``index`` (not the base); everything above drops to close the gap."""
    if index == 0 or len(section.segments) <= 2:
        raise ValueError("the base segment and a two-segment section cannot lose a segment")
    seg = section.segments[index]
    segs = list(section.segments)
    del segs[index]
    smooth = list(section.smooth)
    del smooth[min(index, len(smooth) - 1)]
    gap = (seg.p0[0] - seg.p1[0], seg.p0[1] - seg.p1[1])
    return _with_tail_moved(Section(tuple(segs), tuple(smooth)), segs, index, gap)


def insert_line_after(section: Section, index: int, length: float = 10.0) -> Section:
    """A straight segment of ``length`` mm along the tangent at the end of segment ``index``."""
    seg = section.segments[index]
    t = _tangent(seg, 1.0)
    d = (length * t[0], length * t[1])
    segs = list(section.segments)
    segs.insert(index + 1, Line(seg.p1, _add(seg.p1, d)))
    smooth = list(section.smooth)
    smooth.insert(index, index > 0)
    return _with_tail_moved(Section(tuple(segs), tuple(smooth)), segs, index + 2, d)


def convert_segment(section: Section, index: int, kind: str) -> Section:
    """Segment ``index`` as a ``"line"``, ``"arc"`` or ``"ellipse_arc"`` with the same ends.

    A line becomes a gentle convex arc (sagitta an eighth of the chord); an arc becomes the
    ellipse with equal radii (exact); an ellipse becomes the arc through its ends.
    """
    seg = section.segments[index]
    if kind == seg.kind:
        return section
    p0, p1 = seg.p0, seg.p1
    if kind == "line":
        new = Line(p0, p1)
    elif isinstance(seg, Line):
        chord = math.dist(p0, p1)
        sag = chord / 8.0
        radius = (chord ** 2 / 4 + sag ** 2) / (2 * sag)
        u = _unit((p1[0] - p0[0], p1[1] - p0[1]))
        left = (-u[1], u[0])
        mid = ((p0[0] + p1[0]) / 2, (p0[1] + p1[1]) / 2)
        c = (mid[0] + (radius - sag) * left[0], mid[1] + (radius - sag) * left[1])
        new = Arc(c, radius, p0, p1, "ccw") if kind == "arc" else EllipseArc(c, radius, radius, p0, p1, "ccw")
    elif kind == "ellipse_arc":
        new = EllipseArc(seg.center, seg.radius, seg.radius, p0, p1, seg.direction)
    elif kind == "arc":
        new = _arc_on_bisector(Arc(seg.center, 1.0, p0, p1, seg.direction), p0, p1)
    else:
        raise ValueError(f"unknown segment kind {kind!r}")
    return section.replace_segment(index, new)


def set_smooth(section: Section, joint: int, smooth: bool) -> Section:
    """The designer's tangency request at ``joint`` switched on or off."""
    flags = list(section.smooth)
    flags[joint] = bool(smooth)
    return Section(section.segments, tuple(flags))


def section_polyline(section_or_segments, samples: int = 24) -> np.ndarray:
    """Points (N, 2) along the segments, for drawing."""
    segs = getattr(section_or_segments, "segments", section_or_segments)
    pts = []
    for seg in segs:
        n = 2 if isinstance(seg, Line) else samples
        pts.append(np.atleast_2d(seg.point(np.linspace(0.0, 1.0, n))))
    return np.concatenate(pts, axis=0) if pts else np.zeros((0, 2))


def scaled_radially(section: Section, factor: float) -> Section:
    """``section`` with every radius multiplied by ``factor`` (arcs become ellipses)."""
    def sp(p):
        return (p[0] * factor, p[1])
    segs = []
    for seg in section.segments:
        if isinstance(seg, Line):
            segs.append(Line(sp(seg.p0), sp(seg.p1)))
        elif isinstance(seg, Arc):
            segs.append(EllipseArc(sp(seg.center), seg.radius * factor, seg.radius, sp(seg.p0),
                                   sp(seg.p1), seg.direction))
        else:
            segs.append(EllipseArc(sp(seg.center), seg.radius_r * factor, seg.radius_z, sp(seg.p0),
                                   sp(seg.p1), seg.direction))
    return Section(tuple(segs), section.smooth)
