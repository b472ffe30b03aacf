"""Camera rays, sample positions, seeds and the environment lookup, compiled.

Design rule: everything random is a pure function of integers (counter-based hashing), so a
sample, and every branch of its tree, can be replayed from (pixel, sample, branch) alone and
the image never depends on threads or tile order. Sample 0 of a pixel is its centre; samples
``k >= 1`` follow the R2 low-discrepancy sequence rotated per pixel (Cranley-Patterson), so
any prefix of them is well stratified. Camera and environment follow ../shared/oracle/SPEC.md
sections 2 and 3 exactly.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .roots import JIT

_PLASTIC = 1.32471795724474602596
R2_X = 1.0 / _PLASTIC
R2_Y = 1.0 / (_PLASTIC * _PLASTIC)
# camera array columns: eye (3), forward (3), right (3), up (3), tan(fov/2), width, height
C_EYE, C_F, C_R, C_U, C_TAN, C_W, C_H = 0, 3, 6, 9, 12, 13, 14
C_COLS = 15


@njit(**JIT)
def mix64(x):
    """SplitMix64 finaliser: a bijective, well-mixed hash of a uint64."""
    z = np.uint64(x) + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(**JIT)
def branch_seed(parent, child):
    """Seed of child ``child`` (0, 1, ...) of a branch seeded ``parent``."""
    return mix64(parent ^ mix64(np.uint64(child) + np.uint64(0x632BE59BD9B4E019)))


@njit(**JIT)
def uniform01(seed, k):
    """The ``k``-th uniform number in [0, 1) of a branch's stream (53 bits)."""
    return float(mix64(seed ^ mix64(np.uint64(k) + np.uint64(0xD1B54A32D192ED03))) >> np.uint64(11)) * (2.0 ** -53)


@njit(**JIT)
def pixel_offset(pixel, k):
    """Sub-pixel position in [0, 1)^2 of sample ``k`` of pixel index ``row * width + col``."""
    if k == 0:
        return 0.5, 0.5
    h = mix64(np.uint64(pixel))
    h2 = mix64(h ^ np.uint64(0x5851F42D4C957F2D))
    bx = float(h >> np.uint64(11)) * (2.0 ** -53)
    by = float(h2 >> np.uint64(11)) * (2.0 ** -53)
    fx = bx + k * R2_X
    fy = by + k * R2_Y
    return fx - math.floor(fx), fy - math.floor(fy)


@njit(**JIT)
def camera_ray(cam, x, y):
    """Unit direction of the primary ray through image point ``(x, y)`` (pixels, y down)."""
    t = cam[C_TAN]
    w, h = cam[C_W], cam[C_H]
    sx = (2.0 * x / w - 1.0) * t * w / h
    sy = (1.0 - 2.0 * y / h) * t
    dx = cam[C_F] + sx * cam[C_R] + sy * cam[C_U]
    dy = cam[C_F + 1] + sx * cam[C_R + 1] + sy * cam[C_U + 1]
    dz = cam[C_F + 2] + sx * cam[C_R + 2] + sy * cam[C_U + 2]
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    return dx / n, dy / n, dz / n


@njit(**JIT)
def env_lookup(tex, scale, rot, dx, dy, dz):
    """Radiance ``(r, g, b)`` arriving along unit direction ``d`` (SPEC 3, bilinear, u wraps,
    rows clamped), times ``scale``; the map is turned by ``rot`` rad about +z."""
    h, w = tex.shape[0], tex.shape[1]
    u = (math.atan2(dy, dx) - rot) * (0.5 / math.pi)
    u -= math.floor(u)
    v = math.acos(min(1.0, max(-1.0, dz))) * (1.0 / math.pi)
    x = u * w - 0.5
    x -= w * math.floor(x / w)
    y = v * (h - 1)
    i0 = int(x)
    fx = x - i0
    if i0 > w - 1:
        i0 = w - 1
    i1 = i0 + 1 if i0 + 1 < w else 0
    j0 = int(y)
    if j0 > h - 2:
        j0 = h - 2
    fy = y - j0
    j1 = j0 + 1
    w00 = (1.0 - fx) * (1.0 - fy)
    w01 = fx * (1.0 - fy)
    w10 = (1.0 - fx) * fy
    w11 = fx * fy
    r = (tex[j0, i0, 0] * w00 + tex[j0, i1, 0] * w01 + tex[j1, i0, 0] * w10 + tex[j1, i1, 0] * w11) * scale
    g = (tex[j0, i0, 1] * w00 + tex[j0, i1, 1] * w01 + tex[j1, i0, 1] * w10 + tex[j1, i1, 1] * w11) * scale
    b = (tex[j0, i0, 2] * w00 + tex[j0, i1, 2] * w01 + tex[j1, i0, 2] * w10 + tex[j1, i1, 2] * w11) * scale
    return r, g, b
