"""The adaptive policy's noise criterion: linear radiance (references) or display units (window)."""
from __future__ import annotations

import numpy as np
import pytest

from engine.tracer import adaptive
from engine.tracer.film import Film
from engine.color import srgb_encode
from engine.tracer.job import tonemap_srgb8


def _film_with(pixels, centres=None):
    """A 1-row film whose pixel i holds anti-aliasing samples ``pixels[i]`` (grey values) and
    the centre sample ``centres[i]`` (by default the samples' mean: a centre adding no scatter)."""
    film = Film(len(pixels), 1)
    for i, samples in enumerate(pixels):
        s = np.asarray(samples, float)
        if s.size == 0:  # a pixel without anti-aliasing samples
            continue
        film.aa_count[0, i] = len(s)
        film.aa_sum[0, i] = s.sum()
        film.aa_sumsq[0, i] = (s ** 2).sum()
        film.centre[0, i] = s.mean() if centres is None else centres[i]
        film.has_centre[0, i] = True
    return film


def test_display_slope_is_the_tone_maps_derivative_and_zero_above_white():
    v = np.array([0.001, 0.02, 0.18, 0.5, 0.9])
    h = 1e-6
    numeric = (tonemap_srgb8_float(v + h) - tonemap_srgb8_float(v - h)) / (2 * h)
    assert np.allclose(adaptive.display_slope(v), numeric, rtol=1e-5)
    assert adaptive.display_slope(1.5) == 0.0


tonemap_srgb8_float = srgb_encode  # the tone map before quantisation (to differentiate it)


def test_tone_map_matches_the_slopes_curve():
    x = np.linspace(0, 1, 1001)[:, None, None] * np.ones((1, 1, 3))
    assert np.array_equal(tonemap_srgb8(x)[..., 0], np.clip(np.round(tonemap_srgb8_float(x[..., 0]) * 255), 0, 255))


def test_display_space_asks_more_of_dark_glass_and_nothing_of_clipped_highlights():
    rng = np.random.default_rng(3)
    scatter = rng.normal(0.0, 1.0, 8)
    scatter = (scatter - scatter.mean()) / scatter.std()  # exactly unit spread
    dark = 0.12 + 0.05 * scatter
    mid = 0.5 + 0.05 * scatter  # the same spread, brighter: the display compresses it
    white = 6.0 + 0.5 * scatter  # far above white: the display shows 255 whatever
    film = _film_with([dark, [], mid, [], white])  # two apart: no neighbour shares
    want = adaptive.noise_targets(film, 10_000, adaptive.DISPLAY_NOISE, 1.0, space="display")[0][::2]
    assert want[0] > want[1] > 8, "same radiance spread: the darker pixel needs more samples"
    assert want[2] == 8, "a clipped highlight keeps what it has"
    # n = var slope^2 / target^2, the standard error's tolerance in display units
    var = np.var(np.append(dark, dark.mean()), ddof=1)  # the centre is one more observation
    assert want[0] == np.ceil(var * adaptive.display_slope(dark.mean()) ** 2 / adaptive.DISPLAY_NOISE ** 2)
    lin = adaptive.noise_targets(film, 100_000, 0.001, 1.0)[0][::2]
    assert abs(lin[0] - lin[1]) <= 1 and lin[2] > 9 * lin[0], "linear radiance: the spread alone decides"
    with pytest.raises(ValueError, match="noise space"):
        adaptive.noise_targets(film, 10, 0.01, 1.0, space="log")


def test_the_windows_jobs_use_the_display_criterion():
    from app import engine_bridge
    from engine.tracer.job import RenderJob
    from tests.test_tracer import simple_design

    job = RenderJob(simple_design(40.0, width=8, height=8, spp=1), sampling=engine_bridge.WINDOW_NOISE)
    assert job.sampling.noise_space == "display" and job.sampling.noise_target == adaptive.DISPLAY_NOISE
    assert RenderJob(simple_design(40.0, width=8, height=8, spp=1)).sampling.noise_space == "linear"


def test_sampling_options_are_one_checked_immutable_record():
    """A job's sampling options travel as one :class:`Sampling`: a bad field is refused by
    name when the record is made, equal options compare equal whatever number types they came
    in, and a job takes nothing else (no loose keywords, no dict)."""
    import dataclasses

    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling
    from tests.test_tracer import simple_design

    for bad, field in ((dict(noise_space="gamma"), "noise_space"), (dict(policy="greedy"), "policy"),
                       (dict(noise_target=0.0), "noise_target"), (dict(noise_target=float("nan")), "noise_target"),
                       (dict(noise_target=-0.01), "noise_target"), (dict(cap_factor=0), "cap_factor")):
        with pytest.raises(ValueError, match=field):
            Sampling(**bad)
    s = Sampling()
    assert (s.adaptive, s.noise_target, s.noise_space, s.policy, s.cap_factor) == (
        True, adaptive.NOISE_TARGET, "linear", "split", None)
    assert Sampling(adaptive=1, noise_target=1, cap_factor=3.0) == Sampling(noise_target=1.0, cap_factor=3)
    assert type(Sampling(cap_factor=3.0).cap_factor) is int and type(Sampling(noise_target=1).noise_target) is float
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.noise_target = 0.5
    design = simple_design(40.0, width=8, height=8, spp=1)
    with pytest.raises(TypeError, match="Sampling"):
        RenderJob(design, sampling={"noise_space": "display"})
    with pytest.raises(TypeError):
        RenderJob(design, noise_target=0.01)


def test_a_centre_that_disagrees_with_agreeing_samples_asks_for_more():
    """Four stratified samples can all miss a thin bright feature the centre sample met: the
    scatter counts the centre, so the pixel is not taken as converged."""
    film = _film_with([[0.02] * 4, [], [0.02] * 4], centres=[0.7, 0.0, 0.02])
    want = adaptive.noise_targets(film, 64, 0.01, 1.0)[0][::2]
    assert want[0] >= 16 and want[1] == 4
    assert film.image()[0, 0, 0] == np.float32(0.02), "the centre never enters the pixel's value"


def test_a_quiet_pixel_beside_a_noisy_one_asks_a_share_of_its_need_in_linear_space_only():
    rng = np.random.default_rng(4)
    noisy = 0.5 + 0.3 * rng.standard_normal(8)
    quiet = np.full(8, 0.3)
    film = _film_with([noisy, quiet, quiet])  # pixel 2 is two pixels from the noisy one
    lin = adaptive.noise_targets(film, 10**6, 0.001, 1.0)[0]
    need = np.std(np.append(noisy, noisy.mean()), ddof=1) / 0.001
    assert lin[0] == np.ceil(need)
    assert lin[1] == np.ceil(adaptive.NEIGHBOUR_SHARE * need), "its neighbour's share"
    assert lin[2] == 8, "the share reaches the next pixel only"
    disp = adaptive.noise_targets(film, 10**6, adaptive.DISPLAY_NOISE, 1.0, space="display")[0]
    assert disp[0] > 8 and disp[1] == 8, "display space: the quiet pixel keeps what it has"


def test_final_renders_give_samples_in_proportion_to_a_pixels_scatter():
    """Neyman allocation in linear space: four times the scatter asks four times the samples
    (not sixteen, as a common standard error would); each pixel's standard error is then the
    geometric mean of its one-sample scatter and the tolerance."""
    rng = np.random.default_rng(5)
    unit = rng.normal(0.0, 1.0, 8)
    unit = (unit - unit.mean()) / unit.std(ddof=1)
    film = _film_with([0.5 + 0.01 * unit, [], [], 0.5 + 0.04 * unit])  # apart: no neighbour share
    want = adaptive.noise_targets(film, 10**6, 1e-4, 1.0)[0]
    sd = [np.std(np.append(0.5 + a * unit, 0.5), ddof=1) for a in (0.01, 0.04)]
    assert list(want[[0, 3]]) == [int(np.ceil(s / 1e-4)) for s in sd]
    assert 3.9 < want[3] / want[0] < 4.1
    assert list(adaptive.noise_targets(film, 200, 1e-4, 1.0)[0][[0, 3]]) == [want[0], 200]  # the cap
    assert adaptive.plan(16, True, adaptive.LINEAR_FACTOR)[-1][0] == adaptive.LINEAR_FACTOR * 16


def _plan_factors(monkeypatch) -> list:
    """The cap factors :func:`adaptive.plan` is called with from now on (appended per call)."""
    seen = []
    keep = adaptive.plan

    def spy(spp, adaptive_, factor=adaptive.ADAPTIVE_FACTOR):
        seen.append(factor)
        return keep(spp, adaptive_, factor)

    monkeypatch.setattr(adaptive, "plan", spy)
    return seen


def test_final_renders_raise_pixels_to_the_linear_cap_and_the_window_classic_to_its_own(monkeypatch):
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling
    from tests.test_tracer import simple_design

    seen = _plan_factors(monkeypatch)
    for space, target in (("linear", 0.01), ("display", adaptive.DISPLAY_NOISE)):
        job = RenderJob(simple_design(40.0, width=8, height=8, spp=1),
                        sampling=Sampling(noise_space=space, noise_target=target, policy="classic")).start()
        job.wait()
        assert job.error is None
    assert seen == [adaptive.LINEAR_FACTOR, adaptive.ADAPTIVE_FACTOR]


def test_a_cap_factor_raises_the_classic_cap_and_is_part_of_what_a_job_samples(monkeypatch):
    """References at a tight tolerance need more than the default cap in thick bases
    (outline_public_1 at 0.003: 1.10 % rel RMSE at 512 samples, 1.01 % at 4096)."""
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling
    from tests.test_tracer import simple_design

    seen = _plan_factors(monkeypatch)
    design = simple_design(40.0, width=8, height=8, spp=2)
    jobs = [RenderJob(design, sampling=Sampling(noise_target=0.01, policy="classic", cap_factor=f)) for f in (None, 3)]
    for job in jobs:
        job.start().wait()
        assert job.error is None
    assert seen == [adaptive.LINEAR_FACTOR, 3]
    assert adaptive.ScatterPolicy(0.01, "linear", 3).rounds(2, True)[-1] == (6, True)
    assert jobs[0].sampling_key() != jobs[1].sampling_key()  # (a finished job is not reused for the other)


def _split_film(first, last):
    """A 1-row film whose pixel i had ``len(first[i])`` samples before the last round (the mark)
    and ``first[i] + last[i]`` after it (grey values)."""
    film = _film_with([list(a) + list(b) for a, b in zip(first, last)])
    mark = (np.array([[sum(a) for a in first]], float), np.array([[len(a) for a in first]], np.int64))
    return film, mark


def test_the_split_estimate_asks_for_more_where_the_two_halves_disagree_and_stops_where_they_agree():
    # pixel 0: both halves 0.2 (a converged edge); pixels 1, 2: no samples; pixel 3: halves 0.1
    # and 0.3 (not yet), far enough from pixel 0 not to be pooled with it
    film, mark = _split_film([[0.1, 0.3, 0.2, 0.2], [], [], [0.1] * 4], [[0.2, 0.2, 0.3, 0.1], [], [], [0.3] * 4])
    want = adaptive.split_targets(film, mark, 64, adaptive.DISPLAY_NOISE)
    assert list(want[0]) == [8, 0, 0, 16]
    assert list(adaptive.split_targets(film, mark, 8, adaptive.DISPLAY_NOISE)[0]) == [8, 0, 0, 8]  # the cap


def test_one_lucky_agreement_does_not_stop_a_pixel_whose_neighbours_still_scatter():
    # pixel 1's halves agree exactly; its neighbours' halves are far apart
    film, mark = _split_film([[0.1] * 4, [0.2] * 4, [0.1] * 4], [[0.4] * 4, [0.2] * 4, [0.4] * 4])
    want = adaptive.split_targets(film, mark, 64, adaptive.DISPLAY_NOISE)
    assert list(want[0]) == [16, 16, 16]
    alone, mark1 = _split_film([[0.2] * 4], [[0.2] * 4])
    assert list(adaptive.split_targets(alone, mark1, 64, adaptive.DISPLAY_NOISE)[0]) == [8]


def test_a_pixel_whose_halves_still_disagree_is_unconverged_and_an_agreeing_one_is_not():
    film, mark = _split_film([[0.1, 0.3, 0.2, 0.2], [], [], [0.1] * 4], [[0.2, 0.2, 0.3, 0.1], [], [], [0.3] * 4])
    assert list(adaptive.split_unconverged(film, mark, adaptive.DISPLAY_NOISE)[0]) == [False, False, False, True]


def _one_noisy_pixel_among(n_pixels):
    """A 1-row film of ``n_pixels``: pixel 0's two halves of 4 samples disagree by about 60
    display levels (an estimate of about 30), the others have no anti-aliasing samples."""
    return _split_film([[0.1] * 4] + [[]] * (n_pixels - 1), [[0.3] * 4] + [[]] * (n_pixels - 1))


def test_the_window_loosens_its_tolerance_only_as_far_as_the_image_stays_within_its_bound():
    """One pixel about 30 levels off, clipped to the step: the image's RMS is ``step /
    sqrt(pixels)``, which must stay within half the 2-level tolerance (1 level)."""
    tol = adaptive.DISPLAY_NOISE
    wide = max(adaptive.SPLIT_LADDER)

    def chosen(n_pixels, previous=np.inf, cap=1 << 20):
        film, mark = _one_noisy_pixel_among(n_pixels)
        return adaptive.split_tolerance(film, mark, tol, previous, cap) / tol

    assert chosen(4) == 1.0  # 2 levels over 4 pixels: exactly the bound of 1 level
    assert chosen(20) == 2.0  # 4 levels / sqrt(20) = 0.89; 6 levels would give 1.34
    assert chosen(100) == wide  # 8 levels / 10 = 0.8: the ladder's widest step
    assert chosen(100, previous=1.5 * tol) == 1.5  # rounds only tighten
    # at the sample cap already: the pixel keeps its 30 levels, 3 RMS over 100 pixels whatever
    # the step, so the window spends as the per-pixel tolerance would
    assert chosen(100, cap=8) == 1.0


def test_a_window_render_records_the_tolerance_it_settled_at(monkeypatch):
    from engine.tracer.job import RenderJob
    from app.engine_bridge import WINDOW_NOISE
    from tests.test_tracer import simple_design

    def settled():
        job = RenderJob(simple_design(), width=48, height=64, spp=1, threads=1, sampling=WINDOW_NOISE).start()
        job.wait()
        assert job.error is None
        return job.tolerance / adaptive.DISPLAY_NOISE

    assert settled() in adaptive.SPLIT_LADDER
    monkeypatch.setattr(adaptive, "SPLIT_LADDER", (1.0,))  # a one-step ladder: the per-pixel policy
    assert settled() == 1.0


def test_the_window_counts_the_pixels_its_sample_cap_stopped_above_the_tolerance():
    """A window render whose cap binds says how many pixels it stopped there (the status bar
    shows the share); a tolerance as wide as the display leaves none; final renders count none."""
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling
    from tests.test_tracer import simple_design

    def job_with(**kw):
        job = RenderJob(simple_design(), width=48, height=64, spp=1, threads=1,
                        sampling=Sampling(noise_space="display", **kw)).start()
        job.wait()
        assert job.error is None
        return job

    tight = job_with(noise_target=0.01 / 255.0)  # a hundredth of a level: the cap (24 samples) binds
    at_cap = tight.film.aa_count == adaptive.SPLIT_FACTOR
    assert 0 < tight.capped <= np.count_nonzero(at_cap)
    assert job_with(noise_target=1.0).capped == 0  # the whole display range: every pixel meets it
    assert job_with(noise_target=0.01 / 255.0, policy="classic").capped == 0


def test_the_split_plan_doubles_from_eight_and_the_window_uses_it():
    assert adaptive.split_plan(16, True) == [(4, False), (8, False), (16, True), (32, True), (64, True),
                                             (128, True), (256, True), (384, True)]
    assert adaptive.split_plan(16, True)[-1][0] == adaptive.SPLIT_FACTOR * 16
    assert adaptive.plan(16, True)[-1][0] == adaptive.ADAPTIVE_FACTOR * 16  # final renders keep theirs
    assert adaptive.split_plan(16, False) == [(4, False), (8, False), (16, False)]
    from engine.tracer.job import RenderJob
    from app.engine_bridge import WINDOW_NOISE
    from tests.test_tracer import simple_design
    job = RenderJob(simple_design(), width=8, height=8, sampling=WINDOW_NOISE)
    assert job.sampling.policy == "split" and job.sampling.noise_space == "display"


def test_the_window_plays_its_own_roulette_and_final_renders_theirs(monkeypatch):
    """The split policy's adaptive rounds play :data:`adaptive.SPLIT_ROULETTE`, the classic
    policy's :data:`adaptive.ROULETTE`; the uniform rounds trace whole trees."""
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling
    from tests.test_tracer import simple_design

    seen = {}
    real = RenderJob._wave

    def spy(self, pool, ctx, wave, mask, want, preview=None, roulette=0.0, **kw):
        seen.setdefault(self.sampling.policy, set()).add(roulette)
        return real(self, pool, ctx, wave, mask, want, preview=preview, roulette=roulette, **kw)

    monkeypatch.setattr(RenderJob, "_wave", spy)
    for policy in ("split", "classic"):
        job = RenderJob(simple_design(), width=24, height=32, spp=4, threads=1,
                        sampling=Sampling(noise_space="display", noise_target=0.1 / 255.0, policy=policy)).start()
        job.wait()
        assert job.error is None
    assert seen["split"] == {0.0, adaptive.SPLIT_ROULETTE}
    assert seen["classic"] == {0.0, adaptive.ROULETTE}


def test_a_sample_base_draws_other_samples_of_the_same_pixels():
    """``RenderJob(_bench=BenchHooks(sample_base=B))`` (the benchmarks' independent references)
    traces other anti-aliasing samples: the pixels without them keep their centre bit for bit,
    the anti-aliased ones change, and the image stays the same picture."""
    from engine.tracer.job import RenderJob
    from engine.tracer.job_options import BenchHooks
    from engine.tracer.sampling import Sampling
    from tests.test_tracer import simple_design

    def image(base):
        job = RenderJob(simple_design(), width=48, height=64, spp=8, threads=1, sampling=Sampling(adaptive=False),
                        _bench=BenchHooks(sample_base=base)).start()
        job.wait()
        assert job.error is None
        return job.image(), job.film.aa_count.copy()

    a, count_a = image(0)
    b, count_b = image(1 << 20)
    assert np.array_equal(count_a, count_b) and count_a.any()
    plain = count_a == 0
    assert np.array_equal(a[plain], b[plain])
    assert not np.array_equal(a[~plain], b[~plain])
    edge_a, edge_b = a[~plain], b[~plain]
    assert abs(edge_a.mean() - edge_b.mean()) < 0.05 * edge_a.mean()  # the same picture, unbiased



def test_final_renders_measure_smooth_pixels_on_the_bottle_and_the_window_does_not():
    """The edge test compares neighbouring centres and misses detail inside a pixel: final
    renders (adaptive, linear) measure every pixel on the bottle without an edge, the window's
    rounds and renders without adaptive rounds do not."""
    objects = np.array([[0, 1, 1, 4]])
    edges = np.array([[False, True, False, False]])
    assert adaptive.measure_mask(objects, edges, True, "linear").tolist() == [[False, False, True, True]]
    assert not adaptive.measure_mask(objects, edges, True, "display").any()
    assert not adaptive.measure_mask(objects, edges, False, "linear").any()


def test_a_measurement_stays_only_where_it_finds_detail_inside_the_pixel():
    """Pixel 0's samples agree with its centre (its centre stays its value), pixel 2's mean is
    a step above it (a caustic inside the pixel: it becomes an edge); pixel 1 was not measured."""
    film = _film_with([[0.30, 0.31, 0.29, 0.30], [0.5] * 4, [0.30, 0.30, 0.30, 0.90]],
                      centres=[0.30, 0.1, 0.30])
    measured = np.array([[True, False, True]])
    inner = adaptive.inner_steps(film, measured, 1.0)
    assert inner.tolist() == [[False, False, True]]
    film.forget(measured & ~inner)
    assert film.aa_count.tolist() == [[0, 4, 4]]
    assert film.image()[0, 0, 0] == np.float32(0.30), "a forgotten measurement shows the centre"
    assert adaptive.noise_targets(film, 64, 0.01, 1.0)[0, 0] == 0, "and leaves the adaptive rounds"


def test_a_final_render_measures_in_its_own_wave_and_keeps_what_it_finds(monkeypatch):
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling
    from tests.test_tracer import simple_design

    found = []
    keep = adaptive.inner_steps

    def spy(film, measured, level):
        inner = keep(film, measured, level)
        found.append((int(measured.sum()), int(inner.sum())))
        return inner

    monkeypatch.setattr(adaptive, "inner_steps", spy)
    jobs = {}
    for space, target in (("linear", 0.01), ("display", adaptive.DISPLAY_NOISE)):
        classic = Sampling(noise_space=space, noise_target=target, policy="classic")
        jobs[space] = job = RenderJob(simple_design(40.0, width=24, height=32, spp=4), threads=1,
                                      sampling=classic).start()
        job.wait()
        assert job.error is None
    assert len(found) == 1, "only the final render measures"
    measured, kept = found[0]
    assert measured > 0
    waves = [w[0] for w in jobs["linear"].wave_log]
    assert waves[:3] == [0, 1, 2] and jobs["linear"].wave_log[2][2] == adaptive.MEASURE_AA * measured
    n = jobs["linear"].sample_counts()
    assert (n == 1).sum() >= measured - kept, "the pixels whose measurement found nothing keep their centre"
