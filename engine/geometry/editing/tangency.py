"""Arcs tangent to their neighbours: how a segment becomes an arc between smooth joints.

Design rule: a single circular arc cannot start and end tangent to a straight segment it
replaces (its two end tangents would be equal), so the neighbours make room. The new arc has a
chosen radius; at each smooth joint the neighbour's shared end *slides along the neighbour's own
curve* (a line stays on its line, an arc on its circle) to the point where the new arc touches
it, so the neighbour keeps its other end, its curve and its other tangent; at a corner the end
point stays. The centre of such an arc lies on the neighbour's curve offset by the radius (a
parallel line, or a concentric circle), so it is an intersection of two lines or circles. Pure
functions (mm); ``ValueError`` with the reason when no arc of that radius fits.
"""
from __future__ import annotations

import math

from ..section import Section
from ..segments import Arc, EllipseArc, Line

#: Radii tried for a new arc, as multiples of the length of the segment it replaces: a gentle
#: arc first (radius four times the length: the middle moves about 1/32 of the length).
RADIUS_FACTORS = (4.0, 8.0, 2.0, 16.0, 1.0)


def _left(v):
    return (-v[1], v[0])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def _guide(seg):
    """What the neighbour's shared end may slide along: ``("line", point, unit direction)``,
    ``("circle", centre, radius, +1 ccw / -1 cw)``; ellipses cannot slide."""
    if isinstance(seg, Line):
        u = _sub(seg.p1, seg.p0)
        n = math.hypot(*u)
        return ("line", seg.p0, (u[0] / n, u[1] / n))
    if isinstance(seg, Arc):
        return ("circle", seg.center, seg.radius, 1.0 if seg.direction == "ccw" else -1.0)
    raise ValueError("its neighbour is an ellipse arc, which cannot slide along itself; make it "
                     "an arc first, or untick smooth at the joint between them")


def _centre_locus(guide, radius: float, sigma: float):
    """Where the centre of an arc of ``radius`` (``sigma`` +1 ccw, -1 cw) lies when it touches
    ``guide`` with the same walking direction."""
    if guide[0] == "point":
        return ("circle", guide[1], radius)
    if guide[0] == "line":
        _, q, u = guide
        n = _left(u)
        return ("line", (q[0] + sigma * radius * n[0], q[1] + sigma * radius * n[1]), u)
    _, c, r, s_n = guide
    return ("circle", c, abs(r - sigma * s_n * radius))


def _contact(guide, centre, radius: float, sigma: float):
    """The point where the arc about ``centre`` touches ``guide``."""
    if guide[0] == "point":
        return guide[1]
    if guide[0] == "line":
        n = _left(guide[2])
        return (centre[0] - sigma * radius * n[0], centre[1] - sigma * radius * n[1])
    _, c, r, s_n = guide
    k = r - sigma * s_n * radius
    if abs(k) < 1e-12:
        raise ValueError("the arc would be concentric with its neighbour")
    return (c[0] + (centre[0] - c[0]) * r / k, c[1] + (centre[1] - c[1]) * r / k)


def _intersect(a, b) -> list:
    """Intersection points of two loci (lines ``("line", p, u)``, circles ``("circle", c, r)``)."""
    if a[0] == "circle" and b[0] == "line":
        a, b = b, a
    if a[0] == "line" and b[0] == "line":
        (_, p, u), (_, q, v) = a, b
        det = u[0] * v[1] - u[1] * v[0]
        if abs(det) < 1e-12:
            return []
        t = ((q[0] - p[0]) * v[1] - (q[1] - p[1]) * v[0]) / det
        return [(p[0] + t * u[0], p[1] + t * u[1])]
    if a[0] == "line":
        (_, p, u), (_, c, r) = a, b
        t0 = _dot(_sub(c, p), u)
        foot = (p[0] + t0 * u[0], p[1] + t0 * u[1])
        h2 = r * r - _dot(_sub(c, foot), _sub(c, foot))
        if h2 < 0:
            return []
        h = math.sqrt(h2)
        return [(foot[0] + s * h * u[0], foot[1] + s * h * u[1]) for s in (-1.0, 1.0)]
    (_, c1, r1), (_, c2, r2) = a, b
    d = math.dist(c1, c2)
    if d < 1e-12 or d > r1 + r2 or d < abs(r1 - r2):
        return []
    x = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    h = math.sqrt(max(r1 * r1 - x * x, 0.0))
    e = ((c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d)
    base = (c1[0] + x * e[0], c1[1] + x * e[1])
    return [(base[0] + s * h * -e[1], base[1] + s * h * e[0]) for s in (-1.0, 1.0)]


def _slid(seg, new_point, at_end: bool):
    """``seg`` with its shared end slid along its own curve to ``new_point``."""
    p0, p1 = (seg.p0, new_point) if at_end else (new_point, seg.p1)
    if isinstance(seg, Line):
        return Line(p0, p1)
    return Arc(seg.center, seg.radius, p0, p1, seg.direction)


def _same_way(seg, new) -> bool:
    """The slid neighbour still runs the way it did (not reversed, not wrapped round)."""
    if new.length < 1e-6:
        return False
    if isinstance(seg, Line):
        return _dot(_sub(new.p1, new.p0), _sub(seg.p1, seg.p0)) > 0
    return abs(new.sweep) < math.pi * 1.9 and math.copysign(1, new.sweep) == math.copysign(1, seg.sweep)


def _tangent_ok(a, b) -> bool:
    ta, tb = a.tangent(1.0), b.tangent(0.0)
    return float(ta[0] * tb[0] + ta[1] * tb[1]) > 1.0 - 1e-9


def tangent_arc(section: Section, index: int, radius: float, direction: str) -> Section:
    """Segment ``index`` replaced by an arc of ``radius`` (mm) going ``direction``, tangent to
    each neighbour across a smooth joint (the neighbour slides along itself, see the module
    rule) and through the old end point at a corner. Raises ``ValueError`` when none fits."""
    segs = list(section.segments)
    old = segs[index]
    sigma = 1.0 if direction == "ccw" else -1.0
    smooth_before = index > 0 and section.smooth[index - 1]
    smooth_after = index < len(segs) - 1 and section.smooth[index]
    if smooth_before and index - 1 == 0 and not isinstance(segs[0], Line):
        raise ValueError("the punt's ring stays on z = 0, so the punt cannot slide")
    g0 = _guide(segs[index - 1]) if smooth_before else ("point", old.p0)
    g1 = _guide(segs[index + 1]) if smooth_after else ("point", old.p1)
    mid_old = tuple(float(v) for v in old.point(0.5))
    best = None
    for centre in _intersect(_centre_locus(g0, radius, sigma), _centre_locus(g1, radius, sigma)):
        try:
            x0, x1 = _contact(g0, centre, radius, sigma), _contact(g1, centre, radius, sigma)
            arc = Arc(centre, radius, x0, x1, direction)
            if abs(arc.sweep) >= math.pi or arc.length < 1e-6:
                continue
            trial = list(segs)
            trial[index] = arc
            if smooth_before:
                trial[index - 1] = _slid(segs[index - 1], x0, True)
                if not (_same_way(segs[index - 1], trial[index - 1]) and _tangent_ok(trial[index - 1], arc)):
                    continue
            if smooth_after:
                trial[index + 1] = _slid(segs[index + 1], x1, False)
                if not (_same_way(segs[index + 1], trial[index + 1]) and _tangent_ok(arc, trial[index + 1])):
                    continue
        except ValueError:
            continue
        off = math.dist(tuple(float(v) for v in arc.point(0.5)), mid_old)
        if best is None or off < best[0]:
            best = (off, trial)
    if best is None:
        raise ValueError(f"no {'convex' if sigma > 0 else 'concave'} arc of radius {radius:.4g} mm "
                         f"fits tangent to its neighbours")
    return Section(tuple(best[1]), section.smooth)


def arc_between_neighbours(section: Section, index: int) -> Section:
    """Segment ``index`` (a line or an ellipse arc) as a circular arc that keeps its smooth
    neighbours tangent. An ellipse arc tries its own mean radius first (an ellipse with equal
    radii becomes its circle, exactly); then convex before concave, each at the radii of
    :data:`RADIUS_FACTORS` times the segment's length. Raises ``ValueError`` naming why not."""
    seg = section.segments[index]
    radii = [factor * seg.length for factor in RADIUS_FACTORS]
    directions = ("ccw", "cw")
    if isinstance(seg, EllipseArc):
        radii.insert(0, math.sqrt(seg.radius_r * seg.radius_z))
        directions = (seg.direction, "cw" if seg.direction == "ccw" else "ccw")
    reasons = []
    for direction in directions:
        for radius in radii:
            try:
                return tangent_arc(section, index, radius, direction)
            except ValueError as exc:
                reasons.append(str(exc))
    raise ValueError(reasons[0])


def equal_radii_ellipse(arc: Arc) -> EllipseArc:
    """The ellipse arc with both radii equal to ``arc``'s radius: the same curve (exact)."""
    return EllipseArc(arc.center, arc.radius, arc.radius, arc.p0, arc.p1, arc.direction)
