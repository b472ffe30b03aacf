"""The plant's sheet for outline (free plan) bottles (issue 41) against brute force.

The references never use the engine's closed forms: each section is the plan's exact boundary
sampled densely (``PlanOutline.inner_polyline`` at 0.005 deg a facet) and measured by the
shoelace, clipped by a half-plane with Sutherland-Hodgman, and integrated over height by
adaptive quadrature (``scipy.integrate.quad_vec``) at the core and rounding read straight off the
designer's two profiles, split at their joints and where the rounding less the wall passes 0.
The tip angle's reference turns the standing ring's dense polygon through every direction.
"""
from __future__ import annotations

import dataclasses
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad, quad_vec
from scipy.optimize import brentq, minimize_scalar
from scipy.spatial import cKDTree

from benchmarks.oracle_spec import spec_to_design
from benchmarks.plant_cases import cylinder
from engine.geometry import plan as P
from engine.geometry.body import BottleBody
from engine.geometry.chain import radius_at
from engine.geometry.offset import split_at_ring
from engine.geometry.section import Section
from engine.geometry.shape import BottleShape
from engine.model import fill
from engine.model.design import Design, Liquid
from engine.plant import clip, mass, membrane, stability, thickness
from engine.plant.sheet import plant_numbers
from tests.test_outline_hard_places import _bottle

SPECS = Path(__file__).resolve().parents[2] / "shared" / "oracle" / "specs"
TURN_DEG = 0.005  # the reference polygons' facets: a relative area error of 1e-9 at most


def _pentagon():
    """An irregular convex pentagon: no symmetry at all."""
    pts = [(1.0, 0.0), (0.3, 0.9), (-0.7, 0.6), (-0.8, -0.5), (0.2, -0.9)]
    return P.PlanOutline.from_dicts([{"type": "line", "p0": list(a), "p1": list(b)}
                                     for a, b in zip(pts, pts[1:] + pts[:1])])


def _shoelace(pts):
    """Area (mm^2) and first moments ``(M_x, M_y)`` (mm^3) of a counter-clockwise polygon."""
    x, y = pts[:, 0], pts[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    return np.array([cross.sum() / 2, ((x + x1) * cross).sum() / 6, ((y + y1) * cross).sum() / 6])


def _polygon(plan, k, r):
    return plan.inner_polyline(k, r, max_turn_deg=TURN_DEG)


def _k_c(shape):
    """The designer's core and rounding ``k(z), c(z)`` (mm), off the sections' walls."""
    core, rnd = (split_at_ring(shape.section(n))[1] for n in ("core", "round"))
    return core, rnd, (lambda z: float(radius_at(core, z))), (lambda z: float(radius_at(rnd, z)))


def _brute_solid(shape, z_lo, z_hi, wall):
    """``[V, M_x, M_y, M_z]`` (mm^3, mm^4) of the solid whose section at height z is ``k(z) P``
    grown by ``c(z) - wall``, from ``z_lo`` to ``z_hi``."""
    core, rnd, k, c = _k_c(shape)
    cuts = {z_lo, z_hi} | {p[1] for ch in (core, rnd) for s in ch for p in (s.p0, s.p1)}
    z = np.linspace(z_lo, z_hi, 4001)
    t = np.array([c(v) - wall for v in z])
    for j in np.nonzero(np.signbit(t[1:]) != np.signbit(t[:-1]))[0]:
        cuts.add(brentq(lambda v: c(v) - wall, z[j], z[j + 1], xtol=1e-14))
    cuts = sorted(v for v in cuts if z_lo <= v <= z_hi)

    def f(v):
        a = _shoelace(_polygon(shape.plan, k(v), c(v) - wall))
        return np.append(a, v * a[0])
    return sum(quad_vec(f, a, b, epsabs=0.0, epsrel=1e-12, norm="max")[0] for a, b in zip(cuts, cuts[1:]))


def _design(plan, c=4.0, fill=60.0):
    return Design(shape=_bottle(plan, c=c), liquid=Liquid(fill_mode="height", fill_value=fill))


PLANS = {"shield": P.shield(1.0, 0.9, 0.3), "pentagon": _pentagon(), "flask": P.flask(100.0, 60.0, 9.0)}


# ------------------------------------------------------------------------------ sections
@pytest.mark.parametrize("name", PLANS)
@pytest.mark.parametrize("k, r", [(30.0, 4.0), (30.0, 0.0), (30.0, -2.0), (0.0, 6.0), (12.0, -0.5)])
def test_a_sections_first_moment_is_its_dense_polygons(name, k, r):
    plan = PLANS[name]
    ref = _shoelace(_polygon(plan, k, r))
    mx, my = plan.section_moment(k, r)
    reach = k + abs(r)
    assert float(plan.inner_area(k, r)) == pytest.approx(ref[0], rel=1e-8)
    assert abs(float(mx) - ref[1]) / ref[0] < 1e-8 * reach and abs(float(my) - ref[2]) / ref[0] < 1e-8 * reach


# ------------------------------------------------------------------------------ masses
@pytest.mark.parametrize("name, c", [("shield", 4.0), ("pentagon", 2.0), ("flask", 4.0)])
def test_glass_and_liquid_volumes_and_centres_match_brute_force(name, c):
    """The pentagon's rounding (2 mm) is under the wall (3 mm): sharp inner corners up to the
    shoulder, where the rounding grows past the wall (the section's formula changes there)."""
    design = _design(PLANS[name], c=c)
    shape = design.shape
    w, b = shape.wall_thickness, shape.base_thickness
    outer, cavity = _brute_solid(shape, 0.0, shape.z_top, 0.0), _brute_solid(shape, b, shape.z_top, w)
    glass = mass.glass_part(shape, 2.5)
    v = outer[0] - cavity[0]
    assert glass.mass_g == pytest.approx(2.5e-3 * v, rel=1e-8)
    reach = 34.0
    for got, ref in zip((glass.cg_z_mm, glass.cg_x_mm, glass.cg_y_mm), (outer - cavity)[[3, 1, 2]] / v):
        assert abs(got - ref) < 1e-8 * reach
    fill = design.liquid.fill_value
    liquid, ref = mass.liquid_part(shape, fill, 1.0), _brute_solid(shape, b, fill, w)
    assert liquid.mass_g == pytest.approx(1e-3 * ref[0], rel=1e-8)
    for got, want in zip((liquid.cg_z_mm, liquid.cg_x_mm, liquid.cg_y_mm), ref[[3, 1, 2]] / ref[0]):
        assert abs(got - want) < 1e-8 * reach
    if name == "shield":  # symmetric about the y axis only: off the axis along y
        assert abs(glass.cg_x_mm) < 1e-12 * reach and glass.cg_y_mm > 1.0


def test_a_centrally_symmetric_hexagon_keeps_its_centres_on_the_axis():
    shape = _bottle(P.hexagon(corner_radius=0.1, rotation_deg=7.0))
    for part in (mass.glass_part(shape, 2.5), mass.liquid_part(shape, 70.0, 1.0)):
        assert math.hypot(part.cg_x_mm, part.cg_y_mm) < 1e-12 * 34.0


# ------------------------------------------------------------------------------ tipping
def _brute_tip_deg(shape, cg_xy, cg_z):
    """Turn the standing ring's dense polygon through every plan direction: the least of its
    reach beyond the centre's foot on a half-degree grid, then golden sections between the
    neighbouring directions (the reach has a kink where a flat side faces the direction)."""
    core, rnd, k, c = _k_c(shape)
    ring = shape.plan.polyline(k(0.0), c(0.0), max_turn_deg=TURN_DEG) - np.asarray(cg_xy)

    def margin(psi):
        return float(np.max(ring[:, 0] * math.cos(psi) + ring[:, 1] * math.sin(psi)))
    step = math.radians(0.5)
    i = int(np.argmin([margin(p) for p in np.arange(0.0, 2 * math.pi, step)]))
    lo, hi = (i - 1) * step, (i + 1) * step
    g = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(80):
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        lo, hi = (lo, b) if margin(a) <= margin(b) else (a, hi)
    best = 0.5 * (lo + hi)
    return math.degrees(math.atan2(margin(best), cg_z)), math.degrees(best) % 360.0


@pytest.mark.parametrize("name", PLANS)
def test_frozen_tip_angles_match_turning_the_ring(name):
    design = _design(PLANS[name])
    numbers = plant_numbers(design)
    for state in numbers["states"]:
        tip, direction = _brute_tip_deg(design.shape, state["cg_plan_mm"], state["cg_z_mm"])
        assert state["tip_frozen_deg"] == pytest.approx(tip, abs=1e-7)
        if name != "flask":  # (the flask's two long sides tie: either is the least)
            gap = (state["tip_direction_deg"] - direction + 180.0) % 360.0 - 180.0
            assert abs(gap) < 1e-3
    filled = numbers["states"][1]
    assert filled["tip_deg"] < filled["tip_frozen_deg"]  # the level liquid runs toward the edge
    if name == "shield":  # its centre is off the axis: its tip angle is not the axis' figure
        x, y = filled["cg_plan_mm"]
        assert abs(x) < 1e-12 and y > 1.0
        on_axis = math.degrees(math.atan2(numbers["ring"]["least_mm"], filled["cg_z_mm"]))
        assert abs(filled["tip_frozen_deg"] - on_axis) > 0.1


# ------------------------------------------------------------------------------ the tilted liquid
def _clip(pts, psi, d):
    """Sutherland-Hodgman: the polygon ``pts`` where ``p . u >= d``; area, moment along ``u``.
    Each edge ``a -> b`` gives its crossing (where it enters or leaves) and then ``b`` if kept."""
    u = np.array([math.cos(psi), math.sin(psi)])
    f = pts @ u - d
    a, fa = np.roll(pts, 1, axis=0), np.roll(f, 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = a + (pts - a) * (fa / (fa - f))[:, None]
    slots = np.stack([cross, pts], axis=1).reshape(-1, 2)
    keep = np.stack([(fa >= 0) != (f >= 0), f >= 0], axis=1).ravel()
    out = slots[keep]
    if len(out) < 3:
        return 0.0, 0.0
    area, mx, my = _shoelace(out)
    return area, mx * u[0] + my * u[1]


@pytest.mark.parametrize("name", PLANS)
def test_a_sections_half_plane_clip_matches_a_polygon_clip(name):
    plan = PLANS[name]
    rng = np.random.default_rng(41)
    rows = [(30.0, 4.0), (30.0, 0.0), (30.0, -2.0), (0.0, 6.0), (20.0, 1.0), (25.0, -1.0)]
    for psi in (0.0, 0.4, 1.9, -2.6):
        k = np.array([r[0] for r in rows])
        r = np.array([r[1] for r in rows])
        reach = plan.section_reach(k, r)
        d = rng.uniform(-1.0, 1.0, len(rows)) * reach
        area, m, _ = clip.outline(plan, k, r, psi, d)
        for i in range(len(rows)):
            ref = _clip(_polygon(plan, k[i], r[i]), psi, d[i])
            assert abs(area[i] - ref[0]) < 1e-8 * reach[i] ** 2
            assert abs(m[i] - ref[1]) < 1e-8 * reach[i] ** 3


@pytest.mark.parametrize("name, c, level", [("shield", 4.0, 55.0), ("pentagon", 2.0, 75.0)])
def test_the_tilted_liquid_matches_quadrature_below_a_level_surface(name, c, level):
    """One level surface in a tilted bottle (the pentagon's surface crosses the height where its
    sharp inner corners turn round): the liquid below it by adaptive quadrature
    over height (QUADPACK, which finds the kinks where the cut passes a corner by itself) of the
    sections' exact clips (checked above against polygon clips) at the designer's own profiles;
    the engine, asked for that volume, finds the same moments (it splits at those kinks)."""
    shape = _design(PLANS[name], c=c).shape
    phi, psi = 0.35, 2.2
    core, rnd, k, c = _k_c(shape)
    w, b = shape.wall_thickness, shape.base_thickness
    cp, sp = math.cos(phi), math.sin(phi)

    def f(z, j):  # the cavity at z where z cos(phi) - (p . u) sin(phi) <= level
        d = np.array([(z * cp - level) / sp])
        a, mu, _ = clip.outline(shape.plan, np.array([k(z)]), np.array([c(z) - w]), psi, d)
        return (a[0], mu[0], a[0] * z)[j]
    cuts = sorted({b, shape.z_top} | {p[1] for ch in (core, rnd) for s in ch for p in (s.p0, s.p1)
                                      if b < p[1] < shape.z_top})
    with warnings.catch_warnings():  # why: QUADPACK says when rounding stops it short of 1e-13
        warnings.simplefilter("ignore", IntegrationWarning)
        ref = np.array([sum(quad(f, lo, hi, args=(j,), epsabs=0.0, epsrel=1e-13, limit=500)[0]
                            for lo, hi in zip(cuts, cuts[1:])) for j in range(3)])
    got = mass.tilted_liquid(shape, ref[0], phi, psi)
    assert got[0] == pytest.approx(ref[0], rel=1e-12)
    assert got[1] == pytest.approx(ref[1], rel=1e-10) and got[2] == pytest.approx(ref[2], rel=1e-10)
    u = np.array([math.cos(psi), math.sin(psi)])
    upright = mass.liquid_part(shape, 40.0, 1.0)  # a hair of tilt: the upright centre
    v, mu, _ = mass.tilted_liquid(shape, mass.liquid_volume_mm3(shape, 40.0), 1e-7, psi)
    assert mu / v == pytest.approx(upright.cg_x_mm * u[0] + upright.cg_y_mm * u[1], abs=1e-4)


def _sample(name):
    """A bundled outline sample's design, or a straight-bodied bottle of ``PLANS`` (c = 2 mm)."""
    if name in PLANS:
        return _design(PLANS[name], c=2.0)
    from engine.files.project import load_project
    return load_project(str(Path(__file__).resolve().parents[1] / "resources" / f"{name}.glassbench"))[0]


def _cavity_cuts(shape, k, c, z_lo, z_hi):
    """Where the cavity's section changes formula in height (mm): the designer's profiles'
    joints and where the rounding less the wall passes 0 (found by brentq on a dense grid)."""
    core, rnd = (split_at_ring(shape.section(n))[1] for n in ("core", "round"))
    cuts = {z_lo, z_hi} | {p[1] for ch in (core, rnd) for s in ch for p in (s.p0, s.p1)}
    z = np.linspace(z_lo, z_hi, 4001)
    t = np.array([c(v) - shape.wall_thickness for v in z])
    for j in np.nonzero(np.signbit(t[1:]) != np.signbit(t[:-1]))[0]:
        cuts.add(brentq(lambda v: c(v) - shape.wall_thickness, z[j], z[j + 1], xtol=1e-14))
    return sorted(v for v in cuts if z_lo <= v <= z_hi)


def _event_offsets(plan, k, r, psi):
    """``(samples, places)``: how far along ``u`` (mm) each place lies where a section's clipped
    area changes formula, straight off its pieces (PlanOutline.section_pieces, one sign of ``r``):
    every piece's start and every arc's two points of normal ``+-u`` (NaN where its span does not
    hold that normal or its radius is 0)."""
    u = (math.cos(psi), math.sin(psi))
    cols = []
    for p in plan.section_pieces(k, r):
        p = [np.broadcast_to(v, k.shape) if i else v for i, v in enumerate(p)]
        if p[0] == "line":
            cols.append(p[1] * u[0] + p[2] * u[1])
            continue
        _, cx, cy, rho, a0, a1 = p
        cols.append(cx * u[0] + cy * u[1] + rho * (np.cos(a0) * u[0] + np.sin(a0) * u[1]))
        for sign, at in ((1.0, psi), (-1.0, psi + math.pi)):
            span = np.mod(at - a0, 2 * math.pi) <= a1 - a0
            cols.append(np.where(span & (rho > 0), cx * u[0] + cy * u[1] + sign * rho, np.nan))
    return np.column_stack(cols)


def _scalar_events(shape, k, c, cuts, psi, phi, level):
    """``(roots, lonely)``: the heights (mm) where the level surface ``level`` of a tilt ``phi``
    toward ``psi`` passes an event place of the cavity's sections (_event_offsets at the
    designer's core ``k`` and rounding ``c``), a scalar search: per piece between ``cuts``, 2001
    samples, each sign change of each place solved by brentq to 1e-13 mm; and those of them with
    no other root of their place within 0.5 mm (closer pairs a coarser grid may step over, where
    a split would matter no more)."""
    sp, cp, w = math.sin(phi), math.cos(phi), shape.wall_thickness

    def g(z, kk, rr):
        return _event_offsets(shape.plan, kk, rr, psi) - ((z * cp - level) / sp)[:, None]
    roots, lonely = [], []
    for a, b in zip(cuts, cuts[1:]):
        z = np.linspace(a, b, 2001)[1:-1]  # the ends are joints: a split already
        gz = g(z, np.array([k(v) for v in z]), np.array([c(v) - w for v in z]))
        for j in range(gz.shape[1]):
            found = [brentq(lambda v: g(np.array([v]), np.array([k(v)]), np.array([c(v) - w]))[0, j], z[i], z[i + 1], xtol=1e-13)
                     for i in np.nonzero(np.isfinite(gz[:-1, j]) & np.isfinite(gz[1:, j])
                                         & (np.signbit(gz[:-1, j]) != np.signbit(gz[1:, j])))[0]]
            roots += found
            lonely += [v for v in found if sum(abs(v - o) < 0.5 for o in found) == 1
                       and np.all(np.isfinite(gz[abs(z - v) < 0.5, j]))]
    return np.array(roots), lonely


@pytest.mark.parametrize("name", ["flacon", "hip_flask", "pentagon"])
def test_the_event_search_finds_where_a_scalar_search_finds_them(name):
    """The tilted liquid's split heights (mass._events: one grid of event offsets per plan
    direction, every bracket of every piece solved together) against a scalar search
    (_scalar_events: straight off the section's pieces at the designer's own profiles, between
    their joints and where the cavity's rounding passes 0): every height found is one of its
    roots, and every root that has no other of its place within 0.5 mm is found, to 1e-8 mm.
    The pentagon's rounding less the wall changes sign: both lists of pieces."""
    shape = _sample(name).shape
    cav = mass._cavity(shape)
    _, _, k, c = _k_c(shape)
    psi0 = stability.least_direction(shape)[0]
    checked = 0
    for psi, phi, h in [(psi0, 0.25, 0.6), (psi0, 0.7, 0.75), (1.0, 0.45, 0.5)]:
        level = (cav.z_ib + h * (cav.z_top - cav.z_ib)) * math.cos(phi)
        sp, cp = math.sin(phi), math.cos(phi)
        za = max((level - cav.reach * sp) / cp, cav.z_ib)
        zb = min((level + cav.reach * sp) / cp, cav.z_top)
        roots, lonely = _scalar_events(shape, k, c, _cavity_cuts(shape, k, c, za, zb), psi, phi, level)
        got = mass._events(mass._event_grid(shape, psi), za, zb, lambda z: (z * cp - level) / sp)
        got = got[(got > za) & (got < zb)]
        assert all(np.min(np.abs(roots - e)) < 1e-8 for e in got), (psi, phi, h)
        assert all(len(got) and np.min(np.abs(got - v)) < 1e-8 for v in lonely), (psi, phi, h, lonely, got)
        checked += len(lonely)
    assert checked >= 6  # the cut does pass the sections' corners


@pytest.mark.parametrize("name, phi, psi", [("flacon", 0.2, None), ("flacon", 0.7, None), ("hip_flask", 0.4, 0.3),
                                            ("pentagon", 0.6, -1.0)])
def test_a_samples_tilted_liquid_matches_quadrature_at_several_tilts(name, phi, psi):
    """As above on the bundled outline samples (their shoulders are arcs in the profile; the hip
    flask's plan is arcs) and on a pentagon whose sharp inner corners turn round, at a shallow and
    a steep tilt (the band then reaches from the body into the neck): the liquid below one level
    surface by adaptive quadrature over height (QUADPACK's, all three integrals at once) of the
    sections' exact clips at the designer's own profiles, split where the scalar search finds the
    surface passing a corner (else QUADPACK needs minutes to find those kinks itself); the
    engine, asked for that volume, finds the same moments."""
    shape = _sample(name).shape
    psi = stability.least_direction(shape)[0] if psi is None else psi
    _, _, k, c = _k_c(shape)
    cav = mass._cavity(shape)
    cp, sp = math.cos(phi), math.sin(phi)
    level = (cav.z_ib + 0.6 * (cav.z_top - cav.z_ib)) * cp

    def f(z):
        d = np.array([(z * cp - level) / sp])
        a, mu, _ = clip.outline(shape.plan, np.array([k(z)]), np.array([c(z) - shape.wall_thickness]), psi, d)
        return np.array([a[0], mu[0], a[0] * z])
    cuts = _cavity_cuts(shape, k, c, cav.z_ib, cav.z_top)
    cuts = sorted({*cuts, *_scalar_events(shape, k, c, cuts, psi, phi, level)[0]})
    with warnings.catch_warnings():  # why: QUADPACK says when rounding stops it short of 1e-13
        warnings.simplefilter("ignore", IntegrationWarning)
        ref = sum(quad_vec(f, lo, hi, epsabs=0.0, epsrel=1e-13, norm="max", limit=500)[0] for lo, hi in zip(cuts, cuts[1:]))
    got = mass.tilted_liquid(shape, ref[0], phi, psi)
    assert got[0] == pytest.approx(ref[0], rel=1e-12)
    assert got[1] == pytest.approx(ref[1], rel=1e-10) and got[2] == pytest.approx(ref[2], rel=1e-11)


@pytest.mark.parametrize("name", ["flacon", "hip_flask", "pentagon"])
def test_the_tip_angle_from_levels_found_at_near_tilts_is_the_one_from_the_upright_level(name, monkeypatch):
    """moving_tip seeks each tilt's liquid level from the levels it found at the near tilts
    before (brentq's last tilts are 1e-10 rad apart): the same tip angle, to 1e-12, as a search
    from the upright fill height at every tilt, in fewer clipped integrals (flacon 17 not 27); a
    tilted liquid sought from a level 5 mm off is the same liquid, at the same level, to 1e-12
    (its moments to 1e-12 of the volume times the height)."""
    design = _sample(name)
    calls = []
    clipped = mass._clipped
    monkeypatch.setattr(mass, "_clipped", lambda *a: calls.append(1) or clipped(*a))
    warm, n_warm = plant_numbers(design)["states"][1]["tip_deg"], len(calls)
    monkeypatch.setattr(stability, "WARM_RAD", 0.0)
    calls.clear()
    cold, n_cold = plant_numbers(design)["states"][1]["tip_deg"], len(calls)
    assert warm == pytest.approx(cold, rel=1e-12) and n_warm < n_cold
    shape, psi = design.shape, stability.least_direction(design.shape)[0]
    volume = mass.liquid_volume_mm3(shape, fill.fill_height_mm(shape, design.liquid))
    upright = mass.tilted_liquid_level(shape, volume, math.radians(warm), psi)
    for start in (upright[3] - 5.0, upright[3] + 5.0):
        got = mass.tilted_liquid_level(shape, volume, math.radians(warm), psi, start)
        assert got[0] == pytest.approx(volume, rel=1e-13) and got[3] == pytest.approx(upright[3], rel=1e-12)
        np.testing.assert_allclose(got[1:3], upright[1:3], atol=1e-12 * volume * shape.z_top)  # moments: mm^4


def test_an_outline_has_its_stability_numbers():
    design = _design(PLANS["pentagon"], c=2.0)
    numbers = plant_numbers(design)
    assert [s["state"] for s in numbers["states"]] == ["empty", "filled", "brimful"]
    assert numbers["ring"]["kind"] == "plan" and 0 < numbers["least_tip"]["deg"] < 90
    assert not any("stability" in w for w in numbers["warnings"])
    psi, margin = stability.least_direction(design.shape)  # a flat side's: k h + c, exact
    k, c = stability.ring_radii(design.shape)
    assert margin == pytest.approx(k * min(h for _, _, h in design.shape.plan._lines) + c, rel=1e-14)
    moved = dataclasses.replace(design, shape=dataclasses.replace(design.shape, rotation_deg=30.0))
    turned = plant_numbers(moved)["states"][0]
    assert turned["tip_deg"] == pytest.approx(numbers["states"][0]["tip_deg"], rel=1e-12)
    assert (turned["tip_direction_deg"] - numbers["states"][0]["tip_direction_deg"]) % 360 == pytest.approx(30.0)


# ------------------------------------------------------------------------------ membrane stress
@pytest.mark.parametrize("name, says", [("pentagon", "flat panels (no plan curvature) bend"),
                                        ("flask", "the plan radius jumps where its arcs meet")])
def test_an_outline_has_no_membrane_figure_and_every_point_says_why(name, says):
    """As on a rounded square: no number where the wall bends, which on a free plan is
    everywhere; each wall point names the plan's radii of curvature (of the middle surface) at
    its height, the round neck says so."""
    design = _design(PLANS[name])
    numbers = plant_numbers(design)
    json.dumps(numbers, allow_nan=False)
    stress = numbers["stress"]
    assert stress["max_mpa"] is None and stress["note"] == membrane.REASONS["outline"]
    assert all(p["hoop_mpa"] is None and p["meridional_mpa"] is None and p["reason"] for p in stress["points"])
    wall = [p for p in stress["points"] if p["reason"] != membrane.REASONS["base"]]
    body = [p for p in wall if p["z_mm"] < 70.0]
    assert all(says in p["reason"] for p in body)
    k, c, t = 30.0, 4.0, design.shape.wall_thickness  # the body: core 30, rounding 4 (_bottle)
    radii = [k * s.radius + c - t / 2 for s in design.shape.plan.segments if s.kind == "arc"]
    radii += [c - t / 2] * len(design.shape.plan.corners)
    lo, hi = f"{min(radii):.1f}", f"{max(radii):.1f}"
    assert (lo in body[0]["reason"] and hi in body[0]["reason"])
    assert all("round here" in p["reason"] for p in wall if p["z_mm"] > 96.0 + 1e-9)  # the neck: k = 0
    assert [p["s_mm"] for p in stress["points"]] == sorted(p["s_mm"] for p in stress["points"])
    assert not any("stress" in w for w in numbers["warnings"])


# ------------------------------------------------------------------------------ thin sloped walls
def _sloped(plan, slope_deg, k=20.0, w=3.0):
    """A bottle whose rounding narrows from 15 to 5 mm between z = 30 and 40 + ... at
    ``slope_deg`` from the vertical (a cone all round: the core keeps 20 mm there), then whose
    core shrinks to the round neck from z = 50 to 120 (at most 16 deg from the vertical)."""
    rise = 10.0 / math.tan(math.radians(slope_deg))
    z2 = 30.0 + rise
    core = Section.from_dicts([{"type": "line", "p0": a, "p1": b} for a, b in
                               zip([(0, 0), (k, 0), (k, z2 + 10), (0, z2 + 80)],
                                   [(k, 0), (k, z2 + 10), (0, z2 + 80), (0, z2 + 100)])], smooth=[False] * 3)
    rnd = Section.from_dicts([{"type": "line", "p0": a, "p1": b} for a, b in
                              zip([(0, 0), (15, 0), (15, 30), (5, z2)], [(15, 0), (15, 30), (5, z2), (5, z2 + 100)])],
                             smooth=[False] * 3)
    return BottleShape("outline", (("core", core), ("round", rnd)), w, 6.0, plan=plan), z2


@pytest.mark.parametrize("name", ["hexagon", "flask", "shield"])
def test_a_45_degree_shoulder_is_the_wall_over_root_2_thick_and_warns_where(name):
    """A cone at 45 deg all round the plan: w / sqrt2 along its normal wherever the nearest
    inner point lies on the inner cone too; the run starts where the nearest point is the inner
    knee, sqrt((w - a)^2 + a^2) = 0.9 w at a above the lower knee, and ends where a neck point
    b above the upper knee is (w + b) / sqrt2 = 0.9 w from the inner cone."""
    plan = {"hexagon": P.hexagon(), "flask": PLANS["flask"], "shield": PLANS["shield"]}[name]
    shape, z2 = _sloped(plan, 45.0)
    w = shape.wall_thickness
    (run,) = thickness.thin_walls(shape)
    assert run["least_mm"] == pytest.approx(w / math.sqrt(2.0), rel=1e-9)
    assert run["z_from_mm"] == pytest.approx(30.0 + w * (1.0 - math.sqrt(1.0 - 2 * 0.19)) / 2.0, abs=2e-3)
    assert run["z_to_mm"] == pytest.approx(z2 + (0.9 * math.sqrt(2.0) - 1.0) * w, abs=2e-3)
    assert run["z_from_mm"] < run["at_z_mm"] < run["z_to_mm"]
    (text,) = thickness.warnings([run], w)
    assert f"{run['z_from_mm']:.1f} to {run['z_to_mm']:.1f} mm" in text and "2.12 mm" in text and "71%" in text


@pytest.mark.parametrize("slope, warns", [(30.0, True), (20.0, False)])
def test_a_shoulder_warns_only_below_nine_tenths_of_the_wall(slope, warns):
    """cos 30 deg = 0.87 of the wall warns, cos 20 deg = 0.94 does not (the core's gentle
    narrowing to the neck never does); through the sheet, which quotes it among its warnings."""
    shape, _ = _sloped(P.octagon(0.2), slope)
    runs = thickness.thin_walls(shape)
    numbers = plant_numbers(Design(shape=shape))
    assert numbers["thin_wall"] == [{**r, "direction_deg": pytest.approx(r["direction_deg"])} for r in runs]
    if warns:
        (run,) = runs
        assert run["least_mm"] == pytest.approx(3.0 * math.cos(math.radians(slope)), rel=1e-9)
        assert any(w.startswith("Sloped wall from z = ") for w in numbers["warnings"])
    else:
        assert runs == () and not any("Sloped" in w for w in numbers["warnings"])


@pytest.mark.parametrize("name", ["pentagon shoulder", "rounded triangle shoulder"])
def test_the_vectorised_thickness_search_finds_the_least_a_dense_scan_and_a_scalar_search_find(name):
    """The thickness search (a grid, the knee, Brent's method, every point in step) against
    brute force at every probe direction and at heights across a shoulder, its knees and just
    beside them: a cone at 40 deg on an irregular pentagon (sharp corners; a kink at either
    knee), and a triangle rounded to half its size (arcs all but between the flats) whose core
    narrows to the neck while its rounding grows (a smooth shoulder). The reference: the
    squared distance over the same window at 4001 heights and the knees, then a bounded scalar
    search (scipy's, to 1e-13 mm) between the best one's neighbours. The search finds that
    least to 1e-12 (the golden sections it replaced were off by up to 4e-12 here)."""
    if name == "pentagon shoulder":
        shape, z2 = _sloped(_pentagon(), 40.0)
        z = np.concatenate([np.linspace(27.0, z2 + 8.0, 9), [30.0, 30.0 + 1e-4, z2, z2 - 1e-4]])
    else:
        shape, z2 = _bottle(P.triangle(0.5)), 96.0
        z = np.concatenate([np.linspace(66.0, 100.0, 9), [72.0, 72.0 + 1e-4, z2, z2 - 1e-4]])
    wall = thickness._Wall(shape)
    got = wall.thickness(z[:, None], wall.p, wall.u)
    x, y = (np.broadcast_to(v, got.shape).ravel() for v in wall._outer_points(z[:, None], wall.p, wall.u))
    zz = np.broadcast_to(z[:, None], got.shape).ravel()
    z0 = np.clip(zz, wall.z_ib, wall.z_top)
    reach = np.sqrt(wall._f(x, y, zz, z0))
    lo = np.minimum(np.maximum(zz - reach, wall.z_ib), z0)
    hi = np.maximum(np.minimum(zz + reach, wall.z_top), z0)
    ref = np.empty(len(zz))
    for i in range(len(zz)):
        knees = wall.knees[(wall.knees >= lo[i]) & (wall.knees <= hi[i])]
        dense = np.union1d(np.linspace(lo[i], hi[i], 4001), knees)
        f = wall._f(x[i], y[i], zz[i], dense)
        j = int(np.argmin(f))
        fine = minimize_scalar(lambda t: float(wall._f(x[i], y[i], zz[i], t)), method="bounded",
                               bounds=(dense[max(j - 1, 0)], dense[min(j + 1, len(dense) - 1)]),
                               options={"xatol": 1e-13})
        ref[i] = math.sqrt(min(f[j], fine.fun))
    assert np.all(got.ravel() <= ref * (1 + 1e-12)), "never thicker than the scan's least"
    np.testing.assert_allclose(got.ravel(), ref, rtol=1e-12)
    assert got.min() < thickness.THIN_SHARE * shape.wall_thickness  # the shoulder is thin somewhere: a case that counts


def test_a_hexagonal_flacons_thin_run_names_one_corner_and_height_whatever_the_rounding():
    """The bundled flacon's shoulder is equally thin at its six corners (to rounding, which a
    wall 1e-9 mm thicker shuffles): the run names the first of them in the probes' order, the
    same every time, where the plain least named 120, 0, 240 and 240 deg for four such walls."""
    design = _sample("flacon")
    shapes = [dataclasses.replace(design.shape, wall_thickness=design.shape.wall_thickness + 1e-9 * j)
              for j in range(4)]
    runs = [thickness.thin_walls(s) for s in shapes]
    assert all(len(r) == 1 for r in runs)
    assert {r[0]["direction_deg"] for r in runs} == {runs[0][0]["direction_deg"]}
    assert min(abs(runs[0][0]["direction_deg"] - 60.0 * i) for i in range(7)) < 1e-9  # a corner
    for (run,) in runs[1:]:
        assert run["at_z_mm"] == pytest.approx(runs[0][0]["at_z_mm"], abs=1e-6)
        assert run["least_mm"] == pytest.approx(runs[0][0]["least_mm"], rel=1e-8)


def test_a_straight_walled_flask_and_a_round_bottle_have_no_thin_wall():
    """Vertical walls, and a core narrowing to the neck at 18 deg from the vertical at most
    (the plan's farthest point): nowhere under nine tenths; a round bottle's cavity is its 3-D
    offset."""
    line = [{"type": "line", "p0": a, "p1": b} for a, b in zip([(0, 0), (20, 0), (20, 40), (0, 100)],
                                                              [(20, 0), (20, 40), (0, 100), (0, 120)])]
    core = Section.from_dicts(line, smooth=[False] * 3)
    rnd = Section.from_dicts([{"type": "line", "p0": [0, 0], "p1": [5, 0]},
                              {"type": "line", "p0": [5, 0], "p1": [5, 120]}], smooth=[False])
    flask = Design(shape=BottleShape("outline", (("core", core), ("round", rnd)), 3.0, 6.0, plan=PLANS["flask"]))
    numbers = plant_numbers(flask)
    assert numbers["thin_wall"] == [] and not any("Sloped" in w for w in numbers["warnings"])
    assert plant_numbers(cylinder())["thin_wall"] == []


def test_the_converted_flacons_shoulder_is_as_thin_as_a_dense_point_cloud_says():
    """outline_public_1's shoulder slopes far from the vertical: the glass there is a fifth of
    the wall. The reference: the distance from outer wall points to a dense cloud of inner
    wall points (every 0.05 deg and 0.01 mm), never nearer than the engine's least, and within
    the cloud's spacing of it."""
    design = spec_to_design(SPECS / "outline_public_1.json")[0]
    (run,) = plant_numbers(design)["thin_wall"]
    assert 75.0 < run["z_from_mm"] < run["at_z_mm"] < run["z_to_mm"] < 89.0 and run["share"] < 0.25
    body = BottleBody(design.shape)
    at, turn = run["at_z_mm"], math.radians(run["direction_deg"] - design.shape.rotation_deg)
    zs = np.arange(at - 3.0, at + 3.0, 0.01)
    theta = turn + np.radians(np.arange(-10.0, 10.0, 0.05))
    inner, _ = body.wall("inner", theta[:, None], zs[None, :])
    tree = cKDTree(inner.reshape(-1, 3))
    outer, _ = body.wall("outer", theta[:, None], np.arange(at - 1.0, at + 1.0, 0.02)[None, :])
    brute = float(tree.query(outer.reshape(-1, 3))[0].min())
    assert run["least_mm"] <= brute + 1e-9 and brute < run["least_mm"] * (1.0 + 1e-3)
