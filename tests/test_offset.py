"""Inner sections, sub-segments, radius_at and the BodyProfile (engine.geometry.offset)."""
import json
import math

import numpy as np
import pytest

from engine.errors import WallError
from engine.geometry.offset import inner_section, param_at_z, radius_at, split_at_ring, subsegment
from engine.geometry.validate import body_profile
from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc, Line, OffsetEllipseArc
from engine.geometry.shape import BottleShape
from benchmarks.oracle import shape_from_spec
from benchmarks.paths import ORACLE_SPECS

SPECS = str(ORACLE_SPECS / "public_{}.json")


def spec_shape(n: int) -> BottleShape:
    """The bottle of oracle scene ``public_n`` as a BottleShape."""
    return shape_from_spec(json.load(open(SPECS.format(n)))["bottle"])


def cylinder_section(radius: float, height: float) -> Section:
    """Flat base and one vertical wall (which is also the finish)."""
    return Section((Line((0, 0), (radius, 0)), Line((radius, 0), (radius, height))), (False,))


def stepped_section(r_body, h_body, r_neck, h_shoulder, h_top) -> Section:
    """Flat base, vertical body, straight shoulder and vertical finish, with sharp joints."""
    return Section((Line((0, 0), (r_body, 0)), Line((r_body, 0), (r_body, h_body)),
                    Line((r_body, h_body), (r_neck, h_shoulder)), Line((r_neck, h_shoulder), (r_neck, h_top))),
                   (False, False, False))


def torus_foot_section(r_base, a, height) -> Section:
    """Flat base, a quarter-torus foot arc of radius ``a`` and a vertical wall to ``height``."""
    return Section((Line((0, 0), (r_base, 0)),
                    Arc((r_base, a), a, (r_base, 0), (r_base + a, a), "ccw"),
                    Line((r_base + a, a), (r_base + a, height))), (False, True))


def sphere_section(r_base, c, height) -> Section:
    """Flat base, a sphere arc about ``(0, c)`` from the base edge to the equator, vertical wall."""
    big_r = math.hypot(r_base, c)
    return Section((Line((0, 0), (r_base, 0)), Arc((0, c), big_r, (r_base, 0), (big_r, c), "ccw"),
                    Line((big_r, c), (big_r, height))), (False, True))


def punt_section(h_punt=12.0, r_punt=20.0, r_body=35.0, height=200.0, neck=13.0) -> Section:
    """A wine-bottle-like section with a punt: an elliptical dome from (0, h) down to a
    standing ring at (r_punt, 0), a foot arc, the body and a straight neck taper."""
    dome = EllipseArc((0.0, 0.0), r_punt, h_punt, (0.0, h_punt), (r_punt, 0.0), "cw")
    foot = Arc((r_punt, 5.0), 5.0, (r_punt, 0.0), (r_punt + 5.0, 5.0), "ccw")
    segs = (dome, foot, Line((r_punt + 5.0, 5.0), (r_body, 15.0)),
            Line((r_body, 15.0), (r_body, 120.0)), Line((r_body, 120.0), (neck, 160.0)),
            Line((neck, 160.0), (neck, height)))
    return Section(segs, (False, False, False, False, False))


def test_subsegment_matches_parent_on_every_kind():
    ell = EllipseArc((17, 32), 23, 32, (17, 0), (40, 32), "ccw")
    for seg in (Line((1, 2), (4, 9)), Arc((0, 5), 5, (0, 0), (5, 5), "ccw"), ell, OffsetEllipseArc(ell, 3.0)):
        sub = subsegment(seg, 0.25, 0.75)
        s = np.linspace(0, 1, 7)
        np.testing.assert_allclose(sub.point(s), seg.point(0.25 + 0.5 * s), atol=1e-12)
        assert sub.kind == seg.kind


def test_param_at_z_inverts_each_kind():
    ell = EllipseArc((17, 32), 23, 32, (17, 0), (40, 32), "ccw")
    segs = [Line((1, 2), (4, 9)), Arc((25, 140), 10, (35, 140), (29.226182617407, 149.0630778703665), "ccw"),
            Arc((19, 160.45), 6, (19 + 6 * math.cos(-2.0), 160.45 + 6 * math.sin(-2.0)), (13, 160.45), "cw"),
            ell, OffsetEllipseArc(ell, 4.0)]
    for seg in segs:
        t = np.linspace(0.0, 1.0, 41)
        z = seg.point(t)[:, 1]
        np.testing.assert_allclose(seg.point(param_at_z(seg, z)), seg.point(t), atol=2e-7)


def test_inner_section_of_spec_bottle_is_offset_and_clipped():
    shape = spec_shape(1)
    inner = inner_section(shape.primary, 3.0, 6.0)
    assert inner[0].p0[1] == pytest.approx(6.0, abs=1e-12)
    assert inner[-1].p1 == pytest.approx((10.0, 215.0), abs=1e-9)
    z = np.linspace(6.0, 215.0, 50)
    # vertical body: r_in = 35 - 3; finish: 13 - 3
    assert radius_at(inner, np.array([50.0, 100.0])) == pytest.approx([32.0, 32.0])
    assert radius_at(inner, np.array([200.0]))[0] == pytest.approx(10.0)
    for a, b in zip(inner[:-1], inner[1:]):
        assert math.dist(a.p1, b.p0) < 1e-9
    assert np.all(np.isfinite(radius_at(inner, z)))


def test_radius_at_outside_range_is_nan():
    inner = inner_section(spec_shape(1).primary, 3.0, 6.0)
    assert np.isnan(radius_at(inner, np.array([1.0, 300.0]))).all()


def test_sharp_joints_are_trimmed_and_bridged():
    sec = stepped_section(30.0, 100.0, 12.0, 130.0, 170.0)
    inner = inner_section(sec, 2.0, 5.0)
    # the convex corner at the shoulder is trimmed, the concave one at the neck gets an arc of r = w
    assert any(isinstance(s, Arc) and s.radius == pytest.approx(2.0) for s in inner)
    for a, b in zip(inner[:-1], inner[1:]):
        assert math.dist(a.p1, b.p0) < 1e-9
    assert radius_at(inner, np.array([50.0, 160.0])) == pytest.approx([28.0, 10.0])


def test_per_segment_walls_bridge_thicker_heel():
    sec = stepped_section(30.0, 100.0, 12.0, 130.0, 170.0)
    inner = inner_section(sec, [4.0, 2.5, 2.0], 6.0)
    assert radius_at(inner, np.array([50.0, 160.0])) == pytest.approx([26.0, 10.0])


def test_split_at_ring_for_flat_base_and_punt():
    assert split_at_ring(spec_shape(1).primary)[2] == 1
    assert split_at_ring(punt_section())[2] == 1
    two_part = Section((Line((0, 10), (8, 6)), Line((8, 6), (20, 0)), Line((20, 0), (20, 50))), (False, False))
    base, wall, k = split_at_ring(two_part)
    assert k == 2 and len(base) == 2 and wall == two_part.segments[2:]


def heel_through_ring_section() -> Section:
    """A punt whose single heel arc passes through its lowest point, the ring, as drawn in CAD."""
    heel = Arc((30.0, 4.0), 4.0, (30.0 - 2 * math.sqrt(3.0), 2.0), (34.0, 4.0), "ccw")
    big_r = (heel.p0[0] ** 2 + 100.0) / 20.0  # dome about (0, 12 - R) through (0, 12) and heel.p0
    dome = Arc((0.0, 12.0 - big_r), big_r, (0.0, 12.0), heel.p0, "cw")
    return Section((dome, heel, Line((34.0, 4.0), (34.0, 150.0))), (False, True))


def test_ring_inside_an_arc_splits_it():
    base, wall, k = split_at_ring(heel_through_ring_section())
    assert k == 1 and len(base) == 2 and len(wall) == 2
    assert base[-1].p1 == pytest.approx((30.0, 0.0)) and wall[0].p0 == base[-1].p1
    assert wall[0].kind == "arc" and wall[0].radius == 4.0


def test_body_profile_flat_and_punt():
    prof = body_profile(spec_shape(3))
    assert prof.z_ib == 5.5 and prof.z_top == pytest.approx(162.0)
    assert [s.name for s in prof.sections] == ["u", "v"]
    for sp in prof.sections:
        assert sp.inner_base[0].p1 == sp.inner_wall[0].p0
    punt = body_profile(BottleShape("round", {"profile": punt_section()}, 3.0, 4.0))
    assert punt.punt
    sp = punt.sections[0]
    assert sp.inner_base[0].p0 == pytest.approx((0.0, 16.0))
    assert math.dist(sp.inner_base[-1].p1, sp.inner_wall[0].p0) < 1e-7
    assert 4.0 <= punt.z_ib < 16.0


def test_too_thick_wall_raises_wall_error_naming_segment():
    with pytest.raises(WallError, match="segment 1"):
        inner_section(torus_foot_section(20.0, 5.0, 100.0), 6.0, 7.0)


def cornered_punt_section() -> Section:
    """A punt whose dome meets a straight chamfer down to the ring at a corner."""
    dome = EllipseArc((0.0, 3.0), 15.0, 9.0, (0.0, 12.0), (15.0, 3.0), "cw")
    segs = (dome, Line((15.0, 3.0), (20.0, 0.0)), Line((20.0, 0.0), (32.0, 10.0)),
            Line((32.0, 10.0), (32.0, 150.0)))
    return Section(segs, (False, False, False))


def test_cornered_punt_base_is_offset_and_joined():
    shape = BottleShape("round", {"profile": cornered_punt_section()}, 2.5, 4.0)
    sp = body_profile(shape).sections[0]
    chain = sp.inner_base + sp.inner_wall
    for a, b in zip(chain[:-1], chain[1:]):
        assert math.dist(a.p1, b.p0) < 1e-7
    # the inner dome is the outer dome offset by base_thickness (trimmed where it meets the wall)
    dome_in, dome_out = sp.inner_base[0], sp.outer_base[0]
    assert isinstance(dome_in, OffsetEllipseArc) and dome_in.w == 4.0
    assert (dome_in.base.center, dome_in.base.radius_r, dome_in.base.radius_z) == (
        dome_out.center, dome_out.radius_r, dome_out.radius_z)
    assert dome_in.p0 == pytest.approx((0.0, 16.0))
    assert sp.inner_wall[0].p0[1] == pytest.approx(body_profile(shape).z_ib)


def test_nearly_tangent_joint_offsets_without_a_descent():
    # joint 1 is smooth only to 8e-7 rad (inside the 1e-6 rad tolerance): the offsets miss by
    # a few micrometres and must still join into a rising inner wall
    eps = 8e-7
    c = (25.0 - 10 * (1 - math.cos(eps)), 140.0 - 10 * math.sin(eps))
    arc = Arc(c, 10.0, (35.0, 140.0), (c[0] + 10 * math.cos(0.9), c[1] + 10 * math.sin(0.9)), "ccw")
    sec = Section((Line((0, 0), (35, 0)), Line((35, 0), (35, 140)), arc,
                   Line(arc.p1, (arc.p1[0], arc.p1[1] + 30))), (False, True, False))
    for w in (3.0, 8.0):
        inner = body_profile(BottleShape("round", {"profile": sec}, w, w + 1)).sections[0].inner_wall
        for a, b in zip(inner[:-1], inner[1:]):
            assert math.dist(a.p1, b.p0) < 1e-9
            assert b.p0[1] >= a.p0[1]
        z = np.concatenate([s.point(np.linspace(0, 1, 33))[:, 1] for s in inner])
        assert np.all(np.diff(z) >= -1e-12)


@pytest.mark.parametrize("n", [1, 2, 3])
def test_radius_at_from_its_table_is_the_by_segment_radius_bit_for_bit(n):
    """radius_at evaluates a chain of lines, arcs and ellipse arcs from a table of its segments
    (every formula at every height, no sort) for up to TABLE_POINTS heights: the same operations
    as each segment's param_at_z and point, so the same radii bit for bit, at random heights,
    every joint, just outside the range (within and beyond its tolerance) and NaN, on every wall
    and base of a public scene, of a stepped section, a punt (an ellipse arc) and a torus foot."""
    from engine.geometry import chain
    prof = body_profile(spec_shape(n))
    chains = [c for sp in prof.sections for c in (sp.inner_wall, sp.outer_wall, sp.inner_base, sp.outer_base) if c]
    chains += [tuple(stepped_section(30.0, 100.0, 12.0, 130.0, 180.0).segments),
               *split_at_ring(punt_section())[:2],  # its base: an ellipse arc (the dome), cw
               *split_at_ring(torus_foot_section(20.0, 6.0, 90.0))[:2]]
    rng = np.random.default_rng(n)
    tabled = 0
    for ch in chains:
        zs = [p[1] for s in ch for p in (s.p0, s.p1)]
        lo, hi = min(zs), max(zs)
        z = np.concatenate([rng.uniform(lo - 1.0, hi + 1.0, 400), zs, [lo - 1e-7, hi + 1e-7, lo - 1e-5, hi + 1e-5, np.nan]])
        tabled += chain._radius_table(tuple(ch)) is not None
        np.testing.assert_array_equal(radius_at(ch, z), chain._radius_by_segment(ch, z))
        grid = z[:400].reshape(20, 20).T  # any shape, any strides
        np.testing.assert_array_equal(radius_at(ch, grid), chain._radius_by_segment(ch, grid))
        assert np.array_equal(radius_at(ch, 0.5 * (lo + hi)), chain._radius_by_segment(ch, np.array(0.5 * (lo + hi))))
    assert tabled == len(chains)  # the tables did answer (offset ellipse arcs would go by segment)


@pytest.mark.parametrize("n", [1, 2, 3])
def test_radii_at_in_one_pass_is_each_chains_radius_at_bit_for_bit(n):
    """radii_at evaluates several chains (a section's walls, a punt's dome, rising and
    descending, lines alone or arcs among them) at their own heights in one pass over one table:
    the same radii as radius_at chain by chain, bit for bit, outside each chain's range (NaN) and
    at NaN, for any shape of heights and a single height; a chain of another kind (an offset
    ellipse arc) goes chain by chain."""
    from engine.geometry import chain
    prof = body_profile(spec_shape(n))
    chains = [c for sp in prof.sections for c in (sp.inner_wall, sp.outer_wall, sp.inner_base) if c]
    chains += [*split_at_ring(punt_section())[:2], (Line((0.0, 0.0), (5.0, 40.0)),)]
    rng = np.random.default_rng(40 + n)
    lo = min(p[1] for ch in chains for s in ch for p in (s.p0, s.p1))
    hi = max(p[1] for ch in chains for s in ch for p in (s.p0, s.p1))
    zs = [rng.uniform(lo - 1.0, hi + 1.0, (3, 50)) for _ in chains]
    zs[0][0, 0] = np.nan
    for picked in (chains, chains[:1], chains[::-1]):
        got = chain.radii_at(picked, zs[:len(picked)])
        for ch, z, r in zip(picked, zs, got):
            assert r.shape == z.shape
            np.testing.assert_array_equal(r, chain._radius_by_segment(ch, z))
            np.testing.assert_array_equal(r, radius_at(ch, z))
    one = chain.radii_at(chains, [0.5 * (lo + hi)] * len(chains))
    assert [np.shape(r) for r in one] == [()] * len(chains)
    assert all(np.array_equal(r, radius_at(ch, 0.5 * (lo + hi)), equal_nan=True) for ch, r in zip(chains, one))
    offset = OffsetEllipseArc(EllipseArc((0.0, 10.0), 8.0, 4.0, (0.0, 6.0), (8.0, 10.0), "ccw"), 1.0)
    mixed = chain.radii_at([chains[0], (offset,)], [zs[0], np.linspace(6.0, 10.0, 7)])
    np.testing.assert_array_equal(mixed[0], radius_at(chains[0], zs[0]))
    np.testing.assert_array_equal(mixed[1], chain._radius_by_segment((offset,), np.linspace(6.0, 10.0, 7)))
