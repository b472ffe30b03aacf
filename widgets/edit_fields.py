"""Small pieces the appearance panels (labels, bump tiles, cap, stage) share: number fields, a
form page, a colour button for linear-RGB model colours, a picture from a numpy array, and the
list-edit helpers.

Design rule: the model stores colours as linear RGB (0..1); designers see and pick sRGB. The
conversion happens here, once, with the engine's own curves
(:func:`engine.color.linear_to_srgb` / ``srgb_to_linear``), so a colour shown,
picked and stored is the same colour everywhere.
"""
from __future__ import annotations

import contextlib

import numpy as np
from PySide6.QtGui import QColor, QImage
from PySide6.QtWidgets import (QColorDialog, QComboBox, QDoubleSpinBox, QFormLayout, QPushButton, QSpinBox,
                               QVBoxLayout)

from engine.appearance.images import EXTENSIONS
from engine.color import linear_to_srgb, srgb_to_linear
from engine.operations.edit import removed, replaced  # noqa: F401  (the panels edit tuples so)


def spin(lo, hi, decimals=1, step=1.0, suffix="", tip="") -> QDoubleSpinBox:
    """A number field that commits on Enter or focus loss (no edit per keystroke)."""
    s = QDoubleSpinBox()
    s.setRange(lo, hi)
    s.setDecimals(decimals)
    s.setSingleStep(step)
    s.setSuffix(suffix)
    s.setKeyboardTracking(False)
    s.setToolTip(tip)
    return s


def int_spin(lo, hi, tip="") -> QSpinBox:
    s = QSpinBox()
    s.setRange(lo, hi)
    s.setKeyboardTracking(False)
    s.setToolTip(tip)
    return s


def compact(*combos) -> None:
    """Let ``combos`` be narrower than their longest item (long names must not widen a dock)."""
    for combo in combos:
        combo.setSizeAdjustPolicy(QComboBox.AdjustToMinimumContentsLengthWithIcon)
        combo.setMinimumContentsLength(10)


def form_page(widget, rows) -> QFormLayout:
    """Lay ``widget`` out as a form of ``rows`` above a stretch (the fields stay at the top of a
    tall dock); a row is ``(label, field)`` or a lone widget across the form."""
    form = QFormLayout()
    for row in rows:
        if isinstance(row, tuple):
            form.addRow(*row)
        else:
            form.addRow(row)
    layout = QVBoxLayout(widget)
    layout.addLayout(form)
    layout.addStretch(1)
    return form


def srgb_of(linear) -> tuple[float, float, float]:
    return tuple(float(v) for v in linear_to_srgb(np.asarray(linear, np.float32)))


def linear_of(srgb) -> tuple[float, float, float]:
    return tuple(round(float(v), 6) for v in srgb_to_linear(np.asarray(srgb, np.float32)))


class LinearColorButton(QPushButton):
    """A button showing a linear-RGB model colour as its sRGB swatch and hex name."""

    rgb = (1.0, 1.0, 1.0)

    def set_linear(self, rgb):
        self.rgb = tuple(rgb)
        c = QColor.fromRgbF(*srgb_of(self.rgb))
        self.setText(c.name())
        self.setStyleSheet(f"background-color: {c.name()}; "
                           f"color: {'black' if c.lightness() > 128 else 'white'}")


def ask_linear_color(parent, initial_linear, title: str):
    """A colour from the dialog as linear RGB, or ``None`` when cancelled."""
    c = QColorDialog.getColor(QColor.fromRgbF(*srgb_of(initial_linear)), parent, title)
    return linear_of((c.redF(), c.greenF(), c.blueF())) if c.isValid() else None


def qimage_of(pixels: np.ndarray) -> QImage:
    """A ``QImage`` (own copy) of uint8 ``(H, W, 3)`` RGB or ``(H, W, 4)`` RGBA pixels."""
    data = np.ascontiguousarray(pixels, dtype=np.uint8)
    h, w, c = data.shape
    fmt = QImage.Format_RGBA8888 if c == 4 else QImage.Format_RGB888
    return QImage(data.data, w, h, c * w, fmt).copy()


def show_rows(view, texts: list, row: int) -> None:
    """Make the list widget ``view`` show ``texts`` (rebuilt only when they differ) with row
    ``row`` (clamped) current; the caller blocks its signals."""
    if [view.item(i).text() for i in range(view.count())] != texts:
        view.clear()
        view.addItems(texts)
    if texts:
        view.setCurrentRow(min(max(row, 0), len(texts) - 1))


def follow(widget, editor, fields, refresh, derived=None) -> None:
    """Show the editor's design now with ``refresh(design, assets)``, again after every change
    that touches ``fields``, and after every refused edit (the widget that asked shows the model
    again, not what was asked for); with ``derived``, show each set of numbers derived from the
    design (``editor.derived``: a :class:`~app.wireframe_controller.Derived`, computed off the
    GUI thread) with ``derived(result)``. The panel shows what the model holds without anyone
    routing it. Unsubscribe when ``widget`` is destroyed. Notifications arrive on the GUI thread."""
    scene = editor.scene
    fields = frozenset(fields)
    refresh(scene.design, scene.assets)

    def on_change(changed, scene):
        if changed & fields:
            refresh(scene.design, scene.assets)

    def on_refused(_message):
        refresh(scene.design, scene.assets)

    def on_derived(result):  # (a plain function: disconnecting it never touches a deleted widget)
        derived(result)

    unsubscribe = scene.subscribe(on_change)
    signals = [(editor.refused, on_refused)] + ([(editor.derived, on_derived)] if derived is not None else [])
    for signal, slot in signals:
        signal.connect(slot)

    def forget(*_):
        unsubscribe()
        for signal, slot in signals:
            with contextlib.suppress(RuntimeError, TypeError):  # the editor may be gone first
                signal.disconnect(slot)
    widget.destroyed.connect(forget)


#: The file dialog's filter for the images labels and reliefs may use.
IMAGE_FILTER = "Images (" + " ".join("*" + e for e in EXTENSIONS) + ")"
