"""Ray intersection with quadrics of revolution about z: cone frusta, cylinders, annuli, spheroids,
and the cheap ray culling test against a revolved box (two cylinders and two planes).

Design rule: candidates come from a numerically stable quadratic formed after the ray origin
has been moved to its closest approach to the surface's centre (so far-away origins lose no
digits), and every candidate is then checked and Newton-polished on the *unsquared* geometric
equation. Squaring ``n_r rho = c - n_z z`` adds the mirror nappe ``-n_r rho = c - n_z z``;
candidates nearer the mirror than the surface are dropped. No absolute epsilons: tolerances
are fractions of the segment's own size.

The intersection functions return an (N, 2) float64 array of hit distances ``t`` (mm),
ascending per ray, NaN-padded, for rays ``p(t) = origin + t direction`` with unit directions.
"""
from __future__ import annotations

import numpy as np

#: Hits this close to a segment's ends (as a fraction of its length) still count, so that
#: neighbouring segments of a section overlap by a hair instead of leaving cracks.
EXTENT_SLACK = 1e-9


def stable_quadratic_roots(A, B, C):
    """Real roots of ``A t^2 + 2 B t + C = 0`` (arrays, any units), as (N, 2) ascending.

    Uses ``q = -(B + sign(B) sqrt(B^2 - AC))``, ``t = q / A`` and ``t = C / q`` so that neither
    root suffers cancellation; a vanishing ``A`` leaves the single root ``-C / 2B``. NaN where
    the discriminant is negative or a root is not finite.
    """
    A, B, C = (np.asarray(v, dtype=float) for v in (A, B, C))
    disc = B * B - A * C
    with np.errstate(divide="ignore", invalid="ignore"):
        sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        q = -(B + np.where(B >= 0.0, sq, -sq))
        t1 = q / A
        t2 = C / q
    roots = np.stack([t1, t2], axis=-1)
    roots[~np.isfinite(roots)] = np.nan
    roots.sort(axis=-1)
    return roots


def _prepare(origins, directions, centre_z):
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    rel = o - np.array([0.0, 0.0, centre_z])
    t0 = -np.einsum("ij,ij->i", rel, d)
    return rel + t0[:, None] * d, d, t0


def ray_cone_hits(origins, directions, r0, z0, r1, z1, tmin=None):
    """Hits of rays with the segment ``(r0, z0) -> (r1, z1)`` (mm) revolved about z.

    A cone frustum in general, a cylinder when ``r0 == r1`` and an annulus (a disc when one
    radius is 0) when ``z0 == z1``. Only hits whose meridian point projects onto the segment
    (within ``EXTENT_SLACK`` of its length) count.

    Parameters
    ----------
    origins, directions : array_like, shape (N, 3)
        Ray origins (mm) and unit directions.
    r0, z0, r1, z1 : float
        End points (mm), ``r >= 0``, not both equal.
    tmin : float, optional
        Hits at ``t <= tmin`` (mm) are dropped; default ``1e-9`` times the segment's size
        (its length plus its largest radius), far below any feature yet above rounding.

    Returns
    -------
    numpy.ndarray, shape (N, 2)
        Hit distances (mm), ascending, NaN-padded.
    """
    r0, z0, r1, z1 = float(r0), float(z0), float(r1), float(z1)
    dr, dz = r1 - r0, z1 - z0
    length = float(np.hypot(dr, dz))
    if not length > 0:
        raise ValueError(f"a revolved segment needs two distinct end points, got ({r0}, {z0}) twice")
    size = length + max(abs(r0), abs(r1))
    tmin = 1e-9 * size if tmin is None else float(tmin)
    zm = 0.5 * (z0 + z1)
    P, d, t0 = _prepare(origins, directions, zm)
    # Unit outward normal of the meridian line and its offset: n_r rho + n_z z = c (z from zm).
    n_r, n_z = dz / length, -dr / length
    c = n_r * r0 + n_z * (z0 - zm)
    if n_r == 0.0:
        # Annulus: one plane crossing, exact.
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (z0 - zm - P[:, 2]) / d[:, 2]
        s = np.where(np.isfinite(s), s, np.nan)  # a ray in the annulus' plane: no crossing
        cand = np.stack([s, np.full_like(s, np.nan)], axis=1)
    else:
        w0 = c - n_z * P[:, 2]          # n_r rho must equal w0 + w1 s
        w1 = -n_z * d[:, 2]
        A = n_r * n_r * (d[:, 0] ** 2 + d[:, 1] ** 2) - w1 * w1
        B = n_r * n_r * (P[:, 0] * d[:, 0] + P[:, 1] * d[:, 1]) - w0 * w1
        C = n_r * n_r * (P[:, 0] ** 2 + P[:, 1] ** 2) - w0 * w0
        cand = stable_quadratic_roots(A, B, C)
        # Drop the mirror nappe before polishing, so a polished mirror root cannot land on a
        # true one and be counted twice.
        rho = np.hypot(P[:, 0, None] + cand * d[:, 0, None], P[:, 1, None] + cand * d[:, 1, None])
        lin = (w0[:, None] + w1[:, None] * cand)
        cand = np.where(np.abs(n_r * rho - lin) <= np.abs(n_r * rho + lin), cand, np.nan)
        for _ in range(2):  # Newton on the unsquared equation h(s) = n_r rho(s) - w0 - w1 s
            x = P[:, 0, None] + cand * d[:, 0, None]
            y = P[:, 1, None] + cand * d[:, 1, None]
            rho = np.hypot(x, y)
            h = n_r * rho - w0[:, None] - w1[:, None] * cand
            with np.errstate(divide="ignore", invalid="ignore"):
                dh = n_r * (x * d[:, 0, None] + y * d[:, 1, None]) / rho - w1[:, None]
                step = h / dh
            ok = np.isfinite(step) & (np.abs(step) < 1e-3 * size)
            cand = np.where(ok, cand - step, cand)
    x = P[:, 0, None] + cand * d[:, 0, None]
    y = P[:, 1, None] + cand * d[:, 1, None]
    z = P[:, 2, None] + cand * d[:, 2, None] + zm
    rho = np.hypot(x, y)
    along = ((rho - r0) * dr + (z - z0) * dz) / (length * length)
    keep = (along >= -EXTENT_SLACK) & (along <= 1.0 + EXTENT_SLACK)
    t = t0[:, None] + cand
    t = np.where(keep & (t > tmin), t, np.nan)
    t.sort(axis=1)
    return t


def ray_spheroid_hits(origins, directions, a, b, zc=0.0, tmin=None):
    """Hits of rays with the spheroid ``(hypot(x, y)/a)^2 + ((z - zc)/b)^2 = 1`` (mm).

    The degenerate torus (tube centre on the axis). Solved in the frame scaled to a unit
    sphere with the origin at the ray's closest approach, where the two roots are
    ``+-sqrt((1 - |Q0|)(1 + |Q0|))`` without cancellation.

    Parameters
    ----------
    origins, directions : array_like, shape (N, 3)
        Ray origins (mm) and unit directions.
    a, b : float or array_like (N,)
        Equatorial and polar semi-axes (mm), > 0 (per ray if arrays).
    zc : float
        Height of the centre (mm).
    tmin : float or array_like (N,), optional
        Hits at ``t <= tmin`` are dropped; default ``1e-6 a``.

    Returns
    -------
    numpy.ndarray, shape (N, 2)
        Hit distances (mm), ascending, NaN-padded.
    """
    o = np.asarray(origins, dtype=float).reshape(-1, 3) - np.array([0.0, 0.0, zc])
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    a = np.broadcast_to(np.asarray(a, dtype=float), (o.shape[0],))
    b = np.broadcast_to(np.asarray(b, dtype=float), (o.shape[0],))
    tmin = 1e-6 * a if tmin is None else np.broadcast_to(np.asarray(tmin, dtype=float), a.shape)
    inv = np.column_stack([1.0 / a, 1.0 / a, 1.0 / b])
    Q, D = o * inv, d * inv
    speed = np.linalg.norm(D, axis=1)
    D = D / speed[:, None]
    s0 = -np.einsum("ij,ij->i", Q, D)
    m = np.linalg.norm(Q + s0[:, None] * D, axis=1)
    with np.errstate(invalid="ignore"):
        u = np.sqrt((1.0 - m) * (1.0 + m))
    t = np.stack([(s0 - u) / speed, (s0 + u) / speed], axis=1)
    return np.where(t > tmin[:, None], t, np.nan)


def rays_touching_bounds(origins, directions, bounds, tmin=0.0, tmax=np.inf):
    """Mask (N,) of rays whose part ``tmin < t < tmax`` can meet the revolved box ``bounds``.

    ``bounds = (rmin, rmax, zmin, zmax)`` (mm) describes the solid between two cylinders and
    two planes; the test is conservative (never culls a ray that meets it) and is meant to
    skip segments cheaply before calling :func:`engine.intersect.revolved_hits`.
    """
    rmin, rmax, zmin, zmax = (float(v) for v in bounds)
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    pad = 1e-9 * (abs(rmax) + abs(zmax) + abs(zmin) + (zmax - zmin))
    zmin, zmax, rmin, rmax = zmin - pad, zmax + pad, max(rmin - pad, 0.0), rmax + pad
    with np.errstate(divide="ignore", invalid="ignore"):
        ta = (zmin - o[:, 2]) / d[:, 2]
        tb = (zmax - o[:, 2]) / d[:, 2]
    flat = d[:, 2] == 0.0
    inside_slab = (o[:, 2] >= zmin) & (o[:, 2] <= zmax)
    lo = np.where(flat, np.where(inside_slab, -np.inf, np.inf), np.minimum(ta, tb))
    hi = np.where(flat, np.where(inside_slab, np.inf, -np.inf), np.maximum(ta, tb))
    lo, hi = np.maximum(lo, tmin), np.minimum(hi, tmax)
    # rho^2 along the ray is a convex quadratic: its minimum on [lo, hi] is at the clamped
    # closest approach to the axis, its maximum at an end of the interval.
    E = d[:, 0] ** 2 + d[:, 1] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        s_axis = np.where(E > 0, -(o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]) / E, 0.0)
    s_near = np.clip(s_axis, lo, hi)

    def rho_at(s):
        with np.errstate(invalid="ignore"):
            x = o[:, 0] + np.where(np.isfinite(s), s, 0.0) * d[:, 0]
            y = o[:, 1] + np.where(np.isfinite(s), s, 0.0) * d[:, 1]
        return np.where(np.isfinite(s) | (E == 0), np.hypot(x, y), np.inf)

    rho_near = rho_at(s_near)
    rho_far = np.maximum(rho_at(lo), rho_at(hi))
    return (lo <= hi) & (rho_near <= rmax) & (rho_far >= rmin)
