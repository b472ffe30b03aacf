"""Exact ray intersection with surfaces of revolution about the z axis (no Qt).

Conventions shared by every function here: rays ``p(t) = origin + t direction`` with unit
directions, so ``t`` is in mm; hits come back as (N, k) float64 arrays of ``t``, ascending
per ray, NaN-padded.
"""
from .torus import ray_torus_hits

__all__ = ["ray_torus_hits"]
