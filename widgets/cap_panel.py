"""Cap panel: the closure on the finish (none, screw, crown, cork, roll-on, lug), its material,
colour, height, count of ridges/flutes/lugs and a cork's capsule.

Design rule: every edit is an operation of :mod:`engine.operations.closure` (the ones
``glassbench cap set`` calls: a kind chosen afresh starts from its trade's material, colour and
standard sizes), applied as one undoable step (``editor.apply(text, merge_key, cap=...)``) and
checked by the engine (a closure that cannot fit the finish is refused with its message). The cap's
sizes follow the neck (:func:`engine.appearance.closures.closure_geometry`); the panel shows
the closure's size and the overall height, and the Design panel's trade numbers show them too.
"""
from __future__ import annotations

from PySide6.QtCore import QSignalBlocker
from PySide6.QtWidgets import QCheckBox, QComboBox, QLabel, QWidget

from engine.operations import closure
from engine.appearance.closures import closure_trade
from engine.errors import GlassbenchError
from engine.model.design import CAP_KINDS, CAP_MATERIALS
from widgets import edit_fields as ef

CAP_WORDS = closure.CAP_WORDS
MATERIAL_WORDS = {"metal": "Metal (lacquered aluminium)", "plastic": "Plastic"}


class CapPanel(QWidget):
    """Edits ``design.cap`` through ``editor``."""

    #: The design fields the panel shows (it follows the scene for them itself).
    FIELDS = frozenset({"cap", "shape"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.kind = QComboBox()
        for kind in ("none",) + CAP_KINDS:
            self.kind.addItem(CAP_WORDS[kind], kind)
        self.kind.setToolTip("The closure on the finish; its size follows the neck")
        self.material = QComboBox()
        for m in CAP_MATERIALS:
            self.material.addItem(MATERIAL_WORDS[m], m)
        self.color = ef.LinearColorButton()
        self.color.setToolTip("Metal: the lacquer's tint over aluminium; plastic: its colour")
        self.cap_height = ef.spin(0, 300, 1, 0.5, " mm", "Height from the top to the skirt's edge "
                              "(cork: its length); 0 takes the kind's standard")
        self.count = ef.int_spin(0, 720, "Knurl ridges, crown flutes or lugs; 0 takes the kind's standard")
        for field in (self.cap_height, self.count):
            field.setSpecialValueText("standard")  # 0: the kind's standard
        self.capsule = QCheckBox("Capsule over the cork")
        self.size_text = QLabel("")
        self.size_text.setWordWrap(True)
        ef.compact(self.kind, self.material)
        ef.form_page(self, (("Closure", self.kind), ("Material", self.material), ("Colour", self.color),
                            ("Height", self.cap_height), ("Count / lugs", self.count), self.capsule,
                            self.size_text))
        self.kind.currentIndexChanged.connect(lambda _: self.set_kind(self.kind.currentData()))
        self.material.currentIndexChanged.connect(lambda _: self._edit("Cap material", None,
                                                                       material=self.material.currentData()))
        self.color.clicked.connect(self._pick_color)
        self.cap_height.valueChanged.connect(lambda v: self._edit("Cap height", "cap-height", height=v))
        self.count.valueChanged.connect(lambda v: self._edit("Cap count", "cap-count", count=v))
        self.capsule.toggled.connect(lambda on: self._edit("Cork capsule", None, capsule=on))
        ef.follow(self, editor, self.FIELDS, lambda d, a: self.refresh(d))

    def choose_color(self, initial_linear, title: str):
        """Ask for a colour (linear RGB) or ``None``; tests replace this method."""
        return ef.ask_linear_color(self, initial_linear, title)

    def set_kind(self, kind: str) -> bool:
        return self._apply(lambda: closure.set_cap(self.editor.design, kind))

    def _edit(self, text, key, **fields) -> bool:
        return self._apply(lambda: closure.edit_cap(self.editor.design, text, **fields), key)

    def _apply(self, make, key=None) -> bool:
        """Apply the operation's :class:`~engine.operations.edit.Edit` as one undoable step
        (``None``: nothing to do); an operation's refusal goes the editor's way, so the panel
        (which follows refusals) shows the model again, not what was asked for."""
        try:
            edit = make()
        except (GlassbenchError, ValueError) as exc:
            self.editor.refused.emit(str(exc))  # the same path as the editor's own refusals
            edit, ok = None, False
        else:
            ok = edit is not None and self.editor.apply(edit.text, key, cap=edit.design.cap)
        return ok  # (a refusal re-shows the model: the panel follows the editor's refusals)

    def _pick_color(self):
        cap = self.editor.design.cap
        if cap is not None:
            rgb = self.choose_color(cap.color, "Cap colour")
            if rgb is not None:
                self._edit("Cap colour", None, color=tuple(rgb))

    def refresh(self, design):
        widgets = (self.kind, self.material, self.cap_height, self.count, self.capsule)
        blockers = [QSignalBlocker(w) for w in widgets]
        cap = design.cap
        self.kind.setCurrentIndex(self.kind.findData(cap.kind if cap is not None else "none"))
        for w in (self.material, self.color, self.cap_height, self.count, self.capsule):
            w.setEnabled(cap is not None)
        if cap is not None:
            self.material.setCurrentIndex(self.material.findData(cap.material))
            self.color.set_linear(cap.color)
            self.cap_height.setValue(cap.height)
            self.count.setValue(cap.count)
            self.capsule.setChecked(cap.capsule)
            self.capsule.setEnabled(cap.kind == "cork")
        try:
            info, overall = closure_trade(design)
        except (GlassbenchError, ValueError, ArithmeticError) as exc:
            info, overall = None, None
            self.size_text.setText(f"The closure does not fit: {exc}")
        else:
            self.size_text.setText("No closure" if info is None else
                                   f"{info['diameter_mm']:.1f} mm across, {info['height_mm']:.1f} mm high; "
                                   f"overall height {overall:.1f} mm")
        del blockers


__all__ = ["CapPanel"]
