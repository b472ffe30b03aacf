"""Command line: info numbers, new --from-dxf, export-mesh, render dispatch, app.main routing."""
from __future__ import annotations

import json
import math
import os
import sys
import types

import pytest

import app.main as app_main
from engine import cli
from engine.model.design import Design, Liquid, RenderSettings
from engine.files.dxf_import import section_to_dxf
from engine.files.project import load_project, save_project
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape

INFO_KEYS = {"brimful_ml", "fill_ml", "fill_height_mm", "glass_volume_cm3", "glass_mass_g",
             "height_mm", "max_diameter_mm"}


def cylinder(liquid=Liquid(fill_mode="height", fill_value=50.0)) -> Design:
    sec = Section((Line((0, 0), (30, 0)), Line((30, 0), (30, 100))))
    return Design(BottleShape("round", (("profile", sec),), 3.0, 6.0), liquid=liquid,
                  render=RenderSettings(8, 8, 1), name="Cylinder")


@pytest.fixture
def project(tmp_path):
    path = tmp_path / "cyl.glassbench"
    save_project(path, cylinder(), {})
    return path


def test_info_json_numbers(project, capsys):
    assert cli.main(["info", str(project), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert INFO_KEYS <= set(out)
    cavity = math.pi * 27.0 ** 2
    assert out["brimful_ml"] == pytest.approx(cavity * 94.0 / 1000, rel=1e-9)
    assert out["fill_ml"] == pytest.approx(cavity * 44.0 / 1000, rel=1e-9)
    assert out["fill_height_mm"] == 50.0
    glass = (math.pi * 30.0 ** 2 * 100.0 - cavity * 94.0) / 1000
    assert out["glass_volume_cm3"] == pytest.approx(glass, rel=1e-9)
    assert out["glass_mass_g"] == pytest.approx(glass * 2.52, rel=1e-9)
    assert out["height_mm"] == 100.0 and out["max_diameter_mm"] == pytest.approx(60.0)


def test_info_volume_mode_and_empty(tmp_path, capsys):
    p = tmp_path / "v.glassbench"
    save_project(p, cylinder(Liquid(fill_mode="volume", fill_value=100.0)), {})
    assert app_main.main(["info", str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["fill_ml"] == 100.0
    assert out["fill_height_mm"] == pytest.approx(6.0 + 100e3 / (math.pi * 27.0 ** 2), rel=1e-6)
    save_project(p, cylinder(None), {})
    assert cli.main(["info", str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["fill_ml"] is None and out["brimful_ml"] > 200


def test_info_table_is_readable(project, capsys):
    assert cli.main(["info", str(project)]) == 0
    text = capsys.readouterr().out
    assert "Cylinder" in text and "Brimful capacity" in text and "215.3 ml" in text


def test_errors_are_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.glassbench"
    bad.write_bytes(b"garbage")
    assert cli.main(["info", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a glassbench project" in err and "Traceback" not in err
    assert app_main.main([str(tmp_path / "missing.glassbench")]) == 2
    assert "no such project" in capsys.readouterr().err


def test_new_from_dxf(tmp_path, capsys):
    sec = cylinder().shape.primary
    dxf = tmp_path / "cyl.dxf"
    section_to_dxf(sec, dxf)
    out = tmp_path / "new.glassbench"
    assert cli.main(["new", "--from-dxf", str(dxf), str(out), "--wall", "2.5", "--base", "5"]) == 0
    design, assets = load_project(out)
    assert design.shape.primary == sec and assets == {}
    assert design.shape.wall_thickness == 2.5 and design.shape.base_thickness == 5.0
    assert design.name == "cyl"
    # The framing camera looks at the middle of the bottle from the front.
    assert design.camera.target == (0.0, 0.0, 50.0) and design.camera.eye[1] < -100


def test_new_from_invalid_dxf_section(tmp_path, capsys):
    # A section without a vertical finish: imports, but validation refuses it; nothing written.
    import ezdxf
    doc = ezdxf.new(units=4)
    doc.modelspace().add_lwpolyline([(0, 0), (30, 0), (20, 100)])
    dxf = tmp_path / "cone.dxf"
    doc.saveas(dxf)
    out = tmp_path / "cone.glassbench"
    assert cli.main(["new", "--from-dxf", str(dxf), str(out)]) == 2
    assert "vertical" in capsys.readouterr().err and not out.exists()


def test_export_mesh_rejects_bad_tolerance(project, tmp_path, capsys):
    assert cli.main(["export-mesh", str(project), str(tmp_path / "m.stl"), "--tol", "-1"]) == 2
    assert "--tol" in capsys.readouterr().err


def test_render_rejects_bad_extension_and_sizes(project, tmp_path, capsys):
    assert cli.main(["render", str(project), "-o", str(tmp_path / "x.jpg")]) == 2
    assert ".png" in capsys.readouterr().err
    assert cli.main(["render", str(project), "-o", str(tmp_path / "x.png"), "--spp", "0"]) == 2
    assert "--spp" in capsys.readouterr().err


def test_app_main_routes_to_gui(project, monkeypatch):
    calls = []
    fake = types.ModuleType("app.startup")
    fake.run = lambda path, screenshot: calls.append((path, screenshot))
    monkeypatch.setitem(sys.modules, "app.startup", fake)
    monkeypatch.setenv("DISPLAY", ":0")
    assert app_main.main([str(project)]) == 0
    assert app_main.main([]) == 0
    monkeypatch.delenv("DISPLAY")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("QT_QPA_PLATFORM", "placeholder")  # recorded, so restored afterwards
    monkeypatch.delenv("QT_QPA_PLATFORM")
    monkeypatch.setattr(sys, "platform", "linux")
    assert app_main.main(["--screenshot", "shot.png", str(project)]) == 0  # no display needed
    assert calls == [(str(project), None), (None, None), (str(project), "shot.png")]
    assert os.environ["QT_QPA_PLATFORM"] == "offscreen"


def test_app_main_without_display_renders_preview(project, monkeypatch, capsys):
    seen = []
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setattr(cli, "main", lambda argv: seen.append(argv) or 0)
    assert app_main.main([str(project)]) == 0
    assert seen[0][:3] == ["render", str(project), "-o"] and seen[0][3].endswith("glassbench-cyl.png")
    assert capsys.readouterr().out.strip().endswith("glassbench-cyl.png")


RESOURCES = app_main.RESOURCES


def test_bordeaux_sample_trade_numbers(capsys):
    assert cli.main(["info", str(RESOURCES / "bordeaux.glassbench"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert 770.0 <= out["brimful_ml"] <= 790.0
    assert out["fill_ml"] == 750.0
    assert 55.0 <= out["fill_point_below_top_mm"] <= 70.0
    assert out["height_mm"] == pytest.approx(300.0) and out["max_diameter_mm"] == pytest.approx(75.0)


def test_samples_are_up_to_date_and_valid():
    # The committed files are exactly what resources/make_samples.py builds today.
    import importlib.util
    spec = importlib.util.spec_from_file_location("make_samples", RESOURCES / "make_samples.py")
    make_samples = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_samples)
    built = {"bordeaux": make_samples.bordeaux(), "square": make_samples.square(),
             "jar": make_samples.jar()}
    for name, design in built.items():
        loaded, assets = load_project(RESOURCES / f"{name}.glassbench")
        assert loaded == design, name
        assert design.render.width == 360 and design.render.height == 480
    assert built["square"].shape.cross_section == "rounded_square"
    assert built["jar"].shape.primary.r_top > 30.0  # a wide mouth
    red = built["bordeaux"].liquid.absorption
    assert red[0] < red[1] and red[0] < red[2]  # wine passes red
    from engine.files.dxf_import import section_from_dxf
    dxf = section_from_dxf(RESOURCES / "bordeaux_profile.dxf")
    assert len(dxf) == len(built["bordeaux"].shape.primary)
    assert dxf.z_top == pytest.approx(300.0)


def test_unexpected_failure_is_one_line_not_a_traceback(project, monkeypatch, capsys):
    def broken(*a, **k):
        raise RuntimeError("boom\nsecond line")
    import engine.geometry.capacity
    monkeypatch.setattr(engine.geometry.capacity, "brimful_ml", broken)
    monkeypatch.delenv("GLASSBENCH_DEBUG", raising=False)
    assert cli.main(["info", str(project)]) == 2
    err = capsys.readouterr().err
    assert err == "glassbench info: internal error: RuntimeError: boom second line\n"


def read_image(path):
    import OpenImageIO as oiio
    buf = oiio.ImageBuf(str(path))
    assert not buf.has_error, buf.geterror()
    return buf.get_pixels()


def test_render_writes_png_and_exr(project, tmp_path, capsys):
    png, exr = tmp_path / "c.png", tmp_path / "c.exr"
    assert cli.main(["render", str(project), "-o", str(png), "--width", "8", "--height", "6",
                     "--spp", "1"]) == 0
    assert cli.main(["render", str(project), "-o", str(exr)]) == 0  # the project's own 8 x 8
    assert f"wrote {png}" in capsys.readouterr().out
    assert read_image(png).shape == (6, 8, 3)
    img = read_image(exr)
    assert img.shape == (8, 8, 3) and img.dtype.kind == "f" and (img >= 0).all() and img.max() > 0


def test_headless_preview_really_renders(project, monkeypatch, tmp_path, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setattr(app_main.tempfile, "gettempdir", lambda: str(tmp_path))
    assert app_main.main([str(project)]) == 0
    out = tmp_path / "glassbench-cyl.png"
    assert capsys.readouterr().out.strip().splitlines()[-1] == str(out)
    assert read_image(out).shape == (8, 8, 3)


def test_export_mesh_is_a_closed_solid_of_the_glass_volume(project, tmp_path, capsys):
    import trimesh
    out = tmp_path / "cyl.stl"
    assert cli.main(["export-mesh", str(project), str(out), "--tol", "0.05"]) == 0
    mesh = trimesh.load(out)
    glass_mm3 = math.pi * 30.0 ** 2 * 100.0 - math.pi * 27.0 ** 2 * 94.0
    assert mesh.is_watertight
    assert abs(mesh.volume) == pytest.approx(glass_mm3, rel=5e-3)
    assert cli.main(["export-mesh", str(project), str(tmp_path / "cyl.xyz")]) == 2


def test_new_from_the_sample_dxf_matches_the_sample(tmp_path, capsys):
    out = tmp_path / "b.glassbench"
    assert cli.main(["new", "--from-dxf", str(RESOURCES / "bordeaux_profile.dxf"), str(out)]) == 0
    assert cli.main(["info", str(out), "--json"]) == 0
    numbers = json.loads(capsys.readouterr().out.split("\n", 1)[1])
    assert numbers["brimful_ml"] == pytest.approx(776.0, abs=0.01)


class _Stream:
    """A stderr stand-in: what was written, and whether it claims to be a terminal."""

    def __init__(self, tty):
        self.tty, self.text = tty, ""

    def isatty(self):
        return self.tty

    def write(self, s):
        self.text += s

    def flush(self):
        pass


@pytest.mark.parametrize("tty", [False, True])
def test_render_progress_is_a_line_per_tenth_in_a_log_and_one_live_line_on_a_terminal(tty):
    """A render polls its progress four times a second: a redirected stderr (a CI log) gets a
    line per tenth of the work, not one per poll; a terminal one line rewritten only when its
    text changes."""
    from engine.cli.render import ProgressLine
    out = _Stream(tty)
    line = ProgressLine("rendering 8x6 at 1 spp", out)
    polls = [0.0] * 50 + [i / 400 for i in range(401)] + [1.0] * 50
    for f in polls:
        line.update(f)
    line.close()
    if tty:
        shown = out.text.split("\r")[1:]
        assert len(shown) == len(set(shown)) == 401 and shown[-1] == "rendering 8x6 at 1 spp: 100.0 %\n"
    else:
        assert out.text.splitlines() == [f"rendering 8x6 at 1 spp: {p:3d} %" for p in range(10, 101, 10)]
