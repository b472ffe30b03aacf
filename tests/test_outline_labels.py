"""Labels on outline (free plan) bottles: the girth they are measured along, their die-lines and
warnings, and the tracer drawing them.

The girth (engine.geometry.plan_girth, behind engine.appearance.girth) is checked against an
independent arc length: a dense polyline of the exact section boundary
(:meth:`PlanOutline.section_boundary`) whose polar angles include every joint of the section's
pieces and finely spaced points of its arcs, so its only error is the chords' on arcs (about
2e-10 of each arc), and against the closed form of a regular hexagon. The bottles are outline_public_1 (a hexagonal flacon with
straight walls below z = 70 mm, corners rounded 3.5 mm) and the same flacon with its rounding
brought down to 0.01 mm on the body (sharp plan corners: creases for paper).
"""
from __future__ import annotations

import dataclasses
import math
import os

import numpy as np
import pytest

from benchmarks.oracle_spec import spec_to_design
from engine.appearance import girth
from engine.geometry import plan_girth
from engine.geometry.crosssection import Outline
from engine.geometry.plan import flask, hexagon, shield
from engine.geometry.section import Section
from engine.geometry.validate import validate_shape
from engine.model.design import Label, LabelSide

SPECS = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "oracle", "specs")
PLANS = {"hexagon": hexagon(), "rounded hexagon": hexagon(0.1), "flask": flask(1.0, 0.6), "shield": shield()}
#: (core k, rounding r) mm: rounded corners, sharp corners (r = 0), a hair of rounding, the round
#: neck (k = 0) and the cavity's inner parallel set (r < 0, sharp inner corners).
RADII = ((30.0, 3.5), (30.0, 0.0), (25.0, 1e-3), (0.0, 4.0), (20.0, -1.0))
#: Polar angles of the reference polylines (plus the joints and the arcs' points).
DENSE = 4001
#: Step (deg of an arc's own angle) of the reference polylines' points on arcs.
ARC_STEP_DEG = 0.004
RED = (0.8, 0.05, 0.05)
#: The flacon's core on its straight body (mm).
K_BODY = 30.599564267050162


def _flacon(rounding: float | None = None):
    """outline_public_1, optionally with the rounding ``rounding`` mm on its straight body
    (up to z = 76 mm) easing into the same 9 mm neck at z = 94 mm by two tangent arcs."""
    design = spec_to_design(os.path.join(SPECS, "outline_public_1.json"))[0]
    if rounding is None:
        return design
    c, neck, z0, z1, top = rounding, 9.0, 76.0, 94.0, design.shape.z_top
    dr, dz = (neck - c) / 2, (z1 - z0) / 2
    radius = (dr * dr + dz * dz) / (2 * dr)
    mid = [c + dr, z0 + dz]
    sec = Section.from_dicts([
        {"type": "line", "p0": [0, 0], "p1": [c, 0]},
        {"type": "line", "p0": [c, 0], "p1": [c, z0]},
        {"type": "arc", "center": [c + radius, z0], "radius": radius, "p0": [c, z0], "p1": mid, "direction": "cw"},
        {"type": "arc", "center": [neck - radius, z1], "radius": radius, "p0": mid, "p1": [neck, z1],
         "direction": "ccw"},
        {"type": "line", "p0": [neck, z1], "p1": [neck, top]}])
    shape = design.shape.with_section("round", sec)
    validate_shape(shape)
    return dataclasses.replace(design, shape=shape)


def _label(shape, bottle_deg: float, **kw) -> Label:
    """A red label centred at polar angle ``bottle_deg`` of the bottle's own frame, z 40 mm,
    40 mm high and 25 mm around (the flacon's flats are 30.6 mm wide)."""
    base = dict(z_mm=40.0, angle_deg=bottle_deg + shape.rotation_deg, height_mm=40.0, width_mm=25.0,
                diffuse=0.7, specular=0.0, transmission=0.0, front=LabelSide(None, RED))
    base.update(kw)
    return Label(**base)


# ---------------------------------------------------------------------------------- the girth
def _reference_length(plan, k, r):
    """``(theta, arc length from theta = 0)`` along a polyline of the exact boundary over one
    turn, its vertices including every joint of the section's pieces and, on each arc, the
    polar angles of points every :data:`ARC_STEP_DEG` of the arc's own angle (a tiny corner arc
    is spanned by a sliver of polar angle): the chords then miss less than 1e-9 of each arc."""
    points = []
    for p in plan.inner_pieces(k, r):
        points.append(np.array([p.p0]))
        if p.kind == "arc":
            a = np.linspace(p.theta0, p.theta1, max(3, int(math.degrees(p.theta1 - p.theta0) / ARC_STEP_DEG)))
            points.append(np.stack([p.center[0] + p.radius * np.cos(a), p.center[1] + p.radius * np.sin(a)], -1))
    at = np.mod(np.arctan2(*np.concatenate(points)[:, ::-1].T), 2 * math.pi)
    theta = np.unique(np.concatenate([np.linspace(0.0, 2 * math.pi, DENSE), at]))
    x, y, _, _ = plan.section_boundary(theta, k, r)
    return theta, np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])


@pytest.mark.parametrize("plan", PLANS.values(), ids=PLANS.keys())
@pytest.mark.parametrize("k, r", RADII)
def test_the_girth_length_is_the_arc_length_of_the_exact_boundary(plan, k, r):
    theta, ref = _reference_length(plan, k, r)
    xs = Outline(plan)
    perimeter = float(xs.girth((k, r)))
    got = girth.girth_length(xs, (k, r), theta)
    assert np.max(np.abs(got - ref)) < 1e-9 * perimeter
    assert ref[-1] == pytest.approx(perimeter, rel=1e-9)
    assert np.all(np.diff(got) >= -1e-13 * perimeter)  # (some joints' angles are a rounding apart)
    uniform = girth.girth_length(xs, (k, r), np.linspace(-1.0, 7.0, 100_001))
    assert np.all(np.diff(uniform) > 0)  # increasing, even along a crease (r = 0)
    assert float(plan_girth.perimeter(plan, k, r)) == pytest.approx(perimeter, rel=1e-14)


@pytest.mark.parametrize("plan", PLANS.values(), ids=PLANS.keys())
@pytest.mark.parametrize("k, r", RADII)
def test_the_girth_length_runs_on_across_theta_0_and_turn_after_turn(plan, k, r):
    xs = Outline(plan)
    perimeter = float(xs.girth((k, r)))
    theta = np.linspace(-7.0, 13.0, 4001)
    length = girth.girth_length(xs, (k, r), theta)
    np.testing.assert_allclose(girth.girth_length(xs, (k, r), theta + 2 * math.pi), length + perimeter,
                               rtol=0, atol=1e-12 * perimeter)
    eps = 1e-9
    near = girth.girth_length(xs, (k, r), np.array([-eps, 0.0, eps]))
    assert near[1] == 0.0 and -2 * eps * (k + abs(r)) < near[0] < 0 < near[2] < 2 * eps * (k + abs(r))
    # theta_at_length is its exact inverse, both ways, on any turn
    np.testing.assert_allclose(girth.theta_at_length(xs, (k, r), length), theta, rtol=0, atol=1e-12)
    lengths = np.linspace(-2.5 * perimeter, 3.5 * perimeter, 2001)
    np.testing.assert_allclose(girth.girth_length(xs, (k, r), girth.theta_at_length(xs, (k, r), lengths)),
                               lengths, rtol=0, atol=1e-11 * perimeter)


def test_the_hexagons_girth_is_its_closed_form_and_broadcasts_over_heights():
    """Regular hexagon, a vertex at polar angle 0: half the corner arc (``c pi / 6``), then the
    flat (``k``) to the next corner; radii arrays (one per height) broadcast with theta."""
    plan = hexagon()
    k, c = np.array([30.0, 20.0, 10.0]), np.array([3.5, 0.0, 2.0])
    got = plan_girth.girth_length(plan, k[:, None], c[:, None], np.array([math.pi / 6, math.pi / 3]))
    want = np.stack([c * math.pi / 6 + k / 2, c * math.pi / 3 + k], axis=1)
    np.testing.assert_allclose(got, want, rtol=1e-14)
    assert got.shape == (3, 2)
