"""What an edit changed: the design's fields and the assets, named once, by the scene.

Design rule: the :class:`~engine.model.scene.Scene` computes a :class:`Change` when a value is
swapped in (the only place designs are compared for an edit) and hands it to every observer; a
consumer that outlives several edits (the render controller between full renders) unions them
(``a | b``) instead of comparing designs again. A ``Change`` is the frozenset of changed
top-level field names (plus ``"assets"`` when an asset changed), so ``change & {"shape"}`` reads
as it always did, and carries the names of the assets that changed (``assets``; ``None`` when the
maker did not know them, as for a hand-made set of names).
"""
from __future__ import annotations

from typing import Iterable


#: Design fields that no image shows (the name, the notes, the plant's settings): an edit of
#: these alone restarts no render.
UNSEEN_FIELDS = frozenset({"name", "notes", "plant"})


class Change(frozenset):
    """Changed field names, and the changed assets' names in ``assets`` (module rule)."""

    def __new__(cls, names: Iterable[str] = (), assets: Iterable[str] | None = ()):
        assets = None if assets is None else frozenset(assets)
        names = frozenset(names) | ({"assets"} if assets else frozenset())
        self = super().__new__(cls, names)
        self.assets = assets if assets is not None or "assets" not in names else None
        return self

    @classmethod
    def of(cls, changed) -> "Change":
        """``changed`` as a :class:`Change`: itself, or a set of names whose assets are unknown."""
        if isinstance(changed, Change):
            return changed
        names = frozenset(changed)
        return cls(names, None if "assets" in names else ())

    @property
    def fields(self) -> frozenset:
        """The design fields that changed (without the pseudo-field ``"assets"``)."""
        return frozenset(self) - {"assets"}

    def __or__(self, other) -> "Change":
        other = Change.of(other)
        assets = None if self.assets is None or other.assets is None else self.assets | other.assets
        return Change(frozenset(self) | frozenset(other), assets)

    def __reduce__(self):
        return (Change, (frozenset(self), self.assets))

    def __repr__(self) -> str:
        return f"Change({sorted(self)}, assets={None if self.assets is None else sorted(self.assets)})"


def changed_assets(old, new) -> frozenset:
    """Names of the assets added, removed or replaced between mappings ``old`` and ``new``."""
    old, new = old or {}, new or {}
    return frozenset(n for n in set(old) | set(new) if not (old.get(n) is new.get(n) or old.get(n) == new.get(n)))
