"""A design's name that states its volume ("Bordeaux 750 ml"), kept true when the fill changes.

Design rule: a name may quote the bottle's nominal volume in ml, cl or l (``750 ml``, ``75cl``,
``0.75 l``). When the fill volume moves away from it, :func:`updated_name` gives the name with
the new volume in the same unit and style, which the window offers the designer (it never
renames by itself). A name without a volume, or whose volume already matches the fill to
:data:`MATCH_TOLERANCE`, is left alone.
"""
from __future__ import annotations

import re

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
