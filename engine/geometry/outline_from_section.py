"""An outline bottle from a designer's two drawings: a half front view and a plan (top view).

Design rule: the section ``r(z)`` (mm) is the right half of the bottle's front view, drawn as for
a round bottle, so ``r(z)`` is how far the bottle reaches along the plan's ``+x`` at height
``z``; the plan ``P`` is the body's top view with the axis at its origin. The bottle's outer
section is ``O(z) = k(z) P (+) disc(c(z))`` (SPEC_outline 4) with

    c(z) = r_m + (C - r_m) (r(z) - r_m) / (R - r_m)          (the corners' rounding)
    k(z) = (r(z) - c(z)) / h_x                                (the core)

where ``R`` is the section's widest radius, ``r_m`` its mouth radius, ``C`` the rounding at the
widest height and ``h_x`` the normalised plan's reach along ``+x`` (its support value there).
So ``O(z)`` reaches exactly ``r(z)`` along ``+x`` at every height: the front view is the drawn
section. The rounding is ``C`` where the body is widest and changes in proportion as the section
narrows, to the mouth radius where the section reaches it; there ``k = 0`` and the neck is round.
Both profiles are affine images of the section's wall (:func:`~engine.geometry.editing.curves.
mapped_radially`), so they are exact lines, arcs and ellipse arcs with the drawing's tangencies
and corners. An outline bottle stands on a flat base: the section's base part (a punt) is
replaced by a flat base from the axis to its standing ring.

The section may nowhere be narrower than its mouth (the core would be negative), must be wider
than its mouth somewhere, and ``0 < C < R``. :func:`size_mismatch` compares the plan's drawn
size with the section's (both drawings of one bottle must agree). Whether the result is a valid
bottle (its cavity, its wall) is :mod:`engine.geometry.validate`'s business. No Qt; mm.
"""
from __future__ import annotations

import dataclasses
import math

from ..errors import OutlineError, SectionError
from .editing.curves import mapped_radially
from .offset import split_at_ring
from .plan import PlanOutline
from .section import Section
from .segments import Line, POINT_TOL_MM
from .shape import BottleShape
from .validate import r_max, r_min

#: Default rounding (mm) of the plan's corners at the body's widest height: a sharp glass edge
#: cannot be blown, and 3 mm equals the default wall, so the cavity's corners are just sharp.
DEFAULT_ROUND_MM = 3.0
#: How far (relative) the plan's drawn reach along +x may differ from the section's widest radius.
SIZE_TOL = 0.01


def widest_radius(section: Section) -> float:
    """The section's largest radius (mm) on its wall (standing ring to mouth)."""
    return max(r_max(s) for s in split_at_ring(section)[1])


def size_mismatch(section: Section, plan: PlanOutline) -> str | None:
    """Why the plan as drawn (``plan.scale`` mm per unit) is not the body of ``section``, or
    ``None``: its reach along ``+x`` must be the section's widest radius within ``SIZE_TOL``."""
    drawn = plan.scale * float(plan.support(0.0))
    widest = widest_radius(section)
    if abs(drawn - widest) <= SIZE_TOL * widest:
        return None
    return (f"the plan reaches {drawn:.4g} mm along +x from the axis but the section's widest radius "
            f"is {widest:.4g} mm: draw the plan at the body's widest section, the section as the "
            f"right half of the front view (the same x)")


def outline_sections(section: Section, plan: PlanOutline, rounding_mm: float = DEFAULT_ROUND_MM
                     ) -> tuple[Section, Section]:
    """``(core, round)``: the profiles (mm) of the module's rule for ``section`` and ``plan``.

    Raises ``SectionError`` (naming the section's segment) for a section narrower than its mouth
    below it, or nowhere wider, and ``OutlineError`` for a rounding outside ``(0, R)``.
    """
    _, wall, first = split_at_ring(section)
    r_m, widest = section.r_top, widest_radius(section)
    _check_narrowing(wall, first, r_m, widest)
    if not (math.isfinite(rounding_mm) and 0 < rounding_mm < widest):
        raise OutlineError(None, f"the corners' rounding must be more than 0 and less than the section's "
                                 f"widest radius {widest:.4g} mm, got {rounding_mm:g} mm")
    a_c = (rounding_mm - r_m) / (widest - r_m)      # c = r_m + a_c (r - r_m)
    a_k = (1.0 - a_c) / float(plan.support(0.0))    # k = a_k (r - r_m)
    smooth = (False,) + section.smooth[first:first + len(wall) - 1]
    core = _on_flat_base(mapped_radially(wall, a_k, r_m, 0.0), smooth)
    if abs(a_c) <= 1e-12:  # C = r_m: the rounding is the mouth's all the way down
        rnd = Section((Line((0.0, 0.0), (r_m, 0.0)), Line((r_m, 0.0), (r_m, section.z_top))))
    else:
        rnd = _on_flat_base(mapped_radially(wall, a_c, r_m, r_m), smooth)
    return core, rnd


def outline_from_section(section: Section, plan: PlanOutline, wall_mm: float, base_mm: float,
                         rounding_mm: float = DEFAULT_ROUND_MM) -> BottleShape:
    """The outline bottle of :func:`outline_sections` with wall and base thickness (mm); not
    validated. Its plan is ``plan`` with ``scale`` 1 (the core carries the millimetres)."""
    core, rnd = outline_sections(section, plan, rounding_mm)
    return BottleShape("outline", (("core", core), ("round", rnd)), wall_mm, base_mm,
                       plan=dataclasses.replace(plan, scale=1.0))


def _check_narrowing(wall, first: int, r_m: float, widest: float) -> None:
    """The wall nowhere narrower than the mouth, its standing ring and its widest part wider."""
    if widest - r_m <= POINT_TOL_MM:
        raise SectionError(None, f"the section is nowhere wider than its mouth (r = {r_m:.4g} mm): an "
                                 f"outline bottle's body narrows to a round mouth")
    for i, seg in enumerate(wall, start=first):
        if r_min(seg) < r_m - POINT_TOL_MM:
            z0, z1 = seg.p0[1], seg.p1[1]
            raise SectionError(i, f"between z = {z0:.4g} and {z1:.4g} mm the section narrows to "
                                  f"r = {r_min(seg):.4g} mm, below its mouth's {r_m:.4g} mm: an outline "
                                  f"bottle's corners round off into its mouth, so no part below may be narrower")
    if wall[0].p0[0] <= r_m + POINT_TOL_MM:
        raise SectionError(first, f"the standing ring (r = {wall[0].p0[0]:.4g} mm) must be wider than "
                                  f"the mouth (r = {r_m:.4g} mm)")


def _on_flat_base(wall: tuple, smooth: tuple) -> Section:
    """``wall`` standing on a flat base from the axis to its first point (at z = 0 within the
    ring's tolerance: the base ends exactly where the wall starts)."""
    return Section((Line((0.0, 0.0), wall[0].p0),) + wall, smooth)
