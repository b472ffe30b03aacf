"""The label on the glass: a square stays square on a cylinder, rows become concentric arcs on a
cone, the artwork reads left to right with increasing azimuth and top up, the decal's grid
interpolates the exact map to a quarter texel, and the packed lookup the kernels will run
agrees with the reference."""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine.appearance.decal import TOLERANCE, back_coordinates, label_decal
from engine.appearance.dieline import flat_shape
from engine.appearance.frame import Placement, label_frame
from engine.appearance.surface import surface_coordinates
from engine.files.project import load_project
from engine.model.design import Label
from engine.tracer.kernels.labels import decal_lookup
from engine.tracer.tables.labels import pack_decals
from tests.label_helpers import SQUARE, cone_shape, cylinder_shape, prism_shape


def test_a_square_of_artwork_stays_a_square_on_a_cylinder():
    # 120 x 80 mm label of 1200 x 800 texels: square texels; a 100-texel square of artwork.
    shape, label = cylinder_shape(r=40.0), Label(z_mm=100.0, height_mm=80.0, width_mm=120.0)
    frame = label_frame(shape, Placement.of(label))
    s0, t0, side_s, side_t = 0.3, 0.4, 100 / 1200, 100 / 800
    corners = frame.points(np.array([s0, s0 + side_s, s0, s0 + side_s]), np.array([t0, t0, t0 + side_t, t0 + side_t]))
    theta = np.arctan2(corners[:, 1], corners[:, 0])
    across = 40.0 * abs(theta[1] - theta[0])  # arc length around the cylinder (mm)
    down = abs(corners[0, 2] - corners[2, 2])
    assert across == pytest.approx(10.0, abs=1e-9) and down == pytest.approx(10.0, abs=1e-9)
    assert corners[0, 2] == pytest.approx(corners[1, 2]) and theta[0] == pytest.approx(theta[2])
    flat = flat_shape(shape, Placement.of(label))
    assert flat.kind == "rectangle" and flat.strain.max() == 0.0
    a, b, c = flat.at([s0, s0 + side_s, s0], [t0, t0, t0 + side_t])
    assert np.linalg.norm(b - a) == pytest.approx(10.0) and np.linalg.norm(c - a) == pytest.approx(10.0)
    assert abs(np.dot(b - a, c - a)) < 1e-9


def test_the_artwork_reads_left_to_right_with_increasing_azimuth_and_top_up():
    shape = cylinder_shape()
    decal = label_decal(shape, Label(z_mm=100.0, angle_deg=30.0, height_mm=50.0, width_mm=60.0))
    theta = math.radians(30.0) + np.array([-0.1, 0.0, 0.1])
    s, t = decal.lookup(theta, np.full(3, 100.0 - 0.0 + 40.0))  # h = z + base radius (40)
    assert s[0] < 0.5 < s[2] and s[1] == pytest.approx(0.5) and np.all(t == pytest.approx(0.5))
    s, t = decal.lookup(np.full(2, math.radians(30.0)), np.array([140.0 + 20.0, 140.0 - 20.0]))
    assert t[0] < 0.5 < t[1]  # higher on the wall is nearer the artwork's top
    assert decal.lookup(np.array([math.radians(30.0) + math.pi]), np.array([140.0]))[0][0] != decal.lookup(
        np.array([math.radians(30.0)]), np.array([140.0]))[0][0]
    # Seen from inside, the back reads the other way, so a viewer there sees it the right way round.
    assert back_coordinates(0.2, 0.3) == (pytest.approx(0.8), pytest.approx(0.3))


def test_rows_of_artwork_are_concentric_arcs_on_a_cone():
    shape = cone_shape()  # r 40 at z 60 to r 20 at z 160: slant sqrt(100^2 + 20^2)
    label = Label(z_mm=110.0, height_mm=60.0, width_mm=120.0)
    p = Placement.of(label)
    flat = flat_shape(shape, p)
    fig = flat.figures
    slope = 20.0 / math.hypot(20.0, 100.0)
    r_top, r_bottom = 30.0 - 30.0 * slope, 30.0 + 30.0 * slope
    c1, c2 = 2 * math.pi * r_top, 2 * math.pi * r_bottom
    r1 = c1 * 60.0 / (c2 - c1)  # R1 = C1 L / (C2 - C1)
    assert fig["kind"] == "sector" and fig["narrow_end"] == "top"
    assert fig["r_inner_mm"] == pytest.approx(r1, rel=1e-12)
    assert fig["r_outer_mm"] == pytest.approx(r1 + 60.0, rel=1e-12)
    # The label's share of the whole unrolled cone's angle C1 / R1 is its share of the girth.
    assert math.radians(fig["angle_deg"]) == pytest.approx(c1 / r1 * 120.0 / (2 * math.pi * 30.0), rel=1e-12)
    apex = np.array([0.0, r1 + 30.0])  # above the centre: the cone narrows upwards
    nt = flat.flat.shape[0]
    for i, row in enumerate(flat.flat):  # each row of the flat grid: one row of artwork
        radius = np.linalg.norm(row - apex, axis=1)
        assert np.ptp(radius) < 1e-9 and radius[0] == pytest.approx(r1 + 60.0 * i / (nt - 1))
    assert flat.strain.max() == 0.0
    # The mapping on the glass is the same patch: rows on parallels, s linear in azimuth.
    decal = label_decal(shape, label)
    assert decal.kind == "sector" and decal.max_error == 0.0


def test_a_prism_rolls_its_label_without_stretch_around_its_girth():
    shape = prism_shape()
    label = Label(z_mm=75.0, angle_deg=0.0, height_mm=100.0, width_mm=150.0)
    p = Placement.of(label)
    assert flat_shape(shape, p).figures == {"kind": "rectangle", "width_mm": 150.0, "height_mm": 100.0}
    frame = label_frame(shape, p)
    s = np.linspace(0.0, 1.0, 4001)
    pts = frame.points(s, np.full(s.shape, 0.5))
    assert np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)) == pytest.approx(150.0, rel=1e-6)
    assert np.ptp(pts[:, 2]) < 1e-9  # one row of artwork is one horizontal girth line


def exact_error(shape, label, n=40000):
    """Largest |decal - exact| of (s, t) at random points of the label."""
    frame = label_frame(shape, Placement.of(label))
    decal = label_decal(shape, label)
    rng = np.random.default_rng(7)
    s, t = rng.uniform(0.001, 0.999, n), rng.uniform(0.001, 0.999, n)
    theta, h = frame.surface(s, t)
    ds, dt = decal.lookup(theta + 2 * math.pi * rng.integers(-2, 3, n), h)  # any turn of theta
    assert not np.isnan(ds).any()
    return max(np.abs(ds - s).max(), np.abs(dt - t).max()), decal


@pytest.mark.parametrize("label", [
    Label(z_mm=80.0, angle_deg=-90.0, height_mm=80.0, width_mm=90.0),       # across two corners
    Label(z_mm=100.0, angle_deg=170.0, height_mm=60.0, width_mm=220.0),     # almost all round, across 180 deg
    Label(z_mm=145.0, angle_deg=-90.0, height_mm=40.0, width_mm=60.0),      # over the shoulder
])
def test_the_decal_interpolates_to_a_quarter_texel_of_a_2048_texel_label(label):
    design, _ = load_project(SQUARE)
    err, decal = exact_error(design.shape, label)
    assert err < 0.25 / 2048 and decal.max_error <= max(TOLERANCE, err)
    assert max(decal.shape) <= 256


def test_round_decals_are_exact_and_small():
    err, decal = exact_error(cylinder_shape(), Label(z_mm=100.0, angle_deg=179.0, height_mm=80.0, width_mm=200.0))
    assert err < 1e-6 and decal.shape == (17, 17)


def test_a_point_off_the_label_is_nan_even_inside_the_footprint():
    design, _ = load_project(SQUARE)
    label = Label(z_mm=145.0, angle_deg=-90.0, height_mm=40.0, width_mm=60.0)
    decal = label_decal(design.shape, label)
    s_nodes = decal.st[..., 0]
    assert (s_nodes < 0).any() and (s_nodes > 1).any()  # the footprint is wider than the label
    rows, nodes = pack_decals([decal])
    theta = np.linspace(decal.theta0, decal.theta1, 9)
    s, _ = decal.lookup(theta, np.full(9, decal.h0))
    assert np.isnan(s[0]) or np.isnan(s[-1])
    assert math.isnan(decal_lookup(rows, nodes, 0, decal.theta0 - 0.1, decal.h0)[0])


def test_the_compiled_lookup_of_the_packed_rows_matches_the_reference():
    design, _ = load_project(SQUARE)
    decals = [label_decal(cylinder_shape(), Label(z_mm=100.0, height_mm=50.0, width_mm=70.0)),
              label_decal(design.shape, Label(z_mm=80.0, angle_deg=30.0, height_mm=80.0, width_mm=90.0))]
    rows, nodes = pack_decals(decals)
    assert rows.dtype == np.float64 and nodes.dtype == np.float32 and nodes.shape[1] == 2
    rng = np.random.default_rng(3)
    for k, d in enumerate(decals):
        theta = rng.uniform(d.theta0 - 0.2, d.theta1 + 0.2, 500)
        h = rng.uniform(d.h0 - 5, d.h1 + 5, 500)
        ref_s, ref_t = d.lookup(theta, h)
        got = np.array([decal_lookup(rows, nodes, k, a, b) for a, b in zip(theta, h)])
        assert np.allclose(got[:, 0], ref_s, equal_nan=True, atol=1e-6)
        assert np.allclose(got[:, 1], ref_t, equal_nan=True, atol=1e-6)


def test_surface_coordinates_are_the_tracers_convention():
    shape = cylinder_shape(r=40.0)
    theta, h = surface_coordinates(shape, np.array([[0.0, 40.0, 50.0], [-40.0, 0.0, 0.0]]))
    assert theta == pytest.approx([math.pi / 2, math.pi]) and h == pytest.approx([90.0, 40.0])
    square = prism_shape()  # turned 20 deg: theta in the bottle's own frame, h = z
    theta, h = surface_coordinates(square, np.array([[10.0, 0.0, 33.0]]))
    assert theta == pytest.approx([math.radians(-20.0)]) and h == pytest.approx([33.0])


def test_a_label_centred_behind_the_bottle_wraps_across_180_degrees():
    decal = label_decal(cylinder_shape(), Label(z_mm=100.0, angle_deg=180.0, height_mm=40.0, width_mm=100.0))
    s, t = decal.lookup(np.array([math.pi - 0.01, -math.pi + 0.01]), np.full(2, 140.0))
    assert s == pytest.approx([0.5 - 0.01 * 40.0 / 100.0, 0.5 + 0.01 * 40.0 / 100.0])


def test_a_corner_gives_the_size_of_the_label_it_bounds():
    """``size_to`` inverts the footprint: the corner of a placed label gives back its size."""
    import math

    from engine.appearance.frame import Placement, label_frame

    shape = cylinder_shape(r=30.0, top=150.0)
    frame = label_frame(shape, Placement(70.0, 20.0, 40.0, 50.0))
    theta, h = frame.surface(1.0, 0.0)  # the top right corner
    z = float(frame.wall.at(h)[1])
    height, width = frame.size_to(z, math.degrees(theta))
    assert (height, width) == (pytest.approx(40.0, abs=1e-9), pytest.approx(50.0, abs=1e-9))
    assert frame.size_to(70.0, 20.0 - 360.0) == (pytest.approx(0.0, abs=1e-9), pytest.approx(0.0, abs=1e-9))


def test_a_corner_gives_the_size_on_a_non_round_wall_too():
    import math

    from engine.appearance.frame import Placement, label_frame

    shape = prism_shape()
    frame = label_frame(shape, Placement(70.0, 45.0, 60.0, 60.0))
    _, z_top_edge = frame.surface(0.5, 0.0)
    theta_side, _ = frame.surface(1.0, 0.5)
    angle = math.degrees(float(theta_side)) + shape.rotation_deg
    height, width = frame.size_to(float(z_top_edge), angle)
    assert (height, width) == (pytest.approx(60.0, rel=1e-3), pytest.approx(60.0, rel=1e-3))
