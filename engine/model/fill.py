"""The liquid's level: the one rule for where a liquid may stand and the one volume -> height.

Design rule: a :class:`~engine.model.design.Liquid` is filled either to a height (mm above the
standing plane z = 0) or with a volume (ml). Everything that needs the level (trade numbers,
the CLI, the window, the tracer) asks :func:`fill_height_mm`; everything that accepts a liquid
(the project loader and writer, the panels) asks :func:`check_fill`. The surface must stand at
least :data:`MIN_DEPTH_MM` above the lowest point of the cavity and at most at the mouth,
``z_ib + 0.01 <= h <= z_top``; a volume must be positive, at most the brimful capacity and stand
at such a height. Geometry must be valid
before either is asked (the errors of :mod:`engine.geometry.validate` propagate).
"""
from __future__ import annotations

import dataclasses
import math

from ..errors import DesignError, shown
from ..geometry import capacity
from ..geometry.validate import body_profile

FILL_MODES = ("height", "volume")
#: Shallowest liquid (mm above the lowest point of the cavity): a thinner one has no volume to
#: render and no height the float64 level can tell from the inner base.
MIN_DEPTH_MM = 0.01
#: Relative slack on the brimful volume (the quadrature's rounding).
_VOLUME_SLACK = 1e-12


def check_fill_mode(liquid) -> None:
    """Raise ``DesignError`` unless ``liquid.fill_mode`` is one of :data:`FILL_MODES`."""
    if liquid.fill_mode not in FILL_MODES:
        raise DesignError(f"design.liquid.fill_mode must be 'height' or 'volume', "
                          f"got {shown(liquid.fill_mode)}")


def check_fill(shape, liquid) -> None:
    """Raise ``DesignError`` naming ``design.liquid.fill_value`` unless the liquid fits ``shape``.

    Parameters
    ----------
    shape : BottleShape
        A valid shape (mm).
    liquid : Liquid or None
        ``None`` (an empty bottle) always fits.
    """
    if liquid is None:
        return
    check_fill_mode(liquid)
    value = liquid.fill_value
    prof = body_profile(shape)
    lowest = prof.z_ib + MIN_DEPTH_MM
    if liquid.fill_mode == "height":
        if not lowest <= value <= prof.z_top:
            raise DesignError(f"design.liquid.fill_value = {shown(value)} mm: the fill height must "
                              f"lie {MIN_DEPTH_MM:g} mm or more above the inner base "
                              f"({prof.z_ib:.6g} mm) and at most at the mouth ({prof.z_top:.6g} mm)")
        return
    brimful = capacity.brimful_ml(shape)
    if not 0.0 < value <= brimful * (1.0 + _VOLUME_SLACK):
        raise DesignError(f"design.liquid.fill_value = {shown(value)} ml: the fill volume must "
                          f"be more than 0 and at most the brimful capacity ({brimful:.6g} ml)")
    if capacity.fill_height_for_volume(shape, min(value, brimful)) < lowest:
        raise DesignError(f"design.liquid.fill_value = {shown(value)} ml is too little to stand "
                          f"{MIN_DEPTH_MM:g} mm deep above the inner base")


def fitted_liquid(shape, liquid):
    """``liquid`` moved to the nearest level :func:`check_fill` accepts in ``shape`` (itself when
    it fits, ``None`` for ``None``): for a shape edit that takes the mouth below the liquid, so the
    design stays one that can be saved. Raises the geometry's errors for an invalid shape and
    ``DesignError`` for an unknown fill mode."""
    if liquid is None:
        return None
    check_fill_mode(liquid)
    try:
        check_fill(shape, liquid)
        return liquid
    except DesignError:
        pass
    prof = body_profile(shape)
    lowest = min(prof.z_ib + MIN_DEPTH_MM, prof.z_top)
    value = liquid.fill_value if math.isfinite(liquid.fill_value) else prof.z_top
    if liquid.fill_mode == "height":
        value = min(max(value, lowest), prof.z_top)
    else:
        least = capacity.capacity_ml(shape, lowest) * (1.0 + 1e-9)
        value = min(max(value, least), capacity.brimful_ml(shape))
    return dataclasses.replace(liquid, fill_value=float(value))


def fill_height_mm(shape, liquid) -> float | None:
    """The height (mm above z = 0) of the liquid's surface, or ``None`` for no liquid.

    A ``"height"`` liquid stands at its ``fill_value``; a ``"volume"`` one at the height that
    holds ``fill_value`` ml (:func:`engine.geometry.capacity.fill_height_for_volume`). Raises
    ``DesignError`` when the liquid does not fit (:func:`check_fill`).
    """
    if liquid is None:
        return None
    check_fill(shape, liquid)
    if liquid.fill_mode == "height":
        return float(liquid.fill_value)
    brimful = capacity.brimful_ml(shape)
    return float(capacity.fill_height_for_volume(shape, min(float(liquid.fill_value), brimful)))


def fill_volume_ml(shape, liquid) -> float | None:
    """The liquid's volume (ml), or ``None`` for no liquid (the converse of :func:`fill_height_mm`)."""
    if liquid is None:
        return None
    check_fill(shape, liquid)
    if liquid.fill_mode == "volume":
        return float(liquid.fill_value)
    return float(capacity.capacity_ml(shape, liquid.fill_value))


def fill_height_of(design) -> float | None:
    """The liquid level (mm) of a whole design: :func:`fill_height_mm` of its shape and liquid."""
    return fill_height_mm(design.shape, design.liquid)


def liquid_at_height(shape, liquid, height_mm: float):
    """``liquid`` standing at ``height_mm`` (mm above z = 0), in its own fill mode: a height
    liquid gets that height, a volume liquid the volume below it (ml, rounded to 0.01 ml), so a
    drag of the fill line keeps the designer's choice of mode. ``None`` stays ``None``; the
    result is not checked (:func:`check_fill` says whether it fits)."""
    if liquid is None:
        return None
    check_fill_mode(liquid)
    if liquid.fill_mode == "height":
        return dataclasses.replace(liquid, fill_value=round(float(height_mm), 2))
    return dataclasses.replace(liquid, fill_value=round(capacity.capacity_ml(shape, height_mm), 2))
