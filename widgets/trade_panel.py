"""Design panel: the design's name, and its trade numbers (capacities, fill point, glass).

Design rule: the numbers are a read-only view: ``refresh(numbers)`` takes the dict computed by
the window's controller (``None`` values show as a dash: not computable). The name is an edit
like any other (``editor.apply(..., name=...)``, one undo step per finished edit), refreshed with
its signals blocked. When the fill no longer matches a volume the name quotes, the window calls
:meth:`offer_name`: a line under the name offers the corrected name, and the designer takes it
(an undoable rename) or keeps the old one; nothing is renamed unasked.
"""
from __future__ import annotations

from PySide6.QtCore import QSignalBlocker
from PySide6.QtWidgets import (QFormLayout, QHBoxLayout, QLabel, QLineEdit, QPushButton,
                               QVBoxLayout, QWidget)

ROWS = (
    ("brimful_ml", "Brimful capacity", "{:.1f} ml", "Volume up to the brim"),
    ("fill_ml", "Fill capacity", "{:.1f} ml", "Volume of liquid at the fill line"),
    ("fill_height_mm", "Fill height", "{:.2f} mm", "Height of the fill line above the standing plane"),
    ("fill_point_below_top_mm", "Fill point (below top)", "{:.2f} mm", "Distance from the brim down to the fill line"),
    ("glass_volume_cm3", "Glass volume", "{:.2f} cm\u00b3", "Volume of the glass"),
    ("glass_mass_g", "Glass weight", "{:.1f} g", "Weight of the glass at its density"),
    ("closure", "Closure", "{kind} \u2300 {diameter_mm:.1f} \u00d7 {height_mm:.1f} mm",
     "The closure on the finish (Cap panel): its kind, largest diameter \u00d7 its height"),
    ("overall_height_mm", "Overall height", "{:.1f} mm", "Height of the bottle with its closure on"),
)


class TradeNumbersPanel(QWidget):
    """Shows the design's name and trade numbers; renames through ``editor`` when given one."""

    def __init__(self, editor=None, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.name = QLineEdit()
        self.name.setToolTip("The design's name (it titles renders and batch summaries)")
        self.offer_label = QLabel("")
        self.offer_label.setWordWrap(True)
        self.accept_offer = QPushButton("Rename")
        self.accept_offer.setToolTip("Take the name that states the bottle's fill (one undoable step)")
        self.keep_name = QPushButton("Keep")
        self.keep_name.setToolTip("Keep the name as it is")
        offer = QHBoxLayout()
        offer.addWidget(self.offer_label, 1)
        offer.addWidget(self.accept_offer)
        offer.addWidget(self.keep_name)
        self.offer_box = QWidget()
        self.offer_box.setLayout(offer)
        self.offer_box.hide()
        self.offered: str | None = None
        form = QFormLayout()
        form.addRow("Name", self.name)
        self.labels: dict[str, QLabel] = {}
        for key, title, _, tip in ROWS:
            label = QLabel("\u2014")
            label.setObjectName(key)
            label.setToolTip(tip)
            form.addRow(title, label)
            self.labels[key] = label
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.offer_box)
        layout.addStretch(1)
        self.name.editingFinished.connect(self._rename_typed)
        self.accept_offer.clicked.connect(self.take_offer)
        self.keep_name.clicked.connect(self.withdraw_offer)
        self.dismissed: set[tuple[str, str]] = set()

    def refresh(self, numbers: dict):
        for key, _, fmt, _ in ROWS:
            value = numbers.get(key)
            text = "\u2014" if value is None else fmt.format(**value) if isinstance(value, dict) \
                else fmt.format(value)
            self.labels[key].setText(text)

    def show_name(self, name: str):
        with QSignalBlocker(self.name):
            if self.name.text() != name:
                self.name.setText(name)

    def text(self, key: str) -> str:
        """The text shown for ``key`` (for tests and the status bar)."""
        return self.labels[key].text()

    # ------------------------------------------------------------------- renaming
    def _rename_typed(self):
        if self.editor is not None and self.name.text() != self.editor.design.name:
            if not self.editor.apply("Rename design", None, name=self.name.text()):
                self.show_name(self.editor.design.name)

    def offer_name(self, current: str, proposed: str | None, why: str = ""):
        """Offer ``proposed`` instead of ``current`` (``None``: offer nothing); an offer the
        designer declined for this name is not made again."""
        if proposed is None or (current, proposed) in self.dismissed:
            self.offered = None
            self.offer_box.hide()
            return
        self.offered = proposed
        self.offer_label.setText(f"{why} Rename to \u201c{proposed}\u201d?".strip())
        self.offer_box.show()

    def take_offer(self) -> bool:
        proposed, self.offered = self.offered, None
        self.offer_box.hide()
        return bool(proposed) and self.editor is not None and \
            self.editor.apply("Rename design", None, name=proposed)

    def withdraw_offer(self):
        if self.offered is not None and self.editor is not None:
            self.dismissed.add((self.editor.design.name, self.offered))
        self.offered = None
        self.offer_box.hide()
