"""RenderJob: determinism across threads and tiles, progressive waves, cancellation, errors."""
from __future__ import annotations

import threading

import numpy as np
import pytest

import engine.tracer.job as job_module
from engine.tracer import scheduler
from engine.tracer.adaptive import preview_block
from engine.tracer.tables.render_objects import render_geometry_for
from engine.tracer.job import RenderJob, render_image, tonemap_srgb8
from engine.tracer.job_options import BenchHooks, JobObservers, Replaces, Workers
from tests.test_tracer import simple_design


def test_image_is_bit_identical_for_any_thread_count_and_tile_order():
    design = simple_design(40.0, glass_absorption=(0.01, 0.0, 0.02), width=24, height=32, spp=4)
    a = render_image(design, threads=1, workers=Workers(tile=16))
    b = render_image(design, threads=2, workers=Workers(tile=12), _bench=BenchHooks(tile_shuffle_seed=7))
    c = render_image(design, threads=3, workers=Workers(tile=32), _bench=BenchHooks(tile_shuffle_seed=1))
    assert a.shape == (32, 24, 3) and a.dtype == np.float32
    assert np.array_equal(a, b) and np.array_equal(a, c)
    assert a.std() > 0.01  # a real picture, not a constant


def test_waves_go_from_preview_to_full_resolution_and_progress_reaches_one():
    design = simple_design(40.0, width=32, height=32, spp=4)
    waves, progress = [], []

    def on_tile(job, tile):
        waves.append(tile.wave)
        progress.append(job.progress)
        assert 0 <= tile.x0 < tile.x1 <= 32 and 0 <= tile.y0 < tile.y1 <= 32

    done = threading.Event()
    job = RenderJob(design, threads=2, workers=Workers(tile=16),
                    observers=JobObservers(on_tile=on_tile, on_done=lambda j: done.set())).start()
    assert job.wait(120) and done.is_set()
    assert job.done and not job.cancelled and job.error is None
    assert waves == sorted(waves) and waves[0] == 0 and max(waves) >= 2
    assert all(0 <= p <= 1 for p in progress) and progress == sorted(progress) and job.progress == 1.0
    n = job.sample_counts()
    assert n.min() >= 1  # every pixel has its centre
    assert n.max() >= 4 and (n >= 4).mean() < 0.9  # edges are anti-aliased, smooth parts are not


def test_preview_wave_fills_the_whole_image():
    design = simple_design(40.0, width=32, height=32, spp=2)
    seen = {}

    def on_tile(job, tile):
        if tile.wave == 1 and "img" not in seen:  # the preview wave is complete: a barrier
            seen["img"] = job.image()
            job.cancel()

    job = RenderJob(design, threads=1, workers=Workers(tile=16), observers=JobObservers(on_tile=on_tile)).start()
    assert job.wait(120) and job.cancelled
    img = seen["img"]
    assert img.shape == (32, 32, 3) and np.all(np.isfinite(img)) and np.all(img > 0)


def test_on_wave_sees_the_film_after_each_whole_wave():
    design = simple_design(40.0, width=32, height=32, spp=4)
    seen = []

    def on_wave(job, wave):
        seen.append((wave, threading.current_thread().name, job.sample_counts(), job.image()))

    job = RenderJob(design, threads=2, workers=Workers(tile=16), observers=JobObservers(on_wave=on_wave)).start()
    assert job.wait(120) and job.error is None
    waves = [w for w, *_ in seen]
    assert waves == list(range(len(waves))) and len(waves) == len(job.wave_log) >= 3
    assert all(name == "RenderJob" for _, name, _, _ in seen)  # between waves, not on a worker
    counts = [n for _, _, n, _ in seen]
    b = preview_block(32, 32)
    assert (counts[0] > 0).sum() == (32 // b) ** 2  # the preview: one centre per b x b block
    assert counts[1].min() >= 1  # after the centres' wave every pixel has one
    assert all(np.all(b >= a) for a, b in zip(counts, counts[1:]))
    assert np.array_equal(counts[-1], job.sample_counts())
    assert np.array_equal(seen[-1][3], job.image())  # the last wave's film is the result
    assert all(np.all(np.isfinite(img)) for *_, img in seen)


def test_cancel_stops_within_one_tile_per_thread():
    design = simple_design(40.0, width=64, height=64, spp=16)
    calls = []

    def on_tile(job, tile):
        calls.append(tile)
        job.cancel()

    job = RenderJob(design, threads=2, workers=Workers(tile=8), observers=JobObservers(on_tile=on_tile)).start()
    assert job.wait(120)
    assert job.cancelled and job.done and job.error is None
    assert 1 <= len(calls) <= 2  # only tiles already running when the flag was set finish
    assert job.progress < 0.1


def test_a_failing_worker_is_reported_not_swallowed(monkeypatch):
    design = simple_design(40.0, width=32, height=32, spp=2)
    render_geometry_for(design)
    real = job_module.trace_pixels
    count = {"n": 0}

    def flaky(*args, **kw):
        count["n"] += 1
        if count["n"] == 3:
            raise RuntimeError("tile exploded")
        return real(*args, **kw)

    monkeypatch.setattr(job_module, "trace_pixels", flaky)
    reported = []
    job = RenderJob(design, threads=2, workers=Workers(tile=16),
                    observers=JobObservers(on_done=lambda j: reported.append(j.error))).start()
    assert job.wait(120)
    assert isinstance(job.error, RuntimeError) and "exploded" in str(job.error)
    assert reported and reported[0] is job.error
    count["n"] = 0
    with pytest.raises(RuntimeError, match="exploded"):
        render_image(design, threads=1, workers=Workers(tile=16))


def test_wait_returns_only_after_on_done_returned():
    """A window tears down the signals ``on_done`` emits once ``wait`` returned: the job must
    not run any code after that (the race crashed the window at quit, CI stop 17)."""
    design = simple_design(40.0, width=8, height=8, spp=1)
    inside, release, seen = threading.Event(), threading.Event(), []

    def on_done(j):
        seen.append(j.done)  # done is already true for the callback
        inside.set()
        release.wait(60)

    job = RenderJob(design, threads=1, workers=Workers(tile=16), observers=JobObservers(on_done=on_done)).start()
    assert inside.wait(120) and seen == [True]
    assert job.done and not job.wait(0.05), "wait returned while on_done still ran"
    release.set()
    assert job.wait(60)


def test_camera_edit_reuses_geometry_and_fill_edit_rebuilds_it():
    import dataclasses

    design = simple_design(40.0)
    g = render_geometry_for(design)
    moved = dataclasses.replace(design, camera=dataclasses.replace(design.camera, eye=(10, -200, 50)),
                                glass=dataclasses.replace(design.glass, absorption=(0.1, 0, 0)))
    assert render_geometry_for(moved) is g
    refilled = dataclasses.replace(design, liquid=dataclasses.replace(design.liquid, fill_value=30.0))
    assert render_geometry_for(refilled) is not g


def test_tonemap_is_clamped_srgb():
    img = np.array([[[0.0, 1.0, 0.5], [np.nan, 7.0, 0.0031308]]])
    out = tonemap_srgb8(img)
    assert out.dtype == np.uint8
    assert out[0, 0].tolist() == [0, 255, 188]
    assert out[0, 1].tolist() == [0, 255, 10]


def test_render_command_writes_png_and_exr(tmp_path, capsys):
    from engine.tracer.tables.environment import read_radiance_image
    from engine.files.project import save_project
    from engine.cli.render import render_command

    proj = tmp_path / "b.glassbench"
    save_project(proj, simple_design(40.0))
    for name in ("o.png", "o.exr"):
        assert render_command(proj, tmp_path / name, width=20, height=16, spp=1, progress=False) == 0
        img = read_radiance_image(tmp_path / name)
        assert img.shape == (16, 20, 3) and img.max() > 0
    assert "rendered 20x16" in capsys.readouterr().out


def test_an_edit_of_nothing_rendered_keeps_the_film_and_a_visible_edit_does_not():
    import dataclasses

    design = simple_design(40.0, width=24, height=24, spp=2)
    first = RenderJob(design, threads=2).start()
    assert first.wait(120) and first.error is None
    renamed = dataclasses.replace(design, name="another name", notes="n")
    again = RenderJob(renamed, threads=2, replaces=Replaces(first, {"name", "notes"})).start()
    assert again.wait(120) and again.error is None
    assert again.film is first.film and again.stats.rays_cast == first.stats.rays_cast
    assert again.progress == 1.0 and np.array_equal(again.image(), first.image())
    tinted = dataclasses.replace(design, glass=dataclasses.replace(design.glass, absorption=(0.05, 0, 0)))
    third = RenderJob(tinted, threads=2, replaces=Replaces(first, {"glass"})).start()
    assert third.wait(120) and third.film is not first.film
    assert not np.array_equal(third.image(), first.image())
    # the same design asked with another sampling: a new film, never the old one
    finer = RenderJob(renamed, threads=2, replaces=Replaces(first, {"name"}),
                      sampling=dataclasses.replace(first.sampling, noise_target=first.sampling.noise_target / 4)).start()
    assert finer.wait(120) and finer.film is not first.film and finer.stats.rays_cast > first.stats.rays_cast


def test_workers_run_niced_and_render_the_same_image():
    """The window's workers yield the core to the GUI thread (niceness) without changing a pixel."""
    import os

    design = simple_design(40.0, width=24, height=32, spp=2)
    seen = []

    def record(job, tile):
        seen.append(os.getpriority(os.PRIO_PROCESS, threading.get_native_id()))

    base = os.getpriority(os.PRIO_PROCESS, 0)
    plain = render_image(design, width=24, height=32, threads=2)
    job = RenderJob(design, width=24, height=32, threads=2, workers=Workers(nice=5),
                    observers=JobObservers(on_tile=record)).start()
    job.wait()
    assert job.error is None and seen
    assert set(seen) == {min(19, base + 5)}
    assert os.getpriority(os.PRIO_PROCESS, 0) == base  # the calling thread keeps its priority
    assert np.array_equal(job.image(), plain)


def test_a_region_of_the_image_is_that_slice_of_the_whole():
    """The window repaints finished tiles from ``image(region)``: the same pixels as the whole
    image, without copying it."""
    from tests.test_tracer import simple_design

    job = RenderJob(simple_design(40.0, width=24, height=20, spp=2), threads=1).start()
    assert job.wait(60) and job.error is None
    whole = job.image()
    for region in [(0, 20, 0, 24), (3, 11, 5, 17), (19, 20, 23, 24)]:
        y0, y1, x0, x1 = region
        part = job.image(region)
        assert part.dtype == np.float32 and np.array_equal(part, whole[y0:y1, x0:x1])


def test_the_film_adds_a_tiles_results_where_they_belong():
    """The film's compiled accumulation against the same sums written out: centres stored,
    anti-aliasing sums and counts added, object masks OR-ed, depths min-ed and capped at 255,
    a scalar count applying to every pixel; pixels not listed untouched."""
    from engine.tracer.context import PixelResult
    from engine.tracer.film import NEVER, Film

    rng = np.random.default_rng(3)
    film = Film(5, 4, 2)
    cols, rows = np.array([0, 4, 2]), np.array([3, 0, 1])

    def result():
        return PixelResult(rng.random((3, 3)), rng.random(3), rng.integers(0, 2 ** 63, 3).astype(np.uint64),
                           rng.integers(0, 2 ** 40, 3), rng.integers(0, 400, (3, 2)), np.zeros(8, np.int64), 3)

    c, a1, a2 = result(), result(), result()
    film.add_centre(cols, rows, c)
    film.add_aa(cols, rows, np.array([1, 2, 3]), a1)
    film.add_aa(cols, rows, 4, a2)
    np.testing.assert_array_equal(film.centre[rows, cols], c.sums)
    np.testing.assert_array_equal(film.signature[rows, cols], c.signature)
    np.testing.assert_allclose(film.aa_sum[rows, cols], a1.sums + a2.sums, rtol=1e-15)
    np.testing.assert_allclose(film.aa_sumsq[rows, cols], a1.sumsq + a2.sumsq, rtol=1e-15)
    np.testing.assert_array_equal(film.aa_count[rows, cols], [5, 6, 7])
    np.testing.assert_array_equal(film.objects[rows, cols], c.objects | a1.objects | a2.objects)
    np.testing.assert_array_equal(film.depth[rows, cols],
                                  np.minimum(np.minimum(np.minimum(c.depth, a1.depth), a2.depth), NEVER))
    untouched = np.ones((4, 5), bool)
    untouched[rows, cols] = False
    assert not film.has_centre[untouched].any() and not film.aa_count[untouched].any()
    assert np.all(film.depth[untouched] == NEVER) and film.has_centre[rows, cols].all()


def test_the_film_refuses_pixels_outside_it_and_results_of_another_size():
    """The compiled loops check no bounds: the film does, before them, and changes nothing."""
    from engine.tracer.context import PixelResult
    from engine.tracer.film import Film

    film = Film(5, 4, 2)

    def result(n, m=2):
        return PixelResult(np.ones((n, 3)), np.ones(n), np.ones(n, np.uint64), np.ones(n, np.int64),
                           np.zeros((n, m), np.int64), np.zeros(8, np.int64), n)

    for cols, rows in (([5], [0]), ([0], [4]), ([-1], [0]), ([0, 1], [0])):
        with pytest.raises(ValueError, match="film"):
            film.add_centre(np.array(cols), np.array(rows), result(len(cols)))
    with pytest.raises(ValueError, match="film"):
        film.add_aa(np.array([0, 1]), np.array([0, 0]), 1, result(3))
    with pytest.raises(ValueError, match="film"):
        film.add_aa(np.array([0]), np.array([0]), 1, result(1, m=1))
    assert not film.has_centre.any() and not film.aa_count.any()


def test_small_tiles_are_batched_in_order_until_a_task_is_worth_its_overhead():
    """A preview wave's tiles (a few samples each) go in batches of at least MIN_TASK_SAMPLES,
    in their order; a tile of that much work is a task of its own; no tile lost or repeated."""
    work = np.zeros((64, 96), np.int64)
    work[::8, ::8] = 1  # a preview: one centre per 8 x 8 block
    work[32:48, 48:64] = scheduler.MIN_TASK_SAMPLES  # one heavy tile
    tiles = [(x, y, x + 16, y + 16) for y in range(0, 64, 16) for x in range(0, 96, 16)]
    batches = scheduler.batches(tiles, [int(work[y0:y1, x0:x1].sum()) for x0, y0, x1, y1 in tiles])
    assert [tl for b in batches for tl in b] == tiles
    sums = [sum(int(work[y0:y1, x0:x1].sum()) for x0, y0, x1, y1 in b) for b in batches]
    assert all(s >= scheduler.MIN_TASK_SAMPLES for s in sums[:-1])
    assert [(48, 32, 64, 48)] in batches or any(b[-1] == (48, 32, 64, 48) for b in batches)
    assert len(batches) < len(tiles) // 4


def test_the_films_display_levels_are_the_tone_map_of_its_estimate_bit_for_bit():
    """The window's tiles (compiled) against tonemap_srgb8 of Film.image: pixels with only a
    preview, a centre, anti-aliasing samples, non-finite and negative values, highlights above
    white and values at every level's threshold; a region cut at the image's edge."""
    from engine.color import LEVEL_THRESHOLDS, tonemap_srgb8
    from engine.tracer.film import Film

    rng = np.random.default_rng(4)
    film = Film(40, 30, 1)
    film.preview[...] = rng.random((30, 40, 3)) * 1.5
    film.centre[10:] = rng.random((20, 40, 3))
    film.has_centre[10:] = True
    film.aa_sum[20:] = rng.random((10, 40, 3)) * 3.0
    film.aa_count[20:] = rng.integers(1, 4, (10, 40))
    film.centre[12, :3] = [[np.nan, np.inf, -np.inf], [-1.0, 2.0, 0.5], [1e30, 0.0, 1e-9]]
    t = LEVEL_THRESHOLDS.astype(np.float64)
    film.centre[14:17, :, :] = np.stack([t[:120], np.nextafter(t[:120], 0), t[120:240]], 0).reshape(3, 40, 3)
    for region in ((0, 30, 0, 40), (5, 25, 7, 33), (28, 45, 35, 60)):
        want = tonemap_srgb8(film.image(region if region[1] <= 30 else (28, 30, 35, 40)))
        np.testing.assert_array_equal(film.display(region), want)
    assert film.display((0, 30, 0, 40)).dtype == np.uint8 and len(np.unique(film.display((14, 17, 0, 40)))) > 200


def test_the_grouped_options_come_as_records_checked_when_the_job_is_made():
    """Options that travel together come as records (:mod:`engine.tracer.job_options`): a loose
    keyword of the old signature, or a record's fields passed as a dict, is a TypeError at once,
    not in the middle of a render; the workers' record keeps its tile and niceness in range."""
    design = simple_design(40.0, width=8, height=8, spp=1)
    for bad in (dict(tile=16), dict(on_tile=print), dict(previous=None, changed=None), dict(worker_nice=5),
                dict(_sample_base=1), dict(observers={"on_tile": print}), dict(workers=16),
                dict(_bench={"sample_base": 1})):
        with pytest.raises(TypeError):
            RenderJob(design, **bad)
    job = RenderJob(design, workers=Workers(tile=0, nice=-3))
    assert (job.tile, job.worker_nice) == (1, 0)
