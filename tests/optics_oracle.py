"""The tests' oracle of smooth-dielectric optics: Fresnel reflectance, mirror and refraction
directions, absorption, written from SPEC section 5 in numpy apart from the kernels
(:mod:`engine.tracer.kernels.materials`), which tests/test_optics.py checks against it.

Design rule: pure vectorised numpy on float64 arrays, no geometry and no state. Formulas follow
../shared/oracle/SPEC.md section 5 exactly (unpolarised average of the s and p amplitudes,
total internal reflection as R = 1). Directions are unit vectors, shapes ``(N, 3)``; normals
face the incident side (``d . n < 0``). Absorption coefficients are in 1/mm, lengths in mm.
"""
from __future__ import annotations

import numpy as np


def fresnel_dielectric(cos_i, eta):
    """Unpolarised Fresnel reflectance and the transmitted cosine.

    Parameters
    ----------
    cos_i : array_like
        Cosine of the incidence angle, ``-d . n`` with ``n`` facing the incident side; in [0, 1].
    eta : array_like
        ``n_transmitted / n_incident`` (> 0), broadcast against ``cos_i``.

    Returns
    -------
    reflectance : ndarray
        R in [0, 1]; exactly 1 under total internal reflection. Transmittance is ``1 - R``.
    cos_t : ndarray
        Cosine of the refraction angle (>= 0); 0 where total internal reflection happens.
    """
    cos_i = np.clip(np.asarray(cos_i, dtype=float), 0.0, 1.0)
    eta = np.asarray(eta, dtype=float)
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    tir = sin2_t >= 1.0
    cos_t = np.sqrt(np.clip(1.0 - sin2_t, 0.0, 1.0))
    # Both denominators are > 0 unless cos_i = cos_t = 0 (exact grazing), which only TIR reaches.
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
        rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
        refl = 0.5 * (rs * rs + rp * rp)
    refl = np.where(tir | ~np.isfinite(refl), 1.0, np.clip(refl, 0.0, 1.0))
    return refl, np.where(tir, 0.0, cos_t)


def reflect(d, n, cos_i):
    """Mirror direction ``d + 2 cos_i n`` (unit when ``d`` and ``n`` are unit); shape ``(N, 3)``."""
    return d + 2.0 * np.asarray(cos_i)[..., None] * n


def refract(d, n, cos_i, cos_t, eta):
    """Refracted direction ``d / eta + (cos_i / eta - cos_t) n`` (SPEC 5), renormalised.

    Only meaningful where there is no total internal reflection. ``eta`` is
    ``n_transmitted / n_incident``; the result is a unit vector on the far side of the surface.
    """
    eta = np.asarray(eta, dtype=float)[..., None]
    t = d / eta + (np.asarray(cos_i)[..., None] / eta - np.asarray(cos_t)[..., None]) * n
    return t / np.linalg.norm(t, axis=-1, keepdims=True)


def beer_lambert(sigma_a, length):
    """Per-channel transmittance ``exp(-sigma_a * length)``.

    Parameters
    ----------
    sigma_a : array_like, shape (..., 3)
        Absorption coefficients (1/mm, >= 0).
    length : array_like, shape (...)
        Path lengths (mm, >= 0).

    Returns
    -------
    ndarray, shape (..., 3), values in (0, 1].
    """
    return np.exp(-np.asarray(sigma_a, dtype=float) * np.asarray(length, dtype=float)[..., None])


def critical_angle_deg(n_dense: float, n_rare: float) -> float:
    """Critical angle (degrees) for light going from ``n_dense`` into ``n_rare`` (< n_dense)."""
    return float(np.degrees(np.arcsin(n_rare / n_dense)))
