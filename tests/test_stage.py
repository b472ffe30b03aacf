"""The stage: a ground under the bottle, its light through the glass, and where the method could fail.

Energy (a white ground under clear glass in a white furnace stays white), the control variate's
exactness where nothing is in the way, a camera below the ground, a mirror's regress, dark
glass, the ground seen through the liquid, alpha without the ground, and the SPEC ground
scene against its reference.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from benchmarks.paths import ORACLE_SPECS
from engine.model.design import Camera, Glass, Light, Stage
from engine.tracer.context import RenderContext, TraceStats, trace_pixels, trace_rays
from engine.tracer.tables.environment import EnvironmentMap
from engine.tracer.kernels.ground import S_RMAX
from engine.tracer.kernels.intersect import O_MAT
from engine.tracer.kernels.materials import MG_BOUND_R
from engine.tracer.picking import coverage
from engine.tracer.tables.stage import open_sky_irradiance
from tests.test_tracer import WHITE, simple_design

TABLE = Stage(kind="table", color=(1.0, 1.0, 1.0))


def _on_stage(stage, **kw):
    d = simple_design(**kw)
    cam = Camera(eye=(0, -220, 120), target=(0, 0, 20), fov_y_deg=40)  # looking down on the ground
    return dataclasses.replace(d, stage=stage, camera=cam, lights=())


def _pixels(design, env=None, spp=16, first=1, grids=None):
    w, h = design.render.width, design.render.height
    ctx = RenderContext.from_design(design, None, w, h, environment=env, grids=grids)
    rows, cols = np.mgrid[0:h, 0:w]
    res = trace_pixels(ctx, cols.ravel(), rows.ravel(), first, spp)
    st = TraceStats()
    st.add_counters(res.counters)
    return (res.sums / spp).reshape(h, w, 3), res.objects.reshape(h, w), ctx, st


def test_a_white_ground_under_clear_glass_in_a_white_furnace_stays_white():
    img, objects, ctx, st = _pixels(_on_stage(TABLE, fill=40.0), env=WHITE)
    ground = ctx.ground_objects
    assert ((objects & ground) != 0).mean() > 0.3 and ((objects & 1) != 0).any()  # ground and bottle seen
    assert np.abs(img - 1.0).max() < 1e-9  # every pixel: ground, glass, both, and the sky
    assert st.escaped_inside == 0 and st.mismatches == 0


def test_open_ground_is_exact_and_noise_free_and_shadowed_ground_is_darker():
    design = _on_stage(Stage(kind="table", color=(0.5, 0.5, 0.5)), fill=40.0, glass_absorption=(0.5, 0.5, 0.5))
    ctx = RenderContext.from_design(design, None, 8, 8, grids=True)
    e_up = open_sky_irradiance(ctx.environment)
    down = np.tile([0.0, 0.0, -1.0], (64, 1))
    # a metre from the bottle, in the sky grid: the bottle's sliver of sky is taken (1e-6 of the
    # light), the same for every sample and smooth from point to point
    far = np.column_stack([1000 + np.arange(64) * 0.37, np.arange(64) * 0.11, np.full(64, 300.0)])
    out, _ = trace_rays(ctx, far, down)
    again, _ = trace_rays(ctx, far, down)
    assert np.array_equal(out, again)
    assert (out < 0.5 * e_up).all() and np.abs(out - 0.5 * e_up).max() < 1e-5 * e_up.max()
    assert np.abs(np.diff(out, axis=0)).max() < 1e-8
    # beyond the grid the ground probes per hit, and there its probes miss: albedo x the open sky, to rounding
    reach = ctx.finish.sky_grid[S_RMAX]
    assert 1000.0 < reach < 3000.0
    beyond = far + [reach, 0.0, 0.0]
    out, _ = trace_rays(ctx, beyond, down)
    assert np.abs(out - 0.5 * e_up).max() < 1e-12
    # 3 mm from the dark bottle's foot the ground loses sky to it: its contact shadow
    near = np.column_stack([23 + np.arange(64) * 0.01, np.zeros(64), np.full(64, 300.0)])
    out, _ = trace_rays(ctx, near, down)
    assert (out.mean(axis=0) < 0.8 * 0.5 * e_up).all()


def test_the_open_sky_irradiance_of_a_white_sky_is_one():
    assert np.allclose(open_sky_irradiance(WHITE), 1.0, atol=1e-12)
    # a sky bright only below the horizon gives an upward surface nothing
    tex = np.zeros((64, 128, 3), np.float32)
    tex[40:] = 5.0
    assert np.abs(open_sky_irradiance(EnvironmentMap(tex))).max() < 1e-6


def test_a_camera_below_the_ground_sees_its_black_underside_and_never_the_bottle_above():
    design = _on_stage(TABLE, fill=40.0)
    design = dataclasses.replace(design, camera=Camera(eye=(0, -200, -30), target=(0, 0, 30), fov_y_deg=40))
    img, objects, ctx, _ = _pixels(design, env=WHITE, spp=1, first=0)  # pixel centres: no sky mixed in
    ground = ctx.ground_objects
    assert ((objects & ground) != 0).mean() > 0.2
    assert not ((objects & 1) != 0).any()  # the outer wall (object 0) is never met from below
    assert np.all(img[(objects & ground) != 0] == 0.0)  # the underside absorbs
    assert np.allclose(img[objects == 0], 1.0, atol=1e-12)  # where the ground does not reach, the sky


def test_a_bottle_on_a_mirror_ends_its_regress_and_the_open_mirror_shows_the_tinted_sky():
    design = _on_stage(Stage(kind="mirror", color=(0.9, 0.8, 0.7)), fill=40.0)
    img, objects, ctx, st = _pixels(design, env=WHITE, spp=4)
    assert st.escaped_inside == 0 and np.isfinite(img).all()
    open_mirror = objects == ctx.ground_objects
    assert open_mirror.any()
    assert np.allclose(img[open_mirror], (0.9, 0.8, 0.7))
    assert np.all(img <= 1.0 + 1e-9)  # a mirror under clear glass in a white sky: its tint at most


def _ground_points(ctx, xy, repeats=32):
    """Mean radiance of ``repeats`` vertical rays onto each ground point ``xy`` (mm), ``(len(xy), 3)``."""
    xy = np.repeat(np.asarray(xy, float), repeats, axis=0)
    origins = np.column_stack([xy, np.full(len(xy), 300.0)])
    out, _ = trace_rays(ctx, origins, np.tile([0.0, 0.0, -1.0], (len(xy), 1)))
    return out.reshape(-1, repeats, 3).mean(axis=1)


# ground points in a ring 1-15 mm from the 20 mm bottle's foot
RING = [((20 + g) * math.cos(a), (20 + g) * math.sin(a)) for g in (1.0, 4.0, 15.0)
        for a in np.linspace(0, 2 * math.pi, 12, endpoint=False)]


def test_dark_glass_casts_a_shadow_and_almost_no_caustic():
    clear = _on_stage(Stage(kind="table", color=(0.6, 0.6, 0.6)), fill=None)
    dark = dataclasses.replace(clear, glass=Glass(ior=1.5, absorption=(3.0, 3.0, 3.0)))
    ctx_a = RenderContext.from_design(clear, None, 8, 8)
    ctx_b = RenderContext.from_design(dark, None, 8, 8)
    a, b = _ground_points(ctx_a, RING), _ground_points(ctx_b, RING)
    open_sky = 0.6 * open_sky_irradiance(ctx_a.environment)
    # beside the dark bottle the ground never receives more than the open sky gives (no caustic)...
    assert (b <= open_sky * 1.001).all()
    # ...and less the nearer its foot (its contact shadow; grazing reflections off the wall keep some light)
    assert (b[:12] < 0.95 * open_sky).all() and (b[:12].mean(axis=0) < b[24:].mean(axis=0)).all()
    assert b.sum() < a.sum()  # clear glass lets light through to the ground


def test_the_ground_is_seen_through_the_glass_and_liquid():
    design = _on_stage(TABLE, fill=40.0)
    _, objects, ctx, _ = _pixels(design, spp=1)
    ground = ctx.ground_objects
    bottle_and_ground = ((objects & 1) != 0) & ((objects & ground) != 0)
    assert bottle_and_ground.mean() > 0.05


def test_alpha_covers_the_bottle_not_the_ground():
    design = _on_stage(TABLE, fill=40.0)
    bare = dataclasses.replace(design, stage=Stage())
    assert np.array_equal(coverage(design, 24, 32), coverage(bare, 24, 32))


def test_the_lights_light_the_ground_and_the_bottle_shadows_them():
    lit = dataclasses.replace(_on_stage(Stage(kind="table", color=(0.5, 0.5, 0.5)), fill=None,
                                        glass_absorption=(2.0, 2.0, 2.0)),
                              lights=(Light(direction=(0.0, 1.0, 1.0), intensity=2.0),))
    dark = dataclasses.replace(lit, lights=())
    a = RenderContext.from_design(lit, None, 8, 8, environment=WHITE)
    b = RenderContext.from_design(dark, None, 8, 8, environment=WHITE)
    # the light comes from +y at 45 degrees: (0, -40) lies in the bottle's shadow, (0, 300) in the open
    points = [(0.0, -40.0), (0.0, 300.0)]
    gain = _ground_points(a, points, 8) - _ground_points(b, points, 8)
    # open ground: albedo x irradiance x cos / pi of a light at 45 degrees (and, through the sky
    # grid's probes, the faint light the bottle's wall throws back from the lit ground: 2e-6 of it)
    assert np.allclose(gain[1], 0.5 * 2.0 * math.cos(math.pi / 4) / math.pi, rtol=1e-5)
    assert (gain[0] < 1e-3 * gain[1]).all()  # 5 mm of dark glass in the light's way


def test_the_spec_ground_scene_is_within_two_per_cent_of_its_reference():
    from benchmarks.oracle_render import reference_path, rel_rmse, render_spec
    from engine.tracer.tables.environment import read_radiance_image
    spec = str(ORACLE_SPECS / "ground_public_1.json")
    img, _, _ = render_spec(spec, spp=8, threads=2)
    assert rel_rmse(img, read_radiance_image(reference_path(spec))) < 0.02


# ----------------------------------------------------------------------------- the lights' caustics
def _lit(stage=TABLE, light=Light(direction=(0.3, 0.5, 1.0), intensity=2.0), **kw):
    """A bottle on ``stage`` under ``light`` and an environment's sky."""
    return dataclasses.replace(_on_stage(stage, **kw), lights=(light,))


def _light_only(design, points, repeats=16):
    """What ``design``'s lights add on the ground at ``points`` (mm): its radiance less that of
    the same design without lights."""
    a = RenderContext.from_design(design, None, 8, 8)
    b = RenderContext.from_design(dataclasses.replace(design, lights=()), None, 8, 8)
    return _ground_points(a, points, repeats) - _ground_points(b, points, repeats)


def _caustic_flux(design):
    """Red flux (mm^2 x irradiance) the lights' caustic grids hold, in the shadow and in the open:
    the light that came through the bottle and landed on the ground."""
    ctx = RenderContext.from_design(design, None, 8, 8)
    cs, g = ctx.finish.caustics, ctx.finish.caustic_grid
    return np.array([(cs[q, ..., 0].sum() + cs[q, ..., 3].sum()) * g[q, 2] ** 2 * math.pi for q in range(len(g))])


def test_a_bottle_of_index_one_glass_casts_no_shadow_from_a_light():
    """Index-matched glass lets the light through unbent and undimmed: the straight light (shadow
    rays) and the traced light (the caustic grid) must add up to the open ground's everywhere,
    across the shadow's edge too (the grid's division by its shadow share), to the photons' noise."""
    d = _lit(Stage(kind="table", color=(1.0, 1.0, 1.0)), fill=None)
    d = dataclasses.replace(d, glass=Glass(ior=1.0))
    l = np.array([0.3, 0.5, 1.0]) / np.linalg.norm([0.3, 0.5, 1.0])
    points = [(x, y) for x in np.linspace(-60, 30, 46) for y in (-40.0, -25.0, 0.0, 25.0) if x * x + y * y > 24 ** 2]
    ratio = _light_only(d, points)[:, 0] / (2.0 * l[2] / math.pi)
    assert abs(ratio.mean() - 1.0) < 0.01
    assert ratio.std() < 0.05 and np.abs(ratio - 1.0).max() < 0.2


def test_the_caustic_grid_is_the_same_for_any_number_of_threads():
    from engine.tracer.tables.caustics import caustic_grids
    from engine.tracer.tables.labels import with_buffers
    ctx = RenderContext.from_design(_lit(fill=40.0), None, 8, 8)
    args = (ctx.tables(with_buffers(ctx.labels)), ctx.scene.mat_i.shape[0] - 1, -0.05)
    one, two = caustic_grids(*args, threads=1), caustic_grids(*args, threads=3)
    assert np.array_equal(one[0], two[0]) and np.array_equal(one[1], two[1])
    assert one[0][..., :6].max() > 0.0


def test_clear_liquid_focuses_a_light_into_a_caustic_and_dark_glass_passes_almost_none():
    clear = _lit(fill=40.0)
    dark = dataclasses.replace(clear, glass=Glass(ior=1.5, absorption=(3.0, 3.0, 3.0)))
    l = np.array([0.3, 0.5, 1.0]) / np.linalg.norm([0.3, 0.5, 1.0])
    ctx = RenderContext.from_design(clear, None, 8, 8)
    peak = ctx.finish.caustics[0, ..., :3].max()
    assert peak > 3.0 * 2.0 * l[2] / math.pi  # focused: brighter than the open ground
    # dark glass: only the outer surface's reflection reaches the ground (Fresnel over a cylinder's
    # profile averages about a tenth, grazing at its sides)
    assert _caustic_flux(dark)[0] < 0.15 * _caustic_flux(clear)[0]


def test_a_sun_sized_light_softens_the_shadow_and_keeps_the_caustics_light():
    dark_glass = Glass(ior=1.5, absorption=(3.0, 3.0, 3.0))
    point = dataclasses.replace(_lit(light=Light(direction=(0.0, 1.0, 1.0), intensity=2.0), fill=None),
                                glass=dark_glass)
    sun = dataclasses.replace(point, lights=(dataclasses.replace(point.lights[0], angle_deg=0.53),))
    # across the edge of the shadow of the bottle's side, 60 mm from it: the sun's penumbra is
    # 60 x 0.53 degrees = 0.55 mm wide; the point light's edge is a step
    xs = np.linspace(19.0, 21.5, 26)
    points = [(x, -60.0) for x in xs]
    p = _light_only(point, points, 64)[:, 0] / (2.0 * math.cos(math.pi / 4) / math.pi)
    s = _light_only(sun, points, 64)[:, 0] / (2.0 * math.cos(math.pi / 4) / math.pi)
    assert ((p > 0.1) & (p < 0.9)).sum() <= 1  # a step (one point may fall on it)
    assert ((s > 0.1) & (s < 0.9)).sum() >= 3  # a ramp
    clear_point, clear_sun = _lit(fill=40.0), _lit(fill=40.0, light=Light((0.3, 0.5, 1.0), intensity=2.0,
                                                                          angle_deg=0.53))
    a, b = _caustic_flux(clear_point)[0], _caustic_flux(clear_sun)[0]
    assert abs(b / a - 1.0) < 0.03  # the same light, spread a little


def test_a_light_from_above_through_a_thick_base_is_bounded_and_conserves_its_light():
    """Light straight down through the neck, the liquid and a 5 mm base: focused under the
    bottle, finite, and no more light lands than entered the bottle's cylinder."""
    d = _lit(light=Light(direction=(0.0, 0.0, 1.0), intensity=1.0), fill=40.0)
    ctx = RenderContext.from_design(d, None, 8, 8)
    cs = ctx.finish.caustics[0]
    assert np.isfinite(cs).all()
    bound_r = 20.0 + 1e-3
    # clear glass and liquid: all but the reflections (about a tenth) and the light the rim sends up
    assert 0.6 * math.pi * bound_r ** 2 < _caustic_flux(d)[0] <= math.pi * bound_r ** 2 * 1.0


def test_a_shadow_catchers_cutout_holds_the_shadow_in_alpha_and_composites_back_to_the_render():
    from engine.tracer.picking import coverage, cutout
    design = _on_stage(Stage(kind="shadow"), fill=40.0, glass_absorption=(0.3, 0.3, 0.3))
    img, objects, ctx, _ = _pixels(design, spp=8)
    colour, alpha = cutout(design, None, img)
    h, w = img.shape[:2]
    bottle = coverage(design, w, h)
    assert (alpha >= bottle - 1e-6).all() and (alpha[bottle == 1.0] == 1.0).all()
    # where each pixel's centre ray meets the ground: how far from the bottle's axis (mm)
    rows, cols = np.mgrid[0:h, 0:w]
    eye, d = ctx.camera.rays(cols.ravel() + 0.5, rows.ravel() + 0.5)
    t = (design.stage.z_mm - eye[:, 2]) / np.where(d[:, 2] < 0.0, d[:, 2], -1e-300)
    rho = np.hypot(eye[:, 0] + t * d[:, 0], eye[:, 1] + t * d[:, 1]).reshape(h, w)
    ground = (objects & ctx.ground_objects) != 0
    ground_mat = int(ctx.scene.geom.obj_i[-1, O_MAT])
    bound_r = float(ctx.scene.mat_f[ground_mat, MG_BOUND_R])
    near, far = ground & (bottle == 0.0) & (rho < 1.5 * bound_r), ground & (bottle == 0.0) & (rho > 6.0 * bound_r)
    assert near.any() and far.any()
    assert np.median(alpha[near]) > 0.05, "the bottle's shadow is in alpha"
    # the sky it hides falls with distance: far off, the catcher shows the environment itself (to
    # the bottle's faint sky shadow, and where the far ground shows the studio's sharp edges the
    # render's 8 samples per pixel average it differently from the cutout's 16)
    assert np.median(alpha[far]) < 0.02 and np.median(alpha[far]) < 0.2 * np.median(alpha[near])
    # laid over the background the catcher showed, the cutout gives the render back
    from engine.tracer.picking import _pixel_parts
    _, _, bg = _pixel_parts(design, w, h, 4, ctx.environment)
    back = alpha[..., None] * colour + (1.0 - alpha[..., None]) * bg
    ground_only = (bottle == 0.0) & (objects != 0) & (img <= bg).all(axis=2)  # (a caustic: alpha 0, lost)
    assert np.allclose(back[ground_only], img[ground_only], atol=1e-4)
    # a stage other than the catcher: alpha is the bottle's coverage alone
    table = dataclasses.replace(design, stage=TABLE)
    assert np.array_equal(cutout(table, None, img)[1], bottle)
