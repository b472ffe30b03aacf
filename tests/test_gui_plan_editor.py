"""The plan editor panel on the hexagonal flacon (outline_public_1): presets and undo, a corner
rounded and its radius typed, a concave drag refused with the plan kept, the across-flats number
of the flacon's note, one undo step per drag, and the panel disabled on a round bottle."""
from __future__ import annotations

import dataclasses
import math
import os

import pytest

from benchmarks.oracle_spec import spec_to_design
from engine.geometry.editing import Handle
from engine.geometry.plan_widths import widest_core

SPEC = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "oracle", "specs", "outline_public_1.json")


@pytest.fixture
def flacon_window(make_window, qtbot):
    w = make_window()
    # why: these tests edit the plan, not the picture: a preview render of every edit would only
    # compete for the cores (and a job caught compiling may outlive the window's shutdown)
    w.render_controller.cancel()
    w.render_controller.hold(True, live=False)
    design, assets = spec_to_design(SPEC)
    design = dataclasses.replace(design, render=dataclasses.replace(design.render, width=24, height=24, spp=1))
    w.files.replace_document(design, assets, None)
    qtbot.waitUntil(lambda: w.plan_panel.model.rowCount() == 6, timeout=10000)
    yield w
    qtbot.waitUntil(w.derived_idle, timeout=60000)


def kinds(w):
    return [s.kind for s in w.scene.design.shape.plan.segments]


def test_a_preset_replaces_the_outline_and_undo_brings_it_back(flacon_window, qtbot):
    w = flacon_window
    panel = w.plan_panel
    assert panel.body.isEnabled() and not panel.reason.isVisible()
    k = widest_core(w.scene.design.shape).k
    panel.preset_buttons["octagon"].click()
    qtbot.waitUntil(lambda: panel.model.rowCount() == 8)
    assert kinds(w) == ["line"] * 8
    assert w.undo_stack.undoText() == "Plan outline: octagon preset"
    assert widest_core(w.scene.design.shape).k == pytest.approx(k), "the core stays"
    w.undo_stack.undo()
    qtbot.waitUntil(lambda: panel.model.rowCount() == 6)
    assert kinds(w) == ["line"] * 6


def test_a_corner_is_rounded_and_its_radius_typed(flacon_window, qtbot):
    w = flacon_window
    panel = w.plan_panel
    panel.canvas.select(2)  # the line after the sharp corner at joint 2
    assert panel.round_button.isEnabled() and not panel.round_button.isChecked()
    panel.round_button.click()
    qtbot.waitUntil(lambda: panel.model.rowCount() == 7)
    assert w.undo_stack.undoText() == "Round plan corner"
    assert kinds(w)[2] == "arc"
    panel.canvas.select(2)
    assert panel.round_button.isChecked()
    model = panel.model
    assert model.setData(model.index(2, 7), 5.0)
    shape = w.scene.design.shape
    k = widest_core(shape).k
    qtbot.waitUntil(lambda: abs(w.scene.design.shape.plan.segments[2].radius * widest_core(
        w.scene.design.shape).k - 5.0) < 1e-9)
    assert model.data(model.index(2, 7)) == "5.00"
    assert shape.plan.segments[2].radius * k == pytest.approx(5.0, abs=1e-9)
    assert w.undo_stack.undoText() == "Edit plan radius of segment 2"
    assert not panel.message.text()


def test_a_drag_that_would_make_the_plan_concave_is_refused_and_the_plan_kept(flacon_window, qtbot):
    w = flacon_window
    panel, canvas = w.plan_panel, w.plan_panel.canvas
    before, count = w.scene.design.shape, w.undo_stack.count()
    k = panel.core.k
    with qtbot.waitSignal(canvas.problem, timeout=5000) as blocker:
        canvas.begin_drag(Handle("joint", 0, (k, 0.0)), "plan-joint-0#test-concave")
        canvas.drag_to((0.3 * k, 0.0))  # inside the line joining its neighbours (x = k / 2)
        canvas.end_drag()
    assert "not convex" in blocker.args[0]
    assert "not convex" in panel.message.text()
    assert w.scene.design.shape == before and w.undo_stack.count() == count


def test_a_drag_is_one_undo_step_and_keeps_the_other_joints(flacon_window, qtbot):
    w = flacon_window
    canvas = w.plan_panel.canvas
    k = w.plan_panel.core.k
    others = [(p[0] * k, p[1] * k) for p in (s.p0 for s in w.scene.design.shape.plan.segments[1:])]
    count = w.undo_stack.count()
    canvas.begin_drag(Handle("joint", 0, (k, 0.0)), "plan-joint-0#test-merge")
    for x in (1.02, 1.05, 1.08):
        canvas.drag_to((x * k, 0.0))
    canvas.end_drag()
    assert w.undo_stack.count() == count + 1 and w.undo_stack.undoText() == "Move plan joint"
    shape = w.scene.design.shape
    k2 = widest_core(shape).k
    assert (shape.plan.segments[0].p0[0] * k2, shape.plan.segments[0].p0[1] * k2) == pytest.approx((1.08 * k, 0.0))
    after = [(p[0] * k2, p[1] * k2) for p in (s.p0 for s in shape.plan.segments[1:])]
    assert np_close(after, others)


def np_close(a, b, tol=1e-9):
    return all(math.dist(p, q) <= tol for p, q in zip(a, b)) and len(a) == len(b)


def test_the_across_flats_number_is_the_hexagons_closed_form(flacon_window):
    panel = flacon_window.plan_panel
    k, c = panel.core.k, panel.core.c
    assert panel.widths.flats == pytest.approx(2 * k * math.cos(math.pi / 6) + 2 * c, rel=1e-12)
    assert panel.widths.flats == pytest.approx(60.0, abs=1e-9)  # the flacon's note: 60 mm across flats
    assert panel.widths.corners == pytest.approx(2 * k + 2 * c, rel=1e-12)
    assert "Across flats 60.00 mm" in panel.numbers.text()


def test_the_panel_is_disabled_with_a_reason_on_a_round_bottle(make_window):
    w = make_window()
    panel = w.plan_panel
    assert w.scene.design.shape.cross_section == "round"
    assert not panel.body.isEnabled()
    assert "round" in panel.reason.text() and not panel.reason.isHidden()
    assert panel.model.rowCount() == 0
    assert not panel.apply_preset("hexagon") and w.undo_stack.count() == 0


def test_the_segment_table_is_a_well_behaved_item_model(flacon_window, qtmodeltester):
    qtmodeltester.check(flacon_window.plan_panel.model)
