"""Labels as project values: exact round trip, the format-1 migration, value and placement
checks with messages that name the field."""
from __future__ import annotations

import dataclasses
import json

import pytest

from engine.errors import DesignError, ProjectError
from engine.files.migrate_labels import migrate_1_to_2
from engine.files.project import check_design, load_project, save_project
from engine.files.serialize import CURRENT_FORMAT, MIGRATIONS, design_from_document, design_to_dict
from engine.model.check import check_values
from engine.model.design import FinishRegion, Label, LabelSide
from tests.label_helpers import cylinder_shape, design_with, prism_shape

ASSETS = {"front.png": b"\x89PNG front", "back.jpg": b"\xff\xd8\xff back", "foil mask.png": b"\x89PNG m"}


def full_label(**changes) -> Label:
    label = Label("front", LabelSide("front.png", (0.9, 0.8, 0.7)), LabelSide("back.jpg"),
                  z_mm=80.0 + 1 / 3, angle_deg=-75.5, height_mm=60.0, width_mm=100.0,
                  diffuse=0.7, specular=0.2, transmission=0.3,
                  regions=(FinishRegion("gold", "gold_foil", "chroma", ((1.0, 0.8, 0.0), (0.9, 0.7, 0.1)), 0.12),
                           FinishRegion("relief", "emboss", "mask", (), 0.1, "foil mask.png", -0.25, 0.4)))
    return dataclasses.replace(label, **changes)


def test_a_labelled_design_round_trips_exactly(tmp_path):
    design = design_with(cylinder_shape(), full_label(), Label("plain", z_mm=150.0, angle_deg=90.0))
    save_project(tmp_path / "p.glassbench", design, ASSETS)
    loaded, assets = load_project(tmp_path / "p.glassbench")
    assert loaded == design and assets == ASSETS
    assert loaded.labels[0].regions[0].keys == ((1.0, 0.8, 0.0), (0.9, 0.7, 0.1))
    assert loaded.labels[1].front == LabelSide(None, (1.0, 1.0, 1.0))


def test_the_migration_turns_format_1_placeholders_into_placed_labels(tmp_path):
    assert CURRENT_FORMAT >= 2  # format 1 is read through every later step
    design = design_with(cylinder_shape(r=30.0, top=150.0))
    doc1 = {"format_version": 1, "generator": "glassbench 0.1.0", "design": design_to_dict(design)}
    doc1["design"]["labels"] = [{"name": "front", "asset": "front.png"}, {"name": "neck", "asset": None}]
    migrated = migrate_1_to_2(json.loads(json.dumps(doc1)))
    assert MIGRATIONS[1](json.loads(json.dumps(doc1))) == migrated  # the registered step
    assert migrated["format_version"] == 2 and migrated["generator"] == "glassbench 0.1.0"
    new = design_from_document(doc1)
    front, neck = new.labels
    assert front.front.asset == "front.png" and neck.front.asset is None
    assert (front.z_mm, front.height_mm, front.width_mm) == pytest.approx((52.5, 30.0, 15.0))
    check_design(new, {"front.png": b"\x89PNG"})  # the migrated labels lie on the wall
    doc1["design"]["labels"] = [{"name": "front", "file": "x.png"}]
    with pytest.raises(ProjectError, match=r"design.labels\[0\] is not a format-1 label"):
        design_from_document(doc1)


@pytest.mark.parametrize("changes, message", [
    ({"width_mm": 0.5}, r"design.labels\[0\].width_mm = 0.5 is outside 1..2000 mm"),
    ({"z_mm": float("nan")}, r"design.labels\[0\].z_mm = nan"),
    ({"diffuse": 0.9, "transmission": 0.2}, "diffuse 0.9 \\+ transmission 0.2 is more than 1"),
    ({"front": LabelSide(None, (1.5, 0.0, 0.0))}, r"design.labels\[0\].front.color\[0\] = 1.5"),
    ({"regions": (FinishRegion(keys=()),)}, r"regions\[0\] keys by colour but has no key colours"),
    ({"regions": (FinishRegion(finish="glitter", keys=((1, 1, 1),)),)}, "finish must be one of gold_foil"),
    ({"regions": (FinishRegion(source="mask"),)}, "takes its shape from a mask image but names none"),
    ({"regions": (FinishRegion(keys=((1, 1, 1),), depth_mm=5.0),)}, r"depth_mm = 5.0 is outside -2..2 mm"),
    ({"name": "  "}, "name is empty"),
])
def test_label_values_are_checked_with_the_field_named(changes, message):
    with pytest.raises(DesignError, match=message):
        check_values(design_with(cylinder_shape(), full_label(**changes)))


def test_label_names_must_differ():
    with pytest.raises(DesignError, match=r"labels\[1\].name 'front' is already the name of design.labels\[0\]"):
        check_values(design_with(cylinder_shape(), full_label(), full_label(z_mm=150.0)))


@pytest.mark.parametrize("shape, changes, message", [
    (cylinder_shape(), {"z_mm": 190.0}, r"labels\[0\] \('front'\) reaches above the mouth"),
    (cylinder_shape(), {"z_mm": 20.0}, "reaches below the standing ring"),
    (cylinder_shape(), {"width_mm": 252.0}, "is 252 mm wide but the girth at z = 80.3333 mm is 251.3 mm"),
    (cylinder_shape(), {"z_mm": 250.0}, "its centre z = 250 mm is not on the wall"),
    (prism_shape(), {"z_mm": 175.0}, "reaches above the mouth"),
    (prism_shape(), {"width_mm": 230.0}, "a label wraps at most once around"),
])
def test_a_label_off_the_wall_is_refused_on_save(tmp_path, shape, changes, message):
    design = design_with(shape, full_label(**changes))
    with pytest.raises(DesignError, match=message):
        save_project(tmp_path / "p.glassbench", design, ASSETS)
    assert not (tmp_path / "p.glassbench").exists()


def test_every_image_a_label_names_must_be_in_the_project():
    design = design_with(cylinder_shape(), full_label())
    for missing in ASSETS:
        assets = {k: v for k, v in ASSETS.items() if k != missing}
        with pytest.raises(ProjectError, match=f"names asset '{missing}', which the project lacks"):
            check_design(design, assets)
