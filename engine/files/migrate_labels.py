"""Format 1 -> format 2 of ``project.json``: placeholder labels become real labels.

Design rule: one self-contained function of plain JSON data, registered as
``engine.files.serialize.MIGRATIONS[1]``. It writes the format-2 label literally (never from
today's dataclasses), so later formats can migrate on from it. Format 1 labels were
placeholders, ``{"name": str, "asset": str | null}``, never placed or rendered; format 2 gives
each one its artwork as the front face and a placement on the lower body that any valid bottle
can carry: centre at 35 % of the height, 20 % of the height tall, at most half the smallest
radius of the first section above 20 % of the height wide (a quarter of any girth there),
facing -y (the default camera). Everything else in the document is kept as it is.
"""
from __future__ import annotations

from ..errors import ProjectError, shown

#: Face of a migrated label without artwork, and its back: white paper (linear RGB).
WHITE = [1.0, 1.0, 1.0]


def migrate_1_to_2(doc: dict) -> dict:
    """The format-2 document for a format-1 ``doc`` (``ProjectError`` for a malformed label)."""
    design = doc.get("design")
    if not isinstance(design, dict):
        raise ProjectError("project.json.design must be an object")
    labels = design.get("labels")
    if not isinstance(labels, list):
        raise ProjectError("project.json.design.labels must be a list")
    placement = _placement(design.get("shape"))
    new = []
    for i, old in enumerate(labels):
        if not isinstance(old, dict) or set(old) != {"name", "asset"}:
            raise ProjectError(f"design.labels[{i}] is not a format-1 label "
                               f"(an object of name and asset), got {shown(old)}")
        new.append({"name": old["name"], "front": {"asset": old["asset"], "color": list(WHITE)},
                    "back": {"asset": None, "color": list(WHITE)}, **placement,
                    "diffuse": 0.85, "specular": 0.05, "transmission": 0.1, "regions": []})
    out = {k: v for k, v in doc.items() if k != "format_version"}
    return {"format_version": 2, **out, "design": {**design, "labels": new}}


def _placement(shape) -> dict:
    """Centre height, height, width (mm) and azimuth of a migrated label on ``shape`` (format-1
    JSON); a shape too malformed to read gives the smallest label, for the checks to judge."""
    try:
        section = next(iter(shape["sections"].values()))["segments"]
        z_top = float(section[-1]["p1"][1])
        ends = [seg[k] for seg in section for k in ("p0", "p1")]
        radii = [float(p[0]) for p in ends if float(p[1]) >= 0.2 * z_top and float(p[0]) > 0]
        r_min = min(radii)
    except (KeyError, TypeError, ValueError, IndexError, StopIteration, AttributeError, OverflowError):
        return {"z_mm": 1.0, "angle_deg": -90.0, "height_mm": 1.0, "width_mm": 1.0}
    return {"z_mm": 0.35 * z_top, "angle_deg": -90.0, "height_mm": max(1.0, 0.2 * z_top),
            "width_mm": max(1.0, min(0.2 * z_top, 0.5 * r_min))}
