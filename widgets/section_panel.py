"""The section editor panel: canvas, segment table, tools, cross-section kind and thicknesses.

Design rule: the panel talks to the model only through ``editor.apply(label, merge_key,
shape=...)`` (an undoable, validated edit) and is refreshed by ``refresh(design)`` with its
widgets' signals blocked, so a refresh never echoes back as an edit. A refused edit
shows the engine's message in the panel's message line.
"""
from __future__ import annotations

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtWidgets import (QComboBox, QDoubleSpinBox, QFormLayout, QHBoxLayout, QHeaderView,
                               QLabel, QSplitter, QTableView, QToolButton, QVBoxLayout, QWidget)

from engine.geometry.shape import SECTION_NAMES, BottleShape
from engine.geometry import editing as edits
from widgets.section_editor import SectionCanvas
from widgets.section_table import KindDelegate, MillimetreDelegate, SectionTableModel

#: Radial scale of the first section used to make the others when the kind changes. All 1:
#: every kind must meet in a round finish at the mouth, and equal sections are the one start
#: that is valid for any profile (the designer then edits the other sections).
_DERIVED_SCALE: dict[str, float] = {}


class SectionPanel(QWidget):
    """Edits ``design.shape`` through ``editor`` (see :class:`app.commands.DesignEditor`)."""

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.shape: BottleShape | None = None
        self.current_name = "profile"
        self.derived = {"inner": {}, "fill_z": None}
        self.canvas = SectionCanvas()
        self.model = SectionTableModel(self)
        self.table = QTableView()
        self.table.setModel(self.model)
        self.table.setItemDelegateForColumn(0, KindDelegate(self.table))
        self._mm_delegate = MillimetreDelegate(self.table)
        for column in range(1, 7):
            self.table.setItemDelegateForColumn(column, self._mm_delegate)
        # why: ResizeToContents asks every cell for its size on every change; size once per reset
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.Interactive)
        self.model.modelReset.connect(self.table.resizeColumnsToContents)
        self.message = QLabel("")
        self.message.setWordWrap(True)
        self.message.setStyleSheet("color: #a02020")

        self.kind_combo = QComboBox()
        self.kind_combo.addItems(list(SECTION_NAMES))
        self.name_combo = QComboBox()
        self.wall_spin = self._spin(0.3, 20.0, " mm wall")
        self.base_spin = self._spin(0.3, 60.0, " mm base")
        self.rotation_spin = self._spin(-180.0, 180.0, " \u00b0")
        form = QFormLayout()
        form.addRow("Cross-section", self.kind_combo)
        form.addRow("Section", self.name_combo)
        form.addRow("Wall", self.wall_spin)
        form.addRow("Base", self.base_spin)
        form.addRow("Rotation", self.rotation_spin)

        tools = QHBoxLayout()
        self.tool_buttons = {}
        for key, text in (("split", "Split"), ("delete", "Delete"), ("insert", "Insert line"),
                          ("line", "\u2192 line"), ("arc", "\u2192 arc"), ("ellipse_arc", "\u2192 ellipse"),
                          ("smooth", "Smooth"), ("snap", "Snap"), ("fit", "Fit")):
            b = QToolButton()
            b.setText(text)
            b.clicked.connect(lambda _=False, k=key: self.run_tool(k))
            tools.addWidget(b)
            self.tool_buttons[key] = b
        self.tool_buttons["smooth"].setCheckable(True)
        snap = self.tool_buttons["snap"]
        snap.setCheckable(True)
        snap.setChecked(True)
        snap.setToolTip("Snap dragged points to a 0.5 mm grid (hold Ctrl to drag freely)")
        tools.addStretch(1)

        split = QSplitter(Qt.Vertical)
        split.addWidget(self.canvas)
        split.addWidget(self.table)
        split.setStretchFactor(0, 3)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addLayout(tools)
        layout.addWidget(split, 1)
        layout.addWidget(self.message)

        self.canvas.sectionProposed.connect(self.propose_section)
        self.model.sectionProposed.connect(self.propose_section)
        self.model.problem.connect(self.show_problem)
        self.canvas.selectionChanged.connect(self._on_canvas_selection)
        self.canvas.toolRequested.connect(self.run_tool)
        self.table.selectionModel().currentRowChanged.connect(lambda cur, _: self.canvas.select(cur.row()))
        self.name_combo.currentTextChanged.connect(self._on_name_chosen)
        self.kind_combo.currentTextChanged.connect(self.set_cross_section)
        self.wall_spin.valueChanged.connect(lambda v: self._set_shape_number("wall_thickness", v))
        self.base_spin.valueChanged.connect(lambda v: self._set_shape_number("base_thickness", v))
        self.rotation_spin.valueChanged.connect(lambda v: self._set_shape_number("rotation_deg", v))
        editor.refused.connect(self.show_problem)

    @staticmethod
    def _spin(lo, hi, suffix) -> QDoubleSpinBox:
        s = QDoubleSpinBox()
        s.setRange(lo, hi)
        s.setDecimals(2)
        s.setSingleStep(0.1)
        s.setSuffix(suffix)
        s.setKeyboardTracking(False)
        return s

    # ---------------------------------------------------------------- model → view
    def set_derived(self, inner: dict, fill_z):
        """Inner walls (section name -> segments) and fill height (mm) computed off-thread for
        the newest shape; shown with the section until newer ones arrive."""
        self.derived = {"inner": dict(inner), "fill_z": fill_z}
        if self.shape is not None:
            self.canvas.show_section(self.canvas.section, self.derived["inner"].get(self.current_name),
                                     fill_z, self.canvas.ghosts)

    def refresh(self, design, derived: dict | None = None):
        """Show ``design.shape`` (with the last derived inner walls and fill line)."""
        if derived is not None:
            self.derived = derived
        derived = self.derived
        shape = design.shape
        self.shape = shape
        names = [n for n, _ in shape.sections]
        if self.current_name not in names:
            self.current_name = names[0]
        blockers = [QSignalBlocker(w) for w in (self.kind_combo, self.name_combo, self.wall_spin,
                                                 self.base_spin, self.rotation_spin)]
        self.kind_combo.setCurrentText(shape.cross_section)
        if [self.name_combo.itemText(i) for i in range(self.name_combo.count())] != names:
            self.name_combo.clear()
            self.name_combo.addItems(names)
        self.name_combo.setCurrentText(self.current_name)
        self.wall_spin.setValue(shape.wall_thickness)
        self.base_spin.setValue(shape.base_thickness)
        self.rotation_spin.setValue(shape.rotation_deg)
        self.rotation_spin.setEnabled(shape.cross_section != "round")
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

    # ---------------------------------------------------------------- view → command
    def propose_section(self, section, label: str, merge_key: str = ""):
        """Apply ``section`` in place of the current one (one undo step per merge key)."""
        shape = self.editor.design.shape.with_section(self.current_name, section)
        if self.editor.apply(label, merge_key or None, shape=shape):
            self.message.setText("")
            return True
        return False

    def _set_shape_number(self, field, value):
        shape = self.editor.design.shape
        new = BottleShape(shape.cross_section, shape.sections,
                          **{**{k: getattr(shape, k) for k in ("wall_thickness", "base_thickness",
                                                                "rotation_deg", "wall_per_segment")},
                             field: value})
        label = {"wall_thickness": "Wall thickness", "base_thickness": "Base thickness"}.get(field, "Rotation")
        if not self.editor.apply(label, f"shape-{field}", shape=new):
            self.refresh(self.editor.design)

    def set_cross_section(self, kind: str):
        """Change the cross-section kind; missing sections derive from the first one."""
        shape = self.editor.design.shape
        if kind == shape.cross_section:
            return
        first = shape.primary
        sections = tuple((n, edits.scaled_radially(first, _DERIVED_SCALE.get(n, 1.0)))
                         for n in SECTION_NAMES[kind])
        try:
            new = BottleShape(kind, sections, shape.wall_thickness, shape.base_thickness,
                              shape.rotation_deg, None)
        except ValueError as exc:
            self.show_problem(str(exc))
            new = None
        if new is None or not self.editor.apply(f"Cross-section {kind}", None, shape=new):
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
                if row >= len(sec.smooth):
                    raise ValueError("the mouth has no joint above it")
                new, label = edits.set_smooth(sec, row, not sec.smooth[row]), "Toggle smooth joint"
            else:
                new, label = edits.convert_segment(sec, row, key), f"Convert to {key}"
        except ValueError as exc:
            self.show_problem(f"segment {row}: {exc}")
            self._sync_smooth_button()
            return False
        ok = self.propose_section(new, label)
        if key == "delete" and ok:
            self.canvas.select(min(row, len(new.segments) - 1))
        self._sync_smooth_button()
        return ok
