"""What an operation on a design returns: the new design, the assets it adds or lets go, the
words an undo stack shows.

Design rule: every named operation (:mod:`.labels`, :mod:`.tiles`, :mod:`.closure`) takes the
current ``Design`` (and the project's assets where images are named) and returns an
:class:`Edit`; nothing is saved or applied there. The caller applies it: the window's undoable
editor (``editor.apply_edit``), the command line's save (:meth:`Edit.assets_after`), a batch
variant. So one edit does the same to a project whichever door it comes through, and an image
no part of the design uses any more leaves the project (:func:`released`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from ..model.design import Design


@dataclass(frozen=True)
class Edit:
    """What an operation did (module rule). ``assets`` maps names to new bytes, or to ``None``
    for an asset the design no longer uses; ``select`` is the item (label, region, tile) to show."""

    design: Design
    text: str
    assets: Mapping[str, bytes | None] = field(default_factory=dict)
    select: int | None = None

    def assets_after(self, assets: Mapping[str, bytes]) -> dict:
        """The project's assets once the edit is applied to ``assets``."""
        out = {k: v for k, v in assets.items() if self.assets.get(k, v) is not None}
        out.update({k: v for k, v in self.assets.items() if v is not None})
        return out


def assets_in_use(design) -> set:
    """Every asset name ``design`` refers to (environment, labels, bump tiles)."""
    names = {design.environment.asset} | {t.asset for t in design.bumps}
    names |= {n for lab in design.labels for n in lab.asset_names()}
    return {n for n in names if n is not None}


def replaced(items: tuple, i: int, value) -> tuple:
    """``items`` with item ``i`` replaced by ``value``."""
    return items[:i] + (value,) + items[i + 1:]


def removed(items: tuple, i: int) -> tuple:
    """``items`` without item ``i``."""
    return items[:i] + items[i + 1:]


def swapped(items: tuple, i: int, step: int) -> tuple | None:
    """``items`` with item ``i`` moved ``step`` places (swapped with its neighbour there), or
    ``None`` when either place is outside the tuple."""
    j = i + step
    if not (0 <= i < len(items) and 0 <= j < len(items)):
        return None
    out = list(items)
    out[i], out[j] = out[j], out[i]
    return tuple(out)


def released(before, after, added: Mapping | None = None) -> dict:
    """``{name: None}`` for each asset ``before`` used that ``after`` does not (nor ``added``
    brings), then ``added``: the ``assets`` of an :class:`Edit` from ``before`` to ``after``."""
    kept = assets_in_use(after) | set(added or {})
    out = {n: None for n in assets_in_use(before) - kept}
    out.update(added or {})
    return out
