"""Trade numbers of outline bottles (SPEC_outline) against an independent integration.

The reference integrates the plan's exact section areas (Steiner's polynomial outside, the inner
parallel set's area where the rounding less the wall is negative) by adaptive quadrature
(scipy.integrate.quad, tight tolerances, the profiles' joints as break points) at the core and
rounding read straight off the designer's two profiles (the cavity: the rounding less the wall),
not off the body profile or the Gauss-Legendre pieces :mod:`engine.geometry.capacity` uses.
"""
from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest
from scipy.integrate import quad

from benchmarks.oracle_spec import spec_to_design
from engine.geometry import capacity
from engine.geometry.capacity import area_breaks
from engine.geometry.chain import radius_at
from engine.geometry.crosssection import Outline, cross_section_of
from engine.geometry.offset import split_at_ring
from engine.geometry.validate import body_profile
from engine.operations.trade import trade_numbers

SPECS = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "oracle", "specs")
PUBLIC = ("outline_public_1", "outline_public_2")
REL = 1e-12  # both sides reach ~1e-14; without the break joint the w = 4 mm case is off by 1e-10


def _design(name):
    return spec_to_design(os.path.join(SPECS, f"{name}.json"))[0]


def _wall(shape, name):
    return split_at_ring(shape.section(name))[1]


def _reference_mm3(shape, z_lo, z_hi, wall):
    """``int A(z) dz`` (mm^3) from ``z_lo`` to ``z_hi`` of the section with core ``k(z)`` and
    growth ``c(z) - wall``, by adaptive quadrature between the profiles' joints and where the
    growth crosses 0 (found by the quadrature's own bisection-free sampling: a dense grid)."""
    core, rnd = _wall(shape, "core"), _wall(shape, "round")

    def k_t(z):
        return float(radius_at(core, z)), float(radius_at(rnd, z)) - wall

    def area(z):
        k, t = k_t(z)
        return float(shape.plan.inner_area(k, t))

    joints = {s.p0[1] for c in (core, rnd) for s in c} | {s.p1[1] for c in (core, rnd) for s in c}
    z = np.linspace(z_lo, z_hi, 20001)
    t = np.array([k_t(v)[1] for v in z])
    joints |= set(z[1:][np.signbit(t[1:]) != np.signbit(t[:-1])])  # a grid point near each crossing
    cuts = sorted({z_lo, z_hi} | {j for j in joints if z_lo < j < z_hi})
    return sum(quad(area, a, b, epsabs=0.0, epsrel=1e-13, limit=400)[0] for a, b in zip(cuts, cuts[1:]))


def _cavity_ml(shape, z_hi):
    return _reference_mm3(shape, shape.base_thickness, z_hi, shape.wall_thickness) / 1000.0


def _glass_cm3(shape):
    return (_reference_mm3(shape, 0.0, shape.z_top, 0.0) - _cavity_ml(shape, shape.z_top) * 1000.0) / 1000.0


@pytest.mark.parametrize("name", PUBLIC)
def test_trade_numbers_of_the_public_outlines_match_adaptive_quadrature(name):
    design = _design(name)
    numbers = trade_numbers(design)
    shape = design.shape
    assert numbers["brimful_ml"] == pytest.approx(_cavity_ml(shape, shape.z_top), rel=REL)
    assert numbers["glass_volume_cm3"] == pytest.approx(_glass_cm3(shape), rel=REL)
    if numbers["fill_height_mm"] is not None:
        assert numbers["fill_ml"] == pytest.approx(_cavity_ml(shape, numbers["fill_height_mm"]), rel=REL)
    # the widest outer section: the plan's farthest point (at 1) times the core plus the rounding
    z = np.linspace(0.0, shape.z_top, 4001)
    reach = radius_at(_wall(shape, "core"), z) + radius_at(_wall(shape, "round"), z)
    assert numbers["max_diameter_mm"] == pytest.approx(2 * np.nanmax(reach), rel=1e-6)


def test_a_wall_past_the_rounding_gives_sharp_inner_corners_and_exact_volumes():
    """A 4 mm wall on outline_public_1 (rounding 3.5 mm on the body, 6 mm at the neck): the
    cavity's growth c - w passes 0 on the shoulder, where the area changes formula; that height
    is a joint of the integration, so the volumes stay exact."""
    shape = dataclasses.replace(_design("outline_public_1").shape, wall_thickness=4.0)
    prof = body_profile(shape)
    breaks = area_breaks(prof, "inner")
    assert len(breaks) == 1 and prof.z_ib < breaks[0] < prof.z_top
    k = radius_at(prof.sections[1].inner_wall, np.array(breaks))
    assert abs(float(k[0])) < 1e-9  # the cavity's rounding is 0 there
    assert capacity.brimful_ml(shape) == pytest.approx(_cavity_ml(shape, shape.z_top), rel=REL)
    assert capacity.glass_volume_cm3(shape) == pytest.approx(_glass_cm3(shape), rel=REL)
    assert capacity.capacity_ml(shape, breaks[0] + 0.3) == pytest.approx(_cavity_ml(shape, breaks[0] + 0.3), rel=REL)


def test_the_fill_height_of_an_outline_bottle_inverts_its_capacity():
    shape = _design("outline_public_2").shape
    h = capacity.fill_height_for_volume(shape, 150.0)
    assert capacity.capacity_ml(shape, h) == pytest.approx(150.0, rel=1e-12)
    assert _cavity_ml(shape, h) == pytest.approx(150.0, rel=REL)


def test_an_outline_bottle_asks_its_plan_and_offers_every_feature():
    shape = _design("outline_public_1").shape
    xs = cross_section_of(shape)
    assert xs == Outline(shape.plan) and shape.xs == xs and body_profile(shape).xs == xs
    assert not xs.revolved and xs.sections == ("core", "round")
    assert not xs.unsupported
    xs.require("relief")  # (tests/test_outline_relief.py)
    xs.require("stress")  # (tests/test_plant_outline.py)
    xs.require("cad")  # (tests/test_export_cad_outline.py)
    xs.require("drawing")  # (tests/test_drawing_outline.py)


@pytest.mark.parametrize("plan", ["public", "shield"])
def test_the_cavity_below_a_height_is_its_pieces_so_far_and_one_more(plan):
    """capacity.cavity_moments_below_mm (the tilted liquid's below-the-band part: the whole pieces
    cached, the last one integrated) against volume_and_moment_mm and plan_moment_mm from the
    inner base (every piece integrated again), at the joints, the area break, in between and
    out of range; the volume against adaptive quadrature too. A shield's centre is off the axis:
    its plan moments are not 0."""
    from engine.geometry import plan as P
    shape = dataclasses.replace(_design("outline_public_1").shape, wall_thickness=4.0)
    if plan == "shield":
        shape = dataclasses.replace(shape, plan=P.shield(1.0, 0.9, 0.3))
    prof = body_profile(shape)
    joints = capacity._cavity_moments_table(shape)[1]
    heights = [*joints, *area_breaks(prof, "inner"), *np.random.default_rng(5).uniform(prof.z_ib, prof.z_top, 12)]
    for z in heights:
        got = capacity.cavity_moments_below_mm(shape, z)
        want = (*capacity.volume_and_moment_mm(shape, "inner", prof.z_ib, z), *capacity.plan_moment_mm(shape, "inner", prof.z_ib, z))
        scale = max(abs(want[0]), 1.0), max(abs(want[1]), 1.0)
        assert all(abs(g - w) <= 1e-13 * s for g, w, s in zip(got, want, (scale[0], scale[1], scale[1], scale[1]))), (z, got, want)
    assert capacity.cavity_moments_below_mm(shape, prof.z_ib - 5.0) == (0.0, 0.0, 0.0, 0.0)
    assert capacity.cavity_moments_below_mm(shape, prof.z_top + 5.0) == capacity.cavity_moments_below_mm(shape, prof.z_top)
    z = 0.5 * (joints[2] + joints[3])
    assert capacity.cavity_moments_below_mm(shape, z)[0] == pytest.approx(_cavity_ml(shape, z) * 1000.0, rel=REL)
    mx, my = capacity.cavity_moments_below_mm(shape, prof.z_top)[2:]
    assert (abs(my) > 1.0) == (plan == "shield") and abs(mx) < 1e-6 * capacity.cavity_moments_below_mm(shape, prof.z_top)[1]
