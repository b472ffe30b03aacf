"""The window's denoised preview (issue 42): after an edit on the knurled jar the pane shows the
denoiser's estimate, says so, and then the converged raw film; View ▸ Raw preview shows the
raw film at once."""
from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from engine.files.project import load_project

pytestmark = pytest.mark.usefixtures("no_leaks")


def _knurled_jar(width=64, height=80):
    d, a = load_project("resources/knurled_jar.glassbench")
    return dataclasses.replace(d, render=dataclasses.replace(d.render, width=width, height=height)), a


def _shown(preview) -> np.ndarray:
    """The preview's image as an ``(h, w, 3)`` uint8 array."""
    w, h = preview.image_size()
    return np.array([[preview.pixel_rgb(x, y) for x in range(w)] for y in range(h)], np.uint8)


def _raw(rc) -> np.ndarray:
    w, h = rc.size
    return rc.job.display((0, h, 0, w))


def test_an_edit_on_the_knurled_jar_shows_a_denoised_preview_then_the_converged_raw_film(make_window, qtbot):
    d, a = _knurled_jar()
    w = make_window(d, assets=a)
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=300_000)
    seen = []
    rc.stateChanged.connect(lambda state, wave, fraction: seen.append((state, w.render_state.text())))
    frames = []
    rc.tileReady.connect(lambda g, x0, y0, rgb8: frames.append(rgb8) if rgb8.shape[:2] == (80, 64) else None)
    assert w.editor.apply("Glass IOR", None, glass=dataclasses.replace(d.glass, ior=d.glass.ior + 0.02))
    qtbot.waitUntil(lambda: rc.state == "denoised", timeout=300_000)
    assert re.fullmatch(r"Denoised preview \u00b7 (1 sample|\d+ samples)", w.render_state.text())
    assert w.preview.note == "denoised preview"
    denoised = frames[-1]
    assert np.array_equal(_shown(w.preview), denoised)  # the whole frame, not tiles over it
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=300_000)
    states = [s for s, _ in seen]
    assert "denoised" in states and states[-1] == "converged" and states.index("denoised") < len(states) - 1
    assert w.render_state.text().startswith("Converged")  # never said of the denoised image
    assert np.array_equal(_shown(w.preview), _raw(rc)), "converged: the raw film, whole"
    assert not np.array_equal(denoised, _raw(rc))
    qtbot.waitUntil(rc.denoiser_idle, timeout=60_000)


def test_the_raw_toggle_shows_the_raw_film_and_back(make_window, qtbot):
    d, a = _knurled_jar()
    w = make_window(d, assets=a)
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.state == "denoised", timeout=300_000)
    frames = []
    rc.tileReady.connect(lambda g, x0, y0, rgb8: frames.append(rgb8))
    w.raw_preview_action.setChecked(True)  # View ▸ Raw preview: at once, the film as it is
    if rc.ended_generation != rc.generation:
        assert frames and frames[0].shape[:2] == (80, 64), "the raw film painted whole"
        assert w.render_state.text().startswith("Refining") and w.preview.note == "refining"
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=300_000)
    assert np.array_equal(_shown(w.preview), _raw(rc))
    states = []
    rc.stateChanged.connect(lambda state, wave, fraction: states.append(state))
    assert w.editor.apply("Glass IOR", None, glass=dataclasses.replace(d.glass, ior=d.glass.ior + 0.03))
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=300_000)
    assert "denoised" not in states and states[-1] == "converged"  # raw: no denoised frame at all
    w.raw_preview_action.setChecked(False)
    assert rc.denoise
    qtbot.waitUntil(rc.denoiser_idle, timeout=60_000)


def test_a_tint_edit_on_the_knurled_jar_shows_the_last_image_retinted_then_the_converged_film(make_window, qtbot):
    """Issue 42 item 4: a colour-only edit shows the last converged image in the new colour from
    the first wave on, says what it is, and ends on the raw converged film."""
    d, a = _knurled_jar()
    w = make_window(d, assets=a)
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=300_000)
    before = _raw(rc).astype(float)
    seen = []
    rc.stateChanged.connect(lambda state, wave, fraction: seen.append((state, wave, w.render_state.text())))
    frames = []
    rc.tileReady.connect(lambda g, x0, y0, rgb8: frames.append(rgb8) if rgb8.shape[:2] == (80, 64) else None)
    amber = tuple(x + t for x, t in zip(d.glass.absorption, (0.004, 0.03, 0.09)))
    assert w.editor.apply("Glass colour", None, glass=dataclasses.replace(d.glass, absorption=amber))
    qtbot.waitUntil(lambda: rc.state == "retinted", timeout=300_000)
    assert rc.job.retint is not None
    assert re.fullmatch(r"Retinted preview \(the last image, new colour\) \u00b7 (1 sample|\d+ samples)",
                        w.render_state.text())
    assert w.preview.note == "retinted preview"
    retinted = frames[-1]
    assert np.array_equal(_shown(w.preview), retinted)
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation, timeout=300_000)
    states = [s for s, _, _ in seen]
    assert "denoised" not in states and states[-1] == "converged"
    first = next(wave for s, wave, _ in seen if s == "retinted")
    assert first <= 1, "the retinted frame comes with the first waves"
    assert np.array_equal(_shown(w.preview), _raw(rc)), "converged: the raw film, whole"
    # the estimates near the result (nearer than the image before the edit), and nearer as the
    # new film's own samples take over (every whole frame but the last, the converged film's)
    after = _raw(rc).astype(float)
    edit, first, last = (float(np.sqrt(np.mean((img.astype(float) - after) ** 2))) for img in (before, frames[0], frames[-2]))
    assert first < edit and last < 0.5 * edit, (first, last, edit)
    qtbot.waitUntil(rc.denoiser_idle, timeout=60_000)
