"""Plan outlines from DXF (engine.files.dxf_plan), the outline bottle of a section and a plan
(engine.geometry.outline_from_section) and ``glassbench new --from-dxf S.dxf --plan P.dxf``.

Plans are drawn here with ezdxf from the presets' exact segments (mm), so a read plan can be
held against the drawn one; the bottle's capacity is held against Steiner's formula integrated
independently over the rule's core and rounding.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest

from engine import cli
from engine.errors import OutlineError, SectionError
from engine.files.dxf_import import DxfImportError, section_from_dxf, section_to_dxf
from engine.files.dxf_plan import plan_from_dxf
from engine.files.project import load_project
from engine.geometry.offset import radius_at
from engine.geometry.outline_from_section import outline_from_section, outline_sections, size_mismatch
from engine.geometry.plan import PlanOutline, flask, hexagon, regular_polygon
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.validate import validate_shape

ROOT = Path(__file__).resolve().parents[1]
BORDEAUX = ROOT / "resources" / "bordeaux_profile.dxf"


# --------------------------------------------------------------------------- drawing helpers
def new_doc(units=4):
    doc = ezdxf.new(units=units)
    return doc, doc.modelspace()


def draw(msp, outline: PlanOutline, mm: float, shift=(0.0, 0.0)):
    """``outline`` drawn at ``mm`` per unit as DXF LINEs and ARCs (ccw), moved by ``shift``."""
    def at(p):
        return (p[0] * mm + shift[0], p[1] * mm + shift[1])
    for s in outline.segments:
        if s.kind == "line":
            msp.add_line(at(s.p0), at(s.p1))
        else:
            msp.add_arc(at(s.center), s.radius * mm, math.degrees(s.theta0), math.degrees(s.theta1))


def saved(doc, path) -> Path:
    doc.saveas(path)
    return path


def assert_same_plan(got: PlanOutline, want: PlanOutline, mm: float):
    """Segment by segment equal to 1e-9 mm (normalised values times the drawn scale)."""
    assert [s.kind for s in got.segments] == [s.kind for s in want.segments]
    for g, w in zip(got.segments, want.segments):
        for a, b in ((g.p0, w.p0), (g.p1, w.p1)) + (((g.center, w.center),) if g.kind == "arc" else ()):
            assert math.dist(a, b) * mm <= 1e-9, (g, w)
        if g.kind == "arc":
            assert abs(g.radius - w.radius) * mm <= 1e-9


def hexagon_dxf(path, mm=37.5, units=4) -> Path:
    doc, msp = new_doc(units)
    draw(msp, hexagon(), mm)
    return saved(doc, path)


# --------------------------------------------------------------------------- reading a plan
@pytest.mark.parametrize("outline, mm", [
    (hexagon(), 40.0),                                # six lines
    (regular_polygon(6, 0.2), 50.0),                  # lines and corner arcs
    (flask(100.0, 40.0), 50.0),                       # a hip flask: four arcs, 100 mm wide
    (regular_polygon(4, 0.3, 45.0), 25.0),            # a rounded square
])
def test_a_drawn_plan_reads_back_as_the_same_outline(tmp_path, outline, mm):
    doc, msp = new_doc()
    draw(msp, outline, mm)
    plan = plan_from_dxf(saved(doc, tmp_path / "plan.dxf"))
    assert plan.scale == pytest.approx(mm, rel=1e-12)
    assert_same_plan(plan, outline, mm)


def test_any_order_and_direction_of_the_curves_gives_the_counter_clockwise_loop(tmp_path):
    want = regular_polygon(6, 0.2)
    doc, msp = new_doc()
    segs = list(want.segments)
    order = [7, 2, 11, 0, 5, 9, 1, 4, 10, 3, 8, 6]
    for k in order:
        s = segs[k]
        if s.kind == "line":  # every other line drawn backwards
            p0, p1 = (s.p1, s.p0) if k % 4 == 0 else (s.p0, s.p1)
            msp.add_line((p0[0] * 30, p0[1] * 30), (p1[0] * 30, p1[1] * 30))
        else:
            msp.add_arc((s.center[0] * 30, s.center[1] * 30), s.radius * 30,
                        math.degrees(s.theta0), math.degrees(s.theta1))
    plan = plan_from_dxf(saved(doc, tmp_path / "shuffled.dxf"))
    # the loop starts with the drawing's first curve and runs counter-clockwise from it
    start = order[0]
    assert_same_plan(plan, PlanOutline.from_dicts([s.to_dict() for s in segs[start:] + segs[:start]]), 30)


def test_a_clockwise_polyline_with_bulges_is_turned_counter_clockwise(tmp_path):
    # a rounded square drawn clockwise: the corners' bulges are negative (clockwise arcs)
    want = regular_polygon(4, 0.3, 45.0)
    pts = []
    for s in reversed(want.segments):
        bulge = 0.0 if s.kind == "line" else -math.tan(s.sweep / 4)
        pts.append((s.p1[0] * 20, s.p1[1] * 20, bulge))
    doc, msp = new_doc()
    msp.add_lwpolyline(pts, format="xyb", close=True)
    plan = plan_from_dxf(saved(doc, tmp_path / "bulges.dxf"))
    assert plan.scale == pytest.approx(20.0, rel=1e-12)
    assert [s.kind for s in plan.segments].count("arc") == 4
    arcs = [s for s in plan.segments if s.kind == "arc"]
    assert all(abs(a.radius - 0.3) <= 1e-12 for a in arcs)
    assert plan.area == pytest.approx(want.area, rel=1e-12)
    # the same joints as the preset, walked the other way round
    got = {tuple(np.round(s.p0, 9)) for s in plan.segments}
    assert got == {tuple(np.round(s.p0, 9)) for s in want.segments}


def test_the_drawing_units_scale_the_plan(tmp_path):
    plan = plan_from_dxf(hexagon_dxf(tmp_path / "cm.dxf", mm=4.0, units=5))  # 4 cm
    assert plan.scale == pytest.approx(40.0, rel=1e-12)
    assert_same_plan(plan, hexagon(), 40.0)


def _star(m):
    pts = [((20 if i % 2 == 0 else 8) * math.cos(math.pi * i / 5), (20 if i % 2 == 0 else 8) * math.sin(math.pi * i / 5))
           for i in range(10)]
    for i in range(10):
        m.add_line(pts[i], pts[(i + 1) % 10])


def _square_with_a_dent(m):
    m.add_line((-10, -10), (10, -10))
    m.add_line((10, -10), (10, 10))
    m.add_line((10, 10), (-10, 10))
    m.add_arc((-20, 0), 10 * math.sqrt(2), -45, 45)  # from (-10, -10) to (-10, 10), bulging in


@pytest.mark.parametrize("build, says", [
    (lambda m: [m.add_line(a, b) for a, b in (((-10, -10), (10, -10)), ((10, -10), (10, 10)), ((10, 10), (-10, 10)))],
     r"not closed: loose ends at \(-10, -10\), \(-10, 10\) \(mm\)"),
    (lambda m: (draw(m, hexagon(), 20), draw(m, hexagon(), 5)), "more than one loop: 6 curve"),
    (_star, r"entity [0-9A-F]+, segment 1 of the outline: the outline turns right .*not convex"),
    (_square_with_a_dent, "entity [0-9A-F]+ is an arc bulging into the outline: the outline is not convex"),
    (lambda m: draw(m, hexagon(), 20, shift=(50, 0)), r"origin must lie strictly inside .*30 outside.*bottle's axis"),
    (lambda m: draw(m, hexagon(), 20, shift=(20, 0)), "origin must lie strictly inside the outline .it is on the boundary"),
    (lambda m: None, "the drawing holds no lines, arcs or polylines"),
    (lambda m: (draw(m, hexagon(), 20), m.add_ellipse((0, 0), (3, 0), 0.5, 0, 1)),
     r"unsupported DXF entity ELLIPSE .handle [0-9A-F]+. in a plan outline; use LINE, ARC or LWPOLYLINE"),
    (lambda m: m.add_circle((0, 0), 20), "unsupported DXF entity CIRCLE"),
    (lambda m: (draw(m, hexagon(), 20), m.add_line((20, 0), (30, 0))), r"branches at \(20, 0\): 3 curves"),
    (lambda m: draw(m, hexagon(), 3000), "reaches 3000 mm from its origin"),
    (lambda m: m.add_lwpolyline([(20 * math.cos(a), 20 * math.sin(a)) for a in np.linspace(0, 6.28, 300)], close=True),
     "more than 256 curves; a plan outline holds at most 256 segments"),
])
def test_a_plan_that_is_no_convex_outline_round_the_axis_is_one_clear_line(tmp_path, build, says):
    doc, msp = new_doc()
    build(msp)
    path = saved(doc, tmp_path / "bad plan.dxf")
    with pytest.raises(DxfImportError) as err:
        plan_from_dxf(path)
    text = str(err.value)
    assert text.startswith(f"{path}: ") and "\n" not in text
    assert err.match(says)


@pytest.mark.parametrize("content, says", [
    (b"", "cannot read DXF"),
    (b"\x00\x01 not a dxf", "cannot read DXF"),
    (None, "cannot read DXF"),           # no file at all
    ("truncated", "cannot read DXF"),    # the first third of a good file
])
def test_an_unreadable_plan_file_is_named(tmp_path, content, says):
    path = tmp_path / "plan.dxf"
    if content == "truncated":
        data = hexagon_dxf(tmp_path / "good.dxf").read_bytes()
        path.write_bytes(data[: len(data) // 3])
    elif content is not None:
        path.write_bytes(content)
    with pytest.raises(DxfImportError, match=says) as err:
        plan_from_dxf(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


# --------------------------------------------------------------------------- the rule
def shouldered(r_body=40.0, r_mouth=12.0) -> Section:
    """A flat base, a body, a straight shoulder and a neck (corners at its ends), mm."""
    return Section((Line((0, 0), (r_body, 0)), Line((r_body, 0), (r_body, 100)),
                    Line((r_body, 100), (r_mouth, 140)), Line((r_mouth, 140), (r_mouth, 160))),
                   (False, False, False))


def _k_c(shape, z):
    prof = validate_shape(shape)
    return [radius_at(sp.outer_wall, z) for sp in prof.sections]


@pytest.mark.parametrize("plan", [hexagon(), hexagon(rotation_deg=30.0), flask(100.0, 40.0), regular_polygon(8, 0.25)])
def test_the_bottle_reaches_the_drawn_section_along_x_and_its_neck_is_round(plan):
    section = section_from_dxf(BORDEAUX)
    shape = outline_from_section(section, plan, 3.0, 6.0, 2.5)
    z = np.linspace(0.0, section.z_top, 301)
    k, c = _k_c(shape, z)
    wall = section.segments[1:]  # the wall above the punt's ring
    r = radius_at(wall, np.clip(z, wall[0].p0[1], wall[-1].p1[1]))
    np.testing.assert_allclose(np.asarray(shape.xs.support([k, c], 0.0)), r, atol=1e-9)
    assert np.all(c > 0) and np.all(k >= -1e-12)
    widest = z[(z > 10) & (z < 189)]
    np.testing.assert_allclose(_k_c(shape, widest)[1], 2.5, atol=1e-12)  # the rounding asked for
    neck = z[z > 228]
    np.testing.assert_allclose(_k_c(shape, neck)[0], 0.0, atol=1e-12)     # the core has vanished
    np.testing.assert_allclose(_k_c(shape, neck)[1], 14.5, atol=1e-9)     # the round mouth
    assert shape.r_mouth == pytest.approx(14.5, abs=1e-9)
    core, rnd = shape.section("core"), shape.section("round")
    assert core.segments[0] == Line((0.0, 0.0), core.segments[1].p0)   # the punt stood flat
    assert rnd.segments[0].p1 == rnd.segments[1].p0


def test_the_rounding_may_equal_the_mouth_all_the_way_down():
    shape = outline_from_section(shouldered(), hexagon(), 3.0, 6.0, 12.0)
    rnd = shape.section("round")
    assert rnd.segments == (Line((0, 0), (12, 0)), Line((12, 0), (12, 160)))
    k, _ = _k_c(shape, np.array([50.0, 120.0, 150.0]))
    np.testing.assert_allclose(k, [28.0, 14.0, 0.0], atol=1e-12)


@pytest.mark.parametrize("section, rounding, error, says", [
    (Section((Line((0, 0), (40, 0)), Line((40, 0), (40, 100)), Line((40, 100), (8, 130)), Line((8, 130), (12, 140)),
              Line((12, 140), (12, 160))), (False,) * 4), 3.0, SectionError,
     r"segment 2: between z = 100 and 130 mm the section narrows to r = 8 mm, below its mouth's 12 mm"),
    (Section((Line((0, 0), (30, 0)), Line((30, 0), (30, 100)))), 3.0, SectionError, "nowhere wider than its mouth"),
    (Section((Line((0, 0), (12, 0)), Line((12, 0), (40, 60)), Line((40, 60), (12, 100)), Line((12, 100), (12, 120))),
             (False,) * 3), 3.0, SectionError, r"segment 1: the standing ring \(r = 12 mm\) must be wider than the mouth"),
    (shouldered(), 0.0, OutlineError, "more than 0 and less than the section's widest radius 40 mm, got 0 mm"),
    (shouldered(), 40.0, OutlineError, "got 40 mm"),
    (shouldered(), math.nan, OutlineError, "got nan mm"),
])
def test_a_section_the_rule_cannot_follow_is_refused(section, rounding, error, says):
    with pytest.raises(error, match=says):
        outline_sections(section, hexagon(), rounding)


def test_the_plan_must_be_drawn_at_the_section_s_widest_size(tmp_path):
    section = shouldered()
    assert size_mismatch(section, plan_from_dxf(hexagon_dxf(tmp_path / "a.dxf", mm=40.0))) is None
    assert size_mismatch(section, plan_from_dxf(hexagon_dxf(tmp_path / "b.dxf", mm=40.3))) is None  # within 1 %
    # 80 mm across the flats where the section meant 80 across the corners (a vertex on +x)
    across_flats = plan_from_dxf(hexagon_dxf(tmp_path / "c.dxf", mm=40.0 / math.cos(math.pi / 6)))
    assert "the plan reaches 46.19 mm along +x" in size_mismatch(section, across_flats)


# --------------------------------------------------------------------------- the command line
def _steiner_capacity_ml(section_r, plan: PlanOutline, r_m, widest, rounding, wall, base, z_top, breaks):
    """Brimful capacity (ml) of the rule's bottle from Steiner's formula (t = c - w >= 0 here)."""
    h_x = float(plan.support(0.0))
    total = 0.0
    x, wq = np.polynomial.legendre.leggauss(40)
    edges = [base] + [b for b in breaks if base < b < z_top] + [z_top]
    for lo, hi in zip(edges, edges[1:]):
        z = lo + (x + 1) / 2 * (hi - lo)
        r = section_r(z)
        c = r_m + (rounding - r_m) * (r - r_m) / (widest - r_m)
        k = (r - c) / h_x
        t = c - wall
        assert np.all(t >= 0)
        area = k * k * plan.area + k * plan.perimeter * t + math.pi * t * t
        total += (hi - lo) / 2 * float(wq @ area)
    return total / 1000.0


def test_new_makes_an_outline_bottle_whose_capacity_is_steiner_s(tmp_path, capsys):
    sec_path, plan_path = tmp_path / "shoulder.dxf", tmp_path / "hex.dxf"
    section_to_dxf(shouldered(), sec_path)
    hexagon_dxf(plan_path, mm=40.0)
    out = tmp_path / "hex.glassbench"
    argv = ["new", "--from-dxf", str(sec_path), "--plan", str(plan_path), "--wall", "2.5", "--base", "5", str(out)]
    assert cli.main(argv) == 0
    assert capsys.readouterr().out.strip() == f"wrote {out}"
    design, _ = load_project(out)
    assert design.shape.cross_section == "outline"
    assert_same_plan(design.shape.plan, hexagon(), 40.0)
    assert design.name == "shoulder" and design.shape.wall_thickness == 2.5
    assert cli.main(["info", str(out), "--json"]) == 0
    numbers = json.loads(capsys.readouterr().out)

    def r_of(z):
        return np.where(z <= 100, 40.0, np.where(z >= 140, 12.0, 40.0 - 28.0 * (z - 100) / 40))
    want = _steiner_capacity_ml(r_of, hexagon(), 12.0, 40.0, 3.0, 2.5, 5.0, 160.0, [100.0, 140.0])
    assert numbers["brimful_ml"] == pytest.approx(want, rel=1e-6)
    assert numbers["max_diameter_mm"] == pytest.approx(80.0, abs=1e-6)  # across the corners on x
    assert cli.main(["info", str(out)]) == 0
    assert f"Brimful capacity      {numbers['brimful_ml']:10.1f} ml" in capsys.readouterr().out


def test_new_from_the_bordeaux_section_and_a_hexagon_polyline(tmp_path, capsys):
    doc, msp = new_doc()
    msp.add_lwpolyline([(37.5 * math.cos(a), 37.5 * math.sin(a)) for a in np.arange(6) * math.pi / 3], close=True)
    plan = saved(doc, tmp_path / "hex.dxf")
    hexed, rounded = tmp_path / "hex.glassbench", tmp_path / "round.glassbench"
    assert cli.main(["new", "--from-dxf", str(BORDEAUX), "--plan", str(plan), "--round", "4", str(hexed)]) == 0
    assert cli.main(["new", "--from-dxf", str(BORDEAUX), str(rounded)]) == 0
    design, _ = load_project(hexed)
    assert design.shape.cross_section == "outline"
    assert_same_plan(design.shape.plan, hexagon(), 37.5)
    capsys.readouterr()
    caps = []
    for path in (hexed, rounded):
        assert cli.main(["info", str(path), "--json"]) == 0
        caps.append(json.loads(capsys.readouterr().out)["brimful_ml"])
    # the hexagonal body fits inside the round one drawn with the same section
    assert 0.75 * caps[1] < caps[0] < caps[1]


def _run_refused(argv, out, capsys):
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and not out.exists()
    return err


def test_new_refuses_a_bad_plan_or_combination_and_writes_nothing(tmp_path, capsys):
    good_plan = hexagon_dxf(tmp_path / "hex.dxf")
    doc, msp = new_doc()
    _star(msp)
    star = saved(doc, tmp_path / "star.dxf")
    out = tmp_path / "new.glassbench"
    base = ["new", "--from-dxf", str(BORDEAUX)]
    err = _run_refused(base + ["--plan", str(star), str(out)], out, capsys)
    assert f"{star}: entity" in err and "not convex" in err
    err = _run_refused(base + ["--plan", str(tmp_path / "missing.dxf"), str(out)], out, capsys)
    assert "cannot read DXF" in err and "missing.dxf" in err
    big = hexagon_dxf(tmp_path / "big.dxf", mm=45.0)
    err = _run_refused(base + ["--plan", str(big), str(out)], out, capsys)
    assert f"{BORDEAUX} with plan {big}: the plan reaches 45 mm along +x" in err
    err = _run_refused(base + ["--plan", str(good_plan), "--wall", "14", "--base", "15", str(out)], out, capsys)
    assert f"with plan {good_plan}: the cavity at z = " in err
    err = _run_refused(base + ["--plan", str(good_plan), "--round", "40", str(out)], out, capsys)
    assert "less than the section's widest radius 37.5 mm" in err
    err = _run_refused(base + ["--round", "2", str(out)], out, capsys)
    assert "--round rounds a plan outline's corners" in err
    doc, msp = new_doc()
    msp.add_line((0, 0), (30, 0))
    msp.add_line((30, 1), (30, 50))
    gap = saved(doc, tmp_path / "gap.dxf")
    err = _run_refused(["new", "--from-dxf", str(gap), "--plan", str(good_plan), str(out)], out, capsys)
    assert f"{gap}: the drawing has gaps" in err  # (the section's fault, named by its file)


def test_a_plan_without_a_section_is_refused_by_the_parser(tmp_path, capsys):
    out = tmp_path / "new.glassbench"
    with pytest.raises(SystemExit) as exit_:
        cli.main(["new", "--plan", str(hexagon_dxf(tmp_path / "hex.dxf")), str(out)])
    assert exit_.value.code == 2 and "--from-dxf" in capsys.readouterr().err and not out.exists()
