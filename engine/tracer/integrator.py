"""Whitted wavefront integrator: every boundary splits a ray into its Fresnel branches.

Design rule: rays travel as flat numpy batches (origins, directions, RGB weights, pixel slot).
Each pass intersects the whole batch with Embree, refines the hits onto the exact surfaces
(:func:`exact_hits`), shades them with the exact normals and
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

from .optics import beer_lambert, fresnel_dielectric, reflect, refract
from .embree_scene import SURFACE_EPS_MM
from .geometry import AIR, FREE_SURFACE, GLASS, LIQUID
from .refine import NEIGHBOURS, refine_on

#: Most Embree casts per ray and boundary (candidates passed before giving up: a miss).
MAX_PASSES = 12
#: Step (mm) past a passed mesh hit before re-casting: above Embree's float32 error at bottle
#: scale (~2e-5 mm), far below any wall (a passed candidate lies off the true surface anyway).
PASS_STEP_MM = 1e-4
#: A lost ray (no mesh seen from inside glass or liquid) is cast again this many mesh
#: tolerances into its medium (past the chordal sliver; below any wall the engine validates).
PUSH_TOLS = 2.0


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
    passed: int = 0  # rays given up after MAX_PASSES passed candidates
    per_pass: list = field(default_factory=list)

    def add(self, other: "TraceStats") -> None:
        for name in ("rays_cast", "passes", "escaped_inside", "cut_weight", "cut_depth", "passed"):
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
    left = np.full(len(o), -1, dtype=np.int8)  # surface each ray just left (-1: none)
    side = np.zeros(len(o), dtype=np.int8)  # sign of d . n (oriented) when it left
    push = np.zeros((len(o), 3))  # unit normal into the medium each ray just entered
    while len(o):
        t, surf, p, n = exact_hits(geometry, o, d, left, side, st, push=push, medium=medium)
        st.passes += 1
        st.per_pass.append(len(o))
        miss = surf < 0
        if np.any(miss):
            st.escaped_inside += int(np.count_nonzero(medium[miss] != AIR))
            rad = w[miss] * environment.lookup(d[miss])
            _accumulate(acc, slot[miss], rad)
        hit = ~miss
        if depth >= max_depth:
            st.cut_depth += int(np.count_nonzero(hit))
            _close_branches(acc, slot[hit], w[hit], d[hit], environment)
            break
        o, d, w, slot, t, surf, p, n = o[hit], d[hit], w[hit], slot[hit], t[hit], surf[hit], p[hit], n[hit]
        if not len(o):
            break
        front, back = geometry.media(surf, p[:, 2])
        dn = np.einsum("ij,ij->i", d, n)
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
        left = np.concatenate([surf, surf[keep_t]])
        side = np.where(np.einsum("ij,ij->i", d, np.concatenate([n, n[keep_t]])) >= 0, 1, -1).astype(np.int8)
        finite = np.isfinite(w).all(axis=1) & np.isfinite(d).all(axis=1)
        alive = finite & (w.max(axis=1) >= min_weight)
        cut = finite & ~alive
        st.cut_weight += int(np.count_nonzero(cut))
        if np.any(cut):
            _close_branches(acc, slot[cut], w[cut], d[cut], environment)
        o, d, w, slot, medium = o[alive], d[alive], w[alive], slot[alive], medium[alive]
        push = np.concatenate([n_face, -n_face[keep_t]])[alive]
        left, side = left[alive], side[alive]
        depth += 1
    return acc


def exact_hits(geometry, o, d, left, side, stats=None, push=None, medium=None):
    """Nearest true-surface hits of rays ``o + t d`` (mm, unit ``d``).

    Embree finds the candidate on the mesh, :meth:`RenderGeometry.refine` moves it onto the
    exact surface. A candidate is *passed* (the ray re-cast from just beyond the mesh hit, at
    most :data:`MAX_PASSES` times) when the true surface is not crossed near it, when it is the
    surface the ray just left (``left``) met again from the side it left towards (``side``,
    the sign of ``d . n``: that is the crossing the ray started from, seen through the chordal
    mesh), or when it is the free surface's overlap lip outside the cavity.

    A ray that starts inside glass or liquid (``medium``) may start in the sliver between a
    true surface and its chordal mesh and so see no mesh at all; such misses are cast again
    ``PUSH_TOLS`` mesh tolerances along ``push`` (the unit normal into the medium at the
    surface the ray left), past the sliver, and the candidate found is refined from the true
    origin; what is still lost gets :func:`_nearby_exact`. Camera rays pass ``left = -1``.

    Returns ``(t, surface, points, normals)``: exact distance from ``o``, surface id (-1 for a
    miss), exact hit points and oriented normals.
    """
    n_rays = len(o)
    t_out = np.full(n_rays, np.inf)
    surf_out = np.full(n_rays, -1, dtype=np.int8)
    p_out = np.zeros((n_rays, 3))
    n_out = np.zeros((n_rays, 3))
    todo = np.arange(n_rays)
    cur = np.array(o, dtype=float, copy=True)
    for _ in range(MAX_PASSES):
        if not len(todo):
            break
        oc, dc = cur[todo], d[todo]
        t_mesh, prim = geometry.triangles.intersect(oc, dc)
        if stats is not None:
            stats.rays_cast += len(todo)
        hit = prim >= 0
        todo, oc, dc, t_mesh, prim = todo[hit], oc[hit], dc[hit], t_mesh[hit], prim[hit]
        surf = geometry.surface_of_triangle[prim]
        # The mesh of the surface just left, crossed the way the ray left it: the sliver
        # between true surface and chords, never a true hit (no refinement needed).
        crossing = np.where(np.einsum("ij,ij->i", dc, geometry.face_sign[prim]) >= 0, 1, -1)
        t_ex, n = np.full(len(todo), np.nan), np.zeros((len(todo), 3))
        fresh = ~((surf == left[todo]) & (crossing == side[todo]))
        if np.any(fresh):
            t_ex[fresh], n[fresh], surf[fresh] = geometry.refine(oc[fresh], dc[fresh], t_mesh[fresh], surf[fresh])
        good = np.isfinite(t_ex)
        p = oc + np.where(good, t_ex, 0.0)[:, None] * dc
        dn = np.einsum("ij,ij->i", dc, n)
        again = (surf == left[todo]) & (np.where(dn >= 0, 1, -1) == side[todo])
        good &= ~again
        lip = good & (surf == FREE_SURFACE)
        if np.any(lip):
            good[lip] = geometry.in_cavity(p[lip])
        k = todo[good]
        surf_out[k], p_out[k], n_out[k] = surf[good], p[good], n[good]
        t_out[k] = np.einsum("ij,ij->i", p[good] - o[k], d[k])
        rest = ~good
        todo = todo[rest]
        cur[todo] = oc[rest] + (t_mesh[rest] + PASS_STEP_MM)[:, None] * dc[rest]
    if push is not None and medium is not None:
        lost = np.nonzero((surf_out < 0) & (medium != AIR) & (left >= 0))[0]
        if len(lost):
            shift = geometry.tol_mm * PUSH_TOLS * push[lost] + (cur[lost] - o[lost])  # from the last pass
            t_mesh, prim = geometry.triangles.intersect(o[lost] + shift, d[lost])
            if stats is not None:
                stats.rays_cast += len(lost)
            hit = prim >= 0
            lost, t_mesh, prim, shift = lost[hit], t_mesh[hit], prim[hit], shift[hit]
            t_mesh = t_mesh + np.einsum("ij,ij->i", shift, d[lost])
            t_ex, n, surf = geometry.refine(o[lost], d[lost], t_mesh, geometry.surface_of_triangle[prim])
            dn = np.einsum("ij,ij->i", d[lost], n)
            good = np.isfinite(t_ex) & ~((surf == left[lost]) & (np.where(dn >= 0, 1, -1) == side[lost]))
            k = lost[good]
            surf_out[k], n_out[k], t_out[k] = surf[good], n[good], t_ex[good]
            p_out[k] = o[k] + t_ex[good, None] * d[k]
        _nearby_exact(geometry, o, d, left, side, medium, t_out, surf_out, p_out, n_out)
    if stats is not None:
        stats.passed += int(len(todo))
    return t_out, surf_out, p_out, n_out


def _nearby_exact(geometry, o, d, left, side, medium, t_out, surf_out, p_out, n_out) -> None:
    """Last resort for rays still lost in glass or liquid (in place): the first exact crossing
    ahead of the surface they left and of its neighbours (a ray leaving an edge, say the rim,
    straight into the sliver of the neighbouring wall, or grazing along a wall in its sliver)."""
    lost = np.nonzero((surf_out < 0) & (medium != AIR) & (left >= 0))[0]
    if not len(lost):
        return
    # anywhere in the bottle: a ray grazing a wall inside its sliver may run far along it
    r_max = max(max(sg.p0[0], sg.p1[0]) for sp in geometry.body.profile.sections for sg in sp.outer_wall)
    reach = 4.0 * (geometry.z_top + r_max)
    for sid in np.unique(left[lost]):
        k = lost[left[lost] == sid]
        for other in (sid, *NEIGHBOURS[int(sid)]):
            if other == FREE_SURFACE and geometry.fill_height is None:
                continue
            t_ex, n = refine_on(geometry, o[k], d[k], np.zeros(len(k)), np.full(len(k), other, np.int8),
                                forward=True, window_mm=reach)
            dn = np.einsum("ij,ij->i", d[k], n)
            ok = np.isfinite(t_ex) & (t_ex < t_out[k])
            ok &= ~((other == sid) & (np.where(dn >= 0, 1, -1) == side[k]))
            j = k[ok]
            t_out[j], surf_out[j], n_out[j] = t_ex[ok], other, n[ok]
            p_out[j] = o[j] + t_ex[ok, None] * d[j]


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
