"""Moving a section's joints and changing its radii, as the section editor offers them.

Design rule: every edit is a pure function ``Section -> Section`` that keeps the chain connected
and, where the designer asked for tangency (``Section.smooth``), keeps it by construction when it
can. Whether the result is a valid bottle is for :mod:`engine.geometry.validate` to say; these
functions raise ``ValueError`` only when the requested geometry does not exist.

Dragging a joint *stretches* the section: the segment below the joint deforms (its free
directions are limited so that its smooth ends keep their tangents) and everything above the
joint moves rigidly with it, so the neck follows the shoulder and tangents stay tangent. The
*local* mode moves only the joint and refits both neighbours.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..section import Section
from ..segments import Arc, EllipseArc, Line
from .curves import Vec, _add, _unit, deform_end, deform_start, translated

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


@dataclass(frozen=True)
class Handle:
    """Something the designer can grab: ``kind`` is joint / centre / radius_r / radius_z."""

    kind: str
    index: int
    point: tuple[float, float]


def handles_of(section: Section) -> list[Handle]:
    """Every draggable point of ``section`` (joints, arc centres, ellipse radius handles)."""
    out = [Handle("joint", i, seg.p1) for i, seg in enumerate(section.segments)]
    for i, seg in enumerate(section.segments):
        if isinstance(seg, Arc):
            out.append(Handle("centre", i, seg.center))
        elif isinstance(seg, EllipseArc):
            c = seg.center
            out.append(Handle("radius_r", i, (c[0] + seg.radius_r, c[1])))
            out.append(Handle("radius_z", i, (c[0], c[1] + seg.radius_z)))
    return out


def propose_drag(section: Section, handle: Handle, delta, local: bool) -> Section:
    """The section after dragging ``handle`` by ``delta`` (mm); may raise ``ValueError``."""
    if handle.kind == "joint":
        return move_joint(section, handle.index, delta, "local" if local else "stretch")
    seg = section.segments[handle.index]
    if handle.kind == "centre":
        return move_arc_centre(section, handle.index, delta)
    if handle.kind == "radius_r":
        return set_ellipse_radii(section, handle.index, seg.radius_r + delta[0], seg.radius_z)
    return set_ellipse_radii(section, handle.index, seg.radius_r, seg.radius_z + delta[1])
