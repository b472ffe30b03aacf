"""Undo and redo from every widget: a field being typed in commits its edit first.

Design rule: Qt's line edits (one sits inside every spin box) take Ctrl+Z for their own text
undo, so the window's shortcut never sees it. An application event filter catches the undo and
redo key sequences (as ``ShortcutOverride``) while the focus is in an editing field of the
window, commits that field's edit (a spin box interprets its text; a table's cell editor hands
its value to the model) and lets the shortcut through, so Edit > Undo always acts on the design,
never on the text of one field. The Undo and Redo actions commit the same way before they act,
so the menu and the keys behave alike.
"""
from __future__ import annotations

from PySide6.QtCore import QEvent, QObject
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (QAbstractItemDelegate, QAbstractItemView, QAbstractSpinBox,
                               QApplication, QLineEdit, QPlainTextEdit, QTextEdit, QWidget)

UNDO_KEYS = ("Ctrl+Z",)
REDO_KEYS = ("Ctrl+Shift+Z", "Ctrl+Y")
_FIELDS = (QLineEdit, QAbstractSpinBox, QTextEdit, QPlainTextEdit)


def _cell_editor(widget: QWidget):
    """``(view, editor)`` when ``widget`` is (inside) an item view's open cell editor."""
    child, parent = widget, widget.parentWidget()
    while parent is not None:
        if isinstance(parent.parentWidget(), QAbstractItemView) and \
                parent is parent.parentWidget().viewport():
            return parent.parentWidget(), child
        child, parent = parent, parent.parentWidget()
    return None, None


def _field_of(widget: QWidget | None):
    """The editing field ``widget`` belongs to (itself, or the spin box around its line edit)."""
    if widget is None:
        return None
    parent = widget.parentWidget()
    if isinstance(parent, QAbstractSpinBox):
        return parent
    return widget if isinstance(widget, _FIELDS) else None


def commit_field(widget: QWidget | None) -> bool:
    """Commit the edit being typed in ``widget`` (the focus widget); ``True`` if it was a field.

    A cell editor gives its value to the table's model and closes; a spin box interprets its
    text (which emits ``valueChanged`` when the value changed, as Enter would); a line edit
    emits ``editingFinished``.
    """
    if widget is None:
        return False
    view, editor = _cell_editor(widget)
    if view is not None:
        delegate = view.itemDelegateForIndex(view.currentIndex())
        delegate.commitData.emit(editor)
        delegate.closeEditor.emit(editor, QAbstractItemDelegate.NoHint)
        return True
    field = _field_of(widget)
    if isinstance(field, QAbstractSpinBox):
        field.interpretText()
        return True
    if isinstance(field, QLineEdit):
        field.editingFinished.emit()
        return True
    return field is not None


def _matches(event, keys) -> bool:
    pressed = QKeySequence(event.keyCombination())
    return any(pressed.matches(QKeySequence(k)) == QKeySequence.ExactMatch for k in keys)


class UndoKeys(QObject):
    """Undo/Redo actions for ``window``'s ``undo_stack`` that work from every widget.

    Attributes
    ----------
    undo_action, redo_action : QAction
        For the Edit menu; their texts follow the stack ("Undo Move joint").
    """

    def __init__(self, window, stack):
        super().__init__(window)
        self.window = window
        self.stack = stack
        self.undo_action = self._action("&Undo", UNDO_KEYS, self.undo)
        self.redo_action = self._action("&Redo", REDO_KEYS, self.redo)
        stack.canUndoChanged.connect(self.undo_action.setEnabled)
        stack.canRedoChanged.connect(self.redo_action.setEnabled)
        stack.undoTextChanged.connect(lambda t: self.undo_action.setText(f"&Undo {t}".strip()))
        stack.redoTextChanged.connect(lambda t: self.redo_action.setText(f"&Redo {t}".strip()))
        self.undo_action.setEnabled(stack.canUndo())
        self.redo_action.setEnabled(stack.canRedo())
        QApplication.instance().installEventFilter(self)

    def _action(self, text, keys, slot) -> QAction:
        act = QAction(text, self.window)
        act.setShortcuts([QKeySequence(k) for k in keys])
        act.triggered.connect(slot)
        return act

    def attach_menu(self, menu):
        """Put the actions in ``menu`` (Edit); opening it commits the field being typed in, so
        Undo is offered for the value just typed."""
        menu.addAction(self.undo_action)
        menu.addAction(self.redo_action)
        menu.aboutToShow.connect(lambda: commit_field(QApplication.focusWidget()))

    def undo(self):
        """Commit the field being typed in, then undo the last step of the design."""
        commit_field(QApplication.focusWidget())
        self.stack.undo()

    def redo(self):
        commit_field(QApplication.focusWidget())
        self.stack.redo()

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        if event.type() != QEvent.ShortcutOverride or not isinstance(obj, QWidget):
            return False
        if obj.window() is not self.window or not (_matches(event, UNDO_KEYS) or _matches(event, REDO_KEYS)):
            return False
        if _field_of(obj) is None and _cell_editor(obj)[0] is None:
            return False
        if obj is QApplication.focusWidget():
            # why now: the action is enabled only once the stack holds the field's edit
            commit_field(obj)
            if _matches(event, UNDO_KEYS) and not self.stack.canUndo():
                return False
        event.ignore()  # not for the field: the window's shortcut takes it
        return True

    def shutdown(self):
        """Stop watching the application's key events (the window is closing)."""
        app = QApplication.instance()
        if app is not None:
            app.removeEventFilter(self)
