"""The ground's caustic grids: the design lights' light that came through the bottle.

Design rule: for each design light above the horizon, photons leave a rectangle across its beam
that covers the bottle's bounding cylinder (:func:`beam_of`) and are traced through the scene
(:func:`engine.tracer.kernels.caustics.trace_photons`); those that land on the ground after
meeting the bottle are splatted bilinearly into a grid over the cylinder's shadow and a margin
(:func:`grid_of`), whose cells hold irradiance over pi (what a white diffuse ground sends back
per unit albedo), apart for photons that land in the light's shadow and in the open, with
the share of each cell's ground that lies in the shadow (from where the same photons would
have landed going straight). The ground divides by that share
(:func:`engine.tracer.kernels.ground.caustic_irradiance`): a density estimate blurs across the
shadow's edge, and a shadow ray's sharp edge beside a blurred caustic would draw a bright or
dark line one cell wide; the division undoes the blur where light passes straight (a glass of
index 1 then casts no shadow at all, to the photons' noise: tested). The cells are sized from the bottle's radius (:data:`CELLS_PER_RADIUS`) and
the photons from the cells the beam's shadow covers (:data:`PHOTONS_PER_CELL`), both bounded
(:data:`MAX_CELLS`, :data:`MAX_PHOTONS`): memory and time do not depend on anything but the
bottle's proportions and the light's height. The photons are traced in fixed chunks, each from
its own seeds, and summed in chunk order: the grid is bit for bit the same for any number of
threads. Light the grid misses (a reflection thrown farther than the margin) is lost: a few
per cent of the outer surface's 4 % reflection. Units mm.
"""
from __future__ import annotations

import math
import os
from collections import deque
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..kernels.caustics import P_B, P_COLS, P_G, P_IN, P_R, P_SHADOW, P_SX, P_SY, P_X, P_Y, trace_photons
from ..kernels.ground import (C_IN, C_OUT, C_SHADOW, CAUSTIC_COLS, G_CELL, G_NX, G_NY, G_X0, G_Y0, GRID_COLS, L_DZ,
                             light_frame)
from ..kernels.materials import MG_BOUND_R, MG_BOUND_Z
from ..kernels.tile import make_work

#: Grid cells across the bottle's bounding radius (a 37 mm Bordeaux: 1.5 mm cells).
CELLS_PER_RADIUS = 24
#: Cells along a grid's longer side at most (a light near the horizon casts a long shadow).
MAX_CELLS = 640
#: Photons per cell of the beam's shadow: the grid's noise is about 1 / sqrt(this x 4) there
#: (a bilinear splat spreads each over four cells).
PHOTONS_PER_CELL = 64
#: Photons per light at most and at least.
MAX_PHOTONS = 1 << 22
MIN_PHOTONS = 1 << 14
#: Photons per chunk (one kernel call; chunks are the unit of threads and of determinism).
CHUNK = 1 << 15
#: Boundaries a photon crosses at most.
MAX_BOUNCES = 32
#: Cells between the shadow and the edge of the photons' footprint (a splat and its lookup
#: reach two cells).
FOOTPRINT_MARGIN = 3
#: Lights this close to the horizon (sine of elevation) cast no caustic grid.
MIN_LIGHT_Z = 0.02
_SEED = 0x5EED_CA05


def beam_of(light, bound_r: float, z0: float, z1: float, margin: float) -> tuple[np.ndarray, float]:
    """The emitting rectangle of ``light`` (a light row) for the upright cylinder of radius
    ``bound_r`` between heights ``z0`` and ``z1`` (mm), ``margin`` (mm) wider all round:
    ``(beam, area)``, ``beam`` = ``(centre x, y, z, half side along u, half side along v)``
    (:func:`~engine.tracer.kernels.ground.light_frame`) and its area (mm^2). The margin keeps the
    edge of the photons' footprint away from the shadow: a cell the footprint's edge crosses
    holds fewer photons than its light."""
    lx, ly, lz = float(light[0]), float(light[1]), float(light[2])
    ux, uy, uz, vx, vy, vz = light_frame(lx, ly, lz)
    widen = math.sqrt(max(0.0, 1.0 - float(light[6]) ** 2)) * (2.0 * bound_r + (z1 - z0))  # a disc's penumbra
    widen += margin
    u_half = bound_r + widen
    hv = math.hypot(vx, vy)
    v_lo, v_hi = min(vz * z0, vz * z1) - bound_r * hv - widen, max(vz * z0, vz * z1) + bound_r * hv + widen
    v_mid, v_half = 0.5 * (v_lo + v_hi), 0.5 * (v_hi - v_lo)
    s = 2.0 * (bound_r + abs(z0) + abs(z1)) + 1.0  # beyond everything on the stage
    centre = np.array([v_mid * vx + s * lx, v_mid * vy + s * ly, v_mid * vz + s * lz])
    return np.array([*centre, u_half, v_half]), 4.0 * u_half * v_half


def grid_of(light, bound_r: float, z0: float, z1: float) -> np.ndarray:
    """The grid row (``G_*`` columns) over the shadow of the cylinder (as :func:`beam_of`) that
    ``light`` casts on the plane ``z = z0``, with a margin of one radius."""
    lx, ly, lz = float(light[0]), float(light[1]), float(light[2])
    reach = (z1 - z0) / lz  # how far the cylinder's top is thrown
    xs, ys = (0.0, -reach * lx), (0.0, -reach * ly)
    margin = 2.0 * bound_r
    x0, x1 = min(xs) - margin, max(xs) + margin
    y0, y1 = min(ys) - margin, max(ys) + margin
    cell = max(bound_r / CELLS_PER_RADIUS, max(x1 - x0, y1 - y0) / MAX_CELLS)
    row = np.zeros(GRID_COLS)
    row[G_X0], row[G_Y0], row[G_CELL] = x0, y0, cell
    row[G_NX], row[G_NY] = math.ceil((x1 - x0) / cell), math.ceil((y1 - y0) / cell)
    return row


def photon_count(area: float, lz: float, cell: float) -> int:
    """Photons for a beam of ``area`` (mm^2) whose shadow falls at sine of elevation ``lz`` on
    cells of side ``cell`` (mm), a whole number of chunks within the bounds."""
    n = PHOTONS_PER_CELL * area / (lz * cell * cell)
    n = min(MAX_PHOTONS, max(MIN_PHOTONS, int(n)))
    return -(-n // CHUNK) * CHUNK


def _splat(grid: np.ndarray, row: np.ndarray, x: np.ndarray, y: np.ndarray, weights: np.ndarray) -> None:
    """Add ``weights`` ``(n, channels)`` at ground points ``(x, y)`` (mm) bilinearly to ``grid``
    ``(rows, cols, channels)`` of grid ``row`` (a tent of two cells about each point), in order
    (:func:`numpy.bincount` sums in index order: the same for any chunking)."""
    ny, nx, nc = grid.shape
    fx = (x - row[G_X0]) / row[G_CELL] - 0.5
    fy = (y - row[G_Y0]) / row[G_CELL] - 0.5
    i0, j0 = np.floor(fx).astype(np.int64), np.floor(fy).astype(np.int64)
    tx, ty = fx - i0, fy - j0
    flat = grid.reshape(-1, nc)
    for dj, wy in ((0, 1.0 - ty), (1, ty)):
        for di, wx in ((0, 1.0 - tx), (1, tx)):
            i, j = i0 + di, j0 + dj
            inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
            idx = (j * nx + i)[inside]
            w = (wx * wy)[inside]
            for c in range(nc):
                flat[:, c] += np.bincount(idx, weights=w * weights[inside, c], minlength=nx * ny)


def _add_chunk(sums: np.ndarray, counts: np.ndarray, row: np.ndarray, out: np.ndarray, scale: float) -> None:
    """Splat one chunk of photon records ``out`` (``P_*``): landed power times ``scale`` into the
    in-shadow or open channels of ``sums``, and every photon's straight landing into ``counts``
    (in the shadow, all)."""
    landed = out[(out[:, P_R] + out[:, P_G] + out[:, P_B]) > 0.0]
    if len(landed):
        w = np.zeros((len(landed), C_SHADOW))
        inside = landed[:, P_IN] > 0.5
        power = landed[:, [P_R, P_G, P_B]] * scale
        w[inside, C_IN:C_IN + 3] = power[inside]
        w[~inside, C_OUT:C_OUT + 3] = power[~inside]
        _splat(sums, row, landed[:, P_X], landed[:, P_Y], w)
    _splat(counts, row, out[:, P_SX], out[:, P_SY], np.column_stack([out[:, P_SHADOW], np.ones(len(out))]))


def _in_order(pool, fn, args, in_flight: int):
    """``fn(a)`` for each of ``args`` on ``pool``, yielded in the order of ``args``, with at most
    ``in_flight`` calls queued or running: the caller's work on one result (the splat) overlaps
    the pool's on the next ones, and memory stays bounded. (Waiting for a whole batch before
    splatting it left the workers idle during every splat: 0.30 s of 1.13 s on the tabled
    Bordeaux.)"""
    pending = deque()
    for a in args:
        pending.append(pool.submit(fn, a))
        if len(pending) >= in_flight:
            yield pending.popleft().result()
    while pending:
        yield pending.popleft().result()


def caustic_grids(tables, ground_mat: int, z0: float, threads: int | None = None):
    """``(caustics, grid rows)`` of the lights in the finishes of ``tables`` (a
    :class:`~engine.tracer.kernels.records.Tables`: the scene with its ground) (module rule): ``caustics`` ``(n_lights, rows, cols, CAUSTIC_COLS)`` (:mod:`engine.tracer.kernels.ground`:
    irradiance over pi landing in the shadow and in the open, and the shadow's share of each
    cell), zero-padded to the largest grid; a light below :data:`MIN_LIGHT_Z` gets an empty grid."""
    scene, lights = tables.scene, tables.finishes.lights
    bound_r = float(scene.mat_f[ground_mat, MG_BOUND_R])
    z1 = float(scene.mat_f[ground_mat, MG_BOUND_Z])
    rows, grids = [], []
    threads = max(1, threads or (os.cpu_count() or 1))
    for q in range(lights.shape[0]):
        light = lights[q]
        row = grid_of(light, bound_r, z0, z1) if light[L_DZ] > MIN_LIGHT_Z else np.zeros(GRID_COLS)
        shape = (max(1, int(row[G_NY])), max(1, int(row[G_NX])))
        sums, counts = np.zeros((*shape, C_SHADOW)), np.zeros((*shape, 2))
        if row[G_CELL] > 0.0:
            beam, area = beam_of(light, bound_r, z0, z1, FOOTPRINT_MARGIN * float(row[G_CELL]))
            n = photon_count(area, float(light[L_DZ]), float(row[G_CELL]))
            seed = np.uint64((_SEED * 1000003 + q) & 0xFFFFFFFFFFFFFFFF)

            def chunk(first, beam=beam, light=light, seed=seed):
                out = np.zeros((CHUNK, P_COLS))
                trace_photons(tables, light, beam, z0, first, CHUNK, seed, MAX_BOUNCES, make_work(MAX_BOUNCES), out)
                return out

            # power per photon: the light's irradiance (applied below) x the beam's area per photon;
            # irradiance over pi per cell: / (cell area x pi)
            scale = area / n / (row[G_CELL] ** 2 * math.pi)
            with ThreadPoolExecutor(threads) as pool:
                for out in _in_order(pool, chunk, range(0, n, CHUNK), 2 * threads):
                    _add_chunk(sums, counts, row, out, scale)
            sums[..., C_IN:C_IN + 3] *= light[3:6]
            sums[..., C_OUT:C_OUT + 3] *= light[3:6]
        grid = np.zeros((*shape, CAUSTIC_COLS))
        grid[..., :C_SHADOW] = sums
        # the share of each cell's (tent-weighted) ground in the shadow, from the same photons' straight paths
        np.divide(counts[..., 0], counts[..., 1], out=grid[..., C_SHADOW], where=counts[..., 1] > 0.0)
        rows.append(row)
        grids.append(grid)
    shape = (max(g.shape[0] for g in grids), max(g.shape[1] for g in grids)) if grids else (1, 1)
    caustics = np.zeros((len(grids), *shape, CAUSTIC_COLS))
    for q, g in enumerate(grids):
        caustics[q, :g.shape[0], :g.shape[1]] = g
    return np.ascontiguousarray(caustics), np.ascontiguousarray(np.array(rows).reshape(-1, GRID_COLS))
