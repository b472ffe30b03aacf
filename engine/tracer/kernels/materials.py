"""What a hit does to a branch: the materials of the tracer, compiled.

Design rule: a material turns one incoming branch at a surface interaction into at most
``MAX_CHILDREN`` outgoing branches (direction, RGB weight factor, which side's medium) written
into ``kids``, and returns the radiance it sends back at once (a lit diffuse part); the
integrator owns the tree. Kinds (``mat_i[m, M_KIND]``, parameters in ``mat_f``):

=================  =========================================================================
SMOOTH_DIELECTRIC  the interface between the media on the two sides (SPEC section 5: unpolarised
                   Fresnel, total internal reflection, both branches)
CONDUCTOR          a metal: complex IOR ``(n, k)`` per RGB channel, times a tint (foil, caps)
PLASTIC            a dielectric coat (IOR) over a lit diffuse base (albedo RGB)
GROUND             the stage under the bottle: a Lambertian base (or a shadow catcher, or a
                   tinted mirror) under an optional clear coat; black from below
                   (:func:`engine.tracer.kernels.surface.scatter`)
BACKDROP           the stage's backdrop sweep behind the bottle: the ground's base and coat on
                   a curved surface; black from behind (:mod:`engine.tracer.kernels.backdrop`)
=================  =========================================================================

Paper labels are a decal over another material (:mod:`~engine.tracer.kernels.labels`).
Branches that need random numbers draw them from the branch's own seed
(:func:`~engine.tracer.kernels.sampling.uniform01`), so the image stays deterministic.
"""
from __future__ import annotations

import math

from numba import njit

from .jit import INLINE, JIT

SMOOTH_DIELECTRIC, CONDUCTOR, PLASTIC, GROUND, BACKDROP = 0, 1, 2, 3, 4
MAX_CHILDREN = 4
# kids columns: direction, RGB weight factor, medium side (0: incident side, 1: transmitted)
KD_X, KD_Y, KD_Z, KW_R, KW_G, KW_B, K_SIDE = range(7)
KID_COLS = K_SIDE + 1
# mat_i columns
M_KIND = 0
# mat_f columns: CONDUCTOR n (rgb), k (rgb), tint (rgb); PLASTIC albedo (rgb), coat ior
MF_N, MF_K, MF_TINT = 0, 3, 6
MF_ALBEDO, MF_COAT_IOR = 0, 3
# GROUND (the stage, :mod:`.surface`): albedo of the base or the mirror's tint (rgb), the coat's
# index (0: none), a shadow catcher (1) or not, a mirror (1) or not, the coat's GGX alpha (0: sharp),
# the radius and top (mm) of an upright cylinder about the z axis holding everything on the stage;
# columns MF_FAVG.. (microfacet) the coat's mean Fresnel for a rough coat's energy; MG_WIDE 1 where
# a backdrop stands on the ground (its probes span the whole sky: :func:`.ground.probe_window`).
# BACKDROP: the same columns (its albedo, coat, alpha, mean Fresnel).
MG_ALBEDO, MG_COAT_IOR, MG_SHADOW, MG_MIRROR, MG_ALPHA, MG_BOUND_R, MG_BOUND_Z = 0, 3, 4, 5, 6, 7, 8
MG_WIDE = 12
MAT_COLS = 13


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
def fresnel_conductor(cos_i, n, k):
    """Unpolarised reflectance of a conductor with complex IOR ``n + i k`` (from a dielectric
    of index 1) at incidence cosine ``cos_i``: the exact s and p amplitudes, averaged."""
    c = min(1.0, max(0.0, cos_i))
    c2 = c * c
    s2 = 1.0 - c2
    t0 = n * n - k * k - s2
    a2b2 = math.sqrt(t0 * t0 + 4.0 * n * n * k * k)
    a = math.sqrt(max(0.5 * (a2b2 + t0), 0.0))
    t1 = a2b2 + c2
    t2 = 2.0 * a * c
    rs = (t1 - t2) / (t1 + t2)
    t3 = c2 * a2b2 + s2 * s2
    t4 = t2 * s2
    rp = rs * (t3 - t4) / (t3 + t4)
    return min(1.0, max(0.0, 0.5 * (rs + rp)))


@njit(**INLINE)
def _mirror(kids, c, dx, dy, dz, nx, ny, nz, cos_i, fr, fg, fb):
    kids[c, KD_X] = dx + 2.0 * cos_i * nx
    kids[c, KD_Y] = dy + 2.0 * cos_i * ny
    kids[c, KD_Z] = dz + 2.0 * cos_i * nz
    kids[c, KW_R], kids[c, KW_G], kids[c, KW_B] = fr, fg, fb
    kids[c, K_SIDE] = 0.0


@njit(**JIT)
def smooth_dielectric(dx, dy, dz, nx, ny, nz, cos_i, eta, scale, kids, c):
    """Both branches of a smooth interface, their weights times ``scale``, into ``kids[c:]``;
    ``n`` faces the incident side (``d . n < 0``). Returns the number of children (1 under
    total internal reflection, else 2: reflected, refracted)."""
    refl, cos_t = fresnel_dielectric(cos_i, eta)
    _mirror(kids, c, dx, dy, dz, nx, ny, nz, cos_i, refl * scale, refl * scale, refl * scale)
    if refl >= 1.0:
        return 1
    k = cos_i / eta - cos_t
    tx, ty, tz = dx / eta + k * nx, dy / eta + k * ny, dz / eta + k * nz
    h = math.sqrt(tx * tx + ty * ty + tz * tz)
    f = (1.0 - refl) * scale
    kids[c + 1, KD_X], kids[c + 1, KD_Y], kids[c + 1, KD_Z] = tx / h, ty / h, tz / h
    kids[c + 1, KW_R], kids[c + 1, KW_G], kids[c + 1, KW_B] = f, f, f
    kids[c + 1, K_SIDE] = 1.0
    return 2


@njit(**JIT)
def conductor(mat_f, m, dx, dy, dz, nx, ny, nz, cos_i, scale, kids, c):
    """The mirror branch of a metal (per-channel Fresnel of ``(n, k)`` times the tint)."""
    fr = fresnel_conductor(cos_i, mat_f[m, MF_N], mat_f[m, MF_K]) * mat_f[m, MF_TINT]
    fg = fresnel_conductor(cos_i, mat_f[m, MF_N + 1], mat_f[m, MF_K + 1]) * mat_f[m, MF_TINT + 1]
    fb = fresnel_conductor(cos_i, mat_f[m, MF_N + 2], mat_f[m, MF_K + 2]) * mat_f[m, MF_TINT + 2]
    _mirror(kids, c, dx, dy, dz, nx, ny, nz, cos_i, fr * scale, fg * scale, fb * scale)
    return 1


@njit(**JIT)
def coat(ior, dx, dy, dz, nx, ny, nz, cos_i, scale, kids, c):
    """The mirror branch of a dielectric coat of index ``ior`` over a diffuse base; returns the
    fraction ``1 - R`` that reaches the base."""
    refl, _ = fresnel_dielectric(cos_i, ior)
    _mirror(kids, c, dx, dy, dz, nx, ny, nz, cos_i, refl * scale, refl * scale, refl * scale)
    return 1.0 - refl


@njit(**JIT)
def keep_sides(kids, nk, dx, dy, dz, fx, fy, fz, eta):
    """Send every child whose direction is on the wrong side of the geometric surface (normal
    ``f``, facing the incident side; ``eta`` transmitted / incident index) for its medium the
    way the smooth geometric surface would: a reflection along the geometric mirror direction,
    a refraction along the geometric refraction (mirrored across the tangent plane where the
    geometric surface reflects totally). Weights are kept (module doc). Mirroring a bent
    direction instead leaves rays that creep along the wall at grazing angles until a hit is
    lost to rounding."""
    cos_i = -(dx * fx + dy * fy + dz * fz)
    for c in range(nk):
        x, y, z = kids[c, KD_X], kids[c, KD_Y], kids[c, KD_Z]
        d = x * fx + y * fy + z * fz
        want = 1.0 if kids[c, K_SIDE] < 0.5 else -1.0
        if d * want > 0.0:
            continue
        if want > 0.0:
            x, y, z = dx + 2.0 * cos_i * fx, dy + 2.0 * cos_i * fy, dz + 2.0 * cos_i * fz
        else:
            _, cos_t = fresnel_dielectric(cos_i, eta)
            if cos_t > 0.0:
                q = cos_i / eta - cos_t
                x, y, z = dx / eta + q * fx, dy / eta + q * fy, dz / eta + q * fz
            elif d != 0.0:
                x, y, z = x - 2.0 * d * fx, y - 2.0 * d * fy, z - 2.0 * d * fz
            else:
                x, y, z = x - 1e-9 * fx, y - 1e-9 * fy, z - 1e-9 * fz
        h = math.sqrt(x * x + y * y + z * z)
        kids[c, KD_X], kids[c, KD_Y], kids[c, KD_Z] = x / h, y / h, z / h
