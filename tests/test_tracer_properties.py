"""Where tracing methods fail, tested: random designs under a memory limit, thin walls, grazing
rays, rays along the axis, far cameras, extreme scales, liquid at the shoulder and the mouth."""
from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.shape import BottleShape
from engine.model.design import Camera, Design, Glass, Liquid, RenderSettings
from engine.tracer.context import RenderContext, nearest_hits, trace_rays
from engine.tracer.tables.render_objects import BOTTOM, FREE_SURFACE, INNER_BASE, OUTER_WALL, RIM, render_geometry_for
from tests.test_tracer import WHITE, _furnace, simple_design

ROOT = Path(__file__).resolve().parents[1]


def test_random_designs_render_finite_without_leaks_under_a_memory_limit():
    """Hypothesis designs (round, smooth round, rounded square, rectangle, oval; with and
    without liquid, odd fills, depths and weights) in a process limited to 2 GiB of address
    space: each image finite and >= 0, no light leaving a medium unseen, memory flat."""
    limit = 2 * 1024 ** 3
    out = subprocess.run([sys.executable, "-m", "tests.render_fuzz_worker", str(limit), "25"], cwd=ROOT,
                         capture_output=True, text=True, timeout=1200)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-4000:]
    last = out.stdout.strip().splitlines()[-1]
    assert last.startswith("OK"), last
    fields = dict(kv.split("=") for kv in last.split()[1:])
    assert int(fields["rendered"]) >= 15
    assert float(fields["peak_rss_mb"]) < 2048
    assert float(fields["growth_mb"]) < 20.0  # no leak across renders


def tall(wall=0.5, scale=1.0, fill=None):
    """A 300 mm bottle (times ``scale``) with walls ``wall`` mm (times ``scale``)."""
    s = scale
    segs = (Line((0, 0), (30 * s, 0)), Arc((30 * s, 8 * s), 8 * s, (30 * s, 0), (38 * s, 8 * s), "ccw"),
            Line((38 * s, 8 * s), (38 * s, 200 * s)), Line((38 * s, 200 * s), (14 * s, 250 * s)),
            Line((14 * s, 250 * s), (14 * s, 300 * s)))
    shape = BottleShape("round", {"profile": Section(segs, (False, True, False, False))}, wall * s, 2 * wall * s)
    liquid = None if fill is None else Liquid(ior=1.33, absorption=(0, 0, 0), fill_value=fill * s)
    return Design(shape=shape, glass=Glass(ior=1.5), liquid=liquid,
                  camera=Camera(eye=(0, -900 * s, 150 * s), target=(0, 0, 150 * s), fov_y_deg=22),
                  render=RenderSettings(width=24, height=32, spp=1, max_depth=64))


def test_half_millimetre_wall_in_a_300_mm_bottle_has_no_leaks_and_no_acne():
    img, st = _furnace(tall(0.5, fill=120.0), spp=2)
    assert st.boundaries > 1000
    assert np.all(np.abs(img - 1.0) < 1e-9)  # acne or a leak would darken or brighten a pixel
    assert st.escaped_inside == 0 and st.mismatches == 0


def _grazing(design, x, z):
    """Rays along +y from y = -500 mm at ``x`` mm and heights ``z``: their first hits ``(t, k)``,
    after checking that in a white environment they return it exactly (clear glass and liquid:
    no light lost or made) with no leaks and no medium mismatches."""
    o = np.stack([np.full_like(z, x), np.full_like(z, -500.0), z], 1)
    d = np.tile([0.0, 1.0, 0.0], (len(z), 1))
    t, k, _, _ = nearest_hits(render_geometry_for(design), o, d)
    ctx = RenderContext.from_design(design, None, 8, 8, environment=WHITE)
    rad, counters = trace_rays(ctx, o, d)
    assert np.all(np.abs(rad - 1.0) < 1e-9)
    assert counters[1] == 0 and counters[2] == 0  # no leaks, no medium mismatches
    return t, k


def _scaled_image(make, s):
    """The 24 x 32 image (2 samples, ``(32, 24, 3)``) and kernel counters of ``make(s)``, a design
    ``s`` times the size, its absorption coefficients divided by ``s`` (the same optical depths)."""
    from engine.tracer.context import trace_pixels

    d = make(s)
    d = dataclasses.replace(d, glass=Glass(ior=1.5, absorption=(0.01 / s, 0.0, 0.02 / s)),
                            liquid=dataclasses.replace(d.liquid, absorption=(0.0, 0.01 / s, 0.0)))
    ctx = RenderContext.from_design(d, None, 24, 32)
    ys, xs = np.mgrid[0:32, 0:24]
    res = trace_pixels(ctx, xs.ravel(), ys.ravel(), 1, 2)
    return res.sums.reshape(32, 24, 3), res.counters


@pytest.mark.parametrize("offset", [1e-3, 1e-6, 1e-9, 1e-12, -1e-12, -1e-9])
def test_grazing_rays_at_the_silhouette(offset):
    """Rays tangent to the 38 mm cylinder, shifted by ``offset`` mm outwards (negative: into the
    glass): they miss or hit consistently, never leak, and the furnace stays exact."""
    t, k = _grazing(tall(3.0), 38.0 + offset, np.linspace(20.0, 190.0, 50))
    if offset > 0:
        assert np.all(k < 0)
    elif offset < -1e-10:
        assert np.all(k == OUTER_WALL) and np.all(np.abs(t - 500.0) < 1e-3)


def test_rays_along_the_axis_through_mouth_and_base():
    design = tall(3.0, fill=100.0)
    g = render_geometry_for(design)
    down = nearest_hits(g, [[0.0, 0.0, 400.0]], [[0.0, 0.0, -1.0]])
    assert down[1][0] == FREE_SURFACE and abs(down[0][0] - 300.0) < 1e-9
    t, k, _, n = nearest_hits(g, [[0.0, 0.0, 100.0]], [[0.0, 0.0, -1.0]], 2)  # in the liquid
    assert k[0] == INNER_BASE and abs(t[0] - 94.0) < 1e-9 and n[0][2] == 1.0
    t, k, _, n = nearest_hits(g, [[0.0, 0.0, -50.0]], [[0.0, 0.0, 1.0]])
    assert k[0] == BOTTOM and abs(t[0] - 50.0) < 1e-9 and n[0][2] == -1.0
    t, k, _, n = nearest_hits(g, [[0.0, 0.0, 350.0]], [[0.0, 0.0, -1.0]])
    assert k[0] == FREE_SURFACE  # the mouth is open: straight down through it
    # straight down the inner wall of the neck, a hair inside it: the rim is not hit
    t, k, _, _ = nearest_hits(g, [[11.0 - 1e-9, 0.0, 350.0]], [[0.0, 0.0, -1.0]])
    assert k[0] != RIM


def test_a_camera_ten_metres_away_sees_the_same_hits_as_a_near_one():
    """The same rays started 10 m and 0.3 m away: exact hits agree to 1e-9 mm."""
    design = tall(2.0, fill=150.0)
    g = render_geometry_for(design)
    rng = np.random.default_rng(3)
    target = np.stack([rng.uniform(-40, 40, 400), rng.uniform(-40, 40, 400), rng.uniform(0, 300, 400)], 1)
    far = np.array([0.0, -10_000.0, 150.0])
    d = target - far
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    t_far, k_far, _, n_far = nearest_hits(g, np.broadcast_to(far, d.shape), d)
    near = far + (10_000.0 - 300.0) * d
    t_near, k_near, _, n_near = nearest_hits(g, near, d)
    hit = k_far >= 0
    assert hit.sum() > 100 and np.array_equal(k_far, k_near)
    assert np.max(np.abs((t_far[hit] - (10_000.0 - 300.0)) - t_near[hit])) < 1e-9
    assert np.max(np.abs(n_far[hit] - n_near[hit])) < 1e-9


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_the_image_does_not_depend_on_the_bottle_scale(scale):
    """A bottle and camera scaled by 1/1000 and 1000 (a 0.3 mm and a 300 m bottle) render the
    same image as at 1x: exact float64 surfaces, tolerances relative to the bottle's size."""
    def make(s):
        return tall(2.0, scale=s, fill=150.0)
    ref, _ = _scaled_image(make, 1.0)
    img, counters = _scaled_image(make, scale)
    assert counters[1] == 0 and counters[2] == 0
    assert np.max(np.abs(img - ref)) < 1e-6 * ref.max()


def rounded_rect(scale=1.0, fill=None):
    """A 160 mm rounded rectangle (times ``scale``; half width 30, half depth 20, corner 8 mm in the
    body), straight sections only, so its walls are ruled slabs: flat sides and slanted corner
    cones in closed form (:func:`engine.tracer.kernels.swept.ruled_roots`). Not turned: its
    sides lie along the world axes."""
    from tests.test_offset import stepped_section

    s = scale
    secs = {"half_width": stepped_section(30.0 * s, 100.0 * s, 14.0 * s, 130.0 * s, 160.0 * s),
            "half_depth": stepped_section(20.0 * s, 100.0 * s, 14.0 * s, 130.0 * s, 160.0 * s),
            "corner": stepped_section(8.0 * s, 100.0 * s, 14.0 * s, 130.0 * s, 160.0 * s)}
    liquid = None if fill is None else Liquid(ior=1.33, absorption=(0, 0, 0), fill_value=fill * s)
    return Design(shape=BottleShape("rounded_rect", secs, 2.0 * s, 5.0 * s), glass=Glass(ior=1.5), liquid=liquid,
                  camera=Camera(eye=(-150 * s, -420 * s, 90 * s), target=(0, 0, 80 * s), fov_y_deg=30),
                  render=RenderSettings(width=24, height=32, spp=1, max_depth=64))


@pytest.mark.parametrize("offset", [1e-3, 1e-6, 1e-9, 1e-12, -1e-12, -1e-9])
def test_grazing_rays_along_a_flat_side_of_a_rounded_rectangle(offset):
    """Rays parallel to the flat side x = 30 mm, shifted by ``offset`` mm outwards (negative: into
    the glass, which they enter through the corner where the side begins): they miss or hit
    consistently, never leak, and the furnace stays exact. A ray parallel to a side is where
    the ruled slabs' box clip has no crossing with that side at all."""
    t, k = _grazing(rounded_rect(fill=70.0), 30.0 + offset, np.linspace(10.0, 95.0, 40))
    if offset > 0:
        assert np.all(k < 0)
    elif offset < -1e-10:  # the corner's cone, 0.13 mm before the side's flat part begins
        assert np.all(k == OUTER_WALL) and np.all(np.abs(t - (500.0 - 12.0)) < 1e-3)


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_a_rounded_rectangles_image_does_not_depend_on_its_scale(scale):
    """The ruled slabs' closed forms hold their digits at 1/1000 and 1000 times the size: the
    same image as at 1x (absorption scaled with the size), no leaks, no medium mismatches. A few
    pixels see light trapped by total internal reflection in the rounded corners, where after
    dozens of bounces (some reach the depth limit) the last digits steer the path: those agree to
    2e-4 of the peak (the kernels before the box clip: the same pixels, the same bound)."""
    def make(s):
        return rounded_rect(s, fill=70.0)
    ref, _ = _scaled_image(make, 1.0)
    img, counters = _scaled_image(make, scale)
    assert counters[1] == 0 and counters[2] == 0
    diff = np.abs(img - ref).max(axis=-1) / ref.max()
    assert np.count_nonzero(diff > 1e-6) <= 4, np.argwhere(diff > 1e-6)  # of 768 pixels
    assert diff.max() < 2e-4


@pytest.mark.parametrize("where", ["shoulder joint", "mouth", "nearly empty"])
def test_liquid_at_the_shoulder_at_the_mouth_and_nearly_empty(where):
    design = simple_design(40.0)
    top, ib = design.shape.z_top, design.shape.base_thickness
    fill = {"shoulder joint": 60.0, "mouth": top, "nearly empty": ib + 0.01}[where]
    design = dataclasses.replace(design, liquid=dataclasses.replace(design.liquid, fill_value=fill))
    img, st = _furnace(design)
    assert np.all(np.abs(img - 1.0) < 1e-9)
    assert st.escaped_inside == 0 and st.mismatches == 0
