"""The plant drawing (issue 43): every sample's sheet read back as a plant would read it. The PDF
is the sheet's size with its fonts embedded, its outline measures the bottle's height at the
stated scale, its table prints the plant's own figures; the SVG is sized in millimetres; the DXF
is model space at 1:1 with real dimension entities; the scale is the largest that fits; a failed
write leaves the old file; bad requests are one-line errors."""
from __future__ import annotations

import math

import ezdxf
import numpy as np
import pdfplumber
import pytest
from ezdxf import bbox

from engine import cli
from engine.export import drawing
from engine.export.drawing import SCALES, DrawingError, layout, write_drawing
from engine.export.drawing_page import SHEETS, THICK_MM
from engine.geometry import capacity
from engine.geometry.tessellate import tessellate_body
from engine.operations.trade import trade_numbers
from engine.plant.sheet import plant_numbers
from tests.export_helpers import SAMPLES, load

PT_PER_MM = 72.0 / 25.4


def thick_strokes(page, box_mm):
    """The visible-outline strokes (ISO thick lines) of a PDF page inside a paper box (mm; a
    plan stacked above the section is not in it)."""
    x0, y0, x1, y1 = (v * PT_PER_MM for v in box_mm)
    return [o for o in page.lines + page.curves
            if o.get("stroke") and abs((o.get("linewidth") or 0) - THICK_MM * PT_PER_MM) < 1e-3
            and o["x0"] >= x0 - 0.5 and o["x1"] <= x1 + 0.5 and o["y0"] >= y0 - 0.5 and o["y1"] <= y1 + 0.5]


def vertical_texts(page) -> set[str]:
    """The texts set upwards (vertical dimensions), read bottom to top, one per column of chars."""
    columns = {}
    for c in page.chars:
        if not c["upright"]:
            columns.setdefault(round(c["x0"], 1), []).append(c)
    return {"".join(c["text"] for c in sorted(cs, key=lambda c: -c["top"])) for cs in columns.values()}


@pytest.mark.parametrize("project", SAMPLES, ids=lambda p: p.stem)
def test_every_samples_pdf_is_to_scale_with_its_fonts_and_figures(project, tmp_path):
    design, _ = load(project.name)
    out = tmp_path / "sheet.pdf"
    report = write_drawing(design, out, sheet="A3")
    data = out.read_bytes()
    assert data[:5] == b"%PDF-" and b"/FontFile2" in data and b"/Type3" not in data
    with pdfplumber.open(out) as pdf:
        [page] = pdf.pages
        assert page.width == pytest.approx(420.0 * PT_PER_MM, abs=1e-3)
        assert page.height == pytest.approx(297.0 * PT_PER_MM, abs=1e-3)
        assert {c["fontname"].split("+")[-1] for c in page.chars} <= {"DejaVuSans", "DejaVuSans-Bold"}
        text = page.extract_text()
        upwards = vertical_texts(page)
        strokes = thick_strokes(page, report["views"]["section"])
    height = capacity.height_mm(design.shape)
    trade, plant = trade_numbers(design), plant_numbers(design)
    assert f"{height:.1f} ±{plant['tolerances']['height_mm']:.1f}" in upwards
    tip = plant["least_tip"]   # (None where the stability check is not offered: an outline)
    for figure in (design.name, "glassbench", f"{trade['brimful_ml']:.1f} ml",
                   f"{trade['glass_mass_g']:.1f} g", f"{tip['deg']:.1f} °" if tip else "Least tip angle -",
                   report["scale"]):
        assert figure in text, figure
    # the section's outline, drawn with the thick line, spans the bottle's height at the scale
    # (pdfplumber's boxes are the paths' points, not the stroke's ink)
    top, bottom = max(o["y1"] for o in strokes), min(o["y0"] for o in strokes)
    assert (top - bottom) / PT_PER_MM == pytest.approx(height * report["scale_factor"], abs=1e-3)
    [dim] = [d for d in report["dimensions"] if d["tag"] == "height"]
    assert dim["measured_mm"] == pytest.approx(height, abs=1e-9)


def test_the_scale_is_the_largest_standard_one_that_fits(tmp_path):
    design, _ = load("bordeaux.glassbench")
    for sheet in SHEETS:
        page, _ = layout(design, sheet)
        k = SCALES.index(page.scale)
        assert k > 0
        with pytest.raises(DrawingError, match="smaller scale or a larger sheet"):
            layout(design, sheet, scale=SCALES[k - 1])
    assert layout(design, "A3")[0].scale > layout(design, "A4")[0].scale
    assert layout(design, "A3", scale="1:10")[0].scale == pytest.approx(0.1)


def test_a_square_bottle_shows_its_side_and_is_dimensioned_across_its_corners(tmp_path):
    design, _ = load("square.glassbench")
    report = write_drawing(design, tmp_path / "square.svg", sheet="A4")
    assert set(report["views"]) == {"section", "side", "plan"}
    dims = {d["tag"]: d["measured_mm"] for d in report["dimensions"]}
    assert {"width", "depth", "plan-width", "plan-depth", "corners"} <= set(dims)
    # against the tessellated glass: the farthest any outer vertex lies from the axis in plan
    mesh = tessellate_body(design.shape, 0.01)
    reach = float(np.max(np.hypot(mesh.vertices[:, 0], mesh.vertices[:, 1])))
    assert dims["corners"] / 2 == pytest.approx(reach, abs=0.02)
    turn = math.radians(design.shape.rotation_deg)   # the mesh is turned in the scene, not the drawing
    x = mesh.vertices[:, 0] * math.cos(turn) + mesh.vertices[:, 1] * math.sin(turn)
    half_x = float(np.max(np.abs(x)))
    assert dims["width"] / 2 == pytest.approx(half_x, abs=0.02)
    svg = (tmp_path / "square.svg").read_text()
    assert 'width="297mm" height="210mm"' in svg and design.name in svg and "<text" in svg


def test_a_labelled_bottle_dimensions_each_labels_band(tmp_path):
    design, _ = load("labelled.glassbench")
    report = write_drawing(design, tmp_path / "l.pdf")
    wall = [lb for lb in design.labels if lb.surface == "wall"]
    zones = [d for d in report["dimensions"] if d["tag"].startswith("zone-") and not d["tag"].endswith("bottom")]
    assert wall and len(zones) == len(wall)
    assert all(d["measured_mm"] > 0 for d in zones)


def test_the_dxf_is_model_space_at_full_size_with_dimension_entities(tmp_path):
    design, _ = load("bordeaux.glassbench")
    out = tmp_path / "b.dxf"
    report = write_drawing(design, out, sheet="A3")
    doc = ezdxf.readfile(out)
    assert doc.header["$INSUNITS"] == 4
    msp = doc.modelspace()
    outline = bbox.extents(msp.query('*[layer=="OUTLINE"]'))
    height = capacity.height_mm(design.shape)
    assert outline.extmin.y == pytest.approx(0.0, abs=1e-6)
    assert outline.extmax.y == pytest.approx(height, abs=1e-6)
    measured = sorted(d.get_measurement() for d in msp.query("DIMENSION"))
    assert len(measured) == len(report["dimensions"])
    assert any(math.isclose(m, height, abs_tol=1e-6) for m in measured)
    assert len(msp.query('ARC[layer=="OUTLINE"]')) > 0 and len(msp.query("HATCH")) > 0


def test_a_failed_write_leaves_the_old_file_and_no_leftovers(tmp_path, monkeypatch):
    design, _ = load("jar.glassbench")
    out = tmp_path / "jar.pdf"
    out.write_bytes(b"the previous drawing")

    def failing(page, path):
        with open(path, "wb") as fh:
            fh.write(b"%PDF- half")
        raise OSError(28, "No space left on device")

    monkeypatch.setitem(drawing.WRITERS, ".pdf", failing)
    with pytest.raises(OSError):
        write_drawing(design, out)
    assert out.read_bytes() == b"the previous drawing"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["jar.pdf"]


@pytest.mark.parametrize("kwargs, match", [
    ({"path": "x.png"}, "written as .dxf, .pdf, .svg"),
    ({"path": "x"}, "no suffix"),
    ({"sheet": "A0"}, "one of A4, A3"),
    ({"scale": "half"}, "1:N"),
    ({"scale": "1:0"}, "N > 0"),
])
def test_bad_requests_are_clear_errors(tmp_path, kwargs, match):
    design, _ = load("jar.glassbench")
    args = {"path": "x.pdf", **kwargs}
    path = tmp_path / args.pop("path")
    with pytest.raises(DrawingError, match=match):
        write_drawing(design, path, **args)
    assert not path.exists()


def test_the_command_line_writes_a_drawing_and_refuses_in_one_line(tmp_path, capsys):
    project = SAMPLES[0]
    out = tmp_path / "d.pdf"
    assert cli.main(["drawing", str(project), "-o", str(out), "--sheet", "A4"]) == 0
    printed = capsys.readouterr().out
    assert f"wrote {out}" in printed and "A4 landscape at 1:" in printed
    assert out.read_bytes()[:5] == b"%PDF-"
    assert cli.main(["drawing", str(project), str(tmp_path / "d.pdf"), "--scale", "2:1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("glassbench drawing: error: at 2:1 the views need") and "\n" not in err
    assert cli.main(["drawing", str(project)]) == 2
    assert "-o OUT.pdf" in capsys.readouterr().err


def test_a_squat_jar_is_drawn_at_full_size_with_its_plan_above_it(tmp_path):
    """A cream jar 100 mm across and 60 mm tall: beside the section its plan would force 1:2;
    stacked above the front view, the sheet holds both at 1:1."""
    import dataclasses

    from benchmarks.plant_cases import cylinder
    from engine.export.drawing import _needs
    from engine.export.drawing_views import figures
    design = dataclasses.replace(cylinder(r=50.0, h=60.0), name="Cream jar")
    report = write_drawing(design, tmp_path / "jar.pdf", sheet="A3")
    assert report["scale"] == "1:1"
    assert _needs(figures(design.shape), False, 0, 1.0)[0] > 260.0, "beside it, 1:1 does not fit"
    section, plan = report["views"]["section"], report["views"]["plan"]
    assert plan[1] > section[3] and abs((plan[0] + plan[2]) - (section[0] + section[2])) < 1e-6
    with pdfplumber.open(tmp_path / "jar.pdf") as pdf:
        text = pdf.pages[0].extract_text()
    assert "Plan, from above" in text and "the band shown" not in text  # no straight body part
