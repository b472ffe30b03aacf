"""The standing ring and the tip angle of a bottle: empty, filled to its fill point, brimful.

Design rule: a bottle stands on its **standing ring**, the outermost points of its base on the
plane z = 0 (for a punt or a heel arc that is not the base's outer edge; for a non-round plan
the cross-section of the ring radii of each named section). Tilted about the ring's edge toward
a plan direction ``u``, it tips when its centre of gravity passes over that edge: with the
edge at distance ``R(u)`` from the axis (the ring's support function) and the centre at
``(c_u, c_z)`` in the bottle's frame, the margin is

    g(phi) = (c_u - R) cos(phi) + c_z sin(phi)

(negative: it falls back), and the **tip angle** is its first zero. With every mass fixed
(the empty bottle; a brimful one, which is capped and has no room for its liquid to move; the
"frozen liquid" figure) ``c_u`` is the centre's reach along ``u`` and ``tan(phi) = (R - c_u) /
c_z``: least where the ring's edge comes nearest to the centre's foot in the plan. On a
centrally symmetric plan the centre is on the axis (``c_u = 0``) and that direction is found by
a 0.25-degree sweep of ``R(u)`` (closed form); an outline's centre may be off the axis, and its
ring's exact signed distance gives the nearest edge and its direction in closed form. A partly
filled bottle's liquid keeps its surface level as it tilts (:func:`engine.plant.mass.tilted_liquid`):
it runs toward the edge, ``c_u`` grows, and the bottle tips sooner; it is solved in the frozen
figure's least direction. See ``docs/PLANT.md`` for the derivation and its assumptions.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq

from ..geometry.chain import Z_TOL_MM
from ..geometry.segments import Arc, EllipseArc
from . import mass

#: Plan directions swept for the least frozen tip angle (deg step).
DIRECTION_STEP_DEG = 0.25
#: Tilts sampled beyond the frozen angle when the margin is still negative there.
TILT_SAMPLES = 4
#: A tilt's liquid level is sought from the levels found at tilts within this (rad): brentq's
#: last tilts are 1e-10 rad apart, and a search from the upright fill height takes five steps.
WARM_RAD = 0.05
#: A centre of gravity this near the axis (mm) is on it: a centrally symmetric outline's
#: moments are 0 to rounding, and the tie between its equal edges must not follow the noise.
ON_AXIS_MM = 1e-9


def _contact_radius(section) -> float | None:
    """Largest radius (mm) at which ``section`` touches the plane z = 0: joints on it and the
    lowest points of arcs that reach it inside their sweep (``None`` if it never does)."""
    best = None
    for s in section.segments:
        for (r, z) in (s.p0, s.p1):
            if abs(z) <= Z_TOL_MM:
                best = r if best is None else max(best, r)
        if isinstance(s, (Arc, EllipseArc)):
            d = ((-math.pi / 2 - s.angle0) * math.copysign(1.0, s.sweep)) % (2 * math.pi)
            if 0.0 < d < abs(s.sweep):
                r, z = (float(v) for v in s.point(d / abs(s.sweep)))
                if abs(z) <= Z_TOL_MM:
                    best = r if best is None else max(best, r)
    return best


def ring_radii(shape) -> tuple[float, ...]:
    """The standing ring's radius (mm) of each named section (the kind's cross-section radii)."""
    out = []
    for name, sec in shape.sections:
        r = _contact_radius(sec)
        if r is None or r <= 0:
            raise ValueError(f"section {name!r} never stands on the plane z = 0")
        out.append(r)
    return tuple(out)


def ring_support(shape, psi):
    """How far (mm) the standing ring reaches from the axis toward plan direction ``psi`` (rad,
    the bottle's own frame): the lever arm of the tipping edge."""
    return shape.xs.support(ring_radii(shape), psi)


def frozen_tip_deg(margin_mm: float, cg_z_mm: float) -> float:
    """The tip angle (deg) of fixed masses: ``atan((R - c_u) / z_cg)``, ``margin_mm = R - c_u``
    the ring's edge beyond the centre's foot (:func:`least_direction`)."""
    return math.degrees(math.atan2(margin_mm, cg_z_mm))


def least_direction(shape, at=(0.0, 0.0)) -> tuple[float, float]:
    """``(psi, margin)``: the plan direction (rad, own frame) in which the ring's edge comes
    nearest to the plan point ``at`` (mm, own frame: a centre of gravity's foot), and how near
    (mm, ``R(psi) - at . u(psi)``; negative: the point is outside the ring). With ``at`` on the
    axis: where the ring reaches least from the axis, and that reach."""
    x, y = (0.0, 0.0) if math.hypot(*at) <= ON_AXIS_MM else (float(at[0]), float(at[1]))
    radii = ring_radii(shape)
    if shape.xs.revolved:
        off = math.hypot(x, y)
        return (math.atan2(y, x) if off else 0.0), float(radii[0]) - off
    if not shape.xs.centred:  # an outline: its signed distance is exact (Euclidean, c >= 0)
        sd, gx, gy, _ = shape.xs.signed_distance(radii, x, y)
        return math.atan2(float(gy), float(gx)), -float(sd)
    psi = np.radians(np.arange(0.0, 360.0, DIRECTION_STEP_DEG))
    margin = ring_support(shape, psi) - (x * np.cos(psi) + y * np.sin(psi))
    i = int(np.argmin(margin))
    return float(psi[i]), float(margin[i])


def _level_guess(levels: dict, phi: float) -> float | None:
    """Where the liquid's level (mm) at the tilt ``phi`` (rad) is sought from, given the levels
    found at other tilts (``{tilt: level}``): on the line through the two nearest within
    :data:`WARM_RAD`, at the one if only one is, else ``None`` (the upright fill height's)."""
    near = sorted((p for p in levels if abs(p - phi) < WARM_RAD), key=lambda p: abs(p - phi))[:2]
    if len(near) == 2:
        (p0, p1), (l0, l1) = near, (levels[near[0]], levels[near[1]])
        return l0 + (l1 - l0) * (phi - p0) / (p1 - p0)
    return levels[near[0]] if near else None


def moving_tip(shape, fixed: mass.Part, liquid_mm3: float, density_g_ml: float,
               psi: float, reach_mm: float) -> float:
    """The tip angle (rad) of the bottle toward ``psi`` (rad, own frame) with the fixed parts
    ``fixed`` and ``liquid_mm3`` of liquid keeping its surface level; ``reach_mm`` is the ring's
    support in that direction."""
    liquid_g = liquid_mm3 * density_g_ml * mass.G_PER_MM3
    m = fixed.mass_g + liquid_g

    levels = {}  # tilt (rad) -> the liquid's level there (mm): where the next tilt's search starts

    @lru_cache(maxsize=None)  # why: brentq asks again for the two ends it is given
    def centre(phi):
        """``(c_u, c_z)`` (mm) of the whole at the tilt ``phi``."""
        v, mu, mz, levels[phi] = mass.tilted_liquid_level(shape, liquid_mm3, phi, psi, _level_guess(levels, phi))
        return ((fixed.mass_g * fixed.along(psi) + liquid_g * mu / v) / m,
                (fixed.mass_g * fixed.cg_z_mm + liquid_g * mz / v) / m)

    def margin(phi):
        cu, cz = centre(phi)
        return (cu - reach_mm) * math.cos(phi) + cz * math.sin(phi)

    frozen_cu, frozen_cz = centre(1e-6)
    if frozen_cu >= reach_mm:
        return 0.0  # the centre stands beyond the edge: the bottle does not stand that way
    top = math.atan2(reach_mm - frozen_cu, frozen_cz)  # the liquid runs toward the edge: no later than frozen
    if margin(top) >= 0.0:  # the usual case: one bracket, refined (the margin rises with the tilt)
        return brentq(margin, 1e-6, top, xtol=1e-10, rtol=1e-12)
    lo = top  # the liquid's centre fell as it ran: look further, upward, for the first zero
    for phi in np.linspace(top, 0.5 * math.pi - 1e-6, TILT_SAMPLES + 1)[1:]:
        if margin(phi) >= 0.0:
            return brentq(margin, lo, phi, xtol=1e-10, rtol=1e-12)
        lo = phi
    return 0.5 * math.pi
