"""Whether each label lies on the glass: on the outer wall, at most once around the girth.

Design rule: :func:`check_label_placement` is the geometric half of checking labels, run by
:func:`engine.operations.check.check_design` (so on every save, load and panel edit) after the
shape itself is valid. It builds each label's :class:`~engine.appearance.frame.LabelFrame`
(cached by value, so a drag re-checks only the label that moved) and refuses, with one line
naming the label and the numbers, a label whose patch leaves the outer wall (below the
standing ring, above the mouth) or wraps more than once around. What a label *may* do but paper
does badly (strain, a shoulder, a sharp corner) is a warning of :mod:`engine.appearance.dieline`,
not a refusal. Units: mm.
"""
from __future__ import annotations

import math

from ..errors import DesignError, shown
from .cap_surfaces import check_cap_label
from .frame import TWO_PI, Placement, label_frame


def _where(i: int, label) -> str:
    return f"design.labels[{i}] ({shown(label.name, 40)})"


def check_label_placement(design) -> None:
    """Raise ``DesignError`` for the first label of ``design`` that does not lie on its wall."""
    for i, label in enumerate(design.labels):
        if label.surface == "wall":
            check_one(design.shape, label, _where(i, label))
        else:  # a print on the closure: the cap must be there and the print fit on it
            check_cap_label(design, label, _where(i, label))


def check_one(shape, label, where: str = "the label") -> None:
    """Raise ``DesignError`` unless ``label`` lies on the outer wall of ``shape`` (module rule)."""
    p = Placement.of(label)
    frame = label_frame(shape, p, where)
    if p.width_mm > frame.girth_mm * (1.0 + 1e-12):
        raise DesignError(f"{where} is {p.width_mm:g} mm wide but the girth at z = {p.z_mm:g} mm "
                          f"is {frame.girth_mm:.1f} mm: a label wraps at most once around")
    if frame.kind == "round":
        low, high, unit = frame.wall.h_ring, frame.wall.h_top, "along the section"
    else:
        low, high, unit = 0.0, frame.wall.z_top, "high"
    if not (math.isfinite(frame.h0) and frame.h0 >= low - 1e-9):
        raise DesignError(f"{where} reaches below the standing ring: its {p.height_mm:g} mm "
                          f"centred at z = {p.z_mm:g} mm do not fit on the wall below the centre")
    if not (math.isfinite(frame.h1) and frame.h1 <= high + 1e-9):
        raise DesignError(f"{where} reaches above the mouth: its {p.height_mm:g} mm centred at "
                          f"z = {p.z_mm:g} mm end {frame.h1 - high:.1f} mm past the top "
                          f"({high:g} mm {unit})" if math.isfinite(frame.h1) else
                          f"{where} reaches above the mouth: its {p.height_mm:g} mm centred at "
                          f"z = {p.z_mm:g} mm do not fit on the wall above the centre")
    if frame.span > TWO_PI * (1.0 + 1e-12):
        raise DesignError(f"{where} wraps more than once around where the girth narrows "
                          f"(it spans {math.degrees(frame.span):.0f} deg)")
