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
