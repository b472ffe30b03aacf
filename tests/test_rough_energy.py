"""Rough (GGX) surfaces keep their energy: the stored albedo tables are the kernels' own draws,
and one frosted interface or one glossy mirror in a white furnace returns 1 on average, where
the single-scattering draw alone returned its albedo (up to 40 % less)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from engine.tracer.tables import ggx_albedo as A
from engine.tracer.kernels import microfacet as M
from engine.tracer.kernels.materials import MAT_COLS, MF_K, MF_N, MF_TINT, fresnel_conductor

ALPHAS = (0.02, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5)
COSINES = (0.05, 0.15, 0.3, 0.5, 0.7, 0.85, 1.0)
#: Draws per (alpha, cosine, side): R2 points, so the mean's error is well below the tolerance.
DRAWS = 20000
#: Largest error of one interface's mean weight allowed (table interpolation ~3e-3 at most).
TOL = 0.01


def _r2(n):
    """``n`` points of the R2 low-discrepancy sequence in [0, 1)^2."""
    g = 1.32471795724474602596
    k = np.arange(1, n + 1)[:, None]
    return (0.5 + k * np.array([1.0 / g, 1.0 / (g * g)])) % 1.0


@njit(cache=False)
def _glass_mean(glass, alpha, cos_i, eta, u, compensate):
    """Mean total weight of one frosted interface met at ``cos_i`` over the draws ``u``."""
    kids = np.zeros((2, 8))
    sin_i = math.sqrt(1.0 - cos_i * cos_i)
    total = 0.0
    for i in range(u.shape[0]):
        if compensate:
            nk = M.frosted_glass(glass, alpha, sin_i, 0.0, -cos_i, 0.0, 0.0, 1.0, eta, u[i, 0], u[i, 1], kids)
        else:
            nk = M.rough_dielectric(alpha, sin_i, 0.0, -cos_i, 0.0, 0.0, 1.0, eta, u[i, 0], u[i, 1], 1.0, kids)
        total += kids[0, 3] + (kids[1, 3] if nk == 2 else 0.0)
    return total / u.shape[0]


@njit(cache=False)
def _mirror_mean(mirror, mirror_avg, alpha, cos_i, u, mat_f):
    """Mean RGB weight of one glossy conductor (material row 0) met at ``cos_i``."""
    kids = np.zeros((1, 8))
    sin_i = math.sqrt(1.0 - cos_i * cos_i)
    out = np.zeros(3)
    for i in range(u.shape[0]):
        M.rough_mirror(mirror, mirror_avg, alpha, (sin_i, 0.0, -cos_i), (0.0, 0.0, 1.0), u[i, 0], u[i, 1], kids,
                       mat_f, 0, -1.0)
        out += kids[0, 3:6]
    return out / u.shape[0]


def _conductor_row(n, k, tint=(1.0, 1.0, 1.0)):
    """A conductor's ``mat_f`` row as :func:`engine.tracer.tables.finishes.material_row` makes it."""
    from engine.appearance.closure_parts import ClosureMaterial
    from engine.tracer.tables.finishes import material_row
    _, row = material_row(ClosureMaterial("conductor", tuple(n), tuple(k), tuple(tint)))
    return row.reshape(1, MAT_COLS)


def test_the_stored_tables_are_the_kernels_own_albedo():
    """Recomputed entries equal the stored ones (float32): a kernel change that alters the
    draw without rebuilding the tables (python -m engine.tracer.tables.ggx_albedo) fails here."""
    glass, mirror, mirror_avg = A.albedo_tables()
    rng = np.random.default_rng(7)
    for _ in range(6):
        side, ix = int(rng.integers(2)), int(rng.integers(M.N_X))
        ia, im = int(rng.integers(1, M.N_ALPHA)), int(rng.integers(M.N_MU))
        assert glass[side, ix, ia, im] == pytest.approx(A.glass_entry(side, ix, ia, im), abs=1e-6)
    mus, alphas, _ = A.grid()
    for ia, im in ((3, 32), (12, 5), (25, 17)):
        assert mirror[ia, im] == pytest.approx(M.mirror_albedo(alphas[ia], mus[im], A.QUADRATURE), abs=1e-6)
    assert np.allclose(mirror_avg, A.cosine_average(mirror), atol=1e-6)
    assert np.all(glass[:, :, 0] == 1.0) and np.all(mirror[0] == 1.0)   # alpha 0: smooth
    # what the compensation makes up for: up to 40 % at alpha 0.5 leaving glass, ~0 when smooth
    e = [M.glass_albedo_at(glass, 0.5, c, 1.0 / 1.5) for c in COSINES]
    assert 0.55 < min(e) < 0.65 and M.glass_albedo_at(glass, 0.02, 1.0, 1.5) > 0.999


@pytest.mark.parametrize("eta", [1.5, 1.0 / 1.5], ids=["air-to-glass", "glass-to-air"])
def test_one_frosted_interface_returns_all_its_energy_at_every_roughness(eta):
    """Reflection + transmission of a frosted interface average 1 in a white furnace for
    alpha 0.02..0.5 at every incidence, from both sides (total internal reflection included:
    leaving glass beyond 42 deg): the single-scattering draw alone loses up to 40 %."""
    glass = A.albedo_tables()[0]
    u = _r2(DRAWS)
    new_err, old_err = [], []
    for alpha in ALPHAS:
        for c in COSINES:
            new_err.append(abs(_glass_mean(glass, alpha, c, eta, u, True) - 1.0))
            old_err.append(abs(_glass_mean(glass, alpha, c, eta, u, False) - 1.0))
    assert max(new_err) < TOL, max(new_err)
    assert max(old_err) > 0.25   # measured: 0.33 entering, 0.40 leaving (alpha 0.5, grazing)


def test_a_glossy_mirror_keeps_its_energy_and_a_coloured_metal_saturates():
    """A perfect conductor (F = 1) averages 1 at every roughness and incidence; aluminium gains
    a little (its colour a touch deeper: the gain is the more, the higher F_avg) and never
    beyond the perfect one."""
    _, mirror, mirror_avg = A.albedo_tables()
    u = _r2(DRAWS)
    perfect = _conductor_row((1e-4,) * 3, (1e4,) * 3)
    assert fresnel_conductor(0.3, 1e-4, 1e4) > 0.9999
    worst = 0.0
    for alpha in ALPHAS:
        for c in COSINES:
            worst = max(worst, abs(_mirror_mean(mirror, mirror_avg, alpha, c, u, perfect)[0] - 1.0))
    assert worst < TOL, worst
    alu = _conductor_row((1.57, 1.07, 0.61), (7.74, 6.78, 5.37), (1.0, 0.8, 0.5))
    gain = (_mirror_mean(mirror, mirror_avg, 0.4, 0.5, u, alu)
            / _mirror_mean(mirror, mirror_avg, 0.4, 0.5, u, _single_bounce(alu)))
    white_gain = 1.0 / _mirror_mean(mirror, mirror_avg, 0.4, 0.5, u, _single_bounce(perfect))[0]
    assert white_gain > 1.1
    assert np.all(gain > 1.0) and np.all(gain < white_gain)
    assert gain[0] > gain[1] > gain[2]        # red reflects most: its bounces lose least
    assert alu[0, MF_TINT + 2] == 0.5 and alu[0, MF_N] == 1.57 and alu[0, MF_K] == 7.74


def _single_bounce(row):
    """``row`` with ``F_avg`` 0: the compensation adds nothing (the single-scattering draw)."""
    out = row.copy()
    out[0, M.MF_FAVG:M.MF_FAVG + 3] = 0.0
    return out
