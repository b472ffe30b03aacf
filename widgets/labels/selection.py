"""The selected label: which of the design's labels the labels panel's parts edit, and how.

Design rule: the panel's parts (:mod:`~widgets.labels.placement`, :mod:`~widgets.labels.preview`,
:mod:`~widgets.labels.sheet`, :mod:`~widgets.labels.regions`) take the editor and this small
observable, never the panel. The panel's list writes it (:meth:`SelectedLabel.select`); the
label itself is always read from the editor's design, so it is never stale. An edit of the
selected label is an operation's :class:`~engine.operations.labels.Edit` applied through the
editor as one undoable step (:meth:`SelectedLabel.apply`); an edit refused before it reaches the
editor (an image that does not decode) is said with :meth:`SelectedLabel.refuse`.
"""
from __future__ import annotations

import dataclasses

from PySide6.QtCore import QObject, Signal

from engine.operations import labels as ops


class SelectedLabel(QObject):
    """The label of ``editor``'s design that is selected (index -1: none).

    Signals
    -------
    changed()
        Another label, or none, is selected.
    problem(str)
        Why an edit of the label was refused before it reached the editor; an empty text when a
        new edit starts (what was said no longer holds).
    """

    changed = Signal()
    problem = Signal(str)

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self._index = -1
        #: The row an edit being applied asks the list to show (``None``: keep the selection).
        self.after_edit: int | None = None

    @property
    def index(self) -> int:
        """The selected label (-1: none)."""
        i = self._index
        return i if 0 <= i < len(self.editor.design.labels) else -1

    @property
    def label(self):
        """The selected :class:`~engine.model.design.Label` as the design holds it now, or ``None``."""
        i = self.index
        return self.editor.design.labels[i] if i >= 0 else None

    def select(self, index: int) -> None:
        """Select label ``index`` (-1: none); ``changed`` when that is another one."""
        if index != self._index:
            self._index = index
            self.changed.emit()

    def refuse(self, text: str) -> None:
        """Say why an edit of the label was refused before it reached the editor."""
        self.problem.emit(text)

    def apply(self, edit, key=None) -> bool:
        """Apply an operation's :class:`~engine.operations.labels.Edit` as one undoable step
        (``key`` merges a gesture's or a field's steps); the list then shows the label the edit
        names. ``False`` when refused (the panel shows the model again, following the refusal)."""
        if edit is None:
            return False
        self.problem.emit("")
        self.after_edit = edit.select if key is None else None
        try:
            return self.editor.apply(edit.text, key, assets=dict(edit.assets), labels=edit.design.labels)
        finally:
            self.after_edit = None

    def put(self, text: str, key, label) -> bool:
        """The selected label becomes ``label``."""
        i = self.index
        return i >= 0 and self.apply(ops.replace_label(self.editor.design, i, label, text), key)

    def edit_field(self, text: str, field: str, **fields) -> bool:
        """Change fields of the selected label (``label-INDEX-FIELD`` merges a field's steps)."""
        lab = self.label
        if lab is None:
            return False
        return self.put(text, f"label-{self.index}-{field}", dataclasses.replace(lab, **fields))
