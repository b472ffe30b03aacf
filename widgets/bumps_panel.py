"""Bump-tiles panel: relief bands on the glass (knurl, flutes, facets, threads, frosting, relief
images), each with its parameters and a small live picture of its pattern.

Design rule: edits become ``editor.apply(text, merge_key, bumps=...)`` (with ``assets=`` for a
relief image), one undoable step each, checked by the engine (a relief image that cannot be
used is refused with its message). New tiles and kind changes start from
:func:`engine.operations.tiles.new_tile`, the numbers ``glassbench bump add`` uses;
images go through :func:`~engine.operations.tiles.add_image_tile`, which checks them
first. The picture is :func:`engine.tracer.swatch.swatch_rgb` of the selected tile, drawn
again after each change of the design's tiles. A thread says how it is drawn (relief or true
geometry, :func:`engine.appearance.bands.thread_drawings`) and why, under its choice.
"""
from __future__ import annotations

import dataclasses

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
from engine.operations.labels import assets_in_use

BUMP_WORDS = {"knurl": "Knurl", "stipple": "Stipple (dots)", "flutes": "Flutes", "facets": "Facets",
              "diamond": "Diamond cut", "thread": "Screw thread", "frosted": "Frosted / satin",
              "height_map": "Image: height map", "colour_code": "Image: colour code",
              "normal_gl": "Image: normal map (OpenGL)", "normal_dx": "Image: normal map (DirectX)",
              "emboss": "Image: embossed logo"}
ON_WORDS = {"bottle": "Bottle", "cap": "Cap"}
#: A thread's ``geometry`` choices as the panel names them.
GEOMETRY_WORDS = {"auto": "Auto (by the wall)", "relief": "Relief (normal only)", "true": "True geometry"}
#: Swatch size (px).
SWATCH_PX = 128


def default_band(design, kind: str) -> tuple[float, float]:
    """Where a new tile of ``kind`` goes (mm): a thread on the finish, frosting over the body,
    a logo at mid-height, other patterns on the heel."""
    top = float(design.shape.z_top)
    if kind == "thread":
        return round(top - 14.0, 1), round(top - 3.0, 1)
    if kind == "frosted":
        return round(0.05 * top, 1), round(0.6 * top, 1)
    if kind in IMAGE_BUMPS:
        return round(0.3 * top, 1), round(0.45 * top, 1)
    return 2.0, round(min(12.0, 0.2 * top), 1)


def default_cap_band(design) -> tuple[float, float] | None:
    """Where a tile moved onto the cap goes (mm above the lower edge of its straight skirt):
    the skirt less a sixth at each end (clear of the rounded edges); ``None`` without a cap
    or a straight skirt."""
    from engine.appearance.bands import cap_band
    band = cap_band(design, 0.0, 1e9) if design.cap is not None else None
    if band is None:
        return None
    height = band[2] - band[1]
    return round(height / 6.0, 1), round(5.0 * height / 6.0, 1)


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
        ef.follow(self, editor.scene, self.FIELDS, self.refresh)

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

    def _apply(self, text, key, bumps, assets=None, select=None) -> bool:
        self.problem.setText("")
        self._select = select  # the refresh that follows shows this row
        current = self.editor.design
        used = assets_in_use(dataclasses.replace(current, bumps=bumps)) | set(assets or {})
        gone = {t.asset: None for t in current.bumps if t.asset is not None and t.asset not in used}
        ok = self.editor.apply(text, key, assets={**gone, **(assets or {})}, bumps=bumps)
        self._select = None
        if not ok:
            self.refresh(self.editor.design)
        return ok

    def _edit(self, text, key, **fields) -> bool:
        tile = self.tile
        if tile is None or all(getattr(tile, k) == v for k, v in fields.items()):
            return False
        new = dataclasses.replace(tile, **fields)
        return self._apply(text, None if key is None else f"bump-{self.index}-{key}",
                           ef.replaced(self.editor.design.bumps, self.index, new))

    def _image_tile(self, kind, z0, z1, **given):
        """``(tile, {asset: bytes})`` of an image kind, asking for the image; ``None`` if none."""
        path = self.choose_image_file("Relief image")
        if not path:
            return None
        try:
            data = read_bounded(path, MAX_ARTWORK_BYTES, "relief image")
            tile, name = tiles.add_image_tile(self.editor.design, self.editor.scene.assets, kind,
                                                      path, data, z0, z1, **given)
        except (GlassbenchError, OSError, ValueError) as exc:
            self._refuse(str(exc))
            return None
        return tile, {name: data}

    def add_tile(self, kind: str) -> bool:
        """Add a tile of ``kind`` on its default band (an image kind asks for its image)."""
        design = self.editor.design
        z0, z1 = default_band(design, kind)
        assets = None
        if kind in IMAGE_BUMPS:
            made = self._image_tile(kind, z0, z1)
            if made is None:
                return False
            tile, assets = made
        else:
            tile = tiles.new_tile(design, kind, z0, z1)
        bumps = design.bumps + (tile,)
        return self._apply(f"Add {BUMP_WORDS[kind].lower()}", None, bumps, assets, select=len(bumps) - 1)

    def remove_tile(self) -> bool:
        i = self.index
        if i < 0:
            return False
        bumps = ef.removed(self.editor.design.bumps, i)
        return self._apply("Remove tile", None, bumps, select=min(i, len(bumps) - 1))

    def set_kind(self, kind: str) -> bool:
        """Make the selected tile ``kind``, on the same band, with that kind's usual numbers."""
        tile = self.tile
        if tile is None or kind == tile.kind:
            return False
        given = {"angle_deg": tile.angle_deg, "inverted": tile.inverted}
        assets = None
        if kind in IMAGE_BUMPS and tile.asset is not None:
            new = tiles.new_tile(self.editor.design, kind, tile.z0, tile.z1, asset=tile.asset,
                                         name=tile.name, **given)
        elif kind in IMAGE_BUMPS:
            made = self._image_tile(kind, tile.z0, tile.z1, **given)
            if made is None:
                self.refresh(self.editor.design)
                return False
            new, assets = made
        else:
            new = tiles.new_tile(self.editor.design, kind, tile.z0, tile.z1, **given)
        return self._apply(f"Tile kind {BUMP_WORDS[kind].lower()}", None,
                           ef.replaced(self.editor.design.bumps, self.index, new), assets)

    def set_surface(self, on: str) -> bool:
        """Move the selected tile onto the glass or the cap's skirt (its default band there,
        its repeat sized for that girth); refused without a cap, or for a thread."""
        tile = self.tile
        if tile is None or on == tile.on:
            return False
        design = self.editor.design
        if on == "cap":
            band = default_cap_band(design)
            if tile.kind == "thread":
                why = "a thread belongs to the glass finish, not to the cap"
            elif band is None:
                why = "the design has no cap with a straight skirt: put one on in the Cap tab first"
            else:
                why = None
            if why is not None:
                self._refuse(why)
                self.refresh(design)
                return False
        else:
            band = default_band(design, tile.kind)
        keep = {f: getattr(tile, f) for f in ("name", "asset", "angle_deg", "inverted", "depth", "width",
                                              "sharpness", "alpha", "pitch", "width_deg")}
        new = tiles.new_tile(design, tile.kind, *band, on=on, **keep)
        return self._apply(f"Tile on the {on}", None, ef.replaced(design.bumps, self.index, new))

    def choose_tile_image(self) -> bool:
        tile = self.tile
        if tile is None or tile.kind not in IMAGE_BUMPS:
            return False
        made = self._image_tile(tile.kind, tile.z0, tile.z1)
        if made is None:
            return False
        new, assets = made
        new = dataclasses.replace(tile, asset=new.asset)
        return self._apply("Tile image", None, ef.replaced(self.editor.design.bumps, self.index, new), assets)

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
