"""Light traced from the design's lights through the glass onto the ground: its caustic.

Design rule: a distant light's light reaches the ground either straight (a shadow ray that
meets nothing: :func:`~.ground.light_on_ground`) or after at least one surface of the bottle or its
closure; the second part is what these photons carry. A light is a disc in the sky of
apparent diameter given by its row's ``L_COS`` (:mod:`.ground`; 1: a point at infinity); each photon leaves a rectangle
across the light's beam that covers the bottle's bounding cylinder, along a direction drawn
in the disc, and follows one branch per boundary through the same surface layer the camera's
trees use (:func:`~engine.tracer.kernels.surface.scatter`: Fresnel, labels by their alpha,
the closure's metal), chosen with probability proportional to its weight, so its power is the
light's (times absorption and the colours of what it met), unless something stands between the
light and its start (a backdrop sweep: the beam starts outside the bottle). Where it lands on the ground from
above, having met something, its landing point and power are written out; the table builder
(:mod:`engine.tracer.tables.caustics`) splats them into an irradiance grid that the ground
looks up (:func:`~.ground.caustic_irradiance`). Photon ``i`` draws from ``mix64(seed ^ i)``: the grid is
the same for any split of the photons into chunks and threads.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .intersect import O_KIND, O_MAT, SWEEP, nearest_hit
from .ground import in_disc, light_frame
from .jit import JIT
from .materials import BACKDROP, GROUND, K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, M_KIND
from .records import Ray
from .sampling import branch_seed, mix64, uniform01
from .surface import interaction, scatter

AIR = 0
#: Columns of a photon's record: where it landed after meeting the bottle (mm) and its power
#: (r, g, b; zero where it did not), 1 if that point lies in the light's shadow (its own
#: direction's), and where it would have landed going straight (mm) and 1 if that point is in
#: the shadow: what the grid's shadow fraction is estimated from (:mod:`engine.tracer.tables.caustics`).
P_X, P_Y, P_R, P_G, P_B, P_IN, P_SX, P_SY, P_SHADOW = range(9)
P_COLS = 9
#: Streams of a photon's seed: its start on the beam (0, 1), in the light's disc (2, 3), its
#: choice of branch (4; each boundary draws from a new seed, :func:`branch_seed`).
_START, _DISC, _CHOICE = 0, 2, 4


@njit(**JIT)
def trace_photons(tables, light, beam, ground_z, first, count, seed, max_depth, work, out):
    """Trace photons ``first .. first + count - 1`` of ``light`` (module rule) onto the ground at
    height ``ground_z`` (mm) into rows ``0 .. count - 1`` of ``out`` (``P_*`` columns; power per
    unit of the light's irradiance times the beam's area per photon, which the caller applies).

    ``beam`` = ``(cx, cy, cz, u_half, v_half)``: the centre (mm) of the emitting rectangle,
    outside everything, and its half sides (mm) along the light's frame
    (:func:`~.ground.light_frame`); ``tables`` what the photons meet (a :class:`~.records.Tables`).
    """
    sc = tables.scene
    obj_i, media, mat_i = sc.geom.obj_i, sc.media, sc.mat_i
    kids, scratch = work.kids, work.scratch
    ux, uy, uz, vx, vy, vz = light_frame(light[0], light[1], light[2])
    swept = False  # a backdrop sweep may stand between the light and the beam (nothing else can)
    for k in range(obj_i.shape[0]):
        swept = swept or obj_i[k, O_KIND] == SWEEP
    for j in range(count):
        for c in range(P_COLS):
            out[j, c] = 0.0
        s = mix64(np.uint64(seed) ^ np.uint64(first + j))
        a = (2.0 * uniform01(s, _START) - 1.0) * beam[3]
        b = (2.0 * uniform01(s, _START + 1) - 1.0) * beam[4]
        ox, oy, oz = beam[0] + a * ux + b * vx, beam[1] + a * uy + b * vy, beam[2] + a * uz + b * vz
        lx, ly, lz = in_disc(light, uniform01(s, _DISC), uniform01(s, _DISC + 1))
        dx, dy, dz = -lx, -ly, -lz
        wr = wg = wb = 1.0
        medium, last, side = AIR, -1, 0
        t_straight = (ground_z - oz) / dz
        out[j, P_SX], out[j, P_SY] = ox + t_straight * dx, oy + t_straight * dy
        if swept and nearest_hit(sc.geom, Ray(ox, oy, oz, lx, ly, lz), AIR, -1, 0, scratch)[1] >= 0:
            out[j, P_SHADOW] = 1.0  # the beam itself is in a shadow (a backdrop sweep's): no light
            continue
        for depth in range(max_depth):
            ray = Ray(ox, oy, oz, dx, dy, dz)
            hit = nearest_hit(sc.geom, ray, medium, last, side, scratch)
            t, k, part, nx, ny, nz = hit
            if k < 0:
                break
            if depth == 0 and mat_i[obj_i[k, O_MAT], M_KIND] != GROUND:
                out[j, P_SHADOW] = 1.0
            if medium != AIR:
                wr *= math.exp(-media[medium, 1] * t)
                wg *= math.exp(-media[medium, 2] * t)
                wb *= math.exp(-media[medium, 3] * t)
            px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
            mat = obj_i[k, O_MAT]
            if mat_i[mat, M_KIND] == GROUND:
                if depth > 0 and dz < 0.0:  # light that met the bottle (straight light is the shadow ray's)
                    out[j, P_X], out[j, P_Y] = px, py
                    out[j, P_R], out[j, P_G], out[j, P_B] = wr, wg, wb
                    if nearest_hit(sc.geom, Ray(px, py, pz, lx, ly, lz), AIR, k, 1, scratch)[1] >= 0:
                        out[j, P_IN] = 1.0
                break
            if mat_i[mat, M_KIND] == BACKDROP:  # the sweep is lit straight only (:mod:`.backdrop`)
                break
            it = interaction(tables, ray, hit, -1, np.uint64(0))
            inc, trn = it.inc, it.trn
            sc_ = scatter(tables, it, wr, wg, wb, s, kids, scratch)
            total = 0.0
            for c in range(sc_.nk):
                total += kids[c, KW_R] + kids[c, KW_G] + kids[c, KW_B]
            if not total > 0.0:
                break  # absorbed (a diffuse part's light is not followed: it lights the ground faintly)
            # one child, chosen by weight; dividing by its probability keeps the power unbiased,
            # and the chance of none (the absorbed share) ends the photon
            u = uniform01(s, _CHOICE) * max(total, 3.0)
            c = 0
            acc = kids[0, KW_R] + kids[0, KW_G] + kids[0, KW_B]
            while acc <= u and c < sc_.nk - 1:
                c += 1
                acc += kids[c, KW_R] + kids[c, KW_G] + kids[c, KW_B]
            if acc <= u:
                break
            p_c = (kids[c, KW_R] + kids[c, KW_G] + kids[c, KW_B]) / max(total, 3.0)
            wr, wg, wb = wr * kids[c, KW_R] / p_c, wg * kids[c, KW_G] / p_c, wb * kids[c, KW_B] / p_c
            dx, dy, dz = kids[c, KD_X], kids[c, KD_Y], kids[c, KD_Z]
            medium = trn if kids[c, K_SIDE] > 0.5 else inc
            last, side = k, (1 if dx * nx + dy * ny + dz * nz >= 0.0 else -1)
            ox, oy, oz = px, py, pz
            s = branch_seed(s, c)
