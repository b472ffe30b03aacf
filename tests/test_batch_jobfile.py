"""Batch job files: overrides applied, views planned, and every bad line named before rendering."""
from __future__ import annotations

import dataclasses
import json
import math
import os

import pytest

from engine.batch.jobfile import read_job, turntable_job
from engine.batch.source import JobError, read_source
from engine.batch.views import orbit_about_axis, turntable_views
from engine.files.project import load_project, save_project
from engine.model.design import Camera, Label

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BORDEAUX = os.path.join(REPO, "resources", "bordeaux.glassbench")


def png(width: int, height: int) -> bytes:
    """A red RGB PNG of ``width`` x ``height`` pixels, built by hand."""
    import struct
    import zlib

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    rows = b"".join(b"\x00" + b"\xff\x00\x00" * width for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


PNG_2PX = png(2, 2)

JOB = f"""\
# a review of two bottles
output = "out"
width = 24
height = 32
spp = 2
turntable = 4

[cameras.high]
eye = [0, -600, 500]
target = [0, 0, 150]

[[projects]]
file = "{BORDEAUX}"

  [[projects.variants]]
  name = "amber"
  glass_tint = [0.002, 0.006, 0.02]
  liquid_color = [0.01, 0.2, 0.3]
  fill_ml = 700

  [[projects.variants]]
  name = "flint-empty"
  glass_tint = [0, 0, 0]
  empty = true
  camera = {{ fov_y_deg = 24 }}
"""


def write(tmp_path, text, name="job.toml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def line_of(text, needle):
    """The last line that holds ``needle`` (1-based)."""
    return [i for i, line in enumerate(text.splitlines(), 1) if needle in line][-1]


def test_a_job_file_plans_variants_times_views_with_overrides_applied(tmp_path):
    job = read_job(write(tmp_path, JOB))
    base, _ = load_project(BORDEAUX)
    assert job.output == str(tmp_path / "out"), "the file's output is relative to the file"
    assert read_job(tmp_path / "job.toml", "elsewhere").output == os.path.abspath("elsewhere"), \
        "-o is relative to the current folder"
    assert [v.name for v in job.variants] == ["amber", "flint-empty"]
    assert [v.name for v in job.views] == ["frame_0000", "frame_0001", "frame_0002", "frame_0003", "high"]
    amber, flint = job.variants
    assert amber.design.glass.absorption == (0.002, 0.006, 0.02)
    assert amber.design.liquid.absorption == (0.01, 0.2, 0.3)
    assert (amber.design.liquid.fill_mode, amber.design.liquid.fill_value) == ("volume", 700.0)
    assert flint.design.liquid is None and flint.design.camera.fov_y_deg == 24
    assert amber.design.shape == base.shape and amber.design.camera == base.camera
    frames = job.frames()
    assert len(frames) == 10 and frames[0].relpath == "amber/frame_0000.png"
    assert all((f.design.render.width, f.design.render.height, f.design.render.spp) == (24, 32, 2)
               for f in frames)
    assert frames[0].design.camera == base.camera, "frame 0 is the project's own view"
    assert frames[4].design.camera.eye == (0.0, -600.0, 500.0)


def test_json_job_files_are_read_the_same_way(tmp_path):
    doc = {"output": "o", "turntable": 2,
           "projects": [{"file": BORDEAUX, "variants": [{"name": "a", "fill_height_mm": 200}]}]}
    job = read_job(write(tmp_path, json.dumps(doc, indent=1), "job.json"))
    assert job.variants[0].design.liquid.fill_value == 200.0
    assert [f.relpath for f in job.frames()] == ["a/frame_0000.png", "a/frame_0001.png"]


@pytest.mark.parametrize("old, new, words, at", [
    ("glass_tint = [0, 0, 0]", "glass_tnt = [0, 0, 0]", "did you mean 'glass_tint'", None),
    ("fill_ml = 700", "fill_ml = 7000", "brimful capacity", None),
    ("fill_ml = 700", "fill_ml = 700\n  fill_height_mm = 100", "cannot both be given", "fill_ml"),
    ("empty = true", "empty = true\n  liquid_color = [1, 1, 1]", "no liquid to colour", None),
    ("liquid_color = [0.01, 0.2, 0.3]", "liquid_color = [0.01, -0.2, 0.3]", "three numbers >= 0", None),
    ("camera = { fov_y_deg = 24 }", "camera = { fov_y_deg = 240 }", "(0, 180)", None),
    ("camera = { fov_y_deg = 24 }", "camera = { up = [0, 1, 0], eye = [0, -600, 150] }", "parallel", None),
    ("camera = { fov_y_deg = 24 }", "stag = { kind = \"table\" }", "did you mean 'stage'", None),
    ("name = \"amber\"", "name = \"../amber\"", "becomes a file name", None),
    ("name = \"flint-empty\"", "name = \"amber\"", "two variants are named", None),
    ("glass_tint = [0, 0, 0]", "labels = { front = \"art.png\" }", "has no label 'front'", None),
    ("target = [0, 0, 150]", "target = [0, -600, 500]", "same point", "[cameras.high]"),
    ("spp = 2", "spp = 0", "spp must be a whole number", None),
    ("turntable = 4", "turntable = 4\nformat = \"jpeg\"", "format must be one of", None),
    ("turntable = 4", "turntable = 4\nthreads = 3", "unknown setting 'threads'", None),
    ("turntable = 4", "turntable = 4\ndenoise = \"yes\"", "denoise must be true or false, got 'yes'", None),
])
def test_a_bad_line_is_named_before_anything_renders(tmp_path, old, new, words, at):
    assert old in JOB
    text = JOB.replace(old, new, 1)
    with pytest.raises(JobError) as err:
        read_job(write(tmp_path, text))
    message = str(err.value)
    assert words in message
    line = line_of(text, at or new.splitlines()[-1].strip())
    assert message.startswith(f"{tmp_path / 'job.toml'}:{line}:"), message
    assert not (tmp_path / "out").exists()


def test_syntax_errors_name_the_line_in_toml_and_json(tmp_path):
    with pytest.raises(JobError, match=r"job.toml:9: invalid TOML"):
        read_job(write(tmp_path, JOB.replace("eye = [0, -600, 500]", "eye = [0, -600 500]")))
    text = '{\n "output": "o",\n "projects": [\n  {"file": "x"},\n ]\n}\n'
    with pytest.raises(JobError, match=r"job.json:5: invalid JSON"):
        read_job(write(tmp_path, text, "job.json"))
    with pytest.raises(JobError, match=r"job.json:3: duplicate key 'output'"):
        read_job(write(tmp_path, '{\n "output": "o",\n "output": "p"}', "job.json"))


def test_json_lines_are_kept_for_nested_keys(tmp_path):
    text = ('{"output": "o",\n "projects": [\n  {"file": "a",\n'
            '   "variants": [{"name": "x"},\n    {"glass_tnt": 1}]}]}')
    tree = read_source(write(tmp_path, text, "job.json"))
    assert tree.line_of(("projects", 0, "variants", 1, "glass_tnt")) == 5
    assert tree.line_of(("projects", 0, "variants", 0, "name")) == 4
    assert tree.line_of(("projects", 0, "file")) == 3


def test_label_artwork_replaces_the_named_labels_asset(tmp_path):
    design, assets = load_project(BORDEAUX)
    project = tmp_path / "labelled.glassbench"
    save_project(project, dataclasses.replace(design, labels=(Label("front"), Label("back", angle_deg=90.0))), assets)
    (tmp_path / "front.png").write_bytes(PNG_2PX)
    (tmp_path / "dot.png").write_bytes(png(1, 1))
    (tmp_path / "notes.txt").write_text("not an image")
    text = (f'output = "o"\n[[projects]]\nfile = "{project}"\n[[projects.variants]]\n'
            'labels = { front = "front.png" }\n')
    var = read_job(write(tmp_path, text)).variants[0]
    front, back = var.design.labels
    assert var.assets[front.front.asset] == PNG_2PX and back.front.asset is None
    with pytest.raises(JobError, match=r"job.toml:5: labels: label 'front': .*notes.txt is not a PNG"):
        read_job(write(tmp_path, text.replace("front.png", "notes.txt")))
    with pytest.raises(JobError, match=r"job.toml:5: labels: label 'front': dot.png is 1 x 1 pixels"):
        read_job(write(tmp_path, text.replace("front.png", "dot.png")))


def test_turntable_frames_orbit_the_axis_and_keep_the_view():
    cam = Camera(eye=(30.0, -600.0, 250.0), target=(0.0, 0.0, 150.0), up=(0.0, 0.0, 1.0), fov_y_deg=28.0)
    views = turntable_views(8)
    assert [v.angle_deg for v in views] == [45.0 * k for k in range(8)]
    assert views[0].camera_for(cam) is cam
    quarter = orbit_about_axis(cam, 90.0)
    assert quarter.eye == pytest.approx((600.0, 30.0, 250.0))
    for v in views:
        c = v.camera_for(cam)
        assert math.hypot(*c.eye[:2]) == pytest.approx(math.hypot(*cam.eye[:2]))
        assert c.eye[2] == cam.eye[2] and c.target == pytest.approx(cam.target) and c.fov_y_deg == 28.0
        assert math.dist(c.eye, c.target) == pytest.approx(math.dist(cam.eye, cam.target))


def test_the_turntable_command_job_writes_flat_frame_names(tmp_path):
    job = turntable_job(BORDEAUX, 3, str(tmp_path / "t"), width=16, height=20, spp=1, format="exr")
    assert [f.relpath for f in job.frames()] == ["frame_0000.exr", "frame_0001.exr", "frame_0002.exr"]
    with pytest.raises(JobError, match="--frames must be in 1..3600"):
        turntable_job(BORDEAUX, 0, str(tmp_path / "t"))


def test_denoise_is_read_and_enters_the_frame_hash_only_when_true(tmp_path):
    import hashlib

    from engine.batch.manifest import RENDERER, asset_digests, frame_hash
    from engine.files.serialize import design_to_dict
    assert read_job(write(tmp_path, JOB)).denoise is False
    job = read_job(write(tmp_path, JOB.replace("turntable = 4", "turntable = 4\ndenoise = true")))
    assert job.denoise is True
    frame = job.frames()[1]
    digests = asset_digests(frame.variant.assets)
    off = frame_hash(frame.design, digests, "png", True, False)
    # off: the document hashed before denoise existed, exactly (existing manifests stay valid)
    doc = {"renderer": RENDERER, "format": "png", "alpha": True, "design": design_to_dict(frame.design),
           "assets": digests}
    old = hashlib.sha256(json.dumps(doc, sort_keys=True, separators=(",", ":")).encode()).hexdigest()
    assert off == old == frame_hash(frame.design, digests, "png", True)
    assert frame_hash(frame.design, digests, "png", True, True) != off, "toggling denoise renders again"
    turn = turntable_job(BORDEAUX, 2, str(tmp_path / "t"), width=36, height=48, spp=2, denoise=True)
    assert turn.denoise is True and turntable_job(BORDEAUX, 2, str(tmp_path / "t")).denoise is False


def test_a_stage_override_merges_into_the_designs_stage(tmp_path):
    from engine.color import hex_to_linear
    from engine.model.design import Stage
    text = JOB.replace('name = "amber"', 'name = "amber"\n'
                       '  stage = { kind = "glossy", colour = "#808080", gloss = 0.5, backdrop = false }')
    amber, flint = read_job(write(tmp_path, text)).variants
    assert amber.design.stage == Stage(kind="glossy", color=hex_to_linear("#808080"), gloss=0.5)
    assert flint.design.stage == load_project(BORDEAUX)[0].stage, "a variant without it keeps the project's"
    doc = {"output": "o", "projects": [{"file": BORDEAUX, "variants": [
        {"name": "mirror", "stage": {"kind": "mirror", "color": [0.2, 0.3, 0.4]}},
        {"name": "catcher", "stage": {"kind": "shadow-catcher"}}]}]}
    mirror, catcher = read_job(write(tmp_path, json.dumps(doc, indent=1), "job.json")).variants
    assert (mirror.design.stage.kind, mirror.design.stage.color) == ("mirror", (0.2, 0.3, 0.4))
    assert catcher.design.stage.kind == "shadow"
    swept = JOB.replace('name = "amber"', 'name = "amber"\n  stage = { kind = "table", backdrop = true }')
    amber = read_job(write(tmp_path, swept)).variants[0]
    assert amber.design.stage.draws_backdrop, "a variant may stand on a table with its sweep"


@pytest.mark.parametrize("stage, words", [
    ('"table"', "stage: must be a table of kind, colour, color, gloss, backdrop"),
    ("{}", "must be a table of"),
    ('{ kind = "tabel" }', "stage: kind must be one of none, shadow (shadow-catcher), table, glossy, mirror"),
    ("{ kind = 3 }", "kind must be one of"),
    ('{ kind = "table", colour = "#12345" }', "colour must be an sRGB colour"),
    ('{ kind = "table", colour = [1, 1, 1] }', "colour must be an sRGB colour"),
    ('{ kind = "table", color = [0.1, 2, 0.1] }', "color must be three numbers in 0..1"),
    ('{ kind = "table", color = "#ffffff" }', "color must be three numbers in 0..1"),
    ('{ kind = "table", colour = "#123456", color = [0, 0, 0] }', "not both"),
    ('{ kind = "glossy", gloss = 1.5 }', "gloss must be a number in 0..1"),
    ('{ kind = "glossy", gloss = true }', "gloss must be a number in 0..1"),
    ('{ kind = "table", backdrop = 1 }', "backdrop must be true or false"),
    ('{ kind = "table", glos = 1 }', "unknown stage field 'glos'; did you mean 'gloss'?"),
    ('{ kind = "table", gloss = 0.5 }', "gloss does nothing for the stage 'table'"),
    ('{ colour = "#ffffff" }', "colour does nothing for the stage 'none'"),
    ('{ kind = "none", backdrop = true }', "backdrop does nothing for the stage 'none'"),
    ('{ kind = "mirror", backdrop = true }', "backdrop does nothing for the stage 'mirror'"),
])
def test_a_bad_stage_override_names_its_line(tmp_path, stage, words):
    text = JOB.replace('name = "amber"', f'name = "amber"\n  stage = {stage}')
    with pytest.raises(JobError) as err:
        read_job(write(tmp_path, text))
    message = str(err.value)
    assert message.startswith(f"{tmp_path / 'job.toml'}:{line_of(text, 'stage = ')}: stage: "), message
    assert words in message
    assert not (tmp_path / "out").exists()
