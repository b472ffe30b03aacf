"""Segment tools of the section editor: split, delete, insert, convert and smoothness.

Design rule: pure functions ``Section -> Section`` (mm) that keep the chain connected; a tool
raises ``ValueError`` with the reason when it cannot apply (the base cannot be deleted).
Validation of the result is :mod:`engine.geometry.validate`'s.
"""
from __future__ import annotations

import math

from ..section import Section
from ..segments import Arc, EllipseArc, Line
from .curves import _add, _arc_on_bisector, _tangent, _unit
from . import tangency
from .joints import _with_tail_moved

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
    """Segment ``index`` as a ``"line"``, ``"arc"`` or ``"ellipse_arc"``.

    An arc becomes the ellipse with equal radii (exact). A line or an ellipse next to a smooth
    joint becomes a gentle arc tangent to its neighbours, which slide along themselves to meet
    it (:func:`engine.geometry.editing.tangency.arc_between_neighbours`); between two corners a
    line becomes the convex arc through its ends with a sagitta of an eighth of the chord, an
    ellipse the arc through its ends. The finish (the last segment) stays a vertical line.
    """
    seg = section.segments[index]
    if kind not in ("line", "arc", "ellipse_arc"):
        raise ValueError(f"unknown segment kind {kind!r}")
    if kind == seg.kind:
        return section
    if index == len(section.segments) - 1:
        raise ValueError("this is the finish (the neck up to the mouth): it stays a vertical line")
    p0, p1 = seg.p0, seg.p1
    near_smooth = (index > 0 and section.smooth[index - 1]) or \
        (index < len(section.smooth) and section.smooth[index])
    if kind != "line" and not isinstance(seg, Arc) and near_smooth:
        new = tangency.arc_between_neighbours(section, index)
        if kind == "ellipse_arc":
            new = new.replace_segment(index, tangency.equal_radii_ellipse(new.segments[index]))
        return new
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
    else:
        new = _arc_on_bisector(Arc(seg.center, 1.0, p0, p1, seg.direction), p0, p1)
    return section.replace_segment(index, new)


def set_smooth(section: Section, joint: int, smooth: bool) -> Section:
    """The designer's tangency request at ``joint`` (between segments ``joint`` and
    ``joint + 1``) switched on or off."""
    if not 0 <= joint < len(section.smooth):
        raise ValueError("the last segment ends at the mouth: there is no joint above it")
    flags = list(section.smooth)
    flags[joint] = bool(smooth)
    return Section(section.segments, tuple(flags))


