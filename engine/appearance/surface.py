"""The outer wall in the coordinates labels are measured in, and the tracer's ``(theta, h)``.

Design rule: the tracer hands every hit on the outer wall to the labels as ``(theta, h)``:
``theta`` (rad) the polar angle about +z in the bottle's own frame (the world for round
bottles; for non-round ones the world turned by ``-rotation_deg``), and ``h`` (mm) the **arc
length along the section from the centre of the base** for round bottles (the standing ring
is at :attr:`RoundWall.h_ring`, the mouth at :attr:`RoundWall.h_top`) and the **height z** for
non-round bottles. :func:`surface_coordinates` is that rule for world points, the reference
the tracer's kernels follow. :class:`RoundWall` evaluates a round section by arc length
(exact for lines and arcs, Newton on Gauss-Legendre lengths for ellipse arcs);
:class:`NonRoundWall` gives a non-round wall's radii, girth and perimeter at a height and the
slant length up one meridian (``theta`` fixed), tabulated finely once per meridian.
Both are built from the validated profile (:func:`engine.geometry.validate.body_profile`).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..geometry.body import BottleBody, chain_state
from ..geometry.chain import by_segment, locate
from ..geometry.segments import EllipseArc
from ..geometry.validate import body_profile
from . import girth

_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)
#: Samples of a non-round meridian's slant table over the whole wall.
MERIDIAN_SAMPLES = 8193


def partial_length(seg, t) -> np.ndarray:
    """Arc length (mm) of ``seg`` from its start to parameter ``t`` in [0, 1] (vectorised)."""
    t = np.asarray(t, float)
    if not isinstance(seg, EllipseArc):
        return t * seg.length  # lines and circular arcs are parameterised by length
    tau = t[..., None] * (_GL_X + 1.0) / 2.0
    s = seg.angle(tau)
    speed = np.hypot(seg.radius_r * np.sin(s), seg.radius_z * np.cos(s))
    return abs(seg.sweep) * t / 2.0 * np.sum(_GL_W * speed, axis=-1)


def param_at_length(seg, length) -> np.ndarray:
    """The parameter ``t`` at which :func:`partial_length` is ``length`` (mm, clipped)."""
    total = seg.length
    t = np.clip(np.asarray(length, float) / total, 0.0, 1.0)
    if not isinstance(seg, EllipseArc):
        return t
    for _ in range(12):  # Newton: d length / dt = |sweep| * speed > 0
        s = seg.angle(t)
        speed = abs(seg.sweep) * np.hypot(seg.radius_r * np.sin(s), seg.radius_z * np.cos(s))
        t = np.clip(t - (partial_length(seg, t) - length) / speed, 0.0, 1.0)
    return t


class RoundWall:
    """A round bottle's outer section (base centre -> mouth) evaluated by arc length ``h`` (mm).

    ``segments`` is the outer base followed by the outer wall; ``cum[i]`` is the arc length at
    the start of segment ``i``; ``h_ring`` is where the wall starts (the standing ring) and
    ``h_top`` the mouth.
    """

    def __init__(self, shape):
        prof = body_profile(shape).sections[0]
        self.segments = tuple(prof.outer_base) + tuple(prof.outer_wall)
        self.first_wall = len(prof.outer_base)
        lengths = np.array([seg.length for seg in self.segments])
        self.cum = np.concatenate([[0.0], np.cumsum(lengths)])
        self.h_ring = float(self.cum[self.first_wall])
        self.h_top = float(self.cum[-1])

    def at(self, h):
        """``(r, z, T_r, T_z)`` (mm, unit tangent) at arc lengths ``h`` (clipped to the section)."""
        h = np.clip(np.asarray(h, float), 0.0, self.h_top)
        idx = np.clip(np.searchsorted(self.cum, h, side="right") - 1, 0, len(self.segments) - 1)
        out = [np.empty(h.shape) for _ in range(4)]
        flat_h, flat = h.reshape(-1), [o.reshape(-1) for o in out]
        for i, part in by_segment(idx):
            seg = self.segments[i]
            t = param_at_length(seg, flat_h[part] - self.cum[i])
            p, tan = seg.point(t), seg.tangent(t)
            for k, v in enumerate((p[..., 0], p[..., 1], tan[..., 0], tan[..., 1])):
                flat[k][part] = v
        return tuple(out)

    def h_at_z(self, z) -> np.ndarray:
        """Arc length ``h`` (mm) of the wall point at height ``z`` (mm); NaN off the wall."""
        wall = self.segments[self.first_wall:]
        idx, t = locate(wall, np.asarray(z, float))
        h = np.full(np.shape(t), np.nan)
        flat_h, flat_t = h.reshape(-1), t.reshape(-1)
        for i, part in by_segment(idx):
            if i >= 0:
                k = self.first_wall + i
                flat_h[part] = self.cum[k] + partial_length(self.segments[k], flat_t[part])
        return h

    def joints(self):
        """``(h, turn_deg)`` of every joint of the wall: where it is, how far the tangent turns."""
        out = []
        for k in range(self.first_wall, len(self.segments) - 1):
            a = self.segments[k].tangent(1.0)
            b = self.segments[k + 1].tangent(0.0)
            turn = math.degrees(math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1]))
            out.append((float(self.cum[k + 1]), abs(turn)))
        return out


class NonRoundWall:
    """A non-round bottle's outer wall: radii, girth and perimeter at heights, slant meridians."""

    def __init__(self, shape):
        self.shape = shape
        self.kind = shape.cross_section
        self.xs = shape.xs
        self.profile = body_profile(shape)
        self.body = BottleBody(shape)
        self.z_top = float(self.profile.z_top)

    def radii(self, z):
        """Per-section outer radii (mm) at heights ``z`` (the kind's section order)."""
        return tuple(chain_state(sp.outer_wall, z)[0] for sp in self.profile.sections)

    def girth(self, theta, z) -> np.ndarray:
        """Girth length (mm) from polar angle 0 to ``theta`` at heights ``z``."""
        return girth.girth_length(self.xs, self.radii(z), theta)

    def theta_at(self, length, z) -> np.ndarray:
        """The polar angle whose girth length at ``z`` is ``length`` (mm)."""
        return girth.theta_at_length(self.xs, self.radii(z), length)

    def perimeter(self, z) -> np.ndarray:
        return girth.perimeter(self.xs, self.radii(z))

    def points(self, theta, z) -> np.ndarray:
        """World points ``(..., 3)`` (mm) of the outer wall."""
        return self.body.wall("outer", theta, z)[0]

    def meridian(self, theta: float):
        """``(z, sigma)`` tables: slant length ``sigma`` (mm) up the wall at polar angle
        ``theta`` from z = 0, at :data:`MERIDIAN_SAMPLES` heights (chords of 0.04 mm on a
        300 mm bottle)."""
        return _meridian(self.shape, round(float(theta), 12))


@lru_cache(maxsize=64)
def _meridian(shape, theta: float):
    wall = NonRoundWall(shape)
    z = np.linspace(0.0, wall.z_top, MERIDIAN_SAMPLES)
    p = wall.points(np.full(z.shape, theta), z)
    sigma = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    z.setflags(write=False)
    sigma.setflags(write=False)
    return z, sigma


@lru_cache(maxsize=16)
def wall_of(shape):
    """The :class:`RoundWall` or :class:`NonRoundWall` of a shape (cached by value)."""
    return RoundWall(shape) if shape.xs.revolved else NonRoundWall(shape)


def surface_coordinates(shape, points):
    """The tracer's ``(theta, h)`` of world points ``(..., 3)`` on the outer wall (module rule).

    ``theta`` is in (-pi, pi]; round bottles give ``h`` as arc length (NaN for a point below
    the standing ring or above the mouth), non-round bottles the height z.
    """
    p = np.asarray(points, float)
    if shape.xs.revolved:
        return np.arctan2(p[..., 1], p[..., 0]), wall_of(shape).h_at_z(p[..., 2])
    a = math.radians(shape.rotation_deg)
    theta = np.arctan2(p[..., 1], p[..., 0]) - a
    return np.mod(theta + math.pi, 2.0 * math.pi) - math.pi, p[..., 2].copy()
