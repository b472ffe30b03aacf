"""The plant drawing of outline (free plan) bottles (issue 41), read against the plan's own
geometry: the plan view's pieces lie on the exact section (its signed distance), the elevations'
silhouettes are the sections' support function on each side, the widths across flats and across
corners are the closed forms ``k (h_i + h_j) + 2c``, the radii those of the section's arcs; the
converted flacon, a flask and a shield go through the command line to a PDF that carries the
trade numbers, and the DXF keeps the plan's arcs and radii as entities."""
from __future__ import annotations

import dataclasses
import math

import ezdxf
import numpy as np
import pdfplumber
import pytest

from benchmarks.oracle import main as oracle_main
from benchmarks.oracle_spec import spec_to_design
from benchmarks.paths import ORACLE_SPECS
from engine import cli
from engine.export import drawing_views as views
from engine.export.drawing import layout, write_drawing
from engine.export.drawing_page import Circle, SegmentCurve
from engine.files.project import load_project, save_project
from engine.geometry import plan as P
from engine.geometry.chain import radius_at
from engine.geometry.plan_widths import plan_widths, widest_core
from engine.geometry.validate import body_profile
from engine.model.design import Design
from engine.operations.trade import trade_numbers
from tests.test_drawing import vertical_texts
from tests.test_outline_hard_places import _bottle

#: Bottles across the plan kinds: symmetric both ways, about one axis only, about neither, a
#: cavity with sharp corners (rounding 2 mm under a 3 mm wall); the public flacon and hip flask,
#: whose shoulders curve in both profiles at once.
BOTTLES = {"flacon": lambda: _spec_shape("outline_public_1"),
           "hip-flask": lambda: _spec_shape("outline_public_2"),
           "hexagon": lambda: _bottle(P.hexagon()),
           "octagon": lambda: _bottle(P.octagon(), k=35.0),
           "flask": lambda: _bottle(P.flask(100.0, 35.0), k=46.0),
           "shield": lambda: _bottle(P.shield(), k=35.0),
           "turned-triangle": lambda: _bottle(P.triangle(0.1, rotation_deg=100.0), k=35.0, c=3.0),
           "sharp-cavity": lambda: _bottle(P.hexagon(), c=2.0)}
NAMES = sorted(BOTTLES)
EXACT_MM = 1e-9


def _spec_shape(name: str):
    return spec_to_design(ORACLE_SPECS / f"{name}.json")[0].shape


def _design(name: str) -> Design:
    return Design(BOTTLES[name](), name=f"{name} bottle")


def _radii(shape, z, which: str = "outer"):
    """``(k, r)`` (mm) of the outer (or cavity's) section at heights ``z``, from the profiles."""
    walls = [sp.outer_wall if which == "outer" else sp.inner_wall for sp in body_profile(shape).sections]
    return [radius_at(w, np.clip(z, w[0].p0[1], w[-1].p1[1])) for w in walls]


def _points(curves, layer: str, sx: float) -> np.ndarray:
    """Points (model mm) along the profile curves of one half of a view (41 on each, a line's
    too), flat lines left out."""
    segs = [c for c in curves if isinstance(c, SegmentCurve) and c.layer == layer and c.sx == sx
            and not (c.seg.kind == "line" and c.seg.p0[1] == c.seg.p1[1])]
    assert segs
    p = np.concatenate([np.asarray(c.seg.point(np.linspace(0.0, 1.0, 41)), float).reshape(-1, 2) for c in segs])
    return np.column_stack([sx * p[:, 0], p[:, 1]])


# ------------------------------------------------------------------------- the views
@pytest.mark.parametrize("name", NAMES)
def test_the_elevations_silhouettes_are_the_support_function_on_each_side(name):
    shape = _design(name).shape
    half = views.half_section(shape, 0.0)
    side = views.outside_view(shape, "side", 0.0)
    kinds, checked = set(), 0
    for curves, layer, which, sx, psi in ((half, "OUTLINE", "outer", -1.0, math.pi),
                                          (half, "OUTLINE", "outer", 1.0, 0.0),
                                          (half, "SECTION", "inner", 1.0, 0.0),
                                          (side, "OUTLINE", "outer", -1.0, 1.5 * math.pi),
                                          (side, "OUTLINE", "outer", 1.0, 0.5 * math.pi)):
        p = _points(curves, layer, sx)
        k, r = _radii(shape, p[:, 1], which)
        want = shape.plan.section_support(psi, np.maximum(k, 0.0), r)
        assert np.max(np.abs(sx * p[:, 0] - want)) < EXACT_MM, (layer, which, psi)
        kinds |= {c.seg.kind for c in curves if isinstance(c, SegmentCurve)}
        checked += len(p)
    assert checked > 300
    if name == "flacon":  # its shoulders: arcs, ellipse arcs and, where both profiles curve, neither
        assert {"line", "arc", "ellipse_arc", "silhouette"} <= kinds


def test_a_sharp_cavity_corner_is_seen_where_the_offset_sides_meet():
    # the hexagon's vertex faces +x: the cavity's silhouette there is its sharp corner, k + t/cos 30
    shape = _design("sharp-cavity").shape
    p = _points(views.half_section(shape, 0.0), "SECTION", 1.0)
    body = (p[:, 1] > 10.0) & (p[:, 1] < 70.0)     # the straight body: k = 30, t = 2 - 3
    assert body.sum() > 10
    assert np.max(np.abs(p[body, 0] - (30.0 - 1.0 / math.cos(math.pi / 6)))) < EXACT_MM


@pytest.mark.parametrize("name", NAMES)
def test_the_plan_is_the_exact_section_in_lines_and_arcs(name):
    shape = _design(name).shape
    fig = views.figures(shape)
    curves = views.plan_view(shape, (0.0, 0.0))
    for style, z in (("thick", fig.z_widest), ("hidden", 0.0)):
        pieces = [c for c in curves if c.layer == "OUTLINE" and c.style == style and isinstance(c, SegmentCurve)]
        k, c = (float(v) for v in _radii(shape, np.array(z)))
        assert len(pieces) == len(shape.plan.outer_pieces(k, c))       # one curve per piece
        assert {s.seg.kind for s in pieces} <= {"line", "arc"}
        p = np.concatenate([s.sample(64) for s in pieces])
        sd = shape.plan.signed_distance(p[:, 0], p[:, 1], k, c)[0]
        assert np.max(np.abs(sd)) < EXACT_MM
    [finish] = [c for c in curves if isinstance(c, Circle) and c.layer == "OUTLINE"]
    assert finish.radius == pytest.approx(float(_radii(shape, np.array(shape.z_top))[1]), abs=EXACT_MM)


def test_only_a_plan_symmetric_about_x_is_said_to_be_cut_through_the_axis():
    words = {n: views.section_words(_design(n).shape) for n in NAMES}
    assert {n for n, w in words.items() if w == "cut through the axis"} == {"flacon", "hip-flask", "hexagon",
                                                                            "octagon", "flask", "sharp-cavity"}


# ------------------------------------------------------------------------- the dimensions
def _dims(design, tmp_path):
    report = write_drawing(design, tmp_path / "d.svg", sheet="A3")
    return {d["tag"]: d for d in report["dimensions"]}


def _body(shape):
    """``(k, c)`` of the outer section at the plan's widest height."""
    return (float(v) for v in _radii(shape, np.array(views.figures(shape).z_widest)))


def test_a_hexagon_is_dimensioned_across_flats_and_corners(tmp_path):
    design = _design("hexagon")
    plan, (k, c) = design.shape.plan, _body(design.shape)
    dims = _dims(design, tmp_path)
    flats, corners = 2 * (k * plan.inradius + c), 2 * (k * 1.0 + c)   # its vertex at (1, 0)
    assert dims["plan-depth"]["measured_mm"] == pytest.approx(flats, abs=EXACT_MM)
    assert dims["plan-depth"]["text"] == f"{flats:.1f} across flats"
    assert dims["plan-width"]["measured_mm"] == pytest.approx(corners, abs=EXACT_MM)
    assert dims["plan-width"]["text"] == f"{corners:.1f} across corners"
    assert dims["width"]["measured_mm"] == pytest.approx(corners, abs=EXACT_MM)     # the front view
    assert dims["depth"]["measured_mm"] == pytest.approx(flats, abs=EXACT_MM)       # the side view
    assert dims["radius-0"]["measured_mm"] == pytest.approx(c, abs=EXACT_MM) and dims["radius-0"]["text"] == "R4.0"
    assert "corners" not in dims and "flats" not in dims and "radius-1" not in dims


def test_an_octagon_is_dimensioned_across_its_corners_along_their_own_line(tmp_path):
    design = _design("octagon")
    plan, (k, c) = design.shape.plan, _body(design.shape)
    dims = _dims(design, tmp_path)
    flats = 2 * (k * plan.inradius + c)
    for tag in ("plan-width", "plan-depth", "width", "depth"):
        assert dims[tag]["measured_mm"] == pytest.approx(flats, abs=EXACT_MM)
    assert dims["corners"]["measured_mm"] == pytest.approx(2 * (k + c), abs=EXACT_MM)
    assert dims["corners"]["text"].endswith("across corners")
    assert dims["radius-0"]["measured_mm"] == pytest.approx(c, abs=EXACT_MM)


def test_a_flask_and_a_shield_give_their_widths_and_every_radius(tmp_path):
    for name in ("flask", "shield"):
        design = _design(name)
        plan, (k, c) = design.shape.plan, _body(design.shape)
        dims = _dims(design, tmp_path)
        h = {a: float(plan.support(a)) for a in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi)}
        assert dims["plan-width"]["measured_mm"] == pytest.approx(k * (h[0.0] + h[math.pi]) + 2 * c, abs=EXACT_MM)
        assert dims["plan-depth"]["measured_mm"] == pytest.approx(
            k * (h[0.5 * math.pi] + h[1.5 * math.pi]) + 2 * c, abs=EXACT_MM)
        # every distinct radius of the section: P's arcs grown (k rho + c), P's sharp corners (c)
        want = sorted({round(k * s.radius + c, 6) for s in plan.segments if s.kind == "arc"}
                      | ({round(c, 6)} if plan.corners else set()))
        got = sorted(d["measured_mm"] for t, d in dims.items() if t.startswith("radius-"))
        assert got == pytest.approx(want, abs=1e-6)
    # the shield's straight sides face +-x: its width is across flats; its depth spans a flat and a point
    assert dims["plan-width"]["text"].endswith("across flats") and dims["plan-depth"]["text"][-1].isdigit()


# ------------------------------------------------------------------------- the files
def test_the_converted_flacon_is_drawn_through_the_command_line_with_its_trade_numbers(tmp_path, capsys):
    project, out = tmp_path / "flacon.glassbench", tmp_path / "flacon.pdf"
    assert oracle_main(["convert", str(ORACLE_SPECS / "outline_public_1.json"), str(project)]) == 0
    assert cli.main(["drawing", str(project), "-o", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    design, _ = load_project(project)
    trade = trade_numbers(design)
    with pdfplumber.open(out) as pdf:
        text = pdf.pages[0].extract_text()
        upwards = vertical_texts(pdf.pages[0])
    for figure in (design.name, f"{trade['brimful_ml']:.1f} ml", f"{trade['glass_mass_g']:.1f} g",
                   f"{trade['glass_volume_cm3']:.1f} cm³", "68.2 across corners", "68.2 ±1.3", "60.0 ±1.2",
                   "cut through the axis", "Plan, from above", "Side view"):
        assert figure in text, figure
    assert "60.0 across flats" in upwards and "110.0 ±1.0" in upwards


@pytest.mark.parametrize("name", ["flask", "shield"])
def test_a_flask_and_a_shield_are_drawn_through_the_command_line(name, tmp_path):
    project, out = tmp_path / f"{name}.glassbench", tmp_path / f"{name}.pdf"
    save_project(project, _design(name))
    assert cli.main(["drawing", str(project), "-o", str(out), "--sheet", "A4"]) == 0
    design, _ = load_project(project)
    trade = trade_numbers(design)
    assert out.read_bytes()[:5] == b"%PDF-"
    with pdfplumber.open(out) as pdf:
        text = pdf.pages[0].extract_text()
    for figure in (f"{name} bottle", "Half section", "Side view", "Plan, from above",
                   f"{trade['brimful_ml']:.1f} ml", f"{trade['glass_mass_g']:.1f} g"):
        assert figure in text, figure


def test_the_dxf_keeps_the_plans_arcs_and_dimensions_its_radii(tmp_path):
    design = _design("shield")
    out = tmp_path / "shield.dxf"
    report = write_drawing(design, out)
    msp = ezdxf.readfile(out).modelspace()
    radii = sorted(d.get_measurement() for d in msp.query("DIMENSION") if d.dimtype == 4)
    want = sorted(d["measured_mm"] for d in report["dimensions"] if d["tag"].startswith("radius-"))
    assert len(radii) == len(want) == 2 and radii == pytest.approx(want, abs=1e-9)
    # the plan's pieces: two straight sides and the top as lines, its arcs and rounded corners as arcs
    plan, (k, c) = design.shape.plan, _body(design.shape)
    arcs = [p for p in plan.outer_pieces(k, c) if p.kind == "arc"]
    found = [a for a in msp.query('ARC[layer=="OUTLINE"]')
             if any(abs(a.dxf.radius - p.radius) < 1e-9 for p in arcs)]
    assert len(found) >= len(arcs)


def test_a_labelled_flacon_dimensions_its_labels_band_on_the_silhouette(tmp_path):
    from tests.test_outline_labels import _flacon, _label
    design = _flacon()
    design = dataclasses.replace(design, labels=(_label(design.shape, 30.0),))  # on the flat at 30 deg
    dims = _dims(design, tmp_path)
    assert dims["zone-0"]["measured_mm"] == pytest.approx(40.0, abs=1e-9)
    assert dims["zone-0-bottom"]["measured_mm"] == pytest.approx(20.0, abs=1e-9)
    band = np.array(views.band(design.shape, 20.0, 60.0, 0.0).points)   # right side up, left side down
    right, left = band[:97], band[97:]
    for side, pts, psi in ((1.0, right, 0.0), (-1.0, left, math.pi)):
        k, r = _radii(design.shape, pts[:, 1])
        assert np.max(np.abs(side * pts[:, 0] - design.shape.plan.section_support(psi, k, r))) < EXACT_MM


@pytest.mark.parametrize("name", ["hexagon", "octagon", "shield", "turned-triangle", "sharp-cavity", "flacon"])
def test_the_plan_quotes_the_plan_tabs_widths_between_points_of_the_section(name, tmp_path):
    design = _design(name)
    shape, plan = design.shape, design.shape.plan
    core = widest_core(shape)
    quoted = plan_widths(plan, core.k, core.c)     # what the Plan tab shows the designer
    report = write_drawing(design, tmp_path / "d.svg")
    across = {}
    for d in report["dimensions"]:
        for kind in ("flats", "corners"):
            if d["text"].endswith(f"across {kind}"):
                across.setdefault(kind, []).append(d["measured_mm"])
    assert across["flats"] and across["corners"]
    assert across["flats"] == pytest.approx([quoted.flats] * len(across["flats"]), abs=EXACT_MM)
    assert across["corners"] == pytest.approx([quoted.corners] * len(across["corners"]), abs=EXACT_MM)
    # every measured point of the plan lies on the section drawn there
    page, boxes = layout(design)
    fig = views.figures(shape)
    assert fig.z_widest == core.z
    plan_dims = [d for d in page.dims if d.tag.startswith(("plan-", "corners", "flats", "radius-"))]
    centre = _plan_centre(page, shape)
    for d in plan_dims:
        ends = (d.p2,) if d.axis == "radius" else (d.p1, d.p2)
        p = np.array(ends) - centre
        assert np.max(np.abs(plan.signed_distance(p[:, 0], p[:, 1], core.k, core.c)[0])) < EXACT_MM, d.tag


def _plan_centre(page, shape) -> np.ndarray:
    """The plan view's centre (model mm): the centre of its finish circle."""
    [finish] = [c for c in page.curves if isinstance(c, Circle) and c.layer == "OUTLINE"
                and c.radius == pytest.approx(views.figures(shape).r_top)]
    return np.array(finish.center)
