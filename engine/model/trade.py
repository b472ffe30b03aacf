"""The trade numbers of a design: what a glassmaker quotes and a filler checks.

Design rule: one function, :func:`trade_numbers`, gives every number ``glassbench info``, the
batch summary and the window show: brimful and fill capacity (ml), fill height and fill point
below the top (mm), glass volume (cm^3) and mass (g), height and largest diameter (mm). It
reads the geometry through :mod:`engine.geometry.capacity` and the liquid's level through
:mod:`engine.model.fill` (the one volume -> height), so no caller resolves either itself.
"""
from __future__ import annotations

from ..geometry import capacity
from . import fill

#: The keys of :func:`trade_numbers` that are numbers (``name`` is the design's name).
NUMBER_KEYS = ("brimful_ml", "fill_ml", "fill_height_mm", "fill_point_below_top_mm",
               "glass_volume_cm3", "glass_mass_g", "height_mm", "max_diameter_mm")


def trade_numbers(design) -> dict:
    """The numbers ``glassbench info`` reports (ml, mm, cm^3, g); fill values ``None`` if empty.

    ``fill_ml``/``fill_height_mm`` follow the liquid's fill mode: a height is converted to
    the volume below it, a volume to the height that holds it (:mod:`engine.model.fill`).
    Raises the geometry's errors for an invalid shape and ``DesignError`` for a liquid that
    does not fit.
    """
    shape = design.shape
    out = {"name": design.name,
           "brimful_ml": capacity.brimful_ml(shape),
           "fill_ml": None, "fill_height_mm": None, "fill_point_below_top_mm": None,
           "glass_volume_cm3": capacity.glass_volume_cm3(shape),
           "glass_mass_g": capacity.glass_mass_g(shape, design.glass.density_g_cm3),
           "height_mm": capacity.height_mm(shape),
           "max_diameter_mm": capacity.max_diameter_mm(shape)}
    if design.liquid is not None:
        height = fill.fill_height_mm(shape, design.liquid)
        out.update(fill_ml=fill.fill_volume_ml(shape, design.liquid), fill_height_mm=height,
                   fill_point_below_top_mm=float(shape.z_top - height))
    return {k: (float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v)
            for k, v in out.items()}
