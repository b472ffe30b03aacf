"""The final image engine behind the dialog (bad requests refused up front, a failed write
reported and leaving nothing behind, the time-left estimate) and the terminal progress bar."""
from __future__ import annotations

import os

import pytest

from engine.batch.progress import TerminalProgress
from engine.batch.still import FinalRender, time_left_s
from engine.files.project import load_project

BORDEAUX = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources",
                        "bordeaux.glassbench")


def test_bad_requests_are_refused_before_rendering(tmp_path):
    design, assets = load_project(BORDEAUX)
    with pytest.raises(ValueError, match="must end in .png, .exr or .tif"):
        FinalRender(design, assets, str(tmp_path / "x.jpg"), width=8, height=8, spp=1)
    with pytest.raises(ValueError, match="does not exist"):
        FinalRender(design, assets, str(tmp_path / "nope" / "x.png"), width=8, height=8, spp=1)
    with pytest.raises(ValueError, match="width = 0"):
        FinalRender(design, assets, str(tmp_path / "x.png"), width=0, height=8, spp=1)


def test_a_write_that_fails_is_reported_and_leaves_nothing(tmp_path):
    design, assets = load_project(BORDEAUX)
    (tmp_path / "final.png").mkdir()  # the name is taken by a folder: the rename must fail
    ended = []
    render = FinalRender(design, assets, str(tmp_path / "final.png"), width=16, height=20, spp=1,
                         on_done=ended.append).start()
    assert render.wait(60)
    assert render.state == "failed" and isinstance(render.error, OSError)
    assert ended == [render] and not render.written and render.progress < 1.0
    assert os.listdir(tmp_path) == ["final.png"] and os.listdir(tmp_path / "final.png") == []


def test_time_left_extrapolates_once_there_is_something_to_go_on():
    assert time_left_s(0.1, 0.5) is None
    assert time_left_s(10.0, 0.01) is None
    assert time_left_s(10.0, 0.25) == pytest.approx(30.0)
    assert time_left_s(3.0, 1.0) == 0.0


def test_the_terminal_bar_counts_frames_and_tiles_and_ignores_late_events():
    import io

    from rich.console import Console
    buf = io.StringIO()
    bar = TerminalProgress(console=Console(file=buf, width=120, force_terminal=False))
    bar.start(total=2, skipped=3)
    bar.frame_progress("a.png", 0.5, 4)
    bar.frame_done("a.png", 1.0, "w")
    bar.frame_progress("a.png", 0.2, 9)  # late event of a finished frame
    bar.frame_progress("b.png", 0.5, 3)
    assert bar.bar.tasks[0].completed == pytest.approx(1.5)
    bar.frame_done("b.png", 1.0, "w")
    bar.finish()
    text = buf.getvalue()
    assert "3 frame(s) already done" in text
    assert "2/2 frames" in text and "7 tiles" in text
