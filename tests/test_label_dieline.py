"""What the printer gets: die-line figures against the closed forms, least-distortion flattening
with its strain, warnings (strain, shoulder, sharp corner) with where they are, and the die-line
files (SVG, PDF, DXF) to scale, written atomically."""
from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from engine.appearance import dieline_files
from engine.appearance.dieline import flat_shape
from engine.appearance.report import label_report
from engine.appearance.dieline_files import DielineError, write_dieline
from engine.appearance.flatten import flatten
from engine.appearance.frame import Placement, label_frame
from engine.files.project import load_project
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape
from engine.model.design import Label
from tests.label_helpers import BORDEAUX, cone_shape, cylinder_shape, design_with, prism_shape


def grid(fn, nt=21, ns=31):
    s, t = np.meshgrid(np.linspace(0, 1, ns), np.linspace(0, 1, nt))
    return s, t, fn(s, t)


def test_flattening_is_exact_on_developable_patches():
    r, width, height = 37.5, 110.0, 70.0
    s, t, pts = grid(lambda s, t: np.stack([r * np.cos((s - 0.5) * width / r), r * np.sin((s - 0.5) * width / r),
                                            (0.5 - t) * height], -1))
    start = np.stack([(s - 0.5) * width * 0.8, (0.5 - t) * height * 1.2], -1)  # a wrong start
    flat, strain = flatten(pts, start)
    assert strain.max() < 1e-6
    assert flat[10, 0] == pytest.approx([-width / 2 * (1 - (width / 30 / r) ** 2 / 24), 0], abs=1e-3)
    assert flat[0, 15] == pytest.approx([0, height / 2], abs=1e-6)  # centre column up, top edge up


def test_the_least_distortion_flattening_beats_the_tangent_cone_on_a_shoulder():
    design, _ = load_project(BORDEAUX)
    p = Placement(200.0, -90.0, 24.0, 60.0)  # on the convex shoulder arc (radius 30 mm)
    frame = label_frame(design.shape, p)
    flat = flat_shape(design.shape, p)
    assert flat.kind == "outline"
    # The tangent cone keeps the centre parallel and every meridian, so all of the stretch
    # lands on the parallels: |r(h) / (r_c + r'(h_c) (h - h_c)) - 1|.
    h = np.linspace(frame.h0, frame.h1, 201)
    r, _, tr, _ = frame.wall.at(h)
    r_c, slope = frame.wall.at(frame.h_c)[0], frame.wall.at(frame.h_c)[2]
    cone_strain = np.max(np.abs(r / (r_c + slope * (h - frame.h_c)) - 1))
    assert 0.005 < flat.strain.max() < 0.75 * cone_strain
    # The flat shape is symmetric about its centre column, as the band is about its meridian.
    assert flat.flat[:, ::-1, 0] == pytest.approx(-flat.flat[..., 0], abs=1e-6)


def test_die_line_figures_of_a_cylinder_a_cone_and_a_prism():
    body = label_report(design_with(cylinder_shape(), Label(z_mm=100.0, height_mm=80.0, width_mm=120.0)), 0)
    assert body.flat.figures == {"kind": "rectangle", "width_mm": 120.0, "height_mm": 80.0}
    assert body.area_mm2 == pytest.approx(9600.0, rel=1e-12) and body.max_strain == 0.0 and not body.warnings
    cone = label_report(design_with(cone_shape(), Label(z_mm=110.0, height_mm=60.0, width_mm=120.0)), 0)
    fig = cone.flat.figures
    sector_area = 0.5 * math.radians(fig["angle_deg"]) * (fig["r_outer_mm"] ** 2 - fig["r_inner_mm"] ** 2)
    assert cone.area_mm2 == pytest.approx(sector_area, rel=1e-12)  # a developable label: flat = glass
    assert cone.area_mm2 == pytest.approx(120.0 * 60.0, rel=1e-12)  # the mean girth arc x the slant
    prism = label_report(design_with(prism_shape(), Label(z_mm=70.0, angle_deg=45.0, height_mm=90.0,
                                                          width_mm=100.0)), 0)
    assert prism.flat.figures["kind"] == "rectangle" and prism.area_mm2 == 9000.0


def test_a_label_on_the_body_has_no_warnings_but_one_over_the_shoulder_does():
    design, _ = load_project(BORDEAUX)
    body = label_report(dataclasses.replace(design, labels=(Label(z_mm=100.0, height_mm=100.0, width_mm=100.0),)), 0)
    assert body.warnings == () and body.flat.kind == "rectangle"
    over = label_report(dataclasses.replace(design, labels=(Label(z_mm=185.0, height_mm=50.0, width_mm=80.0),)), 0)
    kinds = [w.kind for w in over.warnings]
    assert kinds[:2] == ["strain", "shoulder"] and over.max_strain > 0.005
    strain, shoulder = over.warnings[:2]
    assert "paper takes about 0.5 %" in strain.message and "at z = " in strain.message
    body_top = design.shape.primary.segments[2].p1[1]  # where the cylinder meets the shoulder
    assert body_top - 5 < shoulder.z_mm < body_top + 30 and shoulder.angle_deg == pytest.approx(-90.0)
    assert over.flat.at(shoulder.s, shoulder.t) == pytest.approx([shoulder.x_mm, shoulder.y_mm])


def test_a_sharp_corner_of_the_section_is_a_warning_at_its_height():
    sec = Section((Line((0, 0), (40, 0)), Line((40, 0), (40, 100)), Line((40, 100), (38, 160)),
                   Line((38, 160), (38, 200))), (False, False, False))
    design = design_with(BottleShape("round", (("profile", sec),)), Label(z_mm=100.0, height_mm=60.0, width_mm=80.0))
    report = label_report(design, 0)
    corner = [w for w in report.warnings if w.kind == "corner"]
    assert len(corner) == 1 and corner[0].z_mm == pytest.approx(100.0) and "sharp corner" in corner[0].message
    assert report.flat.kind == "outline"  # a cylinder and a cone: not one developable band


def test_a_tight_cross_section_corner_is_a_warning():
    shape = prism_shape(u=30.0, v=30.0 * math.sqrt(2) - 1.0, wall=1.0)  # corner radius (sqrt2+1) 1 mm
    report = label_report(design_with(shape, Label(z_mm=70.0, angle_deg=65.0, height_mm=60.0, width_mm=60.0)), 0)
    corner = [w for w in report.warnings if w.kind == "corner"]
    assert len(corner) == 1 and "tighter than 3 mm" in corner[0].message
    assert corner[0].angle_deg == pytest.approx(65.0, abs=2.0)  # the corner at 45 deg + 20 deg turn


@pytest.fixture
def shoulder_report():
    design, _ = load_project(BORDEAUX)
    return label_report(dataclasses.replace(design, labels=(Label("crest", z_mm=185.0, height_mm=50.0,
                                                                  width_mm=80.0),)), 0)


def test_the_svg_is_to_scale_with_true_arcs(tmp_path):
    design = design_with(cone_shape(), Label("arc", z_mm=110.0, height_mm=60.0, width_mm=120.0))
    report = label_report(design, 0)
    write_dieline(report, tmp_path / "d.svg", "Cone")
    root = ET.parse(tmp_path / "d.svg").getroot()
    width, view = root.get("width"), [float(v) for v in root.get("viewBox").split()]
    assert width.endswith("mm") and float(width[:-2]) == pytest.approx(view[2], abs=1e-3)  # 1 unit = 1 mm
    arcs = [e.get("d") for e in root if e.tag.endswith("path")]
    radii = sorted(float(d.split()[4]) for d in arcs)
    fig = report.flat.figures
    assert radii == pytest.approx([fig["r_inner_mm"], fig["r_outer_mm"]], abs=1e-3)
    texts = " ".join(e.text for e in root if e.tag.endswith("text"))
    assert "inner radius 122.97 mm" in texts and "scale 1:1" in texts


def test_the_dxf_is_in_millimetres_and_the_pdf_is_page_sized(tmp_path, shoulder_report):
    import ezdxf
    write_dieline(shoulder_report, tmp_path / "d.dxf")
    doc = ezdxf.readfile(tmp_path / "d.dxf")
    assert doc.header["$INSUNITS"] == 4
    cut = [e for e in doc.modelspace() if e.dxf.layer == "cut"]
    pts = np.array([p[:2] for p in cut[0].get_points()])
    assert np.ptp(pts[:, 0]) == pytest.approx(shoulder_report.flat.figures["width_mm"], abs=1e-3)
    assert len([e for e in doc.modelspace() if e.dxf.layer == "warning" and e.dxftype() == "CIRCLE"]) == 2
    write_dieline(shoulder_report, tmp_path / "d.pdf")
    head = (tmp_path / "d.pdf").read_bytes()
    assert head.startswith(b"%PDF")
    page = dieline_files.drawing(shoulder_report)
    box = head.split(b"/MediaBox [")[1].split(b"]")[0].split()
    assert float(box[2]) == pytest.approx(page.width * 72 / 25.4, abs=0.5)


def test_a_failed_write_leaves_the_previous_die_line(tmp_path, shoulder_report, monkeypatch):
    out = tmp_path / "d.svg"
    write_dieline(shoulder_report, out)
    before = out.read_bytes()

    def broken(page, path):
        open(path, "w").write("half")
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(dieline_files, "_svg", broken)
    with pytest.raises(DielineError, match="No space left on device"):
        write_dieline(shoulder_report, out)
    assert out.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["d.svg"]
    with pytest.raises(DielineError, match=r"must end in .svg, .pdf or .dxf"):
        write_dieline(shoulder_report, tmp_path / "d.png")
