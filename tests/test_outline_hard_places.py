"""Where an outline bottle's walls could fail (issue 41), against references of higher precision.

A plain bottle is built per case: a regular polygon or a plan with a tiny arc or a nearly
straight corner, a straight body (so its walls are ruled slabs, solved in closed form) and a
round neck where the core vanishes. The references: the wall's plane or cylinder solved in
mpmath at 50 digits, or the implicit function evaluated independently (engine.geometry.plan).
"""
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

from engine.geometry import plan as P
from engine.geometry.section import Section
from engine.geometry.shape import BottleShape
from engine.geometry.validate import body_profile
from engine.tracer.context import nearest_hits
from engine.tracer.tables.render_objects import build_render_geometry

mp.mp.dps = 50


def _profile(points):
    """A section of straight lines through ``points`` ((r, z) mm), base first, finish last."""
    return Section.from_dicts([{"type": "line", "p0": a, "p1": b} for a, b in zip(points[:-1], points[1:])],
                              smooth=[False] * (len(points) - 2))


def _bottle(plan, k=30.0, c=4.0, wall=3.0, base=6.0, neck=9.0, height=120.0, scale=1.0):
    """A straight-bodied outline bottle scaled by ``scale``: core ``k`` up to 0.6 of its height,
    then straight to 0 (the neck); rounding ``c`` rising straight to the neck's radius."""
    s = scale
    z1, z2 = 0.6 * height * s, 0.8 * height * s
    core = _profile([(0, 0), (k * s, 0), (k * s, z1), (0, z2), (0, height * s)])
    rnd = _profile([(0, 0), (c * s, 0), (c * s, z1), (neck * s, z2), (neck * s, height * s)])
    return BottleShape("outline", (("core", core), ("round", rnd)), wall * s, base * s, plan=plan)


def _on_wall(shape, p, which="outer"):
    """The wall's implicit function at ``p`` (mm), evaluated by the plan module."""
    from engine.geometry.offset import radius_at
    prof = body_profile(shape)
    walls = [sp.outer_wall if which == "outer" else sp.inner_wall for sp in prof.sections]
    k, c = (float(radius_at(w, np.clip(p[2], w[0].p0[1], w[-1].p1[1]))) for w in walls)
    return float(shape.plan.signed_distance(np.array(p[0]), np.array(p[1]), k, c)[0])


def test_a_ray_skimming_a_flat_panel_from_100_m_meets_it_where_mpmath_does():
    shape = _bottle(P.hexagon())  # vertices at 0, 60, ... deg: a flat face towards -y, y = -(k cos 30 + c)
    geom = build_render_geometry(shape, None)
    k, c = 30.0, 4.0
    face = -(k * math.cos(math.pi / 6) + c)
    rng = np.random.default_rng(2)
    for _ in range(40):
        # from 100 m away along x, descending onto the face at a grazing angle of 1e-4 .. 1e-2 rad
        tilt = 10 ** rng.uniform(-4, -2)
        x_hit, z_hit = rng.uniform(-10, 10), rng.uniform(20, 60)
        d = np.array([math.cos(tilt), math.sin(tilt), 0.0])
        o = np.array([x_hit - 1e5 * d[0], face - 1e5 * d[1], z_hit])
        t, obj, _, n = nearest_hits(geom, o[None], d[None])
        assert geom.names[obj[0]] == "outer wall"
        # the reference: the plane y = face, in 50 digits
        t_ref = (mp.mpf(face) - mp.mpf(o[1])) / mp.mpf(d[1])
        assert abs(mp.mpf(t[0]) - t_ref) <= 1e-12 * t_ref, (tilt, t[0], t_ref)  # (1e-7 mm at 100 m)
        assert n[0] @ np.array([0.0, -1.0, 0.0]) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("c", [2.999999, 3.0, 3.000001, 2.0])
def test_sharp_and_barely_round_inner_corners_seen_edge_on_are_met_and_continuous(c):
    # rounding just below, at and above the wall: the cavity's corners are sharp (c <= w) or
    # round by a hair; a ray from the axis straight at a corner meets the inner wall there
    shape = _bottle(P.hexagon(), c=c)
    geom = build_render_geometry(shape, None)
    k, t = 30.0, c - 3.0
    # corner at angle 0: the cavity's vertex is k + t / cos(30 deg) out for a sharp one (t <= 0)
    # and k + t for a round one
    want = k + (t / math.cos(math.pi / 6) if t <= 0 else t)
    for ang in (0.0, 1e-9, -1e-9, 1e-6):
        d = np.array([math.cos(ang), math.sin(ang), 0.0])
        tt, obj, _, _ = nearest_hits(geom, np.array([[0.0, 0.0, 40.0]]), d[None])
        assert geom.names[obj[0]] == "inner wall"
        if abs(ang) <= 1e-9:  # (1e-6 rad off the bisector meets a face 1.7e-5 mm before the vertex)
            assert tt[0] == pytest.approx(want, abs=1e-7)
        p = tt[0] * d + np.array([0.0, 0.0, 40.0])
        assert abs(_on_wall(shape, p, "inner")) < 1e-9


def test_the_neck_where_the_core_vanishes_is_the_rounding_circle():
    shape = _bottle(P.octagon())
    geom = build_render_geometry(shape, None)
    rng = np.random.default_rng(5)
    z = 0.9 * 120.0  # above the core's end: the section is the circle of the rounding, 9 mm
    for a in rng.uniform(0, 2 * np.pi, 30):
        d = np.array([math.cos(a), math.sin(a), 0.0])
        tt, obj, _, n = nearest_hits(geom, np.array([[0.0, 0.0, z]]), d[None])
        assert geom.names[obj[0]] == "inner wall"
        assert tt[0] == pytest.approx(9.0 - 3.0, abs=1e-12)
        assert n[0] @ (-d) == pytest.approx(1.0, abs=1e-12)


def test_an_outline_bottle_a_thousandth_of_its_size_is_refused_for_its_cavity():
    from engine.errors import WallError
    with pytest.raises(WallError, match="no cavity margin"):
        body_profile(_bottle(P.flask(100.0, 30.0), k=20.0, c=4.0, scale=1e-3))


@pytest.mark.parametrize("scale", [0.25, 1e3])
def test_an_outline_bottle_at_a_quarter_and_a_thousand_times_its_size_is_met_alike(scale):
    # the same rays scaled: distances scale exactly (to rounding), whatever the size
    shape = _bottle(P.flask(100.0, 30.0), k=20.0, c=4.0, scale=scale)
    base = _bottle(P.flask(100.0, 30.0), k=20.0, c=4.0)
    rng = np.random.default_rng(8)
    n = 200
    o = np.stack([rng.uniform(-3, 3, n), rng.uniform(-3, 3, n), rng.uniform(10, 60, n)], 1)
    a, el = rng.uniform(0, 2 * np.pi, n), rng.uniform(-0.7, 0.7, n)
    d = np.stack([np.cos(a) * np.cos(el), np.sin(a) * np.cos(el), np.sin(el)], 1)
    t0, k0, _, n0 = nearest_hits(build_render_geometry(base, None), o, d)
    t1, k1, _, n1 = nearest_hits(build_render_geometry(shape, None), o * scale, d)
    np.testing.assert_array_equal(k0, k1)
    np.testing.assert_allclose(t1 / scale, t0, rtol=1e-9)
    np.testing.assert_allclose(n1, n0, atol=1e-9)


def test_a_tiny_arc_and_a_nearly_straight_corner_are_exact():
    # a pentagon-like plan with a 0.01 mm (at k = 30) arc at one corner and a 179.9 deg corner
    pts = [(1.0, 0.0), (0.31, 0.95), (-0.81, 0.59), (-0.81, -0.59), (0.31, -0.95)]
    # nearly straight: insert a vertex on the last edge turning by 0.1 deg
    mid = (0.5 * (pts[4][0] + pts[0][0]) + 1e-3, 0.5 * (pts[4][1] + pts[0][1]) - 4e-4)
    segs = []
    ring = pts + [mid]
    for a, b in zip(ring, ring[1:] + ring[:1]):
        segs.append({"type": "line", "p0": list(a), "p1": list(b)})
    plan = P.PlanOutline.from_dicts(segs)
    shape = _bottle(plan, c=3.5)
    geom = build_render_geometry(shape, None)
    rng = np.random.default_rng(13)
    m = 3000
    o = np.stack([rng.uniform(-2, 2, m), rng.uniform(-2, 2, m), rng.uniform(10, 60, m)], 1)
    a, el = rng.uniform(0, 2 * np.pi, m), rng.uniform(-0.5, 0.5, m)
    d = np.stack([np.cos(a) * np.cos(el), np.sin(a) * np.cos(el), np.sin(el)], 1)
    t, obj, _, _ = nearest_hits(geom, o, d)
    assert {geom.names[j] for j in obj} <= {"inner wall", "inner base"}
    for i in np.nonzero(obj == geom.names.index("inner wall"))[0][:300]:
        assert abs(_on_wall(shape, o[i] + t[i] * d[i], "inner")) < 1e-9
