"""glassbench export-cad: solids read back by OpenCascade are valid, closed and hold the volumes
``glassbench info`` reports, on every bundled sample; the rounded square's fitted surfaces lie
within the tolerance of the exact walls; formats, names and refusals."""
from __future__ import annotations

import json

import pytest

from engine import cli
from engine.export.cad import VOLUME_RTOL, export_cad
from engine.export.cad_check import is_closed, read_solids, volume_mm3
from tests.export_helpers import SAMPLES, bspline_face_points, load, wall_distance


def info_json(capsys, project) -> dict:
    """What ``glassbench info --json`` prints for ``project``."""
    assert cli.main(["info", str(project), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("project", SAMPLES, ids=lambda p: p.stem)
def test_step_solids_match_info_on_every_sample(project, tmp_path, capsys):
    numbers = info_json(capsys, project)
    out = tmp_path / "bottle.step"
    assert cli.main(["export-cad", str(project), str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    solids = dict(read_solids(out))  # read back by OpenCascade, not the shapes in memory
    from OCP.BRepCheck import BRepCheck_Analyzer
    for name, solid in solids.items():
        assert BRepCheck_Analyzer(solid).IsValid(), name
        assert is_closed(solid), name
    glass = volume_mm3(solids["glass"]) / 1000.0
    assert abs(glass - numbers["glass_volume_cm3"]) <= VOLUME_RTOL * numbers["glass_volume_cm3"]
    if numbers["fill_ml"] is not None:
        liquid = volume_mm3(solids["liquid"]) / 1000.0
        assert abs(liquid - numbers["fill_ml"]) <= VOLUME_RTOL * numbers["fill_ml"]
    closures = [n for n in solids if n.startswith("closure")]
    assert bool(closures) == (numbers["closure"] is not None)
    for n in closures:
        assert volume_mm3(solids[n]) > 0


@pytest.mark.parametrize("suffix", [".iges", ".brep", ".stp"])
@pytest.mark.parametrize("name", ["bordeaux.glassbench", "square.glassbench"])
def test_other_formats_read_back_with_the_same_volumes(name, suffix, tmp_path):
    design, _ = load(name)
    report = export_cad(design, tmp_path / f"b{suffix}")
    assert [b["name"] for b in report["bodies"]] == ["glass", "liquid"]
    for body in report["bodies"]:
        assert body["valid"] and body["closed"]
        assert body["relative_error"] <= VOLUME_RTOL
    names = [n for n, _ in read_solids(tmp_path / f"b{suffix}")]
    assert names == (["", ""] if suffix == ".brep" else ["glass", "liquid"])


def test_round_bottles_are_exact_surfaces(tmp_path):
    """Lines and arcs revolve into planes, cones, cylinders, tori and spheres (or surfaces of
    revolution of an exact line or circle): no B-spline anywhere."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_CurveType as C
    from OCP.GeomAbs import GeomAbs_SurfaceType as T
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    design, _ = load("bordeaux.glassbench")
    export_cad(design, tmp_path / "b.step")
    kinds = set()
    for _, solid in read_solids(tmp_path / "b.step"):
        it = TopExp_Explorer(solid, TopAbs_ShapeEnum.TopAbs_FACE)
        while it.More():
            surface = BRepAdaptor_Surface(TopoDS.Face(it.Current()))
            kinds.add(surface.GetType())
            if surface.GetType() == T.GeomAbs_SurfaceOfRevolution:
                assert surface.BasisCurve().GetType() in (C.GeomAbs_Line, C.GeomAbs_Circle)
            it.Next()
    assert kinds <= {T.GeomAbs_Plane, T.GeomAbs_Cylinder, T.GeomAbs_Cone, T.GeomAbs_Torus,
                     T.GeomAbs_Sphere, T.GeomAbs_SurfaceOfRevolution}
    assert T.GeomAbs_Torus in kinds and T.GeomAbs_Cylinder in kinds


def test_rounded_square_within_its_tolerance(tmp_path):
    """Every point of the read-back walls lies within the stated tolerance of an exact wall
    (distance by the wall's implicit function, first order: |g| / |grad g|)."""
    design, _ = load("square.glassbench")
    tol = 0.001
    report = export_cad(design, tmp_path / "sq.step", tol)
    assert 0 < report["bodies"][0]["deviation_mm"] <= tol
    glass = dict(read_solids(tmp_path / "sq.step"))["glass"]
    pts = bspline_face_points(glass)
    assert len(pts) > 1000
    assert float(wall_distance(design.shape, pts).max()) <= tol


def test_no_liquid_option_and_bad_names(tmp_path, capsys):
    project = SAMPLES[0]
    out = tmp_path / "glass.step"
    assert cli.main(["export-cad", str(project), str(out), "--no-liquid"]) == 0
    assert [n for n, _ in read_solids(out)] == ["glass"]
    assert cli.main(["export-cad", str(project), str(tmp_path / "x.obj")]) == 2
    assert "unknown CAD format" in capsys.readouterr().err
    assert not (tmp_path / "x.obj").exists()
    assert cli.main(["export-cad", str(project), str(out), "--tol", "0"]) == 2
    assert "--tol" in capsys.readouterr().err


def test_a_failed_check_writes_nothing(tmp_path, monkeypatch):
    """A solid whose read-back volume is off is refused and the old file stays as it was."""
    from engine.export import cad
    from engine.export.occ_profile import CadError
    design, _ = load("jar.glassbench")
    out = tmp_path / "jar.step"
    out.write_text("the old file")
    real = cad.glass_bodies

    def off(*args, **kwargs):
        import dataclasses
        bodies = real(*args, **kwargs)
        return [dataclasses.replace(bodies[0], expected_mm3=bodies[0].expected_mm3 * 1.001)] + bodies[1:]
    monkeypatch.setattr(cad, "glass_bodies", off)
    with pytest.raises(CadError, match="glass's volume"):
        export_cad(design, out)
    assert out.read_text() == "the old file"
    assert [p.name for p in tmp_path.iterdir()] == ["jar.step"]
