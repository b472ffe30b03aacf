"""Closed forms of the plant's numbers: the cases ``benchmarks.plant`` and ``tests/test_plant``
check the engine against (issue 43's list, each to 1e-6 relative).

Each case is computed here independently of :mod:`engine.plant`: volumes and moments as
polynomial integrals of a frustum's area, the tilted liquid's centroid in a cylinder from its
plane's equation, the membrane stresses of the textbook cylinder and sphere. Units: mm, g, MPa, deg.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from numpy.polynomial import Polynomial as P
from scipy.optimize import brentq

from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.shape import BottleShape
from engine.model.design import Design, Liquid, Plant

GLASS_G_MM3 = 2.52e-3


def cylinder_section(r: float = 30.0, h: float = 150.0) -> Section:
    """A flat base and a straight wall, radius ``r``, height ``h`` (mm)."""
    return Section((Line((0, 0), (r, 0)), Line((r, 0), (r, h))), (False,))


def cylinder(r=30.0, h=150.0, wall=3.0, base=6.0, liquid=None, **plant) -> Design:
    """A round cylinder design (mm) with ``liquid`` and the plant's settings ``plant``."""
    shape = BottleShape("round", {"profile": cylinder_section(r, h)}, wall, base)
    return Design(shape=shape, liquid=liquid, plant=Plant(**plant))


def frustum_moments(a: float, s: float, z0: float, z1: float) -> tuple[float, float]:
    """Volume and z-moment (mm^3, mm^4) of the solid of radius ``a + s z`` on ``[z0, z1]``:
    polynomial integrals, exact."""
    area = math.pi * P([a, s]) ** 2
    v, m = area.integ(), (area * P([0, 1])).integ()
    return v(z1) - v(z0), m(z1) - m(z0)


def cylinder_glass(r, h, w, b) -> tuple[float, float]:
    """``(mass g, centre height mm)`` of a cylinder's glass."""
    vo, mo = frustum_moments(r, 0.0, 0.0, h)
    vi, mi = frustum_moments(r - w, 0.0, b, h)
    return (vo - vi) * GLASS_G_MM3, (mo - mi) / (vo - vi)


def cylinder_moving_tip_deg(r, h, w, b, h0, rho_l=1.0) -> float:
    """The tip angle (deg) of a capped cylinder holding liquid ``h0`` mm deep, its surface level:
    the liquid under the plane z = b + h0 + tan(phi) x has its centroid at
    x = tan(phi) rho^2 / (4 h0), z = b + h0/2 + tan(phi)^2 rho^2 / (8 h0)."""
    rho = r - w
    mg, zg = cylinder_glass(r, h, w, b)
    ml = math.pi * rho * rho * h0 * rho_l * 1e-3

    def margin(phi):
        t = math.tan(phi)
        xc, zc = t * rho * rho / (4 * h0), b + h0 / 2 + t * t * rho * rho / (8 * h0)
        cu, cz = ml * xc / (mg + ml), (mg * zg + ml * zc) / (mg + ml)
        return (cu - r) * math.cos(phi) + cz * math.sin(phi)

    phi = brentq(margin, 1e-6, 1.5, xtol=1e-14)
    if not (h0 - rho * math.tan(phi) > 0 and h0 + rho * math.tan(phi) < h - b):
        raise ValueError("the tilted surface leaves the closed form's regime")
    return math.degrees(phi)


def cone_design(r0=20.0, r1=45.0, h=160.0, f=12.0, w=3.0, b=8.0):
    """A cone standing on its narrow end (radius ``r0`` at the base, ``r1`` at ``h``) with a
    straight finish ``f`` mm high; returns ``(design, exact empty tip deg, exact centre mm)``."""
    sec = Section((Line((0, 0), (r0, 0)), Line((r0, 0), (r1, h)), Line((r1, h), (r1, h + f))), (False, False))
    s = (r1 - r0) / h
    a_in = r0 - w * math.sqrt(1 + s * s)  # the wall offset along its normal
    z_join = (r1 - w - a_in) / s  # where the inner cone meets the finish's inner wall
    vo, mo = map(sum, zip(frustum_moments(r0, s, 0.0, h), frustum_moments(r1, 0.0, h, h + f)))
    vi, mi = map(sum, zip(frustum_moments(a_in, s, b, z_join), frustum_moments(r1 - w, 0.0, z_join, h + f)))
    z_cg = (mo - mi) / (vo - vi)
    return Design(shape=BottleShape("round", {"profile": sec}, w, b)), math.degrees(math.atan(r0 / z_cg)), z_cg


def sphere_flask(radius=60.0, zc=55.0, neck=15.0, t=3.0) -> BottleShape:
    """A sphere-like flask: a spherical body of outer ``radius`` about (0, ``zc``) standing on a
    flat foot, a straight neck of radius ``neck`` (mm)."""
    foot = math.sqrt(radius ** 2 - zc ** 2)
    z_neck = zc + math.sqrt(radius ** 2 - neck ** 2)
    sec = Section((Line((0, 0), (foot, 0)), Arc((0, zc), radius, (foot, 0), (neck, z_neck), "ccw"),
                   Line((neck, z_neck), (neck, z_neck + 30))), (False, False))
    return BottleShape("round", {"profile": sec}, t, 6.0)


@dataclass(frozen=True)
class Case:
    """One closed form: ``value()`` runs the engine, ``exact`` is the closed form's figure."""

    name: str
    value: Callable[[], float]
    exact: float


def closed_form_cases() -> list[Case]:
    """Every closed-form case of issue 43, each an engine figure and its exact value."""
    from engine.plant import membrane
    from engine.plant.sheet import plant_numbers

    def state(design, i, key):
        return lambda: plant_numbers(design)["states"][i][key]

    def stress(shape, p, key):
        return lambda: max(q[key] for q in membrane.membrane_stresses(shape, p)["points"] if q[key] is not None)

    r, h, w, b = 30.0, 150.0, 3.0, 6.0
    mg, zg = cylinder_glass(r, h, w, b)
    cone, cone_tip, cone_cg = cone_design()
    cases = [Case("cylinder empty tip_deg", state(cylinder(r, h, w, b), 0, "tip_deg"),
                  math.degrees(math.atan(r / zg))),
             Case("cylinder empty cg_z_mm", state(cylinder(r, h, w, b), 0, "cg_z_mm"), zg),
             Case("cylinder empty mass_g", state(cylinder(r, h, w, b), 0, "mass_g"), mg),
             Case("cone on its narrow end tip_deg", state(cone, 0, "tip_deg"), cone_tip),
             Case("cone on its narrow end cg_z_mm", state(cone, 0, "cg_z_mm"), cone_cg)]
    for h0 in (40.0, 70.0, 100.0):
        liquid = Liquid(fill_mode="height", fill_value=b + h0)
        cases.append(Case(f"cylinder liquid {h0:g} mm, level surface tip_deg",
                          state(cylinder(r, h, w, b, liquid), 1, "tip_deg"), cylinder_moving_tip_deg(r, h, w, b, h0)))
    p, rc, t = 1.2, 40.0, 3.0
    cyl = cylinder(rc, h, t, b).shape
    cases += [Case("cylinder hoop p r/t", stress(cyl, p, "hoop_mpa"), p * (rc - t / 2) / t),
              Case("cylinder meridional p r/(2t)", stress(cyl, p, "meridional_mpa"), p * (rc - t / 2) / (2 * t))]
    thin = cylinder(rc, h, 0.3, b).shape
    cases.append(Case("very thin cylinder hoop p r/t", stress(thin, p, "hoop_mpa"), p * (rc - 0.15) / 0.3))
    flask = sphere_flask()
    for key in ("hoop_mpa", "meridional_mpa"):
        cases.append(Case(f"sphere-like flask {key} p R/(2t)", stress(flask, 2.0, key), 2.0 * (60.0 - 1.5) / 6.0))
    return cases
