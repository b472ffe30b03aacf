"""One label's exact map between the wall's ``(theta, h)`` and its artwork's ``(s, t)``.

Design rule: a label is the patch of the outer wall between two *parallels* (its top and bottom
edges, ``height_mm`` apart measured up the wall through its centre) and two *meridians-by-girth*
(its side edges, ``width_mm`` apart measured around the girth at its centre height), and its
artwork fills that patch with

* ``t`` (top 0 -> bottom 1) linear in the slant length up the wall at the centre azimuth, and
* ``s`` (left 0 -> right 1, increasing azimuth seen from outside) linear in the *fraction of the
  girth*: at every height the label covers the same fraction ``width_mm / P(z_mm)`` of the
  perimeter ``P`` (round: ``theta`` itself).

This is how paper goes on glass where it can: on a cylinder (or a straight prism) the patch is
a rolled rectangle, on a cone it unrolls to an annular sector whose rows are concentric arcs
(the artwork warped to the sector, as arc labels are printed), and it is the same rule on any
other band, whose least-distortion flat shape :mod:`engine.appearance.flatten` computes. Round
bottles make ``s`` and ``t`` exactly linear in ``(theta, h)``; non-round ones need the girth
(:mod:`engine.appearance.girth`) and a slant table. Angles in rad in the bottle's own frame
(``theta_c`` = ``angle_deg - rotation_deg``); lengths in mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import DesignError
from .surface import NonRoundWall, RoundWall, wall_of

TWO_PI = 2.0 * math.pi
#: Rows at which a non-round label's side edges are solved for its footprint's theta range.
EDGE_ROWS = 129


@dataclass(frozen=True)
class Placement:
    """The numbers of a label that fix its patch (mm, degrees): its geometry key."""

    z_mm: float
    angle_deg: float
    height_mm: float
    width_mm: float

    @classmethod
    def of(cls, label) -> "Placement":
        return cls(float(label.z_mm), float(label.angle_deg), float(label.height_mm),
                   float(label.width_mm))


class LabelFrame:
    """The exact map of one placed label (see the module rule).

    Attributes
    ----------
    theta_c, h_c : float
        The centre (rad in the bottle frame, tracer ``h`` in mm).
    theta0, theta1, h0, h1 : float
        The footprint: every label point has ``theta0 <= theta <= theta1`` (unwrapped, span at
        most ``2 pi``) and ``h0 <= h <= h1`` (the bottom and top edges exactly).
    girth_mm : float
        The girth at the centre height; ``width_mm <= girth_mm``.
    """

    kind = "round"

    def __init__(self, shape, p: Placement, where: str = "label"):
        self.shape, self.placement, self.where = shape, p, where
        self.wall: RoundWall = wall_of(shape)
        w = self.wall
        self.h_c = float(w.h_at_z(p.z_mm))
        if not math.isfinite(self.h_c):
            raise DesignError(f"{where}: its centre z = {p.z_mm:g} mm is not on the wall "
                              f"(0 .. {shape.z_top:g} mm)")
        self.r_c = float(w.at(self.h_c)[0])
        self.girth_mm = TWO_PI * self.r_c
        self.theta_c = math.radians(p.angle_deg)
        self.span = p.width_mm / self.r_c
        self.theta0, self.theta1 = self.theta_c - self.span / 2, self.theta_c + self.span / 2
        self.h0, self.h1 = self.h_c - p.height_mm / 2, self.h_c + p.height_mm / 2

    def st(self, theta, h):
        """Artwork ``(s, t)`` of surface points (``theta`` unwrapped near the label)."""
        s = (np.asarray(theta, float) - self.theta0) / self.span
        return s, (self.h1 - np.asarray(h, float)) / self.placement.height_mm

    def surface(self, s, t):
        """``(theta, h)`` of artwork points: the inverse of :meth:`st`."""
        return (self.theta0 + np.asarray(s, float) * self.span,
                self.h1 - np.asarray(t, float) * self.placement.height_mm)

    def points(self, s, t) -> np.ndarray:
        """World points ``(..., 3)`` (mm) of artwork points on the wall."""
        theta, h = self.surface(s, t)
        r, z, _, _ = self.wall.at(h)
        return np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=-1)

    def linear(self) -> bool:
        """Whether ``(s, t)`` is exactly linear in ``(theta, h)`` (so 2 x 2 nodes interpolate it)."""
        return True

    def size_to(self, z_mm: float, angle_deg: float) -> tuple[float, float]:
        """``(height_mm, width_mm)`` of the label, kept centred, whose corner is the surface point
        at height ``z_mm`` and azimuth ``angle_deg`` (world frame): twice the slant from the
        centre's height and twice the girth arc from the centre's azimuth at the centre height
        (the shorter way round). What a drag on a label's corner asks for."""
        return 2.0 * abs(self._slant(z_mm)), 2.0 * self._arc(math.radians(angle_deg))

    def _slant(self, z_mm: float) -> float:
        return float(self.wall.h_at_z(z_mm)) - self.h_c

    def _arc(self, theta: float) -> float:
        d = math.remainder(theta - self.theta_c, TWO_PI)
        return abs(d) * self.r_c


class NonRoundFrame(LabelFrame):
    """The map on a non-round wall: ``h`` is z, ``s`` follows the girth fraction."""

    kind = "non-round"

    def __init__(self, shape, p: Placement, where: str = "label"):
        self.shape, self.placement, self.where = shape, p, where
        self.wall: NonRoundWall = wall_of(shape)
        w = self.wall
        if not 0.0 < p.z_mm < w.z_top:
            raise DesignError(f"{where}: its centre z = {p.z_mm:g} mm is not on the wall "
                              f"(0 .. {w.z_top:g} mm)")
        self.theta_c = math.radians(p.angle_deg - shape.rotation_deg)
        self._z, self._sigma = w.meridian(self.theta_c)
        self.h_c = float(p.z_mm)
        self.sigma_c = float(np.interp(self.h_c, self._z, self._sigma))
        self.p_c = float(w.perimeter(self.h_c))
        self.girth_mm = self.p_c
        lo, hi = self.sigma_c - p.height_mm / 2, self.sigma_c + p.height_mm / 2
        self.h0 = float(np.interp(lo, self._sigma, self._z, left=-math.inf))
        self.h1 = float(np.interp(hi, self._sigma, self._z, right=math.inf))
        self.theta0 = self.theta1 = self.theta_c
        if math.isfinite(self.h0) and math.isfinite(self.h1) and p.width_mm <= self.p_c:
            z = np.linspace(self.h0, self.h1, EDGE_ROWS)
            left, _ = self.surface(np.zeros_like(z), self.t_of_z(z))
            right, _ = self.surface(np.ones_like(z), self.t_of_z(z))
            pad = 1e-9 * (right.max() - left.min())
            self.theta0, self.theta1 = float(left.min()) - pad, float(right.max()) + pad
        self.span = self.theta1 - self.theta0

    def t_of_z(self, z):
        sigma = np.interp(np.asarray(z, float), self._z, self._sigma)
        return 0.5 - (sigma - self.sigma_c) / self.placement.height_mm

    def _fraction(self, z):
        """``width_mm / P(z_c) * P(z)``: the label's girth arc (mm) at heights ``z``."""
        return self.placement.width_mm / self.p_c * self.wall.perimeter(z)

    def st(self, theta, h):
        theta, z = np.broadcast_arrays(np.asarray(theta, float), np.asarray(h, float))
        centre = self.wall.girth(np.full(z.shape, self.theta_c), z)
        s = 0.5 + (self.wall.girth(theta, z) - centre) / self._fraction(z)
        return s, self.t_of_z(z)

    def surface(self, s, t):
        s, t = np.broadcast_arrays(np.asarray(s, float), np.asarray(t, float))
        sigma = self.sigma_c + (0.5 - t) * self.placement.height_mm
        z = np.interp(sigma, self._sigma, self._z)
        centre = self.wall.girth(np.full(z.shape, self.theta_c), z)
        return self.wall.theta_at(centre + (s - 0.5) * self._fraction(z), z), z

    def points(self, s, t) -> np.ndarray:
        theta, z = self.surface(s, t)
        return self.wall.points(theta, z)

    def linear(self) -> bool:
        return False

    def _slant(self, z_mm: float) -> float:
        return float(np.interp(z_mm, self._z, self._sigma)) - self.sigma_c

    def _arc(self, theta: float) -> float:
        theta = theta - math.radians(self.shape.rotation_deg)  # world -> bottle frame
        d = math.remainder(theta - self.theta_c, TWO_PI)
        z = np.array([self.h_c])
        arc = abs(float(self.wall.girth(np.array([self.theta_c + d]), z)[0]
                        - self.wall.girth(np.array([self.theta_c]), z)[0]))
        return min(arc, self.p_c - arc) if arc > 0.5 * self.p_c else arc


@lru_cache(maxsize=256)
def label_frame(shape, placement: Placement, where: str = "label") -> LabelFrame:
    """The :class:`LabelFrame` of a label with ``placement`` on ``shape`` (cached by value).

    Raises ``DesignError`` when its centre is not on the wall or the bottle's cross-section
    cannot carry labels (:meth:`~engine.geometry.crosssection.CrossSection.require`; every kind
    can today); whether the whole patch is, :func:`engine.appearance.placement.check_label_placement` says.
    """
    shape.xs.require("labels")
    cls = LabelFrame if shape.xs.revolved else NonRoundFrame
    return cls(shape, placement, where)
