"""What the window tells a designer about a valid design without refusing it.

Design rule: validation (:mod:`engine.geometry.validate`, :mod:`engine.model.fill`) refuses what
is not a bottle at all; this module only advises, in designer's words (mm, ml), and never
changes the design itself.

* **Warnings** (:func:`design_warnings`): what a glassworks or a filling line would send back,
  the most serious first: a neck bore too narrow to form or to fill through, glass too thin to
  blow, a liquid with no headspace left below the brim. The limits are the module's constants,
  so the window and the command line warn alike.
* **A name that states the fill** (:func:`updated_name`): a name may quote the bottle's nominal
  volume in ml, cl or l (``750 ml``, ``75cl``, ``0.75 l``). When the fill moves away from it,
  the name with the new volume in the same unit and style, which the window *offers*; a name
  without a volume, or whose volume matches the fill to :data:`MATCH_TOLERANCE`, is left alone.
"""
from __future__ import annotations

import re

from ..errors import GlassbenchError
from . import fill

#: Narrowest bore (mm across) a plunger can form and a filling nozzle can enter.
MIN_BORE_MM = 4.0
#: Thinnest glass wall (mm) a bottle is blown with reliably.
MIN_WALL_MM = 1.0
#: Least headspace (mm from the liquid's surface to the brim) a filled bottle needs for the
#: filler's nozzle and the liquid's thermal expansion.
MIN_HEADSPACE_MM = 5.0


def bore_mm(shape) -> float:
    """The neck's bore (mm across) at the mouth: twice the mouth radius less the finish's wall."""
    wall = shape.wall_thickness
    if shape.wall_per_segment:
        wall = shape.wall_per_segment[-1]
    return 2.0 * (shape.r_mouth - wall)


def design_warnings(design, fill_height_mm: float | None = None) -> list[str]:
    """What about ``design`` a glassworks or a filler would refuse, in words (mm).

    Parameters
    ----------
    design : Design
        A design whose shape is valid (an invalid shape gives no warnings: validation speaks).
    fill_height_mm : float, optional
        The liquid's level (mm above z = 0) when the caller knows it already; computed here
        (:func:`engine.model.fill.fill_height_mm`) otherwise.
    """
    shape = design.shape
    out = []
    bore = bore_mm(shape)
    if bore < MIN_BORE_MM:
        wall = shape.wall_per_segment[-1] if shape.wall_per_segment else shape.wall_thickness
        out.append(f"The neck's bore is {max(bore, 0.0):.2f} mm across (a {shape.r_mouth:.2f} mm "
                   f"mouth radius less the {wall:g} mm wall, twice): at least {MIN_BORE_MM:g} mm are "
                   f"needed to form the bore and to fill through it.")
    walls = list(shape.wall_per_segment or ()) + [shape.wall_thickness]
    if min(walls) < MIN_WALL_MM:
        out.append(f"A {min(walls):g} mm wall is thinner than the {MIN_WALL_MM:g} mm glass can be "
                   f"blown with reliably.")
    if design.liquid is not None:
        if fill_height_mm is None:
            try:
                fill_height_mm = fill.fill_height_mm(shape, design.liquid)
            except (GlassbenchError, ValueError, ArithmeticError):
                return out
        headspace = shape.z_top - fill_height_mm
        if headspace < 0:
            out.insert(0, f"The fill line ({fill_height_mm:.1f} mm) is {-headspace:.1f} mm above the "
                          f"brim ({shape.z_top:.1f} mm): the bottle cannot hold it.")
        elif headspace < MIN_HEADSPACE_MM:
            where = "at the brim" if headspace < 0.05 else f"{headspace:.1f} mm below the brim"
            out.insert(0, f"The liquid stands {where} ({fill_height_mm:.1f} mm): a filled bottle "
                          f"needs at least {MIN_HEADSPACE_MM:g} mm of headspace to be filled "
                          f"and closed.")
    return out


# ------------------------------------------------------------------- names and volumes
#: A volume in a name: a number and a unit, not part of a longer word or number.
VOLUME = re.compile(r"(?<![\w.,])(\d+(?:[.,]\d+)?)(\s*)(ml|cl|l)(?!\w)", re.IGNORECASE)
_ML_PER = {"ml": 1.0, "cl": 10.0, "l": 1000.0}
#: Relative difference (and at least 0.5 ml) below which a quoted volume matches the fill.
MATCH_TOLERANCE = 0.005


def volume_in_name(name: str) -> float | None:
    """The volume (ml) the name quotes, or ``None`` (the last volume when it quotes several)."""
    found = list(VOLUME.finditer(name))
    if not found:
        return None
    m = found[-1]
    return float(m.group(1).replace(",", ".")) * _ML_PER[m.group(3).lower()]


def _format(ml: float, unit: str, decimal_comma: bool) -> str:
    value = ml / _ML_PER[unit.lower()]
    digits = 0 if unit.lower() == "ml" and value >= 10 else 1 if unit.lower() != "l" else 2
    text = f"{value:.{digits}f}".rstrip("0").rstrip(".") if digits else f"{value:.0f}"
    return text.replace(".", ",") if decimal_comma else text


def updated_name(name: str, fill_ml: float) -> str | None:
    """``name`` with its quoted volume replaced by ``fill_ml`` (same unit and style), or
    ``None`` when it quotes no volume or already quotes this one."""
    found = list(VOLUME.finditer(name))
    if not found or not fill_ml > 0:
        return None
    m = found[-1]
    quoted = volume_in_name(name)
    if abs(quoted - fill_ml) <= max(MATCH_TOLERANCE * fill_ml, 0.5):
        return None
    number = _format(fill_ml, m.group(3), "," in m.group(1))
    new = f"{name[:m.start()]}{number}{m.group(2)}{m.group(3)}{name[m.end():]}"
    return None if new == name else new
