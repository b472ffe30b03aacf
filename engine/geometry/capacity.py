"""Trade numbers: brimful and filled capacity, fill point, glass volume and mass, sizes.

Design rule: every volume is the integral over height of a cross-section area,
``V = int A(z) dz``, split into pieces between the heights of all joints (of every section, inner
and outer, base and wall), so that inside a piece each radius is an analytic function of z. Each
piece is integrated by Gauss-Legendre after the substitution ``z = za + (zb - za)(1 - cos(pi x))/2``,
which turns the square-root behaviour of r(z) where a section turns horizontal (foot arcs,
the top of a punt) into a smooth integrand; 24 nodes give ~1e-12 relative. A punt's dome is
taken off as the disk ``pi rho_b(z)^2`` of the base curve at that height. Where the area's formula
changes inside a segment (an outline's cavity where its rounding less the wall passes 0:
:attr:`~engine.geometry.crosssection.CrossSection.area_breaks`) that height is a joint too.

Units: mm in, ml (= cm^3 = 1000 mm^3) and grams out. Results are cached per shape (shapes are
hashable), so the GUI can ask for them on every edit.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from .chain import radii_at
from .offset import BodyProfile
from .validate import body_profile

MM3_PER_ML = 1000.0
#: Soda-lime container glass (g/cm^3).
DEFAULT_DENSITY_G_CM3 = 2.52

_X, _W = np.polynomial.legendre.leggauss(24)
_X, _W = (_X + 1.0) / 2.0, _W / 2.0                      # nodes and weights on [0, 1]
_SUB_Z = (1.0 - np.cos(math.pi * _X)) / 2.0              # z fraction at each node
_SUB_W = _W * (math.pi / 2.0) * np.sin(math.pi * _X)     # weight times dz/dx / (zb - za)


def _joints(chains, z_lo: float, z_hi: float, extra=()) -> np.ndarray:
    zs = [z_lo, z_hi, *extra] + [p for c in chains for s in c for p in (s.p0[1], s.p1[1])]
    z = np.unique(np.clip(np.asarray(zs, float), z_lo, z_hi))
    return z


#: Samples per segment where a radius is looked for crossing an area break.
_BREAK_SAMPLES = 65


def _crossings(chain, value: float) -> list[float]:
    """Heights (mm) where the z-rising ``chain``'s radius passes ``value``: every sign change of
    ``r - value`` between :data:`_BREAK_SAMPLES` samples per segment, bisected to float64 (a
    segment that only touches the value changes no formula's side)."""
    out = []
    t = np.linspace(0.0, 1.0, _BREAK_SAMPLES)
    for seg in chain:
        f = seg.point(t)[:, 0] - value
        for j in np.nonzero(np.signbit(f[:-1]) != np.signbit(f[1:]))[0]:
            lo, hi = t[j], t[j + 1]
            below = np.signbit(f[j])
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if np.signbit(seg.point(mid)[0] - value) == below:
                    lo = mid
                else:
                    hi = mid
            out.append(float(seg.point(0.5 * (lo + hi))[1]))
    return out


@lru_cache(maxsize=64)  # why: a fill height's Newton steps integrate the same cavity again and again
def area_breaks(prof: BodyProfile, which: str) -> tuple[float, ...]:
    """Heights (mm) where the cross-section's area changes formula (its ``area_breaks``)."""
    walls = [sp.inner_wall if which == "inner" else sp.outer_wall for sp in prof.sections]
    return tuple(z for i, value in prof.xs.area_breaks for z in _crossings(walls[i], value))


def section_radii_at(prof: BodyProfile, z, which: str):
    """``(radii, dome)`` at heights ``z`` (mm): the cavity's (``which="inner"``) or outer solid's
    section radii per named section (mm, the kind's :mod:`~engine.geometry.crosssection` radii)
    and, for a punt, the radius (mm) of the dome's disk under the base curve at each height (0
    above the dome; ``None`` without a punt). Heights outside a chain take its end's radius."""
    walls = [sp.inner_wall if which == "inner" else sp.outer_wall for sp in prof.sections]
    if not prof.punt:  # round only: the dome under the base curve
        return _chain_radii(walls, z), None
    base = prof.sections[0].inner_base if which == "inner" else prof.sections[0].outer_base
    *radii, rho = _chain_radii(walls + [base], z)
    return radii, np.where(np.asarray(z) < base[0].p0[1], rho, 0.0)


def _chain_radii(chains, z) -> list:
    """Each z-monotone chain's radius (mm) at the heights ``z`` (mm), those outside it taking its
    end's radius (one pass: :func:`~engine.geometry.chain.radii_at`)."""
    return radii_at(chains, [np.clip(z, *sorted((ch[0].p0[1], ch[-1].p1[1]))) for ch in chains])


def _area_at(prof: BodyProfile, z, which: str) -> np.ndarray:
    """Area (mm^2) of the cavity (``which="inner"``) or outer solid at heights ``z`` (mm)."""
    radii, dome = section_radii_at(prof, z, which)
    a = prof.xs.area(radii)
    return a if dome is None else a - math.pi * dome ** 2


def _chains(prof: BodyProfile, which: str):
    if which == "inner":
        return [c for sp in prof.sections for c in (sp.inner_wall, sp.inner_base)]
    return [c for sp in prof.sections for c in (sp.outer_wall, sp.outer_base)]


def _nodes(prof: BodyProfile, which: str, z_lo: float, z_hi: float):
    """``(joints, z, dz)``: the joints from ``z_lo`` to ``z_hi`` (mm) and, per piece between
    them, the quadrature's heights ``z`` (mm, ``(pieces, 24)``) and the piece's height ``dz``
    (mm): ``dz * (f(z) @ _SUB_W)`` is each piece's ``int f dz``."""
    joints = _joints(_chains(prof, which), z_lo, z_hi, area_breaks(prof, which))
    za, zb = joints[:-1, None], joints[1:, None]
    return joints, za + (zb - za) * _SUB_Z, zb[:, 0] - za[:, 0]


def _integrate(prof: BodyProfile, which: str, z_lo: float, z_hi: float, power: int = 0) -> np.ndarray:
    """Volumes (mm^3) of each piece between joints from ``z_lo`` to ``z_hi``, and the joints;
    with ``power`` 1 the pieces' moments ``int z A(z) dz`` (mm^4) instead."""
    joints, z, dz = _nodes(prof, which, z_lo, z_hi)
    a = _area_at(prof, z.ravel(), which).reshape(z.shape) * z ** power
    return joints, dz * (a @ _SUB_W)


def volume_and_moment_mm(shape, which: str, z_lo: float, z_hi: float) -> tuple[float, float]:
    """``(V, M)``: the volume (mm^3) of the cavity (``which="inner"``) or the outer solid
    (``"outer"``) between heights ``z_lo`` and ``z_hi`` (mm), and its first moment
    ``int z A(z) dz`` (mm^4) about the standing plane, by the same exact quadrature as every
    volume here (so ``M / V`` is the piece's centre of gravity height, mm)."""
    prof = body_profile(shape)
    if z_hi <= z_lo:
        return 0.0, 0.0
    return (float(_integrate(prof, which, z_lo, z_hi)[1].sum()),
            float(_integrate(prof, which, z_lo, z_hi, power=1)[1].sum()))


def plan_moment_mm(shape, which: str, z_lo: float, z_hi: float) -> tuple[float, float]:
    """``(M_x, M_y)``: the first moments (mm^4) in the plan (the bottle's own frame, before
    ``rotation_deg``) of the cavity (``which="inner"``) or the outer solid between heights
    ``z_lo`` and ``z_hi`` (mm): ``int M(z) dz`` of the sections' moments
    (:meth:`~engine.geometry.crosssection.CrossSection.moment`) by the same quadrature as the
    volume, so ``M / V`` is the piece's centre of gravity in the plan (mm). 0 for a
    :attr:`~engine.geometry.crosssection.CrossSection.centred` kind, without integrating."""
    prof = body_profile(shape)
    if prof.xs.centred or z_hi <= z_lo:
        return 0.0, 0.0
    _, z, dz = _nodes(prof, which, z_lo, z_hi)
    radii, _ = section_radii_at(prof, z.ravel(), which)  # a punt's dome is round: centred
    mx, my = (float(np.sum(dz * (np.reshape(m, z.shape) @ _SUB_W))) for m in prof.xs.moment(radii))
    return mx, my


@lru_cache(maxsize=64)
def _cavity_table(shape):
    """Joints and cumulative cavity volume (mm^3) at each, from the inner base up."""
    prof = body_profile(shape)
    joints, vols = _integrate(prof, "inner", prof.z_ib, prof.z_top)
    return prof, joints, np.concatenate([[0.0], np.cumsum(vols)])


def _cavity_below_mm3(shape, z: float) -> float:
    prof, joints, cum = _cavity_table(shape)
    if z <= prof.z_ib:
        return 0.0
    if z >= prof.z_top:
        return float(cum[-1])
    i = int(np.searchsorted(joints, z, side="right")) - 1
    _, part = _integrate(prof, "inner", joints[i], z)
    return float(cum[i] + part.sum())


@lru_cache(maxsize=64)
def _cavity_moments_table(shape):
    """Joints and the cavity's cumulative ``(V, M_z, M_x, M_y)`` (mm^3, mm^4) at each, from the
    inner base up (the moments of :func:`volume_and_moment_mm` and :func:`plan_moment_mm`)."""
    prof = body_profile(shape)
    joints, z, dz = _nodes(prof, "inner", prof.z_ib, prof.z_top)
    return prof, joints, np.vstack([np.zeros(4), np.cumsum(_piece_moments(prof, z, dz), axis=1).T])


def _piece_moments(prof: BodyProfile, z, dz) -> np.ndarray:
    """``(4, pieces)``: each piece's cavity volume (mm^3) and moments ``int z A``, ``int M_x``,
    ``int M_y`` (mm^4) on the quadrature heights ``z`` (mm) of :func:`_nodes` (one radii call)."""
    radii, dome = section_radii_at(prof, z.ravel(), "inner")
    a = prof.xs.area(radii)
    a = np.reshape(a if dome is None else a - math.pi * dome ** 2, z.shape)
    mx, my = (np.reshape(m, z.shape) for m in prof.xs.moment(radii))  # a punt's dome is round: centred
    return np.array([dz * (f @ _SUB_W) for f in (a, a * z, mx, my)])


def cavity_moments_below_mm(shape, z: float) -> tuple[float, float, float, float]:
    """``(V, M_z, M_x, M_y)``: the cavity's volume (mm^3) from its inner base up to height ``z``
    (mm, clamped to the cavity) and its first moments about the standing plane and in the plan
    (mm^4, the bottle's own frame): :func:`volume_and_moment_mm` and :func:`plan_moment_mm` of
    ``("inner", z_ib, z)`` by the same quadrature, the whole pieces below ``z`` cached per shape
    (a tilted liquid's level search asks for many heights of one cavity)."""
    prof, joints, cum = _cavity_moments_table(shape)
    z = min(max(float(z), prof.z_ib), prof.z_top)
    i = min(int(np.searchsorted(joints, z, side="right")) - 1, len(joints) - 1)
    if z <= joints[i]:
        return tuple(float(v) for v in cum[i])
    zz = joints[i] + (z - joints[i]) * _SUB_Z
    return tuple(float(v) for v in cum[i] + _piece_moments(prof, zz[None, :], np.array([z - joints[i]]))[:, 0])


def brimful_ml(shape) -> float:
    """Cavity volume (ml) from the inner base up to the mouth ``z_top`` (the brimful capacity)."""
    return float(_cavity_table(shape)[2][-1]) / MM3_PER_ML


def capacity_ml(shape, fill_height_mm: float) -> float:
    """Liquid volume (ml) when filled to ``fill_height_mm`` above z = 0 (clamped to the cavity)."""
    return _cavity_below_mm3(shape, float(fill_height_mm)) / MM3_PER_ML


@lru_cache(maxsize=256)  # why: a drag checks the fill and then shows its numbers, same shape
def fill_height_for_volume(shape, ml: float) -> float:
    """Height of the liquid surface when the bottle holds ``ml`` millilitres.

    Parameters
    ----------
    shape : BottleShape
        The bottle (validated, results cached per shape).
    ml : float
        Liquid volume (ml), between 0 and :func:`brimful_ml`.

    Returns
    -------
    float
        Fill height (mm above z = 0), solved by Newton steps on ``V(h) - ml`` (``dV/dh`` is the
        cavity area) inside the piece that holds it, to 1e-10 mm.

    Raises
    ------
    ValueError
        For a negative volume or one above the brimful capacity.
    """
    prof, joints, cum = _cavity_table(shape)
    target = float(ml) * MM3_PER_ML
    if not (0.0 <= target <= cum[-1] * (1 + 1e-12)):
        raise ValueError(f"{ml:g} ml does not fit: the brimful capacity is {cum[-1] / MM3_PER_ML:.6g} ml")
    i = min(int(np.searchsorted(cum, target, side="right")) - 1, len(joints) - 2)
    z0 = float(joints[i])
    lo, hi = z0, float(joints[i + 1])
    h = lo + (hi - lo) * (target - cum[i]) / max(cum[i + 1] - cum[i], 1e-300)
    for _ in range(60):
        f = cum[i] - target + (_integrate(prof, "inner", z0, h)[1].sum() if h > z0 else 0.0)
        lo, hi = (h, hi) if f <= 0 else (lo, h)
        area = float(_area_at(prof, np.array([h]), "inner")[0])
        h_new = h - f / area if area > 0 else 0.5 * (lo + hi)
        if not lo <= h_new <= hi:
            h_new = 0.5 * (lo + hi)
        if abs(h_new - h) < 1e-10 or hi - lo < 1e-10:
            return float(h_new)
        h = h_new
    return float(h)


def fill_point_below_top_mm(shape, ml: float) -> float:
    """How far (mm) below the mouth the liquid stands when the bottle holds ``ml`` (the fill point)."""
    return float(shape.z_top) - fill_height_for_volume(shape, ml)


@lru_cache(maxsize=64)
def _outer_volume_mm3(shape) -> float:
    prof = body_profile(shape)
    return float(_integrate(prof, "outer", 0.0, prof.z_top)[1].sum())


def glass_volume_cm3(shape) -> float:
    """Volume of glass (cm^3): the outer solid less the cavity up to the mouth."""
    return (_outer_volume_mm3(shape) - float(_cavity_table(shape)[2][-1])) / MM3_PER_ML


def glass_mass_g(shape, density_g_cm3: float = DEFAULT_DENSITY_G_CM3) -> float:
    """Mass of the glass (g) at ``density_g_cm3`` (soda-lime glass: 2.52 g/cm^3)."""
    return glass_volume_cm3(shape) * float(density_g_cm3)


@lru_cache(maxsize=64)
def max_diameter_mm(shape) -> float:
    """Largest outside width (mm) through the axis: twice the largest circumradius of any
    horizontal cross-section (the diagonal of a rounded square, the long axis of an oval)."""
    prof = body_profile(shape)
    walls = [sp.outer_wall for sp in prof.sections]
    z = np.unique(np.concatenate([s.point(np.linspace(0, 1, 257))[:, 1] for w in walls for s in w]))

    def radius(zz):
        zz = np.asarray(zz, float)
        return prof.xs.circumradius(_chain_radii(walls, zz))

    r = radius(z)
    j = int(np.argmax(r))
    lo, hi = z[max(j - 1, 0)], z[min(j + 1, len(z) - 1)]
    for _ in range(60):  # golden-section refinement of the maximum between neighbouring samples
        m1, m2 = hi - 0.618034 * (hi - lo), lo + 0.618034 * (hi - lo)
        r1, r2 = radius(np.array([m1, m2]))  # both in one call: each the value it has alone
        if r1 >= r2:
            hi = m2
        else:
            lo = m1
    return 2.0 * float(max(r[j], radius(0.5 * (lo + hi))))


def height_mm(shape) -> float:
    """Overall height (mm): from the standing plane z = 0 to the mouth."""
    return float(shape.z_top)
