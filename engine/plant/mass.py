"""Masses and centres of gravity of a bottle's parts, upright and with the liquid tilted.

Design rule: every mass is a density times an exact volume of :mod:`engine.geometry.capacity`
(the integral over height of a cross-section's area), and every centre of gravity the same
integral's first moment. A :class:`Part` is a mass (g) at a point (mm) of the bottle's own frame:
``z`` above the standing plane and ``(x, y)`` in the plan (before ``rotation_deg``). The
sections' plan moments are exact too (:func:`engine.geometry.capacity.plan_moment_mm`): 0 on
a centrally symmetric plan (every fixed kind), off the axis on an outline that is not (a shield,
a flask with unequal ends). The closure and the labels are taken on the axis (a label's own
offset from the axis moves the centre by under a thousandth of a mm for any label stock: it is
not modelled).

The liquid in a tilted bottle keeps its surface level (:func:`tilted_liquid`). In the bottle's
frame, tilted by ``phi`` toward the plan direction ``u``, the liquid fills the cavity below the
plane ``z cos(phi) - (p . u) sin(phi) = L``; at each height that is the part of the cavity's
cross-section with ``p . u >= d(z) = (z cos(phi) - L) / sin(phi)``. Its area and first moment
have closed forms on a circle (a circular segment: ``A = rho^2 acos(d/rho) - d sqrt(rho^2 - d^2)``,
``M_u = 2/3 (rho^2 - d^2)^(3/2)``); so has an oval (the unit disc's segment mapped by
``diag(a, b)``), a rounded rectangle (Green's theorem along its four sides and four quarter
arcs, each arc's integrals in closed form over the angles it keeps) and an outline (the same
along its section's own lines and arcs, :meth:`engine.geometry.plan.PlanOutline.section_pieces`,
of any sign of the rounding): :mod:`.clip`. Only the band of heights the surface plane crosses
is clipped, on Gauss nodes of its own (the integrands are C^1 there: their kinks, where the
surface meets the wall, go as a 3/2 power); an outline's band is split where the plane passes
a joint of its section or touches an arc (:func:`_events`: a corner crossing the cut is a kink
of the cut's length, which would cost the quadrature its order). Below the band the upright
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
from ..geometry.capacity import area_breaks  # the heights the capacity cuts at too
from ..geometry.validate import body_profile
from . import clip

#: Gauss panels per piece between joints for the tilted liquid (each 24 nodes, cosine-spaced).
SUB_PANELS = 2
#: Samples per piece between joints where an outline's cut events are looked for: at least
#: :data:`EVENT_SAMPLES`, and :data:`EVENT_SAMPLES_PER_MM` a mm (once per plan direction:
#: :func:`_event_grid`); each sign change then solved to :data:`EVENT_TOL_MM`.
EVENT_SAMPLES = 17
EVENT_SAMPLES_PER_MM = 4
EVENT_TOL_MM = 1e-10
#: g/mm^3 per g/cm^3 (and per g/ml).
G_PER_MM3 = 1e-3

_X, _W = np.polynomial.legendre.leggauss(24)
_X, _W = (_X + 1.0) / 2.0, _W / 2.0
_SUB_Z = (1.0 - np.cos(math.pi * _X)) / 2.0
_SUB_W = _W * (math.pi / 2.0) * np.sin(math.pi * _X)


@dataclass(frozen=True)
class Part:
    """A mass (g) whose centre of gravity is ``cg_z_mm`` above the standing plane and at
    ``(cg_x_mm, cg_y_mm)`` in the plan (mm, the bottle's own frame)."""

    mass_g: float
    cg_z_mm: float
    cg_x_mm: float = 0.0
    cg_y_mm: float = 0.0

    def along(self, psi: float) -> float:
        """The centre's reach (mm) along the plan direction ``psi`` (rad, own frame)."""
        return self.cg_x_mm * math.cos(psi) + self.cg_y_mm * math.sin(psi)


def combined(parts) -> Part:
    """The parts as one: their total mass and its centre of gravity (``Part(0, 0)`` for none)."""
    parts = [p for p in parts if p is not None and p.mass_g > 0]
    m = sum(p.mass_g for p in parts)
    if m <= 0:
        return Part(0.0, 0.0)
    return Part(m, *(sum(p.mass_g * getattr(p, f) for p in parts) / m
                     for f in ("cg_z_mm", "cg_x_mm", "cg_y_mm")))


def glass_part(shape, density_g_cm3: float) -> Part:
    """The glass: the outer solid from the standing plane to the mouth less the cavity."""
    prof = body_profile(shape)
    solids = (("outer", 0.0, shape.z_top), ("inner", prof.z_ib, prof.z_top))
    (v_out, m_out), (v_in, m_in) = (capacity.volume_and_moment_mm(shape, *s) for s in solids)
    (x_out, y_out), (x_in, y_in) = (capacity.plan_moment_mm(shape, *s) for s in solids)
    v = v_out - v_in
    return Part(v * density_g_cm3 * G_PER_MM3, (m_out - m_in) / v, (x_out - x_in) / v, (y_out - y_in) / v)


def liquid_part(shape, height_mm: float, density_g_ml: float) -> Part:
    """The liquid standing upright up to ``height_mm`` above the standing plane."""
    prof = body_profile(shape)
    top = min(height_mm, prof.z_top)
    v, m = capacity.volume_and_moment_mm(shape, "inner", prof.z_ib, top)
    if v <= 0:
        return Part(0.0, prof.z_ib)
    mx, my = capacity.plan_moment_mm(shape, "inner", prof.z_ib, top)
    return Part(v * density_g_ml * G_PER_MM3, m / v, mx / v, my / v)


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
    prof = body_profile(shape)
    chains = [c for sp in prof.sections for c in (sp.inner_wall, sp.inner_base)]
    zs = [prof.z_ib, prof.z_top, *area_breaks(prof, "inner")] + \
        [p for c in chains for s in c for p in (s.p0[1], s.p1[1])]
    joints = np.unique(np.clip(np.asarray(zs, float), prof.z_ib, prof.z_top))
    z = np.linspace(prof.z_ib, prof.z_top, 4097)
    radii, _ = capacity.section_radii_at(prof, z, "inner")
    reach = float(np.max(prof.xs.circumradius(radii))) * (1 + 1e-9) + 1e-9
    return _Cavity(prof.xs, prof, joints, prof.z_ib, prof.z_top, reach)


def _nodes(cav: _Cavity, za: float, zb: float, events=()):
    """Gauss nodes and weights (mm) on ``[za, zb]``: split at the cavity's joints and at the
    heights ``events`` (mm), each piece into :data:`SUB_PANELS` panels, 24 cosine-spaced nodes a
    panel."""
    inner = np.union1d(cav.joints, np.asarray(events, float))
    cuts = np.concatenate([[za], inner[(inner > za) & (inner < zb)], [zb]])
    edges = np.concatenate([np.linspace(a, b, SUB_PANELS + 1)[:-1] for a, b in zip(cuts[:-1], cuts[1:])]
                           + [cuts[-1:]])
    lo, hi = edges[:-1, None], edges[1:, None]
    return (lo + (hi - lo) * _SUB_Z).ravel(), ((hi - lo) * _SUB_W).ravel()


@dataclass(frozen=True)
class _EventGrid:
    """An outline cavity's event offsets for one plan direction ``psi`` (rad), sampled once:
    per sign of the rounding (``grown``, its own list of columns: :func:`.clip.outline_events`)
    the sample heights ``z`` (mm, rising), the piece between joints each lies in (``piece``) and
    the offsets ``e`` (mm, ``(samples, columns)``) of the places where the clipped area changes
    formula, along ``u`` (``outline_events`` at ``d = 0``: a cut ``d`` passes one where
    ``e - d`` changes sign). The offsets do not depend on the tilt or the level, only on ``u``."""

    cav: _Cavity
    psi: float
    tables: tuple  # ((grown, z, piece, e), ...)


@lru_cache(maxsize=32)
def _event_grid(shape, psi: float) -> _EventGrid:
    """The event offsets of ``shape``'s outline cavity along the plan direction ``psi`` (rad) on
    :data:`EVENT_SAMPLES` (or :data:`EVENT_SAMPLES_PER_MM` a mm) samples per piece between its
    joints, ends included (cached: a tip angle's tilts and levels all look along one ``psi``)."""
    cav = _cavity(shape)
    a, b = cav.joints[:-1], cav.joints[1:]
    counts = np.maximum(EVENT_SAMPLES, np.ceil(EVENT_SAMPLES_PER_MM * (b - a)).astype(int) + 1)
    z = np.concatenate([np.linspace(lo, hi, n) for lo, hi, n in zip(a, b, counts)])
    piece = np.repeat(np.arange(len(a)), counts)
    grown = capacity.section_radii_at(cav.prof, 0.5 * (a + b), "inner")[0][1] >= 0
    k, r = capacity.section_radii_at(cav.prof, z, "inner")[0]
    tables = []
    for sign in (True, False):
        rows = grown[piece] == sign
        if rows.any():
            e = clip.outline_events(cav.xs.plan, k[rows], r[rows], sign, psi, np.zeros(int(rows.sum())))
            tables.append((sign, z[rows], piece[rows], e))
    return _EventGrid(cav, psi, tuple(tables))


def _events(grid: _EventGrid, za: float, zb: float, cut) -> np.ndarray:
    """Heights (mm) in about ``[za, zb]`` where the cut ``p . u >= cut(z)`` (mm) passes a joint of
    an outline cavity's section or touches one of its arcs (:func:`.clip.outline_events`): there
    the clipped area changes formula, and a quadrature that does not split there loses its order
    (a corner crossing the cut is a kink of the cut's length). Every sign change of ``e - cut``
    between neighbouring samples of one piece of ``grid`` is solved, all together, by the
    Illinois method (:func:`_illinois`); ``grid`` is ``None`` for the other kinds (their arcs'
    ends are the band's ends, or quarter arcs: left as they were)."""
    if grid is None:
        return np.empty(0)
    brackets = []  # (grown, column, lo, hi, f(lo), f(hi)) per table
    for grown, z, piece, e in grid.tables:
        i0 = max(int(np.searchsorted(z, za, side="right")) - 1, 0)
        i1 = int(np.searchsorted(z, zb, side="left")) + 1
        zz, f = z[i0:i1], e[i0:i1] - cut(z[i0:i1])[:, None]
        same = (piece[i0:i1][:-1] == piece[i0:i1][1:])[:, None]
        i, j = np.nonzero(same & np.isfinite(f[:-1]) & np.isfinite(f[1:]) & (np.signbit(f[:-1]) != np.signbit(f[1:])))
        brackets.append((np.full(len(i), grown), j, zz[i], zz[i + 1], f[i, j], f[i + 1, j]))
    grown, col, lo, hi, flo, fhi = (np.concatenate(parts) for parts in zip(*brackets))
    if not len(lo):
        return lo

    def values(z, which):
        """The bracket ``which``'s functions ``e - cut`` (mm) at heights ``z`` (mm)."""
        k, r = capacity.section_radii_at(grid.cav.prof, z, "inner")[0]
        out = np.empty(len(z))
        for sign in (True, False):
            rows = grown[which] == sign
            if rows.any():
                e = clip.outline_events(grid.cav.xs.plan, k[rows], r[rows], sign, grid.psi, cut(z[rows]))
                out[rows] = e[np.arange(len(e)), col[which][rows]]
        return out
    return _illinois(values, lo, hi, flo, fhi)


def _illinois(values, lo, hi, flo, fhi) -> np.ndarray:
    """Roots (mm) of the functions ``values(z, which)`` (those of the brackets ``which`` at the
    heights ``z``) bracketed by ``[lo, hi]`` (their values ``flo``, ``fhi`` of opposite signs):
    regula falsi with the Illinois halving, every bracket at once (one call a step), each to
    :data:`EVENT_TOL_MM` and then left alone. A root that cannot be refined (NaN met) stays where
    it got: a split anywhere is harmless, it only helps where it lies on the event."""
    lo, hi, flo, fhi = (np.array(v, float) for v in (lo, hi, flo, fhi))
    z, side, live = 0.5 * (lo + hi), np.zeros(len(lo)), np.arange(len(lo))
    for _ in range(60):
        a, b, fa, fb = lo[live], hi[live], flo[live], fhi[live]
        with np.errstate(divide="ignore", invalid="ignore"):
            new = np.where(fb != fa, b - fb * (b - a) / (fb - fa), 0.5 * (a + b))
        new = np.clip(np.where(np.isnan(new), 0.5 * (a + b), new), a, b)
        moving = np.abs(new - z[live]) > EVENT_TOL_MM
        z[live] = new
        live = live[moving]
        if not len(live):
            break
        fm = values(z[live], live)
        fm = np.where(np.isfinite(fm), fm, 0.0)
        right = np.signbit(fm) == np.signbit(flo[live])  # the root lies in [z, hi]
        fhi[live] = np.where(right & (side[live] == 1), 0.5 * fhi[live], fhi[live])
        flo[live] = np.where(~right & (side[live] == -1), 0.5 * flo[live], flo[live])
        zl = z[live]
        lo[live], flo[live] = np.where(right, zl, lo[live]), np.where(right, fm, flo[live])
        hi[live], fhi[live] = np.where(right, hi[live], zl), np.where(right, fhi[live], fm)
        side[live] = np.where(right, 1, -1)
    return z


def _clipped(cav: _Cavity, z, d, psi: float):
    """Area (mm^2), first moment along ``u`` (mm^3) and the cut's length (mm) of the cavity's
    sections at heights ``z`` where ``p . u >= d``. A section wholly short of the cut (its
    support along ``u`` at most ``d``) keeps nothing: 0 without clipping it (as its clip is),
    most of a steep tilt's band above the shoulder."""
    radii, dome = capacity.section_radii_at(cav.prof, z, "inner")
    out = np.zeros((3, len(z)))
    keep = d < cav.xs.support(radii, psi)
    radii, d = [np.asarray(r, float)[keep] for r in radii], d[keep]
    if cav.xs.revolved:
        a, m, c = clip.segment(radii[0], d)
        if dome is not None:
            a2, m2, c2 = clip.segment(dome[keep], d)
            a, m, c = a - a2, m - m2, c - c2
    elif cav.xs.name == "oval":  # why by name: the clipped areas are this module's closed forms
        a, m, c = clip.oval(radii[0], radii[1], psi, d)
    elif cav.xs.name == "outline":
        a, m, c = clip.outline(cav.xs.plan, radii[0], radii[1], psi, d)
    else:
        a, m, c = clip.rounded_rect(*(np.asarray(v, float) for v in cav.xs.as_rect(radii)), psi, d)
    out[:, keep] = a, m, c
    return out


def tilted_liquid(shape, volume_mm3: float, phi: float, psi: float = 0.0) -> tuple[float, float, float]:
    """``(V, M_u, M_z)`` of :func:`tilted_liquid_level` (its level left out)."""
    return tilted_liquid_level(shape, volume_mm3, phi, psi)[:3]


def tilted_liquid_level(shape, volume_mm3: float, phi: float, psi: float = 0.0,
                        start_mm: float | None = None) -> tuple[float, float, float, float]:
    """``(V, M_u, M_z, L)``: the liquid of ``volume_mm3`` in the bottle tilted by ``phi`` (rad,
    0 < phi < pi/2) toward the plan direction ``psi`` (rad, the bottle's own frame), its surface
    level (module rule); its volume (mm^3), first moments along ``u`` and ``z`` (mm^4) and its
    surface ``z cos(phi) - (p . u) sin(phi) = L`` (mm). Newton's search for ``L`` starts from
    ``start_mm`` (the level at a near tilt: a search over tilts asks many close ones) or else
    from the upright fill height's; it ends where the volume is met to 1e-13 either way.

    Below the height where the surface plane leaves the cavity's reach every section is whole
    (its volume and moments are the upright ones of :mod:`engine.geometry.capacity`; its moment
    along ``u`` is 0 on a centrally symmetric plan); only the band the plane crosses,
    ``2 reach tan(phi)`` high, is clipped. The bottle is closed (capped): a liquid that reaches
    the mouth stays in."""
    cav = _cavity(shape)
    grid = _event_grid(shape, psi) if cav.xs.name == "outline" else None
    sphi, cphi = math.sin(phi), math.cos(phi)

    def parts(level):
        """``(V, M_u, M_z, dV/dlevel)`` of the liquid below the surface at ``level``."""
        za = min(max((level - cav.reach * sphi) / cphi, cav.z_ib), cav.z_top)
        zb = min(max((level + cav.reach * sphi) / cphi, cav.z_ib), cav.z_top)
        v0, mz0, mx0, my0 = capacity.cavity_moments_below_mm(shape, za)
        mu0 = mx0 * math.cos(psi) + my0 * math.sin(psi)
        if zb <= za:
            return v0, mu0, mz0, 0.0
        def cut(z):
            return (z * cphi - level) / sphi
        z, w = _nodes(cav, za, zb, _events(grid, za, zb, cut))
        a, m, c = _clipped(cav, z, cut(z), psi)
        return v0 + float(np.dot(w, a)), mu0 + float(np.dot(w, m)), mz0 + float(np.dot(w, a * z)), \
            float(np.dot(w, c)) / sphi

    lo = cav.z_ib * cphi - cav.reach * sphi
    hi = cav.z_top * cphi + cav.reach * sphi
    if volume_mm3 >= capacity.cavity_moments_below_mm(shape, cav.z_top)[0] * (1 - 1e-12):
        return (*parts(hi)[:3], hi)  # brimful: the whole cavity
    # Newton on the level (dV/dL is the surface's area), kept inside a shrinking bracket
    if start_mm is None:
        start_mm = capacity.fill_height_for_volume(shape, volume_mm3 / MM3_PER_ML) * cphi
    level = min(max(start_mm, lo), hi)
    for _ in range(60):
        v, mu, mz, slope = parts(level)
        if abs(v - volume_mm3) <= 1e-13 * volume_mm3:
            return v, mu, mz, level
        lo, hi = (level, hi) if v < volume_mm3 else (lo, level)
        step = level - (v - volume_mm3) / slope if slope > 0 else 0.5 * (lo + hi)
        level = step if lo < step < hi else 0.5 * (lo + hi)
        if hi - lo < 1e-12:
            break
    return (*parts(level)[:3], level)


def liquid_volume_mm3(shape, height_mm: float) -> float:
    """The cavity's volume (mm^3) below ``height_mm``."""
    return capacity.capacity_ml(shape, height_mm) * MM3_PER_ML
