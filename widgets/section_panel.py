"""The section editor panel: canvas, segment table, tools, cross-section kind and thicknesses.

Design rule: the panel talks to the model only through ``editor.apply(label, merge_key,
shape=... | liquid=...)`` (an undoable, validated edit) and is refreshed by ``refresh(design)``
with its widgets' signals blocked, so a refresh never echoes back as an edit. Geometry is the
engine's (:mod:`engine.geometry.editing`). Two message lines sit under the table: a refusal (red)
says why the last edit was not made and is cleared by the next change of the design (an undo
that removes its cause included); the warnings (amber) say what the design cannot be made or
filled with, for as long as that is so.
"""
from __future__ import annotations

import dataclasses

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtWidgets import (QComboBox, QDoubleSpinBox, QFormLayout, QGridLayout, QLabel,
                               QSizePolicy, QSplitter, QToolButton, QVBoxLayout, QWidget)

from engine.geometry import editing as edits
from engine.geometry.shape import SECTION_NAMES, BottleShape
from engine.model import fill
from widgets import edit_fields as ef
from widgets import words
from widgets.section_editor import SectionCanvas
from widgets.section_table import SectionTable

TOOLS = (
    ("split", "Split", "Cut the selected segment in two at its middle (S)"),
    ("delete", "Delete", "Remove the selected segment; everything above drops to close the gap (Del)"),
    ("insert", "Insert line", "Add a 10 mm straight segment after the selected one"),
    ("line", "\u2192 line", "Make the selected segment straight between its ends"),
    ("arc", "\u2192 arc", "Make the selected segment a circular arc; smooth neighbours stay "
                          "tangent (they slide along themselves to meet it)"),
    ("ellipse_arc", "\u2192 ellipse", "Make the selected segment an ellipse arc (an arc becomes "
                                      "the same curve with equal radii)"),
    ("smooth", "Smooth", "Ask for tangency where the selected segment meets the next one"),
    ("snap", "Snap", "Snap dragged points to a 0.5 mm grid (hold Ctrl to drag freely)"),
    ("fit", "Fit", "Zoom to show the whole section (F)"),
)
TOOLS_PER_ROW = 5


class SectionPanel(QWidget):
    """Edits ``design.shape`` (and the fill level, by dragging the fill line) through ``editor``
    (see :class:`app.commands.DesignEditor`)."""

    #: The design fields the panel shows (it follows the scene for them itself).
    FIELDS = frozenset({"shape", "liquid"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.shape: BottleShape | None = None
        self.current_name = "profile"
        self.derived = {"inner": {}, "fill_z": None}
        self.canvas = SectionCanvas()
        self.table = SectionTable()
        self.model = self.table.model()
        self.message = QLabel("")
        self.message.setWordWrap(True)
        self.message.setStyleSheet("color: #a02020")
        self.warnings = QLabel("")
        self.warnings.setWordWrap(True)
        self.warnings.setStyleSheet("color: #8a5a00")
        self.warnings.setToolTip("What this design cannot be made or filled with")

        self.kind_combo = QComboBox()
        words.fill_combo(self.kind_combo, words.CROSS_SECTIONS)
        self.kind_combo.setToolTip("The shape across the bottle: round, rounded square, "
                                   "rounded rectangle or oval")
        self.name_combo = QComboBox()
        self.name_combo.setToolTip("Which section the canvas and the table edit (the others are "
                                   "drawn dashed)")
        self.wall_spin = self._spin(0.3, 20.0, " mm", "Wall thickness of the glass (mm)")
        self.base_spin = self._spin(0.3, 60.0, " mm", "Height of the inner base above the standing "
                                                       "plane (mm); at least the wall")
        self.rotation_spin = self._spin(-180.0, 180.0, " \u00b0", "Turn of a non-round bottle "
                                                                  "about its axis (degrees)")
        form = QFormLayout()
        form.addRow("Cross-section", self.kind_combo)
        form.addRow("Section", self.name_combo)
        form.addRow("Wall", self.wall_spin)
        form.addRow("Base", self.base_spin)
        form.addRow("Rotation", self.rotation_spin)

        tools = QGridLayout()  # two rows: the panel stays narrow enough for a side dock
        self.tool_buttons = {}
        for k, (key, text, tip) in enumerate(TOOLS):
            b = QToolButton()
            b.setText(text)
            b.setToolTip(tip)
            b.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
            b.clicked.connect(lambda _=False, k=key: self.run_tool(k))
            tools.addWidget(b, k // TOOLS_PER_ROW, k % TOOLS_PER_ROW)
            self.tool_buttons[key] = b
        self.tool_buttons["smooth"].setCheckable(True)
        snap = self.tool_buttons["snap"]
        snap.setCheckable(True)
        snap.setChecked(True)

        self.split = QSplitter(Qt.Vertical)
        self.split.setObjectName("section-split")
        self.split.addWidget(self.canvas)
        self.split.addWidget(self.table)
        self.split.setStretchFactor(0, 3)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addLayout(tools)
        layout.addWidget(self.split, 1)
        layout.addWidget(self.message)
        layout.addWidget(self.warnings)

        self.canvas.sectionProposed.connect(self.propose_section)
        self.canvas.fillProposed.connect(self.propose_fill)
        self.canvas.problem.connect(self.show_problem)
        self.model.sectionProposed.connect(self.propose_section)
        self.model.problem.connect(self.show_problem)
        self.canvas.selectionChanged.connect(self._on_canvas_selection)
        self.canvas.toolRequested.connect(self.run_tool)
        self.table.selectionModel().currentRowChanged.connect(lambda cur, _: self.canvas.select(cur.row()))
        self.name_combo.currentIndexChanged.connect(lambda _: self._on_name_chosen(self.name_combo.currentData()))
        self.kind_combo.currentIndexChanged.connect(lambda _: self.set_cross_section(self.kind_combo.currentData()))
        self.wall_spin.valueChanged.connect(lambda v: self._set_shape_number("wall_thickness", v))
        self.base_spin.valueChanged.connect(lambda v: self._set_shape_number("base_thickness", v))
        self.rotation_spin.valueChanged.connect(lambda v: self._set_shape_number("rotation_deg", v))
        editor.refused.connect(self.show_problem)
        ef.follow(self, editor, self.FIELDS, lambda d, a: self.refresh(d), self.show_derived)

    @staticmethod
    def _spin(lo, hi, suffix, tip) -> QDoubleSpinBox:
        s = QDoubleSpinBox()
        s.setRange(lo, hi)
        s.setDecimals(2)
        s.setSingleStep(0.1)
        s.setSuffix(suffix)
        s.setKeyboardTracking(False)
        s.setToolTip(tip)
        return s

    # ---------------------------------------------------------------- model → view
    def show_derived(self, result):
        """Show what was derived off-thread from the newest design (a
        :class:`~app.wireframe_controller.Derived`): its inner walls (section name -> segments)
        and fill height (mm), drawn with the section until newer ones arrive, and its warnings."""
        fill_z = result.numbers.get("fill_height_mm") if result.design.liquid is not None else None
        self.derived = {"inner": dict(result.inner), "fill_z": fill_z}
        if self.shape is not None:
            self.canvas.show_section(self.canvas.section, self.derived["inner"].get(self.current_name),
                                     fill_z, self.canvas.ghosts)
        self.warnings.setText("\n".join(f"\u26a0 {w}" for w in result.warnings))

    def refresh(self, design):
        """Show ``design.shape`` (with the last derived inner walls and fill line)."""
        derived = self.derived
        shape = design.shape
        self.shape = shape
        names = [n for n, _ in shape.sections]
        if self.current_name not in names:
            self.current_name = names[0]
        blockers = [QSignalBlocker(w) for w in (self.kind_combo, self.name_combo, self.wall_spin,
                                                 self.base_spin, self.rotation_spin)]
        words.select_key(self.kind_combo, shape.cross_section)
        # a plan outline comes from a scene or project that has one: no plan to convert to yet
        outline = self.kind_combo.model().item(self.kind_combo.findData("outline"))
        outline.setEnabled(shape.cross_section == "outline")
        outline.setToolTip(words.CROSS_SECTIONS["outline"][1] if shape.cross_section == "outline"
                           else "Open a project or SPEC_outline scene with a plan outline; this window "
                                "cannot turn another kind into one yet")
        if words.keys_of(self.name_combo) != names:
            words.fill_combo(self.name_combo, words.SECTIONS, names)
        words.select_key(self.name_combo, self.current_name)
        self.wall_spin.setValue(shape.wall_thickness)
        self.base_spin.setValue(shape.base_thickness)
        self.rotation_spin.setValue(shape.rotation_deg)
        self.rotation_spin.setEnabled(not shape.xs.revolved)
        del blockers
        section = shape.section(self.current_name)
        ghosts = [s for n, s in shape.sections if n != self.current_name]
        self.canvas.show_section(section, derived.get("inner", {}).get(self.current_name),
                                 derived.get("fill_z"), ghosts)
        if self.model.section != section:
            row = self.table.currentIndex().row()
            self.model.set_section(section)
            if 0 <= row < len(section.segments):
                self.table.selectRow(row)
        self._sync_smooth_button()

    def show_problem(self, text: str):
        self.message.setText(text)

    def clear_problem(self):
        """The design changed: a refusal of an edit against the design before no longer applies."""
        self.message.setText("")

    # ---------------------------------------------------------------- view → command
    def propose_section(self, section, text: str, merge_key: str = ""):
        """Apply ``section`` in place of the current one (one undo step per merge key)."""
        shape = self.editor.design.shape.with_section(self.current_name, section)
        if self.editor.apply(text, merge_key or None, shape=shape):
            self.message.setText("")
            return True
        return False

    def propose_fill(self, height_mm: float, merge_key: str = "") -> bool:
        """Stand the liquid at ``height_mm`` (a drag of the fill line; one undo step per drag),
        in the liquid's own fill mode."""
        design = self.editor.design
        if design.liquid is None:
            return False
        liquid = fill.liquid_at_height(design.shape, design.liquid, height_mm)
        return self.editor.apply("Fill level", merge_key or None, liquid=liquid)

    def _set_shape_number(self, field, value):
        new = dataclasses.replace(self.editor.design.shape, **{field: value})  # (the plan, if any, kept)
        label = {"wall_thickness": "Wall thickness", "base_thickness": "Base thickness"}.get(field, "Rotation")
        if not self.editor.apply(label, f"shape-{field}", shape=new):
            self.refresh(self.editor.design)

    def set_cross_section(self, kind: str):
        """Change the cross-section kind; missing sections are copies of the first one (equal
        sections meet in a round finish whatever the kind; the designer then edits them)."""
        shape = self.editor.design.shape
        if not kind or kind == shape.cross_section:
            return
        sections = tuple((n, shape.primary) for n in SECTION_NAMES[kind])
        try:
            new = BottleShape(kind, sections, shape.wall_thickness, shape.base_thickness,
                              shape.rotation_deg, None)
        except ValueError as exc:
            self.show_problem(str(exc))
            new = None
        if new is None or not self.editor.apply(f"Cross-section {words.word(words.CROSS_SECTIONS, kind)}",
                                                None, shape=new):
            self.refresh(self.editor.design)

    def _on_name_chosen(self, name: str):
        if name and self.shape is not None and name != self.current_name:
            self.current_name = name
            self.canvas.select(-1)
            self.refresh(self.editor.design)

    def _on_canvas_selection(self, row: int):
        if row >= 0 and self.table.currentIndex().row() != row:
            with QSignalBlocker(self.table.selectionModel()):
                self.table.selectRow(row)
        self._sync_smooth_button()

    def _sync_smooth_button(self):
        sec, row = self.model.section, self.canvas.selected
        button = self.tool_buttons["smooth"]
        with QSignalBlocker(button):
            button.setChecked(sec is not None and 0 <= row < len(sec.smooth) and sec.smooth[row])

    def run_tool(self, key: str) -> bool:
        """Run a segment tool on the selected segment; ``False`` when refused or impossible."""
        if key == "fit":
            self.canvas.fit()
            return True
        if key == "snap":
            self.canvas.snap_mm = 0.5 if self.tool_buttons["snap"].isChecked() else 0.0
            return True
        sec, row = self.model.section, self.canvas.selected
        if sec is None or not 0 <= row < len(sec.segments):
            self.show_problem("select a segment first")
            return False
        try:
            if key == "split":
                new, label = edits.split_segment(sec, row), "Split segment"
            elif key == "delete":
                new, label = edits.delete_segment(sec, row), "Delete segment"
            elif key == "insert":
                new, label = edits.insert_line_after(sec, row), "Insert line"
            elif key == "smooth":
                new, label = edits.set_smooth(sec, row, not sec.smooth[row]) if row < len(sec.smooth) \
                    else edits.set_smooth(sec, row, True), "Toggle smooth joint"
            else:
                new = edits.convert_segment(sec, row, key)
                label = f"Convert to {words.word(words.SEGMENT_KINDS, key).lower()}"
        except ValueError as exc:
            self.show_problem(f"segment {row}: {exc}")
            self._sync_smooth_button()
            return False
        ok = self.propose_section(new, label)
        if key == "delete" and ok:
            self.canvas.select(min(row, len(new.segments) - 1))
        self._sync_smooth_button()
        return ok
