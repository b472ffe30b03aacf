"""An outline bottle's wall cut into height bands where its sections keep one form.

Design rule: the section of an outline wall at height ``z`` is ``{q : sd(q, k(z) P) <= r(z)}``
(:mod:`engine.geometry.plan`) with ``k`` the core's and ``r`` the rounding's profile (the outer
wall's ``c``, the cavity's ``c - w``). Inside a band both are one profile segment each and ``r``
keeps its sign, so the section's pieces keep their order and every closed form over the band
(a face's surface, a silhouette's curve) is one formula. Shared by the CAD export and the
drawing; pure geometry, no OCP, no Qt. Units mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .chain import param_at_z, segment_between, z_breaks


@dataclass(frozen=True)
class Band:
    """One height band of a wall: ``za < zb`` (mm), the core's and the rounding's profile
    segments over it (``k``, ``r``: exact segments in (radius, z), mm) and whether its sections
    are grown (``r >= 0``: corner arcs) or eroded (``r < 0``: sharp creases)."""

    za: float
    zb: float
    k: object
    r: object
    grown: bool


def bands(chains, z_lo: float, z_hi: float, crossings=()) -> list[Band]:
    """The bands of the wall whose core and rounding are ``chains`` from ``z_lo`` to ``z_hi``
    (mm), cut at their joints and at the heights ``crossings`` where the rounding passes 0
    (:func:`engine.geometry.capacity.area_breaks` finds them)."""
    inside = [z for z in crossings if z_lo < z < z_hi]
    zs = z_breaks(chains, z_lo, z_hi, inside)
    joints = [p[1] for c in chains for s in c for p in (s.p0, s.p1) if z_lo < p[1] < z_hi]
    # why: z_breaks rounds; a band must end at its segments' own joints (or the profiles' radii
    # there would mix two heights) and where the rounding is 0 exactly
    for z in joints + inside:
        j = int(np.argmin(np.abs(zs - z)))
        if 0 < j < len(zs) - 1 and abs(zs[j] - z) <= 1e-6:  # (merged into the wall's end: the end stays)
            zs[j] = z
    out = []
    for za, zb in zip(zs[:-1], zs[1:]):
        k, r = (segment_between(c, float(za), float(zb)) for c in chains)
        mid = float(r.point(param_at_z(r, 0.5 * (za + zb)))[0])
        out.append(Band(float(za), float(zb), k, r, mid >= 0.0))
    return out


def band_radii(band: Band, z):
    """``(k, r)`` (mm) at heights ``z`` in the band, ``r`` kept on the band's side of 0."""
    k, r = (s.point(param_at_z(s, z))[..., 0] for s in (band.k, band.r))
    return np.maximum(k, 0.0), (np.maximum(r, 0.0) if band.grown else np.minimum(r, 0.0))
