"""The reflection/refraction tree of one camera sample, depth first with a bounded stack.

Design rule: the tree is walked depth first; at every boundary the material's children are
pushed smallest weight first, so the heaviest child is followed next. The stack therefore
never holds more than ``MAX_CHILDREN - 1`` waiting siblings per level: its capacity bounds the
memory of a sample whatever the scene, and the first chain followed (always the heaviest
child) is the sample's *dominant path*, whose object sequence is the sample's signature (the
sampler compares neighbours' signatures to find edges). A branch ends when it escapes (adds
``weight x environment``), after ``max_depth`` boundaries, or when its largest channel weight
falls below ``min_weight``; cut branches are closed with the environment along their direction
(exact in a uniform environment without absorption, so a white furnace stays 1), and a sample
that has visited ``max_nodes`` boundaries closes all it still holds: time and memory per
sample are bounded. Energy is never created: reflectance + transmittance = 1, absorption <= 1.

With ``rr_weight > 0`` (the adaptive rounds' extra samples of noisy pixels, whose error is
their sample positions' scatter anyway) a branch lighter than ``rr_weight`` survives Russian
roulette with probability ``weight / rr_weight`` and is then weighted up to it: unbiased, and
the many faint branches of a deep tree in absorbing glass are not all followed. Only branches
into glass or liquid play: a branch into air costs one segment and is often the brightest part
of the pixel (the key light in the outer surface's 4 % reflection), and its roulette only added
scatter (the window's sample: 0.197 -> 0.184 display levels at convergence in the same time). The draw comes
from the branch's own seed, so it is deterministic. ``rr_weight = 0`` traces the whole tree.
(Following one Fresnel branch per boundary instead, as a path tracer does, was measured: a
sample costs half, but scatters four times as much on public_1, so it loses.)

Counters (``counters[C_*]``, per worker): intersection queries, leaks (a ray inside glass or
liquid that meets nothing: a geometry bug), medium mismatches (a hit whose incident side is
not the ray's medium), depth cuts, weight cuts, node-budget closures, boundaries, branches
ended by Russian roulette.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .intersect import O_MAT, nearest_hit
from .jit import INLINE, JIT
from .labels import finish_radiance
from .materials import (BACKDROP, GROUND, K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, M_KIND, MG_ALBEDO,
                        PLASTIC)
from .records import Ray
from .sampling import branch_seed, env_lookup, mix64, uniform01
from .surface import interaction, scatter

C_QUERIES, C_LEAKS, C_MISMATCH, C_CUT_DEPTH, C_CUT_WEIGHT, C_BUDGET, C_NODES, C_ROULETTE = range(8)
N_COUNTERS = 8
AIR = 0
# stack columns
K_OX, K_OY, K_OZ, K_DX, K_DY, K_DZ, K_WR, K_WG, K_WB = range(9)
KI_MEDIUM, KI_DEPTH, KI_LAST, KI_SIDE = range(4)


@njit(**JIT)
def _record(rec, ox, oy, oz, dx, dy, dz, medium, last, side):
    """Keep a copy of one intersection query in the recorder ``rec`` (benchmarks time Embree on
    the same rays): origin and direction, and with 9 columns the query's medium, the object it
    leaves and its side (what the analytic search is asked with)."""
    rec_rays, rec_n = rec.rays, rec.n_rays
    i = rec_n[0]
    if i < rec_rays.shape[0]:
        rec_rays[i, 0], rec_rays[i, 1], rec_rays[i, 2] = ox, oy, oz
        rec_rays[i, 3], rec_rays[i, 4], rec_rays[i, 5] = dx, dy, dz
        if rec_rays.shape[1] >= 9:
            rec_rays[i, 6], rec_rays[i, 7], rec_rays[i, 8] = medium, last, side
        rec_n[0] = i + 1


@njit(**INLINE)
def _close(tex, scale, rot, lr, lg, lb, wr, wg, wb, dx, dy, dz):
    """Radiance ``l`` plus what a branch of weight ``w`` brings back from the environment
    along ``d`` (how every branch that stops ends)."""
    er, eg, eb = env_lookup(tex, scale, rot, dx, dy, dz)
    return lr + wr * er, lg + wg * eg, lb + wb * eb


@njit(**INLINE)
def _guide(sc, it, s, kids):
    """The denoiser's guide at a node of the dominant path (module rule): ``(done, albedo r, g,
    b, reflected share)``. A label's texel, the ground, the backdrop and a plastic closure end
    the guide with their albedo, a frosted or rough surface with white; smooth glass and metal
    pass it on (specular), giving the share of their children's weight that is reflected."""
    if s.gr >= 0.0:
        return True, s.gr, s.gg, s.gb, 0.0
    kind = sc.mat_i[it.mat, M_KIND]
    if kind == GROUND or kind == BACKDROP or kind == PLASTIC:
        a = sc.mat_f[it.mat]
        return True, a[MG_ALBEDO], a[MG_ALBEDO + 1], a[MG_ALBEDO + 2], 0.0
    if it.rough > 0.0:
        return True, 1.0, 1.0, 1.0, 0.0
    total = reflected = 0.0
    for c in range(s.nk):
        w = kids[c, KW_R] + kids[c, KW_G] + kids[c, KW_B]
        total += w
        if kids[c, K_SIDE] < 0.5:
            reflected += w
    return False, 1.0, 1.0, 1.0, (reflected / total if total > 0.0 else 0.0)


@njit(**JIT)
def trace_sample(tables, ray, seed, cut, work, rec, leaving=-1, sidx=-1, pseed=0):
    """Radiance ``(r, g, b)`` of one camera ray and its record.

    Parameters
    ----------
    tables : records.Tables
        What the tree reads: the render objects, media (``media[m] = (ior, sigma_r, sigma_g,
        sigma_b)``, absorption in 1/mm) and materials (:mod:`engine.tracer.tables.render_objects`);
        the labels (empty tables without labels) and the finishes (reliefs, frosting, closures),
        which the surface layer reads (:func:`engine.tracer.kernels.surface.scatter`; the labels
        consulted set their bits, from ``labels.LABEL_BIT0``, in the object mask); the
        environment's ``(scale, rotation rad, factor, ...)`` and texels ``(H, W, 3)`` (half-float
        bit patterns, or float32): radiance is ``scale * factor * texel``.
    ray : records.Ray
        Origin (mm) and unit direction, starting in air.
    seed : uint64 seed of the sample (branches derive theirs from it).
    cut : records.Cutoffs
        Depth, weight, Russian roulette and node budget of the tree (module rule).
    work : records.Work
        The worker's scratch: the stack, the children of a hit, the solvers' space.
    rec : records.Recorder
        What the tree writes besides its radiance: the shallowest depth at which it met each
        material is min-ed into ``rec.depth``, the counters add up in ``rec.counters``, and each
        intersection query is copied into ``rec.rays`` while room lasts.
    leaving : int
        The object the ray starts on, leaving it on the side its direction points to (a probe
        from the ground: :mod:`.sky`); -1 (default) for a ray starting in free air.
    sidx, pseed : the sample's index among its pixel's anti-aliasing samples (-1, the default:
        none) and the pixel's seed: each node's place in the tree is seeded from ``pseed`` and
        the path to it, and rough surfaces draw their lobes from a net over the samples there
        (:func:`~.surface.lobe_uniforms`).

    Returns ``(r, g, b, signature, object mask, guide)``: radiance (finite, >= 0), a hash of
    the dominant path's objects, a bit per object the tree met, and the denoiser's guide
    ``(albedo r, g, b, normal x, y, z)``: the first hit's shading normal facing the ray (zero
    for a ray that meets nothing: relief and cut facets stay crisp), and the albedo of the first
    surface along the dominant path that is not smooth glass or metal (a label's texel, the
    ground, a closure; white where the path leaves through glass into the environment), mixed
    at the first glass hit with white by the share it reflects (:func:`_guide`). The guide
    never touches the radiance.
    """
    sc, lab, tex, env_p = tables.scene, tables.labels, tables.texels, tables.env
    ox, oy, oz, dx, dy, dz = ray
    depth_rec, counters = rec.depth, rec.counters
    media, obj_i = sc.media, sc.geom.obj_i
    stk_f, stk_i, stk_u, kids, order = work.stk_f, work.stk_i, work.stk_u, work.kids, work.order
    max_depth, min_weight, rr_weight, max_nodes = cut
    scale, rot = env_p[0] * env_p[2], env_p[1]  # the map's scale times its texels' factor
    cap = stk_f.shape[0]
    lr = lg = lb = 0.0
    ar = ag = ab = 0.0  # the labels' terms (kernels.labels module rule)
    sig = np.uint64(0x243F6A8885A308D3)
    objmask = np.int64(0)
    dominant = True
    g_open, g_first = True, True  # the guide: still looking; at the first hit
    gr = gg = gb = 1.0
    gnx = gny = gnz = 0.0
    g_refl = 0.0
    stk_f[0, K_OX], stk_f[0, K_OY], stk_f[0, K_OZ] = ox, oy, oz
    stk_f[0, K_DX], stk_f[0, K_DY], stk_f[0, K_DZ] = dx, dy, dz
    stk_f[0, K_WR], stk_f[0, K_WG], stk_f[0, K_WB] = 1.0, 1.0, 1.0
    stk_i[0, KI_MEDIUM], stk_i[0, KI_DEPTH] = AIR, 0
    stk_i[0, KI_LAST], stk_i[0, KI_SIDE] = leaving, (1 if leaving >= 0 else 0)
    stk_u[0, 0] = seed
    stk_u[0, 1] = np.uint64(pseed)
    top = 1
    nodes = 0
    while top > 0:
        top -= 1
        ox, oy, oz = stk_f[top, K_OX], stk_f[top, K_OY], stk_f[top, K_OZ]
        dx, dy, dz = stk_f[top, K_DX], stk_f[top, K_DY], stk_f[top, K_DZ]
        wr, wg, wb = stk_f[top, K_WR], stk_f[top, K_WG], stk_f[top, K_WB]
        medium, depth = stk_i[top, KI_MEDIUM], stk_i[top, KI_DEPTH]
        last, side = stk_i[top, KI_LAST], stk_i[top, KI_SIDE]
        bseed, path = stk_u[top, 0], stk_u[top, 1]
        if nodes >= max_nodes:
            lr, lg, lb = _close(tex, scale, rot, lr, lg, lb, wr, wg, wb, dx, dy, dz)
            counters[C_BUDGET] += 1
            dominant = False
            continue
        nodes += 1
        counters[C_QUERIES] += 1
        if rec.rays.shape[0] > 0:
            _record(rec, ox, oy, oz, dx, dy, dz, medium, last, side)
        seg_ray = Ray(ox, oy, oz, dx, dy, dz)
        hit = nearest_hit(sc.geom, seg_ray, medium, last, side, work.scratch)
        t, k, part, nx, ny, nz = hit
        if k < 0:
            if medium != AIR:
                counters[C_LEAKS] += 1
            lr, lg, lb = _close(tex, scale, rot, lr, lg, lb, wr, wg, wb, dx, dy, dz)
            dominant = False
            continue
        counters[C_NODES] += 1
        if medium != AIR:  # Beer-Lambert over the segment just travelled
            wr *= math.exp(-media[medium, 1] * t)
            wg *= math.exp(-media[medium, 2] * t)
            wb *= math.exp(-media[medium, 3] * t)
        objmask |= np.int64(1) << np.int64(k)
        mat = obj_i[k, O_MAT]
        if depth < depth_rec[mat]:
            depth_rec[mat] = depth
        if dominant:
            sig = mix64(sig ^ np.uint64(k + 1))
        if depth >= max_depth:
            lr, lg, lb = _close(tex, scale, rot, lr, lg, lb, wr, wg, wb, dx, dy, dz)
            counters[C_CUT_DEPTH] += 1
            dominant = False
            continue
        it = interaction(tables, seg_ray, hit, sidx, path)
        px, py, pz, inc, trn = it.px, it.py, it.pz, it.inc, it.trn
        if inc != medium:
            counters[C_MISMATCH] += 1
        s = scatter(tables, it, wr, wg, wb, bseed, kids, work.scratch)
        if dominant and g_open:
            if g_first:
                flip = -1.0 if it.sx * dx + it.sy * dy + it.sz * dz > 0.0 else 1.0
                gnx, gny, gnz = flip * it.sx, flip * it.sy, flip * it.sz
            done, gr, gg, gb, refl = _guide(sc, it, s, kids)
            if g_first and not done:
                g_refl = refl
            g_open, g_first = not done, False
        objmask |= s.bits
        if s.label_bits != 0:  # a sheet's terms are summed apart, so a relabel can recompute them alone
            ar += wr * s.ar
            ag += wg * s.ag
            ab += wb * s.ab
            if dominant:
                sig = mix64(sig ^ np.uint64(0x5BD1E995 + s.label_bits))
        lr += wr * s.er
        lg += wg * s.eg
        lb += wb * s.eb
        nk = s.nk
        # push children lightest first, so the heaviest is followed next (insertion by weight)
        for a_ in range(nk):
            order[a_] = a_
        for a_ in range(1, nk):
            v = order[a_]
            wv = kids[v, KW_R] + kids[v, KW_G] + kids[v, KW_B]
            b_ = a_ - 1
            while b_ >= 0 and kids[order[b_], KW_R] + kids[order[b_], KW_G] + kids[order[b_], KW_B] > wv:
                order[b_ + 1] = order[b_]
                b_ -= 1
            order[b_ + 1] = v
        for q in range(nk):
            c = order[q]
            cr, cg, cb = wr * kids[c, KW_R], wg * kids[c, KW_G], wb * kids[c, KW_B]
            cdx, cdy, cdz = kids[c, KD_X], kids[c, KD_Y], kids[c, KD_Z]
            wmax = max(cr, max(cg, cb))
            into = trn if kids[c, K_SIDE] > 0.5 else inc
            if wmax < rr_weight and into != AIR:  # Russian roulette: survive with probability w / rr_weight
                q_s = wmax / rr_weight
                if uniform01(branch_seed(bseed, c), 0) >= q_s:
                    counters[C_ROULETTE] += 1
                    if q == nk - 1:
                        dominant = False
                    continue
                cr, cg, cb = cr / q_s, cg / q_s, cb / q_s
                wmax = rr_weight
            if wmax < min_weight or top >= cap:
                lr, lg, lb = _close(tex, scale, rot, lr, lg, lb, cr, cg, cb, cdx, cdy, cdz)
                counters[C_CUT_WEIGHT] += 1
                if q == nk - 1:
                    dominant = False
                continue
            stk_f[top, K_OX], stk_f[top, K_OY], stk_f[top, K_OZ] = px, py, pz
            stk_f[top, K_DX], stk_f[top, K_DY], stk_f[top, K_DZ] = cdx, cdy, cdz
            stk_f[top, K_WR], stk_f[top, K_WG], stk_f[top, K_WB] = cr, cg, cb
            stk_i[top, KI_MEDIUM] = into
            stk_i[top, KI_DEPTH] = depth + 1
            stk_i[top, KI_LAST] = k
            stk_i[top, KI_SIDE] = 1 if cdx * nx + cdy * ny + cdz * nz >= 0.0 else -1
            stk_u[top, 0] = branch_seed(bseed, c)
            stk_u[top, 1] = path * np.uint64(0x9E3779B97F4A7C15) + np.uint64(c + 1)  # (hashed where used)
            top += 1
    if lab.hit_f.shape[0] > 0:
        rest = lab.rest
        rest[0], rest[1], rest[2] = lr, lg, lb
    r, g, b = finish_radiance(lr, lg, lb, ar, ag, ab)
    keep = 1.0 - g_refl  # (the first glass hit's reflection shows the environment: white)
    guide = (g_refl + keep * gr, g_refl + keep * gg, g_refl + keep * gb, gnx, gny, gnz)
    return r, g, b, sig, objmask, guide
