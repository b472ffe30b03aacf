"""Render -> Final image, driven through its real widgets: the file is what ``glassbench render``
writes, progress and time left show, cancel writes nothing, and the live preview comes back."""
from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest
from PySide6.QtCore import Qt

from app.final_render import format_seconds
from engine.files.images import read_image
from engine.files.project import load_project
from engine.files.images import save_image
from engine.tracer.denoise import RAW_NOTE
from engine.tracer.job import render_image

pytestmark = pytest.mark.usefixtures("no_leaks")

BORDEAUX = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources",
                        "bordeaux.glassbench")


@pytest.fixture
def window(make_window):
    """The window on the Bordeaux sample with a 48 x 64, 1 spp preview (quick to render)."""
    design, assets = load_project(BORDEAUX)
    small = dataclasses.replace(design, render=dataclasses.replace(design.render, width=48, height=64, spp=1))
    return make_window(small, assets=assets)


def open_dialog(w, qtbot, path, width=24, height=32, spp=2, fmt=0, alpha=False):
    w.render_controller.wait_until_idle(60)
    w.final_image_action.trigger()
    d = w.final_render
    assert d.isVisible()
    d.width_px.setValue(width)
    d.height_px.setValue(height)
    d.samples.setValue(spp)
    d.format.setCurrentIndex(fmt)
    d.alpha.setChecked(alpha)
    d.path.setText(str(path))
    return d


def test_a_final_image_is_the_command_line_render_and_the_preview_comes_back(window, qtbot, tmp_path):
    w = window
    out = tmp_path / "out"
    out.mkdir()
    d = open_dialog(w, qtbot, out / "final.png")
    opened = []
    d.open_folder = opened.append
    rc = w.render_controller
    with qtbot.waitSignal(d.ended, timeout=60_000) as ended:
        qtbot.mouseClick(d.render_button, Qt.LeftButton)
        assert rc.held and rc.job is None, "the preview makes way for the final render"
        assert not d.render_button.isEnabled() and d.cancel_button.isEnabled()
    assert ended.args[0] == "written"
    assert d.progress.value() == d.progress.maximum()
    assert "Saved" in d.status.text()
    reference = out / "reference.png"
    save_image(str(reference), render_image(w.scene.snapshot(), dict(w.scene.assets), width=24, height=32,
                                            spp=2), description=RAW_NOTE)
    assert (out / "final.png").read_bytes() == reference.read_bytes()
    assert d.open_button.isEnabled()
    qtbot.mouseClick(d.open_button, Qt.LeftButton)
    assert opened == [str(out)]
    assert not rc.held
    qtbot.waitUntil(lambda: rc.converged_generation == rc.generation, timeout=60_000)
    assert sorted(os.listdir(out)) == ["final.png", "reference.png"]


def test_cancel_writes_nothing_and_releases_the_preview(window, qtbot, tmp_path):
    w = window
    out = tmp_path / "out"
    out.mkdir()
    d = open_dialog(w, qtbot, out / "big.png", width=320, height=400, spp=256)
    qtbot.mouseClick(d.render_button, Qt.LeftButton)
    qtbot.waitUntil(lambda: d.progress.value() > 0, timeout=60_000)
    assert d.time_left.text().startswith("Time left:")
    with qtbot.waitSignal(d.ended, timeout=60_000) as ended:
        qtbot.mouseClick(d.cancel_button, Qt.LeftButton)
    assert ended.args[0] == "cancelled"
    assert os.listdir(out) == [], "no image and no partial file"
    assert d.render_button.isEnabled() and not d.open_button.isEnabled()
    assert not w.render_controller.held
    qtbot.waitUntil(lambda: w.render_controller.job is not None, timeout=10_000)


def test_exr_with_alpha_and_a_refused_folder(window, qtbot, tmp_path):
    w = window
    d = open_dialog(w, qtbot, tmp_path / "shot.png", fmt=1, alpha=True)
    assert d.path.text().endswith("shot.png")
    d.format.setCurrentIndex(2)
    d.format.setCurrentIndex(1)
    assert d.path.text() == str(tmp_path / "shot.exr"), "the suffix follows the format"
    with qtbot.waitSignal(d.ended, timeout=60_000) as ended:
        qtbot.mouseClick(d.render_button, Qt.LeftButton)
    assert ended.args[0] == "written"
    img = read_image(str(tmp_path / "shot.exr"))
    assert img.shape == (32, 24, 4) and img.dtype == np.float32
    alpha = img[..., 3]
    assert alpha[0, 0] == 0.0 and alpha.max() == 1.0
    assert np.all(img[..., :3][alpha == 0] == 0), "EXR colour is premultiplied"

    d.path.setText(str(tmp_path / "no such folder" / "x.png"))
    qtbot.mouseClick(d.render_button, Qt.LeftButton)
    assert "does not exist" in d.status.text()
    assert not w.render_controller.held and d.render_button.isEnabled()


def test_time_left_reads_as_minutes_and_seconds():
    assert format_seconds(None) == "estimating\u2026"
    assert format_seconds(12.4) == "12 s"
    assert format_seconds(65) == "1 min 05 s"


def test_shutting_the_window_mid_render_stops_it_and_writes_nothing(window, qtbot, tmp_path):
    w = window
    out = tmp_path / "out"
    out.mkdir()
    d = open_dialog(w, qtbot, out / "big.png", width=320, height=400, spp=256)
    qtbot.mouseClick(d.render_button, Qt.LeftButton)
    qtbot.waitUntil(lambda: d.progress.value() > 0, timeout=60_000)
    render = d.current
    w.shutdown()
    assert render.done and render.state == "cancelled"
    assert not d.isVisible() and os.listdir(out) == []


def test_denoise_writes_the_denoised_image_and_the_raw_one_beside_it(window, qtbot, tmp_path):
    import OpenImageIO as oiio
    w = window
    out = tmp_path / "out"
    out.mkdir()
    d = open_dialog(w, qtbot, out / "still.png", spp=1)
    d.denoise.setChecked(True)
    with qtbot.waitSignal(d.ended, timeout=60_000) as ended:
        qtbot.mouseClick(d.render_button, Qt.LeftButton)
        assert not d.denoise.isEnabled()
    assert ended.args[0] == "written"
    assert sorted(os.listdir(out)) == ["still.png", "still.raw.png"]
    notes = {}
    for name in ("still.png", "still.raw.png"):
        inp = oiio.ImageInput.open(str(out / name))
        notes[name] = inp.spec().get_string_attribute("ImageDescription")
        inp.close()
    assert notes["still.raw.png"] == RAW_NOTE
    assert notes["still.png"].startswith("glassbench: denoised estimate of the raw render still.raw.png")
    assert not np.array_equal(read_image(str(out / "still.png")), read_image(str(out / "still.raw.png")))
