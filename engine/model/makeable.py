"""Warnings for a design that is valid geometry but cannot be made or filled as drawn.

Design rule: validation (:mod:`engine.geometry.validate`, :mod:`engine.model.fill`) refuses what
is not a bottle at all; this module says, without refusing, what a glassworks or a filling line
would send back: a neck bore too narrow to form or to fill through, glass too thin to blow, a
liquid with no headspace left below the brim. :func:`design_warnings` returns the texts in
designer's words (mm), the most serious first; an empty list means nothing to say. The limits
are the module's constants, so the window and the command line warn alike.
"""
from __future__ import annotations

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
    return 2.0 * (shape.primary.r_top - wall)


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
        out.append(f"The neck's bore is {max(bore, 0.0):.2f} mm across (a {shape.primary.r_top:.2f} mm "
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
