"""The selected label's sheet and faces: paper or film coefficients, front and back prints.

Design rule: a part of the labels panel (:mod:`widgets.labels.panel`), made with the editor and
the selected label (:class:`~widgets.labels.selection.SelectedLabel`): shows one label with
its signals blocked; each edit is one of the named operations of
:mod:`engine.operations.labels` (a face's image or plain colour) or a field of the label,
applied to the selected label as one undoable step. Colours are linear RGB in the model, sRGB on screen
(:class:`widgets.edit_fields.LinearColorButton`).
"""
from __future__ import annotations

import dataclasses

from PySide6.QtCore import QSignalBlocker
from PySide6.QtWidgets import QComboBox, QFormLayout, QGroupBox, QHBoxLayout, QLabel, QPushButton

from engine.appearance import presets
from engine.errors import GlassbenchError
from engine.operations import labels as ops
from widgets import edit_fields as ef


class SheetBox(QGroupBox):
    """The sheet fields and the two faces of the label ``selection`` (a
    :class:`~widgets.labels.selection.SelectedLabel` of ``editor``'s design). ``ask_image(title)``
    asks for a checked image (its bytes, ``None``: none), ``ask_color(linear, title)`` for a
    colour (linear RGB, ``None``: cancelled)."""

    def __init__(self, editor, selection, ask_image, ask_color):
        super().__init__("Sheet")
        self.editor = editor
        self.selection = selection
        self.ask_image = ask_image
        self.ask_color = ask_color
        self.sheet = QComboBox()
        self.sheet.addItem("(custom)", None)
        for name in presets.SHEET_PRESETS:
            self.sheet.addItem(name, name)
        self.sheet.setToolTip("Coefficient sets of typical papers and films")
        ef.compact(self.sheet)
        self.diffuse = ef.spin(0, 1, 3, 0.01, tip="Diffuse reflectance K: multiplies the face colour")
        self.specular = ef.spin(0, 1, 3, 0.01, tip="Weight of the clear coat's highlight")
        self.transmission = ef.spin(0, 1, 3, 0.01, tip="Diffuse transmission of the sheet "
                                    "(diffuse + transmission at most 1)")
        self.front_image = QPushButton("Image\u2026")
        self.front_color = ef.LinearColorButton()
        self.back_image = QPushButton("Image\u2026")
        self.back_color = ef.LinearColorButton()
        self.front_text, self.back_text = QLabel(""), QLabel("")
        for b, side in ((self.front_image, "front"), (self.back_image, "back")):
            b.setToolTip(f"Print the {side} with an image")
        self.front_color.setToolTip("The front as a plain colour (no image)")
        self.back_color.setToolTip("The back as a plain colour (no image): seen through the bottle")
        form = QFormLayout(self)
        form.addRow("Preset", self.sheet)
        form.addRow("Diffuse", self.diffuse)
        form.addRow("Specular", self.specular)
        form.addRow("Transmission", self.transmission)
        for text, image, colour, shown in (("Front", self.front_image, self.front_color, self.front_text),
                                           ("Back", self.back_image, self.back_color, self.back_text)):
            row = QHBoxLayout()
            row.addWidget(image)
            row.addWidget(colour)
            form.addRow(text, row)
            form.addRow("", shown)
        for w, key, text in ((self.diffuse, "diffuse", "Label diffuse"), (self.specular, "specular", "Label specular"),
                             (self.transmission, "transmission", "Label transmission")):
            w.valueChanged.connect(lambda v, key=key, text=text: selection.edit_field(text, key, **{key: v}))
        self.sheet.currentIndexChanged.connect(lambda _: self._preset(self.sheet.currentData()))
        self.front_image.clicked.connect(lambda: self.choose_side_image("front"))
        self.back_image.clicked.connect(lambda: self.choose_side_image("back"))
        self.front_color.clicked.connect(lambda: self.choose_side_color("front"))
        self.back_color.clicked.connect(lambda: self.choose_side_color("back"))

    def _preset(self, name):
        lab = self.selection.label
        if name is None or lab is None:
            return
        d, s, t = presets.SHEET_PRESETS[name]
        self.selection.put(f"Sheet {name}", None, dataclasses.replace(lab, diffuse=d, specular=s, transmission=t))

    def choose_side_image(self, side: str) -> bool:
        """Print face ``side`` with an image the designer picks (checked before anything changes)."""
        selection = self.selection
        data = self.ask_image(f"Label {side}") if selection.label is not None else None
        if data is None:
            return False
        try:
            edit = ops.set_face_image(self.editor.design, self.editor.scene.assets, selection.index, side, data)
        except (GlassbenchError, ValueError) as exc:
            selection.refuse(str(exc))
            return False
        return selection.apply(edit)

    def choose_side_color(self, side: str) -> bool:
        """Face ``side`` as a plain colour the designer picks."""
        selection = self.selection
        lab = selection.label
        if lab is None:
            return False
        rgb = self.ask_color(getattr(lab, side).color, f"Label {side} colour")
        if rgb is None:
            return False
        return selection.apply(ops.set_face_colour(self.editor.design, selection.index, side, rgb))

    def show_label(self, lab) -> None:
        """Show label ``lab`` (signals blocked)."""
        blockers = [QSignalBlocker(w) for w in (self.sheet, self.diffuse, self.specular, self.transmission)]
        for w, v in ((self.diffuse, lab.diffuse), (self.specular, lab.specular), (self.transmission, lab.transmission)):
            w.setValue(v)
        sheet = next((n for n, v in presets.SHEET_PRESETS.items()
                      if v == (lab.diffuse, lab.specular, lab.transmission)), None)
        self.sheet.setCurrentIndex(max(0, self.sheet.findData(sheet)) if sheet else 0)
        for side, colour, text in (("front", self.front_color, self.front_text),
                                   ("back", self.back_color, self.back_text)):
            face = getattr(lab, side)
            colour.set_linear(face.color)
            text.setText(f"image {face.asset}" if face.asset else "plain colour")
        del blockers
