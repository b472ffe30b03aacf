"""Cross-sections (engine.geometry.crosssection): areas, boundary points, normals, signed distance."""
import math

import numpy as np
import pytest

from engine.geometry import crosssection as cs

CASES = [("round", (25.0,)), ("rounded_square", (30.0, 36.0)), ("rounded_square", (30.0, 30.0)),
         ("rounded_rect", (30.0, 18.0, 7.0)), ("oval", (30.0, 18.0))]
THETA = np.linspace(0.0, 2 * math.pi, 4001)[:-1]


@pytest.mark.parametrize("kind,radii", CASES)
def test_area_matches_polygon_of_boundary(kind, radii):
    x, y, _, _ = cs.boundary(kind, radii, np.linspace(0.0, 2 * math.pi, 200001)[:-1])
    poly = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    assert float(cs.area(kind, radii)) == pytest.approx(poly, rel=1e-8)


def test_rounded_square_closed_forms():
    p, q = cs.square_corner(30.0, 36.0)
    assert p + q == pytest.approx(30.0) and math.sqrt(2) * p + q == pytest.approx(36.0)
    assert float(cs.area("rounded_square", (30.0, 36.0))) == pytest.approx(4 * 900 - (4 - math.pi) * q * q)
    assert float(cs.area("rounded_square", (20.0, 20.0))) == pytest.approx(math.pi * 400)
    assert float(cs.circumradius("rounded_square", (30.0, 36.0))) == pytest.approx(36.0)


@pytest.mark.parametrize("kind,radii", CASES)
def test_boundary_point_is_on_ray_and_surface(kind, radii):
    x, y, nx, ny = cs.boundary(kind, radii, THETA)
    np.testing.assert_allclose(np.mod(np.arctan2(y, x), 2 * math.pi), THETA, atol=1e-12)
    np.testing.assert_allclose(np.hypot(nx, ny), 1.0, atol=1e-12)
    sd, gx, gy, _ = cs.signed_distance(kind, radii, x, y)
    np.testing.assert_allclose(sd, 0.0, atol=1e-10)
    np.testing.assert_allclose(gx, nx, atol=1e-9)
    np.testing.assert_allclose(gy, ny, atol=1e-9)
    # the normal is outward: a step along it leaves the shape
    assert np.all(cs.signed_distance(kind, radii, x + 0.01 * nx, y + 0.01 * ny)[0] > 0)
    assert np.all(cs.signed_distance(kind, radii, x - 0.01 * nx, y - 0.01 * ny)[0] < 0)


@pytest.mark.parametrize("kind,radii", CASES[:4])
def test_signed_distance_is_euclidean_off_the_boundary(kind, radii):
    x, y, nx, ny = cs.boundary(kind, radii, THETA[::37])
    for d in (-2.0, 3.0):
        sd = cs.signed_distance(kind, radii, x + d * nx, y + d * ny)[0]
        np.testing.assert_allclose(sd, d, atol=1e-9)


@pytest.mark.parametrize("kind,radii", CASES)
def test_radius_derivatives_match_finite_differences(kind, radii):
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-45, 45, 400), rng.uniform(-45, 45, 400)
    _, _, _, d = cs.signed_distance(kind, radii, x, y)
    for k in range(len(radii)):
        h = 1e-6
        up = list(radii); up[k] += h
        dn = list(radii); dn[k] -= h
        fd = (cs.signed_distance(kind, up, x, y)[0] - cs.signed_distance(kind, dn, x, y)[0]) / (2 * h)
        np.testing.assert_allclose(d[k], fd, atol=1e-5)


def test_validity_rules():
    bad, rule = cs.invalid_radii("rounded_square", (np.array([30.0, 30.0, 30.0]), np.array([29.0, 36.0, 42.5])))
    assert list(bad) == [True, False, True] and "sqrt2" in rule
    bad, _ = cs.invalid_radii("rounded_rect", (30.0, 20.0, np.array([0.0, 10.0, 21.0])))
    assert list(bad) == [True, False, True]
    assert bool(cs.is_circle("rounded_rect", (12.0, 12.0, 12.0)))
    assert not bool(cs.is_circle("oval", (12.0, 11.0)))


def test_broadcasting_over_heights():
    u = np.linspace(20, 30, 5)[:, None]
    v = u * 1.1
    x, y, nx, ny = cs.boundary("rounded_square", (u, v), THETA[None, :100])
    assert x.shape == (5, 100)
    assert cs.area("rounded_square", (u[:, 0], v[:, 0])).shape == (5,)
