"""Bad input that used to get through a door (issue 44, item 7), tried as a hostile user would:
damaged images saved into a project, C libraries' own words on stderr, a job file too large to
check in time, a project naming a key twice, a DXF whose outline crosses itself in a fine
zigzag. Each is refused with one line and nothing is written."""
from __future__ import annotations

import io
import json
import math
import struct
import subprocess
import sys
import zipfile
import zlib
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from PIL import Image

from engine.appearance.images import ArtworkError
from engine.errors import ProjectError
from engine.files.project import load_project
from engine.operations import labels as label_ops

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "resources" / "bordeaux.glassbench"


def _glassbench(*args, cwd=None):
    """The command line in a fresh process (stderr as the user's terminal gets it)."""
    return subprocess.run([sys.executable, "-m", "app.main", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd or ROOT, timeout=240)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _png(idat: bytes, w: int = 32, h: int = 32) -> bytes:
    """A PNG whose chunks are all well formed (lengths, checksums) around ``idat``."""
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", idat) + _chunk(b"IEND", b"")


def _tiff_strip_past_end() -> bytes:
    buf = io.BytesIO()
    Image.fromarray(np.full((16, 16, 3), 128, np.uint8)).save(buf, "TIFF")
    d = bytearray(buf.getvalue())
    ifd = struct.unpack_from("<I", d, 4)[0]
    for i in range(struct.unpack_from("<H", d, ifd)[0]):
        entry = ifd + 2 + 12 * i
        tag, _, count, value = struct.unpack_from("<HHII", d, entry)
        if tag == 273:  # StripOffsets
            for k in range(count):
                struct.pack_into("<I", d, entry + 8 if count == 1 else value + 4 * k, 10_000_000)
    return bytes(d)


def _tiff_nan(tmp: Path) -> bytes:
    import OpenImageIO as oiio
    px = np.ones((16, 16, 3), np.float32)
    px[3, 3, 0] = np.nan
    path = str(tmp / "nan.tif")
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(16, 16, 3, oiio.FLOAT))
    out.write_image(px)
    out.close()
    return Path(path).read_bytes()


def _jpeg_truncated() -> bytes:
    buf = io.BytesIO()
    rng = np.random.default_rng(1)
    Image.fromarray((rng.random((64, 64, 3)) * 255).astype(np.uint8)).save(buf, "JPEG")
    return buf.getvalue()[: len(buf.getvalue()) // 2]


DAMAGED = {
    "garbage_idat.png": lambda tmp: _png(b"\x78\x9c" + bytes(range(256)) * 4),
    "bad_filter.png": lambda tmp: _png(zlib.compress(b"".join(b"\x07" + bytes(96) for _ in range(32)))),
    "truncated.jpg": lambda tmp: _jpeg_truncated(),
    "nan.tif": _tiff_nan,
    "strip_past_end.tif": lambda tmp: _tiff_strip_past_end(),
}


@pytest.fixture(params=sorted(DAMAGED))
def damaged(request, tmp_path) -> Path:
    path = tmp_path / request.param
    path.write_bytes(DAMAGED[request.param](tmp_path))
    return path


def _one_line_error(run, command: str) -> str:
    lines = run.stderr.strip().splitlines()
    assert run.returncode == 2, run.stdout + run.stderr
    assert len(lines) == 1 and lines[0].startswith(f"glassbench {command}: error:"), run.stderr
    return lines[0]


@pytest.mark.parametrize("side", ["front", "back"])
def test_a_damaged_image_never_becomes_a_label(damaged, side, tmp_path):
    project = tmp_path / "p.glassbench"
    project.write_bytes(SAMPLE.read_bytes())
    before = project.read_bytes()
    image = damaged if side == "front" else ROOT / "resources" / "logo.png"
    extra = ["--back", damaged] if side == "back" else []
    run = _glassbench("label", project, "add", image, "--z", 100, "--height", 50, "--width", 60, *extra)
    line = _one_line_error(run, "label")
    named = damaged.stem if side == "front" else "logo back"  # the label is named after its front
    assert line.startswith(f"glassbench label: error: {named} ")
    assert "cannot be decoded" in line or "NaN" in line
    assert project.read_bytes() == before


def test_a_damaged_image_is_refused_by_the_operation_every_front_end_calls(damaged):
    design, assets = load_project(SAMPLE)
    with pytest.raises(ArtworkError):
        label_ops.add_label(design, assets, damaged.read_bytes(), filename=damaged.name)


def test_a_damaged_relief_image_is_one_line_and_the_project_kept(damaged, tmp_path):
    project = tmp_path / "p.glassbench"
    project.write_bytes(SAMPLE.read_bytes())
    before = project.read_bytes()
    run = _glassbench("bump", project, "add", f"image:{damaged}", "--z0", 100, "--z1", 150)
    assert "relief image" in _one_line_error(run, "bump")
    assert project.read_bytes() == before


def test_a_project_naming_its_format_twice_is_refused(tmp_path):
    with zipfile.ZipFile(SAMPLE) as z:
        members = {n: z.read(n) for n in z.namelist()}
    text = members["project.json"].decode()
    assert text.lstrip().startswith("{")
    members["project.json"] = text.replace("{", '{"format_version": 1, ', 1).encode()
    bad = tmp_path / "twice.glassbench"
    with zipfile.ZipFile(bad, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    with pytest.raises(ProjectError, match="'format_version' twice"):
        load_project(bad)
    assert "twice" in _one_line_error(_glassbench("info", bad), "info")


def test_a_json_job_of_200000_variants_is_refused_by_its_limit(tmp_path):
    from engine.batch.jobfile import MAX_VARIANTS
    (tmp_path / "b.glassbench").write_bytes(SAMPLE.read_bytes())
    job = {"output": "out", "projects": [{"file": "b.glassbench",
                                          "variants": [{"name": f"v{i}"} for i in range(200_000)]}]}
    text = json.dumps(job)
    assert len(text) > 3_000_000
    (tmp_path / "job.json").write_text(text)
    run = _glassbench("batch", tmp_path / "job.json", "--check", cwd=tmp_path)
    assert f"more than {MAX_VARIANTS} variants" in _one_line_error(run, "batch")


def test_a_dxf_whose_wall_zigzags_into_the_punt_is_refused(tmp_path):
    """A wall tooth 0.04 mm high reaching 23 mm into the punt, between the base's samples."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    centre, radius = (0.0, -26.666666666666664), 38.666666666666664  # the Bordeaux's punt
    msp.add_arc(centre, radius, math.degrees(math.atan2(-centre[1], 28.0)), 90.0)
    msp.add_lwpolyline([(28, 0), (28, 5.0), (5, 5.02), (28, 5.04), (28, 200), (14.5, 210), (14.5, 300)])
    dxf = tmp_path / "zigzag.dxf"
    doc.saveas(dxf)
    out = tmp_path / "zigzag.glassbench"
    run = _glassbench("new", "--from-dxf", dxf, out)
    assert "crosses the punt" in _one_line_error(run, "new")
    assert not out.exists()
