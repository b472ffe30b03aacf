"""Tracer invariants: white furnace, no self-hits, closed interfaces, exact normals, media."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from benchmarks.paths import ORACLE_SPECS
from engine.geometry.body import BottleBody
from engine.geometry.offset import radius_at
from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.shape import BottleShape
from engine.model.design import Camera, Design, Glass, Liquid, RenderSettings
from engine.tracer.context import (RenderContext, TraceStats, nearest_hits, object_normals,
                                   trace_pixels, trace_rays)
from engine.tracer.tables.environment import EnvironmentMap
from engine.tracer.tables.render_objects import (AIR, GLASS, INNER_WALL, LIQUID, OUTER_WALL,
                                          render_geometry_for)
from engine.tracer.kernels.integrator import C_NODES, C_ROULETTE
from engine.tracer.kernels.intersect import object_media

SPECS = str(ORACLE_SPECS)
WHITE = EnvironmentMap(np.ones((4, 8, 3), np.float32))


def simple_design(fill=40.0, glass_absorption=(0.0, 0.0, 0.0), liquid_absorption=(0.0, 0.0, 0.0),
                  width=24, height=32, spp=2) -> Design:
    """A 20 mm cylinder bottle with a 5 mm base fillet and a cone shoulder into a 9 mm neck."""
    segs = (Line((0, 0), (15, 0)), Arc((15, 5), 5, (15, 0), (20, 5), "ccw"), Line((20, 5), (20, 60)),
            Arc((10, 60), 10, (20, 60), (10 + 10 * math.cos(1.0), 60 + 10 * math.sin(1.0)), "ccw"))
    p = segs[-1].p1
    t = (-math.sin(1.0), math.cos(1.0))
    # Straight shoulder along the arc's end tangent, then a concave arc into the vertical neck.
    q = (p[0] + t[0] * 6.0, p[1] + t[1] * 6.0)
    rc = 6.0
    c = (q[0] + rc * t[1], q[1] - rc * t[0])  # concave: the centre lies outside, along +n
    neck = (c[0] + rc * math.cos(math.pi), c[1])
    segs = segs + (Line(p, q), Arc(c, rc, q, neck, "cw"), Line(neck, (neck[0], neck[1] + 15)))
    shape = BottleShape("round", (("profile", Section(segs)),), wall_thickness=2.5, base_thickness=5.0)
    liquid = None if fill is None else Liquid(ior=1.33, absorption=liquid_absorption, fill_value=fill)
    return Design(shape=shape, glass=Glass(ior=1.5, absorption=glass_absorption), liquid=liquid,
                  camera=Camera(eye=(0, -220, 45), target=(0, 0, 40), fov_y_deg=30),
                  render=RenderSettings(width=width, height=height, spp=spp, max_depth=40))


def _furnace(design, spp=2, env=WHITE):
    """Mean radiance per pixel of ``spp`` anti-aliasing samples in a uniform environment."""
    w, h = design.render.width, design.render.height
    ctx = RenderContext.from_design(design, None, w, h, environment=env)
    rows, cols = np.mgrid[0:h, 0:w]
    res = trace_pixels(ctx, cols.ravel(), rows.ravel(), 1, spp)
    st = TraceStats()
    st.add_counters(res.counters)
    return res.sums / spp, st


@pytest.mark.parametrize("fill", [None, 40.0])
def test_white_furnace_clear_glass_returns_exactly_the_environment(fill):
    img, st = _furnace(simple_design(fill))
    assert st.boundaries > 2 * img.shape[0]  # the bottle was really hit
    assert np.all(img <= 1.0 + 1e-9)
    assert np.all(np.abs(img - 1.0) < 1e-9)
    assert st.escaped_inside == 0 and st.mismatches == 0


def test_white_furnace_absorbing_media_only_lose_energy():
    img, _ = _furnace(simple_design(40.0, glass_absorption=(0.05, 0.0, 0.0), liquid_absorption=(0.0, 0.02, 0.0)))
    assert np.all(img <= 1.0 + 1e-9) and np.all(img >= 0)
    assert img[:, 0].min() < 0.9 and img[:, 1].min() < 0.95  # the tints absorb
    assert np.allclose(img[:, 2], 1.0)  # the blue channel is clear in both media


def _wall_points(design, n=400, seed=0, z_range=(1.0, 59.0)):
    rng = np.random.default_rng(seed)
    z = rng.uniform(*z_range, n)
    th = rng.uniform(0, 2 * np.pi, n)
    r = radius_at(BottleBody(design.shape).profile.sections[0].outer_wall, z)
    p = np.stack([r * np.cos(th), r * np.sin(th), z], 1)
    n_out = np.stack([np.cos(th), np.sin(th), np.zeros(n)], 1)
    return p, n_out, rng


def test_rays_leaving_a_surface_never_hit_it_again_at_zero_distance():
    design = simple_design(None)
    g = render_geometry_for(design)
    p, n, rng = _wall_points(design, z_range=(6.0, 59.0))  # the convex cylinder
    d = rng.normal(size=p.shape)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d = np.where((np.einsum("ij,ij->i", d, n) < 0.2)[:, None], d + 1.2 * n, d)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    # out into the air from exactly on the surface: nothing at ~0, no re-hit of a convex wall
    t, k, _, _ = nearest_hits(g, p, d, AIR, OUTER_WALL, 1)
    assert np.all(t[k >= 0] > 0.5)
    # into the glass: the next surface is at least about a wall thickness away
    d_in = -n + 0.3 * rng.normal(size=p.shape)
    d_in /= np.linalg.norm(d_in, axis=1, keepdims=True)
    t, k, _, _ = nearest_hits(g, p, d_in, GLASS, OUTER_WALL, -1)
    assert np.all(k >= 0) and np.all(t > 1.0)


def test_closed_interfaces_are_always_hit_from_inside_with_the_right_medium():
    design = simple_design(40.0)
    g = render_geometry_for(design)
    prof = BottleBody(design.shape).profile.sections[0]
    rng = np.random.default_rng(5)
    m = 2000
    z = rng.uniform(10.0, 55.0, m)
    th = rng.uniform(0, 2 * np.pi, m)
    r_out = radius_at(prof.outer_wall, z)
    r_in = radius_at(prof.inner_wall, z)
    for rho, zz, medium in ((0.5 * (r_out + r_in), z, GLASS),
                            (rng.uniform(0, 1, m) * r_in * 0.99, np.minimum(z, 39.0), LIQUID)):
        p = np.stack([rho * np.cos(th), rho * np.sin(th), zz], 1)
        d = rng.normal(size=(m, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        t, k, _, n = nearest_hits(g, p, d, medium)
        assert np.all(k >= 0)
        hit = p + t[:, None] * d
        media = np.array([object_media(g.obj_i, g.obj_f, kk, zh) for kk, zh in zip(k, hit[:, 2])])
        incident = np.where(np.einsum("ij,ij->i", d, n) < 0, media[:, 0], media[:, 1])
        assert np.all(incident == medium)


def test_exact_normals_on_cylinder_and_fillet():
    g = render_geometry_for(simple_design(None))
    p = np.array([[20.0, 0, 30.0], [0, -20.0, 30.0], [15 + 5 * math.cos(-0.7), 0, 5 + 5 * math.sin(-0.7)]])
    o = p + np.array([[5.0, 0, 0], [0, -5.0, 0], [5 * math.cos(-0.7), 0, 5 * math.sin(-0.7)]])
    t, k, part, n = nearest_hits(g, o, (p - o) / np.linalg.norm(p - o, axis=1, keepdims=True))
    assert np.all(k == OUTER_WALL) and np.allclose(o + t[:, None] * (p - o) / 5.0, p, atol=1e-9)
    assert np.allclose(n[0], [1, 0, 0], atol=1e-12) and np.allclose(n[1], [0, -1, 0], atol=1e-12)
    assert np.allclose(n[2], [math.cos(-0.7), 0, math.sin(-0.7)], atol=1e-12)
    # The inner wall's oriented normal points into the cavity.
    t, k, part, n = nearest_hits(g, [[0, 0, 30.0]], [[1.0, 0, 0]], AIR)
    assert k[0] == INNER_WALL and abs(t[0] - 17.5) < 1e-9 and np.allclose(n[0], [-1, 0, 0], atol=1e-12)
    assert np.allclose(object_normals(g, INNER_WALL, part, [[17.5, 0, 30.0]])[0], [-1, 0, 0], atol=1e-12)


def test_wet_inner_wall_faces_liquid_and_dry_faces_air():
    g = render_geometry_for(simple_design(40.0))
    assert object_media(g.obj_i, g.obj_f, INNER_WALL, 20.0) == (LIQUID, GLASS)
    assert object_media(g.obj_i, g.obj_f, INNER_WALL, 50.0) == (AIR, GLASS)


def test_no_liquid_object_without_liquid():
    assert "free surface" not in render_geometry_for(simple_design(None)).names
    assert "free surface" in render_geometry_for(simple_design(40.0)).names


def test_rounded_square_flat_side_normal_follows_the_rotation():
    from benchmarks.oracle import spec_to_design

    design, _ = spec_to_design(f"{SPECS}/public_3.json")
    g = render_geometry_for(design)
    body = BottleBody(design.shape)
    z = 50.0
    u, tr, tz = body.wall_radii("outer", np.array([z]))[0]
    du = tr / tz
    a = math.radians(design.shape.rotation_deg)
    face = np.array([math.cos(a), math.sin(a), 0.0])
    o = np.array([[0.0, 0.0, z]]) + 100.0 * face
    t, k, _, n = nearest_hits(g, o, -face[None])
    assert k[0] == OUTER_WALL and abs(t[0] - (100.0 - u[0])) < 1e-9
    want = np.array([math.cos(a), math.sin(a), -du[0]])
    assert np.allclose(n[0], want / np.linalg.norm(want), atol=1e-9)


def test_rounded_square_white_furnace():
    from benchmarks.oracle import spec_to_design

    design, _ = spec_to_design(f"{SPECS}/public_3.json")
    design = dataclasses.replace(design, glass=Glass(ior=1.52),
                                 liquid=dataclasses.replace(design.liquid, absorption=(0, 0, 0)),
                                 render=RenderSettings(width=24, height=24, spp=1))
    img, st = _furnace(design, spp=1)
    assert np.all(np.abs(img - 1.0) < 1e-9) and st.escaped_inside == 0 and st.mismatches == 0


def test_non_finite_environment_never_reaches_the_image():
    design = simple_design(None)
    ctx = RenderContext.from_design(design, None, 8, 8, environment=EnvironmentMap(np.full((4, 8, 3), np.inf, np.float32)))
    rad, _ = trace_rays(ctx, [[0, -200.0, 30.0], [0, -200.0, 30.0]], [[0, 1.0, 0], [0, 0, 1.0]])
    assert np.all(np.isfinite(rad)) and np.all(rad >= 0)


def test_volume_fill_mode_puts_the_free_surface_at_the_solved_height():
    from engine.geometry.capacity import fill_height_for_volume

    design = simple_design(40.0)
    design = dataclasses.replace(design, liquid=dataclasses.replace(design.liquid, fill_mode="volume", fill_value=30.0))
    g = render_geometry_for(design)
    want = fill_height_for_volume(design.shape, 30.0)
    assert g.z_ib < want < g.z_top and abs(g.fill_height - want) < 1e-9


def test_roulette_spares_branches_into_air_and_plays_inside_glass():
    """A branch into air is one segment, and is the glint (the key light in the outer
    surface's 4 % reflection): Russian roulette never ends it, whatever its weight. At depth 1
    the light branches are the outer surface's reflections (and, at grazing incidence, a faint
    refraction into the glass), so hardly any is killed (a roulette for every branch under 0.5
    would end about 9 in 10 of those reflections); deeper, the reflections inside the glass
    (lighter than 0.5, into glass) are."""
    d = simple_design(40.0, width=16, height=20)
    ys, xs = np.mgrid[0:20, 0:16]
    counts = {}
    for depth in (1, 3):
        ctx = RenderContext.from_design(dataclasses.replace(d, render=dataclasses.replace(d.render, max_depth=depth)))
        res = trace_pixels(ctx, xs.ravel(), ys.ravel(), 1, 4, roulette=0.5)
        counts[depth] = res.counters[C_ROULETTE], res.counters[C_NODES]
    kills, hits = counts[1]
    assert hits > 100 and kills < 0.05 * hits
    kills, nodes = counts[3]
    assert kills > 0.1 * counts[1][1]
