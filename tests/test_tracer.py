"""Tracer invariants: white furnace, no self-hits, closed interfaces, exact normals, media."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from engine.tracer.camera import PinholeCamera
from engine.model.design import Camera, Design, Glass, Liquid, RenderSettings
from engine.tracer.environment import EnvironmentMap
from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.offset import radius_at
from engine.geometry.shape import BottleShape
from engine.tracer.embree_scene import SURFACE_EPS_MM
from engine.tracer.geometry import (AIR, GLASS, INNER_WALL, LIQUID, OUTER_WALL, render_geometry_for)
from engine.tracer.integrator import Materials, TraceStats, exact_hits, trace, trace_pixels
from benchmarks.paths import ORACLE_SPECS

SPECS = str(ORACLE_SPECS)


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


def _furnace(design, spp=2):
    g = render_geometry_for(design)
    cam = PinholeCamera.from_design(design.camera, design.render.width, design.render.height)
    rows, cols = np.mgrid[0:design.render.height, 0:design.render.width]
    env = EnvironmentMap(np.ones((4, 8, 3), np.float32))
    st = TraceStats()
    acc = trace_pixels(g, Materials.from_design(design), env, cam, cols.ravel(), rows.ravel(),
                       np.arange(spp), max_depth=40, min_weight=1e-3, stats=st)
    return acc / spp, st


@pytest.mark.parametrize("fill", [None, 40.0])
def test_white_furnace_clear_glass_returns_exactly_the_environment(fill):
    img, st = _furnace(simple_design(fill))
    assert st.rays_cast > 2 * img.shape[0]  # the bottle was really hit
    assert np.all(img <= 1.0 + 1e-9)
    assert np.all(np.abs(img - 1.0) < 1e-9)
    assert st.escaped_inside == 0


def test_white_furnace_absorbing_media_only_lose_energy():
    img, _ = _furnace(simple_design(40.0, glass_absorption=(0.05, 0.0, 0.0), liquid_absorption=(0.0, 0.02, 0.0)))
    assert np.all(img <= 1.0 + 1e-9) and np.all(img >= 0)
    assert img[:, 0].min() < 0.9 and img[:, 1].min() < 0.95  # the tints absorb
    assert np.allclose(img[:, 2], 1.0)  # the blue channel is clear in both media


def _wall_points(g, n=400, seed=0, z_range=(1.0, 59.0)):
    rng = np.random.default_rng(seed)
    z = rng.uniform(*z_range, n)
    th = rng.uniform(0, 2 * np.pi, n)
    r = radius_at(g.body.profile.sections[0].outer_wall, z)
    p = np.stack([r * np.cos(th), r * np.sin(th), z], 1)
    return p, g.exact_normals(p, np.full(n, OUTER_WALL, np.int8)), rng


def test_rays_leaving_a_surface_never_hit_it_again_at_zero_distance():
    g = render_geometry_for(simple_design(None))
    p, n, rng = _wall_points(g, z_range=(6.0, 59.0))  # the convex cylinder
    d = rng.normal(size=p.shape)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d = np.where((np.einsum("ij,ij->i", d, n) < 0.2)[:, None], d + 1.2 * n, d)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    t, surf = _leave(g, p + SURFACE_EPS_MM * n, d, OUTER_WALL, 1)
    assert np.all(t[surf >= 0] > 0.5)
    # Into the glass: the next surface is at least about a wall thickness away.
    d_in = -n + 0.3 * rng.normal(size=p.shape)
    d_in /= np.linalg.norm(d_in, axis=1, keepdims=True)
    t, surf = _leave(g, p - SURFACE_EPS_MM * n, d_in, OUTER_WALL, -1)
    assert np.all(surf >= 0) and np.all(t > 1.0)


def _leave(g, o, d, surface, side):
    """Exact hits of rays that just left ``surface`` towards ``side`` (+1 front, -1 back)."""
    n = len(o)
    t, surf, _, _ = exact_hits(g, o, d, np.full(n, surface, np.int8), np.full(n, side, np.int8))
    return t, surf


def test_closed_interfaces_are_always_hit_from_inside_with_the_right_medium():
    design = simple_design(40.0)
    g = render_geometry_for(design)
    rng = np.random.default_rng(5)
    m = 2000
    z = rng.uniform(10.0, 55.0, m)
    th = rng.uniform(0, 2 * np.pi, m)
    r_out = radius_at(g.body.profile.sections[0].outer_wall, z)
    r_in = radius_at(g.body.profile.sections[0].inner_wall, z)
    for rho, zz, medium in ((0.5 * (r_out + r_in), z, GLASS),
                            (rng.uniform(0, 1, m) * r_in * 0.99, np.minimum(z, 39.0), LIQUID)):
        p = np.stack([rho * np.cos(th), rho * np.sin(th), zz], 1)
        d = rng.normal(size=(m, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        t, surf, hit, n = exact_hits(g, p, d, np.full(m, -1, np.int8), np.zeros(m, np.int8))
        assert np.all(surf >= 0)
        front, back = g.media(surf, hit[:, 2])
        incident = np.where(np.einsum("ij,ij->i", d, n) < 0, front, back)
        assert np.all(incident == medium)


def test_exact_normals_on_cylinder_and_fillet():
    g = render_geometry_for(simple_design(None))
    p = np.array([[20.0, 0, 30.0], [0, -20.0, 30.0],
                  [15 + 5 * math.cos(-0.7), 0, 5 + 5 * math.sin(-0.7)]])
    n = g.exact_normals(p, np.full(3, OUTER_WALL, np.int8))
    assert np.allclose(n[0], [1, 0, 0], atol=1e-9) and np.allclose(n[1], [0, -1, 0], atol=1e-9)
    assert np.allclose(n[2], [math.cos(-0.7), 0, math.sin(-0.7)], atol=1e-7)
    # The inner wall's oriented normal points into the cavity.
    n_in = g.exact_normals(np.array([[17.5, 0, 30.0]]), np.array([INNER_WALL], np.int8))
    assert np.allclose(n_in[0], [-1, 0, 0], atol=1e-9)


def test_wet_inner_wall_faces_liquid_and_dry_faces_air():
    g = render_geometry_for(simple_design(40.0))
    front, back = g.media(np.array([INNER_WALL, INNER_WALL], np.int8), np.array([20.0, 50.0]))
    assert list(front) == [LIQUID, AIR] and list(back) == [GLASS, GLASS]


def test_rounded_square_flat_side_normal_follows_the_rotation():
    from benchmarks.oracle import spec_to_design

    design, _ = spec_to_design(f"{SPECS}/public_3.json")
    g = render_geometry_for(design)
    z = 50.0
    u, tr, tz = g.body.wall_radii("outer", np.array([z]))[0]
    du = tr / tz
    a = math.radians(design.shape.rotation_deg)
    p = np.array([[u[0] * math.cos(a), u[0] * math.sin(a), z]])  # middle of the +x face, turned
    n = g.exact_normals(p, np.array([OUTER_WALL], np.int8))[0]
    want = np.array([math.cos(a), math.sin(a), -du[0]])
    assert np.allclose(n, want / np.linalg.norm(want), atol=1e-9)


def test_rounded_square_white_furnace():
    from benchmarks.oracle import spec_to_design

    design, _ = spec_to_design(f"{SPECS}/public_3.json")
    design = dataclasses.replace(design, glass=Glass(ior=1.52), liquid=dataclasses.replace(design.liquid, absorption=(0, 0, 0)),
                                 render=RenderSettings(width=24, height=24, spp=1))
    img, st = _furnace(design, spp=1)
    assert np.all(np.abs(img - 1.0) < 1e-9) and st.escaped_inside == 0


def test_non_finite_weights_never_reach_the_image():
    design = simple_design(None)
    g = render_geometry_for(design)
    env = EnvironmentMap(np.full((4, 8, 3), np.inf, np.float32))
    o = np.array([[0, -200.0, 30.0], [0, -200.0, 30.0]])
    d = np.array([[0, 1.0, 0], [0, 0, 1.0]])
    acc = trace(g, Materials.from_design(design), env, o, d, np.array([0, 1]), 2)
    assert np.all(np.isfinite(acc))


def test_volume_fill_mode_puts_the_free_surface_at_the_solved_height():
    from engine.geometry.capacity import fill_height_for_volume

    design = simple_design(40.0)
    design = dataclasses.replace(design, liquid=dataclasses.replace(design.liquid, fill_mode="volume", fill_value=30.0))
    g = render_geometry_for(design)
    want = fill_height_for_volume(design.shape, 30.0)
    assert g.z_ib < want < g.z_top and abs(g.fill_height - want) < 1e-9
