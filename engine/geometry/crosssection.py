"""Horizontal cross-sections: circle, rounded square, rounded rectangle and oval, vectorised.

Design rule: a cross-section at one height is fully given by its *radii*, the values of the
kind's named sections at that height (``engine.geometry.shape.SECTION_NAMES`` order, mm):

=================  ==========================================================================
``round``          ``(r,)``
``rounded_square`` ``(u, v)``: half-width and diagonal radius; sides ``x = +-u`` for
                   ``|y| <= p``, corner arcs about ``(+-p, +-p)`` of radius ``q`` with
                   ``p = (sqrt2+1)(v-u)``, ``q = (sqrt2+1)(sqrt2 u - v)``; needs ``u <= v < sqrt2 u``
``rounded_rect``   ``(half_width a, half_depth b, corner c)``: needs ``0 < c <= min(a, b)``
``oval``           ``(a, b)``: the ellipse ``(x/a)^2 + (y/b)^2 = 1``
=================  ==========================================================================

A rounded square is the rounded rectangle ``(u, u, q)``, so both share one implementation. Every
function takes the radii as a tuple of arrays that broadcast against the other arguments, and the
polar angle ``theta`` (rad) is measured in the bottle's own frame (before ``rotation_deg``).
"""
from __future__ import annotations

import math

import numpy as np

SQRT2 = math.sqrt(2.0)
#: d q / d u and d q / d v for the rounded square (q = (sqrt2+1)(sqrt2 u - v)).
DQ_DU, DQ_DV = (SQRT2 + 1.0) * SQRT2, -(SQRT2 + 1.0)

KINDS = ("round", "rounded_square", "rounded_rect", "oval")


def square_corner(u, v):
    """``(p, q)`` (mm) of the rounded square with half-width ``u`` and diagonal radius ``v``."""
    u, v = np.asarray(u, float), np.asarray(v, float)
    return (SQRT2 + 1.0) * (v - u), (SQRT2 + 1.0) * (SQRT2 * u - v)


def _as_rect(kind, radii):
    """``(a, b, c)`` of the rounded rectangle a rounded square or rectangle is."""
    if kind == "rounded_square":
        u, v = (np.asarray(x, float) for x in radii)
        return u, u, square_corner(u, v)[1]
    a, b, c = (np.asarray(x, float) for x in radii)
    return a, b, c


def area(kind: str, radii) -> np.ndarray:
    """Area (mm^2) of the cross-section; closed forms (rounded square ``4u^2 - (4 - pi) q^2``)."""
    if kind == "round":
        return math.pi * np.asarray(radii[0], float) ** 2
    if kind == "oval":
        return math.pi * np.asarray(radii[0], float) * np.asarray(radii[1], float)
    a, b, c = _as_rect(kind, radii)
    return 4.0 * a * b - (4.0 - math.pi) * c * c


def invalid_radii(kind: str, radii, tol: float = 1e-9):
    """``(mask, rule)``: where the radii make no valid cross-section, and the rule in words."""
    r = [np.asarray(x, float) for x in radii]
    if kind == "round":
        return ~(r[0] > tol), "r > 0"
    if kind == "oval":
        return ~((r[0] > tol) & (r[1] > tol)), "half_width > 0 and half_depth > 0"
    if kind == "rounded_square":
        u, v = r
        return ~((u > tol) & (v >= u - tol) & (v < SQRT2 * u - tol)), "u <= v < sqrt2 u"
    a, b, c = r
    return ~((c > tol) & (c <= a + tol) & (c <= b + tol)), "0 < corner <= min(half_width, half_depth)"


def is_circle(kind: str, radii, tol: float = 1e-6) -> np.ndarray:
    """Whether the cross-section is a circle (the round neck every non-round body blends into)."""
    r = [np.asarray(x, float) for x in radii]
    if kind == "round":
        return np.ones(np.shape(r[0]), bool)
    if kind in ("rounded_square", "oval"):
        return np.abs(r[0] - r[1]) <= tol
    return (np.abs(r[0] - r[1]) <= tol) & (np.abs(r[0] - r[2]) <= tol)


def circumradius(kind: str, radii) -> np.ndarray:
    """Largest distance (mm) of the boundary from the axis (``v`` for a rounded square)."""
    if kind == "round":
        return np.asarray(radii[0], float)
    if kind == "oval":
        return np.maximum(radii[0], radii[1])
    a, b, c = _as_rect(kind, radii)
    return np.hypot(a - c, b - c) + c


def support(kind: str, radii, psi):
    """Support function (mm): how far the cross-section reaches from the axis in the plan
    direction ``psi`` (rad, the bottle's own frame), ``max(p . (cos psi, sin psi))`` over its
    points; broadcast over ``psi`` and the radii. Closed forms: ``r``; the ellipse's
    ``sqrt(a^2 cos^2 + b^2 sin^2)``; the rounded rectangle's ``|cos|(a - c) + |sin|(b - c) + c``."""
    ux, uy = np.cos(np.asarray(psi, float)), np.sin(np.asarray(psi, float))
    if kind == "round":
        return np.asarray(radii[0], float) + 0.0 * ux
    if kind == "oval":
        a, b = (np.asarray(x, float) for x in radii)
        return np.sqrt((a * ux) ** 2 + (b * uy) ** 2)
    a, b, c = _as_rect(kind, radii)
    return np.abs(ux) * (a - c) + np.abs(uy) * (b - c) + c


def boundary(kind: str, radii, theta):
    """Boundary point and outward unit normal at polar angle ``theta`` (rad).

    Returns ``(x, y, nx, ny)`` (mm, unit), broadcast over ``theta`` and the radii.
    """
    th = np.asarray(theta, float)
    ct, st = np.cos(th), np.sin(th)
    if kind == "round":
        r = np.asarray(radii[0], float)
        return r * ct, r * st, ct + 0 * r, st + 0 * r
    if kind == "oval":
        a, b = (np.asarray(x, float) for x in radii)
        t = 1.0 / np.sqrt((ct / a) ** 2 + (st / b) ** 2)
        x, y = t * ct, t * st
        gx, gy = x / a ** 2, y / b ** 2
        g = np.hypot(gx, gy)
        return x, y, gx / g, gy / g
    a, b, c = _as_rect(kind, radii)
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


def signed_distance(kind: str, radii, x, y):
    """Signed distance-like function of the cross-section and its derivatives.

    Returns ``(sd, gx, gy, d_radii)``: ``sd`` (mm) is negative inside, zero on the boundary,
    positive outside; ``(gx, gy)`` is its gradient (unit on the boundary; the exact Euclidean
    distance for circle and rounded shapes, the gradient-normalised implicit ellipse for ovals);
    ``d_radii`` holds ``d sd / d radius`` for each section. A 3-D surface ``g(x, y, z) =
    sd(x, y; radii(z))`` then has ``dg/dz = sum(d_radii[k] * d radii[k] / dz)``.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    if kind == "round":
        r = np.asarray(radii[0], float)
        rho = np.hypot(x, y)
        safe = np.where(rho > 0, rho, 1.0)
        gx, gy = np.where(rho > 0, x / safe, 1.0), np.where(rho > 0, y / safe, 0.0)
        return rho - r, gx, gy, (-np.ones(np.broadcast(rho, r).shape),)
    if kind == "oval":
        return _oval_sd(radii, x, y)
    a, b, c = _as_rect(kind, radii)
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
    d_a, d_b, d_c = -gpx, -gpy, gpx + gpy - 1.0
    if kind == "rounded_square":
        d_radii = (d_a + d_b + d_c * DQ_DU, d_c * DQ_DV)
    else:
        d_radii = (d_a, d_b, d_c)
    return sd, sx * gpx, sy * gpy, d_radii


def _oval_sd(radii, x, y):
    """``(S - 1) / |grad S|`` with ``S = sqrt((x/a)^2 + (y/b)^2)``: unit gradient on the ellipse."""
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
