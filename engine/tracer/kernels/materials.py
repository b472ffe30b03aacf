"""What a hit does to a branch: the materials of the tracer, compiled.

Design rule: a material turns one incoming branch at a surface interaction into at most
``MAX_CHILDREN`` outgoing branches (direction, weight, medium) plus radiance it returns at once
(emission or a lit diffuse part); the integrator owns the tree. Today's material is the smooth
dielectric interface between the media on the two sides of a surface (SPEC section 5:
unpolarised Fresnel, total internal reflection, both branches). Rough dielectrics, paper and
conductors take their own kind number here and their parameters from ``mat_f``; branches that
need random numbers draw them from the branch's own seed (:func:`~engine.tracer.kernels.
sampling.uniform01`), so the image stays deterministic.
"""
from __future__ import annotations

import math

from numba import njit

from .roots import INLINE, JIT

SMOOTH_DIELECTRIC = 0
MAX_CHILDREN = 2
# mat_i columns
M_KIND = 0


@njit(**JIT)
def fresnel_dielectric(cos_i, eta):
    """Unpolarised reflectance and transmitted cosine for ``eta = n_t / n_i`` (SPEC 5);
    ``(1, 0)`` under total internal reflection."""
    cos_i = min(1.0, max(0.0, cos_i))
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    if sin2_t >= 1.0:
        return 1.0, 0.0
    cos_t = math.sqrt(1.0 - sin2_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    r = 0.5 * (rs * rs + rp * rp)
    if not math.isfinite(r):
        return 1.0, 0.0
    return min(1.0, max(0.0, r)), cos_t


@njit(**JIT)
def smooth_dielectric(dx, dy, dz, nx, ny, nz, cos_i, eta, out):
    """Both branches of a smooth interface; ``n`` faces the incident side (``d . n < 0``).

    Writes ``out[c] = (dx, dy, dz, weight factor, transmitted?)`` per child and returns the
    number of children (1 under total internal reflection, else 2: reflected, refracted).
    """
    refl, cos_t = fresnel_dielectric(cos_i, eta)
    out[0, 0] = dx + 2.0 * cos_i * nx
    out[0, 1] = dy + 2.0 * cos_i * ny
    out[0, 2] = dz + 2.0 * cos_i * nz
    out[0, 3] = refl
    out[0, 4] = 0.0
    if refl >= 1.0:
        return 1
    k = cos_i / eta - cos_t
    tx, ty, tz = dx / eta + k * nx, dy / eta + k * ny, dz / eta + k * nz
    h = math.sqrt(tx * tx + ty * ty + tz * tz)
    out[1, 0], out[1, 1], out[1, 2] = tx / h, ty / h, tz / h
    out[1, 3] = 1.0 - refl
    out[1, 4] = 1.0
    return 2
