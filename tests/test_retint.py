"""Colour-only edits keep the ray trees' information (issue 42, item 4): the job after a tint or
liquid-colour edit shows the last converged film retinted by its own first centres, labelled as
an estimate, while it renders in full; the film and "converged" never see the estimate."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from engine.color import srgb_encode
from engine.files.project import load_project
from engine.model.changes import Change
from engine.tracer.denoise import Denoiser, preview_frame
from engine.tracer.job import RenderJob
from engine.tracer.job_options import JobObservers, Replaces
from engine.tracer.retint import RetintBasis, colour_only, local_fit, retinted
from engine.tracer.reuse import FULL_RENDER, Retint, reuse_of
from engine.tracer.sampling import Sampling

WINDOW = Sampling(noise_target=2.0, noise_space="display")
AMBER = (0.004, 0.03, 0.09)


def _sample(name="jar", width=72, height=96):
    d, a = load_project(f"resources/{name}.glassbench")
    return dataclasses.replace(d, render=dataclasses.replace(d.render, width=width, height=height)), a


def _tinted(d, tint=AMBER, liquid=(0.06, 0.02, 0.004)):
    glass = dataclasses.replace(d.glass, absorption=tuple(a + t for a, t in zip(d.glass.absorption, tint)))
    return dataclasses.replace(d, glass=glass, liquid=d.liquid and dataclasses.replace(d.liquid, absorption=liquid))


def _render(d, a, **kw):
    job = RenderJob(d, a, threads=2, sampling=WINDOW, **kw).start()
    assert job.wait(600) and job.error is None
    return job


def _levels(img):
    return srgb_encode(np.asarray(img, np.float64)) * 255.0


def _rms(a, b) -> float:
    return float(np.sqrt(np.mean((_levels(a) - _levels(b)) ** 2)))


@pytest.fixture(scope="module")
def jar_edit():
    """The jar converged, then its amber-and-blue edit rendered as the window renders it (told
    what changed), the new film copied after each wave."""
    d, a = _sample()
    old = _render(d, a)
    frames = []

    def on_wave(job, wave):  # (the job's thread, between waves: the film holds waves 0..wave)
        frames.append((wave, preview_frame(job, None), job.image()))

    new = _render(_tinted(d), a, replaces=Replaces(old, Change({"glass", "liquid"})),
                  observers=JobObservers(on_wave=on_wave))
    return d, a, old, new, frames


def test_only_an_absorption_edit_is_colour_only():
    d, _ = _sample()
    glass = Change({"glass"})
    assert colour_only(d, _tinted(d), Change({"glass", "liquid"}))
    assert colour_only(d, dataclasses.replace(d, notes="why amber"), Change({"notes"}))
    assert not colour_only(d, dataclasses.replace(d, glass=dataclasses.replace(d.glass, ior=1.6)), glass)
    tinted_and_bent = _tinted(dataclasses.replace(d, glass=dataclasses.replace(d.glass, ior=1.6)))
    assert not colour_only(d, tinted_and_bent, glass), "a tint with an index change bends the rays"
    fuller = dataclasses.replace(d, liquid=dataclasses.replace(d.liquid, fill_value=d.liquid.fill_value - 5))
    assert not colour_only(d, fuller, Change({"liquid"})), "a fill level moves the liquid's surface"
    assert not colour_only(d, dataclasses.replace(d, liquid=None), Change({"liquid"})), "no liquid, no tree"
    assert not colour_only(d, _tinted(d), Change({"glass", "camera"}))
    assert not colour_only(d, _tinted(d), Change({"glass"}, assets={"env"}))


def test_a_colour_edit_retints_the_converged_film_and_a_chain_of_them_keeps_its_basis(jar_edit):
    d, a, old, new, _ = jar_edit
    assert isinstance(new.retint, RetintBasis) and new.retint.design is d
    h, w = new.height, new.width
    assert new.retint.nbytes == 33 * h * w  # two float32 images, a signature, a flag: bounded per pixel
    # the next colour edit while that job runs (here: a stand-in that has not finished) keeps it
    unfinished = _Unfinished(new)
    again = _tinted(d, tint=(0.0, 0.01, 0.02))
    chained = reuse_of(unfinished, again, a, new.sampling_key(), Change({"glass"}))
    assert isinstance(chained, Retint) and chained.basis is new.retint
    bent = dataclasses.replace(again, glass=dataclasses.replace(again.glass, ior=1.6))
    assert reuse_of(unfinished, bent, a, new.sampling_key(), Change({"glass"})) is FULL_RENDER
    assert reuse_of(old, again, a, ("other size",), Change({"glass"})) is FULL_RENDER


class _Unfinished:
    """A job still running (or cancelled by the next edit) with ``job``'s design and basis."""

    def __init__(self, job):
        self.design, self.retint, self.sampling_key = job.design, job.retint, job.sampling_key
        self.done, self.error, self.cancelled, self.context = False, None, True, None


def test_the_retint_never_touches_the_film_the_converged_image_is_a_fresh_render(jar_edit):
    d, a, old, new, frames = jar_edit
    fresh = _render(_tinted(d), a)
    assert np.array_equal(new.image(), fresh.image()), "bit for bit: the estimate is display only"
    assert np.array_equal(new.sample_counts(), fresh.sample_counts())
    assert all(np.array_equal(raw, frames[i][2]) for i, (_, _, raw) in enumerate(frames))


def test_the_retinted_preview_is_near_the_new_converged_image_from_the_first_centres(jar_edit):
    d, a, old, new, frames = jar_edit
    converged = new.image()
    edit = _rms(old.image(), converged)
    assert edit > 20.0, "the edit moves the image (display levels RMS)"
    first_wave, first, raw0 = frames[0]
    assert first_wave == 0 and first is not None, "a frame from the preview wave on (the denoiser waits for wave 1)"
    assert _rms(first, converged) < 0.4 * edit < _rms(raw0, converged)
    centres = next(f for w, f, _ in frames if w == 1)
    # measured (display levels RMS) 9.6 after the preview wave, 5.9 after the centres, 3.9 and
    # 2.2 after the next waves, at 72 x 96 where a third of the pixels are edges (the edit: 42)
    assert _rms(centres, converged) < 7.5
    errors = [_rms(f, converged) for _, f, _ in frames]
    assert errors[-1] < 0.5 * errors[1], "the raw film takes over as its own error falls"


def test_where_the_old_channel_is_dark_the_fit_gives_the_new_mean_not_a_ratio():
    """A liquid that absorbed blue (old blue ~ 0) turned blue: a ratio of centres would divide by
    noise; the local line's regulariser gives the neighbourhood's new value."""
    rng = np.random.default_rng(7)
    old = np.zeros((12, 12, 3), np.float32)
    old[..., 0] = 0.5 + 0.05 * rng.random((12, 12))
    old[..., 2] = 1e-7 * rng.random((12, 12))  # black blue, noise only
    new = old.copy()
    new[..., 0] *= 0.5  # red halves: a factor
    new[..., 2] = 0.3  # blue appears
    alpha, beta, count, residual = local_fit(old, new, np.ones((12, 12), bool), eps=(1e-3) ** 2)
    est = alpha * old + beta
    assert np.allclose(est[..., 0], new[..., 0], rtol=1e-3), "a factor is found exactly"
    assert np.allclose(est[..., 2], 0.3, atol=1e-4), "a dark channel gives the new mean"
    assert np.all(count[1:-1, 1:-1] == 9) and float(residual[..., 0].max()) < 1e-8


def test_before_any_centre_there_is_no_retinted_frame():
    d, a = _sample(width=16, height=20)
    old = _render(d, a)
    job = RenderJob(_tinted(d), a, threads=1, sampling=WINDOW)  # (not started: nothing in its film)
    from engine.tracer.retint import basis_of_film

    basis = basis_of_film(d, old.film, old.image(), old.context.reference_level)
    assert retinted(basis, job.film) is None
    job.retint = basis
    assert preview_frame(job, Denoiser()) is None
