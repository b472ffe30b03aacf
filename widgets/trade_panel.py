"""Design panel: the design's name, and its trade numbers (capacities, fill point, glass).

Design rule: the numbers are a read-only view of what was derived from the design off the GUI
thread (:class:`app.wireframe_controller.Derived`, announced by the editor): the panel follows
them itself (:func:`widgets.edit_fields.follow`), ``show_numbers(numbers)`` showing the trade
numbers (``None`` values show as a dash: not computable). The name is an edit like any other
(``editor.apply(..., name=...)``, one undo step per finished edit), refreshed with its signals
blocked. When new numbers change the fill and the name quotes another volume, a line under the
name offers the corrected name (:meth:`offer_name`), and the designer takes it (an undoable
rename) or keeps the old one; nothing is renamed unasked.

Under them the Plant group shows the plant's figures (:func:`engine.plant.sheet.plant_numbers`,
derived with the trade numbers: ``show_plant(plant)``, a part that cannot be computed a dash)
and its warnings (the designer's limits a figure passes, an outline's thin sloped walls), in the
amber of the section's warnings. The plant's
settings and limits (``design.plant``) are edited here too, one undoable
``editor.apply(..., plant=...)`` per finished edit, and the panel follows the scene for that
field and the name (``refresh(design)``), so an undo shows here.
"""
from __future__ import annotations

import dataclasses

from PySide6.QtCore import QSignalBlocker
from PySide6.QtWidgets import (QDoubleSpinBox, QFormLayout, QGridLayout, QGroupBox, QHBoxLayout,
                               QLabel, QLineEdit, QPushButton, QVBoxLayout, QWidget)

from engine.model import advice
from engine.model.check import PLANT_RANGES
from widgets import edit_fields as ef

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

DASH = "\u2014"
#: The colour of a warning (the section panel's: what the design cannot be made or filled with).
AMBER = "#8a5a00"
#: The states a bottle's stability is given for (:mod:`engine.plant.stability`).
STATES = ("empty", "filled", "brimful")
#: The Plant group's single figures: ``(key, title, tip)``; the states' rows come under them.
PLANT_ROWS = (
    ("least_tip", "Least tip angle", "The smallest angle the bottle can be tilted through before "
     "it falls over, the state that has it and the direction (in the plan, from +x) it falls in"),
    ("weight_to_capacity", "Weight to capacity", "Glass weight per millilitre the bottle holds "
     "(at the fill line, or brimful for an empty design): the plant's lightness figure"),
    ("capacity_band", "Capacity band", "Nominal volume \u00b1 the tolerance the rule allows, and "
     "the fill heights (above the standing plane) that keep the volume within it"),
    ("max_stress", "Max stress", "Highest membrane stress in the wall at the proof pressure, "
     "which kind and at what height"),
)
#: The plant's settings and limits: ``(field, title, decimals, step, suffix, text at 0, tip)``;
#: ranges are the engine's (:data:`engine.model.check.PLANT_RANGES`).
PLANT_SETTINGS = (
    ("proof_pressure_mpa", "Proof pressure", 2, 0.1, " MPa", "",
     "Internal pressure the membrane stresses are given at (1.2 MPa: the usual proof test of a "
     "carbonated drink's bottle)"),
    ("liquid_density_g_ml", "Liquid density", 3, 0.01, " g/ml", "",
     "Density of the liquid, for the filled states' weight and balance (water: 1.0)"),
    ("closure_mass_g", "Closure mass", 1, 0.5, " g", "not counted",
     "Weight of the closure, counted in the stability (0: not known, not counted)"),
    ("label_gsm", "Label grammage", 0, 5.0, " g/m\u00b2", "not counted",
     "Grammage of the label stock, counted in the stability (0: not known, not counted)"),
)
PLANT_LIMITS = (
    ("min_tip_deg", "Least tip angle", 1, 0.5, "\u00b0", "no limit",
     "Warn when the bottle tips over at a smaller angle than this in any state (0: no limit)"),
    ("max_stress_mpa", "Highest stress", 1, 1.0, " MPa", "no limit",
     "Warn when the membrane stress at the proof pressure passes this anywhere (0: no limit)"),
    ("min_glass_mass_g", "Lowest glass weight", 1, 5.0, " g", "no limit",
     "Warn when the glass weighs less than this (0: no limit)"),
)


def _num(fmt: str, *values) -> str:
    """``fmt`` filled with ``values``, or a dash when one of them is ``None``."""
    return DASH if any(v is None for v in values) else fmt.format(*values)


def plant_texts(plant: dict | None) -> dict[str, tuple[str, str]]:
    """What the Plant group shows of the plant numbers ``plant`` (the keys of
    :func:`engine.plant.sheet.plant_numbers`; ``None``: none could be computed): key ->
    ``(text, tooltip)``, the tooltip empty where the row's own explanation stays. Keys: those of
    :data:`PLANT_ROWS`, ``tip_STATE`` and ``cg_STATE`` for each of :data:`STATES`. A part that is
    ``None`` (or a state the design does not have) shows as a dash."""
    plant = plant or {}
    out = {key: (DASH, "") for key, _, _ in PLANT_ROWS}
    out.update({f"{kind}_{state}": (DASH, "") for kind in ("tip", "cg") for state in STATES})
    least = plant.get("least_tip")
    if least:
        out["least_tip"] = (_num("{:.1f}\u00b0 {}, towards {:.0f}\u00b0", least.get("deg"),
                                 least.get("state"), least.get("direction_deg")), "")
    for state in plant.get("states") or ():
        moving = _num("{:.1f}\u00b0", state.get("tip_deg"))
        frozen = _num("{:.1f}\u00b0", state.get("tip_frozen_deg"))
        tip = moving if DASH in (moving, frozen) else f"{moving} [{frozen}]"
        out[f"tip_{state['state']}"] = (tip, _num("Falls towards {:.0f}\u00b0 in the plan",
                                                  state.get("tip_direction_deg")))
        out[f"cg_{state['state']}"] = (_num("{:.1f} mm", state.get("cg_z_mm")),
                                       _num("Weighs {:.1f} g in this state", state.get("mass_g")))
    ratio = plant.get("weight_to_capacity")
    if ratio:
        basis = "at the fill line" if ratio.get("basis") == "fill" else "brimful"
        out["weight_to_capacity"] = (_num("{:.3f} g/ml", ratio.get("ratio_g_per_ml")),
                                     _num("Of {:.1f} ml " + basis, ratio.get("capacity_ml")))
    band = plant.get("capacity_band")
    if band:
        text = _num("{:.1f} \u00b1 {:.1f} ml", band.get("nominal_ml"), band.get("tolerance_ml"))
        heights = _num("fill {:.1f}\u2013{:.1f} mm", band.get("fill_height_min_mm"),
                       band.get("fill_height_max_mm"))
        points = _num("Fill point {:.1f}\u2013{:.1f} mm below the brim",
                      band.get("fill_point_min_mm"), band.get("fill_point_max_mm"))
        why = [f"Rule: {band['rule']}." if band.get("rule") else "", "" if points == DASH else f"{points}."]
        out["capacity_band"] = (text if heights == DASH else f"{text}, {heights}",
                                " ".join(t for t in why if t))
    stress = plant.get("stress")
    if stress:
        at = _num(" at the proof pressure of {:.2f} MPa", stress.get("pressure_mpa"))
        note = stress.get("note") or ""
        tip = (f"Membrane stress{at if at != DASH else ''}. {note}").strip()
        if stress.get("max_mpa") is None:
            out["max_stress"] = (DASH, note or tip)
        else:
            out["max_stress"] = (_num("{:.2f} MPa {} at z {:.1f} mm", stress.get("max_mpa"),
                                      stress.get("max_kind"), stress.get("max_at_z_mm")), tip)
    return out


class TradeNumbersPanel(QWidget):
    """Shows the design's name, trade numbers and plant figures; renames and edits the plant's
    settings through ``editor`` when given one."""

    #: The design fields the panel shows (it follows the scene for them itself).
    FIELDS = frozenset({"plant", "name"})

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
        self._shown_fill_ml = None  # the fill of the last numbers shown: a change may offer a rename
        form = QFormLayout()
        form.addRow("Name", self.name)
        self.labels: dict[str, QLabel] = {}
        for key, title, _, tip in ROWS:
            label = QLabel("\u2014")
            label.setObjectName(key)
            label.setToolTip(tip)
            form.addRow(title, label)
            self.labels[key] = label
        self.plant_fields: dict[str, QDoubleSpinBox] = {}
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.offer_box)
        layout.addWidget(self._plant_box())
        layout.addWidget(self._settings_box("Plant settings", PLANT_SETTINGS))
        layout.addWidget(self._settings_box("Plant limits", PLANT_LIMITS))
        layout.addStretch(1)
        self.name.editingFinished.connect(self._rename_typed)
        self.accept_offer.clicked.connect(self.take_offer)
        self.keep_name.clicked.connect(self.withdraw_offer)
        self.dismissed: set[tuple[str, str]] = set()
        if editor is not None:
            ef.follow(self, editor, self.FIELDS, lambda d, a: self.refresh(d), self.show_derived)

    def _figure(self, key: str, tip: str) -> QLabel:
        label = QLabel(DASH)
        label.setObjectName(f"plant_{key}")
        label.setToolTip(tip)
        self.plant_labels[key] = label
        self._plant_tips[key] = tip
        return label

    def _plant_box(self) -> QGroupBox:
        """The plant's figures: the single ones, a row per state, the limits' warnings."""
        box = QGroupBox("Plant")
        form = QFormLayout(box)
        self.plant_labels: dict[str, QLabel] = {}
        self._plant_tips: dict[str, str] = {}
        rows = {key: (title, tip) for key, title, tip in PLANT_ROWS}
        form.addRow(rows["least_tip"][0], self._figure("least_tip", rows["least_tip"][1]))
        grid = QGridLayout()
        grid.setContentsMargins(0, 0, 0, 0)
        for col, (title, tip) in enumerate((("Tip angle [frozen]", "The angle the bottle tips over "
                                              "at with its liquid moving, and with it frozen in place"),
                                             ("Centre of gravity", "Height of the centre of gravity "
                                              "above the standing plane")), start=1):
            head = QLabel(title)
            head.setToolTip(tip)
            grid.addWidget(head, 0, col)
        for row, state in enumerate(STATES, start=1):
            grid.addWidget(QLabel(state.capitalize()), row, 0)
            grid.addWidget(self._figure(f"tip_{state}", f"Tip angle {state}, liquid moving "
                                        "[frozen in place]"), row, 1)
            grid.addWidget(self._figure(f"cg_{state}", f"Centre of gravity {state}, above the "
                                        "standing plane"), row, 2)
        form.addRow(grid)
        for key in ("weight_to_capacity", "capacity_band", "max_stress"):
            form.addRow(rows[key][0], self._figure(key, rows[key][1]))
        self.plant_warnings = QLabel("")
        self.plant_warnings.setWordWrap(True)
        self.plant_warnings.setStyleSheet(f"color: {AMBER}")
        self.plant_warnings.setToolTip("The plant's limits (below) that a figure passes, and where an "
                                       "outline's sloped wall leaves the glass thinner than its wall")
        self.plant_warnings.hide()
        form.addRow(self.plant_warnings)
        return box

    def _settings_box(self, title: str, rows) -> QGroupBox:
        """A group of spin boxes for ``rows`` of the plant's fields (each edit one undo step)."""
        box = QGroupBox(title)
        form = QFormLayout(box)
        ranges = {name: bounds for name, bounds, _ in PLANT_RANGES}
        for field, text, decimals, step, suffix, at_zero, tip in rows:
            spin = ef.spin(*ranges[field], decimals, step, suffix, tip)
            if at_zero and ranges[field][0] == 0.0:
                spin.setSpecialValueText(at_zero)
            spin.setObjectName(f"plant_{field}")
            undo_text = f"{title}: {text.lower()}"
            spin.valueChanged.connect(lambda v, f=field, t=undo_text: self.set_plant(f, v, t))
            spin.setEnabled(self.editor is not None)
            form.addRow(text, spin)
            self.plant_fields[field] = spin
        return box

    # -------------------------------------------------------------------- the plant
    def show_plant(self, plant: dict | None):
        """Show the plant numbers ``plant`` (:func:`engine.plant.sheet.plant_numbers`'s dict;
        ``None``: none could be computed) and their warnings."""
        for key, (text, tip) in plant_texts(plant).items():
            label = self.plant_labels[key]
            label.setText(text)
            label.setToolTip(tip or self._plant_tips[key])
        warnings = (plant or {}).get("warnings") or ()
        self.plant_warnings.setText("\n".join(f"\u26a0 {w}" for w in warnings))
        self.plant_warnings.setVisible(bool(warnings))

    def plant_text(self, key: str) -> str:
        """The text shown for plant figure ``key`` (:func:`plant_texts`' keys; for tests)."""
        return self.plant_labels[key].text()

    def show_settings(self, design):
        """Show ``design.plant`` in the settings' spin boxes (their signals blocked)."""
        for field, spin in self.plant_fields.items():
            with QSignalBlocker(spin):
                spin.setValue(getattr(design.plant, field))

    def set_plant(self, field: str, value: float, text: str = "Plant settings") -> bool:
        """Set the plant's ``field`` to ``value`` (one undo step per finished edit; a field's
        quick steps merge); ``False`` if refused, and the field shows the model again."""
        if self.editor is None:
            return False
        plant = dataclasses.replace(self.editor.design.plant, **{field: float(value)})
        return self.editor.apply(text, f"plant-{field}", plant=plant)  # (a refusal: follow re-shows)

    def refresh(self, design):
        """Show ``design``'s name and plant settings (signals blocked); an offer on show is
        brought up to date with the name."""
        self.show_name(design.name)
        self.show_settings(design)
        if self.offered is not None:
            self._offer_for(self._shown_fill_ml)

    def show_derived(self, result):
        """Show the numbers derived from the newest design (a
        :class:`~app.wireframe_controller.Derived`): trade and plant numbers; a fill that moved
        offers a name that states it."""
        numbers = result.numbers
        self.show_numbers(numbers)
        self.show_plant(result.plant)
        fill_ml = numbers.get("fill_ml")
        if self._shown_fill_ml is not None and fill_ml is not None and abs(fill_ml - self._shown_fill_ml) > 0.05:
            self._offer_for(fill_ml)
        self._shown_fill_ml = fill_ml

    def show_numbers(self, numbers: dict):
        """Show the trade numbers ``numbers`` (:func:`app.engine_bridge.trade_numbers`' dict)."""
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

    def _offer_for(self, fill_ml):
        """Offer a name that states ``fill_ml`` (ml) when the design's name quotes another volume."""
        name = self.editor.design.name
        proposed = advice.updated_name(name, fill_ml) if fill_ml is not None else None
        why = f"The bottle now holds {fill_ml:.0f} ml at its fill line." if fill_ml is not None else ""
        self.offer_name(name, proposed, why)

    def forget_offer(self):
        """Another design was opened: offer nothing, and offer a name only once its fill moves."""
        self._shown_fill_ml = None
        self.offer_name("", None)

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
