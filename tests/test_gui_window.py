"""The window's File menu: open/save, dirty marker, prompts, recent files, bad files,
autosave and crash recovery, DXF import, mesh export, and the screenshot entry."""
from __future__ import annotations

import dataclasses
import os
import subprocess
import sys

import pytest

from engine.model.design import Glass
from engine.model.orbit import camera_to_orbit, orbit_to_camera
from engine.files.project import load_project, save_project

pytestmark = pytest.mark.usefixtures("no_leaks")

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESOURCES = os.path.join(REPO, "resources")


def test_save_then_open_round_trips_through_the_window(make_window, tmp_path):
    w = make_window()
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.61))
    assert w.isWindowModified() and "[*]" in w.windowTitle()
    out = tmp_path / "mine.glassbench"
    w.dialogs.save_path = str(tmp_path / "mine")  # the suffix is added
    assert w.files.save_as()
    assert not w.isWindowModified()
    assert w.windowTitle().startswith("mine.glassbench")
    design, _ = load_project(out)
    assert design == w.scene.design
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.7))
    w.dialogs.open_path = str(out)
    w.dialogs.unsaved_answer = "discard"
    assert w.files.open_dialog()
    assert "unsaved" in w.dialogs.asked
    assert w.scene.design.glass.ior == pytest.approx(1.61)
    assert w.undo_stack.count() == 0 and not w.isWindowModified()
    assert w.recent.paths()[0] == str(out.resolve())


def test_the_window_survives_a_bad_file(make_window, tmp_path):
    w = make_window()
    before = w.scene.design
    bad = tmp_path / "broken.glassbench"
    bad.write_bytes(b"this is not a zip archive")
    assert not w.files.open_path(str(bad))
    assert w.dialogs.errors and "broken.glassbench" in w.dialogs.errors[0][1]
    assert w.scene.design == before
    assert w.editor.apply("Glass IOR", None, glass=Glass(ior=1.5)), "the window still edits"


def test_cancel_at_the_unsaved_prompt_keeps_the_window_open(make_window):
    w = make_window()
    w.show()
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.58))
    w.dialogs.unsaved_answer = "cancel"
    assert not w.close()
    assert w.isVisible()
    assert not w.files.new_design()
    assert w.scene.design.glass.ior == pytest.approx(1.58)


def test_save_answer_at_the_prompt_saves_before_new(make_window, tmp_path):
    w = make_window()
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.59))
    w.dialogs.unsaved_answer = "save"
    w.dialogs.save_path = str(tmp_path / "kept.glassbench")
    assert w.files.new_design()
    assert load_project(tmp_path / "kept.glassbench")[0].glass.ior == pytest.approx(1.59)
    assert w.scene.design.glass.ior != pytest.approx(1.59)


def test_autosave_and_recovery_after_a_crash(make_window, qtbot, tmp_path):
    from app.document import recovery_dir
    w = make_window(autosave_ms=50)
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.66))
    autosave = w.files.autosaver.path
    qtbot.waitUntil(autosave.exists, timeout=5000)
    assert load_project(autosave)[0].glass.ior == pytest.approx(1.66)
    # Pretend the process died: its file now belongs to a pid that is not running.
    crashed = recovery_dir() / "autosave-999999999.glassbench"
    save_project(crashed, w.scene.design, {})
    w2 = make_window()
    assert w2.files.offer_recovery()
    assert "recover" in w2.dialogs.asked
    assert w2.scene.design.glass.ior == pytest.approx(1.66)
    assert w2.isWindowModified(), "recovered work is unsaved work"
    assert not crashed.exists()


def test_a_clean_close_removes_the_autosave(make_window, qtbot):
    w = make_window(autosave_ms=50)
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.57))
    qtbot.waitUntil(w.files.autosaver.path.exists, timeout=5000)
    w.dialogs.unsaved_answer = "discard"
    w.close()
    assert not w.files.autosaver.path.exists()


def test_import_dxf_is_one_undoable_step(make_window):
    w = make_window()
    before = w.scene.design
    assert w.files.import_dxf(os.path.join(RESOURCES, "bordeaux_profile.dxf"))
    assert w.scene.design.shape != before.shape
    w.undo_stack.undo()
    assert w.scene.design == before


def test_import_dxf_into_an_outline_bottle_keeps_its_plan_and_makes_the_section_its_front_view(make_window):
    """The flacon takes the Bordeaux section as its front view (reach along +x = r(z)), keeps
    its hexagon, wall and base and its 4 mm rounding at the widest core; one undo restores it."""
    from engine.geometry.plan_widths import widest_core
    design, assets = load_project(os.path.join(RESOURCES, "flacon.glassbench"))
    w = make_window(design, assets=assets)
    before = w.scene.design
    assert w.files.import_dxf(os.path.join(RESOURCES, "bordeaux_profile.dxf"))
    shape = w.scene.design.shape
    assert shape.cross_section == "outline" and shape.plan.segments == before.shape.plan.segments
    assert (shape.wall_thickness, shape.base_thickness) == (before.shape.wall_thickness, before.shape.base_thickness)
    assert widest_core(shape).c == pytest.approx(4.0, abs=1e-9)
    assert shape.z_top == pytest.approx(300.0)  # the Bordeaux's height
    w.undo_stack.undo()
    assert w.scene.design == before


def test_import_of_a_bad_dxf_is_reported(make_window, tmp_path):
    w = make_window()
    bad = tmp_path / "bad.dxf"
    bad.write_text("0\nSECTION\n2\nNONSENSE\n")
    assert not w.files.import_dxf(str(bad))
    assert w.dialogs.errors


def test_export_mesh(make_window, tmp_path):
    w = make_window()
    out = tmp_path / "bottle.stl"
    assert w.files.export_mesh(str(out))
    assert out.stat().st_size > 1000


def test_screenshot_entry_saves_a_picture_and_exits(gui_paths, no_leaks):
    # A separate process, as a user runs it: `glassbench --screenshot OUT.png PROJECT`. The
    # preview renders at its pane's size, so the test bottle stands far off at 1 sample per
    # pixel (most rays miss it): quick to converge at any size.
    design, assets = load_project(os.path.join(RESOURCES, "bordeaux.glassbench"))
    az, el, dist = camera_to_orbit(design.camera)
    far = dataclasses.replace(design, render=dataclasses.replace(design.render, width=48, height=64, spp=1),
                              camera=orbit_to_camera(design.camera, az, el, 3 * dist))
    project = gui_paths / "far.glassbench"
    save_project(project, far, assets)
    out = gui_paths / "shot.png"
    done = subprocess.run([sys.executable, "-m", "app.main", "--screenshot", str(out), str(project)],
                          cwd=REPO, capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stderr
    from PySide6.QtGui import QImage
    img = QImage(str(out))
    assert (img.width(), img.height()) == (1600, 1000), "the window fits a 1600 x 1000 screen"
    # The VTK view was painted in: its area is not one flat colour.
    view_row = {img.pixel(x, img.height() // 2) for x in range(img.width() // 2, img.width(), 7)}
    assert len(view_row) > 5


def test_screenshot_of_a_missing_project_fails_cleanly(qapp, gui_paths, capsys, no_leaks):
    import app.startup as startup
    assert startup.run(str(gui_paths / "nope.glassbench"), str(gui_paths / "x.png")) == 2
    assert "nope.glassbench" in capsys.readouterr().err


def test_a_screenshot_without_an_opengl_context_keeps_the_window_and_says_so(qapp, capsys):
    """Where the platform gives VTK no OpenGL context (Qt's offscreen platform), pyvista raises
    on the framebuffer: the screenshot is the window without the 3D view, with a warning, and
    the app does not hang on the error (it used to wait for the 20-minute deadline)."""
    from PySide6.QtWidgets import QWidget
    import app.startup as startup

    class NoContextView:
        def isVisible(self):
            return True

        def grab_framebuffer(self):
            raise RuntimeError("Render window is not current.")

    window = QWidget()
    window.resize(64, 48)
    window.wireframe = NoContextView()
    pixmap = startup.grab_window(window)
    assert (pixmap.width(), pixmap.height()) == (64, 48)
    assert "the 3D view is not in the screenshot" in capsys.readouterr().err


def test_recent_files_menu_reopens_a_project(make_window, tmp_path):
    w = make_window()
    path = tmp_path / "again.glassbench"
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.63))
    assert w.files.save_to(str(path))
    w.editor.apply("Glass IOR", None, glass=Glass(ior=1.5))
    w.files.recent_menu.aboutToShow.emit()
    actions = {a.text(): a for a in w.files.recent_menu.actions()}
    assert str(path.resolve()) in actions
    w.dialogs.unsaved_answer = "discard"
    actions[str(path.resolve())].trigger()
    assert w.scene.design.glass.ior == pytest.approx(1.63)
