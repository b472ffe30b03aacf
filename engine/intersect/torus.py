"""Robust ray / torus intersection (circular, elliptic-tube and spindle tori about z).

Design rule: every hit is a *bracketed* root of the geometric implicit function, never a
bare closed-form root. Closed-form quartic solvers (Ferrari, Descartes) lose roots in the
torus' mid-plane, at unusual unit scales and on grazing rays because the float64 quartic
coefficients cancel catastrophically. Here, per ray:

1. The torus is scaled to a unit circular tube (x, y divided by ``a``, z by ``b``) and the ray
   origin is moved to its closest approach to the torus centre. In that frame the quartic in
   the scaled distance ``u`` is depressed, ``f(u) = u^4 + p u^2 + q u + r``, every real root
   lies in ``|u| <= R/a + 1`` and there is no absolute epsilon anywhere.
2. ``f`` is evaluated not from its coefficients but as the product of two geometric factors,
   ``f = g_out * g_in`` with ``g_out = (rho - R')^2 + z^2 - 1`` (the surface itself) and
   ``g_in = (rho + R')^2 + z^2 - 1`` (the quartic's mirror sheet), ``rho = hypot(x, y)``;
   this keeps the sign of ``f`` right to a few ulps of the geometry.
3. The critical points of ``f`` (roots of the depressed cubic ``f'``, closed form and Newton
   polished) split ``[-R'-1, R'+1]`` into at most four monotone pieces. A piece whose ends
   differ in sign holds exactly one root, found by Newton steps on the vanishing factor,
   safeguarded by Illinois false position on the bracket, until the factor is at the
   rounding noise of its own evaluation.
4. Roots on the mirror sheet (``|g_in| < |g_out|``: the inner "lemon" of a spindle torus)
   are dropped, and so is every root with ``t <= tmin``.

Tangent touches (a double root of ``f``) are reported as no hit: a ray within about 1e-9 tube
radii of tangency may report or skip the touching pair, which is what a renderer needs.
"""
from __future__ import annotations

import numpy as np

#: Default self-hit guard as a fraction of the tube radius ``a``: hits at ``t <= 1e-6 a`` are
#: taken to be the ray's own start point (secondary rays leave the surface at t = 0).
SELF_HIT_FRACTION = 1e-6
_MAX_ITER = 80


def _cubic_critical_points(p, q):
    """Real roots of ``f'(u) / 4 = u^3 + (p/2) u + q/4`` as an (N, 3) array, ascending.

    Where the cubic has one real root, it fills all three columns, so the pieces between
    equal critical points are empty. Each root is polished by two Newton steps.
    """
    P = 0.5 * p
    Q = 0.25 * q
    disc = (0.5 * Q) ** 2 + (P / 3.0) ** 3
    roots = np.empty(p.shape + (3,))
    one = disc > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        # One real root: the Cardano sum, written so that the two cube roots never cancel.
        A = -np.sign(Q) * np.cbrt(0.5 * np.abs(Q) + np.sqrt(np.where(one, disc, 0.0)))
        single = np.where(A != 0.0, A - P / (3.0 * A), 0.0)
        # Three real roots: the trigonometric form (P < 0 here).
        k = 2.0 * np.sqrt(np.where(one, 0.0, -P / 3.0))
        arg = np.where(one | (P == 0.0), 0.0, (3.0 * Q / (2.0 * P)) * np.sqrt(np.where(one, 0.0, -3.0 / P)))
        phi = np.arccos(np.clip(arg, -1.0, 1.0)) / 3.0
        for j in range(3):
            roots[:, j] = np.where(one, single, k * np.cos(phi - 2.0 * np.pi * j / 3.0))
        for _ in range(2):
            val = (roots * roots + P[:, None]) * roots + Q[:, None]
            der = 3.0 * roots * roots + P[:, None]
            step = np.where(der != 0.0, val / der, 0.0)
            roots = roots - np.where(np.isfinite(step), step, 0.0)
    roots.sort(axis=1)
    return roots


class _ScaledRays:
    """Rays in the unit-tube frame, origin moved to the closest approach to the centre.

    ``R``, ``a``, ``b`` are per-ray arrays (N,); ``Rn = R / a`` is the scaled ring radius.
    """

    def __init__(self, origins, directions, R, a, b):
        inv = np.column_stack([1.0 / a, 1.0 / a, 1.0 / b])
        Q = origins * inv
        D = directions * inv
        self.speed = np.linalg.norm(D, axis=1)  # scaled length per mm of t
        self.D = D / self.speed[:, None]
        self.s0 = -np.einsum("ij,ij->i", Q, self.D)
        self.Q0 = Q + self.s0[:, None] * self.D
        self.Rn = R / a

    def subset(self, rows):
        sub = _ScaledRays.__new__(_ScaledRays)
        for name in ("speed", "D", "s0", "Q0", "Rn"):
            setattr(sub, name, getattr(self, name)[rows])
        return sub

    def factors(self, u):
        """``(g_out, g_in)`` at scaled distances ``u`` (N, k) from the closest approach."""
        Q0, D, Rn = self.Q0, self.D, self.Rn[:, None]
        x = Q0[:, 0, None] + u * D[:, 0, None]
        y = Q0[:, 1, None] + u * D[:, 1, None]
        z = Q0[:, 2, None] + u * D[:, 2, None]
        rho = np.hypot(x, y)
        d_out = rho - Rn
        z2 = z * z
        # (d - 1)(d + 1) instead of d*d - 1: no cancellation on the tube surface.
        return (d_out - 1.0) * (d_out + 1.0) + z2, (rho + Rn) ** 2 - 1.0 + z2


def _false_position(lo, hi, f_lo, f_hi):
    """Secant point of a bracket with ``f_lo``, ``f_hi`` of opposite signs (inside it)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
    return np.where((x > lo) & (x < hi), x, 0.5 * (lo + hi))


def _solve_pieces(rays, bounds):
    """Roots of ``f`` inside every monotone piece that changes sign; NaN elsewhere.

    ``bounds`` is (N, 5): ``-B, c1, c2, c3, B``. Returns the roots (N, 4) in scaled units.
    """
    n = bounds.shape[0]
    g_out, g_in = rays.factors(bounds)
    f_end = g_out * g_in
    lo, hi = bounds[:, :-1].copy(), bounds[:, 1:].copy()
    f_lo, f_hi = f_end[:, :-1], f_end[:, 1:]
    live = (np.sign(f_lo) * np.sign(f_hi) < 0) & (hi > lo)
    roots = np.full((n, 4), np.nan)
    exact = (f_lo == 0.0) & (hi > lo)
    roots[exact] = lo[exact]
    ri, ci = np.nonzero(live)
    if ri.size == 0:
        return roots
    lo, hi = lo[ri, ci], hi[ri, ci]
    f_lo, f_hi = f_lo[ri, ci], f_hi[ri, ci]
    Q0, D, Rn = rays.Q0[ri], rays.D[ri], rays.Rn[ri]
    x = _false_position(lo, hi, f_lo, f_hi)
    last = np.zeros(ri.size)  # +1: lo moved last, -1: hi moved last (Illinois bookkeeping)
    found = np.empty(ri.size)
    slot = np.arange(ri.size)
    for _ in range(_MAX_ITER):
        pos = Q0 + x[:, None] * D
        rho = np.hypot(pos[:, 0], pos[:, 1])
        d = rho - Rn
        z = pos[:, 2]
        g_out = (d - 1.0) * (d + 1.0) + z * z
        g_in = (rho + Rn) ** 2 - 1.0 + z * z
        f = g_out * g_in
        move_lo = np.sign(f) == np.sign(f_lo)
        # Illinois: an end kept twice in a row has its value halved, so false position
        # cannot stall on one side.
        f_hi = np.where(move_lo & (last > 0), 0.5 * f_hi, f_hi)
        f_lo = np.where(~move_lo & (last < 0), 0.5 * f_lo, f_lo)
        lo, f_lo = np.where(move_lo, x, lo), np.where(move_lo, f, f_lo)
        hi, f_hi = np.where(move_lo, hi, x), np.where(move_lo, f_hi, f)
        last = np.where(move_lo, 1.0, -1.0)
        # Newton on the factor that vanishes here: nearly quadratic along the ray. A step
        # leaving the bracket (it chased the neighbouring root) falls back to false position.
        outer = np.abs(g_out) <= np.abs(g_in)
        with np.errstate(divide="ignore", invalid="ignore"):
            drho = np.where(rho > 0.0, (pos[:, 0] * D[:, 0] + pos[:, 1] * D[:, 1]) / rho, 0.0)
            slope = 2.0 * np.where(outer, d, rho + Rn) * drho + 2.0 * z * D[:, 2]
            xn = x - np.where(outer, g_out, g_in) / slope
        inside = (xn > lo) & (xn < hi)
        xn = np.where(inside, xn, _false_position(lo, hi, f_lo, f_hi))
        # Done when the factor is at the rounding noise of its own evaluation, or the step
        # or the bracket is at the rounding level of the geometry's size.
        tol = 4e-16 * (np.abs(xn) + Rn + 1.0)
        g_here = np.where(outer, g_out, g_in)
        size2 = np.where(outer, rho * np.abs(d) + d * d, (rho + Rn) ** 2) + z * z + 1.0
        settled = np.abs(g_here) <= 8e-16 * size2
        done = settled | (np.abs(xn - x) <= tol) | (hi - lo <= tol)
        x = np.where(settled, x, xn)
        if done.any():
            found[slot[done]] = x[done]
            keep = ~done
            if not keep.any():
                break
            slot, x, lo, hi, f_lo, f_hi, last, Q0, D, Rn = (
                v[keep] for v in (slot, x, lo, hi, f_lo, f_hi, last, Q0, D, Rn))
    else:
        found[slot] = x
    roots[ri, ci] = found
    return roots


def _axis_parallel_roots(Q0, D, Rn, inner):
    """Scaled roots for rays parallel to the axis (constant rho): ``z = +-sqrt(1 - (rho -+ R')^2)``.

    Closed form and exact; it also covers rays through the cusps of a spindle torus, where
    the quartic has a double root that no sign change reveals.
    """
    rho = np.hypot(Q0[:, 0], Q0[:, 1])
    dr = rho + Rn if inner else rho - Rn  # Rn: (N,) per ray
    with np.errstate(invalid="ignore"):
        half = np.sqrt((1.0 - dr) * (1.0 + dr))
    zsign = np.sign(D[:, 2])
    u = np.stack([-half, half], axis=1) * zsign[:, None] - (Q0[:, 2] * zsign)[:, None]
    return np.column_stack([u, np.full((u.shape[0], 2), np.nan)])


def ray_torus_hits(origins, directions, R, a, b=None, tmin=None, sheet="outer"):
    """Real hit distances of rays with the torus ``((hypot(x,y) - R)/a)^2 + (z/b)^2 = 1``.

    Parameters
    ----------
    origins, directions : array_like, shape (N, 3)
        Ray origins (mm) and unit directions (float64), ``p(t) = origin + t direction``.
    R : float or array_like (N,)
        Distance (mm) of the tube centre from the z axis, ``R >= 0``; ``R < a`` is a spindle
        torus, of which only the outer ("apple") sheet is a hit.
    a, b : float or array_like (N,)
        Radial and axial semi-axes of the tube (mm), both > 0; ``b`` defaults to ``a``.
        Arrays give each ray its own torus (all about the z axis, centred at the origin).
    tmin : float or array_like (N,), optional
        Hits at ``t <= tmin`` (mm) are discarded; default ``1e-6 a`` so that a secondary ray
        starting on the surface never reports its own start.
    sheet : {"outer", "inner"}
        ``"inner"`` asks instead for the quartic's mirror sheet
        ``((hypot(x,y) + R)/a)^2 + (z/b)^2 = 1`` (non-empty only when ``R < a``): the surface
        swept by an arc whose centre lies at ``r = -R`` behind the axis.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Hit distances ``t`` (mm) per ray, ascending, NaN-padded. Transversal hits are
        accurate to about 1e-12 of the scene's size in tube radii; the two hits of a ray
        within ~1e-6 tube radii of tangency are ill-conditioned (errors up to ~1e-7 tube
        radii on the shared hard cases). Tangent touches are omitted.
        When ``R < 1e-9 a`` the tube centre is taken to be on the axis (a spheroid; the
        surface moves by less than 1e-9 tube radii).
    """
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    dirs = np.asarray(directions, dtype=float).reshape(-1, 3)
    n = o.shape[0]
    a = np.broadcast_to(np.asarray(a, dtype=float), (n,))
    R = np.broadcast_to(np.asarray(R, dtype=float), (n,))
    b = a if b is None else np.broadcast_to(np.asarray(b, dtype=float), (n,))
    if not (np.all(a > 0) and np.all(b > 0) and np.all(R >= 0)):
        raise ValueError(f"torus needs a, b > 0 and R >= 0 (mm), got R={R}, a={a}, b={b}")
    if sheet not in ("outer", "inner"):
        raise ValueError(f"sheet must be 'outer' or 'inner', got {sheet!r}")
    inner = sheet == "inner"
    tmin = SELF_HIT_FRACTION * a if tmin is None else np.broadcast_to(np.asarray(tmin, dtype=float), (n,))
    out = np.full((n, 4), np.nan)
    if n == 0:
        return out
    ball = R < 1e-9 * a
    if np.any(ball):
        from .quadric import ray_spheroid_hits
        out[ball, :2] = ray_spheroid_hits(o[ball], dirs[ball], a[ball], b[ball], tmin=tmin[ball])
    rays = _ScaledRays(o, dirs, R, a, b)
    B = rays.Rn + 1.0
    # Rays whose closest approach lies outside the bounding sphere cannot hit.
    near = (np.einsum("ij,ij->i", rays.Q0, rays.Q0) < B * B * (1.0 + 1e-12)) & ~ball
    idx = np.nonzero(near)[0]
    if idx.size == 0:
        return out
    sub = rays.subset(idx)
    Q0, D, Rn, B = sub.Q0, sub.D, sub.Rn, B[idx]
    E = D[:, 0] ** 2 + D[:, 1] ** 2
    F = 2.0 * (Q0[:, 0] * D[:, 0] + Q0[:, 1] * D[:, 1])
    C = np.einsum("ij,ij->i", Q0, Q0) + Rn * Rn - 1.0
    p = 2.0 * C - 4.0 * Rn * Rn * E
    q = -4.0 * Rn * Rn * F
    half = np.sqrt(np.maximum(B * B - np.einsum("ij,ij->i", Q0, Q0), 0.0)) * (1.0 + 1e-9) + 1e-12 * B
    crit = _cubic_critical_points(p, q)
    crit = np.clip(crit, -half[:, None], half[:, None])
    bounds = np.column_stack([-half, crit, half])
    u = _solve_pieces(sub, bounds)
    vertical = E == 0.0
    if np.any(vertical):
        u[vertical] = _axis_parallel_roots(Q0[vertical], D[vertical], Rn[vertical], inner)
    g_out, g_in = sub.factors(u)
    # Each root of f = g_out * g_in belongs to the sheet whose factor is nearer zero.
    keep = np.abs(g_in) <= np.abs(g_out) if inner else np.abs(g_out) <= np.abs(g_in)
    t = (sub.s0[:, None] + u) / sub.speed[:, None]
    t = np.where(keep & (t > tmin[idx, None]), t, np.nan)
    t.sort(axis=1)
    out[idx] = t
    return out
