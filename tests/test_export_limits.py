"""Where the export methods could fail (issue 28): a 0.5 mm wall, a punt meeting the standing
ring tangentially, an ellipse arc of axis ratio 1 : 20, a label across the 360 degree seam, no
liquid, no labels, a closure over a 1 km-radius arc, and 4,096 labels (the list limit: the
exports succeed in bounded time and memory and say so)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import pytest

from engine.export.cad import VOLUME_RTOL, export_cad
from engine.export.cad_check import read_solids, volume_mm3
from engine.export.gltf_scene import export_scene
from engine.export.share import write_share
from engine.export.web import check_page, validate_glb
from engine.files.project import save_project
from engine.operations.check import check_design
from engine.operations.trade import trade_numbers
from tests.export_helpers import EDGE_CASES, many_labels, no_liquid
from tests.peak_memory import REPORT_AT_EXIT

#: Bounds for the 4,096-label exports, each in a process of its own (s, bytes of peak memory).
MANY_SECONDS, MANY_BYTES = 240.0, 2 << 30


@pytest.mark.parametrize("case", sorted(EDGE_CASES))
def test_cad_and_scene_at_the_edges(case, tmp_path):
    design, assets = EDGE_CASES[case]()
    check_design(design, assets)  # a design the engine accepts, not a broken one
    numbers = trade_numbers(design)
    report = export_cad(design, tmp_path / "b.step")
    solids = dict(read_solids(tmp_path / "b.step"))
    assert set(solids) == {b["name"] for b in report["bodies"]}
    assert volume_mm3(solids["glass"]) / 1000 == pytest.approx(numbers["glass_volume_cm3"], rel=VOLUME_RTOL)
    if numbers["fill_ml"] is None:
        assert "liquid" not in solids
    else:
        assert volume_mm3(solids["liquid"]) / 1000 == pytest.approx(numbers["fill_ml"], rel=VOLUME_RTOL)
    assert all(b["valid"] and b["closed"] for b in report["bodies"])
    export_scene(design, assets, tmp_path / "s.glb", 0.05)
    validated = validate_glb(tmp_path / "s.glb")
    assert (validated["errors"], validated["warnings"]) == (0, 0), validated["messages"]


def test_the_ellipse_is_exact_and_its_offset_within_tolerance(tmp_path):
    """The 1 : 20 ellipse arc stays an ellipse in the CAD file; the inner wall's offset of it
    is a B-spline whose measured distance from the exact offset is within a tenth of 0.001 mm."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_CurveType as C
    from OCP.GeomAbs import GeomAbs_SurfaceType as T
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    design, _ = EDGE_CASES["ellipse_1_20"]()
    report = export_cad(design, tmp_path / "e.step", 0.001)
    assert 0 < report["bodies"][0]["deviation_mm"] <= 1e-4
    curves = []
    it = TopExp_Explorer(dict(read_solids(tmp_path / "e.step"))["glass"], TopAbs_ShapeEnum.TopAbs_FACE)
    while it.More():
        s = BRepAdaptor_Surface(TopoDS.Face(it.Current()))
        if s.GetType() == T.GeomAbs_SurfaceOfRevolution:
            curves.append(s.BasisCurve().GetType())
        it.Next()
    assert C.GeomAbs_Ellipse in curves and C.GeomAbs_BSplineCurve in curves


def test_a_page_without_liquid_shows_no_fill(tmp_path):
    design, assets = no_liquid()
    out = write_share(design, assets, tmp_path / "r", poster_height=16)
    report = check_page(out / "index.html", tmp_path / "shot.png")
    assert report["loaded"] and report["console_errors"] == [] and report["page_errors"] == []
    assert report["numbers"]["fill_ml"] is None and report["shown"]["fill_ml"] == "null"
    assert report["numbers"] == json.loads((out / "numbers.json").read_text())


def _child(code: str) -> tuple[subprocess.CompletedProcess, float, int]:
    """Run ``code`` in a fresh Python; its result, wall time (s) and its own peak memory (bytes).

    The peak is the child's ``VmHWM`` written as it exits (:mod:`tests.peak_memory`), not any
    ``ru_maxrss``: those keep the pytest process's high-water mark, which failed this test on CI
    at 2.07 and 2.23 GiB while the export alone peaks at 0.22 GiB.
    """
    with tempfile.TemporaryDirectory() as scratch:
        peak_file = os.path.join(scratch, "peak")
        env = dict(os.environ, GLASSBENCH_PEAK_FILE=peak_file)
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", REPORT_AT_EXIT + code], capture_output=True,
                              text=True, env=env, timeout=600)  # a hung export fails, not hangs CI
        seconds = time.perf_counter() - t0
        peak = int(open(peak_file).read()) if os.path.exists(peak_file) else -1
    assert peak > 0, f"the child did not report its peak memory: {done.stderr}"
    return done, seconds, peak


def test_4096_labels_export_in_bounded_time_and_memory(tmp_path):
    design, assets = many_labels(4096)
    project = tmp_path / "many.glassbench"
    save_project(project, design, assets)  # the list limit: the project is valid and saves
    scene = tmp_path / "many.glb"
    done, seconds, peak = _child(f"from engine import cli; raise SystemExit(cli.main("
                                 f"['export-scene', {str(project)!r}, {str(scene)!r}]))")
    assert done.returncode == 0, done.stderr
    assert "4096 labels" in done.stdout and "wrote" in done.stdout  # says that it succeeded
    assert seconds < MANY_SECONDS and peak < MANY_BYTES
    assert (validate_glb(scene)["errors"], validate_glb(scene)["warnings"]) == (0, 0)
    page = tmp_path / "page"
    done, seconds, peak = _child(f"from engine import cli; raise SystemExit(cli.main("
                                 f"['share', {str(project)!r}, '-o', {str(page)!r}, '--poster-height', '16']))")
    assert done.returncode == 0, done.stderr
    assert seconds < MANY_SECONDS and peak < MANY_BYTES
    assert len(list((page / "dielines").iterdir())) == 64  # one per distinct flat shape (row)
    assert (page / "index.html").read_text().count("and 61 more") == 64  # 64 rows of 64 labels
