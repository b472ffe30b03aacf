"""The CrossSection protocol's outline kind against independent references: the plan's signed
distance and exact pieces (a boundary point lies on the section and on its ray, its normal points
out), the vertices of a fine polyline of the section (support, reach, area by the shoelace), and
the fixed kinds' objects against their module-level wrappers (one implementation)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine.errors import DesignError
from engine.geometry import crosssection as cs
from engine.geometry.plan import flask, hexagon, triangle
from engine.geometry.shape import SECTION_NAMES

PLANS = {"hexagon": hexagon(), "flask": flask(1.0, 0.6), "rounded triangle": triangle(0.1)}
#: (core k, growth r) mm: grown, eroded (sharp inner corners), a sharp core and a vanished core.
RADII = ((30.0, 5.0), (30.0, -2.0), (20.0, 0.0), (0.0, 4.0))


def _polygon_area(p):
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


@pytest.mark.parametrize("plan", PLANS.values(), ids=PLANS.keys())
@pytest.mark.parametrize("k, r", RADII)
def test_an_outline_boundary_point_is_on_its_ray_and_on_the_section(plan, k, r):
    xs = cs.Outline(plan)
    theta = np.linspace(-math.pi, 3 * math.pi, 4001)
    x, y, nx, ny = xs.boundary((k, r), theta)
    assert np.max(np.abs(plan.signed_distance(x, y, k, r)[0])) < 1e-12 * (k + abs(r))
    assert np.max(np.abs(np.angle(np.exp(1j * (np.arctan2(y, x) - theta))))) < 1e-14
    assert np.allclose(np.hypot(nx, ny), 1.0, atol=1e-12)
    step = 1e-4 * (k + abs(r))
    assert np.all(plan.signed_distance(x + step * nx, y + step * ny, k, r)[0] > 0.5 * step)


@pytest.mark.parametrize("plan", PLANS.values(), ids=PLANS.keys())
@pytest.mark.parametrize("k, r", RADII)
def test_outline_support_reach_area_and_girth_match_a_fine_polyline(plan, k, r):
    xs = cs.Outline(plan)
    pts = plan.inner_polyline(k, r, max_turn_deg=0.005)  # the section's own exact pieces, sampled
    tol = 2e-8 * (k + abs(r))  # the polyline's sagitta at 0.005 deg
    psi = np.linspace(0.0, 2 * math.pi, 721)
    brute = np.max(np.cos(psi)[:, None] * pts[:, 0] + np.sin(psi)[:, None] * pts[:, 1], axis=1)
    assert np.max(np.abs(xs.support((k, r), psi) - brute)) < tol
    assert float(xs.circumradius((k, r))) == pytest.approx(np.max(np.hypot(pts[:, 0], pts[:, 1])), abs=tol)
    assert float(xs.area((k, r))) == pytest.approx(_polygon_area(pts), rel=1e-8)
    edges = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T).sum()
    assert float(xs.girth((k, r))) == pytest.approx(edges, rel=1e-8)


def test_outline_validity_circle_and_refusals():
    xs = cs.Outline(hexagon())
    bad, rule = xs.invalid((np.array([30.0, -1.0, 30.0, 1.0]), np.array([2.0, 2.0, -30.0, -2.0])))
    assert bad.tolist() == [False, True, True, True] and "core >= 0" in rule
    assert xs.is_circle((np.array([0.0, 1.0]), np.array([5.0, 5.0]))).tolist() == [True, False]
    assert xs.canonical((3.0, 1.0)) == (xs, (3.0, 1.0)) and xs.reach_bound((3.0, -1.0)) == 3.0
    for feature in ("cad", "labels", "drawing", "stability", "stress", "relief"):
        xs.require(feature)  # tests/test_export_cad_outline, _outline_labels, _drawing_outline, _plant_outline, _outline_relief

    class Limited(cs.Outline):  # the refusal a kind that lacks a feature gives
        unsupported = frozenset({"relief"})
    with pytest.raises(DesignError, match=r"^relief \(bump tiles, bands and embossing\): not supported on outline bottles yet$"):
        Limited(hexagon()).require("relief")
    cs.OVAL.require("labels")  # the fixed kinds offer everything


@pytest.mark.parametrize("kind", ["round", "rounded_square", "rounded_rect", "oval"])
def test_a_fixed_kind_is_one_object_behind_its_name(kind):
    xs = cs.of_kind(kind)
    assert xs.name == kind and xs.sections == SECTION_NAMES[kind]
    radii = {"round": (20.0,), "rounded_square": (20.0, 22.0), "rounded_rect": (20.0, 15.0, 4.0),
             "oval": (20.0, 12.0)}[kind]
    theta = np.linspace(0, 2 * math.pi, 37)
    for a, b in zip(cs.boundary(kind, radii, theta), xs.boundary(radii, theta)):
        assert np.array_equal(a, b)
    assert cs.area(kind, radii) == xs.area(radii) and cs.circumradius(kind, radii) == xs.circumradius(radii)
    canon, params = xs.canonical(radii)
    assert canon.area(params) == pytest.approx(float(xs.area(radii)), rel=1e-15)
    with pytest.raises(ValueError, match="needs its plan"):
        cs.of_kind("outline")
