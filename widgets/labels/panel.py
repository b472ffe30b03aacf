"""The labels panel: the labels on the bottle, and the parts that edit the selected one.

Design rule: the panel holds the list (add, remove, reorder) and composes its parts, one module
each: :mod:`~widgets.labels.placement`, :mod:`~widgets.labels.preview` (artwork and die-line),
:mod:`~widgets.labels.sheet` (coefficients and faces), :mod:`~widgets.labels.regions`. The parts
know the editor and the selected label (:class:`~widgets.labels.selection.SelectedLabel`, which
the list writes), not the panel; the panel shows the selected label in them. Every edit
is a named operation of :mod:`engine.operations.labels` (the one the command line uses) or a
changed field of the selected label, applied as ``editor.apply(text, merge_key, labels=...,
assets=...)``: one undoable step, validated by the engine (a label that leaves the wall is refused
with its message). The panel follows the scene itself (:func:`widgets.edit_fields.follow`, the
fields in :data:`LabelsPanel.FIELDS`) and writes the model into its widgets with their signals
blocked. Images are read and decoded before anything changes, so a corrupt, truncated or huge
file is refused with the engine's one-line message and the design stays as it was. A new label
(button, or an image dropped onto the preview) is sized from its artwork's aspect and placed
where the drop point meets the bottle (:func:`app.engine_bridge.surface_point`); without a point,
or when the point misses the glass, it faces the camera at the body's mid-height. Shift+drag on
the preview moves the selected label (:meth:`LabelsPanel.place_selected`).
"""
from __future__ import annotations

import dataclasses
import os

from PySide6.QtCore import QSignalBlocker, Signal
from PySide6.QtWidgets import QFileDialog, QHBoxLayout, QLabel, QListWidget, QPushButton, QVBoxLayout, QWidget

from engine.appearance import images
from engine.appearance.frame import Placement, label_frame
from engine.errors import GlassbenchError
from engine.operations import labels as ops
from widgets import edit_fields as ef
from widgets.labels.placement import PlacementBox
from widgets.labels.preview import PreviewBox
from widgets.labels.regions import RegionsBox
from widgets.labels.selection import SelectedLabel
from widgets.labels.sheet import SheetBox


def is_image_path(path: str) -> bool:
    return os.path.splitext(path)[1].lower() in images.EXTENSIONS


def read_checked_image(path: str) -> bytes:
    """The bytes of an image file checked and decoded once (``ArtworkError``/``OSError``)."""
    data = images.read_image_file(path)
    images.decode_image(data, os.path.basename(path))
    return data


class LabelsPanel(QWidget):
    """Edit ``design.labels`` through ``editor`` (an ``app.commands.DesignEditor``).

    Signals
    -------
    message(str)
        Something to tell the designer (a refused image); the window shows it in the status bar.
    """

    message = Signal(str)
    #: The design fields the panel shows (a print on the cap follows the cap, a label the wall).
    FIELDS = frozenset({"labels", "shape", "assets", "cap"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.selection = SelectedLabel(editor, self)
        self.list = QListWidget()
        self.list.setToolTip("The labels on the bottle; later ones lie on top where they overlap")
        self.list.setMaximumHeight(72)
        self.add_button = QPushButton("Add\u2026")
        self.add_button.setToolTip("Add a label with an artwork image (PNG, JPEG, TIFF, EXR), "
                                   "embedded in the project; you can also drop an image on the preview")
        self.remove_button = QPushButton("Remove")
        self.up_button = QPushButton("\u2191")
        self.up_button.setToolTip("Earlier in the overlap order (under the labels after it)")
        self.down_button = QPushButton("\u2193")
        self.down_button.setToolTip("Later in the overlap order (on top of the labels before it)")
        self.problem = QLabel("")
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #b00020")
        buttons = QHBoxLayout()
        for b in (self.add_button, self.remove_button, self.up_button, self.down_button):
            buttons.addWidget(b)
        for b in (self.up_button, self.down_button):
            b.setMaximumWidth(40)
        self.preview = PreviewBox(editor, self.selection)
        self.placement = PlacementBox(editor, self.selection)
        # (the colour asked for at the click: tests replace choose_color on the panel)
        self.sheet = SheetBox(editor, self.selection, self.ask_image, lambda rgb, title: self.choose_color(rgb, title))
        self.finishes = RegionsBox(editor, self.selection, self.preview, self.ask_image)
        self.details = QWidget()
        dl = QVBoxLayout(self.details)
        dl.setContentsMargins(0, 0, 0, 0)
        for box in (self.placement, self.preview, self.sheet, self.finishes):
            dl.addWidget(box)
        layout = QVBoxLayout(self)
        layout.addWidget(self.list)
        layout.addLayout(buttons)
        layout.addWidget(self.problem)
        layout.addWidget(self.details)
        layout.addStretch(1)
        self.list.currentRowChanged.connect(lambda _: self.refresh(self.editor.design, self.editor.scene.assets))
        self.selection.problem.connect(self._say)
        self.add_button.clicked.connect(lambda: self.add_label())
        self.remove_button.clicked.connect(self.remove_label)
        self.up_button.clicked.connect(lambda: self.move_label(-1))
        self.down_button.clicked.connect(lambda: self.move_label(1))
        self.preview.artwork.picked.connect(self.finishes.pick_key)
        ef.follow(self, editor, self.FIELDS, self.refresh)

    # ---------------------------------------------------------------- replaceable asks
    def choose_image_file(self, title: str) -> str | None:
        """Ask for an image file; tests replace this method."""
        path, _ = QFileDialog.getOpenFileName(self, title, "", ef.IMAGE_FILTER)
        return path or None

    def choose_color(self, initial_linear, title: str):
        """Ask for a colour (linear RGB) or ``None``; tests replace this method."""
        return ef.ask_linear_color(self, initial_linear, title)

    # ---------------------------------------------------------------- what to say
    def _say(self, text: str):
        """Show why an edit was refused (here, and in the status bar); an empty text clears it."""
        self.problem.setText(text)
        if text:
            self.message.emit(f"Refused: {text}")

    def image(self, path: str | None, title: str):
        """``(path, bytes)`` of a checked image file (asked for when ``path`` is ``None``);
        ``bytes`` is ``None`` when none was chosen or it was refused (and said why)."""
        path = path or self.choose_image_file(title)
        if not path:
            return path, None
        try:
            return path, read_checked_image(path)
        except (GlassbenchError, OSError, ValueError) as exc:
            self.selection.refuse(str(exc))
            return path, None

    def ask_image(self, title: str) -> bytes | None:
        """The bytes of a checked image file the designer picks (``None``: none, or refused)."""
        return self.image(None, title)[1]

    # ----------------------------------------------------------------- labels
    def add_label(self, path: str | None = None, at=None) -> bool:
        """Add a label with the image at ``path`` (asked for when ``None``) as its front, at
        ``at`` (``(z_mm, angle_deg)``) or facing the camera; one undo step."""
        path, data = self.image(path, "Label artwork")
        if data is None:
            return False
        return self.selection.apply(ops.add_label(self.editor.design, self.editor.scene.assets, data,
                                                  filename=path, at=at))

    def remove_label(self) -> bool:
        i = self.selection.index
        return i >= 0 and self.selection.apply(ops.remove_label(self.editor.design, i))

    def move_label(self, step: int) -> bool:
        """Move the selected label ``step`` places in the overlap order."""
        return self.selection.apply(ops.move_label(self.editor.design, self.selection.index, step))

    def place_selected(self, at, merge_key=None) -> bool:
        """Move the selected label's centre to ``at`` (``(z_mm, angle_deg)`` on the wall);
        ``merge_key`` makes a drag's moves one undo step. A print on the cap is placed by its
        numbers only."""
        lab = self.selection.label
        if lab is None or lab.surface != "wall":
            return False
        z, angle = (round(float(v), 1) for v in at)
        return self.selection.put("Move label", merge_key, dataclasses.replace(lab, z_mm=z, angle_deg=angle))

    def size_selected(self, at, merge_key=None) -> bool:
        """Size the selected label, kept centred, so that a corner lies at ``at`` (``(z_mm,
        angle_deg)`` on the surface: :meth:`engine.appearance.frame.LabelFrame.size_to`);
        ``merge_key`` makes a drag's sizes one undo step. At least 1 mm a side."""
        lab = self.selection.label
        if lab is None or lab.surface != "wall":
            return False
        try:
            frame = label_frame(self.editor.design.shape, Placement.of(lab))
            height, width = frame.size_to(*at)
        except (GlassbenchError, ValueError, ArithmeticError):
            return False
        height, width = (round(max(1.0, v), 1) for v in (height, width))
        return self.selection.put("Size label", merge_key, dataclasses.replace(lab, height_mm=height, width_mm=width))

    # ------------------------------------------------------------------ model -> view
    def refresh(self, design, assets=None):
        """Show ``design``'s labels, select the list's row (or the one an edit asked for) and show
        that label in every part (signals blocked)."""
        assets = self.editor.scene.assets if assets is None else assets
        after_edit = self.selection.after_edit
        blocker = QSignalBlocker(self.list)
        ef.show_rows(self.list, [lab.name for lab in design.labels],
                     self.list.currentRow() if after_edit is None else after_edit)
        del blocker
        self.selection.select(self.list.currentRow())
        lab = self.selection.label
        self.details.setEnabled(lab is not None)
        for b in (self.remove_button, self.up_button, self.down_button):
            b.setEnabled(lab is not None)
        if lab is None:
            self.preview.clear()
            self.finishes.clear()
            return
        self.placement.show_label(lab)
        self.sheet.show_label(lab)
        self.preview.show_label(lab, assets)
        self.finishes.show_label(lab)

    def dieline_pending(self) -> bool:
        """Whether the die-line shown is not yet that of the selected label as it is now."""
        return self.preview.timer.isActive()

    def shutdown(self):
        self.preview.timer.stop()
