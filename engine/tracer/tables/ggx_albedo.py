"""The GGX single-scattering albedo tables the kernels' energy compensation reads.

Design rule: the tables are the mean weights of the kernels' own rough-surface draws
(:func:`engine.tracer.kernels.microfacet.glass_albedo` and ``mirror_albedo``: the midpoint rule
on a :data:`QUADRATURE` x :data:`QUADRATURE` grid of the draw's two uniforms), so the
compensation divides by exactly what the draw loses. Computing them takes about a minute, so
they are computed once and stored (``data/ggx_albedo.npz``, float32, ~0.2 MB), written by
``python -m engine.tracer.tables.ggx_albedo``; a test recomputes entries and compares, so a kernel
change that leaves them stale fails. Grids: :mod:`engine.tracer.kernels.microfacet`.
Materials' mean Fresnel ``F_avg`` (the other input of a rough mirror's compensation) is
:func:`fresnel_average`.
"""
from __future__ import annotations

import functools
import os
import sys

import numpy as np

from ..kernels import microfacet as M
from ..kernels.materials import fresnel_conductor, fresnel_dielectric

#: Side of the midpoint grid over the draw's two uniforms (16384 draws per entry: converged
#: to about 1e-4 where total internal reflection puts a kink in the integrand).
QUADRATURE = 128
PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "ggx_albedo.npz")


def grid():
    """``(cos_i, alpha, x)`` node values of the tables (``x = (n - 1) / (n + 1)``)."""
    return (np.linspace(0.0, 1.0, M.N_MU), np.linspace(0.0, M.ALPHA_MAX, M.N_ALPHA),
            np.linspace(0.0, M.X_MAX, M.N_X))


def index_ratio(x: float, side: int) -> float:
    """``eta`` (transmitted / incident) of node ``x`` on ``side`` (0: into the denser medium)."""
    n = (1.0 + x) / (1.0 - x)
    return n if side == 0 else 1.0 / n


def glass_entry(side: int, ix: int, ia: int, im: int, q: int = QUADRATURE) -> float:
    """One entry of the glass table, computed."""
    mus, alphas, xs = grid()
    return M.glass_albedo(alphas[ia], mus[im], index_ratio(xs[ix], side), q)


def build_tables(q: int = QUADRATURE) -> dict:
    """``{"glass", "mirror", "mirror_avg"}`` computed (module rule; about a minute at the
    default ``q``). At alpha 0 every surface is a smooth one: albedo exactly 1."""
    mus, alphas, xs = grid()
    glass = np.ones((2, M.N_X, M.N_ALPHA, M.N_MU))
    mirror = np.ones((M.N_ALPHA, M.N_MU))
    for ia in range(1, M.N_ALPHA):
        for im, mu in enumerate(mus):
            mirror[ia, im] = M.mirror_albedo(alphas[ia], mu, q)
            for side in (0, 1):
                for ix in range(M.N_X):
                    glass[side, ix, ia, im] = glass_entry(side, ix, ia, im, q)
    return {"glass": glass, "mirror": mirror, "mirror_avg": cosine_average(mirror)}


def cosine_average(table: np.ndarray) -> np.ndarray:
    """``2 int_0^1 E(mu) mu dmu`` over the last axis (trapezoid rule on the mu nodes)."""
    mus = grid()[0]
    y = 2.0 * table * mus
    return np.sum(0.5 * (y[..., 1:] + y[..., :-1]) * np.diff(mus), axis=-1)


@functools.lru_cache(maxsize=1)
def albedo_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(glass, mirror, mirror_avg)`` float64 (read-only, loaded once per process) for the
    finish tables."""
    try:
        with np.load(PATH) as f:
            out = tuple(np.ascontiguousarray(f[k], dtype=np.float64) for k in ("glass", "mirror", "mirror_avg"))
    except (OSError, KeyError, ValueError) as e:
        raise RuntimeError(f"the GGX albedo tables {PATH} are missing or unreadable ({e}); "
                           "rebuild them with: python -m engine.tracer.tables.ggx_albedo") from e
    want = ((2, M.N_X, M.N_ALPHA, M.N_MU), (M.N_ALPHA, M.N_MU), (M.N_ALPHA,))
    if tuple(a.shape for a in out) != want:
        raise RuntimeError(f"the GGX albedo tables {PATH} do not match the kernels' grid; "
                           "rebuild them with: python -m engine.tracer.tables.ggx_albedo")
    for a in out:
        a.setflags(write=False)
    return out


def fresnel_average(reflectance) -> float:
    """``F_avg = 2 int_0^1 F(mu) mu dmu`` of a reflectance ``F(cos_i)`` (32-point
    Gauss-Legendre): the mean Fresnel over a cosine-weighted hemisphere."""
    x, w = np.polynomial.legendre.leggauss(32)
    mu = 0.5 * (x + 1.0)
    return float(np.sum(0.5 * w * 2.0 * mu * np.array([reflectance(m) for m in mu])))


def conductor_average(n: float, k: float) -> float:
    """``F_avg`` of a conductor of complex index ``n + i k`` (from air)."""
    return fresnel_average(lambda mu: fresnel_conductor(mu, n, k))


def dielectric_average(ior: float) -> float:
    """``F_avg`` of a dielectric coat of index ``ior`` (from air)."""
    return fresnel_average(lambda mu: fresnel_dielectric(mu, ior)[0])


def main() -> int:
    """Build the tables and write :data:`PATH` (float32)."""
    tables = build_tables()
    os.makedirs(os.path.dirname(PATH), exist_ok=True)
    np.savez_compressed(PATH, **{k: v.astype(np.float32) for k, v in tables.items()})
    g = tables["glass"]
    print(f"wrote {PATH}: glass albedo {g.min():.4f}..{g.max():.4f}, "
          f"mirror {tables['mirror'].min():.4f}..{tables['mirror'].max():.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
