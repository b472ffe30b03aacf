"""Whitted wavefront integrator: every boundary splits a ray into its Fresnel branches.

Design rule: rays travel as flat numpy batches (origins, directions, RGB weights, pixel slot).
Each pass intersects the whole batch with Embree, shades the hits with the exact normals and
the media on both sides (:mod:`engine.tracer.geometry`), and replaces each hit ray by its
reflected branch (weight x R) and refracted branch (weight x (1 - R)), after Beer-Lambert
absorption of the segment just travelled. Escaping rays add ``weight x environment``.

A branch is cut when its largest channel weight falls below ``min_weight`` or after
``max_depth`` boundaries; a cut branch is closed with the environment along its direction
(:func:`_close_branches`), so energy is never created (R + T = 1, absorption <= 1, and a cut
adds at most its weight times the environment). Non-finite values are dropped, never accumulated. Batches keep each pixel's
rays in a fixed relative order and accumulate with ``bincount``, so a pixel's value is
bit-identical however pixels are grouped into tiles.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..optics import beer_lambert, fresnel_dielectric, reflect, refract
from .embree_scene import SURFACE_EPS_MM
from .geometry import AIR, GLASS, LIQUID


@dataclass(frozen=True)
class Materials:
    """Index of refraction and absorption (1/mm, RGB) per medium id (AIR, GLASS, LIQUID)."""

    ior: tuple = (1.0, 1.52, 1.333)
    sigma_a: tuple = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))

    @classmethod
    def from_design(cls, design) -> "Materials":
        """Air 1.0 and clear; glass and liquid from ``design.glass`` / ``design.liquid``."""
        liq = design.liquid
        return cls((1.0, float(design.glass.ior), float(liq.ior) if liq else 1.0),
                   ((0.0, 0.0, 0.0), tuple(map(float, design.glass.absorption)),
                    tuple(map(float, liq.absorption)) if liq else (0.0, 0.0, 0.0)))


@dataclass
class TraceStats:
    """Counters of one trace call (for benchmarks and tests)."""

    rays_cast: int = 0
    passes: int = 0
    escaped_inside: int = 0  # rays that left the mesh while not in air: would be a leak
    cut_weight: int = 0
    cut_depth: int = 0
    per_pass: list = field(default_factory=list)

    def add(self, other: "TraceStats") -> None:
        for name in ("rays_cast", "passes", "escaped_inside", "cut_weight", "cut_depth"):
            setattr(self, name, getattr(self, name) + getattr(other, name))


def trace(geometry, materials: Materials, environment, origins, directions, slots, n_slots: int,
          *, max_depth: int = 24, min_weight: float = 1e-3, stats: TraceStats | None = None):
    """Radiance sums per slot of camera rays (Whitted tree, both Fresnel branches).

    Parameters
    ----------
    geometry : RenderGeometry
    materials : Materials
    environment : EnvironmentMap
    origins, directions : ndarray (N, 3)
        Ray starts (mm, in air) and unit directions (float64).
    slots : ndarray of int (N,)
        Accumulation slot (e.g. pixel) of each ray, in ``[0, n_slots)``.
    max_depth : int
        Most boundaries a branch may meet; the branch is dropped at the next one.
    min_weight : float
        A branch whose largest channel throughput is below this is dropped (bias <= this per cut).

    Returns
    -------
    ndarray (n_slots, 3) float64: the sum of the rays' radiance per slot (finite, >= 0).
    """
    ior = np.asarray(materials.ior, dtype=float)
    sigma = np.asarray(materials.sigma_a, dtype=float)
    acc = np.zeros((n_slots, 3))
    o = np.asarray(origins, dtype=float)
    d = np.asarray(directions, dtype=float)
    slot = np.asarray(slots, dtype=np.int64)
    w = np.ones((len(o), 3))
    medium = np.full(len(o), AIR, dtype=np.int8)
    st = stats if stats is not None else TraceStats()
    depth = 0
    while len(o):
        t, prim = geometry.triangles.intersect(o, d)
        st.rays_cast += len(o)
        st.passes += 1
        st.per_pass.append(len(o))
        miss = prim < 0
        if np.any(miss):
            st.escaped_inside += int(np.count_nonzero(medium[miss] != AIR))
            rad = w[miss] * environment.lookup(d[miss])
            _accumulate(acc, slot[miss], rad)
        hit = ~miss
        if depth >= max_depth:
            st.cut_depth += int(np.count_nonzero(hit))
            _close_branches(acc, slot[hit], w[hit], d[hit], environment)
            break
        o, d, w, slot, t, prim = o[hit], d[hit], w[hit], slot[hit], t[hit], prim[hit]
        if not len(o):
            break
        p = o + t[:, None] * d
        surf = geometry.surface_of_triangle[prim]
        front, back = geometry.media(surf, p[:, 2])
        n = geometry.exact_normals(p, surf)
        ng = geometry.face_normals[prim]
        dn_geo = np.einsum("ij,ij->i", d, ng)
        dn = np.einsum("ij,ij->i", d, n)
        # Near silhouettes the flat triangle and the true surface may disagree on which side the
        # ray came from; the mesh decided the hit, so its side wins and shading uses its normal.
        disagree = (dn * dn_geo) <= 0
        if np.any(disagree):
            n[disagree] = ng[disagree]
            dn[disagree] = dn_geo[disagree]
        from_front = dn < 0
        inc = np.where(from_front, front, back)
        trn = np.where(from_front, back, front)
        n_face = np.where(from_front[:, None], n, -n)  # faces the incident side
        cos_i = np.abs(dn)
        w = w * beer_lambert(sigma[inc], t)
        refl, cos_t = fresnel_dielectric(cos_i, ior[trn] / ior[inc])
        eta = ior[trn] / ior[inc]
        tir = refl >= 1.0
        d_r = reflect(d, n_face, cos_i)
        w_r = w * refl[:, None]
        o_r = p + SURFACE_EPS_MM * n_face
        keep_t = ~tir
        d_t = refract(d[keep_t], n_face[keep_t], cos_i[keep_t], cos_t[keep_t], eta[keep_t])
        w_t = w[keep_t] * (1.0 - refl[keep_t])[:, None]
        o_t = p[keep_t] - SURFACE_EPS_MM * n_face[keep_t]
        o = np.concatenate([o_r, o_t])
        d = np.concatenate([d_r, d_t])
        w = np.concatenate([w_r, w_t])
        slot = np.concatenate([slot, slot[keep_t]])
        medium = np.concatenate([inc, trn[keep_t]])
        finite = np.isfinite(w).all(axis=1) & np.isfinite(d).all(axis=1)
        alive = finite & (w.max(axis=1) >= min_weight)
        cut = finite & ~alive
        st.cut_weight += int(np.count_nonzero(cut))
        if np.any(cut):
            _close_branches(acc, slot[cut], w[cut], d[cut], environment)
        o, d, w, slot, medium = o[alive], d[alive], w[alive], slot[alive], medium[alive]
        depth += 1
    return acc


def _close_branches(acc, slot, w, d, environment) -> None:
    """Close cut branches with the environment seen along their current direction.

    The subtree of a cut branch would return ``w x`` (radiance reaching it through the rest of
    the glass); with the rest of the glass ignored that is ``w x L_env(d)``. This is exact in a
    uniform environment without absorption (so a white furnace stays at 1), never exceeds the
    branch's weight times the brightest texel, and is far less biased than adding nothing.
    """
    _accumulate(acc, slot, w * environment.lookup(d))


def _accumulate(acc, slot, rad) -> None:
    """Add radiance rows to their slots in array order (deterministic), skipping non-finite rows."""
    ok = np.isfinite(rad).all(axis=1)
    if not np.all(ok):
        slot, rad = slot[ok], rad[ok]
    n = len(acc)
    for c in range(3):
        acc[:, c] += np.bincount(slot, weights=rad[:, c], minlength=n)


def trace_pixels(geometry, materials, environment, camera, cols, rows, sample_indices, **kw):
    """Mean radiance of the given samples per listed pixel.

    ``cols, rows`` (length P) list pixels; ``sample_indices`` (length S) the sample numbers to
    take in every one of them. Returns ``(P, 3)`` float64 sums over the S samples (not means).
    """
    cols = np.asarray(cols)
    rows = np.asarray(rows)
    pix = np.arange(len(cols))
    ks = np.asarray(sample_indices)
    cc = np.tile(cols, len(ks))
    rr = np.tile(rows, len(ks))
    kk = np.repeat(ks, len(cols))
    slots = np.tile(pix, len(ks))
    o, d = camera.pixel_sample_rays(cc, rr, kk)
    return trace(geometry, materials, environment, o, d, slots, len(cols), **kw)
