"""DXF drawings of a bottle's plan (its top view) -> :class:`engine.geometry.plan.PlanOutline`.

Design rule: the drawing is the plan in the xy plane with the bottle's axis at its origin, in mm
after the ``$INSUNITS`` scale, read exactly as a section is (:mod:`engine.files.dxf_import`: the
same reading, limits, pieces and joint tolerance ``JOIN_TOL_MM``). LINE, ARC and LWPOLYLINE (with
bulges) are allowed; they must form exactly one closed loop. The loop is walked from the start of
the drawing's first curve and turned counter-clockwise (by its signed area, arcs included); at a
joint an arc keeps its exact end and a line takes it, two lines meet at their mean. The loop is
then handed to :meth:`PlanOutline.from_dicts` in mm, which checks SPEC_outline's rules (convex,
the origin strictly inside) and normalises it: its ``scale`` is the drawn reach (mm) of the
farthest point from the axis. Every refusal names the file and, where it can, the entity
(its DXF handle) and the outline's segment.
"""
from __future__ import annotations

import math
import os

from ..errors import OutlineError
from ..geometry.plan import MAX_SEGMENTS, PlanOutline
from .dxf_import import (DxfImportError, Piece, check_reach, drawing_scale, drawn_pieces, joints_of,
                         meeting_point, named_after, read_document, walk)

#: The entities a plan outline is drawn with (a plan has no ellipse arcs: SPEC_outline 2).
PLAN_KINDS = ("LINE", "ARC", "LWPOLYLINE")


def plan_from_dxf(path: str | os.PathLike) -> PlanOutline:
    """Read ``path`` and return its plan outline (normalised; ``scale`` = its reach in mm).

    Raises ``DxfImportError`` (``"PATH: ..."``, one line) for a file that cannot be read, no
    curves, an entity other than LINE / ARC / LWPOLYLINE, an open loop, several loops, a branch,
    an arc bulging inwards or any other non-convex outline, and an outline that does not hold
    the origin (the bottle's axis) strictly inside.
    """
    doc, declares_units = read_document(path, "a plan outline")
    with named_after(path):
        return plan_from_document(doc, declares_units)


def plan_from_document(doc, declares_units: bool = True) -> PlanOutline:
    """The plan outline drawn in an ``ezdxf`` document's model space (see :func:`plan_from_dxf`)."""
    scale = drawing_scale(doc, declares_units)
    drawn = drawn_pieces(doc, PLAN_KINDS, "a plan outline", MAX_SEGMENTS)
    pieces = [p.transformed(scale, 1.0, 0.0) for p in drawn]
    check_reach(pieces)
    loop = _counter_clockwise(_snapped(_loop(pieces)))
    items = [_as_dict(p) for p in loop]
    try:
        return PlanOutline.from_dicts(items)
    except OutlineError as exc:
        raise DxfImportError(_in_drawing_words(exc, loop)) from None


def _loop(pieces: list[Piece]) -> list[Piece]:
    """The pieces as one closed loop, walked from the start of the drawing's first curve."""
    joints, ends, touching = joints_of(pieces)
    free = [j for j, ks in touching.items() if len(ks) == 1]
    if free:
        shown = ", ".join(f"({joints[j][0]:.6g}, {joints[j][1]:.6g})" for j in free[:4])
        raise DxfImportError(f"the outline is not closed: loose ends at {shown} (mm)")
    loop = walk(pieces, ends, touching, ends[0][0])
    if len(loop) != len(pieces):
        raise DxfImportError(f"the drawing holds more than one loop: {len(pieces) - len(loop)} curve(s) "
                             f"are not connected to the loop of entity {pieces[0].handle}; draw one outline")
    return loop


def _snapped(loop: list[Piece]) -> list[Piece]:
    """One exact point per joint (:func:`engine.files.dxf_import.meeting_point`), lines moved to it."""
    pts = [meeting_point(loop[i - 1], loop[i])[0] for i in range(len(loop))]
    return [p.with_ends(pts[i], pts[(i + 1) % len(loop)]) if p.kind == "line" else p
            for i, p in enumerate(loop)]


def _signed_area(loop: list[Piece]) -> float:
    """Area (mm^2) enclosed by the loop, positive when it runs counter-clockwise: the shoelace
    over the joints plus each arc's circular segment, ``+`` for a ccw arc, ``-`` for a cw one."""
    area = 0.0
    for p in loop:
        area += 0.5 * (p.p0[0] * p.p1[1] - p.p1[0] * p.p0[1])
        if p.kind == "arc":
            a0 = math.atan2(p.p0[1] - p.center[1], p.p0[0] - p.center[0])
            a1 = math.atan2(p.p1[1] - p.center[1], p.p1[0] - p.center[0])
            sign = 1.0 if p.direction == "ccw" else -1.0
            sweep = ((a1 - a0) * sign) % (2 * math.pi)
            area += sign * 0.5 * p.radii[0] ** 2 * (sweep - math.sin(sweep))
    return area


def _counter_clockwise(loop: list[Piece]) -> list[Piece]:
    """The loop walked counter-clockwise, still starting with the drawing's first curve."""
    if _signed_area(loop) >= 0:
        return loop
    back = [p.reversed() for p in reversed(loop)]
    return back[-1:] + back[:-1]


def _as_dict(piece: Piece) -> dict:
    """A SPEC outline segment (mm) of a piece of the ccw loop; a cw arc bulges inwards."""
    if piece.kind == "line":
        return {"type": "line", "p0": list(piece.p0), "p1": list(piece.p1)}
    if piece.direction != "ccw":
        raise DxfImportError(f"entity {piece.handle} is an arc bulging into the outline: the outline "
                             f"is not convex (its arcs must all bulge outwards)")
    return {"type": "arc", "center": list(piece.center), "radius": piece.radii[0],
            "p0": list(piece.p0), "p1": list(piece.p1), "ccw": True}


def _in_drawing_words(exc: OutlineError, loop: list[Piece]) -> str:
    """``exc``'s message with the segment named by its DXF entity as well."""
    text = str(exc)
    if exc.index is None:
        if "origin" in text:
            text += "; the drawing's origin (0, 0) is the bottle's axis"
        return text
    if not 0 <= exc.index < len(loop):
        return text
    rest = text.split(": ", 1)[-1]  # (after "segment i")
    return f"entity {loop[exc.index].handle}, segment {exc.index} of the outline: {rest}"
