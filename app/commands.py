"""Undoable edits of the scene: each command replaces top-level parts of the Design.

Design rule: panels never write to the scene; they hand the :class:`DesignEditor` the new
values of the parts they changed. The editor validates the result (an invalid design is refused
with the engine's message and the scene is left as it was), wraps it in a
:class:`ReplacePartsCommand` and pushes it onto the ``QUndoStack``. Commands that share a
*merge key* collapse into one undo step: always for one gesture (a drag's key, from
:meth:`DesignEditor.new_merge_key`), and for a field's key (a spin box being scrolled) while the
edits come less than :data:`FIELD_MERGE_S` apart, so two values typed a moment apart stay two
steps.
"""
from __future__ import annotations

import dataclasses
import time

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoCommand, QUndoStack

from app import engine_bridge
from engine.model.design import Design
from engine.operations.check import check_edit
from engine.errors import GlassbenchError

_merge_ids: dict[str, int] = {}
#: A field's edits closer together than this (seconds) merge into one undo step.
FIELD_MERGE_S = 1.5


def merge_id(key: str | None) -> int:
    """A stable small integer for ``key`` (``-1``: never merge)."""
    if key is None:
        return -1
    return _merge_ids.setdefault(key, len(_merge_ids) + 1)


class ReplacePartsCommand(QUndoCommand):
    """Set top-level Design fields (``shape``, ``glass``, ``liquid`` ...) to new values.

    ``before`` and ``after`` map field names to values; undo restores ``before``. The scene's
    own change notification then updates every view.
    """

    def __init__(self, scene, text: str, before: dict, after: dict, merge_key: str | None = None,
                 assets_before: dict | None = None, assets_after: dict | None = None):
        super().__init__(text)
        self._scene = scene
        self.before = dict(before)
        self.after = dict(after)
        self.assets_before = dict(assets_before or {})
        self.assets_after = dict(assets_after or {})
        self._id = merge_id(merge_key)
        self._gesture = merge_key is not None and "#" in merge_key
        self._last_edit = time.monotonic()

    def id(self) -> int:  # noqa: A003 - Qt's name
        return self._id

    def _set(self, parts: dict, assets: dict):
        with self._scene.batch():  # one notification for parts and assets together
            for name, data in assets.items():
                self._scene.set_asset(name, data)
            if parts:
                self._scene.replace(**parts)

    def redo(self):
        self._set(self.after, self.assets_after)

    def undo(self):
        self._set(self.before, self.assets_before)

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, ReplacePartsCommand) or other.id() != self._id or self._id < 0:
            return False
        if not self._gesture and other._last_edit - self._last_edit > FIELD_MERGE_S:
            return False
        self._last_edit = other._last_edit
        for key, value in other.after.items():
            self.before.setdefault(key, other.before[key])
            self.after[key] = value
        for key, value in other.assets_after.items():
            self.assets_before.setdefault(key, other.assets_before[key])
            self.assets_after[key] = value
        return True


class DesignEditor(QObject):
    """The one way the GUI changes the design: validated, undoable replacement of parts.

    Signals
    -------
    refused(str)
        An edit was refused; the text names the problem (engine validation message).
    adjusted(str)
        An edit was made with a consequence the designer did not ask for (a lower mouth
        lowered the liquid too); the text says what.
    derived(object)
        The numbers derived from the design (a :class:`~app.wireframe_controller.Derived`:
        trade and plant numbers, inner walls, warnings), computed off the GUI thread after a
        change they depend on; the window relays them here, so a panel that shows them
        follows them like the scene (:func:`widgets.edit_fields.follow`).
    """

    refused = Signal(str)
    adjusted = Signal(str)
    derived = Signal(object)

    def __init__(self, scene, stack: QUndoStack, parent=None):
        super().__init__(parent)
        self.scene = scene
        self.stack = stack
        self._drag_serial = 0

    @property
    def design(self) -> Design:
        return self.scene.design

    def check(self, design: Design, changed=frozenset({"shape"}), assets=None) -> str | None:
        """``None`` when ``design`` may be shown, else the message that says why not.

        Only what ``changed`` can break is checked (:func:`engine.operations.check.check_edit`):
        the geometry for a shape edit (the costly part, run on every drag step), ranges and asset
        references for the rest, the fill level for a liquid edit.
        """
        try:
            check_edit(design, changed, self.scene.assets if assets is None else assets)
        except (GlassbenchError, ValueError) as exc:
            return str(exc)
        return None

    def new_merge_key(self, what: str) -> str:
        """A key unique to one gesture (a drag): its commands merge into one step."""
        self._drag_serial += 1
        return f"{what}#{self._drag_serial}"

    def apply(self, text: str, merge_key: str | None = None, *, assets: dict | None = None,
              **parts) -> bool:
        """Push a command named ``text`` (the undo history's words, e.g. "Move label") setting
        ``parts`` (Design field -> value) and ``assets`` (name -> bytes, ``None`` removes);
        ``False`` if refused."""
        current = self.scene.design
        changed = {k: v for k, v in parts.items() if getattr(current, k) != v}
        old_assets = self.scene.assets
        assets = {k: v for k, v in (assets or {}).items() if old_assets.get(k) != v}
        if not changed and not assets:
            return True
        try:
            candidate = dataclasses.replace(current, **changed)
        except (TypeError, ValueError) as exc:
            self.refused.emit(str(exc))
            return False
        if "shape" in changed and "liquid" not in changed and candidate.liquid is not None:
            fitted = engine_bridge.fitted_liquid(candidate)  # a lower mouth lowers the liquid too
            if fitted != candidate.liquid:
                changed["liquid"] = fitted
                candidate = dataclasses.replace(candidate, liquid=fitted)
        new_assets = {**self.scene.assets, **{k: v for k, v in assets.items() if v is not None}}
        problem = self.check(candidate, frozenset(changed), new_assets)
        if problem is not None:
            self.refused.emit(problem)
            return False
        before = {k: getattr(current, k) for k in changed}
        assets_before = {k: old_assets.get(k) for k in assets}
        self.stack.push(ReplacePartsCommand(self.scene, text, before, changed, merge_key,
                                            assets_before, assets))
        if "liquid" in changed and "liquid" not in parts:
            level, was = changed["liquid"].fill_value, before["liquid"].fill_value
            unit = "mm" if changed["liquid"].fill_mode == "height" else "ml"
            why = ("lowered", "the new mouth is below") if level < was else ("raised", "the new inner base is above")
            self.adjusted.emit(f"The liquid was {why[0]} to {level:.1f} {unit}: {why[1]} where it stood")
        return True
