"""Finish optics and the presets designers pick from: sheets, foils, films, relief, varnish.

Design rule: plain data. :data:`FOIL_OPTICS` gives the complex refractive index ``n + i k`` of
the metal foils per RGB channel at 660, 549 and 451 nm (the Johnson & Christy 1972 rows at
1.88, 2.26 and 2.75 eV), for the tracer's conductor Fresnel term. :data:`SHEET_PRESETS` are
coefficient sets of a whole label (``diffuse``, ``specular``, ``transmission``), and
:data:`FINISH_PRESETS` finish regions waiting for their keys or mask: the panel offers both by
name, ``glassbench label add`` uses the default sheet. The kernels number the finish kinds
(:data:`engine.tracer.kernels.labels.FINISH_CODES`).
"""
from __future__ import annotations

import dataclasses

from ..model.design import FinishRegion

#: ``(n (r, g, b), k (r, g, b))`` of each metal foil (Johnson & Christy 1972).
FOIL_OPTICS = {
    "gold_foil": ((0.14, 0.43, 1.38), (3.697, 2.455, 1.914)),
    "silver_foil": ((0.05, 0.06, 0.04), (4.483, 3.586, 2.657)),
}
#: Refractive index of clear vinyl film and of a varnish or coat layer.
FILM_IOR = 1.54
COAT_IOR = 1.5
#: Reflectance (linear RGB) of the white underprint of ``clear_vinyl_white``.
WHITE_UNDERPRINT = (0.85, 0.85, 0.85)

#: Whole-sheet coefficient sets: ``(diffuse, specular, transmission)``.
SHEET_PRESETS = {
    "Paper (uncoated)": (0.80, 0.02, 0.15),
    "Paper (coated)": (0.85, 0.05, 0.10),
    "Paper (thick card)": (0.88, 0.04, 0.02),
    "White film": (0.85, 0.10, 0.05),
    "Clear film": (0.05, 0.10, 0.0),
}
DEFAULT_SHEET = "Paper (coated)"

#: Finish regions by name (source, keys and mask filled in by the designer).
FINISH_PRESETS = {
    "Gold foil": FinishRegion("gold foil", "gold_foil", gloss=0.9),
    "Silver foil": FinishRegion("silver foil", "silver_foil", gloss=0.9),
    "Brushed gold": FinishRegion("brushed gold", "gold_foil", gloss=0.5),
    "Clear vinyl": FinishRegion("clear", "clear_vinyl", gloss=1.0),
    "Clear vinyl, white underprint": FinishRegion("clear white", "clear_vinyl_white", gloss=1.0),
    "Emboss 0.3 mm": FinishRegion("emboss", "emboss", depth_mm=0.3, gloss=0.3),
    "Deboss 0.2 mm": FinishRegion("deboss", "emboss", depth_mm=-0.2, gloss=0.3),
    "Gloss varnish": FinishRegion("gloss varnish", "varnish", gloss=0.95),
    "Matte varnish": FinishRegion("matte varnish", "varnish", gloss=0.2),
}


def finish_preset(name: str, **changes) -> FinishRegion:
    """The region of preset ``name`` with ``changes`` (``keys=...``, ``source="mask"`` ...)."""
    return dataclasses.replace(FINISH_PRESETS[name], **changes)


def preset_of(region: FinishRegion) -> str | None:
    """The name of the finish preset ``region`` follows (finish, depth, gloss), or ``None``."""
    for name, p in FINISH_PRESETS.items():
        if (p.finish, p.depth_mm, p.gloss) == (region.finish, region.depth_mm, region.gloss):
            return name
    return None
