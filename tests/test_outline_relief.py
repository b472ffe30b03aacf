"""Relief on outline bottles: bump tiles follow the outline's arc length (issue 41).

The kernel's girth (:func:`engine.tracer.kernels.plans.plan_girth`) is checked against the
numpy one of :mod:`engine.geometry.plan_girth` (an independent route: the section's exact pieces
walked from polar angle 0) on outlines with sharp and rounded corners, a core that is a point,
and at scales 1/1000 and 1000; then the relief on the hexagonal flacon's wall: its shading
normals repeat every ``girth / n`` of arc length, on the flat panels as round the corners, which
a tile laid by the polar angle would not do.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from engine.appearance.bands import band_coordinates
from engine.cli import main as cli
from engine.files.project import load_project
from engine.geometry import plan as plans
from engine.geometry.chain import radius_at
from engine.geometry.plan_girth import girth_length, perimeter, theta_at_length
from engine.geometry.validate import body_profile
from engine.operations.tiles import new_tile
from engine.tracer.context import RenderContext, trace_pixels
from engine.tracer.kernels.plans import plan_girth
from engine.tracer.tables.plans import plan_table
from tests.test_finish_render import _wall_normals

ROOT = Path(__file__).resolve().parents[1]
FLACON = ROOT / "resources" / "flacon.glassbench"

OUTLINES = {
    "hexagon (sharp)": lambda: plans.hexagon(),
    "hexagon (rounded, turned)": lambda: plans.hexagon(0.1, rotation_deg=17.0),
    "triangle": lambda: plans.triangle(),
    "flask": lambda: plans.flask(1.0, 0.5),
    "shield": lambda: plans.shield(),
}


def _kernel_girth(plan, k, r, x, y):
    table = plan_table(plan.to_dicts())
    out = np.array([plan_girth(table, k, r, float(a), float(b)) for a, b in zip(x, y)])
    return out[:, 0], out[:, 1]


@pytest.mark.parametrize("name", list(OUTLINES))
@pytest.mark.parametrize("k, r", [(30.0, 0.0), (30.0, 2.5), (12.0, 9.0), (0.0, 7.0), (3e-2, 1e-3), (3e4, 5e2)])
def test_the_kernels_girth_is_the_exact_arc_length_along_the_section(name, k, r):
    plan = OUTLINES[name]()
    theta = np.linspace(-math.pi, math.pi, 1441)[:-1] + 1e-4
    x, y, _, _ = plan.section_boundary(theta, k, r)
    length, total = _kernel_girth(plan, k, r, x, y)
    exact_total = float(perimeter(plan, k, r))
    assert np.allclose(total, exact_total, rtol=1e-12)
    # the same arc length up to the origin (the kernel's: where the normal points along +x)
    shift = np.remainder(length - girth_length(plan, k, r, theta), exact_total)
    spread = np.abs(np.remainder(shift - shift[0] + 0.5 * exact_total, exact_total) - 0.5 * exact_total)
    assert spread.max() <= 1e-9 * exact_total
    assert np.all((length >= 0.0) & (length < exact_total))


@pytest.mark.parametrize("turn", [0.0, 30.0])
def test_the_girth_starts_where_the_normal_points_along_plus_x(turn):
    """A flat facing +x starts it at the foot of the perpendicular from the axis; a corner
    facing +x at the corner's point of normal +x (``k V + r (1, 0)``)."""
    plan = plans.hexagon(rotation_deg=turn)
    k, r = 25.0, 1.0
    x, y, nx, _ = plan.section_boundary(np.array([0.0, 1e-3, -1e-3]), k, r)
    length, total = _kernel_girth(plan, k, r, x, y)
    assert nx[0] == pytest.approx(1.0, abs=1e-12)
    assert min(length[0], total[0] - length[0]) == pytest.approx(0.0, abs=1e-9)   # 0 mod L
    if np.ptp(x) < 1e-9:                                                    # a flat faces +x
        assert length[1] == pytest.approx(y[1], rel=1e-9)                   # ccw along the flat
        assert total[2] - length[2] == pytest.approx(-y[2], rel=1e-9)       # cw: just below L
    else:
        assert 0.0 < length[1] < 0.1 and 0.0 < total[2] - length[2] < 0.1


@pytest.fixture(scope="module")
def knurled_flacon():
    design, assets = load_project(FLACON)
    z = design.labels[0].z_mm
    tile = new_tile(design, "flutes", z - 8.0, z + 8.0, angle_deg=0.0, repeat=24, depth=0.3)
    return dataclasses.replace(design, bumps=(tile,), labels=(), cap=None), assets, z


def _wall_at_lengths(design, assets, lengths, z):
    """Shading and geometric normals of the flacon's outer wall at girth ``lengths`` (mm, from
    polar angle 0) and height ``z``: rays shot horizontally at the axis from outside, through
    the points of those lengths (exact, :func:`theta_at_length`), and the girth there (mm)."""
    prof = body_profile(design.shape)
    k, r = (float(radius_at(sp.outer_wall, z)) for sp in prof.sections)
    theta = theta_at_length(design.shape.plan, k, r, lengths)
    s, n = _wall_normals(design, theta, z, assets)
    return s, n, float(perimeter(design.shape.plan, k, r))


def _tangent_bend(s, n):
    """The shading normal's tilt across the wall (component along the horizontal tangent)."""
    tu = np.stack([-n[:, 1], n[:, 0], np.zeros(len(n))], 1)
    tu /= np.linalg.norm(tu, axis=1)[:, None]
    return np.sum(s * tu, axis=1)


def test_relief_on_an_outline_repeats_every_girth_over_n_of_arc_length(knurled_flacon):
    design, assets, z = knurled_flacon
    tile = design.bumps[0]
    _, _, girth = _wall_at_lengths(design, assets, np.array([0.0]), z)
    period = girth / tile.repeat
    base = np.linspace(0.0, period, 61)[:-1]
    bends = []
    for j in range(tile.repeat):          # every period: on the six flats and round the corners
        s, n, _ = _wall_at_lengths(design, assets, base + j * period, z)
        bends.append(_tangent_bend(s, n))
    bends = np.array(bends)
    assert np.ptp(bends[0]) > 0.05                       # the flutes do tilt the normal
    assert np.max(np.abs(bends - bends[0])) < 1e-3 * np.ptp(bends[0])
    # the same lengths measured by the polar angle would not repeat: the tile is not laid by it
    assert band_coordinates(design, tile.z0, tile.z1)[2] == pytest.approx(girth / (2 * math.pi), rel=2e-2)


def test_knurled_flacon_renders_and_the_relief_shows(knurled_flacon):
    design, assets, _ = knurled_flacon
    plain = dataclasses.replace(design, bumps=())
    images = []
    for d in (plain, design):
        ctx = RenderContext.from_design(d, assets, 40, 56)
        ys, xs = np.mgrid[0:56, 0:40]
        res = trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, 2)
        images.append(res.sums.reshape(56, 40, 3) / 2)
    assert all(np.all(np.isfinite(im)) for im in images)
    assert np.mean(np.abs(images[1] - images[0])) > 1e-3     # the flutes change the picture


def test_the_cli_adds_knurling_to_the_flacon(tmp_path):
    out = tmp_path / "flacon.glassbench"
    out.write_bytes(FLACON.read_bytes())
    assert cli(["bump", str(out), "add", "knurl", "--z0", "20", "--z1", "40"]) == 0
    design, _ = load_project(out)
    assert [b.kind for b in design.bumps] == ["knurl"]
