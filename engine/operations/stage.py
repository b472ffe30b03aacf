"""The stage as a designer names it: its kinds (with an alias) and which fields each kind draws.

Design rule: the Stage panel, ``glassbench stage`` and the batch override ``stage`` change the
stage through one operation, :func:`set_stage` (:func:`staged` for a stage alone), which reads
a typed kind with :func:`stage_kind` (the model's :data:`~engine.model.design.STAGE_KINDS` and
the alias ``shadow-catcher``) and refuses, in one sentence for every door, a field the kind
would not draw (:data:`STAGE_USES`, :func:`unused`): a gloss given to a matte table, a colour
given to a shadow catcher would silently do nothing. The panel greys those controls out.
A field a kind does not draw keeps its value (switching to a kind that draws it uses it
again). Ranges are the model's check (:func:`engine.model.check.check_values`).
"""
from __future__ import annotations

import dataclasses

from ..errors import DesignError, shown
from ..model.design import STAGE_KINDS
from .edit import Edit

#: Other names a designer may type for a kind.
STAGE_ALIASES = {"shadow-catcher": "shadow"}
#: The ``Stage`` fields each kind draws (``color``: the table's or riser's albedo, the mirror's
#: tint; a shadow catcher takes the environment's background instead; ``backdrop``: the sweep,
#: :data:`~engine.model.design.BACKDROP_KINDS`).
STAGE_USES = {"none": frozenset(),
              "shadow": frozenset(),
              "table": frozenset({"color", "backdrop"}),
              "glossy": frozenset({"color", "gloss", "backdrop"}),
              "mirror": frozenset({"color"})}
#: The kinds as a sentence lists them, aliases in brackets.
KIND_NAMES = ", ".join(k + "".join(f" ({a})" for a, t in STAGE_ALIASES.items() if t == k)
                       for k in STAGE_KINDS)


def stage_kind(text) -> str | None:
    """The kind of :data:`STAGE_KINDS` that ``text`` names (any case, an alias resolved), or
    ``None`` when it names none."""
    if not isinstance(text, str):
        return None
    key = text.strip().lower()
    key = STAGE_ALIASES.get(key, key)
    return key if key in STAGE_KINDS else None


def unused(kind: str, given: dict) -> list[str]:
    """The names in ``given`` (``Stage`` field -> value asked for) that a stage of ``kind``
    would not draw, in ``given``'s order; turning the backdrop off is always allowed."""
    uses = STAGE_USES[kind]
    return [name for name, value in given.items()
            if name not in uses and name != "kind" and not (name == "backdrop" and value is False)]


def staged(stage, fields: dict, typed: dict | None = None):
    """``stage`` with ``fields`` (``Stage`` field -> value; ``kind`` may be typed, an alias)
    replaced; ``DesignError`` for an unknown kind or a field the kind would not draw, naming it
    as the door's user typed it (``typed``: field -> word, e.g. ``{"gloss": "--gloss"}``)."""
    fields = dict(fields)
    if "kind" in fields:
        kind = stage_kind(fields["kind"])
        if kind is None:
            raise DesignError(f"the stage is one of {KIND_NAMES}, not {shown(fields['kind'])}")
        fields["kind"] = kind
    new = dataclasses.replace(stage, **fields)
    for name in unused(new.kind, fields):
        word = (typed or {}).get(name, name)
        raise DesignError(f"{word} does nothing for the stage {new.kind!r}; leave it out or give another kind")
    return new


def set_stage(design, text: str | None = None, typed: dict | None = None, **fields) -> Edit | None:
    """The design on the stage :func:`staged` makes (``None`` when nothing changes); ``text``
    the undo stack's words (default: the stage's kind)."""
    stage = staged(design.stage, fields, typed)
    if stage == design.stage:
        return None
    return Edit(dataclasses.replace(design, stage=stage), text or f"Stage: {stage.kind}")
