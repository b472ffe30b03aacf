"""The preview's denoiser (issue 42): OIDN with bounded threads over a whole frame, guided by the
albedo and normal the kernels record along each sample's dominant path; display only, so the
film, and with it "converged", never sees it."""
from __future__ import annotations

import dataclasses
import threading

import numpy as np
import pytest

from engine.files.images import image_description
from engine.files.project import load_project
from engine.tracer.denoise import Denoiser, FrameDenoiser, denoised_frame, raw_weight
from engine.tracer.film import Film
from engine.tracer.job import RenderJob
from engine.tracer.job_options import JobObservers

RNG = np.random.default_rng(42)


def _text_card(h=96, w=128):
    """A clean image of dark 'text' strokes on a light card, its albedo, a flat normal."""
    albedo = np.full((h, w, 3), 0.85, np.float32)
    for x0 in range(10, w - 10, 12):  # vertical strokes 3 px wide: text at the Nyquist edge
        albedo[20:h - 20, x0:x0 + 3] = 0.08
    normal = np.zeros((h, w, 3), np.float32)
    normal[..., 2] = 1.0
    return albedo * 0.9, albedo, normal


def test_the_denoiser_lowers_the_noise_and_a_guide_keeps_text_that_noise_would_smear():
    clean, albedo, normal = _text_card()
    noisy = np.maximum(clean * (1.0 + 0.9 * RNG.standard_normal(clean.shape)), 0.0).astype(np.float32)
    den = Denoiser(threads=1, quality="high")
    bare, guided = den(noisy), den(noisy, albedo, normal)
    err = {name: float(np.sqrt(np.mean((img - clean) ** 2))) for name, img in
           (("noisy", noisy), ("bare", bare), ("guided", guided))}
    assert err["bare"] < 0.5 * err["noisy"], err
    # the strokes: the albedo tells them from noise (measured 0.080 against 0.127 RMS)
    assert err["guided"] < 0.75 * err["bare"], err
    stroke, card = clean[48, 11, 0], clean[48, 17, 0]
    assert abs(guided[48, 11, 0] - stroke) < 0.5 * (card - stroke)
    assert noisy.dtype == np.float32 and np.all(np.isfinite(guided)) and guided.min() >= 0.0


def test_bad_guides_are_refused_with_the_reason():
    clean, albedo, normal = _text_card(16, 16)
    den = Denoiser()
    with pytest.raises(ValueError, match="normal guide needs an albedo"):
        den(clean, None, normal)
    with pytest.raises(ValueError, match="albedo guide is"):
        den(clean, albedo[:8], None)
    with pytest.raises(ValueError, match=r"\(height, width, 3\)"):
        den(clean[..., 0])
    with pytest.raises(ValueError, match="quality"):
        Denoiser(quality="best")(clean)


def _labelled(width=48, height=64, spp=4):
    d, a = load_project("resources/labelled.glassbench")
    return dataclasses.replace(d, render=dataclasses.replace(d.render, width=width, height=height, spp=spp)), a


def test_the_guides_show_the_label_through_the_glass_and_the_shape_by_its_normals():
    d, a = _labelled()
    job = RenderJob(d, a, threads=2).start()
    assert job.wait(600) and job.error is None
    albedo, normal = job.film.guides()
    length = np.linalg.norm(normal, axis=2)
    on_bottle, missed = length > 0.5, length == 0.0  # (edge pixels: some samples each)
    assert 0.1 < on_bottle.mean() < 0.9 and 0.1 < missed.mean() < 0.9
    assert np.all(albedo[missed] == 1.0), "nothing met: the environment, white"
    # the label (paper, printed) is not white, as glass and the environment seen through it are
    grey = albedo.mean(axis=2)
    assert (grey[on_bottle] < 0.8).mean() > 0.05 and np.median(grey[on_bottle]) > 0.95
    assert albedo.min() >= 0.0 and albedo.max() <= 1.0


def test_the_converged_image_is_the_same_with_the_denoiser_watching_every_wave():
    d, a = _labelled(36, 48)
    plain = RenderJob(d, a, threads=2).start()
    assert plain.wait(600) and plain.error is None
    frames, done = [], threading.Event()

    def deliver(key, image, samples):
        frames.append((key, image.shape, samples))
        done.set()

    watcher = FrameDenoiser(deliver)
    try:
        # from wave 1, the first at full resolution, as the window asks (wave 0 is the block preview)
        asks = JobObservers(on_wave=lambda job, wave: wave >= 1 and watcher.request(wave, job))
        watched = RenderJob(d, a, threads=2, observers=asks).start()
        assert watched.wait(600) and watched.error is None
        assert done.wait(60), "the denoiser delivered a frame"
    finally:
        watcher.close()
    assert frames and frames[0][1] == (48, 36, 3) and frames[0][2] >= 1.0
    np.testing.assert_array_equal(watched.image(), plain.image())  # bit for bit: display only
    np.testing.assert_array_equal(watched.film.samples(), plain.film.samples())


def _film_with(counts, means, spread):
    """A 1 x len(counts) film whose pixels hold ``counts`` samples of mean luminance ``means``
    scattered +- ``spread`` (every sample grey), each with its centre."""
    k = len(counts)
    film = Film(k, 1)
    film.has_centre[...] = True
    for x, (n, m, d) in enumerate(zip(counts, means, spread)):
        vals = np.array([m + d if i % 2 else m - d for i in range(n)])
        film.aa_count[0, x] = n
        film.aa_sum[0, x] = vals.sum()
        film.aa_sumsq[0, x] = (vals ** 2).sum()
    return film


def test_a_pixel_keeps_its_raw_value_once_its_own_error_is_small_and_an_edge_not_yet_sampled_is_denoised():
    # standard error of a mean of 0.18 (display level ~118): 64 samples +-0.001 -> ~0.05 levels,
    # 4 samples +-0.1 -> ~ 35 levels, 16 samples +-0.02 -> ~ 1.6 levels (between the bounds)
    film = _film_with([64, 4, 16, 0, 0, 1], [0.18] * 6, [0.001, 0.1, 0.02, 0, 0, 0])
    sampled = np.array([[False, True, True, False, True, True]])
    w = raw_weight(film, sampled)
    assert w[0, 0] == 1.0 and w[0, 1] == 0.0 and 0.0 < w[0, 2] < 1.0
    assert w[0, 3] == 1.0, "a smooth pixel's centre is its value: raw"
    assert w[0, 4] == 0.0 and w[0, 5] == 0.0, "an edge with its centre alone (or one sample): denoised"
    assert np.all(raw_weight(film, None)[0, 3:] == 0.0), "before every centre is traced, no pixel is known smooth"
    # more samples of the same scatter: a smaller error, a larger raw weight
    assert raw_weight(_film_with([64], [0.18], [0.02]))[0, 0] > w[0, 2]


def test_the_denoised_frame_of_a_converged_render_keeps_its_settled_pixels_raw():
    d, a = _labelled(36, 48)
    job = RenderJob(d, a, threads=2).start()
    assert job.wait(600) and job.error is None
    raw = job.image()
    out = denoised_frame(job, Denoiser())
    w = raw_weight(job.film, job.aa_pixels())
    settled = w == 1.0
    assert settled.mean() > 0.5, "most pixels of a converged render keep their raw value"
    np.testing.assert_allclose(out[settled], raw[settled], rtol=0, atol=1e-6)
    assert not np.allclose(out, raw), "the rest is the denoiser's"


def test_render_denoise_writes_the_denoised_image_and_keeps_the_raw_one_beside_it(tmp_path, capsys):
    import OpenImageIO as oiio

    from engine import cli
    out = tmp_path / "still.exr"
    assert cli.main(["render", "resources/labelled.glassbench", "-o", str(out), "--width", "36", "--height", "48",
                     "--spp", "2", "--denoise"]) == 0
    raw = tmp_path / "still.raw.exr"
    assert f"wrote {out} (denoised) and {raw} (raw)" in capsys.readouterr().out
    assert image_description(raw).startswith("glassbench: raw render")
    assert image_description(out).startswith("glassbench: denoised estimate of the raw render still.raw.exr")
    a, b = oiio.ImageBuf(str(out)).get_pixels(), oiio.ImageBuf(str(raw)).get_pixels()
    assert a.shape == b.shape == (48, 36, 3) and not np.array_equal(a, b)
    plain = tmp_path / "plain.exr"
    assert cli.main(["render", "resources/labelled.glassbench", "-o", str(plain), "--width", "36", "--height", "48",
                     "--spp", "2"]) == 0
    assert image_description(plain).startswith("glassbench: raw render")
    np.testing.assert_array_equal(oiio.ImageBuf(str(plain)).get_pixels(), b)  # the raw film, untouched
