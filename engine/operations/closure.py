"""The named operations on a design's closure: one door for ``glassbench cap`` and the Cap panel.

Design rule: as :mod:`.tiles`, each operation returns an :class:`~engine.operations.edit.Edit`
checked by the model's own rules (:func:`engine.model.finish_values.check_cap_values`, in the
model's words); a closure chosen afresh starts from
:func:`engine.appearance.closure_shapes.default_cap`, its size from the finish. Taking the cap
off keeps the tiles that were on its skirt (they are listed as not drawn until a cap returns).
"""
from __future__ import annotations

import dataclasses

from ..appearance.closure_shapes import default_cap
from ..model.finish_values import check_cap_values
from .edit import Edit

#: Each closure kind in a designer's words (the panel's list and the undo stack's).
CAP_WORDS = {"none": "None", "screw": "Screw cap (knurled skirt)", "crown": "Crown cap",
             "cork": "Cork", "ropp": "Roll-on screwcap (ROPP)", "lug": "Lug (twist-off) cap"}


def set_cap(design, kind: str, **fields) -> Edit | None:
    """The closure of ``kind`` (``"none"``: none) from its defaults with ``fields`` changed
    (``None`` values ignored); ``None`` when it is already so."""
    if kind == "none":
        return None if design.cap is None else Edit(dataclasses.replace(design, cap=None), "Remove the closure")
    fields = {k: v for k, v in fields.items() if v is not None}
    cap = dataclasses.replace(default_cap(kind), **fields)
    check_cap_values(cap, "the closure")
    if cap == design.cap:
        return None
    return Edit(dataclasses.replace(design, cap=cap), f"Closure {CAP_WORDS.get(kind, kind).lower()}")


def edit_cap(design, text: str, **fields) -> Edit | None:
    """The closure with ``fields`` changed (``None`` without a closure or when nothing changes)."""
    if design.cap is None:
        return None
    cap = dataclasses.replace(design.cap, **fields)
    if cap == design.cap:
        return None
    check_cap_values(cap, "the closure")
    return Edit(dataclasses.replace(design, cap=cap), text)
