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
"frozen liquid" figure) ``c_u = 0`` and ``tan(phi) = R / c_z``. A partly filled bottle's liquid
keeps its surface level as it tilts (:func:`engine.plant.mass.tilted_liquid`): it runs toward
the edge, ``c_u > 0``, and the bottle tips sooner. The least angle over directions is found on
the frozen figure (a 0.25-degree sweep of ``R(u)``, closed form), and the moving liquid is
solved in that direction. See ``docs/PLANT.md`` for the derivation and its assumptions.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ..geometry.chain import Z_TOL_MM
from ..geometry.segments import Arc, EllipseArc
from . import mass

#: Plan directions swept for the least frozen tip angle (deg step).
DIRECTION_STEP_DEG = 0.25
#: Tilts sampled beyond the frozen angle when the margin is still negative there.
TILT_SAMPLES = 4


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
    shape.xs.require("stability")  # why: the masses' centres on the axis hold for symmetric plans only
    return shape.xs.support(ring_radii(shape), psi)


def frozen_tip_deg(support_mm: float, cg_z_mm: float) -> float:
    """The tip angle (deg) of fixed masses: ``atan(R / z_cg)``."""
    return math.degrees(math.atan2(support_mm, cg_z_mm))


def least_direction(shape) -> tuple[float, float]:
    """``(psi, R)``: the plan direction (rad, own frame) where the ring reaches least from the
    axis, and that reach (mm): where a bottle with its masses on the axis tips first."""
    shape.xs.require("stability")
    if shape.xs.revolved:
        return 0.0, float(ring_radii(shape)[0])
    psi = np.radians(np.arange(0.0, 360.0, DIRECTION_STEP_DEG))
    reach = ring_support(shape, psi)
    i = int(np.argmin(reach))
    return float(psi[i]), float(reach[i])


def moving_tip(shape, fixed: mass.Part, liquid_mm3: float, density_g_ml: float,
               psi: float, reach_mm: float) -> float:
    """The tip angle (rad) of the bottle toward ``psi`` (rad, own frame) with the fixed parts
    ``fixed`` (their centre on the axis) and ``liquid_mm3`` of liquid keeping its surface level;
    ``reach_mm`` is the ring's support in that direction."""
    liquid_g = liquid_mm3 * density_g_ml * mass.G_PER_MM3

    def margin(phi):
        v, mu, mz = mass.tilted_liquid(shape, liquid_mm3, phi, psi)
        m = fixed.mass_g + liquid_g
        cu = (fixed.mass_g * fixed.cg_u_mm + liquid_g * mu / v) / m
        cz = (fixed.mass_g * fixed.cg_z_mm + liquid_g * mz / v) / m
        return (cu - reach_mm) * math.cos(phi) + cz * math.sin(phi)

    frozen_cz = (fixed.mass_g * fixed.cg_z_mm
                 + liquid_g * mass.tilted_liquid(shape, liquid_mm3, 1e-6, psi)[2] / liquid_mm3) \
        / (fixed.mass_g + liquid_g)
    top = math.atan2(reach_mm, frozen_cz)  # the liquid runs toward the edge: no later than frozen
    if margin(top) >= 0.0:  # the usual case: one bracket, refined (the margin rises with the tilt)
        return brentq(margin, 1e-6, top, xtol=1e-10, rtol=1e-12)
    lo = top  # the liquid's centre fell as it ran: look further, upward, for the first zero
    for phi in np.linspace(top, 0.5 * math.pi - 1e-6, TILT_SAMPLES + 1)[1:]:
        if margin(phi) >= 0.0:
            return brentq(margin, lo, phi, xtol=1e-10, rtol=1e-12)
        lo = phi
    return 0.5 * math.pi
