"""Glass and liquid colour as glassmakers specify it: the transmittance through a thickness.

Design rule: the model stores Beer-Lambert absorption per RGB channel (``Glass.absorption``,
``Liquid.absorption``, 1/mm), which is what the tracer needs and what the project file holds;
a designer states a colour as the transmittance of white light through a reference thickness
("this amber, seen through 10 mm of glass"). The two convert exactly,
``T = exp(-absorption * thickness)``, here and nowhere else. A transmittance of 0 is clipped to
:data:`MIN_TRANSMITTANCE` (absorption stays finite).
"""
from __future__ import annotations

import math

#: The thickness (mm) a tint is given through unless the designer chooses another.
DEFAULT_THICKNESS_MM = 10.0
#: The darkest transmittance a channel may have (absorption stays finite).
MIN_TRANSMITTANCE = 1e-4


def absorption_from_transmittance(rgb, thickness_mm: float = DEFAULT_THICKNESS_MM) -> tuple[float, float, float]:
    """Absorption (1/mm per channel) of a material that lets ``rgb`` (0..1 per channel) of white
    light through ``thickness_mm`` millimetres."""
    if not thickness_mm > 0:
        raise ValueError(f"a tint is given through a positive thickness, got {thickness_mm!r} mm")
    return tuple(-math.log(min(max(float(c), MIN_TRANSMITTANCE), 1.0)) / thickness_mm for c in rgb)


def transmittance(absorption, thickness_mm: float = DEFAULT_THICKNESS_MM) -> tuple[float, float, float]:
    """The share of white light (0..1 per channel) that ``thickness_mm`` mm of a material with
    ``absorption`` (1/mm) lets through."""
    return tuple(math.exp(-float(a) * thickness_mm) for a in absorption)
