"""Tracer on every shape the engine validates: punts, rounded rectangles, ovals, per-segment and
thin walls. White furnace (clear glass in a uniform environment returns it exactly), refined
hits on the exact surfaces, no self-hits on a thin wall."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from engine.files.project import load_project
from engine.geometry.body import BottleBody
from engine.geometry.shape import BottleShape
from engine.model.design import Camera, Design, Glass, Liquid, RenderSettings
from engine.tracer.context import nearest_hits
from engine.tracer.tables.render_objects import (AIR, BOTTOM, FREE_SURFACE, GLASS, INNER_BASE, INNER_WALL, OUTER_WALL,
                                          RIM, render_geometry_for)
from tests.test_offset import punt_section, stepped_section
from tests.test_tracer import _furnace


def _design(shape, fill=None, size=24):
    """Clear glass, optional clear liquid, a camera framing the whole bottle from the side."""
    h = shape.z_top
    liquid = None if fill is None else Liquid(ior=1.33, absorption=(0.0, 0.0, 0.0), fill_value=fill)
    return Design(shape=shape, glass=Glass(ior=1.5), liquid=liquid,
                  camera=Camera(eye=(0.0, -2.6 * h, 0.35 * h), target=(0.0, 0.0, 0.45 * h), fov_y_deg=30),
                  render=RenderSettings(width=size, height=size, spp=1, max_depth=40))


def _punt(fill=None):
    return _design(BottleShape("round", {"profile": punt_section()}, 3.0, 4.0), fill)


def _rounded_rect(fill=None):
    secs = {"half_width": stepped_section(30.0, 100.0, 14.0, 130.0, 160.0),
            "half_depth": stepped_section(20.0, 100.0, 14.0, 130.0, 160.0),
            "corner": stepped_section(8.0, 100.0, 14.0, 130.0, 160.0)}
    return _design(BottleShape("rounded_rect", secs, 2.0, 5.0, rotation_deg=20.0), fill)


def _oval(fill=None):
    secs = {"half_width": stepped_section(30.0, 100.0, 12.0, 130.0, 160.0),
            "half_depth": stepped_section(20.0, 100.0, 12.0, 130.0, 160.0)}
    return _design(BottleShape("oval", secs, 2.0, 5.0, rotation_deg=30.0), fill)


def _per_segment(fill=None):
    shape = BottleShape("round", {"profile": stepped_section(30.0, 100.0, 12.0, 130.0, 160.0)}, 2.0, 5.0,
                        wall_per_segment=(3.0, 2.0, 1.5))
    return _design(shape, fill)


def _thin(fill=None):
    return _design(BottleShape("round", {"profile": stepped_section(30.0, 100.0, 12.0, 130.0, 160.0)}, 0.3, 2.0),
                   fill)


def _bordeaux(fill=None):
    design = load_project("resources/bordeaux.glassbench")[0]
    liquid = None if design.liquid is None else dataclasses.replace(design.liquid, absorption=(0.0, 0.0, 0.0))
    return dataclasses.replace(_design(design.shape, None), liquid=liquid)


CASES = {"punt": _punt, "punt below the dome": lambda: _punt(8.0), "punt filled": lambda: _punt(90.0),
         "rounded_rect": lambda: _rounded_rect(70.0), "oval": lambda: _oval(115.0),
         "per-segment wall": lambda: _per_segment(120.0), "thin wall": lambda: _thin(60.0),
         "bordeaux sample": _bordeaux}


@pytest.mark.parametrize("name", CASES)
def test_white_furnace_on_every_shape(name):
    img, st = _furnace(CASES[name](), spp=1)
    assert st.boundaries > 2 * len(img)  # the bottle was hit
    assert np.all(img <= 1.0 + 1e-9)
    assert np.all(np.abs(img - 1.0) < 1e-9)
    assert st.escaped_inside == 0 and st.mismatches == 0


def test_bordeaux_sample_has_a_punt_and_its_base_is_hit():
    design = _bordeaux()
    g = render_geometry_for(design)
    assert BottleBody(design.shape).profile.punt
    # Rays straight up through the base hit the dome of the punt, not a flat plane at z = 0.
    o = np.stack([np.linspace(0.0, 5.0, 6), np.zeros(6), np.full(6, -50.0)], 1)
    d = np.tile([0.0, 0.0, 1.0], (6, 1))
    t, surf, _, n = nearest_hits(g, o, d)
    p = o + t[:, None] * d
    assert np.all(surf == BOTTOM) and np.all(p[:, 2] > 1.0)
    assert np.all(n[:, 2] < 0)  # away from the glass


def _random_rays(design, m, seed):
    """Rays from a box around the bottle towards random points near its axis."""
    rng = np.random.default_rng(seed)
    h = design.shape.z_top
    o = rng.normal(size=(m, 3)) * [80.0, 80.0, 0.0]
    o[:, 2] = rng.uniform(-0.2 * h, 1.2 * h, m)
    target = np.stack([rng.uniform(-25, 25, m), rng.uniform(-25, 25, m), rng.uniform(0, h, m)], 1)
    d = target - o
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


@pytest.mark.parametrize("name", ["punt filled", "rounded_rect", "oval", "per-segment wall"])
def test_refined_hits_lie_on_the_exact_surfaces(name):
    design = CASES[name]()
    g = render_geometry_for(design)
    body = BottleBody(design.shape)
    m = 3000
    o, d = _random_rays(design, m, 3)
    t, surf, _, n = nearest_hits(g, o, d)
    p = o + np.where(surf >= 0, t, 0.0)[:, None] * d
    assert np.count_nonzero(surf >= 0) > m // 4
    for sid, part in ((OUTER_WALL, "outer"), (INNER_WALL, "inner")):
        sel = surf == sid
        assert np.any(sel) or sid == INNER_WALL
        g_val, grad = body.wall_implicit(part, p[sel])
        assert np.abs(g_val / np.linalg.norm(grad, axis=1)).max(initial=0.0) < 1e-9  # distance, mm
        sign = 1.0 if sid == OUTER_WALL else -1.0
        assert np.allclose(n[sel], sign * grad / np.linalg.norm(grad, axis=1, keepdims=True), atol=1e-9)
    assert np.all(np.abs(p[surf == RIM, 2] - g.z_top) < 1e-9)
    if g.fill_height is not None:
        assert np.all(np.abs(p[surf == FREE_SURFACE, 2] - g.fill_height) < 1e-9)
    if not body.profile.punt:
        assert np.all(np.abs(p[surf == BOTTOM, 2]) < 1e-9)
        assert np.all(np.abs(p[surf == INNER_BASE, 2] - design.shape.base_thickness) < 1e-9)
    assert np.allclose(np.linalg.norm(n[surf >= 0], axis=1), 1.0)


def test_refined_punt_hits_lie_on_the_revolved_base_curves():
    design = _punt(90.0)
    g = render_geometry_for(design)
    sec = BottleBody(design.shape).profile.sections[0]
    rng = np.random.default_rng(4)
    m = 3000
    below = np.stack([rng.uniform(-40, 40, m), rng.uniform(-40, 40, m), np.full(m, -30.0)], 1)
    inside = np.stack([rng.uniform(-10, 10, m), rng.uniform(-10, 10, m), np.full(m, 60.0)], 1)
    for sid, chain, o, z_aim in ((BOTTOM, sec.outer_base, below, 8.0), (INNER_BASE, sec.inner_base, inside, 10.0)):
        aim = np.stack([rng.uniform(-30, 30, m), rng.uniform(-30, 30, m), np.full(m, z_aim)], 1)
        d = (aim - o) / np.linalg.norm(aim - o, axis=1, keepdims=True)
        t, surf, _, _ = nearest_hits(g, o, d, AIR if sid == BOTTOM else 0)
        p = o + np.where(surf >= 0, t, 0.0)[:, None] * d
        sel = surf == sid
        assert np.count_nonzero(sel) > 100
        rho, z = np.hypot(p[sel, 0], p[sel, 1]), p[sel, 2]
        assert _chain_distance(chain, rho, z).max() < 1e-9


def _chain_distance(chain, rho, z):
    """Distance (mm) in the (r, z) plane from points to a chain: dense samples, then Newton on
    ``(P(t) - q) . P'(t) = 0`` (numeric derivatives) per segment."""
    q = np.stack([rho, z], 1)
    best = np.full(len(rho), np.inf)
    for seg in chain:
        ts = np.linspace(0.0, 1.0, 2001)
        pts = seg.point(ts)
        t = ts[np.argmin(np.linalg.norm(q[:, None, :] - pts[None], axis=2), axis=1)]
        h = 1e-6
        for _ in range(30):
            f = lambda u: np.einsum("ij,ij->i", seg.point(u) - q, (seg.point(u + h) - seg.point(u - h)) / (2 * h))
            df = (f(t + h) - f(t - h)) / (2 * h)
            t = np.clip(t - f(t) / np.where(df == 0, 1.0, df), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(seg.point(t) - q, axis=1))
    return best


def test_no_self_hit_on_a_thin_wall():
    design = _thin()
    g = render_geometry_for(design)
    body = BottleBody(design.shape)
    rng = np.random.default_rng(7)
    m = 2000
    z = rng.uniform(10.0, 95.0, m)
    th = rng.uniform(0.0, 2 * np.pi, m)
    p = np.stack([30.0 * np.cos(th), 30.0 * np.sin(th), z], 1)  # exactly on the outer wall
    n = np.stack([np.cos(th), np.sin(th), np.zeros(m)], 1)
    for side in (-1, 1):
        d = side * n + 0.6 * rng.normal(size=(m, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        # steeper than 17 deg off the wall: into the glass, such a ray must reach the inner wall
        d = np.where((np.einsum("ij,ij->i", d, n) * side < 0.3)[:, None], side * n, d)
        t, surf, _, _ = nearest_hits(g, p, d, GLASS if side < 0 else AIR, OUTER_WALL, side)
        if side < 0:  # into the 0.3 mm glass: the inner wall comes next, never the outer one again
            assert np.all(surf == INNER_WALL)
            assert np.all(t > 0.3 - 1e-9)
            hit = p + t[:, None] * d
            g_in, _ = body.wall_implicit("inner", hit)
            assert np.abs(g_in).max() < 1e-9
        else:  # out into the air: away from a convex wall, nothing is hit again
            assert np.all(surf < 0)
