"""Bump-tiles panel: relief bands on the glass (knurl, flutes, facets, threads, frosting, relief
images), each with its parameters and a small live picture of its pattern.

Design rule: every edit is an operation of :mod:`engine.operations.tiles` (the ones
``glassbench bump`` calls: the same numbers for a new tile, the same refusals in the same words,
an image no tile uses leaving the project), applied as one undoable step
(``editor.apply(text, merge_key, bumps=..., assets=...)``); a refusal shows its message. The picture is :func:`engine.tracer.swatch.swatch_rgb` of the selected tile, drawn
again after each change of the design's tiles. A thread says how it is drawn (relief or true
geometry, :func:`engine.appearance.bands.thread_drawings`) and why, under its choice.
"""
from __future__ import annotations


import numpy as np
from PySide6.QtCore import QSignalBlocker, Qt, Signal
from PySide6.QtGui import QPixmap
from PySide6.QtWidgets import (QCheckBox, QComboBox, QFileDialog, QFormLayout, QGroupBox,
                               QHBoxLayout, QLabel, QLineEdit, QListWidget, QPushButton,
                               QVBoxLayout, QWidget)

from engine.operations import tiles
from engine.tracer import swatch
from engine.appearance.bands import thread_drawings
from engine.errors import GlassbenchError
from engine.io.read import read_bounded
from engine.limits import MAX_ARTWORK_BYTES
from engine.model.design import BUMP_KINDS, BUMP_SURFACES, IMAGE_BUMPS
from widgets import edit_fields as ef

BUMP_WORDS = tiles.KIND_WORDS
ON_WORDS = {"bottle": "Bottle", "cap": "Cap"}
#: A thread's ``geometry`` choices as the panel names them.
GEOMETRY_WORDS = {"auto": "Auto (by the wall)", "relief": "Relief (normal only)", "true": "True geometry"}
#: Swatch size (px).
SWATCH_PX = 128


class BumpsPanel(QWidget):
    """Edits ``design.bumps`` through ``editor``; ``message`` tells the window of a refusal."""

    message = Signal(str)

    #: The design fields the panel shows (it follows the scene for them itself).
    FIELDS = frozenset({"bumps", "shape", "assets"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.swatch_pixels: np.ndarray | None = None
        self._select = None
        self.list = QListWidget()
        self.list.setMaximumHeight(SWATCH_PX)
        self.list.setToolTip("Relief bands on the glass")
        self.add_kind = QComboBox()
        for kind in BUMP_KINDS:
            self.add_kind.addItem(BUMP_WORDS[kind], kind)
        self.add_button = QPushButton("Add")
        self.add_button.setToolTip("Add a tile of the chosen kind (an image kind asks for its image)")
        self.remove_button = QPushButton("Remove")
        self.problem = QLabel("")
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #b00020")
        self.swatch = QLabel()
        self.swatch.setFixedSize(SWATCH_PX, SWATCH_PX)
        self.swatch.setAlignment(Qt.AlignCenter)
        self.swatch.setToolTip("The pattern's relief, lit: about three repeats around, the band's height")

        self.kind = QComboBox()
        for kind in BUMP_KINDS:
            self.kind.addItem(BUMP_WORDS[kind], kind)
        self.kind.setToolTip("Changing the kind starts from that kind's usual numbers")
        self.name = QLineEdit()
        self.on = QComboBox()
        for on in BUMP_SURFACES:
            self.on.addItem(ON_WORDS[on], on)
        self.on.setToolTip("The glass, or the cap's straight skirt (heights then measured from its lower "
                           "edge, so the band follows the cap)")
        self.z0 = ef.spin(-5000, 5000, 1, 1.0, " mm", "Bottom of the band (height above the standing plane)")
        self.z1 = ef.spin(-5000, 5000, 1, 1.0, " mm", "Top of the band")
        self.repeat = ef.int_spin(1, 4096, "Repeats of the pattern around the girth")
        self.depth_mm = ef.spin(0, 10, 2, 0.05, " mm", "Size of the relief (cut kinds go in, raised ones out)")
        self.angle = ef.spin(-360, 360, 1, 5.0, " \u00b0", "Turn of the pattern about the axis")
        self.pitch = ef.spin(0, 100, 2, 0.1, " mm", "Vertical period: rows of knurl/dots, thread pitch "
                             "(0: square cells / the finish standard's)")
        self.ridge_width = ef.spin(0, 1, 2, 0.05, tip="Flute, dot or groove width as a fraction of a period; "
                             "knurl: 0 diamond .. 1 straight; emboss: bevel")
        self.sharpness = ef.spin(0, 1, 2, 0.05, tip="How crisp ridges and edges are")
        self.alpha = ef.spin(0.02, 0.5, 3, 0.01, tip="Frosting roughness (GGX): 0.02 satin .. 0.5 deep etch")
        self.finish = QLineEdit()
        self.finish.setToolTip("Thread standard, e.g. 28-400 (empty: the size nearest the neck, series 400)")
        self.image_button = QPushButton("Image\u2026")
        self.image_button.setToolTip("The relief image (PNG, JPEG, TIFF, EXR), embedded in the project")
        self.image_text = QLabel("")
        self.width_deg = ef.spin(0.1, 360, 1, 5.0, " \u00b0", "The angle one copy of the image spans")
        self.inverted = QCheckBox("Inverted")
        self.inverted.setToolTip("Press in instead of raise (or raise instead of cut)")
        self.drawn_as = QComboBox()
        for key, text in GEOMETRY_WORDS.items():
            self.drawn_as.addItem(text, key)
        self.drawn_as.setToolTip("How a thread is drawn: bending the shading normal (relief) or as real "
                                 "glass (true geometry, silhouette and path through the ridge); auto "
                                 "takes true geometry when the ridge is large against the wall")
        self.drawing = QLabel("")
        self.drawing.setWordWrap(True)
        self.drawing.setToolTip("How the thread is drawn now, and why")

        ef.compact(self.add_kind, self.kind)
        add_row = QHBoxLayout()
        add_row.addWidget(self.add_kind, 1)
        add_row.addWidget(self.add_button)
        add_row.addWidget(self.remove_button)
        self.form_box = QGroupBox("Tile")
        form = QFormLayout(self.form_box)
        form.addRow("Kind", self.kind)
        form.addRow("Name", self.name)
        form.addRow("On", self.on)
        self.rows = {}
        for text, w in (("From height", self.z0), ("To height", self.z1), ("Repeat", self.repeat),
                        ("Depth", self.depth_mm), ("Turn", self.angle), ("Pitch", self.pitch),
                        ("Width", self.ridge_width), ("Sharpness", self.sharpness), ("Roughness", self.alpha),
                        ("Finish", self.finish), ("Image", self.image_button), ("", self.image_text),
                        ("Image span", self.width_deg), ("Drawn as", self.drawn_as), ("", self.drawing)):
            form.addRow(text, w)
            self.rows[w] = text
        form.addRow(self.inverted)
        top = QHBoxLayout()
        top.addWidget(self.list, 1)
        top.addWidget(self.swatch)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addLayout(add_row)
        layout.addWidget(self.problem)
        layout.addWidget(self.form_box)
        layout.addStretch(1)

        self.list.currentRowChanged.connect(lambda _: self.refresh(self.editor.design))
        self.add_button.clicked.connect(lambda: self.add_tile(self.add_kind.currentData()))
        self.remove_button.clicked.connect(self.remove_tile)
        self.kind.currentIndexChanged.connect(lambda _: self.set_kind(self.kind.currentData()))
        self.on.currentIndexChanged.connect(lambda _: self.set_surface(self.on.currentData()))
        self.name.editingFinished.connect(lambda: self._edit("Rename tile", "name", name=self.name.text()))
        for w, key, text in ((self.z0, "z0", "Tile bottom"), (self.z1, "z1", "Tile top"),
                             (self.repeat, "repeat", "Tile repeat"), (self.depth_mm, "depth", "Tile depth"),
                             (self.angle, "angle_deg", "Tile turn"), (self.pitch, "pitch", "Tile pitch"),
                             (self.ridge_width, "width", "Tile width"), (self.sharpness, "sharpness", "Tile sharpness"),
                             (self.alpha, "alpha", "Frosting roughness"), (self.width_deg, "width_deg", "Image span")):
            w.valueChanged.connect(lambda v, key=key, text=text: self._edit(text, key, **{key: v}))
        self.finish.editingFinished.connect(lambda: self._edit("Thread finish", "finish",
                                                               finish=self.finish.text().strip()))
        self.inverted.toggled.connect(lambda on: self._edit("Invert tile", None, inverted=on))
        self.drawn_as.currentIndexChanged.connect(
            lambda _: self._edit("Thread drawing", None, geometry=self.drawn_as.currentData()))
        self.image_button.clicked.connect(self.choose_tile_image)
        ef.follow(self, editor, self.FIELDS, self.refresh)

    def choose_image_file(self, title: str) -> str | None:
        """Ask for a relief image; tests replace this method."""
        path, _ = QFileDialog.getOpenFileName(self, title, "", ef.IMAGE_FILTER)
        return path or None

    @property
    def index(self) -> int:
        i = self.list.currentRow()
        return i if 0 <= i < len(self.editor.design.bumps) else -1

    @property
    def tile(self):
        i = self.index
        return self.editor.design.bumps[i] if i >= 0 else None

    def _refuse(self, text: str):
        self.problem.setText(text)
        self.message.emit(f"Refused: {text}")

    def _apply(self, make, key=None) -> bool:
        """Apply the :class:`~engine.operations.edit.Edit` that ``make()`` returns (``None``:
        nothing to do) as one undoable step; an operation's refusal is shown, not raised."""
        self.problem.setText("")
        try:
            edit = make()
        except (GlassbenchError, OSError, ValueError) as exc:
            self._refuse(str(exc))
            self.refresh(self.editor.design)
            return False
        if edit is None:
            return False
        self._select = edit.select  # the refresh that follows shows this row
        ok = self.editor.apply(edit.text, key, assets=dict(edit.assets), bumps=edit.design.bumps)
        self._select = None
        return ok  # (a refused edit: the panel shows the model again, following the refusal)

    def _edit(self, text, key, **fields) -> bool:
        if self.tile is None:
            return False
        i = self.index
        return self._apply(lambda: tiles.edit_tile(self.editor.design, i, text, **fields),
                           None if key is None else f"bump-{i}-{key}")

    def _image(self) -> tuple[str, bytes] | None:
        """``(path, bytes)`` of a relief image the designer picks; ``None`` if none."""
        path = self.choose_image_file("Relief image")
        if not path:
            return None
        try:
            return path, read_bounded(path, MAX_ARTWORK_BYTES, "relief image")
        except (GlassbenchError, OSError) as exc:
            self._refuse(str(exc))
            return None

    def add_tile(self, kind: str) -> bool:
        """Add a tile of ``kind`` on its default band (an image kind asks for its image)."""
        picked = self._image() if kind in IMAGE_BUMPS else ("", None)
        if picked is None:
            return False
        path, data = picked
        return self._apply(lambda: tiles.add_tile(self.editor.design, self.editor.scene.assets, kind,
                                                  image=data, filename=path or "relief.png"))

    def remove_tile(self) -> bool:
        i = self.index
        return i >= 0 and self._apply(lambda: tiles.remove_tile(self.editor.design, i))

    def set_kind(self, kind: str) -> bool:
        """Make the selected tile ``kind``, on the same band, with that kind's usual numbers."""
        tile, i = self.tile, self.index
        if tile is None or kind == tile.kind:
            return False
        picked = ("", None)
        if kind in IMAGE_BUMPS and tile.asset is None:
            picked = self._image()
            if picked is None:
                self.refresh(self.editor.design)
                return False
        path, data = picked
        return self._apply(lambda: tiles.set_tile_kind(self.editor.design, self.editor.scene.assets, i, kind,
                                                       image=data, filename=path or "relief.png"))

    def set_surface(self, on: str) -> bool:
        """Move the selected tile onto the glass or the cap's skirt (its default band there,
        its repeat sized for that girth); refused without a cap, or for a thread."""
        i = self.index
        return i >= 0 and self._apply(lambda: tiles.set_tile_surface(self.editor.design, i, on))

    def choose_tile_image(self) -> bool:
        tile, i = self.tile, self.index
        if tile is None or tile.kind not in IMAGE_BUMPS:
            return False
        picked = self._image()
        if picked is None:
            return False
        path, data = picked
        return self._apply(lambda: tiles.set_tile_image(self.editor.design, self.editor.scene.assets, i,
                                                        path, data))

    # ------------------------------------------------------------------ model → view
    def refresh(self, design, assets=None):
        assets = self.editor.scene.assets if assets is None else assets
        fields = (self.z0, self.z1, self.repeat, self.depth_mm, self.angle, self.pitch, self.ridge_width,
                  self.sharpness, self.alpha, self.width_deg)
        blockers = [QSignalBlocker(w) for w in (self.list, self.kind, self.name, self.on, self.finish,
                                                self.inverted, self.drawn_as) + fields]
        ef.show_rows(self.list, [f"{t.name} ({BUMP_WORDS.get(t.kind, t.kind)}) {t.z0:g}..{t.z1:g} mm"
                                 + (" on the cap" if t.on == "cap" else "") for t in design.bumps],
                     self.list.currentRow() if self._select is None else self._select)
        tile = self.tile
        self.form_box.setEnabled(tile is not None)
        self.remove_button.setEnabled(tile is not None)
        if tile is None:
            self.swatch_pixels = None
            self.swatch.setPixmap(QPixmap())
            self.swatch.setText("no tile")
            del blockers
            return
        self.kind.setCurrentIndex(self.kind.findData(tile.kind))
        self.name.setText(tile.name)
        self.on.setCurrentIndex(self.on.findData(tile.on))
        above = "the lower edge of the cap's skirt" if tile.on == "cap" else "the standing plane"
        self.z0.setToolTip(f"Bottom of the band (height above {above})")
        for w, key in zip(fields, ("z0", "z1", "repeat", "depth", "angle_deg", "pitch", "width",
                                   "sharpness", "alpha", "width_deg")):
            w.setValue(getattr(tile, key))
        self.finish.setText(tile.finish)
        self.inverted.setChecked(tile.inverted)
        self.drawn_as.setCurrentIndex(self.drawn_as.findData(tile.geometry))
        self.drawing.setText(self._drawing_text(design))
        image = tile.kind in IMAGE_BUMPS
        for w, on in ((self.finish, tile.kind == "thread"), (self.drawn_as, tile.kind == "thread"),
                      (self.alpha, tile.kind == "frosted"),
                      (self.image_button, image), (self.width_deg, image),
                      (self.pitch, tile.kind in ("knurl", "stipple", "thread"))):
            w.setEnabled(on)
        self.image_text.setText(tile.asset or "")
        del blockers
        self._draw_swatch(design, tile, assets)

    def _drawing_text(self, design) -> str:
        """How the selected thread is drawn and why (empty for other kinds)."""
        try:
            drawing = thread_drawings(design)[self.index]
        except (GlassbenchError, ValueError, IndexError) as exc:
            return f"cannot tell how it is drawn: {exc}"
        return "" if drawing is None else f"Drawn as {drawing.reason}."

    def _draw_swatch(self, design, tile, assets):
        try:
            radius = tiles.band_radius(design, tile.z0, tile.z1, tile.on)
            self.swatch_pixels = swatch.swatch_rgb(tile, dict(assets), (SWATCH_PX, SWATCH_PX), radius)
        except (GlassbenchError, ValueError, KeyError, ArithmeticError) as exc:
            self.swatch_pixels = None
            self.swatch.setPixmap(QPixmap())
            self.swatch.setText("no preview")
            self.swatch.setToolTip(str(exc))
            return
        self.swatch.setPixmap(QPixmap.fromImage(ef.qimage_of(self.swatch_pixels)))


__all__ = ["BumpsPanel"]
