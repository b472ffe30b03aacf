"""The trade numbers of a design: what a glassmaker quotes and a filler checks.

Design rule: one function, :func:`trade_numbers`, gives every number ``glassbench info``, the
batch summary and the window show: brimful and fill capacity (ml), fill height and fill point
below the top (mm), glass volume (cm^3) and mass (g), height and largest diameter (mm), the
closure (kind, diameter and height, mm) and the overall height with it on. It
reads the geometry through :mod:`engine.geometry.capacity` and the liquid's level through
:mod:`engine.model.fill` (the one volume -> height), so no caller resolves either itself.
Strictly (the command line: a number that cannot be computed is an error) or tolerantly (the
window, while a design is being edited: that number is ``None``, the others still show).
"""
from __future__ import annotations

import contextlib

from ..errors import GlassbenchError
from ..geometry import capacity
from ..model import fill

#: The keys of :func:`trade_numbers` that are numbers (``name`` is the design's name).
NUMBER_KEYS = ("brimful_ml", "fill_ml", "fill_height_mm", "fill_point_below_top_mm",
               "glass_volume_cm3", "glass_mass_g", "height_mm", "max_diameter_mm",
               "overall_height_mm")
#: ``(key, label, unit)`` of each number in ``glassbench info``'s table.
INFO_ROWS = (("brimful_ml", "Brimful capacity", "ml"), ("fill_ml", "Fill volume", "ml"),
             ("fill_height_mm", "Fill height", "mm"),
             ("fill_point_below_top_mm", "Fill point below top", "mm"),
             ("glass_volume_cm3", "Glass volume", "cm3"), ("glass_mass_g", "Glass mass", "g"),
             ("height_mm", "Height", "mm"), ("max_diameter_mm", "Max diameter", "mm"),
             ("overall_height_mm", "Overall height", "mm"))


def trade_numbers(design, tolerant: bool = False) -> dict:
    """The numbers ``glassbench info`` reports (ml, mm, cm^3, g); fill values ``None`` if empty.

    ``fill_ml``/``fill_height_mm`` follow the liquid's fill mode: a height is converted to
    the volume below it, a volume to the height that holds it (:mod:`engine.model.fill`).
    Raises the geometry's errors for an invalid shape and ``DesignError`` for a liquid that
    does not fit, unless ``tolerant``: then each number that cannot be computed is ``None``.
    ``closure`` is ``None`` or ``{"kind", "diameter_mm", "height_mm"}`` and
    ``overall_height_mm`` the height with the closure on
    (:func:`engine.appearance.closures.closure_trade`).
    """
    from ..appearance.closures import closure_trade  # why: appearance reads the model, not back
    shape, liquid = design.shape, design.liquid
    out = {"name": design.name, **dict.fromkeys(NUMBER_KEYS)}

    def put(key, fn, *args):
        if not tolerant:
            out[key] = float(fn(*args))
            return
        with contextlib.suppress(GlassbenchError, ValueError, ArithmeticError):
            out[key] = float(fn(*args))  # why: one number that fails must not hide the others

    put("brimful_ml", capacity.brimful_ml, shape)
    put("glass_volume_cm3", capacity.glass_volume_cm3, shape)
    put("glass_mass_g", capacity.glass_mass_g, shape, design.glass.density_g_cm3)
    put("height_mm", capacity.height_mm, shape)
    put("max_diameter_mm", capacity.max_diameter_mm, shape)
    if liquid is not None:
        put("fill_height_mm", fill.fill_height_mm, shape, liquid)
        put("fill_ml", fill.fill_volume_ml, shape, liquid)
        if out["fill_height_mm"] is not None:
            out["fill_point_below_top_mm"] = float(shape.z_top - out["fill_height_mm"])
    out["closure"] = None
    if tolerant:
        with contextlib.suppress(GlassbenchError, ValueError, ArithmeticError):
            out["closure"], out["overall_height_mm"] = closure_trade(design)
    else:
        out["closure"], out["overall_height_mm"] = closure_trade(design)
    return out


def format_table(numbers: dict) -> str:
    """The trade numbers as an aligned, human-readable table (``glassbench info``)."""
    lines = [f"{numbers.get('name', '')}".strip() or "Design"]
    for key, label, unit in INFO_ROWS:
        v = numbers.get(key)
        text = "-" if v is None else f"{v:10.1f} {unit}"
        lines.append(f"  {label:<22}{text}")
    closure = numbers.get("closure")
    if closure:
        lines.append(f"  {'Closure':<22}{closure['kind']}, {closure['diameter_mm']:.1f} mm across, "
                     f"{closure['height_mm']:.1f} mm high")
    return "\n".join(lines)
