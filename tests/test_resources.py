"""Resources (issue 11, class 6, and "decode once per asset"): what the loader accepts is
validated, tessellated and lit in bounded memory and in work linear in its size; an embedded
environment image is decoded once, however often a render restarts. Figures for the largest
inputs come from ``python -m benchmarks.hostile``; these tests assert counts and memory only."""
from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine import limits
from engine.geometry import offset, validate
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape
from engine.geometry.tessellate import tessellate_body
from engine.model.design import Environment
from engine.tracer.tables import environment as env_module
from engine.tracer.tables.environment import DECODED, environment_from_design

FUZZ = settings(max_examples=25, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


def polyline_shape(n: int, kind: str = "round") -> BottleShape:
    """A flat base and a gently waisted wall of ``n - 2`` lines (real corners), then the finish."""
    pts = [(30 + 5 * math.sin(k / (n - 2) * math.pi), 100.0 * k / (n - 2)) for k in range(n - 1)]
    segs = [Line((0, 0), (30, 0))] + [Line(a, b) for a, b in zip(pts, pts[1:])]
    segs.append(Line(pts[-1], (pts[-1][0], 120.0)))
    sec = Section(tuple(segs), (False,) * (len(segs) - 1))
    names = {"round": ("profile",), "rounded_square": ("u", "v")}[kind]
    return BottleShape(kind, tuple((name, sec) for name in names), 1.0, 3.0)


def test_validation_locates_heights_a_fixed_number_of_times(monkeypatch):
    # The inner-wall check located every inner segment on its own (quadratic in segments).
    calls = []
    real = offset.locate
    monkeypatch.setattr(validate, "locate", lambda *a: calls.append(1) or real(*a))
    for n in (16, 512):
        calls.clear()
        validate.validate_shape(polyline_shape(n))
        counted = len(calls)
        assert counted <= 4, f"{n} segments: {counted} locate calls"


@FUZZ
@given(n=st.integers(3, 600))
def test_evaluation_by_segment_is_grouped_once(n):
    idx = np.random.default_rng(n).integers(-1, n, size=(7, 13))
    seen = np.zeros(idx.size, dtype=int)
    for i, part in offset.by_segment(idx):
        assert np.all(idx.ravel()[part] == i)
        seen[part] += 1
    assert np.all(seen == 1)


@pytest.mark.parametrize("kind", ["round", "rounded_square"])
def test_the_largest_section_tessellates_in_bounded_memory(kind):
    # 1.8 MB per segment before: 4,000 segments needed 7 GB.
    shape = polyline_shape(limits.MAX_SEGMENTS if kind == "round" else 256, kind)
    tracemalloc.start()
    try:
        mesh = tessellate_body(shape, 0.05)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert mesh.is_watertight()
    assert peak < 150e6, f"{peak / 1e6:.0f} MB"


@pytest.mark.parametrize("tol", [0.0, 1e-4, 11.0, float("nan")])
def test_tessellation_tolerance_is_bounded(tol):
    with pytest.raises(ValueError, match="chordal tolerance"):
        tessellate_body(polyline_shape(4), tol)


# ----------------------------------------------------------------------- environment images
def exr_bytes(tmp_path, pixels) -> bytes:
    import OpenImageIO as oiio
    path = str(tmp_path / "e.exr")
    out = oiio.ImageOutput.create(path)
    h, w = pixels.shape[:2]
    assert out.open(path, oiio.ImageSpec(w, h, 3, oiio.FLOAT)) and out.write_image(pixels)
    out.close()
    return (tmp_path / "e.exr").read_bytes()


def test_an_embedded_image_is_decoded_once_per_content(tmp_path, monkeypatch):
    data = exr_bytes(tmp_path, np.random.default_rng(1).random((8, 16, 3), dtype=np.float32))
    env = Environment("file", "sky.exr", 1.0, 0.0)
    first = environment_from_design(env, {"sky.exr": data})
    before = DECODED.decodes

    def no_second_decode(*a):
        raise AssertionError("decoded again")
    monkeypatch.setattr(env_module, "_decode_bytes", no_second_decode)
    again = environment_from_design(env, {"sky.exr": data})  # a render restart
    reopened = environment_from_design(env, {"sky.exr": bytes(bytearray(data))})  # equal bytes, new object
    assert DECODED.decodes == before
    assert again.texels is first.texels and reopened.texels is first.texels
    assert not first.texels.flags.writeable  # shared between jobs: nobody may change it


def test_hostile_texels_in_a_file_are_cleaned_by_the_one_rule(tmp_path):
    px = np.array([[np.nan, -1.0, np.inf], [0.25, -np.inf, 2e30]] * 2, dtype=np.float32).reshape(2, 2, 3)
    emap = environment_from_design(Environment("file", "bad.exr", 1.0, 0.0),
                                   {"bad.exr": exr_bytes(tmp_path, px)})
    want = np.array([[0, 0, limits.MAX_TEXEL], [0.25, 0, limits.MAX_TEXEL]] * 2, np.float32).reshape(2, 2, 3)
    np.testing.assert_array_equal(emap.texels, want)


def test_an_image_too_large_is_refused_from_its_header(tmp_path, monkeypatch):
    data = exr_bytes(tmp_path, np.zeros((4, 8, 3), np.float32))
    monkeypatch.setattr(env_module, "MAX_ENV_TEXELS", 31)
    with pytest.raises(ValueError, match="has 8 x 4 texels"):
        env_module._decode_bytes("big.exr", data)
