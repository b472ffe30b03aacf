"""Hostile and awkward DXF drawings (issue 11, classes 1 and 4): corners kept, units right,
tiny gaps closed exactly, damaged files refused with a DxfImportError, size bounded."""
from __future__ import annotations

import math

import ezdxf
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine import limits
from engine.files.dxf_import import JOIN_TOL_MM, DxfImportError, section_from_dxf
from engine.files.project import load_project
from engine.geometry.validate import validate_section

FUZZ = settings(max_examples=40, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
SAMPLE = "resources/bordeaux_profile.dxf"


def save(doc, path):
    doc.saveas(path)
    return path


@st.composite
def polylines(draw):
    """Axis -> base corner -> rising wall with real corners -> vertical finish, as (r, z) points."""
    r0 = draw(st.floats(10, 60))
    pts = [(0.0, 0.0), (r0, 0.0)]
    z = 0.0
    for _ in range(draw(st.integers(1, 8))):
        z += draw(st.floats(2, 40))
        pts.append((draw(st.floats(8, 60)), z))
    pts.append((pts[-1][0], z + draw(st.floats(5, 30))))
    return pts


@FUZZ
@given(pts=polylines(), jitter=st.lists(st.tuples(st.floats(-3e-5, 3e-5), st.floats(-3e-5, 3e-5)),
                                        min_size=40, max_size=40),
       order=st.randoms(use_true_random=False), flip=st.lists(st.booleans(), min_size=20, max_size=20))
def test_drawn_corners_and_tiny_gaps_give_a_valid_section(tmp_path_factory, pts, jitter, order, flip):
    doc = ezdxf.new(units=4)
    msp = doc.modelspace()
    lines = []
    for k, (a, b) in enumerate(zip(pts, pts[1:])):
        ja, jb = jitter[2 * k], jitter[2 * k + 1]
        a2 = (a[0] + (ja[0] if k else 0.0), a[1] + ja[1])  # the axis end stays on the axis
        b2 = (b[0] + jb[0], b[1] + jb[1])
        lines.append((b2, a2) if flip[k] else (a2, b2))
    order.shuffle(lines)
    for a, b in lines:
        msp.add_line(a, b)
    sec = section_from_dxf(save(doc, tmp_path_factory.mktemp("dxf") / "p.dxf"))
    validate_section(sec)  # joints exact, base level, finish plumb: a valid bottle profile
    segs = sec.segments
    assert segs[0].p0 == (0.0, 0.0) and segs[0].p1[1] == 0.0
    assert segs[-1].p0[0] == segs[-1].p1[0]
    for (a, b), seg in zip(zip(pts, pts[1:]), segs):  # within the join tolerance of the drawing
        assert math.dist(seg.p0, a) <= 3 * JOIN_TOL_MM and math.dist(seg.p1, b) <= 3 * JOIN_TOL_MM
    for i, (a, b) in enumerate(zip(segs, segs[1:])):  # smoothness comes from the drawing
        ta, tb = a.tangent(1.0), b.tangent(0.0)
        assert sec.smooth[i] == (abs(ta[0] * tb[1] - ta[1] * tb[0]) <= 1e-6 and ta @ tb > 0)


def test_a_shoulder_cone_meeting_the_body_is_a_corner_not_a_refusal(tmp_path):
    doc = ezdxf.new(units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (30, 0), (30, 100), (12, 140), (12, 180)])
    sec = section_from_dxf(save(doc, tmp_path / "cone.dxf"))
    validate_section(sec)
    assert sec.smooth == (False, False, False)


def test_tangent_joints_of_the_sample_stay_smooth():
    sec = section_from_dxf(SAMPLE)
    want = load_project("resources/bordeaux.glassbench")[0].shape.primary
    assert sec.smooth == want.smooth


def test_a_drawing_without_header_is_in_millimetres(tmp_path):
    body = "".join(f"0\nLINE\n8\n0\n10\n{a}\n20\n{b}\n11\n{c}\n21\n{d}\n"
                   for a, b, c, d in ((0, 0, 30, 0), (30, 0, 30, 100)))
    path = tmp_path / "bare.dxf"
    path.write_text(f"0\nSECTION\n2\nENTITIES\n{body}0\nENDSEC\n0\nEOF\n")
    assert section_from_dxf(path).z_top == 100.0


@FUZZ
@given(cut=st.floats(0.0, 1.0), flips=st.lists(st.tuples(st.floats(0, 1), st.integers(1, 255)), max_size=4))
def test_damaged_files_are_refused_cleanly(tmp_path_factory, cut, flips):
    data = bytearray(open(SAMPLE, "rb").read())
    for where, x in flips:
        data[int(where * (len(data) - 1))] ^= x
    del data[max(1, int(cut * len(data))):]
    path = tmp_path_factory.mktemp("dxf") / "bad.dxf"
    path.write_bytes(bytes(data))
    try:
        sec = section_from_dxf(path)
    except DxfImportError as exc:
        assert "\n" not in str(exc) and len(str(exc)) <= 400
    else:
        assert len(sec.segments) >= 1


def test_truncated_file_says_so(tmp_path):
    path = tmp_path / "t.dxf"
    path.write_bytes(open(SAMPLE, "rb").read()[:100])
    with pytest.raises(DxfImportError, match="cannot read DXF"):
        section_from_dxf(path)


def test_too_many_curves_are_refused_before_chaining(tmp_path):
    doc = ezdxf.new(units=4)
    msp = doc.modelspace()
    n = limits.MAX_SEGMENTS + 1
    for k in range(n):
        msp.add_line((30.0, k * 0.1), (30.0, (k + 1) * 0.1))
    with pytest.raises(DxfImportError, match=f"more than {limits.MAX_SEGMENTS} curves"):
        section_from_dxf(save(doc, tmp_path / "many.dxf"))


def test_a_drawing_in_metres_too_large_for_a_bottle_is_named(tmp_path):
    doc = ezdxf.new(units=6)  # metres: 300 drawing units are a 300 m bottle
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (40, 0), (40, 300)])
    with pytest.raises(DxfImportError, match="units right"):
        section_from_dxf(save(doc, tmp_path / "m.dxf"))
