"""Trade numbers panel: brimful and fill capacity, fill point, glass volume and weight.

Design rule: a read-only view. ``refresh(numbers)`` takes the dict computed by the window's
controller (``None`` values show as a dash: not computable, or the geometry engine missing).
"""
from __future__ import annotations

from PySide6.QtWidgets import QFormLayout, QLabel, QWidget

ROWS = (
    ("brimful_ml", "Brimful capacity", "{:.1f} ml"),
    ("fill_ml", "Fill capacity", "{:.1f} ml"),
    ("fill_height_mm", "Fill height", "{:.2f} mm"),
    ("fill_point_mm", "Fill point (below top)", "{:.2f} mm"),
    ("glass_cm3", "Glass volume", "{:.2f} cm\u00b3"),
    ("glass_g", "Glass weight", "{:.1f} g"),
)


class TradeNumbersPanel(QWidget):
    """Shows the trade numbers of the current design."""

    def __init__(self, parent=None):
        super().__init__(parent)
        form = QFormLayout(self)
        self.labels: dict[str, QLabel] = {}
        for key, title, _ in ROWS:
            label = QLabel("\u2014")
            label.setObjectName(key)
            form.addRow(title, label)
            self.labels[key] = label

    def refresh(self, numbers: dict):
        for key, _, fmt in ROWS:
            value = numbers.get(key)
            self.labels[key].setText("\u2014" if value is None else fmt.format(value))

    def text(self, key: str) -> str:
        """The text shown for ``key`` (for tests and the status bar)."""
        return self.labels[key].text()
