"""Plan outlines of "special shape" bottles: a convex chain of lines and arcs, offset exactly.

Design rule (../shared/oracle/SPEC_outline.md): a bottle's horizontal outer section at height
``z`` is ``O(z) = k(z) P (+) disc(c(z))`` and its cavity section ``I(z) = {q : sd(q, k P) <= t}``,
``t = c - w``, for one convex, counter-clockwise outline ``P`` of lines and circular arcs (sharp
corners allowed). ``P`` is normalised: its farthest point from the origin is at distance 1, so
``k`` and ``c`` are millimetres and ``P`` has no unit. Everything here is exact geometry: the
sections are returned as exact pieces (lines and arcs), areas and perimeters in closed form
(Steiner's polynomial outside; the shoelace with circular-segment terms for the inner parallel
set), the signed distance from the support function ``h`` of ``P``::

    sd(q, K) = max over unit u of (q . u - h_K(u))      (convex K; negative inside, exact both sides)

which splits into one closed-form maximum per line, arc and corner of ``P``. ``PlanOutline`` is
an immutable, hashable value built only by :meth:`PlanOutline.from_dicts` (or a preset, which
goes through it), so every outline in the program has passed SPEC_outline section 2's rules.
No Qt, no numba; float64 throughout.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..errors import OutlineError, shown

TWO_PI = 2.0 * math.pi
#: Length tolerance of SPEC_outline section 2, as a fraction of ``R`` (so: normalised units).
TOL = 1e-6
#: Angle tolerance (rad) of SPEC_outline section 2: a joint turning less is smooth (G1).
ANGLE_TOL = 1e-6
#: Most segments an outline may have (a hostile file must not make us loop for long).
MAX_SEGMENTS = 256
#: Smallest disc (mm radius) the cavity must hold at every height (SPEC_outline section 5).
CAVITY_MARGIN_MM = 1.0
#: An ``R`` this close to 1 is taken as 1, so a normalised outline reads back bit for bit.
_UNIT_SLACK = 8 * np.finfo(float).eps


def _u(theta):
    """Unit vector(s) ``(cos theta, sin theta)`` (scalars or arrays)."""
    return np.cos(theta), np.sin(theta)


# --------------------------------------------------------------------------- values
@dataclass(frozen=True)
class PlanLine:
    """Straight plan segment from ``p0`` to ``p1`` (normalised, or mm for a section piece)."""

    p0: tuple[float, float]
    p1: tuple[float, float]
    kind = "line"

    @property
    def length(self) -> float:
        return math.hypot(self.p1[0] - self.p0[0], self.p1[1] - self.p0[1])

    @property
    def normal(self) -> tuple[float, float]:
        """Outward unit normal: the direction turned clockwise by 90 deg (interior on the left)."""
        ex, ey = self.p1[0] - self.p0[0], self.p1[1] - self.p0[1]
        n = math.hypot(ex, ey)
        return (ey / n, -ex / n)

    def to_dict(self, scale: float = 1.0) -> dict:
        return {"type": "line", "p0": [self.p0[0] * scale, self.p0[1] * scale],
                "p1": [self.p1[0] * scale, self.p1[1] * scale]}


@dataclass(frozen=True)
class PlanArc:
    """Counter-clockwise plan arc about ``center`` of ``radius`` from ``p0`` to ``p1``; it spans
    the angle ``sweep`` in ``(0, 2 pi)`` (the ccw way round from ``p0`` to ``p1``)."""

    center: tuple[float, float]
    radius: float
    p0: tuple[float, float]
    p1: tuple[float, float]
    kind = "arc"

    @property
    def theta0(self) -> float:
        """Polar angle (rad) of ``p0`` about the centre: also the outward normal's angle there."""
        return math.atan2(self.p0[1] - self.center[1], self.p0[0] - self.center[0])

    @property
    def sweep(self) -> float:
        a1 = math.atan2(self.p1[1] - self.center[1], self.p1[0] - self.center[0])
        return (a1 - self.theta0) % TWO_PI

    @property
    def theta1(self) -> float:
        return self.theta0 + self.sweep

    @property
    def length(self) -> float:
        return self.radius * self.sweep

    def to_dict(self, scale: float = 1.0) -> dict:
        return {"type": "arc", "center": [self.center[0] * scale, self.center[1] * scale],
                "radius": self.radius * scale, "p0": [self.p0[0] * scale, self.p0[1] * scale],
                "p1": [self.p1[0] * scale, self.p1[1] * scale], "ccw": True}


@dataclass(frozen=True)
class ArcPiece:
    """A boundary arc of a section (mm): ``center + radius (cos a, sin a)`` for ``a`` from
    ``theta0`` up to ``theta1`` (``theta1 > theta0``; the outward normal is the radius)."""

    center: tuple[float, float]
    radius: float
    theta0: float
    theta1: float
    kind = "arc"

    def point(self, theta) -> tuple[float, float]:
        return (self.center[0] + self.radius * math.cos(theta),
                self.center[1] + self.radius * math.sin(theta))

    @property
    def p0(self) -> tuple[float, float]:
        return self.point(self.theta0)

    @property
    def p1(self) -> tuple[float, float]:
        return self.point(self.theta1)

    @property
    def length(self) -> float:
        return self.radius * (self.theta1 - self.theta0)


@dataclass(frozen=True)
class Corner:
    """A sharp joint of ``P`` where segment ``index`` starts: vertex ``V``, the outward normal
    jumps from ``n_in`` to ``n_out``, turning counter-clockwise by ``alpha`` in ``(0, pi)``."""

    index: int
    vertex: tuple[float, float]
    n_in: tuple[float, float]
    n_out: tuple[float, float]
    alpha: float


Piece = PlanLine | ArcPiece


# --------------------------------------------------------------------------- reading
_FIELDS = {"line": ("p0", "p1"), "arc": ("center", "radius", "p0", "p1", "ccw")}


def _number(value, what: str, index: int) -> float:
    """``value`` as a finite float, or ``OutlineError`` (bools and strings are not numbers)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise OutlineError(index, f"{what} must be a number, got {shown(value)}")
    try:
        x = float(value)
    except (OverflowError, ValueError):
        x = math.nan
    if not math.isfinite(x):
        raise OutlineError(index, f"{what} must be a finite number, got {shown(value)}")
    return x


def _point(value, what: str, index: int) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise OutlineError(index, f"{what} must be two numbers [x, y], got {shown(value)}")
    return (_number(value[0], what, index), _number(value[1], what, index))


def _parse(index: int, d) -> PlanLine | PlanArc:
    """One SPEC segment dictionary as a segment in the file's units (no geometry checked yet)."""
    if not isinstance(d, dict):
        raise OutlineError(index, f"a segment must be an object, got {type(d).__name__}")
    kind = d.get("type")
    if not isinstance(kind, str) or kind not in _FIELDS:
        raise OutlineError(index, f"unknown segment type {shown(kind)} (expected line or arc)")
    fields = _FIELDS[kind]
    missing = [f for f in fields if f not in d and f != "ccw"]
    if missing:
        raise OutlineError(index, f"the {kind} lacks {', '.join(missing)}")
    unknown = [k for k in d if k != "type" and k not in fields]
    if unknown:
        raise OutlineError(index, f"the {kind} has unknown field(s) {', '.join(shown(k, 30) for k in unknown[:3])}")
    p0, p1 = _point(d["p0"], "p0", index), _point(d["p1"], "p1", index)
    if kind == "line":
        return PlanLine(p0, p1)
    if d.get("ccw", True) is not True:
        raise OutlineError(index, f"ccw is {shown(d.get('ccw'))}: a clockwise arc bulges inwards, "
                                  "and a convex outline has counter-clockwise arcs only (ccw: true)")
    radius = _number(d["radius"], "radius", index)
    if radius <= 0:
        raise OutlineError(index, f"the arc radius must be positive, got {shown(d['radius'])}")
    return PlanArc(_point(d["center"], "center", index), radius, p0, p1)


def _reach(seg: PlanLine | PlanArc) -> float:
    """Largest distance from the origin to a point of ``seg`` (an arc's may be inside it)."""
    far = max(math.hypot(*seg.p0), math.hypot(*seg.p1))
    if seg.kind == "arc":
        c = math.hypot(*seg.center)
        if c > 0 and (math.atan2(seg.center[1], seg.center[0]) - seg.theta0) % TWO_PI <= seg.sweep:
            far = max(far, c + seg.radius)
    return far


def _scaled(seg, r: float):
    """``seg`` with every coordinate and radius divided by ``r``."""
    p0, p1 = (seg.p0[0] / r, seg.p0[1] / r), (seg.p1[0] / r, seg.p1[1] / r)
    if seg.kind == "line":
        return PlanLine(p0, p1)
    return PlanArc((seg.center[0] / r, seg.center[1] / r), seg.radius / r, p0, p1)


def _normalised(segs: list) -> tuple[list, float]:
    """``(segments / R, R)`` with ``R`` the chain's reach; an ``R`` within rounding of 1 is 1."""
    r = max(_reach(s) for s in segs)
    if not (math.isfinite(r) and r > 0):
        raise OutlineError(None, f"the outline has no usable size (farthest point {shown(r)} from the origin)")
    if abs(r - 1.0) <= _UNIT_SLACK:
        return list(segs), 1.0
    return [_scaled(s, r) for s in segs], r


def _check_closed(segs: list, scale: float) -> None:
    """SPEC_outline rule 1: each segment starts where the previous one ends (cyclically)."""
    for i, s in enumerate(segs):
        prev = segs[i - 1]
        gap = math.hypot(s.p0[0] - prev.p1[0], s.p0[1] - prev.p1[1])
        if gap > TOL:
            last = " (the last)" if i == 0 else ""
            raise OutlineError(i, f"starts {gap * scale:.6g} from where segment {(i - 1) % len(segs)}{last} "
                                  "ends (the chain must be closed)")


def _check_on_circle(segs: list, scale: float) -> None:
    """SPEC_outline rule 2: arc end points lie on their circle."""
    for i, s in enumerate(segs):
        if s.kind != "arc":
            continue
        for name, p in (("p0", s.p0), ("p1", s.p1)):
            off = abs(math.hypot(p[0] - s.center[0], p[1] - s.center[1]) - s.radius)
            if off > TOL:
                raise OutlineError(i, f"{name} lies {off * scale:.6g} off the arc's circle")


def _snapped(segs: list) -> list:
    """The chain made exactly closed: a joint next to one arc takes the arc's end point (the
    line moves, the arc keeps its exact ends); otherwise the midpoint of the two ends. Idempotent."""
    m = len(segs)
    joint = []
    for i in range(m):
        a, b = segs[i], segs[(i + 1) % m]
        if a.kind == "arc" and b.kind != "arc":
            joint.append(a.p1)
        elif b.kind == "arc" and a.kind != "arc":
            joint.append(b.p0)
        else:
            joint.append(((a.p1[0] + b.p0[0]) / 2, (a.p1[1] + b.p0[1]) / 2))
    out = []
    for i, s in enumerate(segs):
        p0, p1 = joint[i - 1], joint[i]
        out.append(PlanLine(p0, p1) if s.kind == "line" else PlanArc(s.center, s.radius, p0, p1))
    return out


def _end_normals(seg) -> tuple[tuple[float, float], tuple[float, float]]:
    """Outward unit normals at the start and the end of ``seg``."""
    if seg.kind == "line":
        return seg.normal, seg.normal
    return (math.cos(seg.theta0), math.sin(seg.theta0)), (math.cos(seg.theta1), math.sin(seg.theta1))


def _turns(segs: list) -> list[float]:
    """Turn (rad, ccw positive, in (-pi, pi]) at the joint where segment ``i`` starts."""
    out = []
    for i, s in enumerate(segs):
        n_in, n_out = _end_normals(segs[i - 1])[1], _end_normals(s)[0]
        out.append(math.atan2(n_in[0] * n_out[1] - n_in[1] * n_out[0], n_in[0] * n_out[0] + n_in[1] * n_out[1]))
    return out


def _check_convex(segs: list) -> None:
    """SPEC_outline rule 3: no zero-length segment, every joint turns left by [0, pi), and the
    arcs and corners turn by 360 deg in all (convex, counter-clockwise, winding once)."""
    for i, s in enumerate(segs):
        if math.hypot(s.p1[0] - s.p0[0], s.p1[1] - s.p0[1]) <= TOL:
            raise OutlineError(i, "its two ends coincide (a segment needs a length; an arc spans less than 360 deg)")
    turns = _turns(segs)
    for i, turn in enumerate(turns):
        if turn < -ANGLE_TOL:
            raise OutlineError(i, f"the outline turns right by {math.degrees(-turn):.6g} deg where this segment "
                                  "starts (not convex; list the segments counter-clockwise)")
        if turn > math.pi - ANGLE_TOL:
            raise OutlineError(i, "the outline turns back on itself where this segment starts (a 180 deg corner)")
    total = sum(turns) + sum(s.sweep for s in segs if s.kind == "arc")
    if abs(total - TWO_PI) > ANGLE_TOL:
        raise OutlineError(None, f"the outline turns {math.degrees(total):.6g} deg in all, not 360 "
                                 "(it must wind once round, counter-clockwise)")


def _read(items) -> tuple[list, float]:
    """The validated, normalised segments of a SPEC outline block and the mm factor ``R``."""
    if not isinstance(items, (list, tuple)):
        raise OutlineError(None, f"an outline must be a list of segments, got {type(items).__name__}")
    if not 2 <= len(items) <= MAX_SEGMENTS:
        raise OutlineError(None, f"an outline needs 2 to {MAX_SEGMENTS} segments, got {len(items)}")
    segs, r0 = _normalised([_parse(i, d) for i, d in enumerate(items)])
    _check_closed(segs, r0)
    _check_on_circle(segs, r0)
    segs = _snapped(segs)
    _check_convex(segs)
    segs, r1 = _normalised(segs)  # why: snapping may move the farthest point by up to TOL
    return segs, r0 * r1


# --------------------------------------------------------------------------- the outline
@dataclass(frozen=True)
class PlanOutline:
    """A valid, normalised plan outline ``P`` (SPEC_outline section 2).

    ``segments`` is the closed, convex, counter-clockwise chain, exactly closed (each segment
    starts at the previous one's end) with its farthest point at distance 1 from the origin.
    ``scale`` is the ``R`` (file units per unit) it was read at: informational, so it takes no
    part in equality or hashing. Build it with :meth:`from_dicts` or a preset, never directly.
    """

    segments: tuple[PlanLine | PlanArc, ...]
    scale: float = field(default=1.0, compare=False)

    # ------------------------------------------------------------------ dictionaries
    @classmethod
    def from_dicts(cls, items) -> "PlanOutline":
        """Read a SPEC outline block (a list of ``{"type": "line" | "arc", ...}``), validate it
        (SPEC_outline section 2, rules 1-5) and normalise it; ``OutlineError`` names the segment
        and the rule. An arc's ``ccw`` may be left out (it can only be ``true``)."""
        segs, r = _read(items)
        outline = cls(tuple(segs), r)
        inside = -float(outline.signed_distance(0.0, 0.0, 1.0, 0.0)[0])
        if inside <= TOL:
            where = "on the boundary" if inside > -TOL else f"{-inside * r:.6g} outside"
            raise OutlineError(None, f"the origin must lie strictly inside the outline (it is {where})")
        return outline

    def to_dicts(self, scale: float = 1.0) -> list[dict]:
        """The SPEC outline block (normalised; times ``scale``, e.g. ``self.scale`` for the file's
        units). ``from_dicts(o.to_dicts()) == o`` bit for bit."""
        return [s.to_dict(scale) for s in self.segments]

    # ------------------------------------------------------------------ derived geometry of P
    @cached_property
    def _lines(self) -> tuple:
        """``(index, n, h)`` per line: outward unit normal and support value ``h = n . p0 > 0``."""
        out = []
        for i, s in enumerate(self.segments):
            if s.kind == "line":
                n = s.normal
                out.append((i, n, n[0] * s.p0[0] + n[1] * s.p0[1]))
        return tuple(out)

    @cached_property
    def _joint_turns(self) -> tuple[float, ...]:
        """Turn (rad) where segment ``i`` starts, in ``[0, pi)``; a smooth joint turns 0."""
        return tuple(t if t > ANGLE_TOL else 0.0 for t in _turns(list(self.segments)))

    @cached_property
    def corners(self) -> tuple[Corner, ...]:
        """The sharp joints of ``P`` (exterior angle ``alpha > 1e-6`` rad), in chain order."""
        out = []
        for i, s in enumerate(self.segments):
            if self._joint_turns[i] > 0:
                n_in, n_out = _end_normals(self.segments[i - 1])[1], _end_normals(s)[0]
                out.append(Corner(i, s.p0, n_in, n_out, self._joint_turns[i]))
        return tuple(out)

    @cached_property
    def _fans(self) -> tuple:
        """``(center, radius, theta0, sweep, seg_or_None)`` for every arc and corner of ``P``:
        where ``h(u) = C . u + radius`` on its normal range ``[theta0, theta0 + sweep]``. With the
        lines' normals these ranges cover every direction once."""
        out = []
        for i, s in enumerate(self.segments):
            if self._joint_turns[i] > 0:
                n_in = _end_normals(self.segments[i - 1])[1]
                out.append((s.p0, 0.0, math.atan2(n_in[1], n_in[0]), self._joint_turns[i], None))
            if s.kind == "arc":
                out.append((s.center, s.radius, s.theta0, s.sweep, i))
        return tuple(out)

    @cached_property
    def area(self) -> float:
        """Area ``A`` of ``P`` (normalised units squared): the shoelace over the joints plus each
        arc's circular segment ``rho^2 (sweep - sin sweep) / 2``."""
        return _polygon_area([s.p0 for s in self.segments]) + sum(
            0.5 * s.radius ** 2 * (s.sweep - math.sin(s.sweep)) for s in self.segments if s.kind == "arc")

    @cached_property
    def perimeter(self) -> float:
        """Perimeter ``L`` of ``P`` (normalised units)."""
        return math.fsum(s.length for s in self.segments)

    @cached_property
    def _incircle(self) -> tuple[float, float, float]:
        """``(x, y, rho_in)`` of a largest disc inside ``P``: see :func:`_largest_disc`."""
        return _largest_disc(self)

    @property
    def inradius(self) -> float:
        """``rho_in(P)``: radius of the largest disc contained in ``P`` (anywhere)."""
        return self._incircle[2]

    @property
    def incenter(self) -> tuple[float, float]:
        """Centre of a largest disc contained in ``P`` (one of them when several are)."""
        return self._incircle[:2]

    def support(self, psi):
        """Support function ``h(psi) = max over P of p . (cos psi, sin psi)`` (normalised),
        vectorised over ``psi`` (rad). ``P`` is the hull of its joints and arcs, so ``h`` is the
        largest of the joints' ``V . u`` and, on each arc's normal range, ``C . u + rho``."""
        psi = np.asarray(psi, float)
        ux, uy = _u(psi)
        h = np.full(psi.shape, -np.inf)
        for s in self.segments:
            h = np.maximum(h, s.p0[0] * ux + s.p0[1] * uy)
            if s.kind == "arc":
                on = (psi - s.theta0) % TWO_PI <= s.sweep
                h = np.where(on, np.maximum(h, s.center[0] * ux + s.center[1] * uy + s.radius), h)
        return h

    # ------------------------------------------------------------------ signed distance
    @cached_property
    def _sd_tables(self) -> tuple:
        """:meth:`signed_distance`'s candidates as arrays: the lines' ``(n_x, n_y, h)``; the fans'
        ``(c_x, c_y, radius, theta0, sweep)``; the directions ``(u_x, u_y)`` of each fan's range's
        two ends; and per candidate (:meth:`_candidates`' order) its gradient ``(u_x, u_y, h)``,
        ``h = C . u + radius`` (0 for a fan's own point: that one is the point's own direction)."""
        lines = np.array([(n[0], n[1], h) for _, n, h in self._lines], float).reshape(-1, 3).T
        fans = np.array([(c[0], c[1], rho, th0, sweep) for c, rho, th0, sweep, _ in self._fans],
                        float).reshape(-1, 5).T
        ends, grads = ([], []), [(n[0], n[1], h) for _, n, h in self._lines]
        for (cx, cy), rho, th0, sweep, _ in self._fans:
            for end, th in enumerate((th0, th0 + sweep)):
                ux, uy = math.cos(th), math.sin(th)
                ends[end].append((ux, uy))
                grads.append((ux, uy, cx * ux + cy * uy + rho))
            grads.append((0.0, 0.0, 0.0))
        ends = tuple(tuple(np.array(e, float).reshape(-1, 2).T) for e in ends)
        return tuple(lines), tuple(fans), ends, tuple(np.array(grads, float).reshape(-1, 3).T)

    def signed_distance(self, x, y, k, c):
        """Signed distance (mm) from ``(x, y)`` to ``O = k P (+) disc(c)``: ``sd(q, k P) - c``,
        exact Euclidean for ``c >= 0`` (negative inside), vectorised (all arguments broadcast).

        Returns ``(sd, gx, gy, (d_k, d_c))``: ``(gx, gy)`` is the unit gradient (the maximising
        direction ``u*`` of ``q . u - k h(u)``), ``d_k = -h(u*)`` and ``d_c = -1``. With ``c = t < 0``
        it is the level-set function of the inner parallel set (exact distance except near its
        sharp corners, where it is the largest distance to the offset pieces' lines).
        """
        x, y, k, c = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, k, c)))
        every, dx, dy = self._candidates(x, y, k)
        (nx, _, _), (cx, cy, rho, _, _), _, grads = self._sd_tables
        n_lines, m = len(nx), every.shape[0]
        pick = np.argmax(every, axis=0)  # the first of equals, as a running "val > best" takes
        at = np.arange(every.shape[1])
        best = every[pick, at]
        pick = np.where(best > -np.inf, pick, m)  # none taken: the gradient stays 0
        gx, gy, hs = (np.append(t, 0.0)[pick] for t in grads)
        fan = pick - n_lines - 2
        own = (fan >= 0) & (fan % 3 == 0) & (pick < m)  # a fan's own point: its direction
        if own.any():
            f, j = fan[own] // 3, at[own]
            dist = np.hypot(dx[f, j], dy[f, j])  # > 0 where it was taken
            ux, uy = dx[f, j] / dist, dy[f, j] / dist
            gx[own], gy[own], hs[own] = ux, uy, cx[f] * ux + cy[f] * uy + rho[f]
        best, gx, gy, hs = (v.reshape(x.shape) for v in (best, gx, gy, hs))
        return best - c, gx, gy, (-hs, -np.ones(x.shape))

    def distance(self, x, y, k, c):
        """The signed distance (mm) of :meth:`signed_distance` alone (the same value, without its
        gradient: faster where only the distance is asked, as the glass's thickness does)."""
        x, y, k, c = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, k, c)))
        return np.max(self._candidates(x, y, k)[0], axis=0).reshape(x.shape) - c

    def _candidates(self, x, y, k):
        """``(every, dx, dy)``: :meth:`signed_distance`'s candidates ``q . u - k h(u)`` (mm) per point
        of the flattened ``x, y, k`` (arrays of one shape), ``(candidates, points)`` in the order a
        running "largest so far" would meet them (the lines; then per fan its range's two ends and
        its own point, ``-inf`` where the point's direction from the fan's centre is outside its
        range; NaN as ``-inf``: never the largest), and each fan's ``q - k C`` (mm, ``(fans, points)``)."""
        (nx, ny, nh), (cx, cy, rho, th0, sweep), ends, _ = self._sd_tables
        xf, yf, kf = (v.reshape(1, -1) for v in (x, y, k))
        n_lines, col = len(nx), (slice(None), None)
        every = np.empty((n_lines + 3 * len(cx), xf.shape[1]))
        every[:n_lines] = xf * nx[col] + yf * ny[col] - kf * nh[col]
        dx, dy = xf - kf * cx[col], yf - kf * cy[col]
        for end in (0, 1):  # why: the range's ends, for a q whose direction is outside it
            every[n_lines + end::3] = dx * ends[end][0][col] + dy * ends[end][1][col] - kf * rho[col]
        turn = np.fmod(np.arctan2(dy, dx) - th0[col], TWO_PI)  # then + 2 pi where < 0: numpy's %, bit
        on = ((dx != 0) | (dy != 0)) & (np.where(turn < 0, turn + TWO_PI, turn) <= sweep[col])  # for bit, 4x faster
        f, j = np.nonzero(on)  # why only there: hypot is the slowest step, and most points are off
        own = np.full(dx.shape, -np.inf)
        own[f, j] = np.hypot(dx[f, j], dy[f, j]) - kf[0, j] * rho[f]
        every[n_lines + 2::3] = own
        every[np.isnan(every)] = -np.inf
        return every, dx, dy

    # ------------------------------------------------------------------ sections as pieces
    def outer_pieces(self, k: float, c: float) -> tuple[Piece, ...]:
        """Boundary of ``O = k P (+) disc(c)`` (mm; ``k >= 0``, ``c > 0``) as exact pieces in chain
        order (SPEC_outline section 4): each line moved out by ``c``, each arc concentric with
        radius ``k rho + c``, each sharp corner rounded by an arc of radius ``c``; ``k = 0`` gives
        the whole circle of radius ``c``."""
        k, c = _scalar(k, "k"), _scalar(c, "c")
        if k < 0 or c <= 0:
            raise OutlineError(None, f"an outer section needs k >= 0 and c > 0 mm, got k = {k:g}, c = {c:g}")
        return self._grown(k, c)

    def inner_pieces(self, k: float, t: float) -> tuple[Piece, ...]:
        """Boundary of the cavity section ``I = {q : sd(q, k P) <= t}`` (mm; SPEC_outline section 5)
        as exact pieces in chain order. ``t >= 0``: as :meth:`outer_pieces` with ``t`` (at ``t = 0``
        the sharp corners stay sharp). ``t < 0``: the inner parallel set, every line moved in to
        ``x . n = k h + t``, every arc of radius ``k rho + t``, sharp corners where the offset
        neighbours meet; ``OutlineError`` when a segment would vanish (see :meth:`inner_reason`)."""
        k, t = _scalar(k, "k"), _scalar(t, "t")
        if k < 0 or (k == 0 and t <= 0):
            raise OutlineError(None, f"no inner section at k = {k:g}, t = {t:g} mm (needs k >= 0, and t > 0 at k = 0)")
        if t >= 0:
            return self._grown(k, t)
        er = self._eroded(np.array(k), np.array(t))
        bad = self._vanished(er, k, t)
        if bad:
            raise OutlineError(None, bad)
        pieces = []
        for i, s in enumerate(self.segments):
            w0, w1 = er["joint"][i], er["joint"][(i + 1) % len(self.segments)]
            if s.kind == "line":
                pieces.append(PlanLine((float(w0[0]), float(w0[1])), (float(w1[0]), float(w1[1]))))
            else:
                pieces.append(ArcPiece((k * s.center[0], k * s.center[1]), k * s.radius + t,
                                       float(er["phi0"][i]), float(er["phi1"][i])))
        return tuple(pieces)

    def _grown(self, k: float, c: float) -> tuple[Piece, ...]:
        """Pieces of ``k P (+) disc(c)`` for ``k, c >= 0`` (a zero-radius corner arc is left out)."""
        if k == 0:
            return (ArcPiece((0.0, 0.0), c, 0.0, TWO_PI),)
        pieces = []
        for i, s in enumerate(self.segments):
            if self._joint_turns[i] > 0 and c > 0:
                n_in = _end_normals(self.segments[i - 1])[1]
                a = math.atan2(n_in[1], n_in[0])
                pieces.append(ArcPiece((k * s.p0[0], k * s.p0[1]), c, a, a + self._joint_turns[i]))
            if s.kind == "line":
                n = s.normal
                pieces.append(PlanLine((k * s.p0[0] + c * n[0], k * s.p0[1] + c * n[1]),
                                       (k * s.p1[0] + c * n[0], k * s.p1[1] + c * n[1])))
            else:
                pieces.append(ArcPiece((k * s.center[0], k * s.center[1]), k * s.radius + c, s.theta0, s.theta1))
        return tuple(pieces)

    def _eroded(self, k, t) -> dict:
        """The inner parallel set of ``k P`` at distance ``-t`` (``t < 0``), vectorised over ``k, t``.

        Returns ``{"joint": [(x, y)] per segment start, "phi0"/"phi1": {arc index: angle}}``. Every
        offset piece keeps its normals; a joint is where the two offset neighbours meet: on their
        common normal at a smooth joint, else their intersection. An arc's trimmed end angles are
        measured from its own angles by the law of cosines (no angle wrapping involved).
        """
        segs, m = self.segments, len(self.segments)
        joint, phi0, phi1 = [None] * m, {}, {}
        for i, b in enumerate(segs):
            a = segs[i - 1]
            n_in, n_out = _end_normals(a)[1], _end_normals(b)[0]
            vx, vy = k * b.p0[0], k * b.p0[1]
            if self._joint_turns[i] == 0:  # smooth: both offsets pass through k V + t n
                joint[i] = (vx + t * n_in[0], vy + t * n_in[1])
                if a.kind == "arc":
                    phi1[(i - 1) % m] = a.theta1 + 0 * t
                if b.kind == "arc":
                    phi0[i] = b.theta0 + 0 * t
            elif a.kind == "line" and b.kind == "line":
                f = t / (1.0 + n_in[0] * n_out[0] + n_in[1] * n_out[1])
                joint[i] = (vx + f * (n_in[0] + n_out[0]), vy + f * (n_in[1] + n_out[1]))
            elif a.kind == "arc" and b.kind == "line":
                phi = a.theta1 - _line_trim(a, b.normal, b.p0, k, t)
                phi1[(i - 1) % m] = phi
                joint[i] = _on_circle(a, k, t, phi)
            elif a.kind == "line":
                phi = b.theta0 + _line_trim(b, a.normal, a.p0, k, t)
                phi0[i] = phi
                joint[i] = _on_circle(b, k, t, phi)
            else:
                d1, d2 = _circle_trims(a, b, k, t)
                phi1[(i - 1) % m], phi0[i] = a.theta1 - d1, b.theta0 + d2
                joint[i] = _on_circle(a, k, t, phi1[(i - 1) % m])
        return {"joint": joint, "phi0": phi0, "phi1": phi1}

    def _survives(self, er: dict, k, t):
        """Per segment, whether its offset keeps a positive length / angle (and radius) in ``er``."""
        m, out = len(self.segments), []
        for i, s in enumerate(self.segments):
            if s.kind == "line":
                (x0, y0), (x1, y1) = er["joint"][i], er["joint"][(i + 1) % m]
                n = s.normal
                out.append((x1 - x0) * -n[1] + (y1 - y0) * n[0] > 0)  # along the direction (-n_y, n_x)
            else:
                out.append((k * s.radius + t > 0) & (er["phi1"][i] - er["phi0"][i] > 0))
        return out

    def _vanished(self, er: dict, k: float, t: float) -> str | None:
        """The first segment that vanishes from the inner parallel set ``er`` (scalar), in words."""
        for i, ok in enumerate(self._survives(er, k, t)):
            if not bool(ok):
                what = "line" if self.segments[i].kind == "line" else "arc"
                return (f"segment {i} ({what}) vanishes from the inner section at k = {k:.6g} mm, "
                        f"t = c - w = {t:.6g} mm (the offset pieces meet past it)")
        return None

    def inner_reason(self, k: float, t: float) -> str | None:
        """Why the cavity section at ``(k, t)`` (mm) is not valid (SPEC_outline section 5), or ``None``:
        it must hold a disc of radius 1 mm (``rho_in k + t >= 1``) and, where ``t < 0``, no segment
        may vanish from it."""
        k, t = _scalar(k, "k"), _scalar(t, "t")
        room = self.inradius * k + t
        if room < CAVITY_MARGIN_MM - 1e-9:
            return (f"no cavity margin: the inner section holds a disc of radius {room:.6g} mm only "
                    f"(rho_in k + c - w must be >= {CAVITY_MARGIN_MM:g} mm)")
        if t < 0:
            return self._vanished(self._eroded(np.array(k), np.array(t)), k, t)
        return None

    # ------------------------------------------------------------------ areas and girths
    def outer_area(self, k, c):
        """Area (mm^2) of ``O = k P (+) disc(c)``: Steiner's ``k^2 A + k L c + pi c^2``, vectorised."""
        k, c = np.asarray(k, float), np.asarray(c, float)
        return k * k * self.area + k * self.perimeter * c + math.pi * c * c

    def girth(self, k, c):
        """Perimeter (mm) of ``O``: ``k L + 2 pi c``, vectorised."""
        return np.asarray(k, float) * self.perimeter + TWO_PI * np.asarray(c, float)

    def inner_area(self, k, t):
        """Area (mm^2) of the cavity section, exact and vectorised over ``k, t``: Steiner's polynomial
        for ``t >= 0``; for ``t < 0`` the inner parallel set's shoelace over its joints plus its arcs'
        circular segments. 0 where the set is empty (``rho_in k + t <= 0``), NaN where it exists but
        a segment of ``P`` has vanished from it (an invalid design: :meth:`inner_reason`)."""
        return self._inner_measure(k, t, area=True)

    def inner_girth(self, k, t):
        """Perimeter (mm) of the cavity section, vectorised as :meth:`inner_area`."""
        return self._inner_measure(k, t, area=False)

    def _inner_measure(self, k, t, area: bool):
        k, t = np.broadcast_arrays(np.asarray(k, float), np.asarray(t, float))
        out = self.outer_area(k, t) if area else self.girth(k, t)
        neg = t < 0
        if not neg.any():
            return out
        kn, tn = k[neg], t[neg]
        er = self._eroded(kn, tn)
        ok = np.logical_and.reduce([np.broadcast_to(s, kn.shape) for s in self._survives(er, kn, tn)])
        value = self._eroded_area(er, kn, tn) if area else self._eroded_girth(er, kn, tn)
        empty = self.inradius * kn + tn <= 0
        out = np.array(out, float)
        out[neg] = np.where(empty, 0.0, np.where(ok, value, np.nan))
        return out

    def _eroded_area(self, er: dict, k, t):
        m, js = len(self.segments), er["joint"]
        twice = sum(js[i][0] * js[(i + 1) % m][1] - js[(i + 1) % m][0] * js[i][1] for i in range(m))
        seg = sum(0.5 * (k * s.radius + t) ** 2 * ((d := er["phi1"][i] - er["phi0"][i]) - np.sin(d))
                  for i, s in enumerate(self.segments) if s.kind == "arc")
        return 0.5 * twice + seg

    def _eroded_girth(self, er: dict, k, t):
        m, js, total = len(self.segments), er["joint"], 0.0
        for i, s in enumerate(self.segments):
            if s.kind == "line":
                total = total + np.hypot(js[(i + 1) % m][0] - js[i][0], js[(i + 1) % m][1] - js[i][1])
            else:
                total = total + (k * s.radius + t) * (er["phi1"][i] - er["phi0"][i])
        return total

    # ------------------------------------------------------------------ vectorised section queries
    def section_pieces(self, k, r, grown: bool | None = None):
        """The boundary pieces of the section ``{q : sd(q, k P) <= r}`` (mm) as arrays over the
        1-d arrays ``k >= 0`` and ``r`` (one sign throughout: all ``r >= 0`` or all ``r < 0``):
        ``("line", ax, ay, bx, by, nx, ny)`` and ``("arc", cx, cy, rho, a0, a1)`` in chain order,
        as :meth:`outer_pieces` / :meth:`inner_pieces` but without their per-height loop (a
        corner arc or line may have zero size; at ``k = 0`` the arcs about the origin cover it).
        ``grown`` says which list to give where ``r`` is 0: ``True`` the grown set's (a corner arc
        of radius ``r`` at each sharp corner of ``P``, then its segment), ``False`` the inner
        parallel set's (one piece per segment); ``None`` takes it from the sign of ``r``."""
        return self._section_pieces(np.asarray(k, float), np.asarray(r, float), grown)

    def _section_pieces(self, k, r, grown: bool | None = None):
        out = []
        if np.all(r >= 0) if grown is None else grown:
            for i, s in enumerate(self.segments):
                if self._joint_turns[i] > 0:
                    n_in = _end_normals(self.segments[i - 1])[1]
                    a = math.atan2(n_in[1], n_in[0])
                    out.append(("arc", k * s.p0[0], k * s.p0[1], r, a, a + self._joint_turns[i]))
                if s.kind == "line":
                    n = s.normal
                    out.append(("line", k * s.p0[0] + r * n[0], k * s.p0[1] + r * n[1],
                                k * s.p1[0] + r * n[0], k * s.p1[1] + r * n[1], n[0], n[1]))
                else:
                    out.append(("arc", k * s.center[0], k * s.center[1], k * s.radius + r, s.theta0, s.theta1))
            return out
        er, m = self._eroded(k, r), len(self.segments)
        for i, s in enumerate(self.segments):
            if s.kind == "line":
                (ax, ay), (bx, by) = er["joint"][i], er["joint"][(i + 1) % m]
                out.append(("line", ax, ay, bx, by, *s.normal))
            else:
                out.append(("arc", k * s.center[0], k * s.center[1], k * s.radius + r,
                            er["phi0"][i], er["phi1"][i]))
        return out

    def _by_sign(self, r, each):
        """``each(mask)`` on the heights where ``r >= 0`` and where ``r < 0`` (their pieces differ)."""
        grown = r >= 0
        for mask in (grown, ~grown):
            if mask.any():
                each(mask)

    def section_boundary(self, theta, k, r):
        """Where the ray from the origin at polar angle ``theta`` (rad) leaves the section
        ``{q : sd(q, k P) <= r}`` (mm; ``k >= 0``, any sign of ``r``, the section holding the
        origin): ``(x, y, nx, ny)`` (mm, unit outward normal), broadcast over the arguments.

        Exact: the section is convex and holds the origin, so the ray leaves it once, through the
        one piece whose line or circle it meets inside the piece (a circle at the crossing where
        the ray leaves its disc). Each piece's miss (mm outside its ends) is measured and the
        least taken, so a ray through a joint takes either neighbour. At a sharp inner corner
        (``r < 0``) the normal is one side's."""
        th, k, r = np.broadcast_arrays(*(np.asarray(v, float) for v in (theta, k, r)))
        ux, uy = np.cos(th).ravel(), np.sin(th).ravel()
        kf, rf = k.ravel(), r.ravel()
        out = np.empty((4, kf.size))

        def each(mask):
            out[:, mask] = _ray_exit(self._section_pieces(kf[mask], rf[mask]), ux[mask], uy[mask])[:4]

        self._by_sign(rf, each)
        return tuple(v.reshape(th.shape) for v in out)

    def section_support(self, psi, k, r):
        """Support function (mm) of the section ``{q : sd(q, k P) <= r}`` in plan direction
        ``psi`` (rad), broadcast: ``k h(psi) + r`` for ``r >= 0``; for ``r < 0`` the largest of the
        inner joints' ``w . u`` and, on each offset arc's normal range, ``k C . u + k rho + r``."""
        ps, k, r = np.broadcast_arrays(*(np.asarray(v, float) for v in (psi, k, r)))
        out = np.empty(k.size)
        pf, kf, rf = ps.ravel(), k.ravel(), r.ravel()

        def each(mask):
            ux, uy = _u(pf[mask])
            if rf[mask][0] >= 0:
                out[mask] = kf[mask] * self.support(pf[mask]) + rf[mask]
                return
            h = np.full(ux.shape, -np.inf)
            for p in self._section_pieces(kf[mask], rf[mask]):
                if p[0] == "line":
                    h = np.maximum(h, p[1] * ux + p[2] * uy)
                else:
                    _, cx, cy, rho, a0, a1 = p
                    on = (pf[mask] - a0) % TWO_PI <= (a1 - a0)
                    h = np.where(on, np.maximum(h, cx * ux + cy * uy + rho), h)
            out[mask] = h

        self._by_sign(rf, each)
        return out.reshape(k.shape)

    def section_moment(self, k, r):
        """First moments ``(M_x, M_y)`` (mm^3: the integrals of ``x`` and ``y`` over the section
        ``{q : sd(q, k P) <= r}``), broadcast over ``k >= 0`` and ``r`` of either sign; the
        centroid is ``M / area``. Exact: Green's theorem along the section's own pieces
        (:meth:`section_pieces`), each line's and arc's integral in closed form
        (:func:`_pieces_moment`); 0 where the section is empty, NaN where a piece of ``P`` has
        vanished from it (as :meth:`inner_area`)."""
        k, r = np.broadcast_arrays(np.asarray(k, float), np.asarray(r, float))
        out = np.zeros((2, k.size))
        kf, rf = k.ravel(), r.ravel()

        def each(mask):
            out[:, mask] = _pieces_moment(self._section_pieces(kf[mask], rf[mask]))

        self._by_sign(rf, each)
        area = self.inner_area(kf, rf)
        out = np.where(area > 0, out, np.where(np.isnan(area), np.nan, 0.0))
        return out[0].reshape(k.shape), out[1].reshape(k.shape)

    def section_reach(self, k, r):
        """Largest distance (mm) of the section ``{q : sd(q, k P) <= r}`` from the origin,
        vectorised: ``k + r`` for ``r >= 0`` (``P``'s farthest point is at 1); for ``r < 0`` the
        farthest inner joint or offset arc point (an arc reaches ``|k C| + k rho + r`` where its
        range holds the direction of its centre)."""
        k, r = np.broadcast_arrays(np.asarray(k, float), np.asarray(r, float))
        out = np.empty(k.size)
        kf, rf = k.ravel(), r.ravel()

        def each(mask):
            if rf[mask][0] >= 0:
                out[mask] = kf[mask] + rf[mask]
                return
            far = np.zeros(int(mask.sum()))
            for p in self._section_pieces(kf[mask], rf[mask]):
                if p[0] == "line":
                    far = np.maximum(far, np.hypot(p[1], p[2]))
                else:
                    _, cx, cy, rho, a0, a1 = p
                    on = (np.arctan2(cy, cx) - a0) % TWO_PI <= (a1 - a0)
                    far = np.where(on, np.maximum(far, np.hypot(cx, cy) + rho), far)
            out[mask] = far

        self._by_sign(rf, each)
        return out.reshape(k.shape)

    # ------------------------------------------------------------------ sampling
    def polyline(self, k: float, c: float, chord_tol_mm: float | None = None, max_turn_deg: float = 0.2):
        """Vertices (mm, shape ``(N, 2)``, closed implicitly) on the outer boundary: see
        :func:`sample_pieces`."""
        return sample_pieces(self.outer_pieces(k, c), chord_tol_mm, max_turn_deg)

    def inner_polyline(self, k: float, t: float, chord_tol_mm: float | None = None, max_turn_deg: float = 0.2):
        """Vertices (mm, ``(N, 2)``) on the cavity boundary; sharp inner corners are vertices."""
        return sample_pieces(self.inner_pieces(k, t), chord_tol_mm, max_turn_deg)


# --------------------------------------------------------------------------- helpers
def _scalar(v, name: str) -> float:
    x = float(v)
    if not math.isfinite(x):
        raise OutlineError(None, f"{name} must be a finite number of mm, got {shown(v)}")
    return x


def _polygon_area(points) -> float:
    """Signed shoelace area of a closed polygon (positive counter-clockwise)."""
    pts = list(points)
    return 0.5 * math.fsum(p[0] * q[1] - q[0] * p[1] for p, q in zip(pts, pts[1:] + pts[:1]))


def _on_circle(arc: PlanArc, k, t, phi):
    """The point at angle ``phi`` on the arc's offset circle (about ``k C``, radius ``k rho + t``)."""
    r = k * arc.radius + t
    return (k * arc.center[0] + r * np.cos(phi), k * arc.center[1] + r * np.sin(phi))


def _line_trim(arc: PlanArc, n, p, k, t):
    """How far (rad) the offset arc is cut back where it meets the offset line ``x . n = k h + t``
    (``h = n . p``) across a sharp corner. The meeting point's angle from ``n`` about the centre
    is ``beta = acos((k h + t - k C . n) / (k rho + t))``; at ``k = 1, t = 0`` it is the corner's
    own ``beta0``, so the cut is ``beta - beta0`` (NaN when they no longer meet)."""
    cn = arc.center[0] * n[0] + arc.center[1] * n[1]
    h = n[0] * p[0] + n[1] * p[1]
    beta0 = math.acos(max(-1.0, min(1.0, (h - cn) / arc.radius)))
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_beta = (k * (h - cn) + t) / (k * arc.radius + t)
        beta = np.arccos(np.where(np.abs(cos_beta) <= 1.0, cos_beta, np.nan))
    return beta - beta0


def _circle_trims(a: PlanArc, b: PlanArc, k, t):
    """How far (rad) the offset arcs ``a`` (at its end) and ``b`` (at its start) are cut back
    where they meet across a sharp corner: the triangle ``k C_a, k C_b, W`` by the law of cosines,
    measured from the same angles of ``P``'s own corner (``k = 1, t = 0``)."""
    dist = math.hypot(b.center[0] - a.center[0], b.center[1] - a.center[1])
    side = math.copysign(1.0, (b.center[0] - a.center[0]) * (b.p0[1] - a.center[1])
                         - (b.center[1] - a.center[1]) * (b.p0[0] - a.center[0]))

    def angle(r1, r2, d):
        with np.errstate(invalid="ignore", divide="ignore"):
            cos = (r1 * r1 + d * d - r2 * r2) / (2 * r1 * d)
            return np.arccos(np.where(np.abs(cos) <= 1.0, cos, np.nan))

    ra, rb = k * a.radius + t, k * b.radius + t
    ga0, gb0 = angle(a.radius, b.radius, dist), angle(b.radius, a.radius, dist)
    ga, gb = angle(ra, rb, k * dist), angle(rb, ra, k * dist)
    # why: W stays on the side `side` of the line C_a -> C_b (direction delta); its angle about
    # C_a is delta + side*gamma_a and about C_b delta + pi - side*gamma_b
    return side * (ga0 - ga), side * (gb0 - gb)


def _pieces_moment(pieces) -> np.ndarray:
    """``(2, n)``: ``(M_x, M_y)`` (mm^3) of the regions bounded counter-clockwise by the chains of
    :meth:`PlanOutline._section_pieces`, by Green's theorem, ``M_x = closed int x^2/2 dy`` and
    ``M_y = -closed int y^2/2 dx``: on a line ``a -> b`` the integrands are quadratic in its
    parameter, on an arc ``C + rho (cos t, sin t)`` trigonometric polynomials in ``t``."""
    mx = my = 0.0
    for p in pieces:
        if p[0] == "line":
            _, ax, ay, bx, by, _, _ = p
            mx = mx + (by - ay) * (ax * ax + ax * bx + bx * bx) / 6.0
            my = my - (bx - ax) * (ay * ay + ay * by + by * by) / 6.0
            continue
        _, cx, cy, rho, a0, a1 = p
        s0, s1, c0, c1 = np.sin(a0), np.sin(a1), np.cos(a0), np.cos(a1)
        dt = a1 - a0
        # int cos t, cos^2 t, cos^3 t dt and int sin t, sin^2 t, sin^3 t dt from a0 to a1
        ic, icc, iccc = s1 - s0, 0.5 * (dt + s1 * c1 - s0 * c0), (s1 - s1 ** 3 / 3.0) - (s0 - s0 ** 3 / 3.0)
        i_s, iss, isss = c0 - c1, 0.5 * (dt - s1 * c1 + s0 * c0), (c0 - c0 ** 3 / 3.0) - (c1 - c1 ** 3 / 3.0)
        mx = mx + 0.5 * rho * (cx * cx * ic + 2.0 * cx * rho * icc + rho * rho * iccc)
        my = my + 0.5 * rho * (cy * cy * i_s + 2.0 * cy * rho * iss + rho * rho * isss)
    return np.array(np.broadcast_arrays(mx, my), float)


def _ray_exit(pieces, ux, uy) -> np.ndarray:
    """``(6, n)``: point and outward normal where the rays from the origin along ``(ux, uy)``
    leave a convex chain of ``pieces`` (:meth:`PlanOutline._section_pieces`), then the index of
    the piece left through and the length (mm) along it from its start (what the girth of
    :mod:`engine.geometry.plan_girth` adds up): on each piece the crossing and how far (mm) it
    lies outside the piece's ends; the least wins."""
    best = np.full(ux.shape, np.inf)
    out = np.zeros((6,) + ux.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        for i, p in enumerate(pieces):
            if p[0] == "line":
                _, ax, ay, bx, by, nx, nyy = p
                un = ux * nx + uy * nyy
                s = (ax * nx + ay * nyy) / un
                ex, ey = bx - ax, by - ay
                length = np.hypot(ex, ey)
                lam = ((s * ux - ax) * ex + (s * uy - ay) * ey) / (length * length)
                miss = np.where((un > 0) & (length > 0), np.maximum(np.maximum(-lam, lam - 1.0), 0.0) * length, np.inf)
                n = (np.broadcast_to(nx, ux.shape), np.broadcast_to(nyy, ux.shape))
                along = np.clip(lam, 0.0, 1.0) * length
            else:
                _, cx, cy, rho, a0, a1 = p
                b = ux * cx + uy * cy
                disc = b * b - (cx * cx + cy * cy) + rho * rho
                s = b + np.sqrt(disc)
                gx, gy = s * ux - cx, s * uy - cy
                d = (np.arctan2(gy, gx) - a0) % TWO_PI
                sweep = a1 - a0
                off = np.where(d <= sweep, 0.0, np.minimum(d - sweep, TWO_PI - d))
                miss = np.where((disc >= 0) & (rho > 0), off * rho, np.inf)
                safe = np.where(rho > 0, rho, 1.0)
                n = (gx / safe, gy / safe)
                along = rho * np.where(d <= sweep, d, np.where(d - sweep < TWO_PI - d, sweep, 0.0))
            take = miss < best
            best = np.where(take, miss, best)
            for j, v in enumerate((s * ux, s * uy, *n, i, along)):
                out[j] = np.where(take, v, out[j])
    return out


def sample_pieces(pieces, chord_tol_mm: float | None = None, max_turn_deg: float = 0.2) -> np.ndarray:
    """Vertices (mm, ``(N, 2)``, the closing edge implied) exactly on a chain of pieces: a line
    is one facet (its start point); an arc is cut into equal angle steps of at most
    ``max_turn_deg`` and, with ``chord_tol_mm``, with a chord sagitta at most that. Each piece
    gives its start and inner points, the next piece its end (sharp corners stay exact)."""
    if not (0 < max_turn_deg <= 90):
        raise OutlineError(None, f"max_turn_deg must be in (0, 90], got {shown(max_turn_deg)}")
    step = math.radians(max_turn_deg) * (1 - 1e-6)  # why: a hair under, so rounding never exceeds it
    pts = []
    for p in pieces:
        if p.kind == "line":
            pts.append(np.array([p.p0]))
            continue
        sweep = p.theta1 - p.theta0
        if p.radius <= 0 or sweep <= 0:
            continue  # a zero-size corner arc: a sharp corner, its point comes with the next piece
        n = math.ceil(sweep / step)
        if chord_tol_mm is not None and p.radius > chord_tol_mm > 0:
            n = max(n, math.ceil(sweep / (2 * math.acos(1 - chord_tol_mm / p.radius))))
        a = p.theta0 + sweep * np.arange(max(n, 1)) / max(n, 1)
        pts.append(np.stack([p.center[0] + p.radius * np.cos(a), p.center[1] + p.radius * np.sin(a)], axis=-1))
    return np.concatenate(pts, axis=0)


def _largest_disc(outline: PlanOutline) -> tuple[float, float, float]:
    """A largest disc inside ``P`` by cutting planes: maximise ``r`` subject to
    ``r + u . x <= h(u)`` over a growing set of directions ``u`` (a linear programme in
    ``(x, y, r)``). Each round adds, at the current centre, every arc's (and the overall) nearest
    boundary direction; ``-sd(x)`` is the exact radius of the disc at ``x`` (a lower bound), the LP
    value an upper bound; stop when they agree to 1e-14."""
    from scipy.optimize import linprog

    psi = [math.atan2(n[1], n[0]) for _, n, _ in outline._lines]
    for _, rho, th0, sweep, seg in outline._fans:
        if seg is not None:  # corner fans add nothing: their ends are their neighbours' normals
            psi.extend(th0 + sweep * np.linspace(0.0, 1.0, 9))
    best = (0.0, 0.0, 0.0)
    for _ in range(40):
        ux, uy = _u(np.array(psi))
        res = linprog([0.0, 0.0, -1.0], A_ub=np.stack([ux, uy, np.ones_like(ux)], axis=1),
                      b_ub=outline.support(np.array(psi)), bounds=[(-1, 1), (-1, 1), (0, 1)], method="highs")
        if res.status != 0:
            break
        x, y, upper = (float(v) for v in res.x)
        sd, gx, gy, _ = outline.signed_distance(x, y, 1.0, 0.0)
        if -float(sd) > best[2]:
            best = (x, y, -float(sd))
        if upper - best[2] <= 1e-9:
            break
        psi.append(math.atan2(float(gy), float(gx)))
        psi.extend(_nearest_on_range(math.atan2(y - cy, x - cx), th0, sweep)
                   for (cx, cy), _, th0, sweep, seg in outline._fans if seg is not None)
    return _polished(outline, *best)


def _contacts(outline: PlanOutline, x: float, y: float) -> list:
    """``(g, grad g, hess g)`` at ``(x, y)`` of each line's ``h - n . x`` and each arc's
    ``rho - |x - C|`` whose direction is on the arc (the smooth pieces of ``-sd``)."""
    out = [(h - n[0] * x - n[1] * y, -np.array(n), np.zeros((2, 2))) for _, n, h in outline._lines]
    for (cx, cy), rho, th0, sweep, seg in outline._fans:
        d = np.array([x - cx, y - cy])
        dist = math.hypot(*d)
        if seg is not None and dist > 1e-12 and (math.atan2(d[1], d[0]) - th0) % TWO_PI <= sweep:
            u = d / dist
            out.append((rho - dist, -u, -(np.eye(2) - np.outer(u, u)) / dist))
    return out


def _polished(outline: PlanOutline, x: float, y: float, r: float) -> tuple[float, float, float]:
    """Newton steps on the optimality conditions of ``max r, g_i(x) >= r`` over the pieces within
    1e-7 of touching the disc: ``g_i(x) = r`` and ``sum l_i grad g_i = 0``, ``sum l_i = 1``
    (least squares, so a segment of optimal centres, e.g. a rectangle's, is no trouble). A step
    is kept only where the exact radius ``-sd`` grows: the result is always a true inscribed disc."""
    best = (x, y, r)
    lam = None
    for _ in range(12):
        act = [c for c in _contacts(outline, x, y) if c[0] <= r + 1e-7]
        m = len(act)
        if m == 0:  # at the centre of arcs (a circular plan): no smooth piece to polish on
            break
        lam = np.full(m, 1.0 / m) if lam is None or len(lam) != m else lam
        jac, res = np.zeros((3 + m, 3 + m)), np.zeros(3 + m)
        res[:2] = sum(l * c[1] for l, c in zip(lam, act))
        jac[:2, :2] = sum(l * c[2] for l, c in zip(lam, act))
        res[2], jac[2, 3:] = lam.sum() - 1.0, 1.0
        for i, (g, grad, _) in enumerate(act):
            jac[:2, 3 + i] = grad
            res[3 + i], jac[3 + i, :2], jac[3 + i, 2] = g - r, grad, -1.0
        step = np.linalg.lstsq(jac, -res, rcond=1e-13)[0]
        x, y, r, lam = x + step[0], y + step[1], r + step[2], lam + step[3:]
        exact = -float(outline.signed_distance(x, y, 1.0, 0.0)[0])
        if exact > best[2]:
            best = (float(x), float(y), exact)
        if np.abs(step).max() < 1e-15:
            break
    return best


def _nearest_on_range(angle: float, th0: float, sweep: float) -> float:
    """The angle of ``[th0, th0 + sweep]`` nearest to ``angle`` (rad, any turn)."""
    a = (angle - th0) % TWO_PI
    if a <= sweep:
        return th0 + a
    return th0 + sweep if a - sweep <= TWO_PI - a else th0


# --------------------------------------------------------------------------- building chains
def _rotated(d: dict, angle: float, mirror: bool = False) -> dict:
    """A segment dictionary turned ccw by ``angle`` (rad) about the origin; with ``mirror`` first
    reflected in the y axis (``x -> -x``) and walked backwards, so a ccw arc stays ccw."""
    ca, sa = math.cos(angle), math.sin(angle)

    def move(p):
        x, y = (-p[0], p[1]) if mirror else (p[0], p[1])
        return [x * ca - y * sa, x * sa + y * ca]

    p0, p1 = (d["p1"], d["p0"]) if mirror else (d["p0"], d["p1"])
    out = {"type": d["type"], "p0": move(p0), "p1": move(p1)}
    if d["type"] == "arc":
        out.update(center=move(d["center"]), radius=d["radius"], ccw=True)
    return out


def _bridged(chain: list[dict]) -> list[dict]:
    """``chain`` closed with a line wherever a segment does not start where the previous one ends
    (beyond SPEC_outline's tolerance ``1e-6 R``, so a closing line is never too short to keep)."""
    reach = max(max(math.hypot(*d["p0"]), math.hypot(*d["p1"])) for d in chain)
    out = []
    for i, d in enumerate(chain):
        prev = chain[i - 1]["p1"]
        if math.hypot(d["p0"][0] - prev[0], d["p0"][1] - prev[1]) > TOL * reach:
            out.append({"type": "line", "p0": list(prev), "p1": list(d["p0"])})
        out.append(d)
    return out


def _dicts_of(chain) -> list[dict]:
    """A chain given as dictionaries or plan segments, as a list of dictionaries."""
    if not isinstance(chain, (list, tuple)) or not chain or len(chain) > MAX_SEGMENTS:
        raise OutlineError(None, f"a piece of outline must be a list of 1 to {MAX_SEGMENTS} segments")
    return [s.to_dict() if isinstance(s, (PlanLine, PlanArc)) else _parse(i, s).to_dict()
            for i, s in enumerate(chain)]


def mirrored(half_chain) -> PlanOutline:
    """The outline symmetric about the y axis whose right half is ``half_chain`` (dictionaries or
    plan segments, any units): it runs counter-clockwise from a bottom point to a top point with
    ``x >= 0``; its mirror image closes it, and a line crosses the axis at the top or bottom
    where an end point is off the axis."""
    half = _dicts_of(half_chain)
    return PlanOutline.from_dicts(_bridged(half + [_rotated(d, 0.0, mirror=True) for d in reversed(half)]))


def n_fold(piece, n: int) -> PlanOutline:
    """The outline with ``n``-fold rotational symmetry made of ``n`` copies of ``piece``
    (dictionaries or plan segments, any units) turned by ``360/n`` deg each; a line joins the
    end of one copy to the start of the next where they do not meet."""
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_SEGMENTS:
        raise OutlineError(None, f"n_fold needs a whole number of copies 1..{MAX_SEGMENTS}, got {shown(n)}")
    part = _dicts_of(piece)
    if len(part) * n > MAX_SEGMENTS:
        raise OutlineError(None, f"{n} copies of {len(part)} segments exceed {MAX_SEGMENTS} segments")
    return PlanOutline.from_dicts(_bridged([_rotated(d, TWO_PI * j / n) for j in range(n) for d in part]))


def regular_polygon(n: int, corner_radius: float = 0.0, rotation_deg: float = 0.0) -> PlanOutline:
    """The regular ``n``-gon with circumradius 1 and a vertex at angle ``rotation_deg`` (deg, ccw
    from +x); with ``corner_radius`` ``r`` in ``[0, 1)`` (relative to the circumradius) its corners
    are arcs of radius ``r`` (the polygon of circumradius ``1 - r`` grown by ``r``: still reaching 1)."""
    if isinstance(n, bool) or not isinstance(n, int) or not 3 <= n <= MAX_SEGMENTS // 2:
        raise OutlineError(None, f"a regular polygon needs 3 to {MAX_SEGMENTS // 2} sides, got {shown(n)}")
    r = _number(corner_radius, "corner_radius", None)
    if not 0.0 <= r < 1.0:
        raise OutlineError(None, f"corner_radius must be in [0, 1) of the circumradius, got {shown(corner_radius)}")
    a0, step = math.radians(_number(rotation_deg, "rotation_deg", None)), TWO_PI / n
    v0 = (1.0 - r) * math.cos(a0), (1.0 - r) * math.sin(a0)
    nx, ny = math.cos(a0 + step / 2), math.sin(a0 + step / 2)   # the outward normal of side 0
    v1 = (1.0 - r) * math.cos(a0 + step), (1.0 - r) * math.sin(a0 + step)
    piece = [{"type": "line", "p0": [v0[0] + r * nx, v0[1] + r * ny], "p1": [v1[0] + r * nx, v1[1] + r * ny]}]
    if r > 0:
        m0, m1 = a0 + step / 2, a0 + 3 * step / 2
        piece.append({"type": "arc", "center": list(v1), "radius": r, "ccw": True,
                      "p0": [v1[0] + r * math.cos(m0), v1[1] + r * math.sin(m0)],
                      "p1": [v1[0] + r * math.cos(m1), v1[1] + r * math.sin(m1)]})
    return n_fold(piece, n)


def triangle(corner_radius: float = 0.0, rotation_deg: float = 90.0) -> PlanOutline:
    """Equilateral triangle, a vertex up by default (see :func:`regular_polygon`)."""
    return regular_polygon(3, corner_radius, rotation_deg)


def square(corner_radius: float = 0.0, rotation_deg: float = 45.0) -> PlanOutline:
    """Square with sides along the axes by default: SPEC_outline's ``(+-1, +-1)/sqrt2``."""
    return regular_polygon(4, corner_radius, rotation_deg)


def hexagon(corner_radius: float = 0.0, rotation_deg: float = 0.0) -> PlanOutline:
    """Regular hexagon, a vertex at (1, 0) by default (as outline_public_1)."""
    return regular_polygon(6, corner_radius, rotation_deg)


def octagon(corner_radius: float = 0.0, rotation_deg: float = 22.5) -> PlanOutline:
    """Regular octagon with sides along the axes by default."""
    return regular_polygon(8, corner_radius, rotation_deg)


def flask(width: float, depth: float, end_radius: float | None = None) -> PlanOutline:
    """The four-arc oval of a hip flask (as outline_public_2), ``width`` along x and ``depth``
    along y (mm): two end arcs of radius ``end_radius`` (default ``width / 16``) about
    ``(+-(width/2 - end_radius), 0)`` and two flat side arcs through ``(0, +-depth/2)`` tangent to
    them, of radius ``(a^2 + b^2 - e^2) / (2 (b - e))`` (``a = width/2 - e``, ``b = depth/2``)."""
    w, d = _number(width, "width", None), _number(depth, "depth", None)
    e = w / 16 if end_radius is None else _number(end_radius, "end_radius", None)
    a, b = w / 2 - e, d / 2
    if not (0 < e < b and d < w):
        raise OutlineError(None, f"a flask needs depth < width and 0 < end_radius < depth / 2, "
                                 f"got {w:g} x {d:g} mm, end radius {e:g} mm")
    side = (a * a + b * b - e * e) / (2 * (b - e))
    f = side / math.hypot(a, side - b)    # the tangent point lies on the line of both centres
    tx, ty = f * a, f * (side - b) - (side - b)
    arcs = [((a, 0.0), e, (tx, -ty), (tx, ty)), ((0.0, b - side), side, (tx, ty), (-tx, ty)),
            ((-a, 0.0), e, (-tx, ty), (-tx, -ty)), ((0.0, side - b), side, (-tx, -ty), (tx, -ty))]
    return PlanOutline.from_dicts([{"type": "arc", "center": list(c), "radius": r, "p0": list(p0),
                                    "p1": list(p1), "ccw": True} for c, r, p0, p1 in arcs])


def shield(width: float = 1.0, height: float = 1.2, shoulder: float = 0.4) -> PlanOutline:
    """A heraldic shield, symmetric about the y axis: a flat top of ``width`` at ``y = height/2``,
    straight sides down a fraction ``shoulder`` of the height, then two arcs tangent to the sides
    meeting in a sharp point at ``(0, -height/2)``; the arcs need ``(1 - shoulder) height > width/2``."""
    w, hh = _number(width, "width", None) / 2, _number(height, "height", None) / 2
    s = _number(shoulder, "shoulder", None)
    y0 = hh - 2 * hh * s
    drop = y0 + hh                       # height of the curved part
    if not (w > 0 and 0 < s < 1 and drop > w):
        raise OutlineError(None, f"a shield needs width > 0, 0 < shoulder < 1 and a curved part "
                                 f"taller than half the width, got {shown((width, height, shoulder))}")
    rho = (w * w + drop * drop) / (2 * w)  # the arc about (w - rho, y0) through (0, -hh)
    half = [{"type": "arc", "center": [w - rho, y0], "radius": rho, "p0": [0.0, -hh], "p1": [w, y0], "ccw": True},
            {"type": "line", "p0": [w, y0], "p1": [w, hh]}]
    return mirrored(half)
