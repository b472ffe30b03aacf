"""The plant's numbers (engine.plant) against closed forms, where the methods are weakest.

Each closed form is computed here independently of the engine (polynomial integrals, the
cylinder's tilted-liquid centroid, the shell equations' textbook cases) and must agree to 1e-6
relative (issue 43's bar); the rules are checked at their table's joints.
"""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from engine.files.project import load_project
from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.shape import BottleShape
from engine.model.design import Design, Liquid, Plant
from engine.plant import clip, mass, membrane, rules, stability
from engine.plant.sheet import plant_numbers, summary_figures
from benchmarks.plant_cases import closed_form_cases, cone_design, cylinder, cylinder_section, sphere_flask

REL = 1e-6
RESOURCES = Path(__file__).resolve().parents[1] / "resources"
SAMPLES = sorted(RESOURCES.glob("*.glassbench"))


# ------------------------------------------------------------------------------ stability
@pytest.mark.parametrize("case", closed_form_cases(), ids=lambda c: c.name)
def test_closed_forms(case):
    """Issue 43's closed forms (benchmarks.plant_cases): cylinder and cone tip angles and
    centres, the cylinder's level liquid, cylinder and sphere membrane stresses, to 1e-6."""
    assert case.value() == pytest.approx(case.exact, rel=REL)


def test_cone_stands_on_its_narrow_ring():
    design, _, _ = cone_design()
    assert stability.ring_radii(design.shape) == (20.0,)


def test_level_liquid_runs_toward_the_edge():
    filled = plant_numbers(cylinder(liquid=Liquid(fill_mode="height", fill_value=76.0)))["states"][1]
    assert filled["tip_deg"] < filled["tip_frozen_deg"]


def test_deep_punt_stands_on_its_ring_not_the_base_edge():
    rp = (25.0 ** 2 + 18.0 ** 2) / 36.0  # a dome through (0, 18), level at the axis, and the ring (25, 0)
    sec = Section((Arc((0, 18 - rp), rp, (0, 18), (25, 0), "cw"), Arc((25, 6), 6.0, (25, 0), (31, 6), "ccw"),
                   Line((31, 6), (31, 180))), (False, True))
    d = Design(shape=BottleShape("round", {"profile": sec}, 3.0, 6.0))
    numbers = plant_numbers(d)
    assert numbers["ring"]["radius_mm"] == pytest.approx(25.0, abs=1e-12)
    empty = numbers["states"][0]
    assert empty["tip_deg"] == pytest.approx(math.degrees(math.atan(25.0 / empty["cg_z_mm"])), rel=1e-12)
    assert empty["tip_deg"] < math.degrees(math.atan(31.0 / empty["cg_z_mm"]))  # not the body's edge


def test_tilted_liquid_in_a_cylinder_a_round_cornered_square_and_a_round_oval_agree():
    """A rounded square whose corners are its half-width is a circle, and so is an oval of equal
    axes: their exact clipping (sides and quarter arcs; a mapped disc) must give the circle's
    volume and moments to rounding."""
    sec = cylinder_section()
    round_shape = BottleShape("round", {"profile": sec}, 3.0, 6.0)
    square = BottleShape("rounded_rect", {"half_width": sec, "half_depth": sec, "corner": sec}, 3.0, 6.0)
    oval = BottleShape("oval", {"half_width": sec, "half_depth": sec}, 3.0, 6.0)
    volume = math.pi * 27.0 ** 2 * 50.0
    for phi in (0.01, 0.2, 0.7):
        exact = mass.tilted_liquid(round_shape, volume, phi)
        for shape, psi in ((square, 0.0), (square, 0.4), (oval, 0.0), (oval, 1.1)):
            got = mass.tilted_liquid(shape, volume, phi, psi)
            assert got == pytest.approx(exact, rel=1e-11)


def clip_polygon(xi, eta, d):
    """Area, first moment along xi and the cut's length of polygons (counter-clockwise) where
    ``xi >= d``: the engine's edge integrals closed around each polygon (the oracle's clip)."""
    area, m2, chord = clip.edges(xi, eta, np.roll(xi, -1, axis=1), np.roll(eta, -1, axis=1), d)
    return area, m2 + d * area, np.abs(chord)


def fine_polygon_clip(a, b, r, psi, d, n):
    """The reference of the exact clip: polygons of ``n`` edges a corner arc, clipped."""
    alpha = np.linspace(0.0, 0.5 * math.pi, n + 1)
    xs, ys = [], []
    for q, (sx, sy) in enumerate(((1, 1), (-1, 1), (-1, -1), (1, -1))):
        xs.append(sx * (a - r)[:, None] + r[:, None] * np.cos(alpha + q * 0.5 * math.pi))
        ys.append(sy * (b - r)[:, None] + r[:, None] * np.sin(alpha + q * 0.5 * math.pi))
    x, y = np.concatenate(xs, axis=1), np.concatenate(ys, axis=1)
    return clip_polygon(x * math.cos(psi) + y * math.sin(psi),
                              -x * math.sin(psi) + y * math.cos(psi), d)


def test_a_rounded_rectangles_exact_clip_matches_ever_finer_polygons():
    """Area and first moment of a cut rounded rectangle (sharp corners, full-round ends, the cut
    across sides and arcs, any direction) against inscribed polygons of 1000 and 2000 edges a
    corner arc, extrapolated (their error falls as n^-2): 1e-10 of the outline's scale."""
    rng = np.random.default_rng(43)
    a = rng.uniform(5.0, 40.0, 400)
    b = a * rng.uniform(0.4, 1.3, 400)
    r = np.minimum(a, b) * rng.uniform(0.0, 1.0, 400)
    r[:20], r[20:40] = 0.0, np.minimum(a, b)[20:40]
    reach = np.hypot(a, b)
    for psi in (0.0, 0.3, math.pi / 4, 1.2, math.pi / 2, 2.5, -0.7, math.pi):
        d = rng.uniform(-1.1, 1.1, 400) * reach
        got = clip.rounded_rect(a, b, r, psi, d)
        fine, coarse = fine_polygon_clip(a, b, r, psi, d, 2000), fine_polygon_clip(a, b, r, psi, d, 1000)
        for k, scale in ((0, reach ** 2), (1, reach ** 3)):
            ref = (4.0 * fine[k] - coarse[k]) / 3.0
            assert np.max(np.abs(got[k] - ref) / scale) < 1e-10


def test_fill_can_make_a_bottle_more_or_less_stable():
    low = plant_numbers(cylinder(liquid=Liquid(fill_mode="height", fill_value=40.0)))["states"]
    assert low[1]["tip_deg"] > low[0]["tip_deg"]  # light glass, liquid low: the centre falls
    heavy = cylinder(wall=3.0, base=45.0, liquid=Liquid(fill_mode="height", fill_value=140.0))
    high = plant_numbers(heavy)["states"]
    assert high[1]["tip_deg"] < high[0]["tip_deg"]  # a heavy base, liquid high: the centre rises


def test_non_round_plan_tips_toward_its_narrow_side():
    d, _ = load_project(RESOURCES / "square.glassbench")
    ring = plant_numbers(d)["ring"]
    u = stability.ring_radii(d.shape)[0]  # the half-width across the flats
    assert ring["kind"] == "plan" and ring["least_mm"] == pytest.approx(u, rel=1e-12)
    turn = d.shape.rotation_deg
    assert (ring["least_direction_deg"] - turn) % 90.0 == pytest.approx(0.0, abs=1e-9)
    turned = dataclasses.replace(d, shape=dataclasses.replace(d.shape, rotation_deg=turn + 20.0))
    assert (plant_numbers(turned)["ring"]["least_direction_deg"] - turn) % 90.0 == pytest.approx(20.0, abs=1e-9)


# ------------------------------------------------------------------------------ membrane
def valid_points(stress):
    return [p for p in stress["points"] if p["hoop_mpa"] is not None]


def test_cylinder_membrane_stresses():
    p, r, t = 1.2, 40.0, 3.0
    stress = membrane.membrane_stresses(cylinder(r=r, wall=t).shape, p)
    pts = valid_points(stress)
    assert len(pts) > 10
    r_mid = r - t / 2
    for q in pts:
        assert q["hoop_mpa"] == pytest.approx(p * r_mid / t, rel=REL)
        assert q["meridional_mpa"] == pytest.approx(p * r_mid / (2 * t), rel=REL)
    assert stress["max_kind"] == "hoop" and stress["max_mpa"] == pytest.approx(p * r_mid / t, rel=REL)
    reasons = {q["reason"] for q in stress["points"]} - {None}
    assert {membrane.REASONS["base"], membrane.REASONS["heel"], membrane.REASONS["finish"]} <= reasons


def test_sphere_like_flask_is_a_membrane_away_from_its_joints():
    stress = membrane.membrane_stresses(sphere_flask(), 2.0)
    assert len(valid_points(stress)) >= 5
    assert any(q["reason"] == membrane.REASONS["corner"] for q in stress["points"])  # the neck joint


def test_a_thick_wall_is_marked():
    thick = membrane.membrane_stresses(cylinder(r=20.0, wall=4.0).shape, 1.2)
    assert not valid_points(thick) and thick["max_mpa"] is None
    assert any(q["reason"] == membrane.REASONS["thick"] for q in thick["points"])


def test_non_round_plan_gets_no_membrane_number():
    d, _ = load_project(RESOURCES / "square.glassbench")
    stress = plant_numbers(d)["stress"]
    assert stress["max_mpa"] is None
    assert all(q["reason"] == membrane.REASONS["plan"] for q in stress["points"] if q["z_mm"] > 1.0)


# ------------------------------------------------------------------------------ rules
@pytest.mark.parametrize("ml, tol", [(50, 3), (75, 3), (100, 3), (150, 4.5), (200, 6), (250, 6), (300, 6),
                                     (400, 8), (500, 10), (750, 10), (1000, 10), (1500, 15), (5000, 50)])
def test_capacity_tolerance_table(ml, tol):
    assert rules.capacity_tolerance_ml(ml) == pytest.approx(tol, rel=1e-12)


def test_capacity_outside_the_directive_has_no_band():
    assert rules.capacity_tolerance_ml(40.0) is None and rules.capacity_tolerance_ml(6000.0) is None


def test_capacity_band_fill_heights_hold_the_band_edges():
    from engine.geometry import capacity
    d, _ = load_project(RESOURCES / "bordeaux.glassbench")
    band = plant_numbers(d)["capacity_band"]
    assert band["tolerance_ml"] == 10.0
    assert capacity.capacity_ml(d.shape, band["fill_height_min_mm"]) == pytest.approx(band["nominal_ml"] - 10, rel=1e-9)
    assert capacity.capacity_ml(d.shape, band["fill_height_max_mm"]) == pytest.approx(band["nominal_ml"] + 10, rel=1e-9)
    assert band["fill_point_min_mm"] == pytest.approx(d.shape.z_top - band["fill_height_max_mm"])


# ------------------------------------------------------------------------------ the sheet
@pytest.mark.parametrize("path", SAMPLES, ids=[p.stem for p in SAMPLES])
def test_every_sample_has_its_plant_numbers(path):
    d, _ = load_project(path)
    numbers = plant_numbers(d)
    json.dumps(numbers, allow_nan=False)
    states = [s["state"] for s in numbers["states"]]
    assert states == (["empty", "filled", "brimful"] if d.liquid else ["empty", "brimful"])
    assert 0 < numbers["least_tip"]["deg"] < 90
    figures = summary_figures(numbers)
    assert figures["least_tip_deg"] == min(s["tip_deg"] for s in numbers["states"])


def test_limits_warn_and_tolerant_numbers_survive_a_broken_shape():
    d = cylinder(r=40.0, min_tip_deg=60.0, max_stress_mpa=5.0, min_glass_mass_g=5000.0)
    warnings = plant_numbers(d)["warnings"]
    assert len(warnings) == 3 and "60" in warnings[0] and "MPa" in warnings[1] and "5000" in warnings[2]
    assert plant_numbers(cylinder())["warnings"] == []
    broken = dataclasses.replace(d, shape=dataclasses.replace(d.shape, wall_thickness=40.0))
    numbers = plant_numbers(broken, tolerant=True)
    assert numbers["states"] in ([], None) and numbers["stress"] is None


def test_closure_and_labels_mass_count_when_known():
    from engine.model.design import Cap
    d, _ = load_project(RESOURCES / "labelled.glassbench")
    base = plant_numbers(d)["states"][0]
    heavy = dataclasses.replace(d, cap=d.cap or Cap(), plant=Plant(closure_mass_g=20.0, label_gsm=80.0))
    more = plant_numbers(heavy)["states"][0]
    label_g = sum(80e-6 * lab.width_mm * lab.height_mm for lab in d.labels)
    assert more["mass_g"] == pytest.approx(base["mass_g"] + 20.0 + label_g, rel=1e-12)
    assert more["cg_z_mm"] > base["cg_z_mm"]  # a closure on top raises the centre
