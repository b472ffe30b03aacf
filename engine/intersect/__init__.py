"""Exact ray intersection with surfaces of revolution about the z axis (no Qt).

Conventions shared by every function here: rays ``p(t) = origin + t direction`` with unit
directions, so ``t`` is in mm; hits come back as (N, k) float64 arrays of ``t``, ascending
per ray, NaN-padded. The tracer calls :func:`revolved_hits` / :func:`revolved_normals` per
section segment, after culling with :func:`segment_bounds` / :func:`rays_touching_bounds`.
"""
from .offset_arc import offset_arc_bounds, offset_arc_parameter, ray_offset_arc_hits
from .quadric import ray_cone_hits, ray_spheroid_hits, rays_touching_bounds, stable_quadratic_roots
from .revolved import revolved_hits, revolved_normals, segment_bounds
from .torus import ray_torus_hits

__all__ = ["ray_torus_hits", "ray_cone_hits", "ray_spheroid_hits", "stable_quadratic_roots",
           "revolved_hits", "revolved_normals", "segment_bounds", "rays_touching_bounds",
           "ray_offset_arc_hits", "offset_arc_parameter", "offset_arc_bounds"]
