"""Editing a plan outline: the geometry behind the plan editor's drags, typed values and corners.

Design rule: every edit is a pure function of frozen values (``PlanOutline -> PlanOutline``,
normalised units of the outline it edits) whose result is built by
:meth:`~engine.geometry.plan.PlanOutline.from_dicts`, so it is a valid outline or an
``OutlineError`` saying why not: a drag that would make the outline concave, clockwise or
self-crossing is refused in SPEC_outline's words and nothing is changed. The result is
normalised again (its farthest point at 1), so its ``scale`` is its unit measured in the old
outline's units; :func:`with_plan` multiplies the bottle's core by it, and the millimetres of
every joint the edit did not move stay as they were.

Symmetry is an option of every edit: ``n`` (rotations by ``360/n`` deg) and ``mirror``
(reflection in the y axis) generate a group, and the edit is applied to the images of the
grabbed joint or segment under it (a joint on a mirror line stays on it). An outline that lacks
the symmetry asked for is refused, naming the joint with no image.

A moved joint drags its neighbours: a line follows with its end; an arc bends to it and keeps
its tangent at its other end (pulling a smooth joint outwards makes a convex corner there,
pushing it in is refused); an arc whose two ends both move keeps the angle it sweeps (so a
rigid move stays rigid). Corners: a sharp corner between
two lines rounds into a tangent arc, such an arc sharpens back into the lines' meeting point,
and its radius changes with both tangencies kept. No Qt.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from ...errors import OutlineError
from .. import plan as pl
from ..plan import ANGLE_TOL, PlanArc, PlanLine, PlanOutline
from .curves import scaled_radially

#: Two points closer than this (normalised units) are the same joint when images are matched.
SAME_POINT = 1e-7


# --------------------------------------------------------------------------- symmetry
def _group(n: int, mirror: bool) -> list[np.ndarray]:
    """The 2 x 2 matrices of the group of ``n`` rotations (and with ``mirror`` the reflections
    ``x -> -x`` composed with them), the identity first."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise OutlineError(None, f"n-fold symmetry needs a whole number n >= 1, got {n!r}")
    rots = [np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
            for a in (2 * math.pi * j / n for j in range(n))]
    flip = np.array([[-1.0, 0.0], [0.0, 1.0]])
    return rots + ([r @ flip for r in rots] if mirror else [])


def _symmetry_words(n: int, mirror: bool) -> str:
    return " and ".join(w for w in ((f"{n}-fold" if n > 1 else ""), ("mirror" if mirror else "")) if w)


def _find(points, p) -> int | None:
    for j, q in enumerate(points):
        if math.hypot(q[0] - p[0], q[1] - p[1]) <= SAME_POINT:
            return j
    return None


def joints(plan: PlanOutline) -> tuple[tuple[float, float], ...]:
    """The joints of ``plan``: joint ``i`` is where segment ``i`` starts (normalised)."""
    return tuple(s.p0 for s in plan.segments)


def _images(what: str, index: int, n: int, mirror: bool, image_of) -> list[tuple[int, np.ndarray]]:
    """``(j, g)`` per element ``g`` of the group, ``j = image_of(g)``, each ``j`` once."""
    out, seen = [], set()
    for g in _group(n, mirror):
        j = image_of(g)
        if j is None:
            raise OutlineError(index, f"the outline is not {_symmetry_words(n, mirror)} symmetric: {what} {index} "
                                      "has no image; turn the symmetry off")
        if j not in seen:
            seen.add(j)
            out.append((j, g))
    return out


def joint_images(plan: PlanOutline, index: int, n: int = 1, mirror: bool = False) -> list[tuple[int, np.ndarray]]:
    """``(joint, g)`` for each element ``g`` of the symmetry group: the joint at ``g`` (joint
    ``index``), the identity first, each joint once. ``OutlineError`` when an image is no joint."""
    pts = joints(plan)
    return _images("joint", index, n, mirror, lambda g: _find(pts, g @ np.array(pts[index])))


def segment_images(plan: PlanOutline, index: int, n: int = 1, mirror: bool = False) -> list[tuple[int, np.ndarray]]:
    """As :func:`joint_images` for segment ``index`` (a reflection walks a segment backwards)."""
    segs = plan.segments

    def image_of(g):
        a, b = g @ np.array(segs[index].p0), g @ np.array(segs[index].p1)
        if np.linalg.det(g) < 0:
            a, b = b, a
        return next((j for j, s in enumerate(segs) if s.kind == segs[index].kind
                     and _find([s.p0], a) == 0 and _find([s.p1], b) == 0), None)
    return _images("segment", index, n, mirror, image_of)


def _fixed(g: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``p`` projected onto the points a reflection ``g`` keeps (its mirror line)."""
    w, v = np.linalg.eigh(g)  # a reflection is symmetric: eigenvalues -1 and +1
    axis = v[:, int(np.argmax(w))]
    return axis * float(axis @ p)


def _constrained(plan: PlanOutline, index: int, to, n: int, mirror: bool, exact: bool) -> np.ndarray:
    """``to`` kept on the mirror line of a reflection of the group that maps joint ``index`` to
    itself (a joint on it stays on it): projected, or with ``exact`` refused when it is off it."""
    to, p = np.array(to, float), np.array(plan.segments[index].p0)
    for g in _group(n, mirror):
        if np.linalg.det(g) < 0 and np.hypot(*(g @ p - p)) <= SAME_POINT:
            on = _fixed(g, to)
            if exact and np.hypot(*(on - to)) > SAME_POINT:
                raise OutlineError(index, "this joint lies on a mirror line and the symmetry keeps it there")
            to = on
    return to


# --------------------------------------------------------------------------- building
def _arc_through(p0, p1, sweep: float) -> dict:
    """The ccw arc dictionary from ``p0`` to ``p1`` sweeping ``sweep`` (rad, in (0, 2 pi))."""
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    chord = math.hypot(dx, dy)
    if chord <= 0:
        raise OutlineError(None, "an arc's two ends would coincide")
    r = chord / (2 * math.sin(sweep / 2))
    f = r * math.cos(sweep / 2) / chord  # why: the centre lies left of the chord for sweep < pi
    centre = [(p0[0] + p1[0]) / 2 - dy * f, (p0[1] + p1[1]) / 2 + dx * f]
    return {"type": "arc", "center": centre, "radius": r, "p0": list(p0), "p1": list(p1), "ccw": True}


def _arc_bent(arc: PlanArc, index: int, p0, p1, fixed_end: int) -> dict:
    """The ccw arc from ``p0`` to ``p1`` tangent to ``arc`` at its unmoved end ``fixed_end``
    (0: ``p0``, 1: ``p1``): its centre slides along that end's radius to ``s`` from it, with
    ``|p - q|^2 = 2 s (p - q) . u`` for the moved end ``p``, the fixed one ``q`` and the unit
    ``u`` from ``q`` towards the old centre."""
    q, p = (p0, p1) if fixed_end == 0 else (p1, p0)
    u = np.subtract(arc.center, q) / arc.radius
    d = np.subtract(p, q)
    dn = float(d @ u)
    if dn <= 1e-12 * max(float(np.hypot(*d)), 1e-300):
        raise OutlineError(index, "the arc cannot bend to reach the moved joint and stay tangent at its other end "
                                  "(the joint would lie outside the arc's tangent there)")
    s = float(d @ d) / (2 * dn)
    centre = np.array(q) + s * u
    return {"type": "arc", "center": list(centre), "radius": s, "p0": list(p0), "p1": list(p1), "ccw": True}


def _rebuilt(plan: PlanOutline, new_joints: dict) -> PlanOutline:
    """``plan`` with joints moved (index -> point): a line follows its ends; an arc with one
    end moved bends to it, keeping its tangent at the other end (a smooth joint stays smooth
    there); an arc with both ends moved keeps the angle it sweeps (a rigid move stays rigid)."""
    pts = [tuple(float(v) for v in new_joints.get(i, p)) for i, p in enumerate(joints(plan))]
    m, out = len(pts), []
    for i, s in enumerate(plan.segments):
        p0, p1 = pts[i], pts[(i + 1) % m]
        moved = (i in new_joints, (i + 1) % m in new_joints)
        if s.kind == "line":
            out.append({"type": "line", "p0": list(p0), "p1": list(p1)})
        elif all(moved):
            out.append(_arc_through(p0, p1, s.sweep))
        elif any(moved):
            out.append(_arc_bent(s, i, p0, p1, fixed_end=1 if moved[0] else 0))
        else:
            out.append(s.to_dict())
    return PlanOutline.from_dicts(out)


def move_joint(plan: PlanOutline, index: int, to, n: int = 1, mirror: bool = False,
               exact: bool = False) -> PlanOutline:
    """``plan`` with joint ``index`` at ``to`` (normalised) and its symmetry images at theirs.
    A joint on a mirror line stays on it (projected; with ``exact``, a point off it is refused)."""
    images = joint_images(plan, index, n, mirror)
    to = _constrained(plan, index, to, n, mirror, exact)
    return _rebuilt(plan, {j: g @ to for j, g in images})


def _arc(plan: PlanOutline, index: int) -> PlanArc:
    seg = plan.segments[index]
    if seg.kind != "arc":
        raise OutlineError(index, "this segment is a line and has no centre or radius")
    return seg


def _with_arcs(plan: PlanOutline, index: int, n: int, mirror: bool, new_arc) -> PlanOutline:
    """``plan`` with arc ``index`` replaced by ``new_arc(arc)`` (a dictionary) and each symmetry
    image by the image of that dictionary."""
    base = new_arc(_arc(plan, index))
    items = [s.to_dict() for s in plan.segments]
    for j, g in segment_images(plan, index, n, mirror):
        c = g @ np.array(base["center"])
        a, b = g @ np.array(base["p0"]), g @ np.array(base["p1"])
        if np.linalg.det(g) < 0:
            a, b = b, a
        items[j] = {**base, "center": list(c), "p0": list(a), "p1": list(b)}
    return PlanOutline.from_dicts(items)


def _bisector(arc: PlanArc):
    """Midpoint and unit left normal of the chord ``p0 -> p1``."""
    dx, dy = arc.p1[0] - arc.p0[0], arc.p1[1] - arc.p0[1]
    chord = math.hypot(dx, dy)
    return np.array([(arc.p0[0] + arc.p1[0]) / 2, (arc.p0[1] + arc.p1[1]) / 2]), np.array([-dy, dx]) / chord, chord


def _arc_with_centre(arc: PlanArc, centre) -> dict:
    return {"type": "arc", "center": [float(centre[0]), float(centre[1])],
            "radius": math.hypot(arc.p0[0] - centre[0], arc.p0[1] - centre[1]),
            "p0": list(arc.p0), "p1": list(arc.p1), "ccw": True}


def move_arc_centre(plan: PlanOutline, index: int, to, n: int = 1, mirror: bool = False) -> PlanOutline:
    """``plan`` with arc ``index``'s centre moved towards ``to`` (normalised) along the chord's
    perpendicular bisector (the ends stay, so the centre cannot leave it): its radius changes."""
    def new(arc):
        mid, left, _ = _bisector(arc)
        return _arc_with_centre(arc, mid + left * float(left @ (np.array(to, float) - mid)))
    return _with_arcs(plan, index, n, mirror, new)


def place_arc_centre(plan: PlanOutline, index: int, axis: int, value: float, n: int = 1,
                     mirror: bool = False) -> PlanOutline:
    """``plan`` with arc ``index``'s centre coordinate ``axis`` (0: x, 1: y) exactly ``value``
    (normalised), the other solved on the chord's bisector; refused where the bisector runs
    along that coordinate's line."""
    def new(arc):
        mid, left, _ = _bisector(arc)
        if abs(left[axis]) < 1e-9:
            raise OutlineError(index, f"the centre must stay on the perpendicular bisector of the arc's "
                                      f"ends, {'x' if axis == 0 else 'y'} = {mid[axis]:.6g} all along")
        return _arc_with_centre(arc, mid + left * (value - mid[axis]) / left[axis])
    return _with_arcs(plan, index, n, mirror, new)


def is_fillet(plan: PlanOutline, index: int) -> bool:
    """Whether segment ``index`` is an arc between two lines, tangent to both (a rounded corner)."""
    segs, m = plan.segments, len(plan.segments)
    seg, before, after = segs[index], segs[index - 1], segs[(index + 1) % m]
    if seg.kind != "arc" or before.kind != "line" or after.kind != "line":
        return False
    turns = plan._joint_turns
    return turns[index] == 0 and turns[(index + 1) % m] == 0


def is_sharp_corner(plan: PlanOutline, index: int) -> bool:
    """Whether joint ``index`` is a sharp corner between two lines (one that can be rounded)."""
    segs = plan.segments
    return plan._joint_turns[index] > 0 and segs[index].kind == "line" and segs[index - 1].kind == "line"


def _meeting(a: PlanLine, b: PlanLine) -> np.ndarray:
    """Where the lines through ``a`` and ``b`` cross."""
    da, db = np.subtract(a.p1, a.p0), np.subtract(b.p1, b.p0)
    den = da[0] * db[1] - da[1] * db[0]
    if abs(den) < 1e-12:
        raise OutlineError(None, "the two sides are parallel and never meet in a corner")
    t = ((b.p0[0] - a.p0[0]) * db[1] - (b.p0[1] - a.p0[1]) * db[0]) / den
    return np.array(a.p0) + t * da


def _rounded(items: list[dict], index: int, radius: float) -> list[dict]:
    """The dictionaries with the sharp line-line corner at joint ``index`` rounded by ``radius``."""
    a, b = items[index - 1], items[index]
    v = np.array(b["p0"], float)
    ea, eb = np.subtract(a["p1"], a["p0"]), np.subtract(b["p1"], b["p0"])
    la, lb = np.hypot(*ea), np.hypot(*eb)
    ea, eb = ea / la, eb / lb
    alpha = math.atan2(ea[0] * eb[1] - ea[1] * eb[0], float(ea @ eb))
    if not ANGLE_TOL < alpha < math.pi:
        raise OutlineError(index, "this joint is no sharp corner to round")
    d = radius * math.tan(alpha / 2)
    room = min(la, lb)
    if d >= room * (1 - 1e-9):
        raise OutlineError(index, f"a radius of {radius:.6g} needs {d:.6g} of each side, and a side "
                                  f"here is only {room:.6g} long (largest radius {room / math.tan(alpha / 2):.6g})")
    t0, t1 = v - d * ea, v + d * eb
    centre = t0 + radius * np.array([-ea[1], ea[0]])
    arc = {"type": "arc", "center": list(centre), "radius": radius, "p0": list(t0), "p1": list(t1), "ccw": True}
    out = list(items)
    out[index - 1] = {**a, "p1": list(t0)}
    out[index] = {**b, "p0": list(t1)}
    return out[:index] + [arc] + out[index:]  # at 0: before segment 0, after the last


def _sharpened(items: list[dict], index: int) -> list[dict]:
    """The dictionaries with the arc ``index`` between two lines replaced by their meeting point."""
    m = len(items)
    a, b = items[index - 1], items[(index + 1) % m]
    v = list(_meeting(PlanLine(tuple(a["p0"]), tuple(a["p1"])), PlanLine(tuple(b["p0"]), tuple(b["p1"]))))
    out = list(items)
    out[index - 1] = {**a, "p1": v}
    out[(index + 1) % m] = {**b, "p0": v}
    del out[index]
    return out


def _apply_each(plan, indices, step) -> PlanOutline:
    """``step(items, i)`` at each of ``indices``, highest first (an earlier index stays valid)."""
    items = [s.to_dict() for s in plan.segments]
    for i in sorted(indices, reverse=True):
        items = step(items, i)
    return PlanOutline.from_dicts(items)


def round_corner(plan: PlanOutline, index: int, radius: float, n: int = 1, mirror: bool = False) -> PlanOutline:
    """``plan`` with the sharp corner at joint ``index`` (between two lines) and its images
    rounded by a tangent arc of ``radius`` (normalised)."""
    if not is_sharp_corner(plan, index):
        raise OutlineError(index, "only a sharp corner between two lines can be rounded")
    if not (math.isfinite(radius) and radius > 0):
        raise OutlineError(index, f"a corner's radius must be positive, got {radius:g}")
    return _apply_each(plan, [j for j, _ in joint_images(plan, index, n, mirror)],
                       lambda items, i: _rounded(items, i, radius))


def sharpen_corner(plan: PlanOutline, index: int, n: int = 1, mirror: bool = False) -> PlanOutline:
    """``plan`` with the arc ``index`` between two lines (and its images) replaced by the sharp
    corner where the lines meet."""
    segs = plan.segments
    if segs[index].kind != "arc" or segs[index - 1].kind != "line" or segs[(index + 1) % len(segs)].kind != "line":
        raise OutlineError(index, "only an arc between two lines can become a sharp corner")
    return _apply_each(plan, [j for j, _ in segment_images(plan, index, n, mirror)], _sharpened)


def set_arc_radius(plan: PlanOutline, index: int, radius: float, n: int = 1, mirror: bool = False) -> PlanOutline:
    """``plan`` with arc ``index`` (and its images) of ``radius`` (normalised): a rounded corner
    (:func:`is_fillet`) stays tangent to its two sides (its ends slide along them); any other
    arc keeps its ends and its centre moves along their bisector."""
    arc = _arc(plan, index)
    if not (math.isfinite(radius) and radius > 0):
        raise OutlineError(index, f"an arc's radius must be positive, got {radius:g}")
    if is_fillet(plan, index):
        def step(items, i):
            items = _sharpened(items, i)
            return _rounded(items, i % len(items), radius)
        return _apply_each(plan, [j for j, _ in segment_images(plan, index, n, mirror)], step)

    def new(arc):
        mid, left, chord = _bisector(arc)
        if radius < chord / 2 * (1 - 1e-12):
            raise OutlineError(index, f"the arc's ends are {chord:.6g} apart: its radius must be at least {chord / 2:.6g}")
        side = 1.0 if arc.sweep <= math.pi else -1.0
        return _arc_with_centre(arc, mid + left * side * math.sqrt(max(radius * radius - chord * chord / 4, 0.0)))
    return _with_arcs(plan, index, n, mirror, new)


# --------------------------------------------------------------------------- presets
#: The plan editor's presets, in its order: name -> the outline (normalised; circumradius 1).
PRESETS = {
    "triangle": pl.triangle,
    "square": pl.square,
    "hexagon": pl.hexagon,
    "octagon": pl.octagon,
    "flask": lambda: pl.flask(100.0, 40.0),
    "shield": pl.shield,
}


def preset(name: str) -> PlanOutline:
    """The preset outline called ``name`` (:data:`PRESETS`)."""
    try:
        return PRESETS[name]()
    except KeyError:
        raise OutlineError(None, f"no preset outline {name!r} (expected one of {', '.join(PRESETS)})") from None


# --------------------------------------------------------------------------- the bottle
def with_plan(shape, plan: PlanOutline, factor: float = 1.0):
    """``shape`` (an outline bottle) with ``plan`` and its core section's radii times ``factor``
    (an edit's ``plan.scale``: the old unit in the new one), so ``k P`` keeps its millimetres. A
    radially scaled arc of the core becomes an ellipse arc (the same curve)."""
    if shape.cross_section != "outline":
        raise OutlineError(None, f"a {shape.cross_section} bottle has no plan outline to edit")
    plan = dataclasses.replace(plan, scale=1.0)
    sections = shape.sections
    if abs(factor - 1.0) > 1e-12:
        sections = tuple((name, scaled_radially(sec, factor) if name == "core" else sec) for name, sec in sections)
    return dataclasses.replace(shape, sections=sections, plan=plan)
