"""Surface evaluation (engine.geometry.body): points on the surfaces, exact normals out of the glass."""
import math

import numpy as np
import pytest

from engine.geometry.body import PARTS, BottleBody
from engine.geometry.shape import BottleShape
from tests.test_offset import punt_section, spec_shape, stepped_section

TH = np.linspace(0.0, 2 * math.pi, 37)[:-1]


def shapes():
    oval = BottleShape("oval", {"half_width": stepped_section(30.0, 100.0, 12.0, 130.0, 160.0),
                                "half_depth": stepped_section(20.0, 100.0, 12.0, 130.0, 160.0)}, 2.0, 5.0,
                       rotation_deg=30.0)
    return [spec_shape(1), spec_shape(3), spec_shape(4), oval,
            BottleShape("round", {"profile": punt_section()}, 3.0, 4.0)]


def _s_values(body, part):
    if part in ("outer", "inner"):
        lo, hi = body.wall_range(part)
        return np.linspace(lo + 0.3, hi - 0.3, 29)
    return np.linspace(0.05, 0.95, 11)


@pytest.mark.parametrize("shape", shapes(), ids=["round", "square", "ellipse", "oval", "punt"])
def test_normals_are_unit_and_perpendicular_to_the_surface(shape):
    body = BottleBody(shape)
    for part in PARTS:
        s = _s_values(body, part)
        th, ss = np.meshgrid(TH, s, indexing="ij")
        p, n = body.point_normal(part, th, ss)
        np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-12)
        h = 1e-6
        for dth, ds in ((h, 0.0), (0.0, h * (10 if part in ("outer", "inner") else 1))):
            p2, _ = body.point_normal(part, th + dth, ss + ds)
            p1, _ = body.point_normal(part, th - dth, ss - ds)
            d = p2 - p1
            dn = np.linalg.norm(d, axis=-1)
            ok = dn > 1e-12
            cos = np.abs(np.sum(d * n, axis=-1))[ok] / dn[ok]
            assert np.max(cos) < 2e-4, part


@pytest.mark.parametrize("shape", shapes(), ids=["round", "square", "ellipse", "oval", "punt"])
def test_normals_face_out_of_the_glass(shape):
    body = BottleBody(shape)
    z_mid = 0.5 * (body.profile.z_ib + body.profile.z_top)
    p, n = body.point_normal("outer", TH, z_mid)
    assert np.all(np.sum(p[:, :2] * n[:, :2], axis=-1) > 0)
    p, n = body.point_normal("inner", TH, z_mid)
    assert np.all(np.sum(p[:, :2] * n[:, :2], axis=-1) < 0)
    assert np.all(body.point_normal("base_outer", TH, 0.5)[1][:, 2] < 0)
    assert np.all(body.point_normal("base_inner", TH, 0.5)[1][:, 2] > 0)
    assert np.all(body.point_normal("rim", TH, 0.5)[1][:, 2] == 1.0)


def test_parts_meet_at_their_edges():
    for shape in shapes():
        body = BottleBody(shape)
        zt = body.profile.z_top
        pairs = [(("outer", 0.0), ("base_outer", 1.0)), (("outer", zt), ("rim", 1.0)),
                 (("inner", zt), ("rim", 0.0)), (("inner", body.profile.sections[0].inner_wall[0].p0[1]),
                                                   ("base_inner", 1.0))]
        for (pa, sa), (pb, sb) in pairs:
            np.testing.assert_allclose(body.point_normal(pa, TH, sa)[0], body.point_normal(pb, TH, sb)[0],
                                       atol=1e-6, err_msg=f"{pa}/{pb}")


def test_round_wall_point_matches_revolved_section():
    body = BottleBody(spec_shape(1))
    p, n = body.point_normal("outer", 0.7, 100.0)
    assert p == pytest.approx([35 * math.cos(0.7), 35 * math.sin(0.7), 100.0])
    assert n == pytest.approx([math.cos(0.7), math.sin(0.7), 0.0])


def test_rotation_turns_the_face_normal():
    base = spec_shape(3)
    turned = BottleShape(base.cross_section, base.sections, 2.5, 5.5, rotation_deg=90.0)
    _, n = BottleBody(turned).point_normal("outer", 0.0, 50.0)
    assert n[0] == pytest.approx(0.0, abs=1e-12) and n[1] > 0.99


@pytest.mark.parametrize("shape", shapes(), ids=["round", "square", "ellipse", "oval", "punt"])
def test_wall_implicit_vanishes_on_the_wall_with_gradient_along_the_normal(shape):
    body = BottleBody(shape)
    for part in ("outer", "inner"):
        lo, hi = body.wall_range(part)
        th, z = np.meshgrid(TH, np.linspace(lo + 0.5, hi - 0.5, 17), indexing="ij")
        p, n = body.point_normal(part, th, z)
        g, grad = body.wall_implicit(part, p)
        np.testing.assert_allclose(g, 0.0, atol=1e-9)
        unit = grad / np.linalg.norm(grad, axis=-1, keepdims=True)
        sign = 1.0 if part == "outer" else -1.0  # the inner wall's normal faces the cavity, -grad
        np.testing.assert_allclose(unit, sign * n, atol=1e-6)
        # a step along the gradient changes g by |grad| * step (first order)
        h = 1e-4
        g2, _ = body.wall_implicit(part, p + h * unit)
        np.testing.assert_allclose(g2 - g, h * np.linalg.norm(grad, axis=-1), rtol=1e-3, atol=1e-9)
