"""Rounded-square rings (SPEC 4.3) for the render mesh, and the exact wall normal.

Design rule: the cross-section at height z is the rounded square ``S(u, v)``: the square
``[-p, p]^2`` grown by a disc of radius ``q`` with ``p = (sqrt2 + 1)(v - u)`` and
``q = (sqrt2 + 1)(sqrt2 u - v)``; ``u = v`` is the circle of radius ``u`` (the round bottle).
Ring vertices use the same parameters on every ring (fraction along the flat side, angle on the
corner arc), so quads between rings follow the ruled wall. Units: mm, angles in radians.
"""
from __future__ import annotations

import math

import numpy as np

_K = math.sqrt(2.0) + 1.0


def corner_params(u, v):
    """``(p, q)`` (mm) of the rounded square with half-width ``u`` and diagonal radius ``v``."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    p = np.maximum(_K * (v - u), 0.0)
    return p, u - p


def ring_points(u, v, n_side: int, n_corner: int, rotation_rad: float = 0.0) -> np.ndarray:
    """Boundary points of ``S(u_k, v_k)`` for each ring k, counter-clockwise from theta = 0.

    Parameters
    ----------
    u, v : array_like, shape (R,)
        Half-width and diagonal radius per ring (mm), ``u <= v < sqrt2 u``.
    n_side, n_corner : int
        Intervals per octant on the flat half-side and on the 45-degree corner arc.
    rotation_rad : float
        Turn of the whole ring about +z (counter-clockwise).

    Returns
    -------
    ndarray, shape (R, 8 (n_side + n_corner), 2)
    """
    p, q = corner_params(u, v)
    p, q = p[:, None], q[:, None]
    f = np.arange(n_side) / max(n_side, 1)
    phi = np.arange(n_corner) / n_corner * (math.pi / 4)
    ax = np.concatenate([np.broadcast_to(p + q, (len(p), n_side)), p + q * np.cos(phi)], axis=1)
    ay = np.concatenate([f * p, p + q * np.sin(phi)], axis=1)
    diag = p + q / math.sqrt(2.0)
    qx = np.concatenate([ax, diag, ay[:, 1:][:, ::-1]], axis=1)
    qy = np.concatenate([ay, diag, ax[:, 1:][:, ::-1]], axis=1)
    xs = np.concatenate([qx, -qy, -qx, qy], axis=1)
    ys = np.concatenate([qy, qx, -qy, -qx], axis=1)
    c, s = math.cos(rotation_rad), math.sin(rotation_rad)
    return np.stack([c * xs - s * ys, s * xs + c * ys], axis=-1)


def rounded_square_sd(x, y, u, v):
    """Signed distance (mm, negative inside) from ``(x, y)`` to the boundary of ``S(u, v)``."""
    p, q = corner_params(u, v)
    cx, cy = np.abs(x) - p, np.abs(y) - p
    outside = np.hypot(np.maximum(cx, 0.0), np.maximum(cy, 0.0))
    return outside + np.minimum(np.maximum(cx, cy), 0.0) - q


def rounded_square_gradient(x, y, u, v, du, dv):
    """Gradient ``(gx, gy, gz)`` of ``F(x, y, z) = sd(x, y; u(z), v(z))`` near the wall.

    ``du, dv`` are ``u'(z), v'(z)``. On the wall the horizontal part is the exact outward
    cross-section normal and ``gz = dsd/du u' + dsd/dv v'``, so the normalised gradient is the
    exact outward surface normal (for ``u = v``: ``(x/rho, y/rho, -r'(z))``).
    """
    p, _ = corner_params(u, v)
    ax, ay = np.abs(x), np.abs(y)
    cx, cy = ax - p, ay - p
    corner = (cx > 0) & (cy > 0)
    length = np.where(corner, np.hypot(cx, cy), 1.0)
    length = np.maximum(length, 1e-300)
    side_x = ~corner & (cx >= cy)
    gx = np.where(corner, cx / length, np.where(side_x, 1.0, 0.0)) * np.sign(x + (x == 0))
    gy = np.where(corner, cy / length, np.where(side_x, 0.0, 1.0)) * np.sign(y + (y == 0))
    dsd_dp = np.where(corner, -(cx + cy) / length, -1.0)
    # p = K (v - u), q = K (sqrt2 u - v); dsd/dq = -1.
    dsd_du = -_K * dsd_dp - _K * math.sqrt(2.0)
    dsd_dv = _K * dsd_dp + _K
    gz = dsd_du * du + dsd_dv * dv
    return gx, gy, gz
