"""Stage panel: what the bottle stands on (none, shadow catcher, table, glossy riser, mirror), its
colour, a glossy riser's gloss and the backdrop sweep of a table or riser.

Design rule: as the other panels, each edit is the engine's operation
(:func:`engine.operations.stage.set_stage`, which ``glassbench stage`` and batches call too)
applied as ``editor.apply(text, merge_key, stage=...)``, one undoable step checked by the engine, and the panel follows the scene for ``design.stage``
itself (:func:`widgets.edit_fields.follow`), so an undo or an edit from elsewhere shows here.
Which controls a kind uses is the engine's (:data:`engine.operations.stage.STAGE_USES`, as
``glassbench stage`` and the batch override refuse the rest): the others are greyed out and
keep their values. The model's colour is linear RGB; the button shows and the dialog picks sRGB
(:mod:`widgets.edit_fields`, with the engine's curves).
"""
from __future__ import annotations

from PySide6.QtCore import QSignalBlocker
from PySide6.QtWidgets import QCheckBox, QComboBox, QWidget

from engine.model.design import STAGE_KINDS
from engine.errors import GlassbenchError
from engine.operations.stage import STAGE_USES, set_stage
from widgets import edit_fields as ef, words


class StagePanel(QWidget):
    """Edits ``design.stage`` through ``editor``."""

    #: The design fields the panel shows (it follows the scene for them itself).
    FIELDS = frozenset({"stage"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.kind = QComboBox()
        words.fill_combo(self.kind, words.STAGES, STAGE_KINDS)
        self.kind.setToolTip("What the bottle stands on; the environment's light and turn stay "
                             "the Camera tab's")
        ef.compact(self.kind)
        self.color = ef.LinearColorButton()
        self.color.setToolTip("Colour of the table or the riser, or the mirror's tint (shown in "
                              "sRGB; click to pick)")
        self.gloss = ef.spin(0, 1, 2, 0.05, "", "Glossy riser: how sharp its clear coat reflects "
                             "(1: mirror-sharp; 0: a blurred, satin sheen)")
        self.backdrop = QCheckBox("Backdrop sweep")
        self.backdrop.setToolTip("Table or riser: its sheet rises behind the bottle, as the camera "
                                 "sees it, in a cyclorama sweep (hides the environment there)")
        ef.form_page(self, (("Ground", self.kind), ("Colour", self.color), ("Gloss", self.gloss),
                            self.backdrop))
        self.kind.currentIndexChanged.connect(lambda _: self.set_kind(self.kind.currentData()))
        self.color.clicked.connect(self._pick_color)
        self.gloss.valueChanged.connect(lambda v: self._edit("Stage gloss", "stage-gloss", gloss=v))
        self.backdrop.toggled.connect(self.set_backdrop)
        ef.follow(self, editor, self.FIELDS, lambda d, a: self.refresh(d))

    def choose_color(self, initial_linear, title: str):
        """Ask for a colour (linear RGB) or ``None``; tests replace this method."""
        return ef.ask_linear_color(self, initial_linear, title)

    def set_kind(self, kind: str) -> bool:
        """Stand the bottle on a ``kind`` of :data:`STAGE_KINDS` (one undo step); ``False`` if
        refused."""
        if kind == self.editor.design.stage.kind:
            return False
        return self._edit(f"Stage: {words.word(words.STAGES, kind).lower()}", None, kind=kind)

    def set_color(self, rgb) -> bool:
        """Make the stage's colour linear RGB ``rgb`` (0..1; one undo step); ``False`` if refused."""
        return self._edit("Stage colour", None, color=tuple(float(c) for c in rgb))

    def set_backdrop(self, on: bool) -> bool:
        """Raise the table's or riser's backdrop sweep, or take it away (one undo step);
        ``False`` if refused or already so."""
        if bool(on) == self.editor.design.stage.backdrop:
            return False
        return self._edit("Backdrop sweep" if on else "No backdrop sweep", None, backdrop=bool(on))

    def _pick_color(self):
        rgb = self.choose_color(self.editor.design.stage.color, "Stage colour")
        if rgb is not None:
            self.set_color(rgb)

    def _edit(self, text, key, **fields) -> bool:
        """One undoable step of :func:`engine.operations.stage.set_stage` (the operation the
        command line and batches use); a refused edit shows the model again."""
        try:
            edit = set_stage(self.editor.design, text, **fields)
        except (GlassbenchError, ValueError) as exc:
            self.editor.refused.emit(str(exc))
            edit, ok = None, False
        else:
            ok = edit is None or self.editor.apply(edit.text, key, stage=edit.design.stage)
        return ok  # (a refusal re-shows the model: the panel follows the editor's refusals)

    def refresh(self, design):
        """Show ``design.stage``: its values, and only the controls its kind uses enabled."""
        stage = design.stage
        blockers = [QSignalBlocker(w) for w in (self.kind, self.gloss, self.backdrop)]
        words.select_key(self.kind, stage.kind)
        self.color.set_linear(stage.color)
        self.gloss.setValue(stage.gloss)
        uses = STAGE_USES.get(stage.kind, frozenset())
        self.color.setEnabled("color" in uses)
        self.gloss.setEnabled("gloss" in uses)
        self.backdrop.setChecked(stage.backdrop)
        self.backdrop.setEnabled("backdrop" in uses)
        del blockers


__all__ = ["StagePanel"]
