"""Horizontal cross-sections as objects: one :class:`CrossSection` per kind, one table of them.

Design rule: a cross-section at one height is fully given by its *radii*, the values of the
kind's named sections at that height (``engine.geometry.shape.SECTION_NAMES`` order, mm):

=================  ==========================================================================
``round``          ``(r,)``
``rounded_square`` ``(u, v)``: half-width and diagonal radius; sides ``x = +-u`` for
                   ``|y| <= p``, corner arcs about ``(+-p, +-p)`` of radius ``q`` with
                   ``p = (sqrt2+1)(v-u)``, ``q = (sqrt2+1)(sqrt2 u - v)``; needs ``u <= v < sqrt2 u``
``rounded_rect``   ``(half_width a, half_depth b, corner c)``: needs ``0 < c <= min(a, b)``
``oval``           ``(a, b)``: the ellipse ``(x/a)^2 + (y/b)^2 = 1``
``outline``        ``(k, r)``: ``{q : sd(q, k P) <= r}`` of the bottle's plan outline ``P``
                   (:mod:`engine.geometry.plan`): the outer solid's ``r = c > 0`` (rounded
                   corners), the cavity's ``r = c - w`` of either sign (``r < 0``: the inner
                   parallel set, sharp inner corners); needs ``k >= 0``
=================  ==========================================================================

Every caller asks the object (:func:`cross_section_of` a shape, or :func:`of_kind` a fixed kind's
name) instead of switching on the kind's name: each kind's closed forms live in its class. A
rounded square is the rounded rectangle ``(u, u, q)``, so both share one implementation. Every
method takes the radii as a tuple of arrays that broadcast against the other arguments, and the
polar angle ``theta`` (rad) is measured in the bottle's own frame (before ``rotation_deg``).
What a kind cannot do yet (relief, CAD, ...) it refuses by :meth:`CrossSection.require`,
with one line naming the feature. The module-level functions taking a kind's name are thin
wrappers for the fixed kinds, kept for the tests and scripts written against them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import NotSupportedError

SQRT2 = math.sqrt(2.0)
#: d q / d u and d q / d v for the rounded square (q = (sqrt2+1)(sqrt2 u - v)).
DQ_DU, DQ_DV = (SQRT2 + 1.0) * SQRT2, -(SQRT2 + 1.0)
HALF_PI = 0.5 * math.pi

#: What a kind may not offer yet (:meth:`CrossSection.require`), in the words of its refusal.
FEATURES = {"labels": "labels", "relief": "relief (bump tiles, bands and embossing)",
            "cad": "CAD export", "drawing": "technical drawings", "stability": "the stability check",
            "stress": "the membrane stress estimate"}


def square_corner(u, v):
    """``(p, q)`` (mm) of the rounded square with half-width ``u`` and diagonal radius ``v``."""
    u, v = np.asarray(u, float), np.asarray(v, float)
    return (SQRT2 + 1.0) * (v - u), (SQRT2 + 1.0) * (SQRT2 * u - v)


class CrossSection:
    """The protocol of a cross-section kind (one immutable, hashable object per kind).

    Attributes: ``name`` (the kind's word in files, ``BottleShape.cross_section``), ``sections``
    (its section names, in radii order), ``revolved`` (a surface of revolution: only the circle)
    and ``unsupported`` (the :data:`FEATURES` it cannot offer yet). Methods, all vectorised over
    radii (mm) that broadcast with the other arguments:

    ``area``, ``girth`` (mm^2, mm), ``circumradius`` (mm, the farthest boundary point from the
    axis), ``reach_bound`` (scalars: a bound of it that never falls as a radius grows), ``area_breaks``,
    ``vanishing``,
    ``support(radii, psi)``, ``boundary(radii, theta)``, ``signed_distance(radii, x, y)``,
    ``invalid(radii) -> (mask, rule)``, ``is_circle(radii)`` and ``canonical(radii)`` (the same
    section as one of round, rounded_rect, oval or outline: what a flat face is drawn with).
    """

    name: str = ""
    sections: tuple[str, ...] = ()
    revolved: bool = False
    unsupported: frozenset = frozenset()
    #: ``(section index, radius)`` pairs where :meth:`area` changes formula as that radius
    #: passes the value (an integrator must cut there to stay exact).
    area_breaks: tuple[tuple[int, float], ...] = ()
    #: The sections whose radius may reach 0 (the axis) on the wall.
    vanishing: tuple[str, ...] = ()
    #: Symmetric about both axes of its own frame, so a quarter turn mirrored is the whole (meshes).
    mirror_quarters: bool = True
    #: Centrally symmetric at every height: each section's centroid is on the axis, so its
    #: :meth:`moment` is 0 and the masses' centres lie on the axis without integrating.
    centred: bool = True
    #: The cavity's section is the outer one's plan offset at the same height (not the 3-D
    #: offset of the outer surface): where the wall slopes, the glass is thinner along its
    #: normal than the wall thickness (:mod:`engine.plant.thickness`).
    plan_offset_wall: bool = False

    def require(self, feature: str) -> None:
        """Raise ``NotSupportedError`` (a ``DesignError``, one line) if this kind cannot offer
        ``feature`` (a key of :data:`FEATURES`) yet; nothing otherwise."""
        if feature in self.unsupported:
            raise NotSupportedError(f"{FEATURES[feature]}: not supported on {self.name} bottles yet")

    def moment(self, radii):
        """First moments ``(M_x, M_y)`` (mm^3, the integrals of ``x`` and ``y`` over the section):
        0 for a :attr:`centred` kind."""
        shape = np.broadcast(*(np.asarray(x, float) for x in radii)).shape
        return np.zeros(shape), np.zeros(shape)

    def canonical(self, radii):
        """``(cross-section, radii)``: the same section as round, rounded_rect, oval or outline."""
        return self, tuple(radii)

    def is_circle(self, radii, tol: float = 1e-6) -> np.ndarray:
        """Whether the cross-section is a circle (the round neck every non-round body blends into)."""
        r = [np.asarray(x, float) for x in radii]
        return np.abs(r[0] - r[1]) <= tol

    def round_radius(self, radii) -> float:
        """Radius (mm) of the section at ``radii`` where it is a circle (:meth:`is_circle`: the
        finish every kind meets in)."""
        return float(radii[0])

    def tile_radius(self, radii) -> float:
        """Reference radius ``R`` (mm) of a bump tile whose band is centred where the section
        has ``radii``: the tracer measures a tile's ``u`` as ``theta R`` around the girth
        (:mod:`engine.tracer.kernels.bumps`), ``theta`` the polar angle here (so the first
        radius); an outline overrides it (arc length)."""
        return float(radii[0])

    def __repr__(self) -> str:
        return f"<{self.name} cross-section>"


@dataclass(frozen=True, repr=False)
class Round(CrossSection):
    """The circle of radius ``r``: a surface of revolution."""

    name = "round"
    sections = ("profile",)
    revolved = True

    def area(self, radii):
        """``pi r^2`` (mm^2)."""
        return math.pi * np.asarray(radii[0], float) ** 2

    def girth(self, radii):
        """``2 pi r`` (mm)."""
        return 2.0 * math.pi * np.asarray(radii[0], float)

    def invalid(self, radii, tol: float = 1e-9):
        return ~(np.asarray(radii[0], float) > tol), "r > 0"

    def is_circle(self, radii, tol: float = 1e-6):
        return np.ones(np.shape(np.asarray(radii[0], float)), bool)

    def circumradius(self, radii):
        return np.asarray(radii[0], float)

    def reach_bound(self, radii) -> float:
        return radii[0]

    def support(self, radii, psi):
        ux = np.cos(np.asarray(psi, float))
        return np.asarray(radii[0], float) + 0.0 * ux

    def boundary(self, radii, theta):
        th = np.asarray(theta, float)
        ct, st = np.cos(th), np.sin(th)
        r = np.asarray(radii[0], float)
        return r * ct, r * st, ct + 0 * r, st + 0 * r

    def signed_distance(self, radii, x, y):
        x, y = np.asarray(x, float), np.asarray(y, float)
        r = np.asarray(radii[0], float)
        rho = np.hypot(x, y)
        safe = np.where(rho > 0, rho, 1.0)
        gx, gy = np.where(rho > 0, x / safe, 1.0), np.where(rho > 0, y / safe, 0.0)
        return rho - r, gx, gy, (-np.ones(np.broadcast(rho, r).shape),)


@dataclass(frozen=True, repr=False)
class RoundedRect(CrossSection):
    """The rounded rectangle ``(a, b, c)``: half-width, half-depth, corner radius."""

    name = "rounded_rect"
    sections = ("half_width", "half_depth", "corner")

    def as_rect(self, radii):
        """``(a, b, c)`` (mm) of the rounded rectangle this section is."""
        a, b, c = (np.asarray(x, float) for x in radii)
        return a, b, c

    def area(self, radii):
        """``4ab - (4 - pi) c^2`` (mm^2; a rounded square's ``4u^2 - (4 - pi) q^2``)."""
        a, b, c = self.as_rect(radii)
        return 4.0 * a * b - (4.0 - math.pi) * c * c

    def girth(self, radii):
        """Four quarters ``(a - c) + (b - c) + pi c / 2`` (mm)."""
        a, b, c = self.as_rect(radii)
        return 4.0 * ((a - c) + (b - c) + HALF_PI * c)

    def invalid(self, radii, tol: float = 1e-9):
        a, b, c = (np.asarray(x, float) for x in radii)
        return ~((c > tol) & (c <= a + tol) & (c <= b + tol)), "0 < corner <= min(half_width, half_depth)"

    def is_circle(self, radii, tol: float = 1e-6):
        r = [np.asarray(x, float) for x in radii]
        return (np.abs(r[0] - r[1]) <= tol) & (np.abs(r[0] - r[2]) <= tol)

    def circumradius(self, radii):
        a, b, c = self.as_rect(radii)
        return np.hypot(a - c, b - c) + c

    def reach_bound(self, radii) -> float:
        return math.hypot(radii[0], radii[1])

    def support(self, radii, psi):
        """``|cos|(a - c) + |sin|(b - c) + c``."""
        ux, uy = np.cos(np.asarray(psi, float)), np.sin(np.asarray(psi, float))
        a, b, c = self.as_rect(radii)
        return np.abs(ux) * (a - c) + np.abs(uy) * (b - c) + c

    def boundary(self, radii, theta):
        th = np.asarray(theta, float)
        ct, st = np.cos(th), np.sin(th)
        a, b, c = self.as_rect(radii)
        dx, dy = np.abs(ct), np.abs(st)
        cx, cy = a - c, b - c
        with np.errstate(divide="ignore", invalid="ignore"):
            t_side = a / dx            # the side x = a
            t_top = b / dy             # the side y = b
            on_side = dy * t_side <= cy
            on_top = ~on_side & (dx * t_top <= cx)
            dc = dx * cx + dy * cy
            t_corner = dc + np.sqrt(np.maximum(dc * dc - cx * cx - cy * cy + c * c, 0.0))
        t = np.where(on_side, t_side, np.where(on_top, t_top, t_corner))
        px, py = t * dx, t * dy
        nx = np.where(on_side, 1.0, np.where(on_top, 0.0, (px - cx) / c))
        ny = np.where(on_side, 0.0, np.where(on_top, 1.0, (py - cy) / c))
        sx, sy = np.where(ct < 0, -1.0, 1.0), np.where(st < 0, -1.0, 1.0)
        return sx * px, sy * py, sx * nx, sy * ny

    def signed_distance(self, radii, x, y):
        x, y = np.asarray(x, float), np.asarray(y, float)
        a, b, c = self.as_rect(radii)
        sx, sy = np.where(x < 0, -1.0, 1.0), np.where(y < 0, -1.0, 1.0)
        dx, dy = np.abs(x) - (a - c), np.abs(y) - (b - c)
        ox, oy = np.maximum(dx, 0.0), np.maximum(dy, 0.0)
        out = np.hypot(ox, oy)
        outside = out > 0
        safe = np.where(outside, out, 1.0)
        side_x = dx > dy
        gpx = np.where(outside, ox / safe, np.where(side_x, 1.0, 0.0))
        gpy = np.where(outside, oy / safe, np.where(side_x, 0.0, 1.0))
        sd = out + np.minimum(np.maximum(dx, dy), 0.0) - c
        return sd, sx * gpx, sy * gpy, self._d_radii(-gpx, -gpy, gpx + gpy - 1.0)

    def _d_radii(self, d_a, d_b, d_c):
        """``d sd / d radius`` per section from those in ``a``, ``b`` and ``c``."""
        return d_a, d_b, d_c


@dataclass(frozen=True, repr=False)
class RoundedSquare(RoundedRect):
    """The rounded square ``(u, v)``: the rounded rectangle ``(u, u, q)`` (module table)."""

    name = "rounded_square"
    sections = ("u", "v")

    def as_rect(self, radii):
        u, v = (np.asarray(x, float) for x in radii)
        return u, u, square_corner(u, v)[1]

    def canonical(self, radii):
        return RECT, self.as_rect(radii)

    def invalid(self, radii, tol: float = 1e-9):
        u, v = (np.asarray(x, float) for x in radii)
        return ~((u > tol) & (v >= u - tol) & (v < SQRT2 * u - tol)), "u <= v < sqrt2 u"

    def is_circle(self, radii, tol: float = 1e-6):
        return CrossSection.is_circle(self, radii, tol)

    def reach_bound(self, radii) -> float:
        return max(radii[1], math.sqrt(2) * radii[0])

    def _d_radii(self, d_a, d_b, d_c):
        return d_a + d_b + d_c * DQ_DU, d_c * DQ_DV


@dataclass(frozen=True, repr=False)
class Oval(CrossSection):
    """The ellipse of semi-axes ``a`` (x) and ``b`` (y)."""

    name = "oval"
    sections = ("half_width", "half_depth")

    def area(self, radii):
        """``pi a b`` (mm^2)."""
        return math.pi * np.asarray(radii[0], float) * np.asarray(radii[1], float)

    def girth(self, radii):
        """Four quarters of the complete elliptic integral of the second kind (mm)."""
        from scipy.special import ellipe  # why here: the only closed form in this module that needs it
        a, b = (np.asarray(x, float) for x in radii)
        wide = a > b  # m = 1 - (minor/major)^2 in [0, 1) either way
        m = np.where(wide, 1.0 - (b / a) ** 2, 1.0 - (a / np.where(wide, a, b)) ** 2)
        return 4.0 * (np.where(wide, a, b) * ellipe(m))

    def invalid(self, radii, tol: float = 1e-9):
        r = [np.asarray(x, float) for x in radii]
        return ~((r[0] > tol) & (r[1] > tol)), "half_width > 0 and half_depth > 0"

    def circumradius(self, radii):
        return np.maximum(radii[0], radii[1])

    def reach_bound(self, radii) -> float:
        return max(radii)

    def support(self, radii, psi):
        """``sqrt(a^2 cos^2 + b^2 sin^2)``."""
        ux, uy = np.cos(np.asarray(psi, float)), np.sin(np.asarray(psi, float))
        a, b = (np.asarray(x, float) for x in radii)
        return np.sqrt((a * ux) ** 2 + (b * uy) ** 2)

    def boundary(self, radii, theta):
        th = np.asarray(theta, float)
        ct, st = np.cos(th), np.sin(th)
        a, b = (np.asarray(x, float) for x in radii)
        t = 1.0 / np.sqrt((ct / a) ** 2 + (st / b) ** 2)
        x, y = t * ct, t * st
        gx, gy = x / a ** 2, y / b ** 2
        g = np.hypot(gx, gy)
        return x, y, gx / g, gy / g

    def signed_distance(self, radii, x, y):
        """``(S - 1) / |grad S|`` with ``S = sqrt((x/a)^2 + (y/b)^2)``: unit gradient on the ellipse."""
        x, y = np.asarray(x, float), np.asarray(y, float)
        a, b = (np.asarray(v, float) for v in radii)
        s = np.sqrt((x / a) ** 2 + (y / b) ** 2)
        s_safe = np.where(s > 0, s, 1.0)
        g = np.hypot(x / a ** 2, y / b ** 2)
        g_safe = np.where(g > 0, g, 1.0 / np.minimum(a, b))
        # grad S = (x/a^2, y/b^2) / S; |grad S| = g / S, so sd = (S - 1) S / g.
        sd = np.where(s > 0, (s - 1.0) * s / g_safe, -np.minimum(a, b))  # S/g -> finite at the centre
        # d sd/da = [dS/da (2S - 1) g - (S - 1) S dg/da] / g^2 with dS/da = -x^2/(a^3 S), dg/da = -2x^2/(a^5 g)
        ds_da, ds_db = -x ** 2 / (a ** 3 * s_safe), -y ** 2 / (b ** 3 * s_safe)
        dg_da, dg_db = -2 * x ** 2 / (a ** 5 * g_safe), -2 * y ** 2 / (b ** 5 * g_safe)
        d_a = (ds_da * (2 * s - 1) * g_safe - (s - 1) * s * dg_da) / g_safe ** 2
        d_b = (ds_db * (2 * s - 1) * g_safe - (s - 1) * s * dg_db) / g_safe ** 2
        # grad sd: exact derivative of (S - 1) S / g in x and y.
        dsx, dsy = x / (a ** 2 * s_safe), y / (b ** 2 * s_safe)
        dgx, dgy = x / (a ** 4 * g_safe), y / (b ** 4 * g_safe)
        gx = (dsx * (2 * s - 1) * g_safe - (s - 1) * s * dgx) / g_safe ** 2
        gy = (dsy * (2 * s - 1) * g_safe - (s - 1) * s * dgy) / g_safe ** 2
        return sd, gx, gy, (d_a, d_b)


@dataclass(frozen=True, repr=False)
class Outline(CrossSection):
    """The section ``{q : sd(q, k P) <= r}`` of a free convex plan outline ``plan``
    (:class:`engine.geometry.plan.PlanOutline`), radii ``(k, r)`` (mm): the outer solid's
    ``r = c > 0``, the cavity's ``r = c - w`` of either sign. Exact everywhere (the plan's pieces
    and closed forms); ``r < 0`` is the inner parallel set, with sharp inner corners."""

    plan: object
    name = "outline"
    sections = ("core", "round")
    mirror_quarters = False  # a flask or a shield is not; a hexagon is, and is meshed whole anyway
    centred = False  # nor centrally symmetric: a shield's centroid is off the axis
    plan_offset_wall = True  # SPEC_outline 5: the cavity is the plan offset at the same height
    #: Steiner's polynomial for r >= 0, the inner parallel set's area below: equal in value and
    #: slope at r = 0 but not in curvature, which would cost Gauss-Legendre its exactness.
    area_breaks = ((1, 0.0),)
    vanishing = ("core",)  # the core shrinks to 0 into the round neck (SPEC_outline 3)

    @staticmethod
    def _kr(radii):
        return np.asarray(radii[0], float), np.asarray(radii[1], float)

    def area(self, radii):
        """Steiner's ``k^2 A + k L r + pi r^2`` for ``r >= 0``; for ``r < 0`` the inner parallel
        set's exact area (0 where it is empty, NaN where a piece of ``P`` has vanished from it:
        :meth:`engine.geometry.plan.PlanOutline.inner_area`)."""
        return self.plan.inner_area(*self._kr(radii))

    def moment(self, radii):
        """Exact, from the section's pieces (:meth:`engine.geometry.plan.PlanOutline.section_moment`)."""
        return self.plan.section_moment(*self._kr(radii))

    def girth(self, radii):
        """Perimeter (mm): ``k L + 2 pi r`` for ``r >= 0``, the inner parallel set's for ``r < 0``."""
        return self.plan.inner_girth(*self._kr(radii))

    def tile_radius(self, radii) -> float:
        """``girth / 2 pi`` (mm): around an outline the tracer's ``theta`` is the girth fraction
        as an angle (:func:`engine.tracer.kernels.finish.shading_frame`), so a tile of ``n``
        repeats spans ``girth / n`` of arc length at its band's middle."""
        return float(self.girth(radii)) / (2.0 * math.pi)

    def invalid(self, radii, tol: float = 1e-9):
        k, r = self._kr(radii)
        with np.errstate(invalid="ignore"):
            bad = ~(k >= -tol) | ~(self.plan.inner_area(np.maximum(k, 0.0), r) > 0)
        return bad, "core >= 0 and a section keeping every piece of the plan outline"

    def is_circle(self, radii, tol: float = 1e-6):
        """Where the core has vanished: the disc of radius ``r`` (the round neck)."""
        return np.abs(np.asarray(radii[0], float)) <= tol

    def circumradius(self, radii):
        """``k + r`` for ``r >= 0`` (the plan's farthest point is at 1); the inner parallel set's
        farthest joint or arc point for ``r < 0``."""
        return self.plan.section_reach(*self._kr(radii))

    def reach_bound(self, radii) -> float:
        return max(radii[0], 0.0) + max(radii[1], 0.0)

    def round_radius(self, radii) -> float:
        """The rounding where the core has vanished (``k + c``, ``k`` about 0)."""
        return max(float(radii[0]), 0.0) + float(radii[1])

    def support(self, radii, psi):
        return self.plan.section_support(psi, *self._kr(radii))

    def boundary(self, radii, theta):
        """Exact, from the section's pieces: the section is convex and holds the origin, so the
        ray at ``theta`` leaves it once (:meth:`engine.geometry.plan.PlanOutline.section_boundary`)."""
        return self.plan.section_boundary(theta, *self._kr(radii))

    def signed_distance(self, radii, x, y):
        """``sd(q, k P) - r`` with ``d_radii = (-h(u*), -1)`` (the plan's, exact for ``r >= 0``)."""
        k, r = self._kr(radii)
        return self.plan.signed_distance(x, y, k, r)


ROUND, RECT, SQUARE, OVAL = Round(), RoundedRect(), RoundedSquare(), Oval()
#: The kinds that need nothing but their name, by name.
FIXED = {xs.name: xs for xs in (ROUND, SQUARE, RECT, OVAL)}
#: Every kind's name, in the order the panels list them.
KINDS = ("round", "rounded_square", "rounded_rect", "oval", "outline")


def of_kind(kind: str) -> CrossSection:
    """The cross-section of a fixed kind's name (``outline`` needs its plan: :func:`cross_section_of`)."""
    try:
        return FIXED[kind]
    except KeyError:
        raise ValueError(f"{kind!r} is not a fixed cross-section kind ({', '.join(FIXED)}); "
                         "an outline needs its plan (cross_section_of(shape))") from None


def cross_section_of(shape) -> CrossSection:
    """The cross-section of a :class:`~engine.geometry.shape.BottleShape` (or a body profile and
    its shape's plan): the kind's object, an outline carrying the shape's plan."""
    if shape.cross_section == "outline":
        return Outline(shape.plan)
    return of_kind(shape.cross_section)


# ------------------------------------------------------------------ the fixed kinds by name
def area(kind: str, radii) -> np.ndarray:
    """Area (mm^2) of a fixed kind's cross-section (:meth:`CrossSection.area`)."""
    return of_kind(kind).area(radii)


def invalid_radii(kind: str, radii, tol: float = 1e-9):
    """``(mask, rule)``: where the radii make no valid cross-section, and the rule in words."""
    return of_kind(kind).invalid(radii, tol)


def is_circle(kind: str, radii, tol: float = 1e-6) -> np.ndarray:
    """Whether a fixed kind's cross-section is a circle."""
    return of_kind(kind).is_circle(radii, tol)


def circumradius(kind: str, radii) -> np.ndarray:
    """Largest distance (mm) of the boundary from the axis (``v`` for a rounded square)."""
    return of_kind(kind).circumradius(radii)


def support(kind: str, radii, psi):
    """Support function (mm) in plan direction ``psi`` (rad): :meth:`CrossSection.support`."""
    return of_kind(kind).support(radii, psi)


def boundary(kind: str, radii, theta):
    """Boundary point and outward unit normal ``(x, y, nx, ny)`` at polar angle ``theta`` (rad)."""
    return of_kind(kind).boundary(radii, theta)


def signed_distance(kind: str, radii, x, y):
    """Signed distance-like function of the cross-section and its derivatives.

    Returns ``(sd, gx, gy, d_radii)``: ``sd`` (mm) is negative inside, zero on the boundary,
    positive outside; ``(gx, gy)`` is its gradient (unit on the boundary; the exact Euclidean
    distance for circle, rounded shapes and outlines, the gradient-normalised implicit ellipse for
    ovals); ``d_radii`` holds ``d sd / d radius`` for each section. A 3-D surface ``g(x, y, z) =
    sd(x, y; radii(z))`` then has ``dg/dz = sum(d_radii[k] * d radii[k] / dz)``.
    """
    return of_kind(kind).signed_distance(radii, x, y)
