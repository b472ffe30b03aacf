"""Section and shape validation (engine.geometry.validate): each error names what and where."""
import math

import numpy as np
import pytest
from hypothesis import assume, event, given, settings, strategies as st

from engine.geometry import capacity
from engine.errors import GlassbenchError, SectionError, WallError
from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc, Line
from engine.geometry.shape import BottleShape
from engine.geometry.tessellate import tessellate_body
from engine.geometry.validate import validate_section, validate_shape
from tests.test_offset import (heel_through_ring_section, punt_section, spec_shape, stepped_section,
                               torus_foot_section)


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_oracle_bottles_are_valid(n):
    validate_shape(spec_shape(n))


def test_punt_is_valid():
    validate_shape(BottleShape("round", {"profile": punt_section()}, 3.0, 4.0))
    # a heel drawn as one arc through the standing ring (as DXF import delivers it)
    validate_shape(BottleShape("round", {"profile": heel_through_ring_section()}, 2.5, 3.0))


def _expect(section, index, match):
    with pytest.raises(SectionError, match=match) as info:
        validate_section(section)
    assert info.value.index == index


def test_gap_names_the_segment():
    s = Section((Line((0, 0), (20, 0)), Line((20, 0.5), (20, 50))), (False,))
    _expect(s, 1, "gap")


def test_broken_tangency_request():
    s = Section((Line((0, 0), (20, 0)), Line((20, 0), (25, 40)), Line((25, 40), (25, 80))), (False, True))
    _expect(s, 2, "the joint between segments 1 and 2 is set smooth")
    Section.__init__  # the same section with the corner allowed is valid
    validate_section(Section(s.segments, (False, False)))


def test_overhang_and_horizontal_wall():
    s = Section((Line((0, 0), (20, 0)), Line((20, 0), (30, 40)), Line((30, 40), (25, 30)),
                 Line((25, 30), (25, 80))), (False, False, False))
    _expect(s, 2, "rise")
    s = Section((Line((0, 0), (20, 0)), Line((20, 0), (20, 40)), Line((20, 40), (10, 40)),
                 Line((10, 40), (10, 80))), (False, False, False))
    _expect(s, 2, "rise")


def test_arc_through_horizontal_is_an_overhang():
    # a convex arc that passes over its top inside the wall
    arc = Arc((20, 40), 10, (30, 40), (20 - 10 * math.cos(0.3), 40 - 10 * math.sin(0.3) + 20), "ccw")
    arc = Arc((20, 40), 10, (30, 40), (20 + 10 * math.cos(2.0), 40 + 10 * math.sin(2.0)), "ccw")
    s = Section((Line((0, 0), (30, 0)), Line((30, 0), (30, 40)), arc,
                 Line(arc.p1, (arc.p1[0], 100))), (False, False, False))
    _expect(s, 2, "rise")


def test_axis_crossing():
    s = Section((Line((0, 0), (20, 0)), Line((20, 0), (-5, 40)), Line((-5, 40), (-5, 80))), (False, False))
    _expect(s, 1, "axis")


def test_a_crossing_of_the_axis_is_named_before_the_tangents_it_breaks():
    # A negative radius typed into a smooth chain also turns the tangent: the axis is the cause.
    s = Section((Line((0, 0), (20, 0)), Line((20, 0), (20, 40)), Line((20, 40), (-5, 60)),
                 Line((-5, 60), (-5, 90))), (False, True, True))
    with pytest.raises(SectionError, match="segment 2: the section crosses the axis"):
        validate_section(s)


def test_degenerate_and_off_circle_arcs():
    s = Section((Line((0, 0), (20, 0)), Line((20, 0), (20, 0)), Line((20, 0), (20, 80))), (False, False))
    _expect(s, 1, "degenerate")
    bad = Arc((20, 5), 5, (20, 0), (25.01, 5), "ccw")
    s = Section((Line((0, 0), (20, 0)), bad, Line((25.01, 5), (25.01, 80))), (False, True))
    _expect(s, 1, "off its circle")
    bad_e = EllipseArc((20, 5), 6, 5, (20, 0), (26.2, 5), "ccw")
    s = Section((Line((0, 0), (20, 0)), bad_e, Line((26.2, 5), (26.2, 80))), (False, True))
    _expect(s, 1, "off its ellipse")


def test_finish_must_be_vertical_line_and_start_on_axis():
    s = Section((Line((0, 0), (20, 0)), Line((20, 0), (15, 80))), (False,))
    _expect(s, 1, "vertical")
    s = Section((Line((2, 0), (20, 0)), Line((20, 0), (20, 80))), (False,))
    _expect(s, 0, "axis")


def test_punt_rules():
    # a punt must leave the axis horizontally
    s = Section((Line((0, 10), (20, 0)), Line((20, 0), (20, 80))), (False,))
    _expect(s, 0, "horizontally")
    # the base must reach z = 0 before the finish
    s = Section((Line((0, 0), (20, 5)), Line((20, 5), (20, 80))), (False,))
    with pytest.raises(SectionError, match="z = 0"):
        validate_section(s)
    # a wall that comes back over the punt
    dome = EllipseArc((0.0, 0.0), 20, 12, (0.0, 12), (20, 0.0), "cw")
    s = Section((dome, Line((20, 0), (30, 2)), Line((30, 2), (10, 6)), Line((10, 6), (10, 80))),
                (False, False, False))
    _expect(s, 2, "punt")


def test_wall_errors():
    sec = torus_foot_section(20.0, 5.0, 100.0)
    with pytest.raises(WallError, match="segment 1: a 5.5 mm wall does not fit inside the 5 mm radius"):
        validate_shape(BottleShape("round", {"profile": sec}, 5.5, 6.0))
    # The real cause first: a thicker base would not cure a wall too thick for the arc.
    with pytest.raises(WallError, match="segment 1: a 14 mm wall does not fit inside the 5 mm radius"):
        validate_shape(BottleShape("round", {"profile": sec}, 14.0, 6.0))
    thin_neck = stepped_section(30.0, 100.0, 3.0, 130.0, 170.0)
    with pytest.raises(WallError, match="segment [23].*reaches the axis"):
        validate_shape(BottleShape("round", {"profile": thin_neck}, 3.5, 6.0))
    with pytest.raises(WallError, match="segment 1: 4 mm of glass is too thick for this arc"):
        validate_shape(BottleShape("round", {"profile": heel_through_ring_section()}, 2.5, 4.0))
    with pytest.raises(SectionError, match="rotation"):
        validate_shape(BottleShape("round", {"profile": sec}, 3.0, 6.0, rotation_deg=float("nan")))
    with pytest.raises(WallError, match="at least as thick"):
        validate_shape(BottleShape("round", {"profile": sec}, 3.0, 2.0))


def test_non_round_rules():
    sq = spec_shape(3)
    u, v = sq.section("u"), sq.section("v")
    # v < u breaks the rounded square at every height of the body
    with pytest.raises(SectionError, match="u <= v"):
        validate_shape(BottleShape("rounded_square", {"u": v, "v": u}, 2.5, 5.5))
    # a finish that is not round
    wide = stepped_section(30.0, 100.0, 14.0, 130.0, 160.0)
    narrow = stepped_section(25.0, 100.0, 12.0, 130.0, 160.0)
    with pytest.raises(SectionError, match="round finish"):
        validate_shape(BottleShape("oval", {"half_width": wide, "half_depth": narrow}, 2.0, 5.0))
    # different heights
    tall = stepped_section(25.0, 100.0, 14.0, 130.0, 170.0)
    with pytest.raises(SectionError, match="mouth"):
        validate_shape(BottleShape("oval", {"half_width": wide, "half_depth": tall}, 2.0, 5.0))
    # a punt on a square bottle
    with pytest.raises(SectionError, match="punt"):
        validate_shape(BottleShape("oval", {"half_width": punt_section(), "half_depth": punt_section()}, 2.0, 5.0))


def test_inner_cross_section_checked():
    # rounded rectangle whose corner equals the depth outside but exceeds it inside? c_in = c - w
    # and depth_in = depth - w keep c <= depth; a corner larger than half the width breaks it.
    hw = stepped_section(30.0, 100.0, 12.0, 130.0, 160.0)
    hd = stepped_section(20.0, 100.0, 12.0, 130.0, 160.0)
    corner = stepped_section(21.0, 100.0, 12.0, 130.0, 160.0)
    with pytest.raises(SectionError, match="corner"):
        validate_shape(BottleShape("rounded_rect", {"half_width": hw, "half_depth": hd, "corner": corner}, 2.0, 5.0))


@settings(max_examples=60, deadline=None)
@given(steps=st.lists(st.tuples(st.floats(2.0, 60.0), st.floats(-3.0, 40.0)), min_size=1, max_size=5),
       z0=st.one_of(st.just(0.0), st.floats(0.0, 15.0)), r_base=st.floats(3.0, 40.0),
       wall=st.floats(0.5, 6.0), base=st.floats(0.5, 10.0),
       bulge=st.one_of(st.just(0.0), st.floats(0.05, 0.9), st.floats(-0.9, -0.05)))
def test_any_section_is_either_rejected_cleanly_or_builds(steps, z0, r_base, wall, base, bulge):
    """Random bottle-like polylines (one segment made an arc): validation answers with a
    SectionError / WallError, or the shape builds into a closed mesh with a positive capacity;
    nothing else escapes."""
    pts = [(0.0, z0), (r_base, 0.0)]
    for r, dz in steps:
        pts.append((r, pts[-1][1] + dz))
    segs = [Line(a, b) for a, b in zip(pts[:-1], pts[1:]) if math.dist(a, b) > 1e-3]
    assume(segs and all(math.dist(a.p1, b.p0) == 0 for a, b in zip(segs[:-1], segs[1:])))
    if len(segs) >= 2 and bulge:
        # replace the second segment by an arc through its ends bulging by ``bulge`` of its length
        (r0, z0_), (r1, z1) = segs[1].p0, segs[1].p1
        mid, half = ((r0 + r1) / 2, (z0_ + z1) / 2), math.dist(segs[1].p0, segs[1].p1) / 2
        nr, nz = (z1 - z0_) / (2 * half), -(r1 - r0) / (2 * half)
        h = bulge * half
        radius = (half * half + h * h) / (2 * abs(h))
        c = (mid[0] - math.copysign(radius - abs(h), h) * nr, mid[1] - math.copysign(radius - abs(h), h) * nz)
        segs[1] = Arc(c, radius, segs[1].p0, segs[1].p1, "ccw" if h > 0 else "cw")
    segs.append(Line(segs[-1].p1, (segs[-1].p1[0], segs[-1].p1[1] + 20.0)))
    sec = Section(tuple(segs), tuple(False for _ in segs[1:]))
    shape = BottleShape("round", {"profile": sec}, wall, base)
    try:
        validate_shape(shape)
    except (SectionError, WallError) as exc:
        event(f"rejected: {type(exc).__name__}")
        assert str(exc)
        return
    except GlassbenchError as exc:  # pragma: no cover - a failure: the wrong error kind
        raise AssertionError(f"unexpected {type(exc).__name__}: {exc}")
    event("valid")
    assert capacity.brimful_ml(shape) > 0
    mesh = tessellate_body(shape, 0.2)
    assert mesh.is_watertight()
    v = mesh.vertices[mesh.faces]
    area = 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1).sum()
    # the shell within 0.2 mm of the true surfaces encloses the exact glass volume to ~ tol x area
    assert abs(mesh.signed_volume() - capacity.glass_volume_cm3(shape) * 1000) <= 0.2 * area * 0.5
