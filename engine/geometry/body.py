"""The glass body's surfaces: point and exact unit normal at any surface parameter, vectorised.

Design rule: :class:`BottleBody` wraps the validated :class:`engine.geometry.offset.BodyProfile` of a shape
and evaluates five parts, each at a pair ``(theta, s)`` of broadcastable arrays:

===============  ==========================================================================
``outer``        outer wall; ``s`` = height z (mm), ``0 <= z <= z_top``
``inner``        inner wall; ``s`` = height z (mm), ``z_ib <= z <= z_top``
``base_outer``   outer base; ``s`` in [0, 1] along the base from the axis to the standing ring
``base_inner``   inner base; ``s`` in [0, 1] from the axis to the foot of the inner wall
``rim``          mouth annulus at ``z_top``; ``s`` in [0, 1] from the inner to the outer edge
===============  ==========================================================================

Walls rise strictly, so the height is a valid along-section parameter common to every section
of a non-round bottle. Along a base, ``s`` walks the base chain with equal shares per segment
(for a flat base: the radial fraction). ``theta`` (rad) is the polar angle in the bottle's own
frame; points and normals come out in the world frame, turned by ``rotation_deg`` about +z.

Normals face **out of the glass**: away from the axis on the outer wall, into the cavity on the
inner wall, down under the base, up on the inner base and on the rim. A wall's normal is the
normalised gradient of ``g(x, y, z) = sd(x, y; radii(z))`` (the shape's
:class:`~engine.geometry.crosssection.CrossSection`), with
``d radius / dz = T_r / T_z`` from each section's tangent; multiplying through by the product of
the ``T_z`` keeps it finite where a section turns horizontal.
"""
from __future__ import annotations

import math

import numpy as np

from .chain import by_segment, locate
from .offset import BodyProfile
from .validate import body_profile

PARTS = ("outer", "inner", "base_outer", "base_inner", "rim")


def chain_state(chain, z, above: bool = False):
    """Radius and unit tangent ``(r, T_r, T_z)`` of a z-monotone chain at heights ``z`` (mm).

    Heights are clamped to the chain's range. At a joint the lower segment answers, or the
    upper one with ``above`` (rising chains: the other side of a corner).
    """
    z = np.asarray(z, float)
    lo, hi = sorted((chain[0].p0[1], chain[-1].p1[1]))
    idx, t = locate(chain, np.clip(z, lo, hi))
    if above:
        up = (t >= 1.0 - 1e-12) & (idx < len(chain) - 1)
        idx, t = np.where(up, idx + 1, idx), np.where(up, 0.0, t)
    r, tr, tz = (np.empty(z.shape) for _ in range(3))
    t_flat, out = np.ravel(t), [a.reshape(-1) for a in (r, tr, tz)]
    for i, part in by_segment(idx):
        tan = chain[i].tangent(t_flat[part])
        out[0][part] = chain[i].point(t_flat[part])[..., 0]
        out[1][part], out[2][part] = tan[..., 0], tan[..., 1]
    return r, tr, tz


def chain_point_at(chain, s):
    """Points and tangents ``(r, z, T_r, T_z)`` at chain parameter ``s`` in [0, 1] (equal share
    per segment)."""
    s = np.clip(np.asarray(s, float), 0.0, 1.0)
    n = len(chain)
    idx = np.minimum((s * n).astype(int), n - 1)
    t = s * n - idx
    out = [np.empty(s.shape) for _ in range(4)]
    t_flat, flat = np.ravel(t), [a.reshape(-1) for a in out]
    for i, part in by_segment(idx):
        p, tan = chain[i].point(t_flat[part]), chain[i].tangent(t_flat[part])
        for k, values in enumerate((p[..., 0], p[..., 1], tan[..., 0], tan[..., 1])):
            flat[k][part] = values
    return tuple(out)


class BottleBody:
    """Surface evaluation for one validated shape (see the module docstring for the parts).

    Raises ``SectionError`` / ``WallError`` at construction when the shape is invalid.
    """

    def __init__(self, shape):
        self.shape = shape
        self.profile: BodyProfile = body_profile(shape)
        self.kind = shape.cross_section
        self.xs = self.profile.xs
        a = math.radians(shape.rotation_deg if not self.xs.revolved else 0.0)
        self._cos, self._sin = math.cos(a), math.sin(a)

    # ------------------------------------------------------------------ helpers
    def _world(self, x, y, z):
        return np.stack([self._cos * x - self._sin * y, self._sin * x + self._cos * y, z], axis=-1)

    def wall_radii(self, part: str, z, above: bool = False):
        """Per-section ``(r, T_r, T_z)`` of the outer or inner wall at heights ``z`` (mm)."""
        chains = [sp.outer_wall if part == "outer" else sp.inner_wall for sp in self.profile.sections]
        return [chain_state(c, z, above) for c in chains]

    def wall(self, part: str, theta, z, above: bool = False):
        """Points ``(..., 3)`` and unit normals ``(..., 3)`` on the ``outer`` / ``inner`` wall
        (at a section's corner, the normal of the side below, or above with ``above``)."""
        theta, z = np.broadcast_arrays(np.asarray(theta, float), np.asarray(z, float))
        states = self.wall_radii(part, z, above)
        radii = [st[0] for st in states]
        x, y, nx, ny = self.xs.boundary(radii, theta)
        _, _, _, d_r = self.xs.signed_distance(radii, x, y)
        tz = [np.maximum(st[2], 1e-12) for st in states]  # walls rise: T_z >= 0
        prod = np.prod(tz, axis=0)
        nz = np.zeros_like(prod)
        for k, st in enumerate(states):
            others = np.prod([tz[j] for j in range(len(tz)) if j != k], axis=0) if len(tz) > 1 else 1.0
            nz = nz + d_r[k] * st[1] * others
        n = np.stack([nx * prod, ny * prod, nz], axis=-1)
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        if part == "inner":
            n = -n
        return self._world(x, y, z), self._world(n[..., 0], n[..., 1], n[..., 2])

    def _base(self, part: str, theta, s):
        sps = self.profile.sections
        chains = [sp.outer_base if part == "base_outer" else sp.inner_base for sp in sps]
        theta, s = np.broadcast_arrays(np.asarray(theta, float), np.asarray(s, float))
        if self.profile.punt:  # round only: a surface of revolution of the base chain
            r, z, tr, tz = chain_point_at(chains[0], s)
            sign = 1.0 if part == "base_outer" else -1.0  # outer: n = (T_z, -T_r) points down
            nr, nz = sign * tz, -sign * tr
            c, sn = np.cos(theta), np.sin(theta)
            return (self._world(r * c, r * sn, z), self._world(nr * c, nr * sn, nz))
        edge = [c[-1].p1[0] for c in chains]
        z0 = chains[0][-1].p1[1]
        x, y, _, _ = self.xs.boundary(edge, theta)
        z = np.full(s.shape, z0)
        nz = np.full(s.shape, -1.0 if part == "base_outer" else 1.0)
        zero = np.zeros(s.shape)
        return self._world(s * x, s * y, z), self._world(zero, zero, nz)

    def _rim(self, theta, s):
        theta, s = np.broadcast_arrays(np.asarray(theta, float), np.asarray(s, float))
        sps = self.profile.sections
        xo, yo, _, _ = self.xs.boundary([sp.r_top for sp in sps], theta)
        xi, yi, _, _ = self.xs.boundary([sp.r_in_top for sp in sps], theta)
        z = np.full(s.shape, self.profile.z_top)
        zero = np.zeros(s.shape)
        return (self._world(xi + s * (xo - xi), yi + s * (yo - yi), z),
                self._world(zero, zero, np.ones(s.shape)))

    # ------------------------------------------------------------------ public
    def point_normal(self, part: str, theta, s):
        """Points ``(..., 3)`` (mm, world frame) and unit normals facing out of the glass.

        ``part`` is one of :data:`PARTS`; ``theta`` (rad) and ``s`` broadcast (see module doc).
        """
        if part in ("outer", "inner"):
            return self.wall(part, theta, s)
        if part in ("base_outer", "base_inner"):
            return self._base(part, theta, s)
        if part == "rim":
            return self._rim(theta, s)
        raise ValueError(f"unknown part {part!r}; expected one of {', '.join(PARTS)}")

    def wall_implicit(self, part: str, points):
        """Implicit function of the ``outer`` / ``inner`` wall at world points ``(..., 3)`` (mm).

        Returns ``(g, grad)``: ``g = sd(x, y; radii(z))`` (mm, the cross-section's
        ``signed_distance`` at the point's height) is negative inside the
        surface (inside the glass's outline for ``outer``, inside the cavity for ``inner``) and
        zero on it; ``grad (..., 3)`` is its world-frame gradient, with ``dg/dz = sum_k
        d sd/d radius_k * T_r,k / T_z,k``. ``g / |grad|`` is the distance to first order, which is
        what a tracer needs to refine a mesh hit onto the exact surface by Newton steps.
        Heights are clamped to the wall's range.
        """
        p = np.asarray(points, float)
        x = self._cos * p[..., 0] + self._sin * p[..., 1]
        y = -self._sin * p[..., 0] + self._cos * p[..., 1]
        states = self.wall_radii(part, p[..., 2])
        g, gx, gy, d_r = self.xs.signed_distance([st[0] for st in states], x, y)
        gz = sum(d_r[k] * st[1] / np.maximum(st[2], 1e-12) for k, st in enumerate(states))
        grad = np.stack([self._cos * gx - self._sin * gy, self._sin * gx + self._cos * gy,
                         np.broadcast_to(gz, np.shape(g))], axis=-1)
        return g, grad

    def wall_range(self, part: str) -> tuple[float, float]:
        """Heights ``(z_lo, z_hi)`` (mm) the ``outer`` / ``inner`` wall spans."""
        return (0.0, self.profile.z_top) if part == "outer" else (self.profile.z_ib, self.profile.z_top)
