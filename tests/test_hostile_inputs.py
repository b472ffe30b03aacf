"""Files a user or an attacker may hand glassbench: each gets one clear line and loses nothing.

Old projects with absurd numbers, images that are devices or grow while read, a job file that
asks for more frames than a job may render; and the bundled samples, saved in today's format
with their old-format originals kept here as the migrations' own cases.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from engine.errors import InputFileError, ProjectError
from engine.files.project import load_project
from engine.files.serialize import CURRENT_FORMAT
from engine.io.read import read_bounded

ROOT = Path(__file__).resolve().parents[1]
OLD = ROOT / "tests" / "data" / "old_formats"


def _glassbench(*args, cwd=None):
    """Run the ``glassbench`` command line in a fresh process (what a user types)."""
    return subprocess.run([sys.executable, "-m", "app.main", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=240)


def _format_of(path) -> int:
    with zipfile.ZipFile(path) as z:
        return json.loads(z.read("project.json"))["format_version"]


def test_every_bundled_sample_is_saved_in_the_current_format():
    samples = sorted((ROOT / "resources").glob("*.glassbench"))
    assert len(samples) >= 8
    assert {p.name: _format_of(p) for p in samples} == {p.name: CURRENT_FORMAT for p in samples}


@pytest.mark.parametrize("old, sample", [("bordeaux_format1", "bordeaux"), ("labelled_format2", "labelled"),
                                         ("threaded_bottle_format2", "threaded_bottle"),
                                         ("cut_decanter_format3", "cut_decanter")])
def test_old_format_originals_migrate_to_the_bundled_samples(old, sample):
    assert _format_of(OLD / f"{old}.glassbench") < CURRENT_FORMAT
    assert load_project(OLD / f"{old}.glassbench") == load_project(ROOT / "resources" / f"{sample}.glassbench")


def _with_huge_mouth_height(src: Path, dst: Path) -> Path:
    """A copy of project ``src`` whose last segment ends at a height of 10^400 mm, written as the
    401-digit integer JSON allows (Python reads it as an int that no float can hold)."""
    with zipfile.ZipFile(src) as z:
        members = {n: z.read(n) for n in z.namelist()}
    doc = json.loads(members["project.json"])
    section = next(iter(doc["design"]["shape"]["sections"].values()))["segments"]
    section[-1]["p1"][1] = "HUGE"
    members["project.json"] = json.dumps(doc).replace('"HUGE"', "1" + "0" * 400).encode()
    with zipfile.ZipFile(dst, "w") as z:
        for n, data in members.items():
            z.writestr(n, data)
    return dst


def test_a_format_1_project_with_a_coordinate_of_10_to_the_400_is_one_clear_error(tmp_path):
    src = OLD / "bordeaux_format1.glassbench"
    assert _format_of(src) == 1
    bad = _with_huge_mouth_height(src, tmp_path / "huge.glassbench")
    with pytest.raises(ProjectError, match="absurdly large"):
        load_project(bad)
    run = _glassbench("info", bad)
    assert run.returncode == 2 and "Traceback" not in run.stderr and "internal error" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and "absurdly large" in run.stderr


def test_a_relief_image_linked_to_dev_zero_is_refused_at_once_and_the_project_kept(tmp_path):
    project = tmp_path / "b.glassbench"
    project.write_bytes((ROOT / "resources" / "bordeaux.glassbench").read_bytes())
    before = project.read_bytes()
    (tmp_path / "zero.png").symlink_to("/dev/zero")
    run = _glassbench("bump", project, "add", f"image:{tmp_path / 'zero.png'}", "--z0", "100", "--z1", "150")
    assert run.returncode == 2, run.stdout + run.stderr
    assert "not a regular file" in run.stderr and "MemoryError" not in run.stderr
    assert project.read_bytes() == before


def test_the_bounded_reader_refuses_devices_pipes_and_oversized_files(tmp_path):
    with pytest.raises(InputFileError, match="not a regular file"):
        read_bounded("/dev/zero", 1 << 20, "image")
    os.mkfifo(tmp_path / "pipe")
    with pytest.raises(InputFileError, match="not a regular file"):  # refused before open blocks
        read_bounded(tmp_path / "pipe", 1 << 20, "image")
    (tmp_path / "big").write_bytes(b"x" * 1001)
    with pytest.raises(InputFileError, match="larger than 1000"):
        read_bounded(tmp_path / "big", 1000, "image")
    assert read_bounded(tmp_path / "big", 1001, "image") == b"x" * 1001


def test_a_job_of_200000_variants_is_refused_by_its_stated_limit(tmp_path):
    from engine.batch.jobfile import MAX_VARIANTS
    (tmp_path / "b.glassbench").write_bytes((ROOT / "resources" / "bordeaux.glassbench").read_bytes())
    variants = ", ".join("{}" for _ in range(200_000))
    (tmp_path / "job.toml").write_text(f'output = "out"\n[[projects]]\nfile = "b.glassbench"\n'
                                       f"variants = [{variants}]\n")
    run = _glassbench("batch", tmp_path / "job.toml", "--check", cwd=tmp_path)
    assert run.returncode == 2
    assert f"more than {MAX_VARIANTS} variants" in run.stderr, run.stderr
