"""Trade numbers (engine.geometry.capacity) against closed forms and an independent integration."""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from engine.geometry import capacity as cap
from engine.geometry.validate import body_profile
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape
from tests.test_offset import (cylinder_section, punt_section, spec_shape, sphere_section,
                               stepped_section, torus_foot_section)

REL = 1e-9


def round_shape(section, wall=3.0, base=6.0, **kw):
    return BottleShape("round", {"profile": section}, wall, base, **kw)


def test_cylinder_brimful_fill_and_glass():
    shape = round_shape(cylinder_section(30.0, 150.0), 3.0, 6.0)
    cavity = math.pi * 27.0 ** 2 * (150.0 - 6.0)
    assert cap.brimful_ml(shape) == pytest.approx(cavity / 1000, rel=REL)
    assert cap.capacity_ml(shape, 100.0) == pytest.approx(math.pi * 27.0 ** 2 * 94.0 / 1000, rel=REL)
    outer = math.pi * 30.0 ** 2 * 150.0
    assert cap.glass_volume_cm3(shape) == pytest.approx((outer - cavity) / 1000, rel=REL)
    assert cap.glass_mass_g(shape) == pytest.approx(2.52 * (outer - cavity) / 1000, rel=REL)
    assert cap.max_diameter_mm(shape) == pytest.approx(60.0, rel=1e-9)
    assert cap.height_mm(shape) == 150.0


def test_cone_frustum_cavity():
    # body a cone frustum from r=30 at z=0 to r=20 at z=100, then a vertical finish.
    sec = Section((Line((0, 0), (30, 0)), Line((30, 0), (20, 100)), Line((20, 100), (20, 140))), (False, False))
    shape = round_shape(sec, 2.0, 5.0)
    prof = body_profile(shape)
    body = prof.sections[0].inner_wall[0]
    (r0, z0), (r1, z1) = body.p0, body.p1
    frustum = math.pi * (z1 - z0) * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0
    rest = sum(math.pi * s.p0[0] ** 2 * (s.p1[1] - s.p0[1]) if s.kind == "line" and s.p0[0] == s.p1[0]
               else 0.0 for s in prof.sections[0].inner_wall[1:])
    # the concave corner's bridge arc is a tiny torus piece; integrate it independently
    arc = [s for s in prof.sections[0].inner_wall if s.kind == "arc"][0]
    x, w = np.polynomial.legendre.leggauss(40)
    t = (x + 1) / 2
    p = arc.point(t)
    dzdt = arc.tangent(t)[:, 1] * arc.length
    arc_vol = float(np.sum(w / 2 * math.pi * p[:, 0] ** 2 * dzdt))
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(frustum + rest + arc_vol, rel=REL)


def test_sphere_cap_cavity():
    r_base, c, h = 20.0, 30.0, 120.0
    big_r = math.hypot(r_base, c)
    shape = round_shape(sphere_section(r_base, c, h), 3.0, 6.0)
    rho = big_r - 3.0
    zone = math.pi * (rho ** 2 * (c - 6.0) - ((0.0) ** 3 - (6.0 - c) ** 3) / 3.0)
    expect = zone + math.pi * rho ** 2 * (h - c)
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(expect, rel=REL)


def test_torus_section_cavity():
    rb, a, h, w, bt = 20.0, 8.0, 100.0, 3.0, 4.0
    shape = round_shape(torus_foot_section(rb, a, h), w, bt)
    rho = a - w

    def prim(y):  # antiderivative of pi (rb + sqrt(rho^2 - y^2))^2 in y = z - a
        s = math.sqrt(max(rho * rho - y * y, 0.0))
        return math.pi * (rb * rb * y + rb * (y * s + rho * rho * math.asin(y / rho)) + rho * rho * y - y ** 3 / 3)

    expect = prim(0.0) - prim(bt - a) + math.pi * (rb + rho) ** 2 * (h - a)
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(expect, rel=REL)


def _t_integral(chain):
    """Independent cavity volume: sum of pi r(t)^2 z'(t) dt over segments (no z inversion)."""
    x, w = np.polynomial.legendre.leggauss(200)
    t = (x + 1) / 2
    total = 0.0
    for s in chain:
        p = s.point(t)
        h = 1e-6
        dz = (s.point(np.clip(t + h, 0, 1))[:, 1] - s.point(np.clip(t - h, 0, 1))[:, 1]) / (
            np.clip(t + h, 0, 1) - np.clip(t - h, 0, 1))
        total += float(np.sum(w / 2 * math.pi * p[:, 0] ** 2 * dz))
    return total


@pytest.mark.parametrize("n", [1, 4])
def test_spec_bottles_match_parameter_integral(n):
    shape = spec_shape(n)
    expect = _t_integral(body_profile(shape).sections[0].inner_wall)
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(expect, rel=1e-7)


def test_punt_cavity_and_glass_match_parameter_integral():
    shape = round_shape(punt_section(), 3.0, 4.0)
    sp = body_profile(shape).sections[0]
    expect = _t_integral(sp.inner_wall) + _t_integral(sp.inner_base)  # base walks down: subtracts
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(expect, rel=1e-7)
    outer = _t_integral(sp.outer_wall) + _t_integral(sp.outer_base)
    assert cap.glass_volume_cm3(shape) * 1000 == pytest.approx(outer - expect, rel=1e-7)


def _square_body(kind, radii_body, r_neck, w=2.0, bt=5.0):
    names = {"rounded_square": ("u", "v"), "rounded_rect": ("half_width", "half_depth", "corner"),
             "oval": ("half_width", "half_depth")}[kind]
    secs = {nm: stepped_section(r, 100.0, r_neck, 130.0, 160.0) for nm, r in zip(names, radii_body)}
    return BottleShape(kind, secs, w, bt)


def test_square_rect_oval_capacity_below_the_shoulder():
    w, bt, fill = 2.0, 5.0, 80.0
    u, v = 30.0, 36.0
    shape = _square_body("rounded_square", (u, v), 12.0, w, bt)
    ui, vi = u - w, v - w
    q = (math.sqrt(2) + 1) * (math.sqrt(2) * ui - vi)
    assert cap.capacity_ml(shape, fill) * 1000 == pytest.approx((4 * ui * ui - (4 - math.pi) * q * q) * (fill - bt), rel=REL)
    rect = _square_body("rounded_rect", (30.0, 20.0, 14.0), 12.0, w, bt)
    a, b, c = 28.0, 18.0, 12.0
    assert cap.capacity_ml(rect, fill) * 1000 == pytest.approx((4 * a * b - (4 - math.pi) * c * c) * (fill - bt), rel=REL)
    oval = _square_body("oval", (30.0, 20.0), 12.0, w, bt)
    assert cap.capacity_ml(oval, fill) * 1000 == pytest.approx(math.pi * 28.0 * 18.0 * (fill - bt), rel=REL)
    assert cap.max_diameter_mm(shape) == pytest.approx(2 * v, rel=1e-9)
    assert cap.max_diameter_mm(oval) == pytest.approx(60.0, rel=1e-9)


def test_fill_height_round_trips_and_fill_point():
    shape = spec_shape(2)
    full = cap.brimful_ml(shape)
    for frac in (0.01, 0.3, 0.77, 0.999):
        h = cap.fill_height_for_volume(shape, frac * full)
        assert cap.capacity_ml(shape, h) == pytest.approx(frac * full, rel=1e-9)
    ml = 0.9 * full
    assert cap.fill_point_below_top_mm(shape, ml) == pytest.approx(shape.z_top - cap.fill_height_for_volume(shape, ml))
    with pytest.raises(ValueError, match="brimful"):
        cap.fill_height_for_volume(shape, full * 1.01)
    assert cap.capacity_ml(shape, 0.0) == 0.0 and cap.capacity_ml(shape, 1e4) == pytest.approx(full)


def test_per_segment_walls_match_parameter_integral():
    shape = round_shape(stepped_section(30.0, 100.0, 12.0, 130.0, 170.0), 2.0, 6.0,
                        wall_per_segment=(4.0, 2.5, 2.0))
    sp = body_profile(shape).sections[0]
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(_t_integral(sp.inner_wall), rel=1e-7)
    assert cap.capacity_ml(shape, 50.0) * 1000 == pytest.approx(math.pi * 26.0 ** 2 * 44.0, rel=1e-9)


@pytest.mark.parametrize("which", ["cornered", "heel through ring"])
def test_cornered_punt_matches_parameter_integral(which):
    from tests.test_offset import cornered_punt_section, heel_through_ring_section
    sec = cornered_punt_section() if which == "cornered" else heel_through_ring_section()
    shape = round_shape(sec, 2.5, 4.0 if which == "cornered" else 3.0)
    sp = body_profile(shape).sections[0]
    expect = _t_integral(sp.inner_wall) + _t_integral(sp.inner_base)
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(expect, rel=1e-7)
    h = cap.fill_height_for_volume(shape, 0.001 * cap.brimful_ml(shape))
    assert cap.capacity_ml(shape, h) == pytest.approx(0.001 * cap.brimful_ml(shape), rel=1e-9)


@settings(max_examples=25, deadline=None)
@given(rb=st.floats(5.0, 40.0), a=st.floats(2.0, 15.0), h=st.floats(40.0, 300.0),
       w_frac=st.floats(0.05, 0.9), bt_extra=st.floats(0.0, 5.0))
def test_torus_foot_closed_form_over_random_bottles(rb, a, h, w_frac, bt_extra):
    w = w_frac * a
    bt = w + bt_extra
    shape = round_shape(torus_foot_section(rb, a, h), w, bt)
    rho = a - w

    def prim(y):
        y = min(max(y, -rho), 0.0)
        s = math.sqrt(max(rho * rho - y * y, 0.0))
        return math.pi * (rb * rb * y + rb * (y * s + rho * rho * math.asin(y / rho)) + rho * rho * y - y ** 3 / 3)

    expect = prim(0.0) - prim(bt - a) + math.pi * (rb + rho) ** 2 * (h - max(a, bt))
    assert cap.brimful_ml(shape) * 1000 == pytest.approx(expect, rel=1e-9)


@settings(max_examples=15, deadline=None)
@given(frac=st.floats(0.0, 1.0), n=st.sampled_from([1, 3, 4]))
def test_fill_height_inverts_capacity(frac, n):
    shape = spec_shape(n)
    ml = frac * cap.brimful_ml(shape)
    h = cap.fill_height_for_volume(shape, ml)
    assert body_profile(shape).z_ib - 1e-9 <= h <= shape.z_top + 1e-9
    assert cap.capacity_ml(shape, h) == pytest.approx(ml, rel=1e-9, abs=1e-9)
