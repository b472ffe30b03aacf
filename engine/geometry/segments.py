"""Section segments: lines, circular arcs and axis-aligned elliptical arcs in the (r, z) plane.

Design rule: a segment is a small immutable value (frozen dataclass) in millimetres, with
float64 geometry. Every segment is parameterised by ``t`` in [0, 1] from ``p0`` to ``p1``;
``point``, ``tangent`` and ``normal`` accept scalars or numpy arrays of ``t``.

Orientation follows ../shared/oracle/SPEC.md section 4.1: walking up the section the glass
interior is on the left, the unit tangent is ``T = (T_r, T_z)`` and the outward normal is
``n = (T_z, -T_r)``. ``"ccw"`` arcs are convex (bulge outwards), ``"cw"`` arcs concave.

The dictionary form (``to_dict`` / ``segment_from_dict``) is exactly the SPEC's segment JSON,
so SPEC profiles and glassbench projects share one vocabulary.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Union

import numpy as np

from ..errors import SectionError, shown

TWO_PI = 2.0 * math.pi
#: Tolerance (mm) for end points lying on their circle / ellipse, as in SPEC 4.1.
POINT_TOL_MM = 1e-6


def _pt(p) -> tuple[float, float]:
    """Return ``p`` as a tuple of two finite floats (mm) or raise ``ValueError``."""
    if len(p) != 2:
        raise ValueError(f"a point needs two coordinates (r, z), got {shown(p)}")
    r, z = float(p[0]), float(p[1])
    if not (math.isfinite(r) and math.isfinite(z)):
        raise ValueError(f"point {shown(p)} is not finite")
    return (r, z)


def _sweep(a0: float, a1: float, direction: str) -> float:
    """Signed angle (rad) swept from ``a0`` to ``a1`` going ``direction``; never zero."""
    d = (a1 - a0) % TWO_PI
    if direction == "ccw":
        return d if d > 1e-15 else TWO_PI
    d = d - TWO_PI
    return d if d < -1e-15 else -TWO_PI


@dataclass(frozen=True)
class Line:
    """Straight segment from ``p0`` to ``p1`` (mm)."""

    p0: tuple[float, float]
    p1: tuple[float, float]
    kind = "line"

    def __post_init__(self):
        object.__setattr__(self, "p0", _pt(self.p0))
        object.__setattr__(self, "p1", _pt(self.p1))

    def point(self, t):
        """Point(s) (mm) at parameter ``t``; shape ``(..., 2)``."""
        t = np.asarray(t, dtype=float)[..., None]
        p0, p1 = np.array(self.p0), np.array(self.p1)
        return p0 + t * (p1 - p0)

    def tangent(self, t):
        """Unit tangent(s) in the walking direction; shape ``(..., 2)``."""
        d = np.array(self.p1) - np.array(self.p0)
        d = d / np.hypot(*d)
        return np.broadcast_to(d, np.shape(t) + (2,)).copy()

    def curvature(self, t):
        """Signed curvature (1/mm): positive where convex (bulging outwards)."""
        return np.zeros(np.shape(t))

    @property
    def length(self) -> float:
        """Arc length (mm)."""
        return math.hypot(self.p1[0] - self.p0[0], self.p1[1] - self.p0[1])

    def offset(self, w: float) -> "Line":
        """The segment moved ``w`` mm inwards (against the outward normal)."""
        (tr, tz) = self.tangent(0.0)
        dr, dz = -w * tz, w * tr
        return Line((self.p0[0] + dr, self.p0[1] + dz), (self.p1[0] + dr, self.p1[1] + dz))

    def reversed(self) -> "Line":
        """The same segment walked from ``p1`` to ``p0``."""
        return Line(self.p1, self.p0)

    def to_dict(self) -> dict:
        return {"type": "line", "p0": list(self.p0), "p1": list(self.p1)}


@dataclass(frozen=True)
class Arc:
    """Circular arc about ``center`` of ``radius`` (mm) from ``p0`` to ``p1``.

    ``direction`` is ``"ccw"`` (angle increasing: convex) or ``"cw"`` (concave).
    The end points must lie on the circle within ``POINT_TOL_MM``.
    """

    center: tuple[float, float]
    radius: float
    p0: tuple[float, float]
    p1: tuple[float, float]
    direction: str = "ccw"
    kind = "arc"

    def __post_init__(self):
        object.__setattr__(self, "center", _pt(self.center))
        object.__setattr__(self, "p0", _pt(self.p0))
        object.__setattr__(self, "p1", _pt(self.p1))
        object.__setattr__(self, "radius", float(self.radius))
        if self.direction not in ("ccw", "cw"):
            raise ValueError(f"arc direction must be 'ccw' or 'cw', got {shown(self.direction)}")
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"arc radius must be a positive number of mm, got {shown(self.radius)}")

    @property
    def angle0(self) -> float:
        """Polar angle (rad) of ``p0`` about the centre."""
        return math.atan2(self.p0[1] - self.center[1], self.p0[0] - self.center[0])

    @property
    def sweep(self) -> float:
        """Signed swept angle (rad): positive for ccw."""
        a1 = math.atan2(self.p1[1] - self.center[1], self.p1[0] - self.center[0])
        return _sweep(self.angle0, a1, self.direction)

    def angle(self, t):
        """Polar angle(s) (rad) at parameter ``t``."""
        return self.angle0 + np.asarray(t, dtype=float) * self.sweep

    def point(self, t):
        a = self.angle(t)
        return np.stack([self.center[0] + self.radius * np.cos(a),
                         self.center[1] + self.radius * np.sin(a)], axis=-1)

    def tangent(self, t):
        a = self.angle(t)
        s = 1.0 if self.direction == "ccw" else -1.0
        return np.stack([-s * np.sin(a), s * np.cos(a)], axis=-1)

    def curvature(self, t):
        s = 1.0 if self.direction == "ccw" else -1.0
        return np.full(np.shape(t), s / self.radius)

    @property
    def length(self) -> float:
        return abs(self.sweep) * self.radius

    def offset(self, w: float) -> "Arc":
        """Concentric arc ``w`` mm inwards (radius ``R - w`` if ccw, ``R + w`` if cw)."""
        r = self.radius - w if self.direction == "ccw" else self.radius + w
        if r <= 0:
            raise SectionError(None, f"wall {w} mm is not thinner than the arc radius {self.radius} mm")
        a0, sw = self.angle0, self.sweep
        c = self.center
        return Arc(c, r, (c[0] + r * math.cos(a0), c[1] + r * math.sin(a0)),
                   (c[0] + r * math.cos(a0 + sw), c[1] + r * math.sin(a0 + sw)), self.direction)

    def reversed(self) -> "Arc":
        return Arc(self.center, self.radius, self.p1, self.p0,
                   "cw" if self.direction == "ccw" else "ccw")

    def to_dict(self) -> dict:
        return {"type": "arc", "center": list(self.center), "radius": self.radius,
                "p0": list(self.p0), "p1": list(self.p1), "direction": self.direction}


@dataclass(frozen=True)
class EllipseArc:
    """Axis-aligned elliptical arc ``center + (radius_r cos s, radius_z sin s)`` (mm).

    ``s`` runs from the parameter angle of ``p0`` to that of ``p1``, increasing for
    ``"ccw"`` (convex) and decreasing for ``"cw"`` (concave).
    """

    center: tuple[float, float]
    radius_r: float
    radius_z: float
    p0: tuple[float, float]
    p1: tuple[float, float]
    direction: str = "ccw"
    kind = "ellipse_arc"

    def __post_init__(self):
        object.__setattr__(self, "center", _pt(self.center))
        object.__setattr__(self, "p0", _pt(self.p0))
        object.__setattr__(self, "p1", _pt(self.p1))
        object.__setattr__(self, "radius_r", float(self.radius_r))
        object.__setattr__(self, "radius_z", float(self.radius_z))
        if self.direction not in ("ccw", "cw"):
            raise ValueError(f"ellipse direction must be 'ccw' or 'cw', got {shown(self.direction)}")
        for name in ("radius_r", "radius_z"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"ellipse {name} must be a positive number of mm, got {shown(v)}")

    def _param(self, p) -> float:
        return math.atan2((p[1] - self.center[1]) / self.radius_z, (p[0] - self.center[0]) / self.radius_r)

    @property
    def angle0(self) -> float:
        """Parameter angle (rad) of ``p0``."""
        return self._param(self.p0)

    @property
    def sweep(self) -> float:
        """Signed parameter sweep (rad): positive for ccw."""
        return _sweep(self.angle0, self._param(self.p1), self.direction)

    def angle(self, t):
        return self.angle0 + np.asarray(t, dtype=float) * self.sweep

    def point(self, t):
        s = self.angle(t)
        return np.stack([self.center[0] + self.radius_r * np.cos(s),
                         self.center[1] + self.radius_z * np.sin(s)], axis=-1)

    def tangent(self, t):
        s = self.angle(t)
        sg = 1.0 if self.direction == "ccw" else -1.0
        d = np.stack([-self.radius_r * np.sin(s), self.radius_z * np.cos(s)], axis=-1) * sg
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def curvature(self, t):
        s = self.angle(t)
        a, b = self.radius_r, self.radius_z
        k = a * b / (a * a * np.sin(s) ** 2 + b * b * np.cos(s) ** 2) ** 1.5
        return k if self.direction == "ccw" else -k

    @property
    def length(self) -> float:
        # Gauss-Legendre on the speed |dP/ds|; 64 nodes are exact to ~1e-12 for sane ellipses.
        x, w = np.polynomial.legendre.leggauss(64)
        s = self.angle0 + (x + 1) / 2 * self.sweep
        speed = np.hypot(self.radius_r * np.sin(s), self.radius_z * np.cos(s))
        return float(abs(self.sweep) / 2 * np.dot(w, speed))

    def reversed(self) -> "EllipseArc":
        return EllipseArc(self.center, self.radius_r, self.radius_z, self.p1, self.p0,
                          "cw" if self.direction == "ccw" else "ccw")

    def to_dict(self) -> dict:
        return {"type": "ellipse_arc", "center": list(self.center), "radius_r": self.radius_r,
                "radius_z": self.radius_z, "p0": list(self.p0), "p1": list(self.p1),
                "direction": self.direction}


class EndsFromPoint:
    """``p0`` and ``p1`` (mm) of a segment whose ends are its ``point(0)`` and ``point(1)``
    (one that stores no end points of its own)."""

    @property
    def p0(self) -> tuple[float, float]:
        return tuple(float(v) for v in self.point(0.0))

    @property
    def p1(self) -> tuple[float, float]:
        return tuple(float(v) for v in self.point(1.0))


@dataclass(frozen=True)
class OffsetEllipseArc(EndsFromPoint):
    """The exact inward offset of an ``EllipseArc`` by ``w`` mm: ``P(t) - w n(t)``.

    Not an ellipse. It shares the base arc's parameter ``t`` and tangent direction; it is
    regular while ``w`` is below the radius of curvature of every convex part of the arc.
    Produced by offsetting sections (inner walls); never stored in a project file.
    """

    base: EllipseArc
    w: float
    kind = "ellipse_offset"

    @property
    def direction(self) -> str:
        return self.base.direction

    def point(self, t):
        return self.base.point(t) - self.w * normal(self.base, t)

    def tangent(self, t):
        return self.base.tangent(t)

    def curvature(self, t):
        k = self.base.curvature(t)
        return k / (1.0 - self.w * k)

    @property
    def length(self) -> float:
        x, wts = np.polynomial.legendre.leggauss(64)
        t = (x + 1) / 2
        s = self.base.angle(t)
        speed = np.hypot(self.base.radius_r * np.sin(s), self.base.radius_z * np.cos(s))
        # |dQ/dt| = |dP/dt| (1 - w k) for the inward offset.
        return float(abs(self.base.sweep) / 2 * np.dot(wts, speed * (1.0 - self.w * self.base.curvature(t))))

    def offset(self, w: float) -> "OffsetEllipseArc":
        return OffsetEllipseArc(self.base, self.w + w)


def _ellipse_offset(self: EllipseArc, w: float) -> OffsetEllipseArc:
    """The exact inward offset curve ``w`` mm inside this arc (not an ellipse)."""
    return OffsetEllipseArc(self, float(w))


EllipseArc.offset = _ellipse_offset

Segment = Union[Line, Arc, EllipseArc, OffsetEllipseArc]


def normal(seg: Segment, t):
    """Outward unit normal(s) ``n = (T_z, -T_r)`` of ``seg`` at ``t``; shape ``(..., 2)``."""
    tan = seg.tangent(t)
    return np.stack([tan[..., 1], -tan[..., 0]], axis=-1)


_FIELDS = {
    "line": (Line, ("p0", "p1")),
    "arc": (Arc, ("center", "radius", "p0", "p1", "direction")),
    "ellipse_arc": (EllipseArc, ("center", "radius_r", "radius_z", "p0", "p1", "direction")),
}


def segment_from_dict(d: dict) -> Segment:
    """Build a segment from its SPEC/project dictionary; raises ``ValueError`` naming the problem.

    The dictionary holds ``type`` and exactly the fields of that type (``direction`` may be
    left out: ``"ccw"``); an unknown field is refused rather than dropped.
    """
    if not isinstance(d, dict):
        raise ValueError(f"a segment must be an object, got {type(d).__name__}")
    kind = d.get("type")
    if not isinstance(kind, str) or kind not in _FIELDS:
        raise ValueError(f"unknown segment type {shown(kind)} (expected line, arc or ellipse_arc)")
    cls, fields = _FIELDS[kind]
    missing = [f for f in fields if f not in d and f != "direction"]
    if missing:
        raise ValueError(f"{kind} segment lacks {', '.join(missing)}")
    unknown = [k for k in d if k != "type" and k not in fields]
    if unknown:
        raise ValueError(f"{kind} segment has unknown field(s) {', '.join(shown(k, 30) for k in unknown[:3])}")
    kwargs = {f: d[f] for f in fields if f in d}
    for f in ("p0", "p1", "center"):
        if f in kwargs and not (isinstance(kwargs[f], (list, tuple)) and len(kwargs[f]) == 2
                                and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                        for v in kwargs[f])):
            raise ValueError(f"{kind} segment field {f!r} must be two numbers, got {shown(kwargs[f])}")
    for f in ("radius", "radius_r", "radius_z"):
        if f in kwargs and (isinstance(kwargs[f], bool) or not isinstance(kwargs[f], (int, float))):
            raise ValueError(f"{kind} segment field {f!r} must be a number, got {shown(kwargs[f])}")
    if "direction" in kwargs and not isinstance(kwargs["direction"], str):
        raise ValueError(f"{kind} segment direction must be 'ccw' or 'cw'")
    return cls(**kwargs)
