"""The sketch (issue 42): display-only samples traced before the centres where those would be
slow, pooled with the film's for the preview's denoiser, never in the film."""
from __future__ import annotations

import dataclasses

import numpy as np

from engine.files.project import load_project
from engine.tracer import sketch
from engine.tracer.context import PixelResult
from engine.tracer.denoise import Denoiser, denoised_frame
from engine.tracer.film import Film
from engine.tracer.job import RenderJob
from engine.tracer.job_options import JobObservers
from engine.tracer.sampling import Sampling

WINDOW = Sampling(noise_space="display", noise_target=2.0 / 255.0)
SKETCHING = dataclasses.replace(WINDOW, sketch=True)


def _result(values, guide=None):
    """A :class:`PixelResult` whose pixels' radiance sums are ``values`` ``(P, 3)``."""
    values = np.asarray(values, float)
    p = len(values)
    return PixelResult(values, np.zeros(p), np.zeros(p, np.uint64), np.zeros(p, np.int64),
                       np.zeros((p, 1), np.int64), np.zeros(1, np.int64), p, None,
                       np.zeros((p, 6)) if guide is None else np.asarray(guide, float))


def test_the_preview_pools_the_sketch_with_the_film_where_the_rounds_will_refine_and_keeps_smooth_centres():
    film = Film(5, 1)
    film.preview[...] = 0.9  # (the block preview)
    film.has_centre[0, :4] = True
    film.centre[0, :4] = 0.2
    film.aa_count[0, 2], film.aa_sum[0, 2] = 3, 3 * 0.5  # anti-aliasing samples, mean 0.5
    sk = sketch.Sketch(5, 1)
    guide = np.zeros((5, 6))
    guide[:, :3], guide[:, 5] = 0.4, 1.0  # (albedo 0.4, normal +z, per sample)
    sk.add(np.arange(5), np.zeros(5, int), 1, _result([[0.6] * 3] * 5, guide))
    sampled = np.array([[False, True, True, False, True]])
    colour, albedo, normal = sk.pooled(film, sampled)
    c = colour[0, :, 0]
    assert c[0] == np.float32(0.2), "a smooth pixel keeps its centre (exact on smooth glass)"
    assert np.isclose(c[1], (0.2 + 0.6) / 2), "an edge's centre counts as one sample beside the sketch's"
    assert np.isclose(c[2], (1.5 + 0.6) / 4), "anti-aliasing samples and the sketch's pooled"
    assert c[3] == np.float32(0.2)
    assert np.isclose(c[4], 0.6), "no centre yet: the sketch alone, not the block preview"
    assert np.allclose(albedo, 0.4) and np.allclose(normal[..., 2], 1.0)
    # before every centre is traced no pixel is known smooth: every centre is one sample more
    early = sk.pooled(film, None)[0][0, :, 0]
    assert np.isclose(early[0], 0.4) and np.isclose(early[4], 0.6)
    # no sketch sample, no centre: the block preview
    assert sketch.Sketch(5, 1).pooled(film, sampled)[0][0, 4, 0] == np.float32(0.9)


def _sample(name, width, height, spp=4):
    d, a = load_project(f"resources/{name}.glassbench")
    return dataclasses.replace(d, render=dataclasses.replace(d.render, width=width, height=height, spp=spp)), a


def test_a_heavy_design_sketches_before_its_centres_and_its_image_is_bit_for_bit_the_same():
    d, a = _sample("knurled_jar", 36, 48)
    waves = []
    seen = JobObservers(on_wave=lambda job, wave: waves.append((wave, job.sketched, int(job.film.has_centre.sum()))))
    plain = RenderJob(d, a, threads=2, sampling=WINDOW).start()
    sketched = RenderJob(d, a, threads=2, sampling=SKETCHING, observers=seen).start()
    assert plain.wait(900) and sketched.wait(900) and plain.error is None and sketched.error is None
    assert plain.sketch is None and plain.sketched == 0
    assert sketched.sketched == sketch.SKETCH_PASSES[-1]
    assert [s for _, s, _ in waves[:3]] == [0, *sketch.SKETCH_PASSES], "wave 0, then once per pass"
    assert all(w == 0 for w, _, _ in waves[:3])
    centres = {c for _, _, c in waves[:3]}
    assert len(centres) == 1 and 0 < centres.pop() < 36 * 48, "the sketch comes between the blocks and the centres"
    assert np.all(sketched.sketch.n == sketch.SKETCH_PASSES[-1])
    # display only: the film, the samples and the image are those of the render without it
    np.testing.assert_array_equal(sketched.image(), plain.image())
    np.testing.assert_array_equal(sketched.film.samples(), plain.film.samples())
    np.testing.assert_array_equal(sketched.film.guide_sum, plain.film.guide_sum)
    assert sketched.stats.rays_cast > plain.stats.rays_cast, "its rays are counted"


def test_a_light_design_traces_its_centres_first_and_an_unwatched_render_never_sketches():
    waves = []
    watched = JobObservers(on_wave=lambda job, wave: waves.append(wave))
    d, a = _sample("bordeaux", 36, 48)
    light = RenderJob(d, a, threads=2, sampling=SKETCHING, observers=watched).start()
    d, a = _sample("knurled_jar", 36, 48)
    unwatched = RenderJob(d, a, threads=2, sampling=SKETCHING).start()  # (the window's live drags)
    for job in (light, unwatched):
        assert job.wait(600) and job.error is None
        assert job.sketch is None and job.sketched == 0
    assert waves[:2] == [0, 1], "the Bordeaux: its centres right after the blocks"


def test_the_first_denoised_frame_of_a_sketch_is_a_full_frame_not_the_blocks():
    d, a = _sample("knurled_jar", 48, 64)
    frames = []

    def at_sketch(job, wave):
        if wave == 0 and job.sketched == 1 and not frames:  # (on the job's thread: the film is still)
            frames.append((job.image(), denoised_frame(job, Denoiser())))

    job = RenderJob(d, a, threads=2, sampling=SKETCHING, observers=JobObservers(on_wave=at_sketch)).start()
    assert job.wait(900) and job.error is None and frames
    blocks, frame = frames[0]
    final = job.image()
    assert np.all(np.isfinite(frame)) and frame.min() >= 0.0

    def rms(x):
        return float(np.sqrt(np.mean((np.clip(x, 0, 1) - np.clip(final, 0, 1)) ** 2)))

    # the blocks are the image at 1/16 of its resolution; the sketch's frame has every pixel
    assert rms(frame) < 0.8 * rms(blocks), (rms(frame), rms(blocks))


def test_a_pass_that_would_overrun_the_budget_is_left_to_the_film(monkeypatch):
    assert sketch.next_pass_fits(0.4, 0.4, 1, 3), "0.4 s, then 3 samples at 0.4 s each: 1.6 s"
    assert not sketch.next_pass_fits(1.3, 1.3, 1, 3), "the knurled jar's pace: 5.2 s"
    monkeypatch.setattr(sketch, "SKETCH_BUDGET_S", 0.0)
    d, a = _sample("knurled_jar", 36, 48)
    waves = []
    job = RenderJob(d, a, threads=2, sampling=SKETCHING,
                    observers=JobObservers(on_wave=lambda job, wave: waves.append((wave, job.sketched)))).start()
    assert job.wait(900) and job.error is None
    assert job.sketched == sketch.SKETCH_PASSES[0] and len(job.sketch_log) == 1, "the first pass only"
    assert waves[:3] == [(0, 0), (0, 1), (1, 1)]
