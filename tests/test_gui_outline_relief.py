"""Relief on an outline bottle from the window (issue 41 with the girth frame): a designer adds
a knurl band to the hexagonal flacon from the Bump tiles panel; the preview renders the knurled
flacon without error, and undo takes the band off again."""
from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtCore import Qt

from engine.files.project import load_project

RESOURCES = Path(__file__).resolve().parents[1] / "resources"
pytestmark = pytest.mark.usefixtures("no_leaks")


def test_a_knurl_band_added_to_the_flacon_renders_and_undoes(make_window, qtbot):
    design, assets = load_project(RESOURCES / "flacon.glassbench")
    assert design.shape.cross_section == "outline" and not design.bumps
    w = make_window(design, assets=assets)
    rc, panel = w.render_controller, w.bumps_panel
    panel.add_kind.setCurrentIndex(panel.add_kind.findData("knurl"))
    qtbot.mouseClick(panel.add_button, Qt.LeftButton)
    bumps = w.scene.design.bumps
    assert [b.kind for b in bumps] == ["knurl"] and not w.render_state.text().startswith("Error")
    shown = []
    rc.tileReady.connect(lambda g, *rest: shown.append(g))
    qtbot.waitUntil(lambda: rc.job is not None and rc.job.design.bumps == bumps
                    and rc.generation in shown, timeout=300_000)
    assert rc.job.error is None
    w.undo_stack.undo()
    assert w.scene.design.bumps == ()
    qtbot.waitUntil(lambda: rc.job is not None and rc.job.design.bumps == (), timeout=60_000)
