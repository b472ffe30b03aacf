"""The selected label's finish regions: foil, vinyl, emboss, varnish, keyed by colour or a mask.

Design rule: a part of the labels panel (:mod:`widgets.labels.panel`), made with the editor, the
selected label (:class:`~widgets.labels.selection.SelectedLabel`) and the artwork it keys
colours on (its sibling :class:`~widgets.labels.preview.PreviewBox`): it lists the label's
regions and edits the selected one; each edit replaces the selected label's ``regions``, one
undoable step. A key colour is picked on the artwork with the eyedropper (sRGB, as the designer
sees it); the artwork view outlines where the selected region applies
(:func:`engine.appearance.regions.region_map`).
"""
from __future__ import annotations

import dataclasses

import numpy as np
from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (QCheckBox, QComboBox, QFormLayout, QGroupBox, QHBoxLayout, QLabel,
                               QListWidget, QPushButton)

from engine.appearance import presets
from engine.appearance.regions import region_map
from engine.errors import GlassbenchError
from engine.model.design import FINISH_KINDS
from engine.operations import labels as ops
from widgets import edit_fields as ef

FINISH_WORDS = {"gold_foil": "Gold foil", "silver_foil": "Silver foil", "clear_vinyl": "Clear vinyl",
                "clear_vinyl_white": "Clear vinyl, white underprint", "emboss": "Emboss",
                "varnish": "Varnish"}


class RegionsBox(QGroupBox):
    """The finish regions of the label ``selection`` (a
    :class:`~widgets.labels.selection.SelectedLabel` of ``editor``'s design), keyed on the
    artwork ``preview`` shows; ``ask_image(title)`` asks for a checked mask image (its bytes,
    ``None``: none)."""

    def __init__(self, editor, selection, preview, ask_image):
        super().__init__("Finish regions")
        self.editor = editor
        self.selection = selection
        self.preview = preview
        self.ask_image = ask_image
        self.select = None  # the row to show after an add or remove
        self.regions = QListWidget()
        self.regions.setMaximumHeight(60)
        self.regions.setToolTip("Finish regions of the front; later ones win where they overlap")
        self.region_preset = QComboBox()
        for name in presets.FINISH_PRESETS:
            self.region_preset.addItem(name, name)
        self.region_preset.setToolTip("The finish a new region gets, or the selected region takes")
        self.add_region = QPushButton("Add region")
        self.remove_region = QPushButton("Remove region")
        self.apply_preset = QPushButton("Apply preset")
        self.finish = QComboBox()
        for kind in FINISH_KINDS:
            self.finish.addItem(FINISH_WORDS[kind], kind)
        self.source = QComboBox()
        self.source.addItem("Chroma key", "chroma")
        self.source.addItem("Mask image", "mask")
        self.eyedropper = QCheckBox("Eyedropper")
        self.eyedropper.setToolTip("Click the artwork to make the colour under the pointer the "
                                   "region's key (Shift+click adds one)")
        self.keys_text = QLabel("")
        self.keys_text.setWordWrap(True)
        self.tolerance = ef.spin(0, 1, 3, 0.01, tip="How far (sRGB distance) a colour may be from a "
                                 "key and still belong to the region")
        self.mask_button = QPushButton("Mask image\u2026")
        self.mask_button.setToolTip("A separation image: where it is dark, the region applies")
        self.depth_mm = ef.spin(-2, 2, 2, 0.05, " mm", "Relief of an emboss (negative: debossed)")
        self.gloss = ef.spin(0, 1, 2, 0.05, tip="Smoothness: 0 matte .. 1 mirror")
        ef.compact(self.region_preset, self.finish, self.source)
        form = QFormLayout(self)
        form.addRow(self.regions)
        row = QHBoxLayout()
        row.addWidget(self.region_preset, 1)
        row.addWidget(self.add_region)
        form.addRow(row)
        row = QHBoxLayout()
        row.addWidget(self.apply_preset)
        row.addWidget(self.remove_region)
        form.addRow(row)
        form.addRow("Finish", self.finish)
        form.addRow("From", self.source)
        form.addRow(self.eyedropper, self.keys_text)
        form.addRow("Tolerance", self.tolerance)
        form.addRow(self.mask_button)
        form.addRow("Emboss depth", self.depth_mm)
        form.addRow("Gloss", self.gloss)
        self.regions.currentRowChanged.connect(lambda _: self.show_region())
        self.eyedropper.toggled.connect(
            lambda on: preview.artwork.setCursor(Qt.CrossCursor if on else Qt.ArrowCursor))
        self.add_region.clicked.connect(lambda: self.add_finish_region(self.region_preset.currentData()))
        self.remove_region.clicked.connect(self.remove_finish_region)
        self.apply_preset.clicked.connect(lambda: self.apply_finish_preset(self.region_preset.currentData()))
        self.finish.currentIndexChanged.connect(lambda _: self.edit_region("Region finish", None,
                                                                            finish=self.finish.currentData()))
        self.source.currentIndexChanged.connect(lambda _: self._source_chosen(self.source.currentData()))
        self.tolerance.valueChanged.connect(lambda v: self.edit_region("Key tolerance", "tolerance", tolerance=v))
        self.depth_mm.valueChanged.connect(lambda v: self.edit_region("Emboss depth", "depth", depth_mm=v))
        self.gloss.valueChanged.connect(lambda v: self.edit_region("Region gloss", "gloss", gloss=v))
        self.mask_button.clicked.connect(self.choose_mask)

    @property
    def index(self) -> int:
        """The selected region of the selected label (-1: none)."""
        lab = self.selection.label
        k = self.regions.currentRow()
        return k if lab is not None and 0 <= k < len(lab.regions) else -1

    # ------------------------------------------------------------------ edits
    def _set_regions(self, text: str, key, regions: tuple, assets: dict | None = None, select=None) -> bool:
        selection = self.selection
        lab = selection.label
        if lab is None:
            return False
        self.select = select
        edit = ops.replace_label(self.editor.design, selection.index, dataclasses.replace(lab, regions=regions),
                                 text, assets)
        ok = selection.apply(edit, key)
        self.select = None
        return ok

    def edit_region(self, text: str, key, **fields) -> bool:
        """Change fields of the selected region (``key``: the merge key's last part)."""
        lab, k = self.selection.label, self.index
        if k < 0:
            return False
        region = dataclasses.replace(lab.regions[k], **fields)
        return self._set_regions(text, None if key is None else f"label-{self.selection.index}-region-{k}-{key}",
                                 ef.replaced(lab.regions, k, region))

    def _first_colour(self) -> tuple:
        """A starting key: the artwork's centre colour (sRGB), white without artwork."""
        px = self.preview.artwork.pixels
        if px is None:
            return (1.0, 1.0, 1.0)
        h, w = px.shape[:2]
        return tuple(float(v) / 255.0 for v in px[h // 2, w // 2, :3])

    def add_finish_region(self, preset: str | None) -> bool:
        lab = self.selection.label
        if lab is None or preset is None:
            return False
        region = presets.finish_preset(preset, keys=(self._first_colour(),))
        return self._set_regions(f"Add {preset}", None, lab.regions + (region,), select=len(lab.regions))

    def remove_finish_region(self) -> bool:
        k = self.index
        if k < 0:
            return False
        regions = ef.removed(self.selection.label.regions, k)
        return self._set_regions("Remove region", None, regions, select=min(k, len(regions) - 1))

    def apply_finish_preset(self, preset: str | None) -> bool:
        if preset is None or self.index < 0:
            return False
        p = presets.FINISH_PRESETS[preset]
        return self.edit_region(f"Finish {preset}", None, finish=p.finish, depth_mm=p.depth_mm, gloss=p.gloss)

    def _source_chosen(self, source: str):
        k = self.index
        if k < 0 or source == self.selection.label.regions[k].source:
            return
        region = self.selection.label.regions[k]
        if source == "mask" and region.mask_asset is None:
            if not self.choose_mask():
                self.show_region()
            return
        keys = region.keys or (self._first_colour(),)
        self.edit_region("Region from a chroma key" if source == "chroma" else "Region from a mask",
                         None, source=source, keys=keys)

    def pick_key(self, srgb: tuple, add: bool = False) -> bool:
        """The eyedropper: make ``srgb`` (0..1) the selected region's key (``add``: one more)."""
        k = self.index
        if not self.eyedropper.isChecked() or k < 0:
            return False
        region = self.selection.label.regions[k]
        key = tuple(round(v, 6) for v in srgb)
        keys = (region.keys + (key,)) if add and region.source == "chroma" else (key,)
        return self.edit_region("Pick key colour", None, source="chroma", keys=keys)

    def choose_mask(self) -> bool:
        k = self.index
        data = self.ask_image("Finish mask") if k >= 0 else None
        if data is None:
            return False
        lab = self.selection.label
        asset = ops.asset_name(lab.name, f"mask{k}", data, self.editor.scene.assets)
        region = dataclasses.replace(lab.regions[k], source="mask", mask_asset=asset)
        return self._set_regions("Region mask", None, ef.replaced(lab.regions, k, region), {asset: data})

    # ------------------------------------------------------------------ model -> view
    def show_label(self, lab) -> None:
        """List ``lab``'s regions (keeping the selection, or the one an edit asked for)."""
        blocker = QSignalBlocker(self.regions)
        names = [f"{r.name} ({FINISH_WORDS.get(r.finish, r.finish)})" for r in lab.regions]
        ef.show_rows(self.regions, names, self.regions.currentRow() if self.select is None else self.select)
        del blocker
        self.show_region()

    def clear(self) -> None:
        blocker = QSignalBlocker(self.regions)
        self.regions.clear()
        del blocker

    def show_region(self) -> None:
        """Show the selected region's fields, and where it applies on the artwork."""
        widgets = (self.finish, self.source, self.tolerance, self.depth_mm, self.gloss)
        blockers = [QSignalBlocker(w) for w in widgets]
        k = self.index
        for w in widgets + (self.keys_text, self.mask_button, self.remove_region, self.apply_preset,
                            self.eyedropper):
            w.setEnabled(k >= 0)
        if k >= 0:
            r = self.selection.label.regions[k]
            self.finish.setCurrentIndex(self.finish.findData(r.finish))
            self.source.setCurrentIndex(self.source.findData(r.source))
            self.tolerance.setValue(r.tolerance)
            self.depth_mm.setValue(r.depth_mm)
            self.depth_mm.setEnabled(r.finish == "emboss")
            self.gloss.setValue(r.gloss)
            if r.source == "chroma":
                self.keys_text.setText("keys: " + ", ".join(QColor.fromRgbF(*key).name() for key in r.keys))
            else:
                self.keys_text.setText(f"mask {r.mask_asset}")
            self.tolerance.setEnabled(r.source == "chroma")
        else:
            self.keys_text.setText("")
        del blockers
        lab = self.selection.label
        if lab is not None:
            self.preview.show_artwork(self._claimed(lab, k))

    def _claimed(self, lab, k: int):
        """Where region ``k`` of ``lab`` applies, at the artwork picture's size (``None``: nothing)."""
        art = self.preview.art
        if k < 0 or art is None:
            return None
        try:
            rmap = region_map(lab, self.editor.scene.assets)
        except (GlassbenchError, ValueError, KeyError):
            return None
        h, w = art.shape[:2]
        rows = np.arange(h) * rmap.shape[0] // h
        cols = np.arange(w) * rmap.shape[1] // w
        return rmap[rows[:, None], cols[None, :]] == k + 1
