"""Moving a section's joints and changing its radii, as the section editor offers them.

Design rule: every edit is a pure function ``Section -> Section`` that keeps the chain connected
and, where the designer asked for tangency (``Section.smooth``), keeps it by construction. Whether
the result is a valid bottle is for :mod:`engine.geometry.validate` to say; these functions raise
``ValueError`` (with the reason, in words) only when the requested geometry does not exist.

Joint ``j`` is the end of segment ``j``: the joint between segments ``j`` and ``j + 1``
(:func:`joint_name`). Moving it (:func:`move_joint`):

* **Placing it.** The segment below deforms with its smooth tangents kept: an arc keeping one
  tangent bends through the target; a segment whose both tangents are tied (a straight body
  between a heel and a shoulder) can only stretch along itself, so the joint below moves along
  *its* own free direction too (the heel grows or shrinks) until the joint lands on the target.
  A drag goes as far towards the pointer as that allows; a typed value lands exactly or is
  refused with the reason.
* **The finish stays.** The last segment is the finish (the vertical neck: its radius and the
  bottle's height). Segments between the moved joint and the finish follow it rigidly, except
  the one that meets the finish, which is scaled about its start so that it still ends on the
  finish, tangent where it was; the finish only gets longer or shorter. Moving the finish's own
  joints (the mouth, or the neck's start) moves the finish; ``mode="carry"`` moves everything
  above the joint with it (the old stretch); ``"local"`` moves only the joint and refits its two
  neighbours.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..section import Section
from ..segments import Arc, EllipseArc, Line
from .curves import Vec, _add, _tangent, _unit, arc_tangent_at, deform_end, deform_start, translated

MODES = ("stretch", "exact", "carry", "local")
#: How close (mm) a placed joint must come to its target to count as there.
PLACE_TOL_MM = 1e-9


def joint_name(joint: int) -> str:
    """Joint ``joint`` in the rows of the segment table: ``"the joint between segments 2 and 3"``."""
    return f"the joint between segments {joint} and {joint + 1}"


def _smooth(section: Section, joint: int) -> bool:
    return 0 <= joint < len(section.smooth) and section.smooth[joint]


def _keeps(section: Section, k: int) -> tuple[bool, bool]:
    """Whether segment ``k`` must keep its start / end tangent (the base keeps its start)."""
    return k == 0 or _smooth(section, k - 1), _smooth(section, k)


def _with_tail_moved(section: Section, segs: list, first_moved: int, delta: Vec) -> Section:
    for k in range(first_moved, len(segs)):
        segs[k] = translated(segs[k], delta)
    return Section(tuple(segs), section.smooth)


def scaled_from(seg, start: Vec, factor: float):
    """``seg`` scaled by ``factor`` about its start, then moved to begin at ``start`` (mm): the
    same shape, so both end tangents keep their directions."""
    if not factor > 1e-3:
        raise ValueError("the segment would shrink to nothing")
    p0 = seg.p0
    end = (start[0] + factor * (seg.p1[0] - p0[0]), start[1] + factor * (seg.p1[1] - p0[1]))
    if isinstance(seg, Line):
        return Line(start, end)
    c = (start[0] + factor * (seg.center[0] - p0[0]), start[1] + factor * (seg.center[1] - p0[1]))
    if isinstance(seg, Arc):
        return Arc(c, seg.radius * factor, start, end, seg.direction)
    return EllipseArc(c, seg.radius_r * factor, seg.radius_z * factor, start, end, seg.direction)


def _base_to(seg, r: float, keep_end: bool):
    """The base segment ending at radius ``r`` on z = 0: a flat base stays flat; a punt keeps
    its top on the axis and leaves it horizontally."""
    if r <= 0:
        raise ValueError(f"the base must end at r > 0, got r = {r:g} mm")
    if isinstance(seg, Line):
        return Line((0.0, 0.0), (r, 0.0))
    if keep_end:
        raise ValueError(f"a punt cannot move its standing ring while {joint_name(0)} is smooth")
    if isinstance(seg, Arc):
        return arc_tangent_at(seg.p0, (1.0, 0.0), (r, 0.0), tangent_at_start=True)
    return deform_end(seg, (r, 0.0), True, False, project=False)


def _prev_motion(section: Section, segs: list, k: int):
    """How the end of segment ``k`` may move while its end tangent stays: ``(direction, rebuild)``
    with ``rebuild(step)`` the segment whose end moved by ``step * direction`` (mm)."""
    seg = segs[k]
    keep0, keep1 = _keeps(section, k)
    if k == 0:
        return (1.0, 0.0), lambda step: _base_to(seg, seg.p1[0] + step, keep1)
    chord = (seg.p1[0] - seg.p0[0], seg.p1[1] - seg.p0[1])
    length = math.hypot(*chord)
    if keep0 or not isinstance(seg, Arc):
        return _unit(chord), lambda step: scaled_from(seg, seg.p0, 1.0 + step / length)
    return None, None  # an arc from a corner reaches any point: see _place


def _place(section: Section, segs: list, j: int, target: Vec, exact: bool) -> None:
    """Put joint ``j`` at ``target`` in ``segs`` (changing segment ``j`` and, if it must,
    segment ``j - 1``); without ``exact`` go as near as the tangents allow."""
    seg = segs[j]
    keep0, keep1 = _keeps(section, j)
    if j == 0:
        if exact and abs(target[1]) > PLACE_TOL_MM:
            raise ValueError("the base ends on the standing plane: its end z stays 0 mm")
        segs[0] = _base_to(seg, target[0], keep1)
        return
    try:
        direct = deform_end(seg, target, keep0, keep1, project=True)
    except ValueError:
        direct = None
    if direct is not None and math.dist(direct.p1, target) <= PLACE_TOL_MM:
        segs[j] = direct
        return
    try:
        segs[j - 1], segs[j] = _absorbed(section, segs, j, target)
        return
    except ValueError:
        if exact or direct is None:
            raise
    segs[j] = direct


def _absorbed(section: Section, segs: list, j: int, target: Vec):
    """Segments ``j - 1`` and ``j`` changed so that joint ``j`` lands on ``target`` although
    segment ``j`` alone cannot reach it: segment ``j`` keeps its shape (scaled about its start)
    and joint ``j - 1`` moves along its own free direction."""
    seg, prev = segs[j], segs[j - 1]
    v = (seg.p1[0] - seg.p0[0], seg.p1[1] - seg.p0[1])
    a = seg.p0
    d = (target[0] - a[0], target[1] - a[1])
    direction, rebuild = _prev_motion(section, segs, j - 1)
    if direction is None:  # a corner below: the arc below bends to meet the translated segment
        start = (target[0] - v[0], target[1] - v[1])
        new_prev = arc_tangent_at(start, _tangent(seg, 0.0), prev.p0, tangent_at_start=False)
        if new_prev.direction != prev.direction:
            raise ValueError("the arc below would turn the other way")
        return new_prev, translated(seg, (start[0] - a[0], start[1] - a[1]))
    det = direction[0] * v[1] - direction[1] * v[0]
    if abs(det) < 1e-12 * math.hypot(*v):
        raise ValueError(f"segments {j - 1} and {j} both run in the same direction, so "
                         f"{joint_name(j)} can only move along them")
    step = (d[0] * v[1] - d[1] * v[0]) / det
    factor = (direction[0] * d[1] - direction[1] * d[0]) / det
    new_prev = rebuild(step)
    return new_prev, scaled_from(seg, new_prev.p1, factor)


def _follow(section: Section, segs: list, j: int, moved: Vec, keep_finish: bool) -> None:
    """Move the segments above joint ``j`` after it moved by ``moved`` (see the module rule)."""
    n = len(segs)
    if j >= n - 1 or moved == (0.0, 0.0):
        return
    finish = segs[n - 1]
    if not keep_finish:
        for k in range(j + 1, n):
            segs[k] = translated(segs[k], moved)
        return
    if j == n - 2:  # the neck's own start: the neck follows sideways and keeps the height
        start = segs[j].p1
        segs[n - 1] = Line(start, (finish.p1[0] + moved[0], finish.p1[1]))
        return
    for k in range(j + 1, n - 2):
        segs[k] = translated(segs[k], moved)
    meets = segs[n - 2]
    start = segs[n - 3].p1
    v = (meets.p1[0] - meets.p0[0], meets.p1[1] - meets.p0[1])
    f = (finish.p1[0] - finish.p0[0], finish.p1[1] - finish.p0[1])
    det = v[0] * f[1] - v[1] * f[0]
    off = (finish.p0[0] - start[0], finish.p0[1] - start[1])
    if abs(det) < 1e-12 * math.hypot(*v) * math.hypot(*f):
        if abs(off[0] * f[1] - off[1] * f[0]) > PLACE_TOL_MM * math.hypot(*f):
            raise ValueError(f"segment {n - 2} runs parallel to the finish and cannot reach it "
                             f"again; hold Alt to move the finish with the joint")
        factor = 1.0
    else:
        factor = (off[0] * f[1] - off[1] * f[0]) / det
    new = scaled_from(meets, start, factor)
    along = ((new.p1[0] - finish.p0[0]) * f[0] + (new.p1[1] - finish.p0[1]) * f[1]) / (f[0] ** 2 + f[1] ** 2)
    if along >= 1.0 - 1e-9:
        raise ValueError("the finish would vanish: the neck needs some length below the mouth")
    segs[n - 2] = new
    segs[n - 1] = Line(new.p1, finish.p1)


def move_joint(section: Section, joint: int, delta: Vec, mode: str = "stretch") -> Section:
    """Joint ``joint`` (the end of segment ``joint``) moved by ``delta`` (mm).

    Parameters
    ----------
    section : Section
        The section to edit (mm).
    joint : int
        Index of the segment whose end moves.
    delta : (float, float)
        Wanted motion (dr, dz) in mm.
    mode : str
        ``"stretch"`` (a drag: as near the target as the smooth joints allow, the finish kept),
        ``"exact"`` (a typed value: exactly on the target, the finish kept, else ``ValueError``
        naming why), ``"carry"`` (as stretch, but everything above moves with the joint) or
        ``"local"`` (only the joint moves; both neighbours refit).

    Raises
    ------
    ValueError
        The target crosses the axis, or (``"exact"``) the joint cannot get there with the
        designer's smooth joints kept; the message says which.
    """
    if mode not in MODES:
        raise ValueError(f"unknown joint move {mode!r}; expected one of {', '.join(MODES)}")
    segs = list(section.segments)
    seg = segs[joint]
    target = _add(seg.p1, delta)
    if joint == 0 and mode != "exact":
        target = (target[0], 0.0)
    if target[0] < 0.0:
        raise ValueError(f"end r {target[0]:.4g} mm crosses the axis: a section stays at r > 0")
    if mode == "local":
        if joint == 0:
            segs[0] = _base_to(seg, target[0], False)
        else:
            segs[joint] = deform_end(seg, target, _keeps(section, joint)[0], False, project=False)
        if joint + 1 < len(segs):
            segs[joint + 1] = deform_start(segs[joint + 1], segs[joint].p1, False,
                                           _smooth(section, joint + 1), project=False)
        return Section(tuple(segs), section.smooth)
    _place(section, segs, joint, target, exact=(mode == "exact"))
    new_end = segs[joint].p1
    _follow(section, segs, joint, (new_end[0] - seg.p1[0], new_end[1] - seg.p1[1]),
            keep_finish=(mode != "carry"))
    return Section(tuple(segs), section.smooth)


def place_joint(section: Section, joint: int, r: float | None = None, z: float | None = None) -> Section:
    """Joint ``joint`` put exactly at end r = ``r`` and/or end z = ``z`` (mm; ``None`` keeps
    that coordinate), solving the smooth joints as a drag does and keeping the finish: what a
    value typed into the segment table does. Raises ``ValueError`` naming why it cannot."""
    p = section.segments[joint].p1
    target = (p[0] if r is None else float(r), p[1] if z is None else float(z))
    if target[0] < 0.0:
        raise ValueError(f"end r {target[0]:.4g} mm crosses the axis: a section stays at r > 0")
    try:
        return move_joint(section, joint, (target[0] - p[0], target[1] - p[1]), "exact")
    except ValueError as exc:
        raise ValueError(f"{joint_name(joint)} cannot go to (r {target[0]:.4g}, z {target[1]:.4g}) mm "
                         f"with its smooth neighbours kept tangent: {exc}") from None


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
    _follow(section, segs, index, (end[0] - seg.p1[0], end[1] - seg.p1[1]), keep_finish=True)
    return Section(tuple(segs), section.smooth)


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
    _follow(section, segs, index, (end[0] - seg.p1[0], end[1] - seg.p1[1]), keep_finish=True)
    return Section(tuple(segs), section.smooth)


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


def propose_drag(section: Section, handle: Handle, delta, local: bool = False,
                 carry: bool = False) -> Section:
    """The section after dragging ``handle`` by ``delta`` (mm): a joint stretches the section
    keeping the finish (``local``: moves alone; ``carry``: the part above moves with it), a
    centre or radius handle changes that radius. May raise ``ValueError``."""
    if handle.kind == "joint":
        mode = "local" if local else "carry" if carry else "stretch"
        return move_joint(section, handle.index, delta, mode)
    seg = section.segments[handle.index]
    if handle.kind == "centre":
        return move_arc_centre(section, handle.index, delta)
    if handle.kind == "radius_r":
        return set_ellipse_radii(section, handle.index, seg.radius_r + delta[0], seg.radius_z)
    return set_ellipse_radii(section, handle.index, seg.radius_r, seg.radius_z + delta[1])
