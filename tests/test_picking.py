"""What the camera sees at an image point, on the tracer's own exact search: the coverage a final
render's alpha takes (the closure included) and the wall point a label dropped on the preview
lands on."""
from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from engine.files.images import read_image
from engine.files.project import load_project
from engine.geometry.chain import radius_at
from engine.tracer.context import scene_tables
from engine.tracer.picking import camera_hits, coverage, wall_point

ROOT = Path(__file__).resolve().parents[1]
W, H = 120, 160


@pytest.fixture(scope="module")
def capped():
    return load_project(ROOT / "resources" / "threaded_bottle.glassbench")


def _first_objects(design):
    """The render object each pixel centre's ray meets first (-1: nothing), ``(H, W)``."""
    ys, xs = np.mgrid[0:H, 0:W] + 0.5
    _, k, _ = camera_hits(design, W, H, xs, ys)
    return k.reshape(H, W)


def test_alpha_covers_the_closure_above_the_glass(capped):
    design, _ = capped
    assert design.cap is not None
    first_cap = scene_tables(dataclasses.replace(design, cap=None))[2].geom.obj_i.shape[0]  # the bottle's objects
    seen = _first_objects(design)
    on_cap = seen >= first_cap
    bare = _first_objects(dataclasses.replace(design, cap=None))
    above_glass = on_cap & (bare < 0)  # the closure where no glass lies behind it
    assert above_glass.sum() >= 3
    alpha = coverage(design, W, H)
    assert alpha.shape == (H, W) and alpha.dtype == np.float32
    assert np.all(alpha[above_glass] > 0.0)
    assert np.all(alpha[seen < 0] < 1.0) and np.all(alpha[seen >= 0] > 0.0)
    assert np.all(coverage(dataclasses.replace(design, cap=None), W, H)[above_glass] < alpha[above_glass])


def test_glassbench_render_alpha_writes_the_coverage(capped, tmp_path):
    project = ROOT / "resources" / "threaded_bottle.glassbench"
    out = tmp_path / "shot.png"
    run = subprocess.run([sys.executable, "-m", "app.main", "render", str(project), "-o", str(out),
                          "--width", "24", "--height", "32", "--spp", "1", "--alpha"],
                         capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert run.returncode == 0, run.stderr
    rgba = read_image(str(out))
    assert rgba.shape == (32, 24, 4)
    expected = np.round(coverage(capped[0], 24, 32) * 255.0).astype(np.uint8)
    assert np.array_equal(rgba[..., 3], expected)


def test_a_point_dropped_on_the_wall_lies_on_the_wall():
    design, _ = load_project(ROOT / "resources" / "bordeaux.glassbench")
    z, angle = wall_point(design, 0.5, 0.55)
    wall = design.shape.primary.segments
    # the point is on the outer surface: its distance from the axis is the section's radius there
    _, k, p = camera_hits(design, design.render.width, design.render.height, [0.5 * design.render.width],
                          [0.55 * design.render.height])
    assert k[0] == 0 and p[0, 2] == pytest.approx(z)
    assert math.hypot(p[0, 0], p[0, 1]) == pytest.approx(float(radius_at(wall, np.array([z]))[0]), abs=1e-9)
    assert math.degrees(math.atan2(p[0, 1], p[0, 0])) == pytest.approx(angle)
    assert -180.0 <= angle <= 180.0 and abs(angle + 90.0) < 20.0  # the camera looks from -y
    assert wall_point(design, 0.02, 0.5) is None  # beside the bottle
