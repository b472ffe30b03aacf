"""Outline bottles (SPEC_outline): the shape, its profile and validation, and the tracer's walls.

The walls are checked against an independent evaluation of their implicit function: the plan
outline's signed distance (engine.geometry.plan, numpy) at the core and rounding the profiles
give at the hit's height, ``sd(q, k(z) P) - c(z)`` (less the wall inside); a hit lies on it to
rounding, and its normal is that function's gradient, taken by central differences.
"""
from __future__ import annotations

import dataclasses
import math
import os

import numpy as np
import pytest

from benchmarks.oracle_spec import spec_to_design
from engine.errors import SectionError, WallError
from engine.geometry.offset import radius_at
from engine.geometry.validate import body_profile, validate_shape
from engine.tracer.context import nearest_hits
from engine.tracer.tables.render_objects import build_render_geometry

SPECS = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "oracle", "specs")
PUBLIC = ("outline_public_1", "outline_public_2")


def _design(name):
    return spec_to_design(os.path.join(SPECS, f"{name}.json"))[0]


def _implicit(shape, prof, which):
    """``f(p)`` (mm) of the outer (``which="outer"``) or inner wall, positive outside it."""
    a = math.radians(shape.rotation_deg)
    walls = [sp.outer_wall if which == "outer" else sp.inner_wall for sp in prof.sections]

    def f(p):
        k, c = (float(radius_at(w, np.clip(p[2], w[0].p0[1], w[-1].p1[1]))) for w in walls)
        x, y = math.cos(a) * p[0] + math.sin(a) * p[1], -math.sin(a) * p[0] + math.cos(a) * p[1]
        return float(shape.plan.signed_distance(np.array(x), np.array(y), k, c)[0])
    return f


def _check_hits(f, o, d, t, normals, z_lo, z_hi):
    """Every hit on the wall (away from its ends) lies on ``f = 0`` and carries its gradient."""
    checked = 0
    for i in range(len(o)):
        p = o[i] + t[i] * d[i]
        if not (z_lo + 0.05 < p[2] < z_hi - 0.05):
            continue
        assert abs(f(p)) < 1e-9, f"hit {p} is {f(p)} mm off the wall"
        h = 1e-5
        g = np.array([(f(p + h * e) - f(p - h * e)) / (2 * h) for e in np.eye(3)])
        g /= np.linalg.norm(g)
        assert abs(abs(float(g @ normals[i])) - 1.0) < 1e-8
        checked += 1
    return checked


@pytest.mark.parametrize("name", PUBLIC)
def test_the_public_outline_bottles_validate_and_their_cavity_is_the_plan_offset(name):
    shape = _design(name).shape
    prof = validate_shape(shape)
    assert [sp.name for sp in prof.sections] == ["core", "round"]
    core, rnd = prof.sections
    assert core.inner_wall[0].p0[1] == pytest.approx(shape.base_thickness)
    # the inner rounding is the outer one moved by the wall, not offset
    z = np.linspace(shape.base_thickness + 1, shape.z_top - 1, 50)
    np.testing.assert_allclose(radius_at(rnd.inner_wall, z), radius_at(rnd.outer_wall, z) - shape.wall_thickness,
                               atol=1e-9)
    np.testing.assert_allclose(radius_at(core.inner_wall, z), radius_at(core.outer_wall, z), atol=1e-9)


@pytest.mark.parametrize("name", PUBLIC)
def test_rays_meet_the_outline_walls_exactly_and_never_leave_the_cavity_unseen(name):
    design = _design(name)
    shape = design.shape
    prof = body_profile(shape)
    geom = build_render_geometry(shape, None)
    rng = np.random.default_rng(4)
    n = 600
    # from outside, aimed at the bottle: the outer wall
    z = rng.uniform(1.0, prof.z_top - 1.0, n)
    a = rng.uniform(0.0, 2 * np.pi, n)
    o = np.stack([300 * np.cos(a), 300 * np.sin(a), z + rng.uniform(-60, 60, n)], 1)
    d = np.stack([rng.uniform(-20, 20, n), rng.uniform(-20, 20, n), z], 1) - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    t, k, _, normals = nearest_hits(geom, o, d)
    on = k == geom.names.index("outer wall")
    assert on.sum() > n // 3
    assert _check_hits(_implicit(shape, prof, "outer"), o[on], d[on], t[on], normals[on], 0.0, prof.z_top) > 100
    # from inside the cavity, every way out crosses the inner wall or base first (no leak)
    # (a vertical wall's outer and inner band outlines coincide: their ends, computed apart,
    # once crossed by an ulp and hid the crossing from about one ray in 4,000)
    m = 8000
    o = np.stack([rng.uniform(-3, 3, m), rng.uniform(-3, 3, m), rng.uniform(prof.z_ib + 1, 90, m)], 1)
    a, el = rng.uniform(0.0, 2 * np.pi, m), rng.uniform(-0.6, 0.6, m)
    d = np.stack([np.cos(a) * np.cos(el), np.sin(a) * np.cos(el), np.sin(el)], 1)
    t, k, _, normals = nearest_hits(geom, o, d)
    names = {geom.names[j] for j in k}
    assert names <= {"inner wall", "inner base"}, names
    on = k == geom.names.index("inner wall")
    on[n:] = False
    assert _check_hits(_implicit(shape, prof, "inner"), o[on], d[on], t[on], normals[on], prof.z_ib,
                       prof.z_top) > 300


def test_an_outline_bottle_without_room_for_its_cavity_is_refused_with_the_height():
    shape = _design("outline_public_1").shape
    thick = dataclasses.replace(shape, wall_thickness=9.5, base_thickness=10.0)
    with pytest.raises(WallError, match="cavity at z = .* mm"):
        validate_shape(thick)


def test_only_the_core_may_reach_the_axis():
    shape = _design("outline_public_1").shape
    core, rnd = shape.section("core"), shape.section("round")
    swapped = shape.with_section("round", core).with_section("core", rnd)
    with pytest.raises(SectionError, match="round"):
        validate_shape(swapped)


def test_an_outline_bottle_needs_its_plan_and_no_other_kind_has_one():
    shape = _design("outline_public_1").shape
    with pytest.raises(ValueError, match="plan outline"):
        dataclasses.replace(shape, plan=None)
    with pytest.raises(ValueError, match="plan outline"):
        dataclasses.replace(_design("public_1").shape, plan=shape.plan)


def test_the_mouth_of_an_outline_bottle_is_its_roundings_circle_and_its_bore_is_checked_there():
    from engine.model.advice import bore_mm, design_warnings
    design = _design("outline_public_1")
    shape = design.shape
    assert shape.r_mouth == pytest.approx(9.0)  # the core has vanished: the rounding's circle
    assert body_profile(shape).r_top == pytest.approx(9.0)
    assert bore_mm(shape) == pytest.approx(2 * (9.0 - 3.0))
    assert not any("bore" in w for w in design_warnings(design))
