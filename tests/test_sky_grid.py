"""The ground's sky grid: the sky's light on the ground estimated once per design.

It must agree with the ground's own per-hit probes (what it replaces) to their noise, be the
same for any number of threads, leave the ground noise-free except where light is really
sampled (a light's penumbra), and not hold up the window: a job draws a draft while it builds,
ends the same image as a job that found it built, and stops building when cancelled.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from engine.model.design import Light, Stage
from engine.tracer.context import RenderContext, trace_rays
from engine.tracer.job import RenderJob
from engine.tracer.job_options import JobObservers
from engine.tracer.sampling import Sampling
from engine.tracer.kernels.ground import NOISY_BIT, S_NRING, SKY_COLS, ring_cells, sky_irradiance
from engine.tracer.tables import stage as stage_tables
from engine.tracer.tables.labels import with_buffers
from engine.tracer.tables.sky import cell_centres, sky_grid, sky_grid_pays
from engine.tracer.tables.stage import open_sky_irradiance, stage_grids_ready
from tests.test_stage import _on_stage, _pixels

GREY = Stage(kind="table", color=(0.6, 0.6, 0.6))


def _down(ctx, xy, repeats=1):
    """Radiance of ``repeats`` vertical rays onto each ground point ``xy`` (mm): ``(n, repeats, 3)``."""
    xy = np.repeat(np.asarray(xy, float), repeats, axis=0)
    out, _ = trace_rays(ctx, np.column_stack([xy, np.full(len(xy), 300.0)]), np.tile([0.0, 0.0, -1.0], (len(xy), 1)))
    return out.reshape(-1, repeats, 3)


def test_the_sky_grid_agrees_with_the_grounds_own_probes_to_their_noise():
    ctx = RenderContext.from_design(_on_stage(GREY, fill=40.0), None, 8, 8, grids=True)
    probing = dataclasses.replace(ctx, finish=ctx.finish._replace(sky_grid=np.zeros(SKY_COLS)))
    # under the 20 mm bottle, at its foot, and out on the table
    points = [(r * math.cos(a), r * math.sin(a)) for r in (5.0, 12.0, 21.0, 24.0, 35.0, 60.0) for a in (0.3, 2.0, 4.0)]
    grid = _down(ctx, points)[:, 0]
    probes = _down(probing, points, 1024)
    mean, se = probes.mean(axis=1), probes.std(axis=1) / math.sqrt(probes.shape[1])
    open_sky = 0.6 * open_sky_irradiance(ctx.environment)
    assert (probes.std(axis=1) > 0.0).all()  # (the probes do scatter: there is something to agree with)
    # each point within its probes' noise, plus the grid's own (cells of 64-256 probes, read bilinearly)
    assert (np.abs(grid - mean) < 4.0 * se + 0.03 * open_sky).all()
    # and no bias over those beside the bottle (under it, seen only through its base, cells are
    # noisier: 64-256 probes through the whole bottle each)
    beside = np.hypot(*np.asarray(points).T) > 20.0
    assert abs(((grid - mean) / open_sky)[beside].mean()) < 0.015


def test_the_sky_grid_is_the_same_for_any_number_of_threads():
    ctx = RenderContext.from_design(_on_stage(GREY, fill=40.0), None, 8, 8, grids=True)
    fin = ctx.finish._replace(sky_grid=np.zeros(SKY_COLS))
    ground = ctx.scene.geom.obj_i.shape[0] - 1
    args = (ctx.tables(with_buffers(ctx.labels))._replace(finishes=fin), ground, -0.0, 60.0, ctx.max_depth,
            ctx.min_weight)
    one, row = sky_grid(*args, threads=1)
    two, row2 = sky_grid(*args, threads=2)
    assert np.array_equal(row, row2) and one.shape == (ring_cells(row, int(row[S_NRING]))[0], 3)
    assert np.array_equal(one, two)


def test_the_ground_reads_each_cell_at_its_centre():
    ctx = RenderContext.from_design(_on_stage(GREY, fill=40.0), None, 8, 8, grids=True)
    row = ctx.finish.sky_grid
    centres, rings = cell_centres(row)
    # the kernels' cell order is the tables': ring i's cells are ring_cells(row, i)
    for i in range(int(row[S_NRING])):
        first, count = ring_cells(row, i)
        assert (rings[first:first + count] == i).all()
    assert len(centres) == len(ctx.finish.sky)
    fin = ctx.finish._replace(sky=np.column_stack([centres, np.arange(len(centres), dtype=float)]))
    for k in range(0, len(centres), 7):
        x, y, z, inside = sky_irradiance(fin, centres[k, 0], centres[k, 1])
        assert inside and abs(x - centres[k, 0]) < 1e-6 * (1 + abs(x)) and abs(z - k) < 1e-6


def test_ground_pixels_are_noisy_only_in_a_lights_penumbra():
    design = _on_stage(GREY, fill=40.0)
    _, objects, ctx, _ = _pixels(design, spp=1, first=0, grids=True)
    ground = (objects & ctx.ground_objects) != 0
    only_ground = objects == ctx.ground_objects
    assert only_ground.mean() > 0.3 and not ((objects[only_ground] & NOISY_BIT) != 0).any()  # all from the grid
    # (a reflection in the glass may reach the ground beyond the grid, where it probes)
    assert ((objects & NOISY_BIT) != 0).mean() < 0.02
    sun = dataclasses.replace(design, lights=(Light(direction=(0.4, 0.6, 0.7), intensity=2.0, angle_deg=2.0),))
    _, objects, ctx, _ = _pixels(sun, spp=1, first=0, grids=True)
    noisy = (objects & NOISY_BIT) != 0
    assert ctx.stochastic_objects == NOISY_BIT
    assert 0 < noisy.sum() < 0.1 * ground.sum()  # the shadow's soft edge, a few pixels wide
    point = dataclasses.replace(sun, lights=(dataclasses.replace(sun.lights[0], angle_deg=0.0),))
    _, objects, _, _ = _pixels(point, spp=1, first=0, grids=True)
    only_ground = objects == ctx.ground_objects
    assert not ((objects[only_ground] & NOISY_BIT) != 0).any()  # a point light's shadow ray is exact


#: A job's image: large enough to pay for a sky grid (engine.tracer.tables.sky.sky_grid_pays).
JOB_SIZE = (320, 320)


def _job(design, **kw):
    job = RenderJob(design, None, width=JOB_SIZE[0], height=JOB_SIZE[1], spp=1, sampling=Sampling(adaptive=False),
                    threads=2, **kw).start()
    assert job.wait(600)
    return job


def test_a_job_draws_a_draft_while_the_grids_build_and_ends_with_the_same_image():
    design = _on_stage(GREY, fill=40.0)
    stage_tables.clear_stage_caches()
    waves = []
    fresh = _job(design, observers=JobObservers(
        on_wave=lambda job, wave: waves.append((wave, job.context.finish.sky_grid[S_NRING]))))
    assert fresh.error is None and stage_grids_ready(design, None, *JOB_SIZE)
    assert waves[0] == (0, 0.0) and waves[1][0] == 0 and waves[1][1] > 0  # the draft's preview, then the render's
    cached = _job(design)
    assert np.array_equal(fresh.image(), cached.image())


def test_cancelling_a_job_stops_its_grids_building():
    design = _on_stage(Stage(kind="table", color=(0.5, 0.6, 0.7)), fill=30.0)
    stage_tables.clear_stage_caches()
    job = _job(design, observers=JobObservers(on_wave=lambda job, wave: job.cancel()))  # after the draft's preview
    assert job.cancelled and job.error is None
    assert not stage_grids_ready(design, None, *JOB_SIZE)  # nothing half-built was kept


def test_small_images_probe_per_hit_and_large_ones_read_the_grid():
    design = _on_stage(GREY, fill=40.0)
    assert not sky_grid_pays(256, 256) and sky_grid_pays(715, 953)
    small = RenderContext.from_design(design, None, 256, 256)
    large = RenderContext.from_design(design, None, 715, 953)
    assert small.finish.sky_grid[S_NRING] == 0 and large.finish.sky_grid[S_NRING] > 0
    assert stage_grids_ready(design, None, 256, 256)  # nothing to build for a small image


def test_the_open_sky_cache_keeps_its_map_alive_so_no_other_map_takes_its_id():
    """The cache names a map by ``id(texels)``; were the map freed while its entry lived, the
    next map allocated at that address would be handed the freed map's irradiance."""
    import gc
    import weakref
    from types import SimpleNamespace

    texels = np.full((4, 8, 3), 0.25, np.float32)
    env = SimpleNamespace(texels=texels, scale=1.0, rotation_deg=0.0,
                          lookup=lambda d: np.full((len(d), 3), 0.25))
    e_up = open_sky_irradiance(env)
    assert np.allclose(e_up, 0.25)
    alive = weakref.ref(texels)
    del env, texels
    gc.collect()
    assert alive() is not None, "while its entry is cached, the map's id cannot be reused"
