"""Where the selected label lies: its name, the surface, its centre and its size.

Design rule: a part of the labels panel (:mod:`widgets.labels.panel`), made with the editor and
the selected label (:class:`~widgets.labels.selection.SelectedLabel`): it shows one label's
placement with its signals blocked and turns each field's edit into one undoable edit of the
selected label (``label-INDEX-FIELD`` merge keys, so scrolling a field is one step).
"""
from __future__ import annotations

from PySide6.QtCore import QSignalBlocker
from PySide6.QtWidgets import QComboBox, QFormLayout, QGroupBox, QLineEdit

from engine.errors import GlassbenchError
from engine.operations import labels as ops
from widgets import edit_fields as ef

#: The designer's words for where a label lies (``Label.surface``).
SURFACE_WORDS = {"wall": "bottle", "cap-top": "cap top", "cap-skirt": "cap skirt"}


class PlacementBox(QGroupBox):
    """The placement fields of the label ``selection`` (a
    :class:`~widgets.labels.selection.SelectedLabel` of ``editor``'s design)."""

    def __init__(self, editor, selection):
        super().__init__("Placement (on the surface)")
        self.editor = editor
        self.selection = selection
        self.name = QLineEdit()
        self.name.setToolTip("The label's name (unique in the design; the command line uses it)")
        self.surface = QComboBox()
        for key, text in SURFACE_WORDS.items():
            self.surface.addItem(text, key)
        self.surface.setToolTip("Where the label lies: on the bottle's wall, or printed on the "
                                "cap's flat top or its skirt (the design needs a cap)")
        self.z_mm = ef.spin(0, 5000, 1, 1.0, " mm", "Height of the label's centre above the standing "
                            "plane (on the cap's skirt: above the skirt's lower edge)")
        self.cap_x_mm = ef.spin(-500, 500, 1, 0.5, " mm", "Cap top: the print's centre, x from the axis")
        self.cap_y_mm = ef.spin(-500, 500, 1, 0.5, " mm", "Cap top: the print's centre, y from the axis")
        self.angle_deg = ef.spin(-360, 360, 1, 5.0, " \u00b0", "Azimuth of the label's centre about the "
                                 "axis, from +x towards +y (on the cap's top: where its reader "
                                 "stands, its bottom edge towards them)")
        self.height_mm = ef.spin(1, 5000, 1, 1.0, " mm", "Height along the wall (slant)")
        self.width_mm = ef.spin(1, 5000, 1, 1.0, " mm", "Arc length around the girth at mid-height")
        form = QFormLayout(self)
        form.addRow("Name", self.name)
        form.addRow("On", self.surface)
        for text, w in (("Centre height", self.z_mm), ("Centre x", self.cap_x_mm), ("Centre y", self.cap_y_mm),
                        ("Centre angle", self.angle_deg), ("Height", self.height_mm), ("Width", self.width_mm)):
            form.addRow(text, w)
        self.name.editingFinished.connect(self._rename)
        self.surface.currentIndexChanged.connect(lambda _: self.choose_surface(self.surface.currentData()))
        for w, key, text in ((self.z_mm, "z_mm", "Label height"), (self.angle_deg, "angle_deg", "Label angle"),
                             (self.cap_x_mm, "cap_x_mm", "Label centre x"),
                             (self.cap_y_mm, "cap_y_mm", "Label centre y"),
                             (self.height_mm, "height_mm", "Label size"), (self.width_mm, "width_mm", "Label width")):
            w.valueChanged.connect(lambda v, key=key, text=text: selection.edit_field(text, key, **{key: v}))

    def _rename(self):
        lab = self.selection.label
        if lab is not None and self.name.text() != lab.name:
            self.selection.edit_field("Rename label", "name", name=self.name.text())

    def choose_surface(self, surface: str) -> bool:
        """Put the selected label on ``surface`` (:data:`SURFACE_WORDS`' keys), centred there
        and shrunk to fit (aspect kept); one undo step, refused by the engine with its message
        (a design without a cap, a crown's skirt)."""
        lab = self.selection.label
        if lab is None or surface is None or surface == lab.surface:
            return False
        try:
            moved = ops.placed_on(self.editor.design, lab, surface)
        except (GlassbenchError, ValueError) as exc:
            self.selection.refuse(str(exc))
            self.show_label(lab)  # the surface it is still on
            return False
        return self.selection.put(f"Label on the {SURFACE_WORDS[surface]}", None, moved)

    def show_label(self, lab) -> None:
        """Show label ``lab`` (signals blocked: nothing echoes back)."""
        widgets = (self.name, self.surface, self.z_mm, self.cap_x_mm, self.cap_y_mm, self.angle_deg,
                   self.height_mm, self.width_mm)
        blockers = [QSignalBlocker(w) for w in widgets]
        self.name.setText(lab.name)
        self.surface.setCurrentIndex(max(0, self.surface.findData(lab.surface)))
        self.z_mm.setEnabled(lab.surface != "cap-top")
        for w in (self.cap_x_mm, self.cap_y_mm):
            w.setEnabled(lab.surface == "cap-top")
        for w, v in ((self.z_mm, lab.z_mm), (self.cap_x_mm, lab.cap_x_mm), (self.cap_y_mm, lab.cap_y_mm),
                     (self.angle_deg, lab.angle_deg), (self.height_mm, lab.height_mm), (self.width_mm, lab.width_mm)):
            w.setValue(v)
        del blockers
