"""Arc length around a horizontal cross-section: how far a label's width reaches.

Design rule: closed forms, vectorised, for every cross-section a label can wrap (a
:class:`~engine.geometry.crosssection.CrossSection`; the partial arc lengths are this module's
own closed forms, and an outline's those of :mod:`engine.geometry.plan_girth`, not the
protocol's, which knows only whole perimeters). The *girth length* ``l(theta)`` is the arc length of the
boundary from polar angle 0 to ``theta`` (rad, the bottle's own frame), counter-clockwise seen
from above; ``theta`` may be any real number (``l(theta + 2 pi) = l(theta) + P``, ``P`` the
perimeter), so a label straddling ``theta = 0`` has a continuous coordinate. Circle: ``r
theta``. Rounded rectangle (and square, the rectangle ``(u, u, q)``): per quadrant a side
``a tan(theta)``, a corner arc ``c phi`` about ``(a - c, b - c)``, a top side. Oval: the
incomplete elliptic integral of the second kind of the eccentric anomaly. Outline: the
plan's pieces, ``k len`` per line, ``(k rho + c) sweep`` per arc, ``c alpha`` per sharp
corner (:mod:`engine.geometry.plan_girth`). Radii are the
kind's section values at one height (mm), broadcast against ``theta``; ``xs`` is the bottle's
cross-section object.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import ellipe, ellipeinc

from ..geometry import plan_girth
from ..geometry.crosssection import RECT

HALF_PI = 0.5 * math.pi


def _oval_quarter(a, b, theta=None):
    """Arc length of the ellipse (semi-axes ``a`` along x, ``b`` along y) from polar angle 0 to
    ``theta`` in [0, pi/2] (``None``: the whole quarter)."""
    wide = a > b  # m = 1 - (minor/major)^2 in [0, 1) either way
    m = np.where(wide, 1.0 - (b / a) ** 2, 1.0 - (a / np.where(wide, a, b)) ** 2)
    quarter = np.where(wide, a, b) * ellipe(m)
    if theta is None:
        return quarter
    ecc = np.arctan2(a * np.sin(theta), b * np.cos(theta))  # eccentric anomaly, same quadrant
    tall = b * ellipeinc(ecc, m)
    flat = a * (ellipe(m) - ellipeinc(HALF_PI - ecc, m))
    return np.where(wide, flat, tall)


def _rect_quarter(a, b, c, theta=None):
    """Arc length of the rounded rectangle ``(a, b, c)`` from polar angle 0 to ``theta`` in
    [0, pi/2] (``None``: the whole quarter)."""
    quarter = (a - c) + (b - c) + HALF_PI * c
    if theta is None:
        return quarter
    with np.errstate(divide="ignore", invalid="ignore"):
        side = a * np.tan(theta)
        top = quarter - b / np.tan(theta)
    x, y, _, _ = RECT.boundary((a, b, c), theta)
    phi = np.arctan2(y - (b - c), x - (a - c))
    corner = (b - c) + c * np.clip(phi, 0.0, HALF_PI)
    on_side = np.sin(theta) * np.hypot(x, y) <= b - c
    on_top = np.cos(theta) * np.hypot(x, y) <= a - c
    return np.where(on_side, side, np.where(on_top, top, corner))


def _quarter(xs, radii, theta=None):
    if xs.name == "oval":
        a, b = (np.asarray(x, float) for x in radii)
        return _oval_quarter(a, b, theta)
    return _rect_quarter(*xs.as_rect(radii), theta)


def perimeter(xs, radii) -> np.ndarray:
    """Perimeter (mm) of the cross-section ``xs`` with ``radii``: its ``girth``."""
    return xs.girth(radii)


def girth_length(xs, radii, theta) -> np.ndarray:
    """Arc length (mm) of the boundary from polar angle 0 to ``theta`` (rad, any real value),
    counter-clockwise; continuous and increasing in ``theta``."""
    theta = np.asarray(theta, float)
    if xs.revolved:
        return np.asarray(radii[0], float) * theta
    if xs.name == "outline":
        return plan_girth.girth_length(xs.plan, radii[0], radii[1], theta)
    turns = np.floor(theta / (2.0 * math.pi))
    rest = theta - 2.0 * math.pi * turns
    quadrant = np.minimum(np.floor(rest / HALF_PI), 3.0)
    q = _quarter(xs, radii)
    mirrored = (quadrant == 1) | (quadrant == 3)
    local = np.where(mirrored, (quadrant + 1) * HALF_PI - rest, rest - quadrant * HALF_PI)
    part = _quarter(xs, radii, np.clip(local, 0.0, HALF_PI))
    within = np.where(mirrored, (quadrant + 1) * q - part, quadrant * q + part)
    return 4.0 * q * turns + within


def theta_at_length(xs, radii, length) -> np.ndarray:
    """The polar angle (rad) whose :func:`girth_length` is ``length`` (mm, any real value):
    the inverse, by bisection to 1e-14 rad (the girth length rises strictly)."""
    length = np.asarray(length, float)
    if xs.revolved:
        return length / np.asarray(radii[0], float)
    if xs.name == "outline":  # exact: the piece at that length, the point on it
        return plan_girth.theta_at_length(xs.plan, radii[0], radii[1], length)
    p = perimeter(xs, radii)
    turns = np.floor(length / p)
    lo = np.broadcast_to(2.0 * math.pi * turns, np.broadcast(length, p).shape).copy()
    hi = lo + 2.0 * math.pi
    for _ in range(52):
        mid = 0.5 * (lo + hi)
        below = girth_length(xs, radii, mid) < length
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)
