"""The section edits of engine.geometry.editing (pure functions, no Qt): chains stay connected, smooth joints
stay tangent under stretch drags, and the inverse edits restore the section."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from app.sample_design import bordeaux_section
from engine.geometry.segments import Arc, EllipseArc, Line
from engine.geometry import editing as edits

SECTION = bordeaux_section()


def _connected(section) -> bool:
    segs = section.segments
    return all(math.dist(a.p1, b.p0) < 1e-9 for a, b in zip(segs, segs[1:]))


def _tangent_at_smooth_joints(section) -> bool:
    for j, smooth in enumerate(section.smooth):
        if smooth:
            a = section.segments[j].tangent(1.0)
            b = section.segments[j + 1].tangent(0.0)
            if not np.allclose(a, b, atol=1e-9):
                return False
    return True


def _ends_on_curves(section) -> bool:
    for seg in section.segments:
        if isinstance(seg, Arc):
            if any(abs(math.dist(p, seg.center) - seg.radius) > 1e-6 for p in (seg.p0, seg.p1)):
                return False
        if isinstance(seg, EllipseArc):
            for p in (seg.p0, seg.p1):
                u = ((p[0] - seg.center[0]) / seg.radius_r) ** 2 + ((p[1] - seg.center[1]) / seg.radius_z) ** 2
                if abs(u - 1.0) > 1e-9:
                    return False
    return True


@settings(max_examples=150, deadline=None)
@given(joint=st.integers(0, len(SECTION.segments) - 1),
       dr=st.floats(-4.0, 4.0), dz=st.floats(-4.0, 4.0))
def test_stretch_drag_keeps_the_chain_connected_and_tangent(joint, dr, dz):
    try:
        new = edits.move_joint(SECTION, joint, (dr, dz), "stretch")
    except ValueError:
        return  # the requested geometry does not exist (e.g. an arc shrunk to nothing)
    assert _connected(new)
    assert _tangent_at_smooth_joints(new)
    assert _ends_on_curves(new)
    assert new.segments[0].p0 == (0.0, 0.0) and new.segments[0].p1[1] == 0.0


@settings(max_examples=80, deadline=None)
@given(joint=st.integers(1, len(SECTION.segments) - 2), dr=st.floats(-3.0, 3.0), dz=st.floats(-3.0, 3.0))
def test_local_drag_moves_only_the_joint(joint, dr, dz):
    try:
        new = edits.move_joint(SECTION, joint, (dr, dz), "local")
    except ValueError:
        return
    assert _connected(new)
    assert _ends_on_curves(new)
    moved = [i for i, (a, b) in enumerate(zip(SECTION.segments, new.segments)) if a != b]
    assert set(moved) <= {joint, joint + 1}
    assert new.segments[joint].p1 == pytest.approx((SECTION.segments[joint].p1[0] + dr,
                                                    SECTION.segments[joint].p1[1] + dz))


@pytest.mark.parametrize("index", range(len(SECTION.segments)))
def test_split_then_delete_restores_the_shape_of_the_chain(index):
    split = edits.split_segment(SECTION, index)
    assert len(split.segments) == len(SECTION.segments) + 1
    assert _connected(split) and _tangent_at_smooth_joints(split)
    assert split.segments[index].p0 == SECTION.segments[index].p0
    assert split.segments[index + 1].p1 == pytest.approx(SECTION.segments[index].p1)


def test_insert_line_then_delete_it_is_the_identity():
    inserted = edits.insert_line_after(SECTION, 2, 12.0)
    assert isinstance(inserted.segments[3], Line)
    assert inserted.z_top == pytest.approx(SECTION.z_top + 12.0)
    assert _connected(inserted) and _tangent_at_smooth_joints(inserted)
    back = edits.delete_segment(inserted, 3)
    for a, b in zip(back.segments, SECTION.segments):
        assert a.p0 == pytest.approx(b.p0) and a.p1 == pytest.approx(b.p1)
    assert back.smooth == SECTION.smooth


def test_arc_radius_and_ellipse_radii_keep_the_start_and_both_tangents():
    arc_index = next(i for i, s in enumerate(SECTION.segments) if isinstance(s, Arc) and i > 1)
    new = edits.set_arc_radius(SECTION, arc_index, SECTION.segments[arc_index].radius * 1.3)
    assert new.segments[arc_index].p0 == SECTION.segments[arc_index].p0
    assert _connected(new) and _tangent_at_smooth_joints(new)
    with pytest.raises(ValueError):
        edits.set_arc_radius(SECTION, arc_index, -1.0)


def test_convert_arc_to_ellipse_is_exact_and_back():
    ellipse = edits.convert_segment(SECTION, 1, "ellipse_arc")
    assert isinstance(ellipse.segments[1], EllipseArc)
    assert np.allclose(ellipse.segments[1].point(np.linspace(0, 1, 9)),
                       SECTION.segments[1].point(np.linspace(0, 1, 9)))
    arc = edits.convert_segment(ellipse, 1, "arc")
    assert arc.segments[1].radius == pytest.approx(SECTION.segments[1].radius)


def test_scaled_radially_keeps_heights_and_tangent_directions_of_vertical_lines():
    wide = edits.scaled_radially(SECTION, 1.25)
    for a, b in zip(wide.segments, SECTION.segments):
        assert a.p1[1] == pytest.approx(b.p1[1])
        assert a.p1[0] == pytest.approx(1.25 * b.p1[0])
    assert _connected(wide) and _ends_on_curves(wide)


# ------------------------------------------------------------- the finish stays, tangents hold
from engine.files.project import load_project  # noqa: E402
from engine.geometry.editing.joints import joint_name, place_joint  # noqa: E402
from engine.geometry.validate import validate_shape  # noqa: E402

BORDEAUX = load_project(__file__.rsplit("/tests/", 1)[0] + "/resources/bordeaux.glassbench")[0]
PROFILE = BORDEAUX.shape.primary


def _finish(section):
    neck = section.segments[-1]
    return neck.p1[0], neck.p1[1], neck.p0[0]


@settings(max_examples=120, deadline=None)
@given(joint=st.integers(0, len(PROFILE.segments) - 3), dr=st.floats(-4.0, 4.0),
       dz=st.floats(-4.0, 4.0), mode=st.sampled_from(["stretch", "exact"]))
def test_moving_a_joint_below_the_neck_keeps_the_finish_and_every_tangent(joint, dr, dz, mode):
    if joint == 0 and mode == "exact":
        dz = 0.0  # the base ends on z = 0 (a typed end z there is refused: see below)
    try:
        new = edits.move_joint(PROFILE, joint, (dr, dz), mode)
    except ValueError:
        return  # no such geometry: refused with a reason (see the tests below)
    assert _connected(new) and _tangent_at_smooth_joints(new) and _ends_on_curves(new)
    assert _finish(new) == pytest.approx(_finish(PROFILE), abs=1e-9)
    if mode == "exact":
        target = (PROFILE.segments[joint].p1[0] + dr, PROFILE.segments[joint].p1[1] + dz)
        assert new.segments[joint].p1 == pytest.approx(target, abs=1e-9)


def test_dragging_the_shoulder_keeps_neck_radius_and_height():
    new = edits.move_joint(PROFILE, 3, (2.0, 6.0))  # the shoulder: end of the convex arc
    assert new.segments[3].p1 == pytest.approx((PROFILE.segments[3].p1[0] + 2, PROFILE.segments[3].p1[1] + 6))
    assert new.z_top == pytest.approx(300.0) and new.r_top == pytest.approx(14.5)
    assert new.segments[5].p0[0] == pytest.approx(14.5), "the neck stays vertical at its radius"
    validate_shape(BORDEAUX.shape.with_section("profile", new))
    carried = edits.move_joint(PROFILE, 3, (2.0, 6.0), "carry")
    assert carried.z_top == pytest.approx(306.0), "carry moves the finish with the joint"


def test_the_mouth_and_the_neck_start_move_the_finish():
    taller = edits.move_joint(PROFILE, 5, (0.0, 12.0))
    assert taller.z_top == pytest.approx(312.0)
    neck_start = edits.move_joint(PROFILE, 4, (0.0, 5.0))
    assert neck_start.z_top == pytest.approx(300.0), "the neck gets shorter, the height stays"


def test_a_typed_end_r_on_the_straight_body_keeps_it_tangent():
    new = place_joint(PROFILE, 2, r=36.0)  # the body: tangent to the heel and to the shoulder
    assert new.segments[2].p0[0] == pytest.approx(36.0) and new.segments[2].p1[0] == pytest.approx(36.0)
    assert _tangent_at_smooth_joints(new) and _connected(new)
    assert _finish(new) == pytest.approx(_finish(PROFILE))
    validate_shape(BORDEAUX.shape.with_section("profile", new))


def test_a_typed_value_that_cannot_be_reached_says_why():
    with pytest.raises(ValueError, match="crosses the axis"):
        place_joint(PROFILE, 2, r=-5.0)
    with pytest.raises(ValueError, match="end z stays 0"):
        place_joint(PROFILE, 0, z=3.0)


def test_joints_are_named_by_the_segments_they_join():
    assert joint_name(2) == "the joint between segments 2 and 3"


def test_a_line_between_smooth_joints_becomes_an_arc_tangent_to_both_neighbours():
    new = edits.convert_segment(PROFILE, 2, "arc")
    assert isinstance(new.segments[2], Arc)
    assert _connected(new) and _tangent_at_smooth_joints(new) and _ends_on_curves(new)
    assert new.segments[1].center == PROFILE.segments[1].center, "the heel slides along its circle"
    assert new.segments[3].center == PROFILE.segments[3].center
    assert new.segments[2].p1[0] > 37.0 and max(new.segments[2].point(np.linspace(0, 1, 33))[:, 0]) > 37.5
    assert _finish(new) == _finish(PROFILE)
    validate_shape(BORDEAUX.shape.with_section("profile", new))
    ellipse = edits.convert_segment(PROFILE, 2, "ellipse_arc")
    assert isinstance(ellipse.segments[2], EllipseArc) and _tangent_at_smooth_joints(ellipse)


def test_the_finish_stays_a_line():
    with pytest.raises(ValueError, match="finish"):
        edits.convert_segment(PROFILE, 5, "arc")
