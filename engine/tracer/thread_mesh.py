"""A thread as true geometry: the helical sweep of its ridge, a watertight triangle mesh.

Design rule: the sweep is the *same* relief the bump draws: every vertex height comes from the
compiled kernel (:func:`engine.tracer.kernels.bumps.relief_grid`) on the same parameter row
(:func:`engine.tracer.tables.bump_rows.tile_params`), the row the tracer's true thread
(:mod:`engine.tracer.kernels.helix`) is raised from too, so the mesh, the relief and the
tracer's geometry are one thread. The ridge's cross-section (its profile across the pitch, standing ``h`` off the
neck) is closed by a base :data:`EMBED_MM` inside the glass, swept along each start's helix
for the tile's turns and capped at both ends: a closed, consistently outward-oriented solid
(for export and other renderers: the tracer raises a true thread analytically, the same ridge
again, :mod:`engine.tracer.kernels.helix`). Units mm.
"""
from __future__ import annotations

import math

import numpy as np

from ..geometry.validate import body_profile
from .kernels import bumps as K
from ..appearance.bands import band_coordinates
from .tables.bump_rows import tile_params

#: How far the swept solid reaches into the neck's glass below the surface (mm).
EMBED_MM = 0.3


def _section_frame(design, v: np.ndarray):
    """Points ``(r, z)`` and outward unit normals of the outer section at arc lengths ``v``."""
    prof = body_profile(design.shape)
    sp = prof.sections[0]
    base = sum(sg.length for sg in sp.outer_base)
    wall = sp.outer_wall
    starts = np.concatenate([[0.0], np.cumsum([sg.length for sg in wall])])
    s = np.clip(v - base, 0.0, starts[-1])
    idx = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(wall) - 1)
    pts, nrm = np.zeros((len(v), 2)), np.zeros((len(v), 2))
    for i in np.unique(idx):
        sel = idx == i
        t = np.clip((s[sel] - starts[i]) / wall[i].length, 0.0, 1.0)
        pts[sel] = wall[i].point(t)
        tan = wall[i].tangent(t)
        nrm[sel] = np.stack([tan[..., 1], -tan[..., 0]], axis=-1)
    return pts, nrm


def thread_mesh(design, tile, steps_per_turn: int = 180, profile_points: int = 17):
    """``(vertices (n, 3) float64 mm, faces (m, 3) int64)`` of thread ``tile`` on ``design``'s
    outer surface as a watertight, outward-oriented solid (see the module rule); empty arrays
    when the tile's band misses the bottle or it has no turns."""
    band = band_coordinates(design, tile.z0, tile.z1)
    empty = np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    if band is None:
        return empty
    v0, v1, radius = band
    kind, p = tile_params(tile, v0, v1, radius, neck_diameter=2.0 * body_profile(design.shape).r_top)
    turns, n, pitch = p[K.P_A], int(p[K.P_REPEAT]), p[K.P_PITCH]
    if kind != K.THREAD or turns <= 0.0:
        return empty
    x = np.linspace(-p[K.P_B], p[K.P_C], profile_points)      # across the ridge, in pitches
    rings = max(2, int(math.ceil(turns * steps_per_turn)) + 1)
    tau = np.linspace(0.0, turns, rings)
    atlas = np.zeros((1, 3), np.float32)
    verts, faces = [], []
    for start in range(n):
        theta = p[K.P_PHASE] + 2.0 * math.pi * (tau - start / n)
        vc = p[K.P_START] + pitch * n * tau
        tt, xx = np.meshgrid(theta, x, indexing="ij")
        vv = vc[:, None] + xx * pitch
        out = np.zeros((tt.size, 3))
        K.relief_grid(kind, p, atlas, np.ascontiguousarray(tt.ravel() * radius),
                      np.ascontiguousarray(vv.ravel()), out)
        h = np.maximum(out[:, 0], 0.0).reshape(tt.shape)
        rz, nrm = _section_frame(design, vv.ravel())
        rz, nrm = rz.reshape(tt.shape + (2,)), nrm.reshape(tt.shape + (2,))
        top = rz + h[..., None] * nrm
        bottom = rz - EMBED_MM * nrm
        loop = np.concatenate([top, bottom[:, ::-1]], axis=1)  # (rings, 2J, 2) closed profile
        xyz = np.stack([loop[..., 0] * np.cos(tt[:, :1]), loop[..., 0] * np.sin(tt[:, :1]),
                        loop[..., 1]], axis=-1)
        first = sum(len(v) for v in verts)
        verts.append(xyz.reshape(-1, 3))
        faces.append(_sweep_faces(rings, loop.shape[1]) + first)
    v_all = np.concatenate(verts)
    f_all = np.concatenate(faces)
    if _signed_volume(v_all, f_all) < 0.0:
        f_all = f_all[:, ::-1]
    return v_all, np.ascontiguousarray(f_all)


def _sweep_faces(rings: int, m: int) -> np.ndarray:
    """Triangles of a closed ``m``-gon swept through ``rings`` rings, both ends capped (the
    loop is ``top_0 .. top_{J-1}, bottom_{J-1} .. bottom_0``, ``m = 2J``)."""
    i = np.arange(rings - 1)[:, None]
    j = np.arange(m)[None, :]
    a, b = i * m + j, i * m + (j + 1) % m
    c, d = a + m, b + m
    tube = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    half = m // 2
    top, bottom = np.arange(half), np.arange(m - 1, half - 1, -1)   # bottom[j] under top[j]
    strip = np.concatenate([np.stack([top[:-1], bottom[:-1], top[1:]], -1),
                            np.stack([top[1:], bottom[:-1], bottom[1:]], -1)])
    end = strip + (rings - 1) * m
    return np.concatenate([tube, strip, end[:, ::-1]]).astype(np.int64)


def _signed_volume(v: np.ndarray, f: np.ndarray) -> float:
    """Volume (mm^3) enclosed by triangles ``f`` of ``v``, positive when they face outwards."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
