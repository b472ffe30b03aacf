"""Issue 26, item 4: a Materials edit and a Bump-tile edit on the heavy relief samples (the cut
decanter, the knurled jar) reach "converged" in the real window. No time is asserted here (the
times are ``benchmarks.window_converge``'s); what is asserted is that each edit starts a render
of the edited design and that the window ends it converged, with no error."""
from __future__ import annotations

from pathlib import Path

import pytest

from engine.files.project import load_project

RESOURCES = Path(__file__).resolve().parents[1] / "resources"
pytestmark = pytest.mark.usefixtures("no_leaks")


def _converged(qtbot, w, design_check):
    rc = w.render_controller
    qtbot.waitUntil(lambda: rc.ended_generation == rc.generation and rc.job is not None
                    and design_check(rc.job.design), timeout=600_000)
    assert rc.job.error is None and rc.job.done
    qtbot.waitUntil(lambda: w.render_state.text().startswith("Converged"), timeout=10_000)
    # it names the share of pixels the sample cap stopped above the tolerance, when there are any
    assert ("at the sample cap" in w.render_state.text()) == (rc.job.capped > 0)
    return rc.job


@pytest.mark.parametrize("sample", ["cut_decanter", "knurled_jar"])
def test_a_materials_and_a_bump_tile_edit_on_relief_converge_in_the_window(make_window, qtbot, sample):
    design, assets = load_project(RESOURCES / f"{sample}.glassbench")
    assert design.bumps, "a relief sample"
    w = make_window(design, assets=assets)
    first = _converged(qtbot, w, lambda d: d == design)
    # a Materials edit: the glass's index, through the panel's own control
    ior = round(design.glass.ior + 0.02, 4)
    w.materials_panel.glass_ior.setValue(ior)
    assert w.scene.design.glass.ior == ior
    job = _converged(qtbot, w, lambda d: d.glass.ior == ior)
    assert job is not first and job.stats.rays_cast > 0
    # a Bump-tile edit: the first tile's depth
    w.bumps_panel.list.setCurrentRow(0)
    depth = round(w.scene.design.bumps[0].depth * 0.8, 3)
    w.bumps_panel.depth_mm.setValue(depth)
    assert w.scene.design.bumps[0].depth == pytest.approx(depth)
    job = _converged(qtbot, w, lambda d: d.bumps[0].depth == pytest.approx(depth))
    assert job.stats.rays_cast > 0
