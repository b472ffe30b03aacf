"""``glassbench batch`` on its default LocalCluster: images, contact sheet, summary with each
variant's trade numbers, and nothing written outside the output folder."""
from __future__ import annotations

import csv
import json
import os

import numpy as np
import pytest

from engine import cli
from engine.files.images import image_description, read_image
from engine.batch.jobfile import read_job
from engine.batch.manifest import Manifest
from engine.batch.run import run_batch
from engine.batch.source import JobError

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESOURCES = os.path.join(REPO, "resources")

JOB = f"""\
output = "review"
width = 20
height = 28
spp = 1
format = "png"
alpha = true

[cameras.front]
eye = [0, -700, 160]
target = [0, 0, 150]

[[projects]]
file = "{RESOURCES}/bordeaux.glassbench"
  [[projects.variants]]
  name = "red-wine"
  [[projects.variants]]
  name = "half-full"
  fill_ml = 375

[[projects]]
file = "{RESOURCES}/jar.glassbench"
"""


def files_under(folder):
    return sorted(os.path.relpath(os.path.join(d, f), folder) for d, _, fs in os.walk(folder) for f in fs)


def test_a_batch_writes_images_contact_sheet_and_trade_numbers(tmp_path, capsys):
    job_file = tmp_path / "review.toml"
    job_file.write_text(JOB)
    before = files_under(tmp_path)
    assert cli.main(["batch", str(job_file), "--workers", "2", "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "rendered 3 frame(s), skipped 0" in printed
    out = tmp_path / "review"
    new = sorted(set(files_under(tmp_path)) - set(before))
    assert all(p.startswith("review" + os.sep) for p in new), "nothing outside the output folder"
    images = [f"{v}/front.png" for v in ("red-wine", "half-full", "jar")]
    assert sorted(os.path.relpath(p, "review") for p in new) == sorted(
        images + ["contact_sheet.png", "manifest.json", "summary.csv", "summary.json"])
    rgba = read_image(str(out / "red-wine/front.png"))
    assert rgba.shape == (28, 20, 4)
    assert rgba[0, 0, 3] == 0 and rgba[14, 10, 3] == 255, "alpha is the bottle's coverage"

    sheet = read_image(str(out / "contact_sheet.png"))
    assert 3 * 160 < sheet.shape[0] < 4 * 160 and sheet.shape[1] < 2 * 160, "3 variant rows of 1 view"

    with open(out / "summary.csv", newline="") as fh:
        rows = {r["variant"]: r for r in csv.DictReader(fh)}
    summary = json.loads((out / "summary.json").read_text())
    for name, project in (("red-wine", "bordeaux"), ("jar", "jar")):
        assert cli.main(["info", os.path.join(RESOURCES, f"{project}.glassbench"), "--json"]) == 0
        info = json.loads(capsys.readouterr().out)
        for key in ("brimful_ml", "fill_ml", "glass_mass_g", "height_mm"):
            assert float(rows[name][key]) == pytest.approx(info[key], abs=5e-4)
    assert float(rows["half-full"]["fill_ml"]) == pytest.approx(375.0, abs=1e-3)
    assert float(rows["half-full"]["fill_height_mm"]) < float(rows["red-wine"]["fill_height_mm"])
    half = next(v for v in summary["variants"] if v["variant"] == "half-full")
    assert half["overrides"] == {"fill_ml": 375} and [f["view"] for f in half["frames"]] == ["front"]
    assert all(f["sha256"] == Manifest(str(out)).frames[f["file"]]["sha256"] for f in half["frames"])

    # Same job again: every frame is skipped, no cluster is started, the outputs stay.
    assert cli.main(["batch", str(job_file), "--quiet"]) == 0
    assert "rendered 0 frame(s), skipped 3" in capsys.readouterr().out
    assert np.array_equal(read_image(str(out / "red-wine/front.png")), rgba)


def test_a_link_out_of_the_output_folder_is_refused_before_rendering(tmp_path):
    job_file = tmp_path / "review.toml"
    job_file.write_text(JOB)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "review").mkdir()
    os.symlink(elsewhere, tmp_path / "review" / "jar")
    with pytest.raises(JobError, match="not inside the output folder"):
        run_batch(read_job(job_file))
    assert os.listdir(elsewhere) == []
    assert not (tmp_path / "review" / "manifest.json").exists()


def test_bad_cluster_options_are_one_line_errors(tmp_path, capsys):
    job_file = tmp_path / "review.toml"
    job_file.write_text(JOB)
    assert cli.main(["batch", str(job_file), "--workers", "0"]) == 2
    assert "--workers must be in 1..1024" in capsys.readouterr().err
    assert cli.main(["batch", str(tmp_path / "missing.toml")]) == 2
    assert "missing.toml" in capsys.readouterr().err
    assert not (tmp_path / "review").exists()


DENOISED_JOB = f"""\
output = "review"
width = 36
height = 48
spp = 2
turntable = 2
alpha = true
denoise = true

[[projects]]
file = "{RESOURCES}/labelled.glassbench"
"""


def test_a_denoised_batch_writes_each_frame_denoised_and_its_raw_film_beside_it(tmp_path, capsys):
    job_file = tmp_path / "review.toml"
    job_file.write_text(DENOISED_JOB)
    assert cli.main(["batch", str(job_file), "--workers", "1", "--quiet"]) == 0
    assert "rendered 2 frame(s), skipped 0" in capsys.readouterr().out
    out = tmp_path / "review"
    assert files_under(out) == sorted(
        ["contact_sheet.png", "manifest.json", "summary.csv", "summary.json"]
        + [f"labelled/frame_000{k}{kind}.png" for k in (0, 1) for kind in ("", ".raw")])
    for k in (0, 1):
        frame, raw = out / f"labelled/frame_000{k}.png", out / f"labelled/frame_000{k}.raw.png"
        assert image_description(raw).startswith("glassbench: raw render")
        assert image_description(frame).startswith(f"glassbench: denoised estimate of the raw render frame_000{k}.raw.png")
        a, b = read_image(str(frame)), read_image(str(raw))
        assert a.shape == b.shape == (48, 36, 4)
        assert not np.array_equal(a[..., :3], b[..., :3]), "the denoised frame is not the raw one"
        assert np.array_equal(a[..., 3], b[..., 3]) and a[0, 0, 3] == 0 and a[24, 18, 3] == 255, \
            "one coverage, the bottle's, on both"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["denoised"] is True
    assert [f["raw_file"] for f in summary["variants"][0]["frames"]] == [
        "labelled/frame_0000.raw.png", "labelled/frame_0001.raw.png"]
    with open(out / "summary.csv", newline="") as fh:
        assert [r["denoised"] for r in csv.DictReader(fh)] == ["true"]
    entry = Manifest(str(out)).frames["labelled/frame_0000.png"]
    assert list(entry["beside"]) == ["labelled/frame_0000.raw.png"]

    # done frames are skipped; a raw film gone is made again with its frame
    os.remove(out / "labelled/frame_0001.raw.png")
    assert cli.main(["batch", str(job_file), "--workers", "1", "--quiet"]) == 0
    assert "rendered 1 frame(s), skipped 1" in capsys.readouterr().out
    assert (out / "labelled/frame_0001.raw.png").exists()
    # denoise off: every frame renders again, raw, at the frame's own name
    job_file.write_text(DENOISED_JOB.replace("denoise = true", "denoise = false"))
    assert cli.main(["batch", str(job_file), "--workers", "1", "--quiet"]) == 0
    assert "rendered 2 frame(s), skipped 0" in capsys.readouterr().out
    assert image_description(out / "labelled/frame_0000.png").startswith("glassbench: raw render")
    assert json.loads((out / "summary.json").read_text())["denoised"] is False


def test_turntable_denoise_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "turn"
    assert cli.main(["turntable", os.path.join(RESOURCES, "labelled.glassbench"), "--frames", "1", "-o", str(out),
                     "--width", "36", "--height", "48", "--spp", "2", "--denoise", "--workers", "1",
                     "--quiet"]) == 0
    assert "raw film of each beside it" in capsys.readouterr().out
    assert {"frame_0000.png", "frame_0000.raw.png"} <= {p.name for p in out.iterdir()}
    assert image_description(out / "frame_0000.png").startswith(
        "glassbench: denoised estimate of the raw render frame_0000.raw.png")
    assert image_description(out / "frame_0000.raw.png").startswith("glassbench: raw render")
    assert not np.array_equal(read_image(str(out / "frame_0000.png")), read_image(str(out / "frame_0000.raw.png")))
