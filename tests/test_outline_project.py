"""Outline bottles in the project file (format 6): the plan outline round-trips, a format-5
project opens unchanged, and a hostile plan is one clear line that loses nothing."""
from __future__ import annotations

import copy
import json
import math
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from benchmarks.oracle_spec import spec_to_design
from engine.errors import ProjectError
from engine.files.project import load_project, load_project_bytes, save_project
from engine.files.serialize import CURRENT_FORMAT, design_from_dict, design_from_document, design_to_dict
from engine.geometry.plan import MAX_SEGMENTS, PlanOutline, hexagon
from engine.operations.trade import trade_numbers
from engine.plant.sheet import plant_numbers

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT.parent / "shared" / "oracle" / "specs"


@pytest.fixture(scope="module")
def flask():
    """The hip flask of outline_public_2 (a four-arc plan given in mm, with liquid) and its assets."""
    return spec_to_design(SPECS / "outline_public_2.json")


def _doc(design):
    return {"format_version": CURRENT_FORMAT, "generator": "test", "design": design_to_dict(design)}


def _archive(doc, assets) -> bytes:
    import io
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("project.json", json.dumps(doc))
        for name, data in assets.items():
            z.writestr("assets/" + name, data)
    return buf.getvalue()


def test_an_outline_design_round_trips_through_its_dictionary_and_its_file(flask, tmp_path):
    design, assets = flask
    data = design_to_dict(design)
    plan = data["shape"]["plan"]
    assert [s["type"] for s in plan] == ["arc"] * 4
    assert PlanOutline.from_dicts(plan).scale == 1.0  # stored normalised: core and rounding are the mm
    back = design_from_dict(json.loads(json.dumps(data)))
    assert back == design and back.shape.plan.segments == design.shape.plan.segments  # bit for bit
    save_project(tmp_path / "flask.glassbench", design, assets, keep_backup=False)
    assert load_project(tmp_path / "flask.glassbench") == (design, assets)


def test_every_fixed_kind_writes_a_null_plan_and_a_format_5_project_opens_unchanged(flask):
    design, assets = load_project(ROOT / "resources" / "square.glassbench")
    doc = _doc(design)
    assert doc["design"]["shape"]["plan"] is None
    old = copy.deepcopy(doc)
    old["format_version"] = 5
    del old["design"]["shape"]["plan"]
    assert design_from_document(old) == design
    hostile = dict(old, design={**old["design"], "shape": "not a shape"})
    with pytest.raises(ProjectError, match=r"design\.shape must be an object"):
        design_from_document(hostile)


def _with_plan(design, plan):
    data = design_to_dict(design)
    data["shape"]["plan"] = plan
    return data


def _open_chain(design):
    plan = design_to_dict(design)["shape"]["plan"]
    plan[1]["p0"] = [plan[1]["p0"][0] + 0.1, plan[1]["p0"][1]]
    return plan


@pytest.mark.parametrize("make, says", [
    (_open_chain, r"^design\.shape\.plan: segment 1: starts .* from where segment 0 ends"),
    (lambda d: [dict(s, radius=math.nan) for s in design_to_dict(d)["shape"]["plan"]],
     r"^design\.shape\.plan: segment 0: radius must be a finite number, got nan$"),
    (lambda d: [{"type": "line", "p0": [1.0, 0.0], "p1": [0.0, 1.0]}] * 10 ** 6,
     rf"^design\.shape\.plan has 1000000 items \(limit {MAX_SEGMENTS}\)$"),
    (lambda d: "hexagon", r"^design\.shape\.plan must be a list, got string$"),
    (lambda d: [1, 2, 3], r"^design\.shape\.plan: segment 0: a segment must be an object, got int$"),
    (lambda d: [dict(s, p0="x") for s in design_to_dict(d)["shape"]["plan"]],
     r"^design\.shape\.plan: segment 0: p0 must be two numbers \[x, y\], got 'x'$"),
    (lambda d: None, r"^design\.shape: an outline bottle needs its plan outline"),
])
def test_a_hostile_plan_is_one_clear_line(flask, make, says):
    with pytest.raises(ProjectError, match=says) as info:
        design_from_dict(_with_plan(flask[0], make(flask[0])))
    assert "\n" not in str(info.value)


def test_a_plan_on_a_round_bottle_is_refused():
    design, _ = load_project(ROOT / "resources" / "bordeaux.glassbench")
    with pytest.raises(ProjectError, match="only an outline bottle has one"):
        design_from_dict(_with_plan(design, hexagon().to_dicts()))


def _glassbench(*args):
    return subprocess.run([sys.executable, "-m", "app.main", *map(str, args)], capture_output=True,
                          text=True, cwd=ROOT, timeout=240)


def test_the_command_line_reads_an_outline_project_and_refuses_a_hostile_one_untouched(flask, tmp_path):
    design, assets = flask
    good = tmp_path / "flask.glassbench"
    save_project(good, design, assets, keep_backup=False)
    run = _glassbench("info", good)
    assert run.returncode == 0, run.stderr
    numbers = trade_numbers(design)
    assert f"Brimful capacity      {numbers['brimful_ml']:10.1f} ml" in run.stdout
    assert f"Glass volume          {numbers['glass_volume_cm3']:10.1f} cm3" in run.stdout
    least = plant_numbers(design)["least_tip"]["deg"]
    assert f"{'Least tip angle':<22}{least:10.2f} deg" in run.stdout  # an outline's plant sheet too
    assert "not supported" not in run.stdout
    bad = tmp_path / "open.glassbench"
    bad.write_bytes(_archive({"format_version": CURRENT_FORMAT, "generator": "test",
                              "design": _with_plan(design, _open_chain(design))}, assets))
    before = bad.read_bytes()
    with pytest.raises(ProjectError, match="the chain must be closed"):
        load_project_bytes(before)
    run = _glassbench("info", bad)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and "the chain must be closed" in run.stderr
    assert bad.read_bytes() == before
