"""Where the panes sit: the preview the largest, the window inside the screen, the layout kept.

Design rule: the preview is the central widget and takes what the docks leave: the section
editor on the left with the plan editor as a tab beside it, the 3D view above the design numbers
on the right, and the materials, the camera, the stage, the labels, the bump tiles and the cap as
tabs below them. Every dock's panel sits in a scroll area, so no panel's size can push the
window past the screen (a 1600 x 1000 screen fits everything, status bar included). The window
opens on the available part of its screen; closing it stores its geometry, the docks' state, the
section splitter and the tint thicknesses in the window's ``QSettings``, and the next window
restores them (clamped to the screen it opens on).
"""
from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import QByteArray, QRect, QSignalBlocker, QSize, Qt
from PySide6.QtWidgets import QDockWidget, QFrame, QScrollArea

from widgets.bumps_panel import BumpsPanel
from widgets.camera_panel import CameraPanel
from widgets.cap_panel import CapPanel
from widgets.labels import LabelsPanel
from widgets.materials_panel import MaterialsPanel
from widgets.plan_editor import PlanPanel
from widgets.section_panel import SectionPanel
from widgets.stage_panel import StagePanel
from widgets.trade_panel import TradeNumbersPanel

#: Widths (px) of the side docks on a fresh layout; the preview gets the rest.
SECTION_WIDTH = 440
SIDE_WIDTH = 410
#: Height (px) of the 3D view on a fresh layout.
WIREFRAME_HEIGHT = 300
#: Largest default window (px); bigger screens get this much, smaller ones all they have.
DEFAULT_SIZE = QSize(1600, 1000)
KEYS = {"geometry": "window/geometry", "rect": "window/rect", "state": "window/state",
        "split": "window/section_split",
        "glass_mm": "tint/glass_mm", "liquid_mm": "tint/liquid_mm"}
STATE_VERSION = 2


@dataclass(frozen=True)
class Panel:
    """One panel of the window: the window's attribute, its class (made with the editor), its
    dock's key, title (its tab's text), side, the name a saved layout knows it by (default: the
    title) and tooltip."""

    attr: str
    cls: type
    key: str
    title: str
    area: Qt.DockWidgetArea = Qt.RightDockWidgetArea
    name: str | None = None
    tip: str | None = None


#: Every panel, once: the window makes them in this order and docks them so. Each follows the
#: scene, refusals and the derived numbers itself (:func:`widgets.edit_fields.follow`); nobody
#: routes to it.
PANELS = (Panel("section_panel", SectionPanel, "section", "Section", Qt.LeftDockWidgetArea),
          Panel("plan_panel", PlanPanel, "plan", "Plan", Qt.LeftDockWidgetArea,
                tip="The plan outline of an outline bottle, at its widest core"),
          Panel("trade_panel", TradeNumbersPanel, "design", "Design"),
          Panel("materials_panel", MaterialsPanel, "materials", "Materials"),
          # why the short title: six tabs share the side's width; the name keeps saved layouts
          Panel("camera_panel", CameraPanel, "camera", "Camera", name="Camera and environment",
                tip="Camera, environment and image size"),
          Panel("stage_panel", StagePanel, "stage", "Stage", tip="What the bottle stands on"),
          Panel("labels_panel", LabelsPanel, "labels", "Labels"),
          Panel("bumps_panel", BumpsPanel, "bumps", "Bump tiles"),
          Panel("cap_panel", CapPanel, "cap", "Cap"))
#: The docks that share one tab row below the Design numbers (the first one raised).
TABBED = ("materials", "camera", "stage", "labels", "bumps", "cap")
#: The docks that share one tab row on the left (the first one raised).
TABBED_LEFT = ("section", "plan")


def make_panels(window) -> None:
    """Make every panel of :data:`PANELS` on ``window.editor`` as the window's attribute."""
    for panel in PANELS:
        setattr(window, panel.attr, panel.cls(window.editor))


def scrolled(widget) -> QScrollArea:
    """``widget`` in a frameless scroll area that lets it shrink below its own minimum size."""
    area = QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    area.setFrameShape(QFrame.NoFrame)
    area.setHorizontalScrollBarPolicy(Qt.ScrollBarAsNeeded)
    return area


def add_dock(window, title: str, widget, area, scroll: bool = True, name: str | None = None) -> QDockWidget:
    """A dock titled ``title`` (its tab's text) named ``name`` (default: the title; the name is
    what a saved layout remembers it by)."""
    dock = QDockWidget(title, window)
    dock.setObjectName(name or title)
    dock.setWidget(scrolled(widget) if scroll else widget)
    window.addDockWidget(area, dock)
    return dock


def build_docks(window) -> dict:
    """Put ``window``'s panels in docks around the preview; returns them by name."""
    window.setCentralWidget(window.preview)
    docks = {}
    for panel in PANELS:
        if panel.area == Qt.RightDockWidgetArea and "wireframe" not in docks and window.wireframe is not None:
            # the 3D view tops the right side
            docks["wireframe"] = add_dock(window, "3D view", window.wireframe, Qt.RightDockWidgetArea,
                                          scroll=False)
        docks[panel.key] = add_dock(window, panel.title, getattr(window, panel.attr), panel.area,
                                    name=panel.name)
        if panel.tip:
            docks[panel.key].setToolTip(panel.tip)
    for row in (TABBED_LEFT, TABBED):
        first, *rest = row
        for name in rest:  # one tab row: the side stays uncrowded
            window.tabifyDockWidget(docks[first], docks[name])
        docks[first].raise_()
    return docks


def default_sizes(window, docks: dict):
    """The fresh layout: side docks at their default widths, the 3D view at its height."""
    window.resizeDocks([docks["section"]], [SECTION_WIDTH], Qt.Horizontal)
    window.resizeDocks([docks["design"]], [SIDE_WIDTH], Qt.Horizontal)
    if "wireframe" in docks:
        window.resizeDocks([docks["wireframe"]], [WIREFRAME_HEIGHT], Qt.Vertical)


def screen_rect(window) -> QRect:
    """The available geometry (px) of the screen the window is on (or the primary one)."""
    screen = window.screen()
    return screen.availableGeometry() if screen is not None else QRect(0, 0, 1600, 1000)


def fit_to_screen(window):
    """Give ``window`` the default size, or all of its screen when that is smaller, and keep
    it (frame included) inside the screen."""
    avail = screen_rect(window)
    frame = window.frameGeometry().size() - window.geometry().size()
    width = min(DEFAULT_SIZE.width(), avail.width()) - frame.width()
    height = min(DEFAULT_SIZE.height(), avail.height()) - frame.height()
    window.resize(max(width, 200), max(height, 200))
    clamp_to_screen(window)


def clamp_to_screen(window):
    """Shrink and move ``window`` so that all of it is on its screen."""
    avail = screen_rect(window)
    frame = window.frameGeometry().size() - window.geometry().size()
    width = min(window.width(), avail.width() - frame.width())
    height = min(window.height(), avail.height() - frame.height())
    if (width, height) != (window.width(), window.height()):
        window.resize(width, height)
    g = window.frameGeometry()
    x = min(max(g.x(), avail.x()), avail.right() - g.width() + 1)
    y = min(max(g.y(), avail.y()), avail.bottom() - g.height() + 1)
    if (x, y) != (g.x(), g.y()):
        window.move(x, y)


def restore(window, settings) -> bool:
    """Restore the layout stored in ``settings``; ``False`` when there was none."""
    geometry, state = settings.value(KEYS["geometry"]), settings.value(KEYS["state"])
    if not isinstance(geometry, QByteArray) or not isinstance(state, QByteArray):
        return False
    ok = window.restoreGeometry(geometry) and window.restoreState(state, STATE_VERSION)
    rect = settings.value(KEYS["rect"])
    if isinstance(rect, QRect) and not window.isMaximized():
        # why: restoreGeometry guesses the window frame without a window manager and shrinks
        # the window by a title bar it does not have; the plain rectangle comes back exactly
        window.resize(rect.size())
        window.move(rect.topLeft())
    split = settings.value(KEYS["split"])
    if isinstance(split, QByteArray):
        window.section_panel.split.restoreState(split)
    panel = window.materials_panel
    for key, spin in (("glass_mm", panel.glass_thickness), ("liquid_mm", panel.liquid_thickness)):
        try:
            value = float(settings.value(KEYS[key], spin.value()))
        except (TypeError, ValueError):
            continue
        with QSignalBlocker(spin):  # a remembered view of the tint, not an edit of the glass
            spin.setValue(value)
    panel.refresh(window.scene.design)
    clamp_to_screen(window)
    return ok


def save(window, settings):
    """Store the window's layout in ``settings`` (on closing)."""
    settings.setValue(KEYS["geometry"], window.saveGeometry())
    settings.setValue(KEYS["rect"], QRect(window.pos(), window.size()))
    settings.setValue(KEYS["state"], window.saveState(STATE_VERSION))
    settings.setValue(KEYS["split"], window.section_panel.split.saveState())
    settings.setValue(KEYS["glass_mm"], window.materials_panel.glass_thickness.value())
    settings.setValue(KEYS["liquid_mm"], window.materials_panel.liquid_thickness.value())
    settings.sync()


def preview_size(pane_px: tuple[int, int], width: int, height: int, max_pixels: int) -> tuple[int, int]:
    """The largest render with the aspect of ``width`` x ``height`` (the design's image) that
    fits ``pane_px`` (device pixels) and has at most ``max_pixels`` pixels."""
    pw, ph = pane_px
    scale = min(pw / width, ph / height)
    scale = min(scale, (max_pixels / (width * height)) ** 0.5)
    return max(1, int(width * scale)), max(1, int(height * scale))
