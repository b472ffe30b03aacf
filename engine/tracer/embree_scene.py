"""Embree (embreex) triangle scene: float32 ray casts that return distance and triangle id.

Design rule: Embree sees float32 copies of the mesh; callers keep float64 geometry and must
start secondary rays a small, scale-aware distance off the surface (:data:`SURFACE_EPS_MM`),
because Embree's float32 hit distances carry errors of a few ulps of the scene size. Scenes
are committed once and are then safe to query from several threads; embreex releases the GIL
while tracing, so threads scale.
"""
from __future__ import annotations

import numpy as np
from embreex.mesh_construction import TriangleMesh
from embreex.rtcore_scene import EmbreeScene

#: Offset (mm) of secondary ray origins off a surface: ~60 float32 ulps at 250 mm, and above
#: the mesh-to-true-surface distance of the render tessellation; far below any wall thickness.
SURFACE_EPS_MM = 1e-3


class EmbreeTriangles:
    """A committed Embree scene of one triangle mesh (vertices in mm)."""

    def __init__(self, vertices, faces):
        self.n_triangles = int(len(faces))
        self.n_vertices = int(len(vertices))
        self._scene = EmbreeScene(robust=True)
        self._mesh = TriangleMesh(self._scene, np.ascontiguousarray(vertices, dtype=np.float32),
                                  np.ascontiguousarray(faces, dtype=np.int32))
        # The first query commits the scene; do it now, on the building thread.
        self._scene.run(np.zeros((1, 3), np.float32), np.array([[0, 0, 1]], np.float32))

    def intersect(self, origins, directions):
        """Nearest hits of rays ``origins + t directions`` (unit directions), t > 0.

        Returns
        -------
        t : ndarray float64, shape (N,)
            Hit distance (mm); ``inf`` for misses.
        prim : ndarray int64, shape (N,)
            Triangle index, -1 for misses.
        """
        if len(origins) == 0:
            return np.empty(0), np.empty(0, dtype=np.int64)
        res = self._scene.run(np.ascontiguousarray(origins, dtype=np.float32),
                              np.ascontiguousarray(directions, dtype=np.float32), output=1)
        prim = np.asarray(res["primID"], dtype=np.int64)
        t = np.where(prim >= 0, np.asarray(res["tfar"], dtype=np.float64), np.inf)
        return t, prim
