"""DXF import: chaining, orientation of arcs/ellipses/bulges, units, and clear errors."""
from __future__ import annotations

import math

import ezdxf
import numpy as np
import pytest

from engine.files.dxf_import import DxfImportError, section_from_dxf, section_to_dxf
from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc, Line


def bottle_section() -> Section:
    """Base, heel arc, body, elliptical shoulder (major axis along z), concave arc, neck."""
    base = Line((0, 0), (25, 0))
    heel = Arc((25, 5), 5, (25, 0), (30, 5), "ccw")
    body = Line((30, 5), (30, 100))
    a, b, s1 = 10.0, 30.0, math.radians(60)
    c = (20.0, 100.0)
    p = (c[0] + a * math.cos(s1), c[1] + b * math.sin(s1))
    shoulder = EllipseArc(c, a, b, (30, 100), p, "ccw")
    tr, tz = -a * math.sin(s1), b * math.cos(s1)
    n = math.hypot(tr, tz)
    nr, nz = tz / n, -tr / n
    radius = (p[0] - 12.0) / (1 - nr)
    c2 = (p[0] + radius * nr, p[1] + radius * nz)
    waist = Arc(c2, radius, p, (12.0, c2[1]), "cw")
    neck = Line((12.0, c2[1]), (12.0, 200.0))
    return Section((base, heel, body, shoulder, waist, neck))


def assert_same_section(got: Section, want: Section, tol=1e-9):
    assert [type(s) for s in got.segments] == [type(s) for s in want.segments]
    t = np.linspace(0, 1, 9)
    for g, w in zip(got.segments, want.segments):
        np.testing.assert_allclose(g.point(t), w.point(t), atol=tol)
        assert getattr(g, "direction", None) == getattr(w, "direction", None)


def test_round_trip_through_dxf(tmp_path):
    want = bottle_section()
    path = tmp_path / "b.dxf"
    section_to_dxf(want, path)
    assert_same_section(section_from_dxf(path), want)


def new_doc(units=4):
    doc = ezdxf.new(units=units)
    return doc, doc.modelspace()


def test_shuffled_and_reversed_entities_are_chained(tmp_path):
    # Neck drawn first and downwards, body reversed, the concave arc as a plain DXF ARC.
    doc, msp = new_doc()
    top = (30 - 20 * math.cos(math.radians(30)), 110.0)
    msp.add_line((top[0], 150), top)
    msp.add_arc((30, 100), 20, 150, 180)        # DXF: ccw from `top` down to (10,100)...
    msp.add_line((10, 100), (10, 5))            # ...walked upward it is cw
    msp.add_arc((5, 5), 5, -90, 0)              # heel, convex
    msp.add_line((5, 0), (0, 0))                # base drawn towards the axis
    msp.add_text("BOTTLE")                      # ignored
    p = tmp_path / "s.dxf"
    doc.saveas(p)
    sec = section_from_dxf(p)
    kinds = [type(s).__name__ for s in sec.segments]
    assert kinds == ["Line", "Arc", "Line", "Arc", "Line"]
    assert sec.segments[0].p0 == (0.0, 0.0) and sec.segments[0].p1 == (5.0, 0.0)
    assert sec.segments[1].direction == "ccw"
    waist = sec.segments[3]
    assert waist.direction == "cw"
    np.testing.assert_allclose(waist.p0, (10, 100), atol=1e-12)
    np.testing.assert_allclose(waist.p1, top, atol=1e-12)
    assert sec.segments[-1].p1 == (top[0], 150.0)


def test_lwpolyline_bulges_become_arcs(tmp_path):
    doc, msp = new_doc()
    bulge = math.tan(math.radians(90) / 4)  # quarter circle, counter-clockwise
    # From the mouth down: neck, body, heel (clockwise when drawn downwards), base.
    msp.add_lwpolyline([(12, 80, 0), (12, 40, 0), (30, 30, 0), (30, 6, -bulge), (24, 0, 0), (0, 0, 0)],
                       format="xyb")
    p = tmp_path / "poly.dxf"
    doc.saveas(p)
    sec = section_from_dxf(p)
    heel = sec.segments[1]
    assert isinstance(heel, Arc) and heel.direction == "ccw"
    np.testing.assert_allclose(heel.center, (24, 6), atol=1e-12)
    assert heel.radius == pytest.approx(6.0, abs=1e-12)
    assert sec.z_top == 80.0 and len(sec) == 5


def test_units_shift_and_mirror(tmp_path):
    doc, msp = new_doc(units=1)  # inches
    msp.add_line((0, 2), (-1, 2))
    msp.add_line((-1, 2), (-1, 6))
    p = tmp_path / "in.dxf"
    doc.saveas(p)
    sec = section_from_dxf(p)
    assert sec.segments[0].p0 == (0.0, 0.0)
    np.testing.assert_allclose(sec.segments[1].p1, (25.4, 101.6), atol=1e-12)


def test_flipped_extrusion_arc_is_mirrored_correctly(tmp_path):
    doc, msp = new_doc()
    msp.add_line((0, 0), (5, 0))
    # An arc seen from below (extrusion -z): OCS x is world -x, so OCS ccw is world cw.
    msp.add_arc((-5, 5), 5, 180, 270, dxfattribs={"extrusion": (0, 0, -1)})
    msp.add_line((10, 5), (10, 50))
    p = tmp_path / "ocs.dxf"
    doc.saveas(p)
    sec = section_from_dxf(p)
    arc = sec.segments[1]
    np.testing.assert_allclose(arc.center, (5, 5), atol=1e-12)
    assert arc.direction == "ccw"
    np.testing.assert_allclose(arc.point(0.5), (5 + 5 / math.sqrt(2), 5 - 5 / math.sqrt(2)), atol=1e-9)


@pytest.mark.parametrize("build, message", [
    (lambda m: (m.add_line((0, 0), (10, 0)), m.add_line((10, 1), (10, 50))), "gaps"),
    (lambda m: (m.add_line((0, 0), (10, 0)), m.add_line((10, 0), (10, 50)),
                m.add_line((10, 0), (20, 0))), "branches"),
    (lambda m: (m.add_line((0, 0), (10, 0)), m.add_spline([(10, 0), (12, 5), (10, 50)])), "SPLINE"),
    (lambda m: (m.add_line((0, 0), (10, 0)), m.add_circle((10, 10), 3)), "CIRCLE"),
    (lambda m: (m.add_line((0, 0), (10, 0)),
                m.add_ellipse((10, 10), (3, 3), 0.5, 0, 1)), "rotated by 45"),
    (lambda m: (m.add_line((5, 0), (10, 0)), m.add_line((10, 0), (10, 50))), "axis"),
    (lambda m: m.add_lwpolyline([(0, 0), (10, 0), (10, 50)], close=True), "closed loop"),
    (lambda m: None, "no lines"),
])
def test_clear_errors(tmp_path, build, message):
    doc, msp = new_doc()
    build(msp)
    p = tmp_path / "bad.dxf"
    doc.saveas(p)
    with pytest.raises(DxfImportError, match=message):
        section_from_dxf(p)


def test_unreadable_file(tmp_path):
    p = tmp_path / "junk.dxf"
    p.write_bytes(b"\x00\x01 not a dxf at all")
    with pytest.raises(DxfImportError, match="cannot read DXF"):
        section_from_dxf(p)
    with pytest.raises(DxfImportError, match="cannot read DXF"):
        section_from_dxf(tmp_path / "missing.dxf")


def punt_section(lift: float = 0.0) -> Section:
    """A punted base: a concave dome from (0, 12) down to the standing ring at (28, 0)."""
    rp = (28.0 ** 2 + 12.0 ** 2) / 24.0
    c = (0.0, 12.0 - rp + lift)
    punt = Arc(c, rp, (0.0, 12.0 + lift), (28.0, lift), "cw")
    heel = Arc((28.0, 9.5 + lift), 9.5, (28.0, lift), (37.5, 9.5 + lift), "ccw")
    return Section((punt, heel, Line((37.5, 9.5 + lift), (37.5, 100.0 + lift))))


def test_punt_stands_on_its_ring(tmp_path):
    # Drawn 40 mm up: the import stands the ring on z = 0 and keeps the dome above it.
    path = tmp_path / "punt.dxf"
    section_to_dxf(punt_section(lift=40.0), path)
    got = section_from_dxf(path)
    assert_same_section(got, punt_section(), tol=1e-9)
    assert abs(got.segments[0].p0[0]) < 1e-12 and got.segments[0].p0[1] == pytest.approx(12.0)


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from engine.files.dxf_import import section_from_document  # noqa: E402


@settings(max_examples=30, deadline=None)
@given(order=st.permutations(range(6)), flip=st.lists(st.booleans(), min_size=6, max_size=6))
def test_any_entity_order_and_line_direction_gives_the_same_section(tmp_path_factory, order, flip):
    path = tmp_path_factory.mktemp("dxf") / "b.dxf"
    want = bottle_section()
    section_to_dxf(want, path)
    drawn = list(ezdxf.readfile(path).modelspace())
    doc, msp = new_doc()
    for k in order:
        e = drawn[k]
        if e.dxftype() == "LINE" and flip[k]:
            msp.add_line(e.dxf.end, e.dxf.start)
        else:
            msp.add_entity(e.copy())
    assert_same_section(section_from_document(doc), want)


def test_flat_ellipse_heel_round_trip(tmp_path):
    # Major axis along r (radius_r > radius_z), walked clockwise: a concave flat ellipse.
    e = EllipseArc((40.0, 8.0), 12.0, 4.0, (28.0, 8.0), (40.0, 4.0), "ccw")
    want = Section((Line((0, 0), (20, 0)), Line((20, 0), (28, 8)), e.reversed().reversed(),
                    Line((40.0, 4.0), (40.0, 60.0))))
    path = tmp_path / "e.dxf"
    section_to_dxf(want, path)
    assert_same_section(section_from_dxf(path), want)
    flipped = Section((Line((0, 0), (20, 0)), Line((20, 0), (28, 8)),
                       EllipseArc((40.0, 8.0), 12.0, 4.0, (28.0, 8.0), (40.0, 4.0), "cw"),
                       Line((40.0, 4.0), (40.0, 60.0))))
    section_to_dxf(flipped, path)
    assert_same_section(section_from_dxf(path), flipped)
