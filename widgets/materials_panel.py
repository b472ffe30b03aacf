"""Materials panel: glass IOR, tint and density; liquid IOR, colour and fill level.

Design rule: widget edits become ``editor.apply(label, merge_key, glass=...|liquid=...)``;
``refresh(design)`` writes the model into the widgets with their signals blocked. A colour is
given as glassmakers give it, by thickness: the colour white light takes through the
thickness beside it ("this amber through 10 mm"), and stored as the model's Beer-Lambert
absorption (``Glass.absorption``, ``Liquid.absorption``, 1/mm) by :mod:`engine.model.tint`. The
thickness is the tint's strength: the same colour through fewer millimetres is a stronger glass,
so changing it keeps the colour shown and changes the absorption (one undoable edit).
"""
from __future__ import annotations

import dataclasses

from PySide6.QtCore import QSignalBlocker
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (QCheckBox, QColorDialog, QComboBox, QDoubleSpinBox, QFormLayout,
                               QGroupBox, QHBoxLayout, QPushButton, QVBoxLayout, QWidget)

from engine.model import tint
from engine.model.design import Liquid
from widgets import edit_fields as ef
from widgets import words
from widgets.edit_fields import spin as _spin


class ColorButton(QPushButton):
    """A push button showing a colour swatch."""

    def set_rgb(self, rgb01):
        self.rgb = tuple(rgb01)
        c = QColor.fromRgbF(*self.rgb)
        self.setText(c.name())
        self.setStyleSheet(f"background-color: {c.name()}; color: {'black' if c.lightness() > 128 else 'white'}")


def _tint_controls(material: str) -> tuple[ColorButton, QDoubleSpinBox]:
    """A colour swatch and the thickness (mm) its colour is seen through, for ``material``."""
    button = ColorButton()
    button.setToolTip(f"The colour white light takes through the thickness beside it of the "
                      f"{material}; click to choose")
    thickness = _spin(0.1, 1000.0, 1, 1.0, " mm", f"The thickness of {material} the colour is seen "
                      f"through: fewer mm for the same colour is a stronger tint")
    thickness.setPrefix("through ")
    thickness.setValue(tint.DEFAULT_THICKNESS_MM)
    return button, thickness


def _tint_row(button: ColorButton, thickness: QDoubleSpinBox) -> QHBoxLayout:
    row = QHBoxLayout()
    row.addWidget(button, 1)
    row.addWidget(thickness)
    return row


class MaterialsPanel(QWidget):
    """Edits ``design.glass`` and ``design.liquid`` through ``editor``."""

    #: The design fields the panel shows (it follows the scene for them itself).
    FIELDS = frozenset({"glass", "liquid"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.trade_numbers: dict = {}  # the newest derived ones: a fill-mode switch keeps the level
        self.glass_ior = _spin(1.0, 3.0, 4, 0.01, tip="Refractive index of the glass (soda-lime: 1.52)")
        self.glass_density = _spin(0.5, 10.0, 3, 0.01, " g/cm\u00b3",
                                   "Density of the glass, for the glass weight (soda-lime: 2.52)")
        self.glass_tint, self.glass_thickness = _tint_controls("glass")
        self.filled = QCheckBox("Filled")
        self.filled.setToolTip("Fill the bottle with a liquid")
        self.liquid_ior = _spin(1.0, 3.0, 4, 0.01, tip="Refractive index of the liquid (water: 1.333)")
        self.liquid_color, self.liquid_thickness = _tint_controls("liquid")
        self.fill_mode = QComboBox()
        words.fill_combo(self.fill_mode, words.FILL_MODES)
        self.fill_mode.setToolTip("Fill to a height, or with a volume")
        self.fill_value = _spin(0.0, 100000.0, 2, 1.0,
                                tip="The fill level: a height above the standing plane, or a volume")

        glass_box = QGroupBox("Glass")
        gf = QFormLayout(glass_box)
        gf.addRow("IOR", self.glass_ior)
        gf.addRow("Tint", _tint_row(self.glass_tint, self.glass_thickness))
        gf.addRow("Density", self.glass_density)
        liquid_box = QGroupBox("Liquid")
        lf = QFormLayout(liquid_box)
        lf.addRow(self.filled)
        lf.addRow("IOR", self.liquid_ior)
        lf.addRow("Colour", _tint_row(self.liquid_color, self.liquid_thickness))
        lf.addRow("Fill by", self.fill_mode)
        lf.addRow("Fill level", self.fill_value)
        layout = QVBoxLayout(self)
        layout.addWidget(glass_box)
        layout.addWidget(liquid_box)
        layout.addStretch(1)

        self.glass_ior.valueChanged.connect(lambda v: self._glass("Glass IOR", "glass-ior", ior=v))
        self.glass_density.valueChanged.connect(
            lambda v: self._glass("Glass density", "glass-density", density_g_cm3=v))
        self.glass_tint.clicked.connect(self._pick_glass_tint)
        self.glass_thickness.valueChanged.connect(lambda _: self._rethicken_glass())
        self.filled.toggled.connect(self._toggle_liquid)
        self.liquid_ior.valueChanged.connect(lambda v: self._liquid("Liquid IOR", "liquid-ior", ior=v))
        self.liquid_color.clicked.connect(self._pick_liquid_color)
        self.liquid_thickness.valueChanged.connect(lambda _: self._rethicken_liquid())
        self.fill_mode.currentIndexChanged.connect(lambda _: self._set_fill_mode(self.fill_mode.currentData()))
        self.fill_value.valueChanged.connect(lambda v: self._liquid("Fill level", "fill-value", fill_value=v))
        ef.follow(self, editor, self.FIELDS, lambda d, a: self.refresh(d), self._take_derived)

    def choose_color(self, initial_rgb01, title: str):
        """Ask for a colour (0..1 RGB) or ``None``; tests replace this method."""
        c = QColorDialog.getColor(QColor.fromRgbF(*initial_rgb01), self, title)
        return (c.redF(), c.greenF(), c.blueF()) if c.isValid() else None

    # ------------------------------------------------------------------ model → view
    def refresh(self, design):
        widgets = (self.glass_ior, self.glass_density, self.filled, self.liquid_ior,
                   self.fill_mode, self.fill_value)
        blockers = [QSignalBlocker(w) for w in widgets]
        g, liquid = design.glass, design.liquid
        self.glass_ior.setValue(g.ior)
        self.glass_density.setValue(g.density_g_cm3)
        self.glass_tint.set_rgb(tint.transmittance(g.absorption, self.glass_thickness.value()))
        self.filled.setChecked(liquid is not None)
        shown = liquid or Liquid()
        for w in (self.liquid_ior, self.liquid_color, self.liquid_thickness, self.fill_mode, self.fill_value):
            w.setEnabled(liquid is not None)
        self.liquid_ior.setValue(shown.ior)
        self.liquid_color.set_rgb(tint.transmittance(shown.absorption, self.liquid_thickness.value()))
        words.select_key(self.fill_mode, shown.fill_mode)
        self.fill_value.setSuffix(" mm" if shown.fill_mode == "height" else " ml")
        self.fill_value.setValue(shown.fill_value)
        del blockers

    def _take_derived(self, result):
        self.trade_numbers = result.numbers

    # ------------------------------------------------------------------ view → command
    def _glass(self, label, key, **fields):
        self.editor.apply(label, key, glass=dataclasses.replace(self.editor.design.glass, **fields))

    def _liquid(self, label, key, **fields):
        liquid = self.editor.design.liquid
        if liquid is not None:
            self.editor.apply(label, key, liquid=dataclasses.replace(liquid, **fields))

    def _toggle_liquid(self, on: bool):
        design = self.editor.design
        if on and design.liquid is None:
            height = round(design.shape.z_top * 0.75, 1)
            self.editor.apply("Fill with liquid", None, liquid=Liquid(fill_value=height))
        elif not on and design.liquid is not None:
            self.editor.apply("Empty the bottle", None, liquid=None)

    def _set_fill_mode(self, mode: str):
        """Switch height <-> volume keeping the same level where the capacity is known."""
        design = self.editor.design
        if design.liquid is None or not mode or mode == design.liquid.fill_mode:
            return
        from_trade = self.trade_numbers
        value = design.liquid.fill_value
        if from_trade:
            other = from_trade.get("fill_ml" if mode == "volume" else "fill_height_mm")
            value = other if other is not None else value
        self._liquid(f"Fill by {mode}", None, fill_mode=mode, fill_value=round(value, 2))

    def _pick_glass_tint(self):
        rgb = self.choose_color(self.glass_tint.rgb, "Glass tint")
        if rgb is not None:
            self._glass("Glass tint", None,
                        absorption=tint.absorption_from_transmittance(rgb, self.glass_thickness.value()))

    def _pick_liquid_color(self):
        rgb = self.choose_color(self.liquid_color.rgb, "Liquid colour")
        if rgb is not None:
            self._liquid("Liquid colour", None,
                         absorption=tint.absorption_from_transmittance(rgb, self.liquid_thickness.value()))

    def _rethicken_glass(self):
        """The tint's colour now holds through the new thickness: a stronger or weaker glass."""
        absorption = tint.absorption_from_transmittance(self.glass_tint.rgb, self.glass_thickness.value())
        self._glass("Tint thickness", "glass-tint-mm", absorption=absorption)

    def _rethicken_liquid(self):
        liquid = self.editor.design.liquid
        if liquid is not None:
            absorption = tint.absorption_from_transmittance(self.liquid_color.rgb,
                                                            self.liquid_thickness.value())
            self._liquid("Liquid colour thickness", "liquid-tint-mm", absorption=absorption)


__all__ = ["MaterialsPanel"]
