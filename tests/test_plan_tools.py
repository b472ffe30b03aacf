"""Plan outline edits (engine.geometry.editing.plan_tools) and the quoted widths
(engine.geometry.plan_widths): moved joints land where asked in millimetres and refuse what is not
convex, symmetry moves the images, corners round and sharpen back, arcs keep their ends or their
tangents, and the widths meet the regular polygons' closed forms."""
import math
from pathlib import Path

import numpy as np
import pytest

from engine.errors import OutlineError
from engine.geometry import plan as pl
from engine.geometry.editing import plan_tools as pt
from engine.geometry.plan_widths import plan_widths, widest_core

SPECS = Path("/work/shared/oracle/specs")


def flacon_shape():
    path = SPECS / "outline_public_1.json"
    from benchmarks.oracle_spec import spec_to_design
    return spec_to_design(str(path))[0].shape


def mm_joints(plan, k):
    return np.array(pt.joints(plan)) * k


def turns_at(plan, index):
    return plan._joint_turns[index]


# --------------------------------------------------------------------------- moving joints
def test_a_moved_joint_lands_in_millimetres_and_the_others_stay():
    shape = flacon_shape()
    k = widest_core(shape).k
    before = mm_joints(shape.plan, k)
    target = (before[0] * 1.1) / k  # the corner pulled out by 10 %: the outline grows past 1
    new = pt.move_joint(shape.plan, 0, target)
    assert new.scale == pytest.approx(1.1)
    edited = pt.with_plan(shape, new, new.scale)
    k2 = widest_core(edited).k
    assert k2 == pytest.approx(k * 1.1)
    after = mm_joints(edited.plan, k2)
    assert after[0] == pytest.approx(before[0] * 1.1, abs=1e-9)
    assert after[1:] == pytest.approx(before[1:], abs=1e-9)
    assert edited.section("round") == shape.section("round")
    assert edited.plan.scale == 1.0


def test_a_drag_that_would_make_the_outline_concave_is_refused_with_the_reason():
    h = pl.hexagon()
    with pytest.raises(OutlineError, match="not convex"):
        pt.move_joint(h, 0, (0.3, 0.0))  # inside the line joining its neighbours (x = 0.5)
    assert pt.move_joint(h, 0, (0.6, 0.0)).segments[0].p0 != h.segments[0].p0  # still convex: taken


def test_n_fold_symmetry_moves_every_image():
    h = pl.hexagon()
    new = pt.move_joint(h, 0, (0.9, 0.05), n=6)
    pts = np.array(pt.joints(new))
    radii = np.hypot(pts[:, 0], pts[:, 1])
    assert radii == pytest.approx(np.full(6, 1.0))  # all six moved alike, then normalised
    angles = np.degrees(np.arctan2(pts[:, 1], pts[:, 0])) % 360
    assert np.diff(np.sort(angles)) == pytest.approx(np.full(5, 60.0))
    assert len(pt.joint_images(new, 2, 6)) == 6


def test_a_joint_on_the_mirror_line_stays_on_it():
    s = pl.shield()
    tip = next(i for i, p in enumerate(pt.joints(s)) if abs(p[0]) < 1e-12)
    new = pt.move_joint(s, tip, (0.1, s.segments[tip].p0[1] * 1.05), mirror=True)
    assert new.segments[tip].p0[0] == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(OutlineError, match="mirror line"):
        pt.move_joint(s, tip, (0.1, -0.5), mirror=True, exact=True)


def test_an_outline_without_the_symmetry_asked_for_is_refused():
    lopsided = pt.move_joint(pl.hexagon(), 0, (0.9, 0.1))
    with pytest.raises(OutlineError, match="no image"):
        pt.move_joint(lopsided, 0, (0.95, 0.1), n=6)


def test_pulling_a_smooth_joint_out_makes_a_convex_corner_and_pushing_it_in_is_refused():
    f = pl.flask(100, 36)
    p = np.array(f.segments[0].p0)
    out = pt.move_joint(f, 0, p * 1.02)
    assert len(out.corners) == 1 and out.corners[0].index == 0
    assert turns_at(out, 1) == 0.0 and turns_at(out, 3) == 0.0  # the arcs stay tangent at their other ends
    with pytest.raises(OutlineError):
        pt.move_joint(f, 0, p * 0.98)


def test_an_arc_whose_two_ends_move_keeps_its_sweep():
    f = pl.flask(100, 36)
    mirrored = pt.move_joint(f, 0, np.array(f.segments[0].p0) + (0.01, 0.0), mirror=True)
    assert mirrored.segments[3].sweep == pytest.approx(f.segments[3].sweep)


# --------------------------------------------------------------------------- corners and arcs
def test_rounding_every_corner_gives_the_rounded_regular_polygon():
    rounded = pt.round_corner(pl.hexagon(), 0, 0.2, n=6)
    assert len(rounded.segments) == 12 and not rounded.corners
    rho = 0.2 / rounded.scale
    ref = pl.regular_polygon(6, rho)
    assert rounded.area == pytest.approx(ref.area, rel=1e-12)
    assert rounded.perimeter == pytest.approx(ref.perimeter, rel=1e-12)
    assert [s.radius for s in rounded.segments if s.kind == "arc"] == pytest.approx([rho] * 6)


def test_one_corner_rounds_and_sharpens_back():
    h = pl.hexagon()
    assert pt.is_sharp_corner(h, 2)
    rounded = pt.round_corner(h, 2, 0.3)
    arc = next(i for i, s in enumerate(rounded.segments) if s.kind == "arc")
    assert arc == 2 and pt.is_fillet(rounded, arc) and len(rounded.corners) == 5
    assert rounded.scale == 1.0  # a corner not the farthest: the outline keeps its size
    back = pt.sharpen_corner(rounded, arc)
    assert np.array(pt.joints(back)) == pytest.approx(np.array(pt.joints(h)), abs=1e-12)


def test_a_corner_radius_too_large_for_its_sides_is_refused_with_the_largest():
    with pytest.raises(OutlineError, match="largest radius"):
        pt.round_corner(pl.hexagon(), 1, 2.0)
    with pytest.raises(OutlineError, match="sharp corner"):
        pt.round_corner(pl.flask(100, 36), 0, 0.1)


def test_a_rounded_corner_changes_radius_keeping_both_tangents():
    rounded = pt.round_corner(pl.square(), 1, 0.1)
    arc = 1
    bigger = pt.set_arc_radius(rounded, arc, 0.25)
    assert bigger.segments[arc].radius * bigger.scale == pytest.approx(0.25)
    assert pt.is_fillet(bigger, arc)
    # the two sides keep their lines: each side's normal and support value are unchanged
    for side in (0, 2):
        assert bigger.segments[side].normal == pytest.approx(rounded.segments[side].normal)


def test_a_free_arc_changes_radius_keeping_its_ends_and_its_centre_on_their_bisector():
    f = pl.flask(100, 36)
    side = f.segments[1]
    new = pt.set_arc_radius(f, 1, side.radius * 1.5)
    arc = new.segments[1]
    scale = new.scale
    assert np.array(arc.p0) * scale == pytest.approx(np.array(side.p0))
    assert np.array(arc.p1) * scale == pytest.approx(np.array(side.p1))
    assert arc.radius * scale == pytest.approx(side.radius * 1.5)
    with pytest.raises(OutlineError, match="at least"):
        pt.set_arc_radius(f, 1, 0.1)


def test_an_arc_centre_moves_along_the_bisector_and_a_typed_coordinate_is_exact():
    f = pl.flask(100, 36)
    side = f.segments[1]  # the top side arc: its ends are mirror images, its bisector the y axis
    moved = pt.move_arc_centre(f, 1, (0.3, side.center[1] - 0.5))
    assert moved.segments[1].center[0] == pytest.approx(0.0, abs=1e-12)
    placed = pt.place_arc_centre(f, 1, 1, side.center[1] - 0.5)
    assert placed.segments[1].center[1] * placed.scale == pytest.approx(side.center[1] - 0.5, abs=1e-12)
    with pytest.raises(OutlineError, match="bisector"):
        pt.place_arc_centre(f, 1, 0, 0.3)
    with pytest.raises(OutlineError, match="line"):
        pt.move_arc_centre(pl.hexagon(), 0, (0, 0))


def test_with_plan_refuses_a_bottle_without_a_plan(tiny_design):
    with pytest.raises(OutlineError, match="no plan outline"):
        pt.with_plan(tiny_design.shape, pl.hexagon())


# --------------------------------------------------------------------------- widths
@pytest.mark.parametrize("n", [3, 4, 5, 6, 8, 12])
def test_the_widths_of_regular_polygons_meet_their_closed_forms(n):
    k, c = 30.0, 2.5
    w = plan_widths(pl.regular_polygon(n), k, c)
    if n % 2 == 0:
        flats, corners = 2 * k * math.cos(math.pi / n), 2 * k
    else:  # a corner faces a side; the diameter is the longest diagonal
        flats, corners = k * (1 + math.cos(math.pi / n)), 2 * k * math.sin(math.pi * (n // 2) / n)
    assert w.flats == pytest.approx(flats + 2 * c, rel=1e-12)
    assert w.corners == pytest.approx(corners + 2 * c, rel=1e-12)


def test_the_widths_of_curved_outlines():
    f = pl.flask(100, 36)
    w = plan_widths(f, f.scale, 0.0)
    assert (w.flats, w.corners) == pytest.approx((36.0, 100.0), rel=1e-12)
    assert (w.flats_deg, w.corners_deg) == pytest.approx((90.0, 0.0), abs=1e-6)
    y = math.sqrt(0.75)  # a disc cut by the chord x = -1/2
    d = pl.PlanOutline.from_dicts([{"type": "arc", "center": [0, 0], "radius": 1, "p0": [-0.5, -y], "p1": [-0.5, y]},
                                   {"type": "line", "p0": [-0.5, y], "p1": [-0.5, -y]}])
    w = plan_widths(d, 1.0, 0.0)
    assert (w.flats, w.corners) == pytest.approx((1.5, 2.0), rel=1e-10)
    assert w.flats_deg == pytest.approx(0.0, abs=1e-4)  # (2 across many directions: the disc's)


def test_the_flacon_is_sixty_millimetres_across_the_flats_at_its_widest_core():
    shape = flacon_shape()
    wc = widest_core(shape)
    assert (wc.k, wc.c) == pytest.approx((30.599564267050162, 3.5))
    w = plan_widths(shape.plan, wc.k, wc.c)
    assert w.flats == pytest.approx(2 * wc.k * math.cos(math.pi / 6) + 2 * wc.c, rel=1e-12)
    assert w.flats == pytest.approx(60.0, abs=1e-9)
    assert w.corners == pytest.approx(2 * wc.k + 2 * wc.c, rel=1e-12)


def test_the_widest_core_of_a_bulging_core_lies_between_samples():
    from engine.geometry.section import Section
    shape = flacon_shape()
    core = shape.section("core")
    bulge = Section.from_dicts([core.segments[0].to_dict(),
                                {"type": "arc", "center": [20.0, 40.0], "radius": math.hypot(10.6, 40.0),
                                 "p0": list(core.segments[0].p1), "p1": [30.6, 80.0], "direction": "ccw"},
                                {"type": "line", "p0": [30.6, 80.0], "p1": [0.0, 90.0]},
                                {"type": "line", "p0": [0.0, 90.0], "p1": [0.0, 110.0]}])
    wc = widest_core(pt.with_plan(shape, shape.plan).with_section("core", bulge))
    assert wc.z == pytest.approx(40.0, abs=1e-3)  # r is flat at its top: z is the square root of k's accuracy
    assert wc.k == pytest.approx(20.0 + math.hypot(10.6, 40.0), abs=1e-9)


def test_every_preset_is_a_valid_outline_and_an_unknown_one_is_refused():
    counts = {name: len(pt.preset(name).segments) for name in pt.PRESETS}
    assert counts["triangle"] == 3 and counts["hexagon"] == 6 and counts["octagon"] == 8
    assert counts["flask"] == 4 and counts["shield"] == 5
    with pytest.raises(OutlineError, match="no preset"):
        pt.preset("heart")
