"""Format 1 -> 2: bump tiles and the closure become real values.

Design rule: one self-contained step, :func:`migrate_1_to_2`, registered as
``engine.files.serialize.MIGRATIONS[1]``; it rewrites only ``design.bumps`` and ``design.cap``
of a format-1 document and checks nothing else (the decoder does). Format 1 held placeholders:
a bump tile was ``{"name": str, "kind": str}`` and a cap ``{"height": mm}``. A placeholder tile
keeps its name and kind (an unknown kind becomes ``"frosted"``, the placeholder's default) and
covers the whole height of the bottle; a placeholder cap becomes a plastic screw cap of that
height. Anything already in the new layout is left as it is.
"""
from __future__ import annotations

from ..errors import ProjectError

#: The format-2 layout of a bump tile, with the values a placeholder gets.
TILE_DEFAULTS = {"name": "bump", "kind": "frosted", "z0": 0.0, "z1": 10.0, "repeat": 24,
                 "depth": 0.3, "angle_deg": 0.0, "pitch": 0.0, "width": 0.5, "sharpness": 0.7,
                 "alpha": 0.2, "finish": "", "asset": None, "width_deg": 360.0, "inverted": False}
#: The format-2 layout of a cap.
CAP_DEFAULTS = {"kind": "screw", "material": "plastic", "color": [0.9, 0.9, 0.88], "height": 0.0,
                "count": 0, "capsule": True}
_KINDS = ("knurl", "stipple", "flutes", "facets", "diamond", "thread", "frosted", "height_map",
          "colour_code", "normal_gl", "normal_dx", "emboss")


def _top(design: dict) -> float:
    """Height of the mouth (mm) from a format-1 shape, or 10 mm if it cannot be read."""
    try:
        sections = design["shape"]["sections"]
        first = next(iter(sections.values()))
        top = float(first["segments"][-1]["p1"][1])
        return top if top > 0.0 else 10.0
    except (KeyError, TypeError, ValueError, IndexError, StopIteration, AttributeError):
        return 10.0


def migrate_1_to_2(doc: dict) -> dict:
    """The format-2 document of format-1 ``doc`` (a new dict; ``doc`` is not changed)."""
    design = doc.get("design")
    if not isinstance(design, dict):
        raise ProjectError("project.json lacks its design object")
    design = dict(design)
    bumps = design.get("bumps", [])
    if isinstance(bumps, list):
        new = []
        for tile in bumps:
            if isinstance(tile, dict) and set(tile) <= {"name", "kind"}:
                kind = tile.get("kind", "frosted")
                tile = dict(TILE_DEFAULTS, name=tile.get("name", "bump"), z1=_top(design),
                            kind=kind if kind in _KINDS else "frosted")
            new.append(tile)
        design["bumps"] = new
    cap = design.get("cap")
    if isinstance(cap, dict) and set(cap) <= {"height"}:
        design["cap"] = dict(CAP_DEFAULTS, height=cap.get("height", 0.0))
    return {**doc, "format_version": 2, "design": design}
