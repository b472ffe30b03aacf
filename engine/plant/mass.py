"""Masses and centres of gravity of a bottle's parts, upright and with the liquid tilted.

Design rule: every mass is a density times an exact volume of :mod:`engine.geometry.capacity`
(the integral over height of a cross-section's area), and every centre of gravity the same
integral's first moment. A :class:`Part` is a mass (g) at a point (mm) of the bottle's own frame:
``z`` above the standing plane and ``u`` along a plan direction (the tilt's). The glass, the
closure and the labels are symmetric about the axis to the figures the plant quotes, so their
``u`` is 0 (a label's own offset from the axis moves the centre by under a thousandth of a mm
for any label stock: it is not modelled).

The liquid in a tilted bottle keeps its surface level (:func:`tilted_liquid`). In the bottle's
frame, tilted by ``phi`` toward the plan direction ``u``, the liquid fills the cavity below the
plane ``z cos(phi) - (p . u) sin(phi) = L``; at each height that is the part of the cavity's
cross-section with ``p . u >= d(z) = (z cos(phi) - L) / sin(phi)``. Its area and first moment
have closed forms on a circle (a circular segment: ``A = rho^2 acos(d/rho) - d sqrt(rho^2 - d^2)``,
``M_u = 2/3 (rho^2 - d^2)^(3/2)``); so has an oval (the unit disc's segment mapped by
``diag(a, b)``) and a rounded rectangle (Green's theorem along its four sides and four quarter
arcs, each arc's integrals in closed form over the angles it keeps). Only the band of heights the
surface plane crosses is clipped, on Gauss nodes of its own (the integrands are C^1 there:
their kinks, where the surface meets the wall, go as a 3/2 power); below it the upright
integrals apply. The level ``L`` that holds a volume is found by Newton's method (the volume's
derivative in ``L`` is the area of the surface, the cut's lengths integrated), bracketed.
Units: mm, g, g/ml.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..geometry import capacity
from ..geometry.capacity import MM3_PER_ML
from ..geometry.validate import body_profile

#: Gauss panels per piece between joints for the tilted liquid (each 24 nodes, cosine-spaced).
SUB_PANELS = 2
#: g/mm^3 per g/cm^3 (and per g/ml).
G_PER_MM3 = 1e-3

_X, _W = np.polynomial.legendre.leggauss(24)
_X, _W = (_X + 1.0) / 2.0, _W / 2.0
_SUB_Z = (1.0 - np.cos(math.pi * _X)) / 2.0
_SUB_W = _W * (math.pi / 2.0) * np.sin(math.pi * _X)


@dataclass(frozen=True)
class Part:
    """A mass (g) whose centre of gravity is ``cg_z_mm`` above the standing plane and
    ``cg_u_mm`` along the tilt's plan direction (mm)."""

    mass_g: float
    cg_z_mm: float
    cg_u_mm: float = 0.0


def combined(parts) -> Part:
    """The parts as one: their total mass and its centre of gravity (``Part(0, 0)`` for none)."""
    parts = [p for p in parts if p is not None and p.mass_g > 0]
    m = sum(p.mass_g for p in parts)
    if m <= 0:
        return Part(0.0, 0.0)
    return Part(m, sum(p.mass_g * p.cg_z_mm for p in parts) / m,
                sum(p.mass_g * p.cg_u_mm for p in parts) / m)


def glass_part(shape, density_g_cm3: float) -> Part:
    """The glass: the outer solid from the standing plane to the mouth less the cavity."""
    v_out, m_out = capacity.volume_and_moment_mm(shape, "outer", 0.0, shape.z_top)
    prof = body_profile(shape)
    v_in, m_in = capacity.volume_and_moment_mm(shape, "inner", prof.z_ib, prof.z_top)
    v = v_out - v_in
    return Part(v * density_g_cm3 * G_PER_MM3, (m_out - m_in) / v)


def liquid_part(shape, height_mm: float, density_g_ml: float) -> Part:
    """The liquid standing upright up to ``height_mm`` above the standing plane."""
    prof = body_profile(shape)
    v, m = capacity.volume_and_moment_mm(shape, "inner", prof.z_ib, min(height_mm, prof.z_top))
    return Part(v * density_g_ml * G_PER_MM3, m / v if v > 0 else prof.z_ib)


def closure_part(design) -> Part | None:
    """The closure's mass (``Design.plant.closure_mass_g``, not known: ``None``) at the middle
    of its height above the mouth (:func:`engine.appearance.closures.closure_trade`)."""
    from ..appearance.closures import closure_trade  # why: appearance reads the model, not back
    mass = design.plant.closure_mass_g
    if design.cap is None or mass <= 0:
        return None
    closure, _ = closure_trade(design)
    height = closure["height_mm"] if closure else 0.0
    return Part(mass, design.shape.z_top + 0.5 * height)


def labels_part(design) -> Part | None:
    """The labels' mass at the label stock's grammage (``Design.plant.label_gsm``, g/m^2; not
    known: ``None``): each label's width x height, centred at its height (a cap-top label at
    the mouth)."""
    gsm = design.plant.label_gsm
    if gsm <= 0 or not design.labels:
        return None
    parts = [Part(gsm * 1e-6 * lab.width_mm * lab.height_mm,
                  lab.z_mm if lab.surface == "wall" else design.shape.z_top)
             for lab in design.labels]
    return combined(parts)


# ---------------------------------------------------------------------- the tilted liquid
@dataclass(frozen=True)
class _Cavity:
    """What the tilted liquid needs of the cavity: its cross-section, profile, joints (mm), height range
    and reach (mm, the largest distance of its wall from the axis)."""

    xs: object
    prof: object
    joints: np.ndarray
    z_ib: float
    z_top: float
    reach: float


@lru_cache(maxsize=32)
def _cavity(shape) -> _Cavity:
    shape.xs.require("stability")
    prof = body_profile(shape)
    chains = [c for sp in prof.sections for c in (sp.inner_wall, sp.inner_base)]
    zs = [prof.z_ib, prof.z_top] + [p for c in chains for s in c for p in (s.p0[1], s.p1[1])]
    joints = np.unique(np.clip(np.asarray(zs, float), prof.z_ib, prof.z_top))
    z = np.linspace(prof.z_ib, prof.z_top, 4097)
    radii, _ = capacity.section_radii_at(prof, z, "inner")
    reach = float(np.max(prof.xs.circumradius(radii))) * (1 + 1e-9) + 1e-9
    return _Cavity(prof.xs, prof, joints, prof.z_ib, prof.z_top, reach)


def _nodes(cav: _Cavity, za: float, zb: float):
    """Gauss nodes and weights (mm) on ``[za, zb]``: split at the cavity's joints, each piece
    into :data:`SUB_PANELS` panels, 24 cosine-spaced nodes a panel."""
    inner = cav.joints[(cav.joints > za) & (cav.joints < zb)]
    cuts = np.concatenate([[za], inner, [zb]])
    edges = np.concatenate([np.linspace(a, b, SUB_PANELS + 1)[:-1] for a, b in zip(cuts[:-1], cuts[1:])]
                           + [cuts[-1:]])
    lo, hi = edges[:-1, None], edges[1:, None]
    return (lo + (hi - lo) * _SUB_Z).ravel(), ((hi - lo) * _SUB_W).ravel()


def _segment(rho, d):
    """Area (mm^2), first moment along u (mm^3) and the cut's length (mm) of the disk of radius
    ``rho`` where ``p.u >= d``."""
    x = np.clip(d / np.where(rho > 0, rho, 1.0), -1.0, 1.0)
    h2 = np.maximum(rho * rho - d * d, 0.0)
    h = np.sqrt(h2)
    area = rho * rho * np.arccos(x) - np.where(np.abs(d) < rho, d * h, 0.0)
    return area, (2.0 / 3.0) * h2 * h, 2.0 * h


def _clip_edges(xa, ea, xb, eb, d):
    """Per row, the sums over straight edges ``(xa, ea) -> (xb, eb)`` (counter-clockwise along
    the outline, mm) of the kept parts' Green integrals where ``xi >= d``: ``(xi - d) d eta``
    (area), ``(xi - d)^2 / 2 d eta`` (first moment about the cut) and the signed ``eta`` of the
    points where an edge crosses the cut (leaving: +, entering: -)."""
    f, f1 = xa - d[:, None], xb - d[:, None]
    de = eb - ea
    with np.errstate(divide="ignore", invalid="ignore"):  # the kept part: f0 + t (f1 - f0) >= 0
        tc = np.clip(f / (f - f1), 0.0, 1.0)
    ta = np.where(f >= 0, 0.0, np.where(f1 >= 0, tc, 1.0))
    tb = np.where(f1 >= 0, 1.0, np.where(f >= 0, tc, 0.0))
    fa, fb = f + ta * (f1 - f), f + tb * (f1 - f)
    dt = np.maximum(tb - ta, 0.0)  # an edge wholly cut away keeps nothing
    area = np.sum(de * dt * 0.5 * (fa + fb), axis=1)
    m2 = np.sum(de * dt * (fa * fa + fa * fb + fb * fb) / 6.0, axis=1)  # int f^2/2, f linear
    crossing = (f >= 0) != (f1 >= 0)
    chord = np.sum(np.where(crossing, (ea + tc * de) * np.where(f >= 0, 1.0, -1.0), 0.0), axis=1)
    return area, m2, chord


def _clip_arcs(cxi, ceta, r, t0, d):
    """The sums of :func:`_clip_edges` over quarter arcs of radius ``r`` (mm) about ``(cxi,
    ceta)``, running counter-clockwise from the angle ``t0`` (rad) through ``t0 + pi/2``; every
    array ``(rows, arcs)``, ``d`` per row. On the arc ``xi = cxi + r cos t``, ``d eta = r cos t
    dt``: the integrals are closed forms over the angles where ``cos t >= k = (d - cxi) / r``,
    the interval ``[-beta, beta]`` (mod 2 pi), ``beta = acos k``."""
    K = cxi - d[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(r > 0, -K / np.where(r > 0, r, 1.0), np.where(K >= 0, -2.0, 2.0))
    beta = np.arccos(np.clip(k, -1.0, 1.0))
    t0 = np.mod(t0 + math.pi, 2 * math.pi) - math.pi       # in [-pi, pi): one turn is enough
    t1 = t0 + 0.5 * math.pi
    area = m2 = chord = 0.0
    for shift in (0.0, 2 * math.pi):
        lo = np.maximum(t0, shift - beta)
        hi = np.minimum(t1, shift + beta)
        hi = np.maximum(hi, lo)

        def F(t):
            s, c = np.sin(t), np.cos(t)
            a = K * r * s + r * r * (0.5 * t + 0.5 * s * c)
            m = 0.5 * r * (K * K * s + K * r * (t + s * c) + r * r * (s - s ** 3 / 3.0))
            return a, m
        (a1, m1), (a0, m0) = F(hi), F(lo)
        area, m2 = area + a1 - a0, m2 + m1 - m0
        # the cut's ends on the arc: leaving at +beta, entering at -beta (inside the arc's span)
        full = (k <= -1.0) | (k >= 1.0)
        for at, sign in ((shift + beta, 1.0), (shift - beta, -1.0)):
            inside = (at >= t0) & (at < t1) & ~full
            chord = chord + np.where(inside, sign * (ceta + r * np.sin(at)), 0.0)
    return np.sum(area, axis=1), np.sum(m2, axis=1), np.sum(chord, axis=1)


def _clip_rounded_rect(a, b, r, psi: float, d):
    """Area (mm^2), first moment along ``u`` (mm^3) and the cut's length (mm) where ``p . u >= d``
    of the rounded rectangles of half-width ``a``, half-depth ``b`` and corner radius ``r``
    (arrays per row, mm), ``u`` at the angle ``psi``: four sides and four quarter arcs, exact."""
    c, s = math.cos(psi), math.sin(psi)
    A, B = a - r, b - r
    # the sides, counter-clockwise: right, top, left, bottom
    x0 = np.column_stack([a, A, -a, -A]); y0 = np.column_stack([-B, b, B, -b])
    x1 = np.column_stack([a, -A, -a, A]); y1 = np.column_stack([B, b, -B, -b])
    la, lm, lc = _clip_edges(x0 * c + y0 * s, -x0 * s + y0 * c, x1 * c + y1 * s, -x1 * s + y1 * c, d)
    cx = np.column_stack([A, -A, -A, A]); cy = np.column_stack([B, B, -B, -B])
    t0 = np.array([0.0, 0.5, 1.0, 1.5]) * math.pi - psi
    aa, am, ac = _clip_arcs(cx * c + cy * s, -cx * s + cy * c, r[:, None] + 0 * cx,
                            np.broadcast_to(t0, cx.shape), d)
    area = la + aa
    return area, lm + am + d * area, np.abs(lc + ac)


def _clip_oval(a, b, psi: float, d):
    """Area, first moment along ``u`` and the cut's length of the ellipses of half axes ``a``,
    ``b`` (mm) where ``p . u >= d``: the ellipse is the unit disc mapped by ``diag(a, b)``, so it
    is the unit disc's segment at ``d / w``, ``w = |(a cos psi, b sin psi)|``, scaled (exact)."""
    w = np.hypot(a * math.cos(psi), b * math.sin(psi))
    area, m, chord = _segment(np.ones_like(w), d / w)
    return a * b * area, a * b * w * m, chord * a * b / w


def _clipped(cav: _Cavity, z, d, psi: float):
    """Area (mm^2), first moment along ``u`` (mm^3) and the cut's length (mm) of the cavity's
    sections at heights ``z`` where ``p . u >= d``."""
    radii, dome = capacity.section_radii_at(cav.prof, z, "inner")
    if cav.xs.revolved:
        a, m, c = _segment(radii[0], d)
        if dome is not None:
            a2, m2, c2 = _segment(dome, d)
            a, m, c = a - a2, m - m2, c - c2
        return a, m, c
    if cav.xs.name == "oval":  # why by name: the clipped areas are this module's closed forms
        return _clip_oval(np.asarray(radii[0], float), np.asarray(radii[1], float), psi, d)
    a, b, c = (np.asarray(v, float) for v in cav.xs.as_rect(radii))
    return _clip_rounded_rect(a, b, c, psi, d)


def tilted_liquid(shape, volume_mm3: float, phi: float, psi: float = 0.0) -> tuple[float, float, float]:
    """``(V, M_u, M_z)``: the liquid of ``volume_mm3`` in the bottle tilted by ``phi`` (rad, 0 <
    phi < pi/2) toward the plan direction ``psi`` (rad, the bottle's own frame), its surface
    level (module rule); its volume (mm^3) and first moments along ``u`` and ``z`` (mm^4).

    Below the height where the surface plane leaves the cavity's reach every section is whole
    (its volume and moment are the upright ones of :mod:`engine.geometry.capacity`, and its
    moment along ``u`` is 0: the plans are centrally symmetric); only the band the plane crosses,
    ``2 reach tan(phi)`` high, is clipped. The bottle is closed (capped): a liquid that reaches
    the mouth stays in."""
    cav = _cavity(shape)
    sphi, cphi = math.sin(phi), math.cos(phi)

    def parts(level):
        """``(V, M_u, M_z, dV/dlevel)`` of the liquid below the surface at ``level``."""
        za = min(max((level - cav.reach * sphi) / cphi, cav.z_ib), cav.z_top)
        zb = min(max((level + cav.reach * sphi) / cphi, cav.z_ib), cav.z_top)
        v0, mz0 = capacity.volume_and_moment_mm(shape, "inner", cav.z_ib, za)
        if zb <= za:
            return v0, 0.0, mz0, 0.0
        z, w = _nodes(cav, za, zb)
        a, m, c = _clipped(cav, z, (z * cphi - level) / sphi, psi)
        return v0 + float(np.dot(w, a)), float(np.dot(w, m)), mz0 + float(np.dot(w, a * z)), \
            float(np.dot(w, c)) / sphi

    lo = cav.z_ib * cphi - cav.reach * sphi
    hi = cav.z_top * cphi + cav.reach * sphi
    top = parts(hi)
    if volume_mm3 >= top[0] * (1 - 1e-12):
        return top[:3]
    # Newton on the level (dV/dL is the surface's area), kept inside a shrinking bracket
    level = min(max(capacity.fill_height_for_volume(shape, volume_mm3 / MM3_PER_ML) * cphi, lo), hi)
    for _ in range(60):
        v, mu, mz, slope = parts(level)
        if abs(v - volume_mm3) <= 1e-13 * volume_mm3:
            return v, mu, mz
        lo, hi = (level, hi) if v < volume_mm3 else (lo, level)
        step = level - (v - volume_mm3) / slope if slope > 0 else 0.5 * (lo + hi)
        level = step if lo < step < hi else 0.5 * (lo + hi)
        if hi - lo < 1e-12:
            break
    return parts(level)[:3]


def liquid_volume_mm3(shape, height_mm: float) -> float:
    """The cavity's volume (mm^3) below ``height_mm``."""
    return capacity.capacity_ml(shape, height_mm) * MM3_PER_ML
