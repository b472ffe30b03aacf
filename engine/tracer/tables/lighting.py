"""Diffuse light for the kernels: the environment's prefiltered irradiance and the lights.

Design rule: a diffuse surface (label paper, a plastic closure's base) is lit by the environment
through one lat-long table of its cosine-convolved irradiance over pi (:func:`irradiance_table`,
computed once per environment map and cached; the kernels look it up like the map itself, with
its scale and rotation, :func:`engine.tracer.kernels.sampling.env_lookup`) and by the design's
directional lights as rows of :func:`light_table`. One module for both, so paper and plastic are
lit alike. Units: radiance as the environment's; directions unit vectors in the world frame.
"""
from __future__ import annotations

import math

import numpy as np

from .environment import ArrayCache
from ..kernels.ground import LIGHT_COLS

#: Rows x columns of the irradiance table (lat-long, the environment's convention): a cosine
#: lobe is smooth, so 32 x 64 holds it to well under 1 %.
IRR_ROWS, IRR_COLS = 32, 64
#: Bins the environment is reduced to before the convolution (energy-preserving box sums).
_BIN_ROWS, _BIN_COLS = 48, 96

_IRR = ArrayCache(4)


def _directions(theta, phi):
    st = np.sin(theta)
    return np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta) * np.ones_like(phi)], -1)


def _irradiance(texels: np.ndarray) -> np.ndarray:
    h, w = texels.shape[:2]
    tex = np.nan_to_num(np.asarray(texels, np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    # texel (j, i) looks along theta = pi j / (h - 1), phi = 2 pi (i + 0.5) / w (SPEC 3); its
    # solid angle is the band between the midpoints of its row and the next
    theta = math.pi * np.arange(h) / (h - 1)
    edges = np.clip(np.concatenate([[0.0], 0.5 * (theta[1:] + theta[:-1]), [math.pi]]), 0.0, math.pi)
    band = (np.cos(edges[:-1]) - np.cos(edges[1:])) * (2.0 * math.pi / w)  # (h,)
    phi = 2.0 * math.pi * (np.arange(w) + 0.5) / w
    rb = np.linspace(0, h, min(_BIN_ROWS, h) + 1).astype(int)[:-1]
    cb = np.linspace(0, w, min(_BIN_COLS, w) + 1).astype(int)[:-1]
    dirs = _directions(theta[:, None], phi[None, :])  # (h, w, 3)
    om = np.broadcast_to(band[:, None], (h, w))

    def reduce(a):
        return np.add.reduceat(np.add.reduceat(a, rb, axis=0), cb, axis=1)

    power = reduce(tex * om[..., None]).reshape(-1, 3)  # radiance x solid angle per bin
    omega = reduce(om).reshape(-1)
    mean_dir = reduce(dirs * om[..., None]).reshape(-1, 3)
    mean_dir /= np.maximum(np.linalg.norm(mean_dir, axis=1, keepdims=True), 1e-300)
    t_out = math.pi * np.arange(IRR_ROWS) / (IRR_ROWS - 1)
    p_out = 2.0 * math.pi * (np.arange(IRR_COLS) + 0.5) / IRR_COLS
    normals = _directions(t_out[:, None], p_out[None, :]).reshape(-1, 3)
    cos = np.maximum(normals @ mean_dir.T, 0.0)  # (out, bins)
    # divide by the discrete integral of the cosine itself (pi in the limit): a uniform
    # environment gives exactly its radiance, the furnace stays exact
    out = (cos @ power) / np.maximum(cos @ omega, 1e-300)[:, None]
    return np.ascontiguousarray(out.reshape(IRR_ROWS, IRR_COLS, 3), dtype=np.float32)


def irradiance_table(texels: np.ndarray) -> np.ndarray:
    """The environment's cosine-convolved irradiance over pi, ``(IRR_ROWS, IRR_COLS, 3)``
    float32, a lat-long table in the environment's own convention (look it up like the map,
    with its scale and rotation): radiance a white Lambertian sheet with that normal sends back.
    Cached by the texel array's identity (environment maps are cached, so one per map)."""
    return _IRR.get(texels, _read_only_irradiance)


def _read_only_irradiance(texels: np.ndarray) -> np.ndarray:
    table = _irradiance(texels)
    table.setflags(write=False)
    return table


def light_table(lights) -> np.ndarray:
    """``Design.lights`` as rows ``(unit direction towards the light, colour x intensity, cosine
    of half its apparent diameter)`` (:data:`engine.tracer.kernels.ground.LIGHT_COLS` columns)."""
    rows = []
    for light in lights:
        d = np.asarray(light.direction, float)
        n = float(np.linalg.norm(d))
        if not (n > 0.0 and math.isfinite(n)) or light.intensity <= 0.0:
            continue
        cos_half = math.cos(math.radians(0.5 * float(light.angle_deg)))
        rows.append(np.concatenate([d / n, np.asarray(light.color, float) * float(light.intensity), [cos_half]]))
    return np.ascontiguousarray(np.array(rows, float).reshape(-1, LIGHT_COLS))
