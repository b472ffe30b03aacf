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
from engine.appearance.dieline import flat_shape
from engine.appearance.frame import Placement, label_frame
from engine.appearance.placement import check_one
from engine.appearance.report import label_report
from engine.errors import DesignError
from engine.geometry import plan_girth
from engine.geometry.crosssection import Outline
from engine.geometry.plan import flask, hexagon, shield
from engine.geometry.section import Section
from engine.geometry.validate import validate_shape
from engine.model.design import Environment, Label, LabelSide

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


# ---------------------------------------------------------------------------------- die-lines
def test_a_label_on_a_flat_panel_is_a_plain_rectangle_lying_on_the_panel():
    design = _flacon()
    shape = design.shape
    lab = _label(shape, 30.0)  # the flat facing polar angle 30 deg (a vertex at 0)
    check_one(shape, lab)
    p = Placement.of(lab)
    flat = flat_shape(shape, p)
    assert flat.kind == "rectangle" and flat.figures == {"kind": "rectangle", "width_mm": 25.0, "height_mm": 40.0}
    assert flat.strain.max() == 0.0
    s, t = np.meshgrid(np.linspace(0, 1, 11), np.linspace(0, 1, 11))
    q = label_frame(shape, p).points(s, t)
    # every point on the panel's plane, and the label's width laid straight across it
    a = math.radians(30.0 + shape.rotation_deg)
    apothem = K_BODY * math.cos(math.pi / 6) + 3.5
    np.testing.assert_allclose(q[..., 0] * math.cos(a) + q[..., 1] * math.sin(a), apothem, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(q[:, -1] - q[:, 0], axis=-1), 25.0, rtol=1e-9)
    np.testing.assert_allclose(q[0, :, 2] - q[-1, :, 2], 40.0, rtol=1e-12)
    report = label_report(dataclasses.replace(design, labels=(lab,)), 0)
    assert report.area_mm2 == pytest.approx(1000.0, rel=1e-12) and report.warnings == ()


def test_a_label_wrapping_a_rounded_corner_rolls_flat_and_keeps_its_width_round_the_girth():
    """Across the 3.5 mm corner at polar angle 0 (a straight prism there: still a rectangle, no
    warning, a corner of 3 mm or more is fine for paper); its edges are 25 mm apart round the
    section at every height, which the girth says exactly."""
    design = _flacon()
    shape = design.shape
    lab = _label(shape, 0.0)
    p = Placement.of(lab)
    frame = label_frame(shape, p)
    assert flat_shape(shape, p).kind == "rectangle"
    t = np.linspace(0.0, 1.0, 9)
    (th0, _), (th1, _) = frame.surface(np.zeros_like(t), t), frame.surface(np.ones_like(t), t)
    arc = plan_girth.girth_length(shape.plan, K_BODY, 3.5, th1) - plan_girth.girth_length(shape.plan, K_BODY, 3.5, th0)
    np.testing.assert_allclose(arc, 25.0, rtol=1e-12)
    assert th0.min() < 0 < th1.max()  # it straddles theta = 0
    assert label_report(dataclasses.replace(design, labels=(lab,)), 0).warnings == ()


def test_a_label_on_the_flask_follows_the_girth_of_its_curved_front():
    """outline_public_2 (a four-arc flask plan, an asymmetric section in its own frame): a label
    on the front is a rectangle on a straight prism, its width round the girth at every height."""
    design = spec_to_design(os.path.join(SPECS, "outline_public_2.json"))[0]
    shape = design.shape
    lab = _label(shape, -90.0, z_mm=50.0, height_mm=60.0, width_mm=60.0)
    check_one(shape, lab)
    frame = label_frame(shape, Placement.of(lab))
    t = np.linspace(0.0, 1.0, 7)
    (th0, z), (th1, _) = frame.surface(np.zeros_like(t), t), frame.surface(np.ones_like(t), t)
    k, c = frame.wall.radii(z)
    np.testing.assert_allclose(plan_girth.girth_length(shape.plan, k, c, th1)
                               - plan_girth.girth_length(shape.plan, k, c, th0), 60.0, rtol=1e-12)
    s, tt = frame.st(0.5 * (th0 + th1), z)
    np.testing.assert_allclose(tt, t, atol=1e-9)
    assert flat_shape(shape, Placement.of(lab)).kind == "rectangle"


# ---------------------------------------------------------------------------------- warnings
def test_a_label_across_a_sharp_plan_corner_is_warned_where_it_creases():
    design = _flacon(rounding=0.01)
    shape = design.shape
    on_corner = _label(shape, 0.0, name="corner")
    # centred 6 mm round the girth past the corner: the corner a quarter of its 24 mm from the left
    past = math.degrees(float(plan_girth.theta_at_length(shape.plan, K_BODY, 0.01, 6.0)))
    shifted = _label(shape, past, name="shifted", width_mm=24.0)
    panel = _label(shape, 30.0, name="panel")
    d = dataclasses.replace(design, labels=(on_corner, shifted, panel))
    for lab in d.labels:
        check_one(shape, lab)
    (w,) = label_report(d, 0).warnings
    assert w.kind == "corner" and w.message == "crosses a sharp corner of the plan (60 deg, a crease) at z = 40.0 mm, 30 deg"
    assert (w.z_mm, w.angle_deg, w.s, w.t, w.x_mm, w.y_mm) == pytest.approx((40.0, 30.0, 0.5, 0.5, 0.0, 0.0), abs=1e-9)
    (w,) = label_report(d, 1).warnings
    assert w.s == pytest.approx(0.25, abs=1e-6) and w.x_mm == pytest.approx(-6.0, abs=1e-4)
    assert w.angle_deg == pytest.approx(30.0, abs=1e-6)
    assert label_report(d, 1).flat.kind == "rectangle"  # it still rolls flat: a fold, no stretch
    assert label_report(d, 2).warnings == ()  # the flat panel between two creases


def test_a_tight_rounded_corner_is_warned_with_its_radius():
    design = _flacon(rounding=1.5)
    lab = _label(design.shape, 120.0)
    (w,) = label_report(dataclasses.replace(design, labels=(lab,)), 0).warnings
    assert w.message == "wraps a corner of 1.5 mm radius (tighter than 3 mm) at z = 40.0 mm, 150 deg"


def test_an_outline_label_off_its_wall_or_round_more_than_once_is_refused():
    shape = _flacon().shape
    with pytest.raises(DesignError, match="a label wraps at most once around"):
        check_one(shape, _label(shape, 0.0, width_mm=206.0))  # the girth is 205.6 mm
    with pytest.raises(DesignError, match="reaches above the mouth"):
        check_one(shape, _label(shape, 0.0, z_mm=100.0, height_mm=40.0))
    check_one(shape, _label(shape, 0.0, width_mm=205.0))  # all but once round


# ---------------------------------------------------------------------------------- the tracer
def test_the_tracer_draws_a_label_on_a_flacons_panel():
    """A red label on the panel facing the camera (-y; the flacon unrotated): rays straight at
    the panel meet paper (0.7 x red in a white furnace) inside the label and glass outside."""
    from engine.tracer.context import RenderContext, trace_rays
    from engine.tracer.tables.environment import EnvironmentMap

    design = _flacon()
    shape = dataclasses.replace(design.shape, rotation_deg=0.0)
    d = dataclasses.replace(design, shape=shape, labels=(_label(shape, -90.0),), lights=())
    ctx = RenderContext.from_design(d, {}, 8, 8, environment=EnvironmentMap(np.ones((8, 16, 3), np.float32)))
    xz = [(0.0, 40.0), (-11.0, 58.0), (11.0, 22.0), (-20.0, 40.0), (0.0, 66.0), (16.0, 40.0)]
    out, counters = trace_rays(ctx, np.array([[x, -500.0, z] for x, z in xz]), np.tile([0.0, 1.0, 0.0], (6, 1)))
    np.testing.assert_allclose(out[:3], np.tile(0.7 * np.array(RED), (3, 1)), rtol=1e-5)
    assert np.all(out[3:, 1] > 0.5)  # the glass, not the red paper
    assert counters[1] == 0 and counters[2] == 0  # no leaks, no medium mismatches


def test_a_label_edit_on_an_outline_bottle_does_not_rebuild_its_scene():
    from engine.tracer.job import RenderJob
    from engine.tracer.job_options import Replaces

    def job(d, **kw):
        out = RenderJob(d, {}, width=24, height=32, spp=2, threads=1, **kw).start()
        out.wait()
        assert out.error is None
        return out

    design = _flacon()
    lab = _label(design.shape, 30.0 + 60.0 * 3)  # a panel facing the spec's camera
    d = dataclasses.replace(design, labels=(lab,), environment=Environment())  # the built-in studio
    first = job(d)
    d2 = dataclasses.replace(d, labels=(dataclasses.replace(lab, front=LabelSide(None, (0.1, 0.2, 0.9))),))
    rel, full = job(d2, replaces=Replaces(first, {"labels"})), job(d2)
    assert rel.context.geometry is first.context.geometry  # the scene was not rebuilt
    np.testing.assert_array_equal(rel.image(), full.image())
    assert not np.array_equal(rel.image(), first.image())  # and the new colour shows
