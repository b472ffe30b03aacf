"""Threads drawn as true geometry: the outer wall's straight neck piece becomes a HELIX row.

Design rule: a thread tile that :func:`engine.appearance.bands.thread_drawings` draws as
true geometry changes one row of the scene's segment table, nothing else: the outer wall's
line row under its band turns into a ``HELIX`` row (:mod:`engine.tracer.kernels.helix`) with
the tile's own relief parameters (the very row :func:`~engine.tracer.tables.bump_rows.tile_params`
gives the bump), its bounds and the outer wall's radius bound widened by the ridge. The outer
wall stays one object with its media and material, its rows keep their numbers (labels, caps
and finishes index them unchanged), and the bump rows of that tile are left out of the finish
tuple (:func:`~engine.tracer.tables.bump_rows.bump_tables`): the thread is never counted twice.
The geometry cache (by shape and fill) is untouched; this runs per render context on a copy.
Units mm.
"""
from __future__ import annotations

import numpy as np

from ..appearance.bands import band_coordinates, thread_drawings
from .tables.bump_rows import tile_params
from ..appearance.closures import finish_of
from .kernels.records import Geometry, Scene
from .kernels import bumps as B
from .kernels import intersect as K
from .kernels import profile as R
from .tables.render_objects import OUTER_WALL

#: Kernel columns of a HELIX row filled from a thread tile's relief row.
_FROM_RELIEF = ((R.H_REF, B.P_RADIUS), (R.H_STARTS, B.P_REPEAT), (R.H_PHASE, B.P_PHASE),
                (R.H_DEPTH, B.P_DEPTH), (R.H_PITCH, B.P_PITCH), (R.H_TURNS, B.P_A),
                (R.H_FLANK_LO, B.P_B), (R.H_FLANK_HI, B.P_C), (R.H_RUNOUT, B.P_D),
                (R.H_START, B.P_START))
#: The ridge's bounds are widened by this much (mm), like every segment box.
_PAD = 1e-6


def _wall_row(seg, obj_i, z0: float, z1: float) -> int:
    """The outer wall's line row holding the heights ``z0..z1`` (mm)."""
    first, count = obj_i[OUTER_WALL, K.O_FIRST], obj_i[OUTER_WALL, K.O_COUNT]
    for j in range(first, first + count):
        row = seg[j]
        if (row[R.S_KIND] == R.LINE and row[R.S_Z1] > row[R.S_Z0] and row[R.S_Z0] <= z0 + 1e-9
                and row[R.S_Z1] >= z1 - 1e-9):
            return j
    raise ValueError(f"no straight piece of the outer wall holds z {z0:g}..{z1:g} mm")


def helix_row(row: np.ndarray, relief: np.ndarray, z0: float, z1: float) -> np.ndarray:
    """The HELIX row of line row ``row`` raised by the thread of relief row ``relief`` (a
    :mod:`~engine.tracer.kernels.bumps` THREAD row) on the band of heights ``z0..z1``."""
    out = row.copy()
    out[R.S_KIND] = R.HELIX
    for col, src in _FROM_RELIEF:
        out[col] = relief[src]
    out[R.H_Z0], out[R.H_Z1] = z0, z1
    depth = relief[B.P_DEPTH]
    out[R.S_RMIN] = min(row[R.S_RMIN], min(row[R.S_R0], row[R.S_R1]) + min(depth, 0.0) - _PAD)
    out[R.S_RMAX] = max(row[R.S_RMAX], max(row[R.S_R0], row[R.S_R1]) + max(depth, 0.0) + _PAD)
    return out


def scene_with_threads(scene: Scene, design) -> Scene:
    """The kernels' scene (:class:`~engine.tracer.kernels.records.Scene`) with every true-geometry thread of ``design`` raised on the
    outer wall (module doc); ``scene`` itself when there is none."""
    drawings = [(t, d) for t, d in zip(design.bumps, thread_drawings(design)) if d is not None and d.mode == "true"]
    if not drawings:
        return scene
    (seg, tab, slab_f, slab_i, obj_i, obj_f, plan), media, mat_i, mat_f = scene
    seg, obj_f = seg.copy(), obj_f.copy()
    neck = 2.0 * finish_of(design).r_neck
    for tile, drawing in drawings:
        v0, v1, radius = band_coordinates(design, tile.z0, tile.z1)
        _, relief = tile_params(tile, v0, v1, radius, neck_diameter=neck)
        j = _wall_row(seg, obj_i, drawing.z0, drawing.z1)
        seg[j] = helix_row(seg[j], relief, drawing.z0, drawing.z1)
        obj_f[OUTER_WALL, K.F_RMAX] = max(obj_f[OUTER_WALL, K.F_RMAX], seg[j, R.S_RMAX])
    return Scene(Geometry(np.ascontiguousarray(seg), tab, slab_f, slab_i, obj_i, np.ascontiguousarray(obj_f), plan),
                 media, mat_i, mat_f)
