"""Prints on the closure through the label mechanism: a cap-top print seen from above, a skirt
print from the side, nothing on the bottle, following the cap when the neck changes, refusals,
the project round trip, the command line, and the relabel of a cap print bit for bit."""
from __future__ import annotations

import dataclasses
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from engine.appearance.cap_surfaces import cap_surface, surface_decal
from engine.tracer.kernels.labels import P_BX, P_CX, P_OBJECT, P_V0
from engine.appearance.closure_shapes import default_cap
from engine.appearance.sample import png_bytes
from engine.cli import main
from engine.errors import DesignError, ProjectError
from engine.files.project import load_project, save_project
from engine.operations.check import check_design
from engine.model.design import Camera, Cap, Label, LabelSide
from engine.tracer.context import RenderContext, trace_pixels, trace_rays
from engine.tracer.job import RenderJob
from engine.tracer.job_options import Replaces
from engine.tracer.kernels import labels as KL
from engine.tracer.kernels.integrator import C_LEAKS, C_MISMATCH
from tests.test_tracer import WHITE

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "resources"))
from make_samples import bordeaux_section, round_shape  # noqa: E402

RED = (220, 20, 20)


@pytest.fixture(scope="module")
def bordeaux():
    d, assets = load_project(ROOT / "resources" / "bordeaux.glassbench")
    return dataclasses.replace(d, cap=Cap("screw", "plastic", (0.9, 0.9, 0.88)), labels=()), assets


def red_png(alpha=None) -> bytes:
    px = np.empty((16, 16, 3 if alpha is None else 4), np.uint8)
    px[..., :3] = RED
    if alpha is not None:
        px[..., 3] = alpha
    return png_bytes(px)


def print_on(surface, **kw) -> Label:
    base = dict(name=surface, front=LabelSide("red.png"), surface=surface, height_mm=8.0, width_mm=12.0,
                diffuse=0.8, specular=0.04, transmission=0.0)
    base.update(kw)
    return Label(**base)


def _with(design, assets, *labels):
    return dataclasses.replace(design, labels=labels), {**assets, "red.png": red_png()}


def _render(design, assets, camera, w=24, h=24):
    d = dataclasses.replace(design, camera=camera)
    ctx = RenderContext.from_design(d, assets, w, h)
    ys, xs = np.mgrid[0:h, 0:w]
    res = trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, 1)
    assert res.counters[C_LEAKS] == 0 and res.counters[C_MISMATCH] == 0
    return res.sums.reshape(h, w, 3), res.objects.reshape(h, w), ctx


def _on_cap(objects, ctx):
    first = ctx.geometry.obj_i.shape[0]
    cap_bits = sum(1 << (first + i) for i in range(ctx.cap.obj_i.shape[0]))
    return (objects & cap_bits) != 0


def _is_red(rgb):
    return rgb[0] > 4.0 * rgb[1] and rgb[0] > 4.0 * rgb[2]


def test_a_cap_top_print_shows_from_above_and_nothing_on_the_bottle(bordeaux):
    plain, assets = bordeaux
    d, a = _with(plain, assets, print_on("cap-top"))
    top = cap_surface(d, "cap-top").z0
    above = Camera(eye=(0.0, -1.0, top + 300.0), target=(0.0, 0.0, top), up=(0.0, 1.0, 0.0), fov_y_deg=14.0)
    img, objects, ctx = _render(d, a, above)
    ref, ref_objects, _ = _render(plain, a, above)
    assert _is_red(img[12, 12]) and not _is_red(ref[12, 12])   # the print, centred on the axis
    assert not _is_red(img[2, 12]) and not _is_red(img[12, 2])  # the cap beyond its 12 x 8 mm
    away = ~_on_cap(objects, ctx)
    assert away.sum() > 50
    np.testing.assert_array_equal(img[away], ref[away])         # nothing printed on the bottle
    np.testing.assert_array_equal(objects[away], ref_objects[away])


def test_a_skirt_print_shows_from_the_side_facing_its_azimuth(bordeaux):
    plain, assets = bordeaux
    d, a = _with(plain, assets, print_on("cap-skirt", angle_deg=-90.0, z_mm=6.0, height_mm=6.0, width_mm=10.0))
    skirt = cap_surface(d, "cap-skirt")
    mid = skirt.z0 + 6.0
    front = Camera(eye=(0.0, -250.0, mid), target=(0.0, 0.0, mid), fov_y_deg=6.0)
    img, objects, ctx = _render(d, a, front)
    ref, _, _ = _render(plain, a, front)
    assert _is_red(img[12, 12]) and not _is_red(ref[12, 12])
    back = Camera(eye=(0.0, 250.0, mid), target=(0.0, 0.0, mid), fov_y_deg=6.0)  # the print faces -y
    behind, _, _ = _render(d, a, back)
    assert not _is_red(behind[12, 12])
    away = ~_on_cap(objects, ctx)
    np.testing.assert_array_equal(img[away], ref[away])


def test_a_cap_print_over_the_knurled_skirt_is_bent_by_the_knurl(bordeaux):
    """A screw cap's skirt is knurled: the knurl bends a skirt print's shading normal as it
    bends the plastic's, so a row of rays across the print sees the ridges."""
    plain, assets = bordeaux
    d, a = _with(plain, assets, print_on("cap-skirt", angle_deg=-90.0, z_mm=6.0, height_mm=6.0, width_mm=12.0,
                                         specular=0.3))
    skirt = cap_surface(d, "cap-skirt")
    xs = np.linspace(-3.0, 3.0, 41)
    o = np.array([[x, -200.0, skirt.z0 + 6.0] for x in xs])
    ctx = RenderContext.from_design(d, a, 8, 8)
    out, counters = trace_rays(ctx, o, np.tile([0.0, 1.0, 0.0], (len(o), 1)))
    assert counters[C_LEAKS] == 0 and np.mean([_is_red(v) for v in out]) > 0.8  # (some see a glint)
    rows = ctx.finish.obj_rows.copy()
    rows[ctx.geometry.obj_i.shape[0], 1] = 0   # the same skirt without its relief rows
    smooth = dataclasses.replace(ctx, finish=ctx.finish._replace(obj_rows=rows))
    flat, _ = trace_rays(smooth, o, np.tile([0.0, 1.0, 0.0], (len(o), 1)))
    assert np.mean(np.abs(out - flat).sum(-1) > 1e-3) > 0.5


def test_a_half_transparent_print_shows_the_cap_beneath():
    """Where the artwork's alpha is 1/2 the cap's own material gives the other half: in a white
    furnace a white plastic cap under a print of a white that gives back all it receives stays
    bounded by 1 and both shares are there."""
    d, assets = load_project(ROOT / "resources" / "bordeaux.glassbench")
    white = np.full((16, 16, 4), 255, np.uint8)
    white[..., 3] = 128
    lab = print_on("cap-top", front=LabelSide("w.png"), diffuse=1.0, specular=0.0)
    d = dataclasses.replace(d, cap=Cap("screw", "plastic", (0.5, 0.5, 0.5)), labels=(lab,), lights=())
    ctx = RenderContext.from_design(d, {"w.png": png_bytes(white)}, 8, 8, environment=WHITE)
    out, counters = trace_rays(ctx, [[0.2, 0.1, 400.0]], [[0.0, 0.0, -1.0]])
    alpha = 128 / 255
    r = ((1.49 - 1) / (1.49 + 1)) ** 2   # the plastic's coat at normal incidence (its own test)
    cap = r + (1 - r) * 0.5
    assert out[0] == pytest.approx([alpha + (1 - alpha) * cap] * 3, abs=1e-4)
    assert counters[C_LEAKS] == 0


def test_a_cap_print_follows_the_cap_when_the_neck_changes(bordeaux):
    plain, assets = bordeaux
    lab = print_on("cap-skirt", z_mm=5.0)
    lo = dataclasses.replace(plain, shape=round_shape(bordeaux_section(190.0, top=280.0)), labels=(lab,))
    hi = dataclasses.replace(lo, shape=round_shape(bordeaux_section(190.0, top=300.0)))
    a = {**assets, "red.png": red_png()}
    for d in (lo, hi):
        check_design(d, a)
    assert surface_decal(hi, lab).h0 - surface_decal(lo, lab).h0 == pytest.approx(20.0, abs=1e-9)
    # a cap-top print too: a ray straight down meets it at the new height on both
    for d in (lo, hi):
        top = dataclasses.replace(d, labels=(print_on("cap-top"),))
        ctx = RenderContext.from_design(top, a, 8, 8)
        out, _ = trace_rays(ctx, [[0.3, 0.2, 500.0]], [[0.0, 0.0, -1.0]])
        assert _is_red(out[0])


def test_the_place_table_names_the_cap_object_and_surface_band(bordeaux):
    plain, assets = bordeaux
    d, a = _with(plain, assets, Label("wall"), print_on("cap-top", angle_deg=0.0))
    ctx = RenderContext.from_design(d, a, 8, 8)
    place = ctx.labels.place
    first = ctx.geometry.obj_i.shape[0]
    assert place[0, P_OBJECT] == 0 and place[1, P_OBJECT] == first
    assert ctx.labels.objects[0] == 1 | (1 << first)
    assert place[1, P_V0] == cap_surface(d, "cap-top").v0 and place[1, P_BX] == 1.0 and place[1, P_CX] == 0.0
    assert (KL.WALL, KL.CAP_TOP, KL.CAP_SKIRT) == (0, 1, 2)


@pytest.mark.parametrize("cap, label, words", [
    (None, print_on("cap-top"), "has no cap"),
    ("screw", print_on("cap-top", width_mm=30.0, height_mm=10.0), "past its edge"),
    ("screw", print_on("cap-top", cap_x_mm=12.0), "past its edge"),
    ("screw", print_on("cap-skirt", z_mm=5.0, height_mm=30.0), "do not fit on the cap's straight skirt"),
    ("screw", print_on("cap-skirt", z_mm=5.0, width_mm=200.0), "at most once around"),
    ("crown", print_on("cap-skirt", z_mm=2.0, height_mm=2.0), "has no straight skirt"),
])
def test_a_cap_print_that_cannot_be_made_is_refused(bordeaux, cap, label, words):
    plain, assets = bordeaux
    d, a = _with(plain, assets, label)
    d = dataclasses.replace(d, cap=None if cap is None else default_cap(cap))
    with pytest.raises(DesignError, match=words) as err:
        check_design(d, a)
    assert "design.labels[0]" in str(err.value)


def test_a_bad_surface_name_is_refused(bordeaux):
    plain, assets = bordeaux
    d, a = _with(plain, assets, print_on("cap-bottom"))
    with pytest.raises(DesignError, match="surface must be one of wall, cap-top, cap-skirt"):
        check_design(d, a)


def test_project_round_trip_and_old_labels_load_on_the_wall(bordeaux, tmp_path):
    plain, assets = bordeaux
    d, a = _with(plain, assets, print_on("cap-top", cap_x_mm=1.5, cap_y_mm=-2.0, angle_deg=30.0),
                 print_on("cap-skirt", z_mm=5.0), Label("wall label"))
    path = tmp_path / "p.glassbench"
    save_project(path, d, a)
    back, _ = load_project(path)
    assert back == d
    from engine.files.serialize import design_from_document, document_from_design
    doc = json.loads(json.dumps(document_from_design(dataclasses.replace(d, labels=(Label("old"),)))))
    doc["format_version"] = 2   # a file written before the fields: format 3 added them
    for key in ("surface", "cap_x_mm", "cap_y_mm"):
        del doc["design"]["labels"][0][key]
    assert design_from_document(doc).labels == (Label("old"),)
    doc["format_version"] = 3   # the current format lacking them is a broken file
    with pytest.raises(ProjectError, match=r"labels\[0\] lacks 'surface'"):
        design_from_document(doc)


def test_the_command_line_adds_cap_prints_and_lists_their_die_lines(bordeaux, tmp_path, capsys):
    plain, assets = bordeaux
    path = tmp_path / "p.glassbench"
    save_project(path, plain, assets)
    (tmp_path / "logo.png").write_bytes(red_png())
    assert main(["label", str(path), "add", str(tmp_path / "logo.png"), "--on", "cap-top",
                 "--width", "10", "--height", "6", "--name", "top"]) == 0
    assert main(["label", str(path), "add", str(tmp_path / "logo.png"), "--on", "cap-skirt",
                 "--width", "20", "--height", "5", "--name", "skirt"]) == 0
    d, _ = load_project(path)
    skirt = cap_surface(d, "cap-skirt")
    assert [lab.surface for lab in d.labels] == ["cap-top", "cap-skirt"]
    assert d.labels[1].z_mm == pytest.approx(skirt.height_mm / 2)  # centred on the skirt
    capsys.readouterr()
    assert main(["labels", str(path), "--json"]) == 0
    figs = [lab["dieline"] for lab in json.loads(capsys.readouterr().out)["labels"]]
    assert figs[0]["surface"] == "cap-top" and figs[0]["disk_diameter_mm"] == pytest.approx(2 * cap_surface(d, "cap-top").radius, abs=1e-3)
    assert figs[1] == {"kind": "rectangle", "width_mm": 20.0, "height_mm": 5.0, "surface": "cap-skirt",
                       "skirt_height_mm": round(skirt.height_mm, 3),
                       "skirt_girth_mm": round(2 * math.pi * skirt.radius, 3)}
    assert main(["labels", str(path)]) == 0
    assert "on the cap's top (a flat disk" in capsys.readouterr().out
    out = tmp_path / "top.svg"
    assert main(["dieline", str(path), "top", "-o", str(out)]) == 0
    assert "printed on the cap's top" in out.read_text()
    # refusals, one line each, the project untouched
    assert main(["label", str(path), "add", str(tmp_path / "logo.png"), "--on", "cap-top",
                 "--width", "40", "--height", "40"]) == 2
    assert "past its edge" in capsys.readouterr().err
    assert main(["label", str(path), "add", str(tmp_path / "logo.png"), "--width", "40", "--height", "40"]) == 2
    assert "needs --z" in capsys.readouterr().err
    assert load_project(path)[0] == d


def test_a_cap_print_relabels_bit_for_bit(bordeaux):
    plain, assets = bordeaux
    top = cap_surface(dataclasses.replace(plain, labels=()), "cap-top").z0
    cam = Camera(eye=(0.0, -60.0, top + 80.0), target=(0.0, 0.0, top - 10.0), fov_y_deg=20.0)
    d, a = _with(dataclasses.replace(plain, camera=cam), assets, print_on("cap-top", width_mm=14.0, height_mm=10.0))
    a["blue.png"] = png_bytes(np.tile(np.array([20, 20, 220], np.uint8), (16, 16, 1)))
    kw = dict(width=32, height=32, spp=2, threads=1)
    first = RenderJob(d, a, **kw).start()
    first.wait()
    assert ((first.film.objects >> KL.LABEL_BIT0) & 1).sum() > 10

    def relabel(lab):
        d2 = dataclasses.replace(d, labels=(lab,))
        rel = RenderJob(d2, a, replaces=Replaces(first, {"labels"}), **kw).start()
        full = RenderJob(d2, a, **kw).start()
        rel.wait()
        full.wait()
        assert rel.context.geometry is first.context.geometry
        np.testing.assert_array_equal(rel.image(), full.image())
        return rel

    rel = relabel(dataclasses.replace(d.labels[0], front=LabelSide("blue.png")))
    assert rel.relabelled_pixels == 0 and rel.recoloured_pixels > 0
    moved = relabel(dataclasses.replace(d.labels[0], cap_x_mm=1.5))
    assert moved.relabelled_pixels > 0
