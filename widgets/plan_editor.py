"""The plan editor panel: an outline bottle's plan outline, drawn, tabulated and edited.

Design rule: as the section panel, the panel talks to the model only through
``editor.apply(label, merge_key, shape=...)`` (an undoable, validated edit) and is refreshed by
``refresh(design)`` with its widgets' signals blocked. The geometry is the engine's: the edits
(:mod:`engine.geometry.editing.plan_tools`: every result a valid convex outline or a refusal
with its reason) and the quoted widths (:mod:`engine.geometry.plan_widths`). An edit renormalises
the outline, and :func:`~engine.geometry.editing.plan_tools.with_plan` scales the core so the
bottle keeps its millimetres; a drag's steps are all computed from the shape it started on, so
they merge into one undo step. Presets replace the outline and keep the core (the farthest
point stays where it was). A bottle without a plan outline leaves the panel disabled, with one
line that says why.
"""
from __future__ import annotations

from PySide6.QtCore import QSignalBlocker, Qt
from PySide6.QtWidgets import (QCheckBox, QFormLayout, QGridLayout, QHBoxLayout, QLabel,
                               QSizePolicy, QSpinBox, QSplitter, QToolButton, QVBoxLayout, QWidget)

from engine.errors import OutlineError
from engine.geometry.editing import plan_tools as pt
from engine.geometry.plan_widths import plan_widths, widest_core
from widgets import edit_fields as ef
from widgets import words
from widgets.plan_canvas import PlanCanvas
from widgets.plan_table import PlanTable

PRESET_WORDS = {
    "triangle": ("Triangle", "An equilateral triangle, a corner up"),
    "square": ("Square", "A square with its sides along x and y"),
    "hexagon": ("Hexagon", "A regular hexagon, a corner on +x"),
    "octagon": ("Octagon", "A regular octagon with sides along x and y"),
    "flask": ("Flask", "The four-arc oval of a hip flask, 2.5 times as wide as deep"),
    "shield": ("Shield", "A heraldic shield: a flat top, straight sides, two arcs meeting in a point"),
}
PRESETS_PER_ROW = 3


class PlanPanel(QWidget):
    """Edits ``design.shape.plan`` of an outline bottle through ``editor``
    (:class:`app.commands.DesignEditor`)."""

    FIELDS = frozenset({"shape"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.shape = None
        self.core = None  # the widest core (engine.geometry.plan_widths.WidestCore)
        self.widths = None
        self._asking = False
        self._base_key, self._base = None, None  # a drag's key and the shape it started on

        self.reason = QLabel("")
        self.reason.setWordWrap(True)
        self.body = QWidget()
        self.canvas = PlanCanvas()
        self.table = PlanTable()
        self.model = self.table.model()
        self.message = QLabel("")
        self.message.setWordWrap(True)
        self.message.setStyleSheet("color: #a02020")
        self.numbers = QLabel("")
        self.numbers.setWordWrap(True)
        self.numbers.setToolTip("Widths of the body's section at the widest core (where the core scale k is "
                                "largest): across the flats the least over all directions, across the "
                                "corners the largest; both include the rounding c on each side")

        presets = QGridLayout()
        self.preset_buttons = {}
        for i, (key, (text, tip)) in enumerate(PRESET_WORDS.items()):
            b = QToolButton()
            b.setText(text)
            b.setToolTip(tip + " (replaces the outline; the core scale stays)")
            b.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Fixed)
            b.clicked.connect(lambda _=False, k=key: self.apply_preset(k))
            presets.addWidget(b, i // PRESETS_PER_ROW, i % PRESETS_PER_ROW)
            self.preset_buttons[key] = b

        self.n_fold = QSpinBox()
        self.n_fold.setRange(1, 12)
        self.n_fold.setToolTip("n-fold symmetry of the edits: moving a joint moves its n-1 images turned "
                               "by 360/n degrees (1: none)")
        self.mirror = QCheckBox("Mirror (y axis)")
        self.mirror.setToolTip("Mirror symmetry of the edits about the y axis: a joint's mirror image moves "
                               "with it, and a joint on the axis stays on it")
        sym = QHBoxLayout()
        sym.addWidget(QLabel("n-fold"))
        sym.addWidget(self.n_fold)
        sym.addWidget(self.mirror)
        sym.addStretch(1)

        self.round_button = QToolButton()
        self.round_button.setText("Rounded corner")
        self.round_button.setCheckable(True)
        self.round_button.setToolTip("Select a line to round the sharp corner where it starts with a tangent "
                                     "arc of the radius beside; select such an arc to make the corner sharp")
        self.radius_spin = ef.spin(0.01, 1000.0, 2, 0.5, " mm", "Radius (mm) of the selected corner's arc in "
                                                                 "the core outline (the body adds the rounding c)")
        self.radius_spin.setValue(3.0)
        corner = QHBoxLayout()
        corner.addWidget(self.round_button)
        corner.addWidget(self.radius_spin)
        corner.addStretch(1)

        form = QFormLayout()
        form.addRow("Presets", presets)
        form.addRow("Symmetry", sym)
        form.addRow("Corner", corner)
        split = QSplitter(Qt.Vertical)
        split.addWidget(self.canvas)
        split.addWidget(self.table)
        split.setStretchFactor(0, 3)
        inner = QVBoxLayout(self.body)
        inner.setContentsMargins(0, 0, 0, 0)
        inner.addLayout(form)
        inner.addWidget(split, 1)
        inner.addWidget(self.numbers)
        inner.addWidget(self.message)
        layout = QVBoxLayout(self)
        layout.addWidget(self.reason)
        layout.addWidget(self.body, 1)

        for source in (self.canvas, self.model):
            source.planProposed.connect(self.propose_plan)
            source.problem.connect(self.show_problem)
        self.canvas.selectionChanged.connect(self._on_canvas_selection)
        self.table.selectionModel().currentRowChanged.connect(lambda cur, _: self.canvas.select(cur.row()))
        self.n_fold.valueChanged.connect(lambda _: self._sync_symmetry())
        self.mirror.toggled.connect(lambda _: self._sync_symmetry())
        self.round_button.clicked.connect(self.toggle_corner)
        self.radius_spin.valueChanged.connect(self.set_corner_radius)
        editor.refused.connect(self._on_refused)
        ef.follow(self, editor, self.FIELDS, lambda d, a: self.refresh(d))

    # ---------------------------------------------------------------- model → view
    def refresh(self, design):
        """Show ``design``'s plan (or say why there is none), its widths and the corner state."""
        shape = design.shape
        if shape != self.shape:
            self.message.setText("")  # a refusal was about the design before this change
        self.shape = shape
        outline = shape.cross_section == "outline"
        self.body.setEnabled(outline)
        self.reason.setVisible(not outline)
        if not outline:
            kind = words.word(words.CROSS_SECTIONS, shape.cross_section).lower()
            self.reason.setText(f"Only a bottle with a plan outline has a plan to edit; this one is {kind}.")
            self.core = self.widths = None
            self.canvas.show_plan(None, 0.0, 0.0)
            self.model.set_plan(None, 1.0)
            self.numbers.setText("")
            return
        self.core = widest_core(shape)
        self.widths = plan_widths(shape.plan, self.core.k, self.core.c)
        self.canvas.show_plan(shape.plan, self.core.k, self.core.c)
        self.model.set_plan(shape.plan, self.core.k)
        w, core = self.widths, self.core
        self.numbers.setText(f"Across flats {w.flats:.2f} mm, across corners {w.corners:.2f} mm\n"
                             f"at z {core.z:.2f} mm (core k {core.k:.2f} mm, rounding c {core.c:.2f} mm)")
        self._sync_corner()

    def show_problem(self, text: str):
        self.message.setText(text)

    def _on_refused(self, text: str):
        if self._asking:  # only this panel's own edits: the others say so themselves
            self.show_problem(text)

    def _sync_symmetry(self):
        sym = (self.n_fold.value(), self.mirror.isChecked())
        self.canvas.symmetry = self.model.symmetry = sym

    @property
    def symmetry(self) -> tuple[int, bool]:
        return self.canvas.symmetry

    def _on_canvas_selection(self, row: int):
        if row >= 0 and self.table.currentIndex().row() != row:
            with QSignalBlocker(self.table.selectionModel()):
                self.table.selectRow(row)
        self._sync_corner()

    def _sync_corner(self):
        """The corner toggle shows the selected segment's corner: checked for a rounded corner
        (its radius beside), unchecked for a line starting at a sharp corner, else disabled."""
        plan, row = self.model.plan, self.canvas.selected
        fillet = plan is not None and 0 <= row < len(plan.segments) and pt.is_fillet(plan, row)
        sharp = plan is not None and 0 <= row < len(plan.segments) and pt.is_sharp_corner(plan, row)
        with QSignalBlocker(self.round_button), QSignalBlocker(self.radius_spin):
            self.round_button.setEnabled(fillet or sharp)
            self.round_button.setChecked(fillet)
            if fillet:
                self.radius_spin.setValue(plan.segments[row].radius * self.core.k)

    # ---------------------------------------------------------------- view → command
    def propose_plan(self, plan, text: str, merge_key: str = "") -> bool:
        """Apply ``plan`` (in the units of the outline it was computed from: the shape a drag
        started on, or the current one) keeping the bottle's millimetres; one undo step per key."""
        if merge_key and merge_key == self._base_key:
            base = self._base
        else:
            base = self.editor.design.shape
            self._base_key, self._base = (merge_key, base) if merge_key else (None, None)
        return self._apply(text, merge_key, pt.with_plan(base, plan, plan.scale))

    def _apply(self, text: str, merge_key: str, shape) -> bool:
        self._asking = True
        try:
            ok = self.editor.apply(text, merge_key or None, shape=shape)
        finally:
            self._asking = False
        if ok:
            self.message.setText("")
        return ok

    def _edit(self, text: str, merge_key: str, make) -> bool:
        """Propose ``make(plan)`` (an engine edit of the current outline), or show its refusal."""
        shape = self.editor.design.shape
        try:
            plan = make(shape.plan)
        except OutlineError as exc:
            self.show_problem(str(exc))
            self._sync_corner()
            return False
        return self._apply(text, merge_key, pt.with_plan(shape, plan, plan.scale))

    def apply_preset(self, name: str) -> bool:
        """Replace the outline by the preset ``name`` (:data:`engine.geometry.editing.plan_tools.PRESETS`)."""
        shape = self.editor.design.shape
        if shape.cross_section != "outline":
            return False
        try:
            new = pt.with_plan(shape, pt.preset(name))
        except OutlineError as exc:
            self.show_problem(str(exc))
            return False
        return self._apply(f"Plan outline: {name} preset", "", new)

    def toggle_corner(self, rounded: bool) -> bool:
        """Round the sharp corner where the selected line starts (``rounded``), or make the
        selected rounded corner sharp."""
        row, (n, mirror), k = self.canvas.selected, self.symmetry, self.core.k
        if not 0 <= row < len(self.model.plan.segments):
            self.show_problem("select a corner's arc or the line after a sharp corner first")
            return False
        if rounded:
            r = self.radius_spin.value() / k
            return self._edit("Round plan corner", "", lambda p: pt.round_corner(p, row, r, n, mirror))
        return self._edit("Sharpen plan corner", "", lambda p: pt.sharpen_corner(p, row, n, mirror))

    def set_corner_radius(self, radius_mm: float) -> bool:
        """Give the selected rounded corner the radius ``radius_mm`` (mm, in the core outline)."""
        row, (n, mirror), k = self.canvas.selected, self.symmetry, self.core.k
        plan = self.editor.design.shape.plan
        if plan is None or not (0 <= row < len(plan.segments) and pt.is_fillet(plan, row)):
            return False  # the radius the next rounded corner will have
        return self._edit("Plan corner radius", "plan-corner-radius",
                          lambda p: pt.set_arc_radius(p, row, radius_mm / k, n, mirror))
