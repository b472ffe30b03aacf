"""The backdrop sweep's grid: the environment's light on the sweep, once per design.

Design rule: as the ground's sky grid (:mod:`engine.tracer.tables.sky`), for the sweep. Its
light from the environment does not depend on the camera (the sweep's facing does, and is in
the grid's key), and its sampled estimate per hit (:func:`engine.tracer.kernels.backdrop.backdrop`)
makes every pixel of a large, plain surface need many samples: so it is estimated once on a grid
over the sweep's own coordinates, ``u`` across and ``s`` along its profile from where the curve
leaves the floor, ``asinh``-spaced (:data:`SOFT_SCALE` of the bottle's size: a few millimetres
near the bottle's foot, where its shadow and the curve are, growing in proportion to the
distance beyond), :data:`CELLS` of them, each from batches of stratified probes
(:func:`engine.tracer.kernels.sky.sweep_cells`) until its error is below the sky grid's
tolerance. The sweep grid is built before the sky grid, so the ground's probes that meet the
sweep read it. The lights' light stays per hit (a shadow ray each, exact). Units mm.
"""
from __future__ import annotations

import numpy as np

from ..kernels import intersect as K
from ..kernels.backdrop import W_A, W_COLS, W_NS, W_NU, W_SMAX, W_UMAX, open_sweep, sweep_point
from ..kernels.materials import MG_ALBEDO
from ..kernels.records import Cutoffs
from ..kernels.sky import Y_SQ, sweep_cells
from ..kernels.tile import make_work
from .sky import MAX_BATCHES, MAX_NODES, PROBES_SIDE, ROULETTE, SE_TOL, WIDE_BATCHES, probe_cells, quiet_recorder, sweep_object

#: Cells across the sweep and along its profile.
CELLS = (96, 64)
#: The grid's soft scale as a share of the bottle's size (the sweep's curve radius).
SOFT_SCALE = 0.25
_SEED = 0x5EED_5EE9
#: The sweep's cells' error tolerance, a share of the sky grid's (:data:`~.sky.SE_TOL`): a
#: plain, bright surface filling the frame shows a cell's error as a cloud. Measured on the
#: Bordeaux on its table with a sweep: most cells take all 512 probes either way (about 1 %
#: standard error), the grid builds in about 3.5 s on 2 cores.
SWEEP_TOL = 0.5


def grid_row(obj_f_row: np.ndarray) -> np.ndarray:
    """The sweep grid's row (``W_*`` columns) for the sweep whose ``obj_f`` row is given."""
    row = np.zeros(W_COLS)
    radius = float(obj_f_row[K.F_SW_RADIUS])
    row[W_A] = SOFT_SCALE * radius
    row[W_NU], row[W_NS] = CELLS
    row[W_UMAX] = float(obj_f_row[K.F_SW_HALF])
    row[W_SMAX] = 0.5 * np.pi * radius + float(obj_f_row[K.F_SW_TOP] - obj_f_row[K.F_PZ]) - radius
    return row


def cell_centres(row: np.ndarray) -> np.ndarray:
    """``(cells, 2)``: each cell's ``(u, s)`` centre (mm), row by row along the profile, across
    within a row: the kernels' order (:func:`engine.tracer.kernels.backdrop.sweep_irradiance`)."""
    nu, ns, a = int(row[W_NU]), int(row[W_NS]), row[W_A]
    half = 0.5 * nu
    fu = (np.arange(nu) + 0.5 - half) / half  # -1..1
    u = np.sign(fu) * a * np.sinh(np.abs(fu) * np.arcsinh(row[W_UMAX] / a))
    s = a * np.sinh((np.arange(ns) + 0.5) / ns * np.arcsinh(row[W_SMAX] / a))
    uu, ss = np.meshgrid(u, s)
    return np.ascontiguousarray(np.column_stack([uu.ravel(), ss.ravel()]))


def sweep_grid(tables, max_depth: int, min_weight: float, threads: int | None = None,
               cancelled=None) -> tuple[np.ndarray, np.ndarray]:
    """``(sweep, row)``: the sweep grid of the backdrop sweep of ``tables`` (a
    :class:`~engine.tracer.kernels.records.Tables`; module rule): ``sweep`` ``(cells, 3)``
    irradiance over pi, traced with the render's cut-offs. Its finishes must carry no
    sweep grid. Raises :class:`~engine.tracer.tables.sky.GridCancelled` once ``cancelled()``."""
    scene, env_p = tables.scene, tables.env
    k = sweep_object(scene)
    obj = scene.geom.obj_f[k]
    row = grid_row(obj)
    cells = cell_centres(row)
    albedo = max(float(scene.mat_f[scene.geom.obj_i[k, K.O_MAT], MG_ALBEDO:MG_ALBEDO + 3].max()), 1e-3)
    cut = Cutoffs(int(max_depth), float(min_weight), ROULETTE, MAX_NODES)

    def run(idx, n_side, batch, out):
        sweep_cells(tables, k, cells, np.ascontiguousarray(idx, np.int64), int(n_side), int(batch), _SEED, cut,
                    make_work(int(max_depth)), quiet_recorder(scene), out)

    side = np.full(len(cells), PROBES_SIDE)
    sums, probes = probe_cells(run, side, MAX_BATCHES + WIDE_BATCHES,
                               SWEEP_TOL * SE_TOL * float(np.mean(env_p[3:6])) / albedo, threads, cancelled)
    mean = sums[:, :Y_SQ] / probes[:, None]
    open_ = np.array([open_sweep(env_p, *sweep_point(obj, u, s)[3:]) for u, s in cells])
    return np.ascontiguousarray(open_ + mean), row
