"""The ground's sky grid: the environment's light on the ground near the bottle, once per design.

Design rule: a diffuse ground's light from the environment is an integral over the sky that the
ground's kernel estimates with a control variate and one probe through the bottle per hit
(:func:`engine.tracer.kernels.ground.ground`). Every pixel of ground near the bottle then needs
many samples to average its probes, and every ground hit seen through or in the glass does too.
That light does not depend on the camera, so it is estimated once per design on a polar grid
about the bottle's axis (:func:`sky_row`): rings :data:`CELLS_PER_RADIUS` to the bottle's
bounding radius, each with sectors about as wide as it is deep (as wide at that radius), then
rings growing geometrically (each
``1 + 1 / CELLS_PER_RADIUS`` times as far out: cells stay as wide as they are far from the
bottle over the distance, where the shadow blurs in proportion) out to :data:`REACH` radii or
the stage's edge. Each cell holds the control variate's estimate at its centre from
``PROBES_SIDE^2`` stratified probes (:func:`engine.tracer.kernels.sky.sky_cells`; the outer
rings, whose share of the sky is small, ``OUTER_PROBES_SIDE^2``), and more batches of as many
where its standard error is still above :data:`SE_TOL` of the open sky; the ground reads it
bilinearly (:func:`engine.tracer.kernels.ground.sky_irradiance`). Measured on the Bordeaux on
its table: the ground then converges with the bottle's own samples (see
``benchmarks/RESULTS.md``). Beyond the grid the per-hit probe remains. Cells are traced in
chunks, each cell from its own seeds: the grid is bit for bit the same for any number of
threads. Time and memory are bounded by :data:`MAX_CELLS` and the probes per cell. Units mm.
"""
from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..kernels import intersect as K
from ..kernels.intersect import O_MAT
from ..kernels.ground import S_DR, S_GROW, S_NIN, S_NRING, S_NSEC, S_R1, S_RMAX, SKY_COLS, ring_sectors, sky_ring
from ..kernels.materials import MG_ALBEDO, MG_BOUND_R, MG_SHADOW, MG_WIDE
from ..kernels.records import Cutoffs, Recorder
from ..kernels.integrator import N_COUNTERS
from ..kernels.sky import Y_COLS, Y_CONTROLLED, Y_SHARE, Y_SQ, sky_cells
from ..kernels.tile import make_work

#: Rings across the bottle's bounding radius, and sectors per radian at it (a 40 mm bound: 2.5 mm).
CELLS_PER_RADIUS = 16
#: The grid reaches this many bounding radii from the axis (or the stage's edge if nearer).
REACH = 64.0
#: Probes per cell: a side of the stratified square, within ``INNER_REACH`` radii and beyond.
PROBES_SIDE = 8
OUTER_PROBES_SIDE = 4
INNER_REACH = 6.0
#: Cells at most (rings x sectors).
MAX_CELLS = 1 << 15
#: A cell's estimate gets more batches of probes while its standard error times the ground's
#: albedo (the error of the light the ground sends back) is above this share of the open sky's
#: irradiance, up to ``MAX_BATCHES`` batches in all; cells per kernel call.
SE_TOL = 0.015
MAX_BATCHES = 4
#: Batches more where a backdrop stands on the ground (its probes span the whole sky, and the
#: sweep they meet is itself sampled).
WIDE_BATCHES = 4
CHUNK = 32
#: A probe's branches lighter than this play Russian roulette (as the render's adaptive rounds'
#: do): a cell averages 16 to 256 probes, so the noise roulette adds is small beside the saving.
#: Measured on ``bordeaux_table`` (the grid's time; display levels RMS of a centres-only render
#: at 715 x 953 against one with a grid of 8 x the probes and no roulette): 0 -> 2.47 s, 0.251;
#: 0.05 -> 1.40 s, 0.253; 0.2 -> 1.07 s, 0.255; 0.5 -> 0.96 s, 0.261; 1.0 -> 0.81 s, 0.286; with
#: its backdrop (sky and sweep grids) 0 -> 6.80 s, 0.667; 0.2 -> 3.93 s, 0.668.
ROULETTE = 0.2
#: The ray tree's node budget per probe (as a render's).
MAX_NODES = 4096
_SEED = 0x5EED_5C1E


def sky_row(bound_r: float, reach_mm: float) -> np.ndarray:
    """The sky grid's row (``S_*`` columns of :mod:`engine.tracer.kernels.ground`) for a bottle of
    bounding radius ``bound_r`` (mm) out to ``reach_mm`` from the axis (module rule)."""
    row = np.zeros(SKY_COLS)
    dr = bound_r / CELLS_PER_RADIUS
    grow = 1.0 / CELLS_PER_RADIUS
    n_in = CELLS_PER_RADIUS
    reach = max(reach_mm, bound_r * (1.0 + grow))
    n_out = max(1, math.ceil(math.log(reach / bound_r) / math.log1p(grow)))
    n_sec = math.ceil(2.0 * math.pi * CELLS_PER_RADIUS)
    n_out = max(1, min(n_out, MAX_CELLS // n_sec - n_in))
    row[S_DR], row[S_R1], row[S_GROW] = dr, bound_r, grow
    row[S_NIN], row[S_NRING], row[S_NSEC] = n_in, n_in + n_out, n_sec
    row[S_RMAX] = bound_r * (1.0 + grow) ** n_out
    return row


def cell_centres(row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(centres, rings)``: the centre ``(x, y)`` (mm) of every cell of grid ``row`` in the
    kernels' order (:func:`~engine.tracer.kernels.ground.ring_cells`: ring by ring, sectors by
    rising angle), at the ring coordinate ``i + 0.5`` and sector angle ``2 pi (j + 0.5) /
    sectors``, and each cell's ring."""
    n_in, n_ring = int(row[S_NIN]), int(row[S_NRING])
    centres, rings = [], []
    for i in range(n_ring):
        f = i + 0.5
        rho = f * row[S_DR] if f <= n_in else row[S_R1] * (1.0 + row[S_GROW]) ** (f - n_in)
        ns = ring_sectors(row, i)
        phi = (np.arange(ns) + 0.5) * (2.0 * math.pi / ns)
        centres.append(np.column_stack([rho * np.cos(phi), rho * np.sin(phi)]))
        rings.append(np.full(ns, i))
    return np.concatenate(centres), np.concatenate(rings)


#: Images of fewer pixels probe per hit instead (:func:`sky_grid_pays`).
GRID_MIN_PIXELS = 100_000


def sky_grid_pays(width: int, height: int) -> bool:
    """Whether an image of ``width x height`` pixels is worth a sky grid. The grid costs about
    the same for any image (some 8,000 cells of 64 to 256 probes); probing per hit costs about
    8 to 16 probes per pixel of ground near the bottle. Measured: on the window's 715 x 953
    preview of the Bordeaux on its table the grid converges in 10.9 s against 47.9 s; on the
    256 x 256 SPEC ground scene the per-hit probe reaches Mitsuba's 1024-spp error about twice
    as fast (the grid's build is most of such a render). Below :data:`GRID_MIN_PIXELS` (the
    oracle's images, the window's quarter-size live pass during a drag, thumbnails) the ground
    probes per hit."""
    return int(width) * int(height) >= GRID_MIN_PIXELS


def sweep_object(scene) -> int | None:
    """The render object of ``scene`` that is the backdrop sweep, or ``None``."""
    k = np.nonzero(scene.geom.obj_i[:, K.O_KIND] == K.SWEEP)[0]
    return int(k[0]) if len(k) else None


def under_sweep_to_edge(scene, cells: np.ndarray) -> np.ndarray:
    """``cells`` ``(n, 2)`` (mm) with the centres that lie under a backdrop sweep (beyond where
    its curve leaves the floor, hidden from every camera) moved back onto that line: their
    probes would see only the sweep's dark underside, and bilinear reads would bleed that
    darkness onto the visible floor beside the line."""
    k = sweep_object(scene)
    if k is None:
        return cells
    f = scene.geom.obj_f[k]
    facing = np.array([f[K.F_COS], f[K.F_SIN]])
    edge = f[K.F_SW_START] * (1.0 - 1e-6)
    v = cells @ facing
    return cells - np.maximum(v - edge, 0.0)[:, None] * facing


class GridCancelled(Exception):
    """A grid's build was stopped: the render that asked for it was cancelled."""


def probe_cells(run, side: np.ndarray, batches: int, tolerance: float, threads: int | None = None,
                cancelled=None) -> tuple[np.ndarray, np.ndarray]:
    """``(sums, probes)``: a grid's cells probed in batches (``Y_*`` sums and probes per cell).
    ``run(idx, n_side, batch, out)`` traces batch ``batch`` of ``n_side^2`` probes for cells
    ``idx`` into ``out``; cell ``i`` takes ``side[i]`` per side. After each batch, the cells whose
    estimate's standard error is above ``tolerance`` get another, up to ``batches`` in all.
    Chunks of :data:`CHUNK` cells run on ``threads``; each cell's batches add in batch order, so
    the sums are the same for any split. Raises :class:`GridCancelled` once ``cancelled()``."""
    threads = max(1, threads or (os.cpu_count() or 1))
    sums = np.zeros((len(side), Y_COLS))
    probes = np.zeros(len(side))

    def job(idx, n_side, batch):
        out = np.zeros((len(idx), Y_COLS))
        if cancelled is None or not cancelled():
            run(idx, n_side, batch, out)
        return idx, n_side, out

    todo = np.arange(len(side))
    with ThreadPoolExecutor(threads) as pool:
        for batch in range(batches):
            jobs = [(todo[side[todo] == n][k:k + CHUNK], n, batch) for n in np.unique(side)
                    for k in range(0, int((side[todo] == n).sum()), CHUNK)]
            for idx, n_side, out in pool.map(lambda a: job(*a), jobs):
                sums[idx, :Y_SQ + 1] += out[:, :Y_SQ + 1]
                sums[idx, Y_SHARE:] = out[:, Y_SHARE:]
                probes[idx] += n_side * n_side
            if cancelled is not None and cancelled():
                raise GridCancelled("a grid's render was cancelled")
            n = np.maximum(probes, 1.0)
            lum = sums[:, :3].mean(axis=1) / n
            se = sums[:, Y_SHARE] * np.sqrt(np.maximum(sums[:, Y_SQ] / n - lum ** 2, 0.0) / n)
            todo = np.nonzero(se > tolerance)[0]
            if not len(todo):
                break
    return sums, probes


def quiet_recorder(scene) -> Recorder:
    """A probe batch's :class:`~engine.tracer.kernels.records.Recorder`: the depths and counters
    its trees write (nobody reads them) and no rays kept."""
    return Recorder(np.full(scene.mat_i.shape[0], 255, np.int64), np.zeros(N_COUNTERS, np.int64),
                    np.zeros((0, 6), np.float32), np.zeros(1, np.int64))


def sky_grid(tables, ground: int, z0: float, reach_mm: float, max_depth: int, min_weight: float,
             threads: int | None = None, cancelled=None) -> tuple[np.ndarray, np.ndarray]:
    """``(sky, row)``: the sky grid of the ground object ``ground`` at height ``z0`` (mm) of
    ``tables`` (a :class:`~engine.tracer.kernels.records.Tables`) out to ``reach_mm`` (module
    rule): ``sky`` ``(cells, 3)`` irradiance over pi, traced with the render's cut-offs
    ``max_depth`` and ``min_weight`` and :data:`ROULETTE`. Its finishes
    must carry no sky grid (its probes' own ground hits probe). A cell whose estimate's standard
    error times the ground's albedo is above :data:`SE_TOL` of the open sky's irradiance gets
    another batch of probes, up to :data:`MAX_BATCHES`. Raises :class:`GridCancelled` once ``cancelled()`` is true (checked
    between chunks of cells)."""
    scene, env_p = tables.scene, tables.env
    mat = int(scene.geom.obj_i[ground, O_MAT])
    bound_r = float(scene.mat_f[mat, MG_BOUND_R])
    row = sky_row(bound_r, min(reach_mm, REACH * bound_r))
    cells, rings = cell_centres(row)
    cells = np.ascontiguousarray(under_sweep_to_edge(scene, cells))
    inner = int(math.ceil(sky_ring(row, INNER_REACH * bound_r)))
    wide = scene.mat_f[mat, MG_WIDE] > 0.5  # a backdrop: no cell's light is the open sky's
    side = np.where((rings < inner) | wide, PROBES_SIDE, OUTER_PROBES_SIDE)
    # the error that matters is the ground's: albedo x the cell's (a shadow catcher's is ~1)
    albedo = 1.0 if scene.mat_f[mat, MG_SHADOW] > 0.5 else max(float(scene.mat_f[mat, MG_ALBEDO:MG_ALBEDO + 3].max()),
                                                                 1e-3)
    cut = Cutoffs(int(max_depth), float(min_weight), ROULETTE, MAX_NODES)

    def run(idx, n_side, batch, out):
        sky_cells(tables, ground, float(z0), cells, np.ascontiguousarray(idx, np.int64), int(n_side), int(batch),
                  _SEED, cut, make_work(int(max_depth)), quiet_recorder(scene), out)

    sums, probes = probe_cells(run, side, MAX_BATCHES + (WIDE_BATCHES if wide else 0),
                               SE_TOL * float(np.mean(env_p[3:6])) / albedo, threads, cancelled)
    mean = sums[:, :3] / probes[:, None]
    controlled = sums[:, Y_CONTROLLED:Y_CONTROLLED + 1] > 0.5
    sky = np.where(controlled, np.asarray(env_p[3:6]) + sums[:, Y_SHARE:Y_SHARE + 1] * mean, mean)
    return np.ascontiguousarray(sky), row
