"""The scene model: an observable holder of the current :class:`engine.model.design.Design`.

Design rule: the design itself is a frozen value; ``Scene`` only swaps whole values and tells
its observers which top-level ``Design`` fields changed (compared by value, so re-setting an
equal value announces nothing), as a :class:`~engine.model.changes.Change`: the scene is the one
place an edit is diffed. Several edits inside ``with scene.batch():`` announce once, with the
union of the changes. Assets (environment maps, label images) are bytes kept beside the design,
named by ``Environment.asset`` / ``Label.asset``; an asset change is announced as the
pseudo-field ``"assets"``, with the asset's name in ``Change.assets``. No Qt here: the GUI wraps edits in undoable
commands and marshals notifications to its own thread.
"""
from __future__ import annotations

import dataclasses
from contextlib import contextmanager
from types import MappingProxyType
from typing import Callable, Iterator, Mapping

from .changes import Change, changed_assets
from .design import Design

#: Top-level field names of ``Design``: the names observers may receive (plus ``"assets"``).
DESIGN_FIELDS = frozenset(f.name for f in dataclasses.fields(Design))
#: Everything an observer may be told changed: every ``Design`` field and ``"assets"`` (what a
#: view that shows a whole new design, such as a window opening, refreshes).
ALL_CHANGES = DESIGN_FIELDS | {"assets"}

Observer = Callable[[frozenset, "Scene"], None]


def changed_fields(old: Design, new: Design) -> Change:
    """The top-level ``Design`` fields whose values differ between ``old`` and ``new``."""
    return Change(f.name for f in dataclasses.fields(Design) if getattr(old, f.name) != getattr(new, f.name))


class Scene:
    """Holds the current design and its assets; notifies observers of real changes.

    Parameters
    ----------
    design : Design
        The initial design.
    assets : Mapping[str, bytes], optional
        Initial assets (names to file contents).

    Notes
    -----
    Observers are called synchronously, in subscription order, as
    ``callback(changed: frozenset[str], scene)`` once per edit (or once per outermost batch).
    An observer that raises does not stop the others; the first exception is re-raised after
    all have been told, so a faulty panel cannot desynchronise the rest of the GUI.
    """

    def __init__(self, design: Design, assets: Mapping[str, bytes] | None = None):
        if not isinstance(design, Design):
            raise TypeError(f"a Scene holds a Design, got {type(design).__name__}")
        self._design = design
        self._assets: dict[str, bytes] = {}
        for name, data in (assets or {}).items():
            self._assets[str(name)] = bytes(data)
        self._observers: list[Observer] = []
        self._batch_depth = 0
        self._pending = Change()

    # -- reading ---------------------------------------------------------------------------
    @property
    def design(self) -> Design:
        """The current design (a frozen value)."""
        return self._design

    def snapshot(self) -> Design:
        """The frozen design to hand to a renderer or worker thread (safe to keep)."""
        return self._design

    @property
    def assets(self) -> Mapping[str, bytes]:
        """Read-only view of the assets: name -> bytes."""
        return MappingProxyType(self._assets)

    # -- editing ---------------------------------------------------------------------------
    def set_design(self, new: Design) -> Change:
        """Make ``new`` the current design; returns (and announces) the changed fields."""
        if not isinstance(new, Design):
            raise TypeError(f"set_design needs a Design, got {type(new).__name__}")
        changed = changed_fields(self._design, new)
        if changed:
            self._design = new
            self._announce(changed)
        return changed

    def replace(self, **changes) -> Change:
        """Replace top-level fields by name (``scene.replace(glass=Glass(ior=1.5))``).

        Raises ``TypeError`` for names that are not ``Design`` fields.
        """
        unknown = set(changes) - DESIGN_FIELDS
        if unknown:
            raise TypeError(f"Design has no field(s) {', '.join(sorted(unknown))}")
        return self.set_design(dataclasses.replace(self._design, **changes))

    def set_asset(self, name: str, data: bytes | None) -> bool:
        """Store (or with ``None`` remove) asset ``name``; returns whether anything changed."""
        if not isinstance(name, str) or not name:
            raise ValueError("an asset needs a non-empty name")
        if data is None:
            if name not in self._assets:
                return False
            del self._assets[name]
        else:
            data = bytes(data)
            if self._assets.get(name) == data:
                return False
            self._assets[name] = data
        self._announce(Change(assets={name}))
        return True

    def load(self, design: Design, assets: Mapping[str, bytes]) -> Change:
        """Replace design and all assets at once (opening a project); one notification."""
        with self.batch():
            changed = self.set_design(design)
            new_assets = {str(k): bytes(v) for k, v in assets.items()}
            names = changed_assets(self._assets, new_assets)
            if names:
                self._assets = new_assets
                self._pending = self._pending | Change(assets=names)
                changed = changed | Change(assets=names)
        return changed

    @contextmanager
    def batch(self) -> Iterator["Scene"]:
        """Collect every change made inside the block into one notification at its end.

        Nested batches join the outermost one. Changes are announced even when the block
        raises, since the model really did change.
        """
        self._batch_depth += 1
        try:
            yield self
        finally:
            self._batch_depth -= 1
            if self._batch_depth == 0 and self._pending:
                pending, self._pending = self._pending, Change()
                self._notify(pending)

    # -- observing -------------------------------------------------------------------------
    def subscribe(self, callback: Observer) -> Callable[[], None]:
        """Call ``callback(changed, scene)`` after each change; returns an unsubscribe function
        (calling it twice is harmless)."""
        self._observers.append(callback)

        def unsubscribe() -> None:
            try:
                self._observers.remove(callback)
            except ValueError:
                pass
        return unsubscribe

    def _announce(self, changed: Change) -> None:
        if self._batch_depth:
            self._pending = self._pending | changed
        else:
            self._notify(changed)

    def _notify(self, changed: Change) -> None:
        first_error = None
        for cb in list(self._observers):
            try:
                cb(changed, self)
            except Exception as exc:  # why: one bad observer must not starve the others
                first_error = first_error or exc
        if first_error is not None:
            raise first_error
