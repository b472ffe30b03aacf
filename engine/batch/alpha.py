"""Alpha for final renders: how much of each pixel the bottle covers, seen from the camera.

Design rule: alpha is geometric coverage, not transparency. Glass lets the studio through, so
a cut-out of a glass bottle keeps the colour the tracer computed (environment seen through the
glass included) and takes as alpha the fraction of the pixel's square whose primary ray meets
the outer glass surface. The fraction is estimated on a fixed ``grid x grid`` lattice of points
per pixel, the same square the tracer's samples cover (pixel ``(i, j)`` spans
``[i, i+1] x [j, j+1]``, SPEC section 2), so alpha is deterministic and independent of samples.
The glass body comes from the geometry engine's tessellation; Embree (embreex) casts the rays.
"""
from __future__ import annotations

import numpy as np

#: Chordal tolerance (mm) of the silhouette mesh: well under a pixel at any sensible framing.
SILHOUETTE_TOL_MM = 0.05
#: Rays per chunk (memory bound for print-size images).
CHUNK_RAYS = 1 << 20


def coverage(design, width: int, height: int, grid: int = 4) -> np.ndarray:
    """Fraction of each pixel covered by the bottle, ``(height, width)`` float32 in [0, 1].

    Parameters
    ----------
    design : engine.model.design.Design
        Its shape and camera are used (mm, degrees).
    width, height : int
        Image size in pixels (>= 1).
    grid : int
        Coverage points per pixel edge (``grid**2`` rays per pixel; values are multiples of
        ``1 / grid**2``).
    """
    from embreex.mesh_construction import TriangleMesh
    from embreex.rtcore_scene import EmbreeScene

    from ..geometry.tessellate import tessellate_body
    from ..tracer.camera import PinholeCamera

    mesh = tessellate_body(design.shape, SILHOUETTE_TOL_MM)
    scene = EmbreeScene()
    TriangleMesh(scene, np.ascontiguousarray(mesh.vertices, dtype=np.float32),
                 np.ascontiguousarray(mesh.faces, dtype=np.int32))
    cam = PinholeCamera.from_design(design.camera, width, height)
    sub = (np.arange(grid) + 0.5) / grid
    dx, dy = np.meshgrid(sub, sub)
    dx, dy = dx.ravel(), dy.ravel()
    out = np.zeros((height, width), dtype=np.float32)
    rows_per_chunk = max(1, CHUNK_RAYS // (width * len(dx)))
    cols = np.arange(width, dtype=float)
    for r0 in range(0, height, rows_per_chunk):
        rows = np.arange(r0, min(height, r0 + rows_per_chunk), dtype=float)
        shape = (len(rows), width, len(dx))
        x = np.broadcast_to(cols[None, :, None] + dx, shape)
        y = np.broadcast_to(rows[:, None, None] + dy, shape)
        o, d = cam.rays(x.ravel(), y.ravel())
        prim = np.asarray(scene.run(o.astype(np.float32), d.astype(np.float32)))
        hits = (prim >= 0).reshape(len(rows), width, len(dx))
        out[r0:r0 + len(rows)] = hits.mean(axis=2)
    return out
