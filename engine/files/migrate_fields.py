"""Format 2 -> 3 -> 4 -> 5 -> 6: fields added since get the values old projects meant.

Design rule: self-contained steps, :func:`migrate_2_to_3` (fields of labels and bump tiles) and
:func:`migrate_3_to_4` (the stage), :func:`migrate_4_to_5` (the plant's settings) and
:func:`migrate_5_to_6` (the shape's plan outline), registered as
``engine.files.serialize.MIGRATIONS[2]`` to ``[5]``. Format 3 added fields whose default is exactly what a
format-2 project drew, so the step only fills in what is missing, in new dictionaries, and checks
nothing else (the decoder does): an old file opens unchanged, and a glassbench of format 2
refuses a format-3 file with "made by a newer glassbench" instead of "unknown field".
"""
from __future__ import annotations

import dataclasses

from ..model.design import Plant

#: Per list of the design: the fields format 3 added to its items, with their values for a
#: format-2 item (the defaults of :mod:`engine.model.design`).
ADDED = {
    "labels": {"surface": "wall", "cap_x_mm": 0.0, "cap_y_mm": 0.0},
    # a format-2 thread was always drawn as relief (a new tile's default, "auto", may not be)
    "bumps": {"on": "bottle", "geometry": "relief"},
}


def migrate_2_to_3(doc: dict) -> dict:
    """The format-3 document of format-2 ``doc`` (a new dict; ``doc`` is not changed)."""
    design = doc.get("design")
    if not isinstance(design, dict):
        return dict(doc, format_version=3)  # the decoder names what is wrong
    design = dict(design)
    for key, fields in ADDED.items():
        items = design.get(key)
        if isinstance(items, list):
            design[key] = [{**fields, **item} if isinstance(item, dict) else item for item in items]
    return dict(doc, format_version=3, design=design)


def migrate_3_to_4(doc: dict) -> dict:
    """The format-4 document of format-3 ``doc``: format 4 added the stage (what the bottle
    stands on; a format-3 bottle floated in its environment, which is the stage ``none``) and
    the lights' apparent size (a format-3 light was a point: 0 degrees)."""
    design = doc.get("design")
    if not isinstance(design, dict):
        return dict(doc, format_version=4)  # the decoder names what is wrong
    lights = design.get("lights")
    if isinstance(lights, list):
        design = dict(design, lights=[{"angle_deg": 0.0, **x} if isinstance(x, dict) else x for x in lights])
    stage = {"kind": "none", "color": [0.55, 0.55, 0.55], "gloss": 1.0, "backdrop": False, "z_mm": -0.05,
             "half_size_mm": 100000.0}
    return dict(doc, format_version=4, design={"stage": stage, **design})


def migrate_4_to_5(doc: dict) -> dict:
    """The format-5 document of format-4 ``doc``: format 5 added the plant's settings (proof
    pressure, liquid density, closure and label masses, the warning limits); a format-4
    project gets the defaults of :class:`engine.model.design.Plant`."""
    design = doc.get("design")
    if not isinstance(design, dict):
        return dict(doc, format_version=5)  # the decoder names what is wrong
    return dict(doc, format_version=5, design={"plant": dataclasses.asdict(Plant()), **design})


def migrate_5_to_6(doc: dict) -> dict:
    """The format-6 document of format-5 ``doc``: format 6 added the shape's ``plan`` (an
    outline bottle's plan outline); no format-5 bottle had one, so it gets ``null``."""
    design = doc.get("design")
    shape = design.get("shape") if isinstance(design, dict) else None
    if not isinstance(shape, dict):
        return dict(doc, format_version=6)  # the decoder names what is wrong
    return dict(doc, format_version=6, design={**design, "shape": {**shape, "plan": None}})
