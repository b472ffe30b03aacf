"""What a designer meets around the section: warnings for designs that cannot be made or
filled, tint by thickness, a file opening fitted, names offered to match the fill, tooltips on
every control, the last project reopening, and a clean quit after Discard."""
from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import textwrap

import pytest
from PySide6.QtWidgets import QAbstractButton, QAbstractItemView, QAbstractSpinBox, QComboBox, QLineEdit

from engine.files.project import load_project, save_project
from engine.model import tint

pytestmark = pytest.mark.usefixtures("no_leaks")
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESOURCES = os.path.join(REPO, "resources")


def _sample(name, **render):
    design, assets = load_project(os.path.join(RESOURCES, f"{name}.glassbench"))
    small = dataclasses.replace(design.render, width=24, height=32, spp=1, **render)
    return dataclasses.replace(design, render=small), assets


def test_deleting_the_jars_body_warns_that_it_is_full_to_the_brim(make_window, qtbot):
    design, assets = _sample("jar")
    w = make_window(design, assets=assets)
    panel = w.section_panel
    qtbot.waitUntil(w.derived_idle)
    assert panel.warnings.text() == ""
    panel.canvas.select(2)
    panel.tool_buttons["delete"].click()
    assert w.scene.design.shape.z_top < design.liquid.fill_value
    assert "lowered" in w.statusBar().currentMessage()
    qtbot.waitUntil(lambda: w.derived_idle() and panel.warnings.text() != "")
    assert "brim" in panel.warnings.text() and "headspace" in panel.warnings.text()
    w.undo_stack.undo()
    qtbot.waitUntil(lambda: w.derived_idle() and panel.warnings.text() == "")


def test_a_neck_bore_too_narrow_is_warned_about(make_window, qtbot):
    from PySide6.QtCore import Qt
    from PySide6.QtWidgets import QDoubleSpinBox
    design, assets = _sample("bordeaux")
    w = make_window(dataclasses.replace(design, liquid=None), assets=assets)
    w.show()
    table = w.section_panel.table
    index = table.model().index(5, 1)  # end r of the neck: the mouth's radius
    table.setCurrentIndex(index)
    table.edit(index)
    editor = table.viewport().findChild(QDoubleSpinBox)
    editor.lineEdit().selectAll()
    qtbot.keyClicks(editor.lineEdit(), "3.44")
    qtbot.keyClick(editor.lineEdit(), Qt.Key_Return)
    qtbot.waitUntil(lambda: w.undo_stack.count() == 1)
    qtbot.waitUntil(lambda: w.derived_idle() and "bore" in w.section_panel.warnings.text())
    assert "0.88 mm across" in w.section_panel.warnings.text()


def test_tint_is_chosen_by_thickness_and_the_thickness_sets_its_strength(make_window):
    w = make_window()
    panel = w.materials_panel
    amber = (0x7A / 255, 0x4F / 255, 0x10 / 255)
    panel.choose_color = lambda rgb, title: amber
    assert panel.glass_thickness.value() == pytest.approx(tint.DEFAULT_THICKNESS_MM)
    panel.glass_tint.click()
    absorption = w.scene.design.glass.absorption
    assert tint.transmittance(absorption, 10.0) == pytest.approx(amber)
    assert tint.transmittance(absorption, 6.0)[2] < 0.25, "two 3 mm walls look amber, not grey"
    panel.glass_thickness.setValue(5.0)  # the same colour through 5 mm: a stronger glass
    stronger = w.scene.design.glass.absorption
    assert stronger == pytest.approx(tuple(2 * a for a in absorption))
    assert panel.glass_tint.text() == "#7a4f10"
    assert w.undo_stack.count() == 2
    w.undo_stack.undo()
    assert w.scene.design.glass.absorption == pytest.approx(absorption)


def test_opening_a_file_fits_the_section_view(make_window, qtbot):
    w = make_window()
    w.resize(1400, 950)
    w.show()
    qtbot.waitExposed(w)
    canvas = w.section_panel.canvas
    canvas.zoom(0.2)  # the designer had zoomed far out
    zoomed_out = canvas.scale
    w.files.open_path(os.path.join(RESOURCES, "jar.glassbench"), ask=False)
    section = w.scene.design.shape.primary
    opened = canvas.scale
    assert opened > 3 * zoomed_out
    top, bottom = canvas.to_px((0.0, section.z_top)).y(), canvas.to_px((0.0, 0.0)).y()
    widest = max(s.p1[0] for s in section.segments)
    left, right = canvas.to_px((-widest, 0.0)).x(), canvas.to_px((widest, 0.0)).x()
    assert 0 < left < right < canvas.width() and 0 < top < bottom <= canvas.height(), "all of it shows"
    assert bottom - top > 0.6 * canvas.height() or right - left > 0.5 * canvas.width(), "and fills it"
    canvas.fit()
    assert canvas.scale == pytest.approx(opened), "opening fitted it"


def test_changing_the_fill_offers_a_name_that_says_it(make_window, qtbot):
    design, assets = _sample("bordeaux")
    w = make_window(design, assets=assets)
    qtbot.waitUntil(w.derived_idle)
    panel = w.trade_panel
    assert panel.offer_box.isHidden() and panel.name.text() == "Bordeaux 750 ml"
    w.materials_panel.fill_value.setValue(500.0)
    qtbot.waitUntil(lambda: w.derived_idle() and panel.offered is not None)
    assert panel.offered == "Bordeaux 500 ml" and not panel.offer_box.isHidden()
    assert "500 ml" in panel.offer_label.text()
    panel.accept_offer.click()
    assert w.scene.design.name == "Bordeaux 500 ml" and panel.name.text() == "Bordeaux 500 ml"
    assert panel.offer_box.isHidden()
    w.undo_stack.undo()
    assert w.scene.design.name == "Bordeaux 750 ml"
    w.materials_panel.fill_value.setValue(600.0)
    qtbot.waitUntil(lambda: w.derived_idle() and panel.offered == "Bordeaux 600 ml")
    panel.keep_name.click()
    assert w.scene.design.name == "Bordeaux 750 ml" and panel.offered is None


def test_the_name_field_renames_as_one_step(make_window, qtbot):
    w = make_window()
    w.trade_panel.name.setText("Flask 330 ml")
    w.trade_panel.name.editingFinished.emit()
    assert w.scene.design.name == "Flask 330 ml" and w.undo_stack.count() == 1


def test_every_control_explains_itself(make_window):
    w = make_window(wireframe=True)
    panels = (w.section_panel, w.materials_panel, w.camera_panel, w.trade_panel)
    missing = []
    for panel in panels:
        widgets = [c for kind in (QAbstractSpinBox, QComboBox, QAbstractButton, QLineEdit)
                   for c in panel.findChildren(kind)]
        for widget in widgets:
            if isinstance(widget, QLineEdit) and isinstance(widget.parent(), (QAbstractSpinBox, QComboBox)):
                continue  # the text field inside a spin box: the spin box explains it
            if isinstance(widget.parent(), QAbstractItemView):
                continue  # the table's corner button
            if not widget.toolTip():
                missing.append(f"{type(panel).__name__}: {type(widget).__name__} {widget.text() if hasattr(widget, 'text') else ''}")
    assert not missing, missing
    assert w.preview.toolTip() and w.wireframe.toolTip() and w.section_panel.table.toolTip()


def test_plain_glassbench_opens_the_last_project_or_else_the_sample(qapp, gui_paths, tiny_design):
    from PySide6.QtCore import QSettings
    from app.document import RecentFiles
    from app.startup import initial_document
    settings = QSettings(str(gui_paths / "recent.ini"), QSettings.IniFormat)
    recent = RecentFiles(settings)
    design, _, path, error = initial_document(None, recent)
    assert path is None and error is None and design.name.startswith("Bordeaux"), "no recent: the sample"
    mine = gui_paths / "mine.glassbench"
    save_project(mine, dataclasses.replace(tiny_design, name="Mine"), {})
    recent.add(str(mine))
    recent.add(str(gui_paths / "gone.glassbench"))  # newest, but deleted since
    design, _, path, error = initial_document(None, recent)
    assert path == str(mine.resolve()) and design.name == "Mine"
    design, _, path, _ = initial_document(None, None)  # --screenshot: never a recent file
    assert path is None


def test_quitting_with_discard_prints_no_error(gui_paths, no_leaks):
    script = textwrap.dedent("""
        import sys
        from PySide6.QtCore import QTimer
        import app.startup as startup
        from app.document import DocumentDialogs
        from engine.model.design import Glass
        DocumentDialogs.ask_unsaved = lambda self: "discard"
        made = startup.MainWindow.__init__
        def init(self, *a, **k):
            made(self, *a, **k)
            def edit_and_quit():
                self.editor.apply("Glass IOR", None, glass=Glass(ior=1.6))
                QTimer.singleShot(100, self.close)
            QTimer.singleShot(300, edit_and_quit)
        startup.MainWindow.__init__ = init
        sys.exit(startup.run(None, None))
    """)
    env = dict(os.environ, XDG_CONFIG_HOME=str(gui_paths / "config"), XDG_DATA_HOME=str(gui_paths / "data"))
    done = subprocess.run([sys.executable, "-c", script], cwd=REPO, env=env, capture_output=True,
                          text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "RuntimeError" not in done.stderr, done.stderr
    assert "already deleted" not in done.stderr, done.stderr
