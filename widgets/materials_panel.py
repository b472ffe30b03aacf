"""Materials panel: glass IOR, tint and density; liquid IOR, colour and fill level.

Design rule: widget edits become ``editor.apply(label, merge_key, glass=...|liquid=...)``;
``refresh(design)`` writes the model into the widgets with their signals blocked. A tint is
shown as the colour white light takes after ``TINT_PATH_MM`` of the material and stored as
Beer-Lambert absorption (1/mm): ``absorption = -ln(colour) / TINT_PATH_MM``.
"""
from __future__ import annotations

import dataclasses
import math

from PySide6.QtCore import QSignalBlocker
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (QCheckBox, QColorDialog, QComboBox, QDoubleSpinBox, QFormLayout,
                               QGroupBox, QPushButton, QVBoxLayout, QWidget)

from engine.model.design import Liquid

#: Path length (mm) over which a tint colour is the transmitted colour of white light.
TINT_PATH_MM = 100.0


def absorption_from_color(rgb01) -> tuple[float, float, float]:
    """Absorption (1/mm) whose transmission over ``TINT_PATH_MM`` is ``rgb01`` (0..1 each)."""
    return tuple(-math.log(min(max(c, 1e-4), 1.0)) / TINT_PATH_MM for c in rgb01)


def color_from_absorption(absorption) -> tuple[float, float, float]:
    """The transmitted colour (0..1 RGB) of ``TINT_PATH_MM`` of material with ``absorption``."""
    return tuple(math.exp(-a * TINT_PATH_MM) for a in absorption)


def _spin(lo, hi, decimals, step, suffix="") -> QDoubleSpinBox:
    s = QDoubleSpinBox()
    s.setRange(lo, hi)
    s.setDecimals(decimals)
    s.setSingleStep(step)
    s.setSuffix(suffix)
    s.setKeyboardTracking(False)
    return s


class ColorButton(QPushButton):
    """A push button showing a colour swatch."""

    def set_rgb(self, rgb01):
        self.rgb = tuple(rgb01)
        c = QColor.fromRgbF(*self.rgb)
        self.setText(c.name())
        self.setStyleSheet(f"background-color: {c.name()}; color: {'black' if c.lightness() > 128 else 'white'}")


class MaterialsPanel(QWidget):
    """Edits ``design.glass`` and ``design.liquid`` through ``editor``."""

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.glass_ior = _spin(1.0, 3.0, 4, 0.01)
        self.glass_density = _spin(0.5, 10.0, 3, 0.01, " g/cm\u00b3")
        self.glass_tint = ColorButton()
        self.filled = QCheckBox("Filled")
        self.liquid_ior = _spin(1.0, 3.0, 4, 0.01)
        self.liquid_color = ColorButton()
        self.fill_mode = QComboBox()
        self.fill_mode.addItems(["height", "volume"])
        self.fill_value = _spin(0.0, 100000.0, 2, 1.0)

        glass_box = QGroupBox("Glass")
        gf = QFormLayout(glass_box)
        gf.addRow("IOR", self.glass_ior)
        gf.addRow("Tint", self.glass_tint)
        gf.addRow("Density", self.glass_density)
        liquid_box = QGroupBox("Liquid")
        lf = QFormLayout(liquid_box)
        lf.addRow(self.filled)
        lf.addRow("IOR", self.liquid_ior)
        lf.addRow("Colour", self.liquid_color)
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
        self.filled.toggled.connect(self._toggle_liquid)
        self.liquid_ior.valueChanged.connect(lambda v: self._liquid("Liquid IOR", "liquid-ior", ior=v))
        self.liquid_color.clicked.connect(self._pick_liquid_color)
        self.fill_mode.currentTextChanged.connect(self._set_fill_mode)
        self.fill_value.valueChanged.connect(lambda v: self._liquid("Fill level", "fill-value", fill_value=v))

    def choose_color(self, initial_rgb01, title: str):
        """Ask for a colour (0..1 RGB) or ``None``; tests replace this method."""
        c = QColorDialog.getColor(QColor.fromRgbF(*initial_rgb01), self, title)
        return (c.redF(), c.greenF(), c.blueF()) if c.isValid() else None

    # ------------------------------------------------------------------ model → view
    def refresh(self, design, trade: dict | None = None):
        widgets = (self.glass_ior, self.glass_density, self.filled, self.liquid_ior,
                   self.fill_mode, self.fill_value)
        blockers = [QSignalBlocker(w) for w in widgets]
        g, liquid = design.glass, design.liquid
        self.glass_ior.setValue(g.ior)
        self.glass_density.setValue(g.density_g_cm3)
        self.glass_tint.set_rgb(color_from_absorption(g.absorption))
        self.filled.setChecked(liquid is not None)
        shown = liquid or Liquid()
        for w in (self.liquid_ior, self.liquid_color, self.fill_mode, self.fill_value):
            w.setEnabled(liquid is not None)
        self.liquid_ior.setValue(shown.ior)
        self.liquid_color.set_rgb(color_from_absorption(shown.absorption))
        self.fill_mode.setCurrentText(shown.fill_mode)
        self.fill_value.setSuffix(" mm" if shown.fill_mode == "height" else " ml")
        self.fill_value.setValue(shown.fill_value)
        del blockers

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
        if design.liquid is None or mode == design.liquid.fill_mode:
            return
        from_trade = getattr(self, "trade_numbers", None)
        value = design.liquid.fill_value
        if from_trade:
            other = from_trade.get("fill_ml" if mode == "volume" else "fill_height_mm")
            value = other if other is not None else value
        self._liquid(f"Fill by {mode}", None, fill_mode=mode, fill_value=round(value, 2))

    def _pick_glass_tint(self):
        rgb = self.choose_color(self.glass_tint.rgb, "Glass tint")
        if rgb is not None:
            self._glass("Glass tint", None, absorption=absorption_from_color(rgb))

    def _pick_liquid_color(self):
        rgb = self.choose_color(self.liquid_color.rgb, "Liquid colour")
        if rgb is not None:
            self._liquid("Liquid colour", None, absorption=absorption_from_color(rgb))


__all__ = ["MaterialsPanel", "absorption_from_color", "color_from_absorption"]
