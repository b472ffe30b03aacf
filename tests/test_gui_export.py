"""File > Export > CAD / glTF scene / Review page, driven through the real menu actions: the
options and the target come from replaceable dialogs, the export runs on a worker thread with
a progress bar, a refusal is a clear error dialog, and nothing is half written."""
from __future__ import annotations

import pytest

from engine.export.cad import VOLUME_RTOL
from engine.export.cad_check import read_solids, volume_mm3
from engine.export.web import validate_glb
from engine.operations.trade import trade_numbers
from tests.export_helpers import load

pytestmark = pytest.mark.usefixtures("no_leaks")

#: Longest an export may take in these tests (ms): the review page renders a poster.
EXPORT_MS = 180_000


class FakeOptions:
    """Answers the export options dialog; records which kinds were asked."""

    def __init__(self, **options):
        self.options = options
        self.asked = []

    def ask_options(self, kind):
        self.asked.append(kind)
        return None if self.options.get("cancel") else dict(self.options)


def export_action(w, kind):
    """The File > Export menu's action of ``kind``, found through the menu bar."""
    file_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&File")
    export = next(a.menu() for a in file_menu.actions() if a.menu() and "xport" in a.text())
    act = w.files.exports.actions[kind]
    assert act in export.actions()
    return act


def run_export(qtbot, w, kind, path, **options):
    """Trigger the menu action and wait for the export to end; ``(ok, message, progress)``."""
    exports = w.files.exports
    exports.dialogs = FakeOptions(**options)
    w.dialogs.save_path = str(path)
    seen = []
    exports.progressed.connect(lambda f, m: seen.append(f))
    with qtbot.waitSignal(exports.finished, timeout=EXPORT_MS) as blocker:
        export_action(w, kind).trigger()
        assert exports.bar.isVisible() or exports.thread is not None
    assert exports.dialogs.asked == [kind]
    assert not exports.bar.isVisible()
    return blocker.args[0], blocker.args[1], seen


def test_cad_from_the_menu(make_window, qtbot, tmp_path):
    design, assets = load("knurled_jar.glassbench")
    w = make_window(design, assets=assets)
    out = tmp_path / "jar.step"
    ok, message, progress = run_export(qtbot, w, "cad", out, tol_mm=0.001, liquid=True)
    assert ok and str(out) in message and w.dialogs.errors == []
    assert progress and progress[-1] == 1.0 and progress == sorted(progress)
    solids = dict(read_solids(out))
    assert sorted(solids) == ["closure shell", "glass", "liquid"]
    numbers = trade_numbers(design)
    assert volume_mm3(solids["glass"]) / 1000 == pytest.approx(numbers["glass_volume_cm3"], rel=VOLUME_RTOL)
    assert volume_mm3(solids["liquid"]) / 1000 == pytest.approx(numbers["fill_ml"], rel=VOLUME_RTOL)


def test_scene_from_the_menu(make_window, qtbot, tmp_path):
    design, assets = load("labelled.glassbench")
    w = make_window(design, assets=assets)
    out = tmp_path / "scene.glb"
    ok, _, _ = run_export(qtbot, w, "scene", out, tol_mm=0.1)
    assert ok and w.dialogs.errors == []
    report = validate_glb(out)
    assert (report["errors"], report["warnings"]) == (0, 0)


def test_review_page_from_the_menu(make_window, qtbot, tmp_path):
    design, assets = load("jar.glassbench")
    w = make_window(design, assets=assets)
    out = tmp_path / "review"
    ok, _, progress = run_export(qtbot, w, "review", out, tol_mm=0.1, poster_height=16, turntable="",
                                 denoise=False)
    assert ok and w.dialogs.errors == []
    assert {"index.html", "scene.glb", "poster.png", "numbers.json",
            "model-viewer-umd.min.js"} <= {p.name for p in out.iterdir()}
    assert "poster.raw.png" not in {p.name for p in out.iterdir()}
    assert len(progress) >= 3


def test_the_review_dialogs_denoise_box_reaches_the_page(make_window, qtbot, tmp_path):
    from app.export_actions import ExportOptionsDialog
    from engine.files.images import image_description
    dialog = ExportOptionsDialog("review")
    qtbot.addWidget(dialog)
    assert dialog.fields["denoise"].isChecked() is False, "off unless asked"
    dialog.fields["denoise"].setChecked(True)
    dialog.fields["poster_height"].setValue(16)
    options = dialog.values()
    assert options["denoise"] is True
    design, assets = load("jar.glassbench")
    w = make_window(design, assets=assets)
    out = tmp_path / "review"
    ok, _, _ = run_export(qtbot, w, "review", out, **options)
    assert ok and w.dialogs.errors == []
    assert image_description(out / "poster.raw.png").startswith("glassbench: raw render")
    assert image_description(out / "poster.png").startswith(
        "glassbench: denoised estimate of the raw render poster.raw.png")
    assert '<a href="poster.raw.png">' in (out / "index.html").read_text()


def test_a_refused_export_says_why_and_keeps_the_old_file(make_window, qtbot, tmp_path):
    """A rounded square cannot be fitted to 1e-6 mm: the kernel's refusal is shown as it is and
    the file from before stays whole."""
    design, assets = load("square.glassbench")
    w = make_window(design, assets=assets)
    folder = tmp_path / "out"  # (tmp_path itself holds the window's settings)
    folder.mkdir()
    out = folder / "square.step"
    out.write_text("the CAD file from before")
    ok, message, _ = run_export(qtbot, w, "cad", out, tol_mm=1e-6, liquid=False)
    assert not ok
    (title, text), = w.dialogs.errors
    assert title == "Cannot export CAD"
    assert "cannot be fitted within 1e-06 mm" in text and "coarser tolerance" in text
    assert out.read_text() == "the CAD file from before"
    assert [p.name for p in folder.iterdir()] == ["square.step"]


def test_cancel_writes_nothing_and_one_export_at_a_time(make_window, qtbot, tmp_path):
    w = make_window()
    exports = w.files.exports
    exports.dialogs = FakeOptions(cancel=True)
    export_action(w, "scene").trigger()
    assert exports.thread is None and "save" not in w.dialogs.asked
    folder = tmp_path / "out"
    folder.mkdir()
    exports.dialogs = FakeOptions(tol_mm=0.2)
    w.dialogs.save_path = str(folder / "a.glb")
    with qtbot.waitSignal(exports.finished, timeout=EXPORT_MS):
        export_action(w, "scene").trigger()
        assert not exports.start("scene", str(folder / "b.glb"), {"tol_mm": 0.2})
        assert w.dialogs.errors[0][0] == "Export already running"
    assert [p.name for p in folder.iterdir()] == ["a.glb"]


@pytest.mark.parametrize("kind", ["cad", "scene", "review"])
def test_the_options_dialog_offers_the_command_lines_options(qtbot, kind):
    from app.export_actions import DEFAULTS, ExportOptionsDialog
    dialog = ExportOptionsDialog(kind)
    qtbot.addWidget(dialog)
    values = dialog.values()
    assert values.keys() == DEFAULTS[kind].keys()
    for key, default in DEFAULTS[kind].items():
        assert values[key] == (pytest.approx(default) if isinstance(default, float) else default)
    dialog.fields["tol_mm"].setValue(0.02)
    assert dialog.values()["tol_mm"] == pytest.approx(0.02)
    if kind == "cad":
        dialog.fields["liquid"].setChecked(False)
        assert dialog.values()["liquid"] is False
    if kind == "review":
        dialog.fields["turntable"].setText(" /tmp/frames ")
        assert dialog.values()["turntable"] == "/tmp/frames"
