"""The labels panel in a real window: add a label from a PNG file, edit it, undo and redo,
reorder, pick key colours with the eyedropper, refuse a corrupt image, show a conical band's
die-line as a sector, and keep it all (images embedded) through save and reopen."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
from PySide6.QtGui import QDropEvent

from tests.label_helpers import artwork, cone_shape, write_image

pytestmark = pytest.mark.usefixtures("no_leaks")


def _two_colour_png(tmp_path, name="two.png"):
    """A 40 x 80 PNG: the left half (200, 30, 30), the right half (20, 180, 90) (sRGB)."""
    px = np.empty((40, 80, 3), np.uint8)
    px[:, :40] = (200, 30, 30)
    px[:, 40:] = (20, 180, 90)
    write_image(tmp_path / name, px)
    return str(tmp_path / name)


def _add(panel, path):
    panel.choose_image_file = lambda title: str(path)
    assert panel.add_button.isEnabled()
    panel.add_button.click()


def test_a_label_from_a_png_is_added_embedded_and_undoable(make_window, tmp_path):
    w = make_window()
    panel = w.labels_panel
    data = artwork(tmp_path, "front.png", size=(40, 80))
    _add(panel, tmp_path / "front.png")
    labels = w.scene.design.labels
    assert len(labels) == 1 and labels[0].name == "front"
    assert w.scene.assets[labels[0].front.asset] == data, "the artwork is embedded as an asset"
    assert labels[0].width_mm == pytest.approx(2 * labels[0].height_mm, abs=0.1), "sized from the aspect"
    assert panel.list.count() == 1 and panel.preview.artwork.pixels is not None
    assert w.undo_action.text().endswith("Add label front")
    w.undo_stack.undo()
    assert w.scene.design.labels == () and labels[0].front.asset not in w.scene.assets
    assert panel.list.count() == 0
    w.undo_stack.redo()
    assert w.scene.design.labels == labels and labels[0].front.asset in w.scene.assets


def test_editing_a_number_is_one_step_and_undo_redo_restore_it(make_window, tmp_path):
    w = make_window()
    panel = w.labels_panel
    artwork(tmp_path, "a.png")
    _add(panel, tmp_path / "a.png")
    z0 = w.scene.design.labels[0].z_mm
    panel.placement.z_mm.setValue(z0 + 12.0)
    assert w.scene.design.labels[0].z_mm == pytest.approx(z0 + 12.0)
    panel.sheet.transmission.setValue(0.12)
    assert w.scene.design.labels[0].transmission == pytest.approx(0.12)
    assert w.undo_stack.count() == 3
    w.undo_stack.undo()
    w.undo_stack.undo()
    assert w.scene.design.labels[0].z_mm == pytest.approx(z0)
    assert panel.placement.z_mm.value() == pytest.approx(z0), "the panel follows the model"
    w.undo_stack.redo()
    assert panel.placement.z_mm.value() == pytest.approx(z0 + 12.0)


def test_a_label_off_the_wall_is_refused_and_the_field_put_back(make_window, tmp_path):
    w = make_window()
    panel = w.labels_panel
    artwork(tmp_path, "a.png")
    _add(panel, tmp_path / "a.png")
    before = w.scene.design
    panel.placement.z_mm.setValue(w.scene.design.shape.z_top + 50.0)
    assert w.scene.design == before
    assert panel.placement.z_mm.value() == pytest.approx(before.labels[0].z_mm)
    assert w.statusBar().currentMessage().startswith("Refused")


def test_labels_reorder_in_the_overlap_order(make_window, tmp_path):
    w = make_window()
    panel = w.labels_panel
    artwork(tmp_path, "first.png")
    artwork(tmp_path, "second.png", colour=(10, 10, 200))
    _add(panel, tmp_path / "first.png")
    _add(panel, tmp_path / "second.png")
    assert [lab.name for lab in w.scene.design.labels] == ["first", "second"]
    assert panel.list.currentRow() == 1
    panel.up_button.click()
    assert [lab.name for lab in w.scene.design.labels] == ["second", "first"]
    assert panel.list.currentRow() == 0 and panel.selection.label.name == "second", "the selection moves along"
    w.undo_stack.undo()
    assert [lab.name for lab in w.scene.design.labels] == ["first", "second"]
    assert [panel.list.item(i).text() for i in range(2)] == ["first", "second"]


def test_the_eyedropper_keys_a_region_to_the_clicked_colour(make_window, tmp_path, qtbot):
    w = make_window()
    panel = w.labels_panel
    _add(panel, _two_colour_png(tmp_path))
    panel.finishes.region_preset.setCurrentIndex(panel.finishes.region_preset.findData("Gold foil"))
    panel.finishes.add_region.click()
    region = w.scene.design.labels[0].regions[0]
    assert region.finish == "gold_foil" and region.gloss == pytest.approx(0.9)
    w.show()
    w.docks["labels"].raise_()
    qtbot.waitUntil(panel.preview.artwork.isVisible)
    panel.finishes.eyedropper.setChecked(True)
    rect = panel.preview.artwork.image_rect()
    right = QPoint(int(rect.x() + 0.8 * rect.width()), int(rect.y() + 0.5 * rect.height()))
    qtbot.mouseClick(panel.preview.artwork, Qt.LeftButton, pos=right)
    keys = w.scene.design.labels[0].regions[0].keys
    assert keys == (pytest.approx((20 / 255, 180 / 255, 90 / 255), abs=1e-6),)
    claimed = panel.preview.artwork.claimed
    assert claimed[:, 40:].all() and not claimed[:, :40].any(), "the keyed half is shown tinted"
    left = QPoint(int(rect.x() + 0.2 * rect.width()), int(rect.y() + 0.5 * rect.height()))
    qtbot.mouseClick(panel.preview.artwork, Qt.LeftButton, Qt.ShiftModifier, pos=left)
    keys = w.scene.design.labels[0].regions[0].keys
    assert len(keys) == 2 and keys[1] == pytest.approx((200 / 255, 30 / 255, 30 / 255), abs=1e-6)
    from engine.appearance.regions import region_map
    regions = region_map(w.scene.design.labels[0], w.scene.assets)
    assert (regions == 1).all(), "both halves are keyed now"
    panel.finishes.eyedropper.setChecked(False)
    count = w.undo_stack.count()
    qtbot.mouseClick(panel.preview.artwork, Qt.LeftButton, pos=right)
    assert w.undo_stack.count() == count, "without the eyedropper a click picks nothing"


def test_a_finish_preset_and_a_mask_region(make_window, tmp_path):
    w = make_window()
    panel = w.labels_panel
    _add(panel, _two_colour_png(tmp_path))
    panel.finishes.add_region.click()
    panel.finishes.region_preset.setCurrentIndex(panel.finishes.region_preset.findData("Emboss 0.3 mm"))
    panel.finishes.apply_preset.click()
    region = w.scene.design.labels[0].regions[0]
    assert (region.finish, region.depth_mm) == ("emboss", pytest.approx(0.3))
    mask = np.full((10, 10, 3), 255, np.uint8)
    mask[:, :5] = 0
    write_image(tmp_path / "mask.png", mask)
    panel.choose_image_file = lambda title: str(tmp_path / "mask.png")
    panel.finishes.source.setCurrentIndex(panel.finishes.source.findData("mask"))
    region = w.scene.design.labels[0].regions[0]
    assert region.source == "mask" and region.mask_asset in w.scene.assets


def test_a_corrupt_or_huge_image_is_refused_with_a_message_and_nothing_changes(make_window, tmp_path):
    w = make_window()
    panel = w.labels_panel
    good = artwork(tmp_path, "good.png")
    (tmp_path / "broken.png").write_bytes(good[: len(good) // 2])
    before, assets = w.scene.design, dict(w.scene.assets)
    _add(panel, tmp_path / "broken.png")
    assert w.scene.design == before and dict(w.scene.assets) == assets
    assert w.undo_stack.count() == 0
    assert "broken.png" in panel.problem.text() and "truncated" in panel.problem.text()
    assert "broken.png" in w.statusBar().currentMessage()
    (tmp_path / "not.png").write_bytes(b"hello, not an image at all")
    _add(panel, tmp_path / "not.png")
    assert w.scene.design == before and "not a PNG" in panel.problem.text()
    (tmp_path / "huge.png").write_bytes(_png_header_only(40000, 30000))
    _add(panel, tmp_path / "huge.png")
    assert w.scene.design == before and dict(w.scene.assets) == assets
    assert "huge.png is 40000 x 30000 pixels" in panel.problem.text()
    assert w.undo_stack.count() == 0


def _png_header_only(width: int, height: int) -> bytes:
    """A PNG whose header claims ``width`` x ``height`` (8-bit RGB) and holds no pixels."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b"")


def test_the_die_line_of_a_label_on_a_cone_is_a_sector(make_window, tiny_design, tmp_path, qtbot):
    design = dataclasses.replace(tiny_design, shape=cone_shape(), liquid=None)
    w = make_window(design)
    panel = w.labels_panel
    artwork(tmp_path, "a.png", size=(40, 40))
    _add(panel, tmp_path / "a.png")
    panel.placement.z_mm.setValue(110.0)
    panel.placement.height_mm.setValue(40.0)
    panel.placement.width_mm.setValue(40.0)
    label = w.scene.design.labels[0]
    assert (label.z_mm, label.height_mm, label.width_mm) == (110.0, 40.0, 40.0)
    qtbot.waitUntil(lambda: not panel.dieline_pending())
    fig = panel.preview.dieline.figures
    assert panel.preview.dieline.kind == "sector"
    # the cone runs r 40 at z 60 to r 20 at z 160: slant L and the apex distance in closed form
    slant = math.hypot(20.0, 100.0)
    apex_to_centre = (20.0 + 0.2 * 50.0) * slant / 20.0  # radius at z 110 over the cone's sine
    assert fig["r_inner_mm"] == pytest.approx(apex_to_centre - 20.0, rel=1e-6)
    assert fig["r_outer_mm"] == pytest.approx(apex_to_centre + 20.0, rel=1e-6)
    assert fig["angle_deg"] == pytest.approx(math.degrees(40.0 / apex_to_centre), rel=1e-6)
    assert panel.preview.dieline.outline is not None and len(panel.preview.dieline.outline) > 8
    panel.placement.z_mm.setValue(60.0)  # now it crosses the joint cylinder -> cone: a shoulder
    assert panel.dieline_pending()
    qtbot.waitUntil(lambda: not panel.dieline_pending())
    assert panel.preview.dieline.kind == "outline"
    assert "shoulder" in panel.preview.warnings.text() or "corner" in panel.preview.warnings.text()
    assert panel.preview.dieline.marks, "the warning is marked on the die-line"


def _with_picture(make_window, qtbot):
    """A shown window whose preview holds a picture (drop and drag points map onto it)."""
    w = make_window()
    w.show()
    qtbot.waitExposed(w)
    qtbot.waitUntil(lambda: w.preview.image_size()[0] > 0)
    return w


def test_an_image_dropped_on_the_preview_becomes_a_label_there(make_window, tmp_path, qtbot):
    w = _with_picture(make_window, qtbot)
    artwork(tmp_path, "drop.png")
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(tmp_path / "drop.png"))])
    rect = w.preview._target_rect()
    # the camera looks at the bottle's middle: the picture's centre lies on the glass, facing it
    centre = QPointF(rect.center())
    event = QDropEvent(centre, Qt.CopyAction, mime, Qt.LeftButton, Qt.NoModifier)
    w.preview.dropEvent(event)
    labels = w.scene.design.labels
    assert len(labels) == 1 and labels[0].name == "drop"
    cam = w.scene.design.camera
    assert labels[0].z_mm == pytest.approx(cam.target[2], abs=15.0)
    facing = math.degrees(math.atan2(cam.eye[1], cam.eye[0]))
    assert abs((labels[0].angle_deg - facing + 180) % 360 - 180) < 5.0


def test_save_and_reopen_keeps_labels_regions_and_images(make_window, tmp_path):
    w = make_window()
    panel = w.labels_panel
    _add(panel, _two_colour_png(tmp_path))
    panel.finishes.add_region.click()
    back = artwork(tmp_path, "back.png", colour=(0, 0, 255))
    panel.choose_image_file = lambda title: str(tmp_path / "back.png")
    panel.sheet.back_image.click()
    panel.placement.width_mm.setValue(70.0)
    design = w.scene.design
    path = str(tmp_path / "labelled.glassbench")
    assert w.files.save_to(path)
    w2 = make_window(path=None)
    assert w2.files.open_path(path, ask=False)
    assert w2.scene.design.labels == design.labels
    lab = w2.scene.design.labels[0]
    assert w2.scene.assets[lab.back.asset] == back
    assert w2.scene.assets[lab.front.asset] == w.scene.assets[lab.front.asset]
    assert w2.labels_panel.list.count() == 1 and w2.labels_panel.placement.width_mm.value() == pytest.approx(70.0)


def test_ctrl_z_in_a_label_field_undoes_the_label_edit(make_window, tmp_path, qtbot):
    w = make_window()
    w.show()
    w.activateWindow()
    qtbot.waitUntil(w.isActiveWindow, timeout=5000)
    w.docks["labels"].raise_()
    panel = w.labels_panel
    artwork(tmp_path, "a.png")
    _add(panel, tmp_path / "a.png")
    spin = panel.placement.width_mm
    qtbot.waitUntil(spin.isVisible)
    before = w.scene.design.labels[0].width_mm
    spin.setFocus()
    qtbot.waitUntil(spin.lineEdit().hasFocus, timeout=5000)
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin.lineEdit(), "55")
    qtbot.keyClick(spin.lineEdit(), Qt.Key_Return)
    assert w.scene.design.labels[0].width_mm == pytest.approx(55.0)
    qtbot.keyClick(spin.lineEdit(), Qt.Key_Z, Qt.ControlModifier)
    assert w.scene.design.labels[0].width_mm == pytest.approx(before)
    assert spin.value() == pytest.approx(before)
    qtbot.keyClick(spin.lineEdit(), Qt.Key_Z, Qt.ControlModifier | Qt.ShiftModifier)
    assert w.scene.design.labels[0].width_mm == pytest.approx(55.0)


def test_shift_drag_on_the_preview_moves_the_selected_label_in_one_step(make_window, tmp_path, qtbot):
    w = _with_picture(make_window, qtbot)
    artwork(tmp_path, "a.png")
    _add(w.labels_panel, tmp_path / "a.png")
    steps = w.undo_stack.count()
    rect = w.preview._target_rect()
    start = QPoint(int(rect.center().x()), int(rect.center().y()))
    end = QPoint(int(rect.center().x() - 0.1 * rect.width()), int(rect.center().y() + 0.08 * rect.height()))
    camera = w.scene.design.camera
    qtbot.mousePress(w.preview, Qt.LeftButton, Qt.ShiftModifier, start)
    qtbot.mouseMove(w.preview, QPoint((start.x() + end.x()) // 2, (start.y() + end.y()) // 2))
    qtbot.mouseMove(w.preview, end)
    qtbot.mouseRelease(w.preview, Qt.LeftButton, Qt.ShiftModifier, end)
    want = w._surface_at(w.preview.image_point(QPointF(end)))
    assert want is not None, "the end point lies on the glass"
    label = w.scene.design.labels[0]
    assert (label.z_mm, label.angle_deg) == (pytest.approx(want[0], abs=0.06), pytest.approx(want[1], abs=0.06))
    assert label.z_mm < camera.target[2], "dragged down the bottle"
    assert w.scene.design.camera == camera, "a Shift+drag does not orbit"
    assert w.undo_stack.count() == steps + 1, "one drag, one step"
    w.undo_stack.undo()
    assert w.scene.design.labels[0].z_mm != label.z_mm


def test_ctrl_shift_drag_sizes_the_selected_label_by_a_corner_in_one_step(make_window, tmp_path, qtbot):
    from engine.appearance.frame import Placement, label_frame

    w = _with_picture(make_window, qtbot)
    artwork(tmp_path, "a.png")
    _add(w.labels_panel, tmp_path / "a.png")
    before = w.scene.design.labels[0]
    steps = w.undo_stack.count()
    rect = w.preview._target_rect()
    start = QPoint(int(rect.center().x()), int(rect.center().y()))
    end = QPoint(int(rect.center().x() + 0.04 * rect.width()), int(rect.center().y() - 0.05 * rect.height()))
    mods = Qt.ShiftModifier | Qt.ControlModifier
    qtbot.mousePress(w.preview, Qt.LeftButton, mods, start)
    qtbot.mouseMove(w.preview, end)
    qtbot.mouseRelease(w.preview, Qt.LeftButton, mods, end)
    corner = w._surface_at(w.preview.image_point(QPointF(end)))
    assert corner is not None, "the corner lies on the glass"
    label = w.scene.design.labels[0]
    want = label_frame(w.scene.design.shape, Placement.of(before)).size_to(*corner)
    assert (label.height_mm, label.width_mm) == (pytest.approx(want[0], abs=0.06), pytest.approx(want[1], abs=0.06))
    assert (label.height_mm, label.width_mm) != (before.height_mm, before.width_mm)
    assert (label.z_mm, label.angle_deg) == (before.z_mm, before.angle_deg), "sizing keeps the centre"
    assert w.undo_stack.count() == steps + 1, "one drag, one step"
    w.undo_stack.undo()
    assert w.scene.design.labels[0] == before


def test_removing_a_label_drops_only_its_own_images(make_window, tiny_design, tmp_path):
    w = make_window(assets={"notes.png": b"kept: not the labels' to drop"})
    panel = w.labels_panel
    artwork(tmp_path, "a.png")
    _add(panel, tmp_path / "a.png")
    asset = w.scene.design.labels[0].front.asset
    panel.remove_button.click()
    assert w.scene.design.labels == ()
    assert asset not in w.scene.assets and "notes.png" in w.scene.assets
    w.undo_stack.undo()
    assert asset in w.scene.assets


def test_a_label_goes_on_the_cap_top_and_skirt_from_the_on_choice_undoably(make_window, tiny_design, tmp_path,
                                                                           qtbot):
    from engine.appearance.cap_surfaces import cap_surface
    from engine.model.design import Cap
    w = make_window(dataclasses.replace(tiny_design, cap=None))
    panel = w.labels_panel
    artwork(tmp_path, "a.png", size=(40, 80))
    _add(panel, tmp_path / "a.png")
    on_wall = w.scene.design
    assert [panel.placement.surface.itemText(i) for i in range(panel.placement.surface.count())] == ["bottle", "cap top", "cap skirt"]
    panel.placement.surface.setCurrentIndex(panel.placement.surface.findData("cap-top"))   # no cap yet: refused
    assert w.scene.design == on_wall and panel.placement.surface.currentData() == "wall"
    assert "has no cap" in panel.problem.text()
    w.editor.apply("Cap", None, cap=Cap("screw", "plastic"))
    panel.placement.surface.setCurrentIndex(panel.placement.surface.findData("cap-top"))
    lab = w.scene.design.labels[0]
    top = cap_surface(w.scene.design, "cap-top")
    assert lab.surface == "cap-top" and (lab.cap_x_mm, lab.cap_y_mm) == (0.0, 0.0)
    assert math.hypot(lab.width_mm, lab.height_mm) <= 2 * top.radius, "shrunk to fit the top"
    assert lab.width_mm / lab.height_mm == pytest.approx(2.0, rel=0.05), "aspect kept"
    assert panel.placement.cap_x_mm.isEnabled() and not panel.placement.z_mm.isEnabled()
    panel.placement.cap_x_mm.setValue(1.5)
    assert w.scene.design.labels[0].cap_x_mm == pytest.approx(1.5)
    qtbot.waitUntil(lambda: not panel.dieline_pending())
    assert "cap's top" in panel.preview.figures.text()
    panel.placement.surface.setCurrentIndex(panel.placement.surface.findData("cap-skirt"))
    lab = w.scene.design.labels[0]
    skirt = cap_surface(w.scene.design, "cap-skirt")
    assert lab.surface == "cap-skirt" and lab.z_mm == pytest.approx(skirt.height_mm / 2, abs=0.01)
    assert panel.placement.z_mm.isEnabled() and not panel.placement.cap_x_mm.isEnabled()
    w.undo_stack.undo()
    w.undo_stack.undo()
    assert w.scene.design.labels[0].surface == "cap-top" and panel.placement.surface.currentData() == "cap-top"
    w.undo_stack.undo()
    assert w.scene.design.labels == on_wall.labels and panel.placement.surface.currentData() == "wall"


def test_a_part_needs_only_the_editor_and_the_selected_label(qtbot, tmp_path):
    """The labels panel's parts take the editor and the selected label (a small observable),
    never the panel: a placement box made alone shows the selected label and edits it as one
    undoable step, and no part's source names a panel."""
    import ast
    import inspect

    from PySide6.QtGui import QUndoStack

    from app.commands import DesignEditor
    from engine.model.scene import Scene
    from engine.operations import labels as ops
    from tests.label_helpers import cylinder_shape, design_with
    from widgets.labels import placement, preview, regions, sheet
    from widgets.labels.selection import SelectedLabel
    for module in (placement, preview, regions, sheet):
        tree = ast.parse(inspect.getsource(module))
        names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        names |= {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)}
        names |= {n.arg for n in ast.walk(tree) if isinstance(n, ast.arg)}
        assert "panel" not in names, f"{module.__name__} reaches into the panel"
    edit = ops.add_label(design_with(cylinder_shape()), {}, artwork(tmp_path, "a.png"), filename="a.png")
    stack = QUndoStack()
    editor = DesignEditor(Scene(edit.design, dict(edit.assets)), stack)
    selection = SelectedLabel(editor)
    box = placement.PlacementBox(editor, selection)
    qtbot.addWidget(box)
    assert selection.index == -1 and selection.label is None
    with qtbot.waitSignal(selection.changed):
        selection.select(0)
    box.show_label(selection.label)
    z0 = selection.label.z_mm
    box.z_mm.setValue(z0 + 10.0)
    assert editor.design.labels[0].z_mm == pytest.approx(z0 + 10.0) and stack.count() == 1
    assert selection.label == editor.design.labels[0], "the selected label is the design's, never stale"
    with qtbot.waitSignal(selection.problem) as said:
        box.surface.setCurrentIndex(box.surface.findData("cap-top"))  # no cap: refused before the editor
    assert said.args[0] and box.surface.currentData() == "wall" and stack.count() == 1
    stack.undo()
    assert editor.design.labels[0].z_mm == pytest.approx(z0)
