"""glassbench share: the review folder opened from disk in Debian's chromium (headless) loads the
scene in <model-viewer> without console errors, shows a picture, and shows the numbers of
``glassbench info --json``; the folder is self-contained and replaced whole."""
from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

from engine import cli
from engine.export.share import MARKER, write_share
from engine.export.web import check_page
from tests.export_helpers import SAMPLES, load, no_labels

#: Poster height (pixels) in tests: small, the tracer still renders it to its noise target.
POSTER = 48


def info_json(capsys, project) -> dict:
    assert cli.main(["info", str(project), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def assert_not_blank(png) -> None:
    """A picture, not a flat fill: many colours and a real spread of levels."""
    px = np.asarray(Image.open(png).convert("RGB"), float)
    assert px.std() > 8.0
    assert len(np.unique(px.reshape(-1, 3), axis=0)) > 100


@pytest.mark.parametrize("project", SAMPLES, ids=lambda p: p.stem)
def test_page_opens_offline_in_chromium_on_every_sample(project, tmp_path, capsys):
    numbers = info_json(capsys, project)
    out = tmp_path / "review"
    assert cli.main(["share", str(project), "-o", str(out), "--poster-height", str(POSTER)]) == 0
    assert "index.html" in capsys.readouterr().out
    html = (out / "index.html").read_text()
    assert "http:" not in html and "https:" not in html  # nothing fetched from elsewhere
    assert json.loads((out / "numbers.json").read_text()) == numbers
    design, _ = load(project.name)
    assert len(list(out.glob("dielines/*.svg"))) == len(design.labels)
    with Image.open(out / "poster.png") as poster:
        assert poster.size[1] == POSTER
    report = check_page(out / "index.html", tmp_path / "shot.png")
    assert report["console_errors"] == [] and report["page_errors"] == []
    assert report["failed_requests"] == []
    assert report["loaded"] is True and report["model_viewer"] is True
    assert report["numbers"] == numbers
    for key, text in report["shown"].items():
        assert json.loads(text) == numbers[key], key
    assert set(report["shown"]) >= {"glass_volume_cm3", "fill_ml", "brimful_ml"}
    assert_not_blank(tmp_path / "shot-viewer.png")


def test_labels_die_lines_are_svg_at_scale(tmp_path):
    design, assets = load("labelled.glassbench")
    out = write_share(design, assets, tmp_path / "r", poster_height=POSTER)
    svg = (out / "dielines" / "0000.svg").read_text()
    assert svg.lstrip().startswith("<?xml") or svg.lstrip().startswith("<svg")
    assert 'width="' in svg and "mm" in svg
    page = (out / "index.html").read_text()
    assert 'href="dielines/0000.svg"' in page and design.labels[0].name in page


def test_turntable_frames_become_a_flip_book(tmp_path):
    frames = tmp_path / "turn"
    frames.mkdir()
    for k in range(3):
        Image.new("RGB", (8, 8), (40 * k, 0, 0)).save(frames / f"frame_{k:04d}.png")
    design, assets = no_labels()
    out = write_share(design, assets, tmp_path / "r", poster_height=POSTER, turntable=frames)
    assert sorted(p.name for p in (out / "turntable").iterdir()) == ["0000.png", "0001.png", "0002.png"]
    page = (out / "index.html").read_text()
    assert 'id="turntable" src="turntable/0000.png"' in page and 'max="2"' in page
    assert "No labels." in page and "Denoised frames" not in page


def test_a_denoised_turntable_is_a_flip_book_of_its_denoised_frames_said_to_be_so(tmp_path):
    from engine.files.images import save_image
    from engine.tracer.denoise import DENOISED_NOTE, RAW_NOTE
    frames = tmp_path / "turn"
    frames.mkdir()
    for k in range(2):  # as turntable --denoise writes them
        rgb = np.full((8, 8, 3), 0.1 * (k + 1), np.float32)
        save_image(frames / f"frame_{k:04d}.raw.png", rgb, None, RAW_NOTE)
        save_image(frames / f"frame_{k:04d}.png", rgb, None, DENOISED_NOTE.format(raw=f"frame_{k:04d}.raw.png"))
    design, assets = no_labels()
    out = write_share(design, assets, tmp_path / "r", poster_height=8, turntable=frames)
    assert sorted(p.name for p in (out / "turntable").iterdir()) == ["0000.png", "0001.png"]
    page = (out / "index.html").read_text()
    assert 'max="1"' in page and "Denoised frames (Intel Open Image Denoise)" in page


def test_a_foreign_folder_is_never_replaced_and_a_page_is(tmp_path, capsys):
    design, assets = load("jar.glassbench")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "thesis.txt").write_text("keep me")
    assert cli.main(["share", str(SAMPLES[0]), "-o", str(mine), "--poster-height", "8"]) == 2
    assert "not a glassbench review page" in capsys.readouterr().err
    assert [p.name for p in mine.iterdir()] == ["thesis.txt"]
    out = write_share(design, assets, tmp_path / "page", poster_height=8)
    (out / "stale.txt").write_text("from before")
    write_share(design, assets, out, poster_height=8)
    assert (out / MARKER).exists() and not (out / "stale.txt").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine", "page"]  # no temporaries left


def test_share_denoise_writes_the_denoised_poster_and_the_raw_one_beside_it_and_says_so(tmp_path, capsys):
    from engine.files.images import image_description, read_image
    project = next(p for p in SAMPLES if p.name == "labelled.glassbench")
    out = tmp_path / "review"
    assert cli.main(["share", str(project), "-o", str(out), "--poster-height", str(POSTER), "--denoise"]) == 0
    assert "poster.raw.png" in capsys.readouterr().out
    poster, raw = out / "poster.png", out / "poster.raw.png"
    assert image_description(raw).startswith("glassbench: raw render")
    assert image_description(poster).startswith("glassbench: denoised estimate of the raw render poster.raw.png")
    a, b = read_image(str(poster)), read_image(str(raw))
    assert a.shape == b.shape and a.shape[0] == POSTER and not np.array_equal(a, b)
    page = (out / "index.html").read_text()
    assert ("denoised estimate (Intel Open Image Denoise); the raw render: "
            '<a href="poster.raw.png">poster.raw.png</a>') in page
    # without --denoise: one poster, the raw render, and no such caption
    plain = write_share(*load("labelled.glassbench"), tmp_path / "plain", poster_height=POSTER)
    assert not (plain / "poster.raw.png").exists()
    assert image_description(plain / "poster.png").startswith("glassbench: raw render")
    assert "poster.raw.png" not in (plain / "index.html").read_text()
