"""Labels panel: the labels on the bottle, their placement, sheet, faces and finish regions, with
the artwork (eyedropper for key colours) and the flat die-line a printer cuts beside it.

Design rule: like every panel, edits become ``editor.apply(text, merge_key, labels=...)``
(with ``assets=`` where an image is embedded or no longer used), so each is one undoable step,
validated by the engine (a label that leaves the wall is refused with its message);
``refresh(design, assets)`` writes the model into the widgets with their signals blocked.
Images are read with :func:`engine.appearance.images.read_image_file` and decoded with
:func:`~engine.appearance.images.decode_image` *before* anything changes, so a corrupt, truncated
or huge file is refused with the engine's one-line message and the design stays as it was.
The die-line and its warnings are :func:`engine.appearance.report.label_report`'s, the same
the ``glassbench labels`` command prints, drawn once the label has held still for
:data:`DIELINE_SETTLE_MS` (a drag does not flatten at every step). A new label (button or an image dropped onto the
preview) is sized from its artwork's aspect and placed where the drop point meets the bottle
(:func:`app.engine_bridge.surface_point`); without a point, or when the point misses the glass,
it faces the camera at the body's mid-height. Shift+drag on the preview moves the selected
label (:meth:`LabelsPanel.place_selected`); its size is set by the numbers.
"""
from __future__ import annotations

import dataclasses
import math
import os

import numpy as np
from PySide6.QtCore import QPointF, QRectF, QSignalBlocker, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import (QCheckBox, QComboBox, QFileDialog, QFormLayout, QGroupBox,
                               QHBoxLayout, QLabel, QLineEdit, QListWidget, QPushButton,
                               QSizePolicy, QVBoxLayout, QWidget)

from engine.appearance import images, presets, report
from engine.appearance.cap_surfaces import cap_surface
from engine.appearance.regions import region_map
from engine.cli.labels import asset_name, camera_azimuth_deg, describe
from engine.appearance.frame import Placement, label_frame
from engine.errors import GlassbenchError
from engine.model.design import FINISH_KINDS, Label, LabelSide
from widgets import edit_fields as ef

FINISH_WORDS = {"gold_foil": "Gold foil", "silver_foil": "Silver foil", "clear_vinyl": "Clear vinyl",
                "clear_vinyl_white": "Clear vinyl, white underprint", "emboss": "Emboss",
                "varnish": "Varnish"}
IMAGE_FILTER = "Images (" + " ".join("*" + e for e in images.EXTENSIONS) + ")"
#: Side (px) of the artwork picture drawn in the panel.
THUMB_PX = 220
#: How long (ms) a label must hold still before its die-line is drawn again (flattening a
#: doubly curved band takes about half a second).
DIELINE_SETTLE_MS = 150


#: The designer's words for where a label lies (``Label.surface``).
SURFACE_WORDS = {"wall": "bottle", "cap-top": "cap top", "cap-skirt": "cap skirt"}


def placed_on(design, label: Label, surface: str) -> Label:
    """``label`` moved onto ``surface`` of ``design``: on the cap centred on its top (read from
    the front) or half-way up its skirt, shrunk to fit (aspect kept); on the wall at 40 % of
    the height. Raises the engine's ``DesignError`` when the design has no such surface."""
    if surface == "wall":
        return dataclasses.replace(label, surface=surface, z_mm=round(0.4 * design.shape.z_top, 1))
    surf = cap_surface(design, surface)
    w, h = label.width_mm, label.height_mm
    if surface == "cap-top":  # the rectangle's diagonal within 90 % of the disk
        scale = min(1.0, 0.9 * 2.0 * surf.radius / math.hypot(w, h))
        z = label.z_mm
    else:
        scale = min(1.0, 0.8 * surf.height_mm / h, 0.5 * 2.0 * math.pi * surf.radius / w)
        z = round(0.5 * surf.height_mm, 2)
    w, h = (max(1.0, math.floor(10.0 * v * scale) / 10.0) for v in (w, h))
    return dataclasses.replace(label, surface=surface, z_mm=z, cap_x_mm=0.0, cap_y_mm=0.0,
                               width_mm=w, height_mm=h)


def is_image_path(path: str) -> bool:
    return os.path.splitext(path)[1].lower() in images.EXTENSIONS


def read_checked_image(path: str) -> bytes:
    """The bytes of an image file checked and decoded once (``ArtworkError``/``OSError``)."""
    data = images.read_image_file(path)
    images.decode_image(data, os.path.basename(path))
    return data


def assets_in_use(design) -> set:
    """Every asset name ``design`` refers to (environment, labels, bump tiles)."""
    names = {design.environment.asset} | {t.asset for t in design.bumps}
    names |= {n for lab in design.labels for n in lab.asset_names()}
    return {n for n in names if n is not None}


class ArtworkView(QWidget):
    """The front artwork, fitted; a click reports the texel's sRGB colour (``picked``)."""

    picked = Signal(tuple, bool)  # (r, g, b) sRGB 0..1, shift held (add a key)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumSize(THUMB_PX // 2, THUMB_PX // 2)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        self.pixels: np.ndarray | None = None  # sRGB uint8 (H, W, 4)
        self._image = None
        self.claimed: np.ndarray | None = None
        self.text = "no artwork"

    def sizeHint(self):  # noqa: N802 - Qt's name
        from PySide6.QtCore import QSize
        return QSize(THUMB_PX, THUMB_PX)

    def set_pixels(self, pixels: np.ndarray | None, text: str = "", claimed: np.ndarray | None = None):
        """Show ``pixels`` (sRGB uint8 RGBA; what the eyedropper reads) with the texels where
        ``claimed`` (bool, same rows and columns) is true tinted magenta: the selected region."""
        self.pixels = pixels
        self.claimed = claimed
        shown = pixels
        if pixels is not None and claimed is not None and claimed.shape == pixels.shape[:2]:
            shown = pixels.copy()
            tint = np.array([255, 0, 200], np.float32)
            shown[claimed, :3] = np.round(0.45 * shown[claimed, :3] + 0.55 * tint).astype(np.uint8)
            shown[claimed, 3] = 255
        self._image = ef.qimage_of(shown) if shown is not None else None
        self.text = text
        self.update()

    def image_rect(self) -> QRectF:
        """Where the artwork is drawn (widget px), aspect kept."""
        if self.pixels is None:
            return QRectF()
        h, w = self.pixels.shape[:2]
        scale = min(self.width() / w, self.height() / h)
        return QRectF((self.width() - w * scale) / 2, (self.height() - h * scale) / 2, w * scale, h * scale)

    def texel_at(self, pos: QPointF):
        """``(row, column)`` of the artwork under widget point ``pos``, or ``None``."""
        r = self.image_rect()
        if self.pixels is None or not r.contains(pos):
            return None
        h, w = self.pixels.shape[:2]
        col = min(int((pos.x() - r.x()) / r.width() * w), w - 1)
        row = min(int((pos.y() - r.y()) / r.height() * h), h - 1)
        return row, col

    def colour_at(self, pos: QPointF):
        at = self.texel_at(pos)
        if at is None:
            return None
        return tuple(float(v) / 255.0 for v in self.pixels[at[0], at[1], :3])

    def paintEvent(self, event):  # noqa: N802
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(60, 60, 64))
        if self._image is not None:
            p.drawImage(self.image_rect(), self._image)
        else:
            p.setPen(QColor(200, 200, 200))
            p.drawText(self.rect(), Qt.AlignCenter, self.text)

    def mousePressEvent(self, event):  # noqa: N802
        colour = self.colour_at(event.position())
        if colour is not None and event.button() == Qt.LeftButton:
            self.picked.emit(colour, bool(event.modifiers() & Qt.ShiftModifier))


class DielineView(QWidget):
    """The label's flat shape to scale (outline in mm, y up), warnings marked in red."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumSize(THUMB_PX // 2, THUMB_PX // 2)
        self.setSizePolicy(QSizePolicy.Expanding, QSizePolicy.Preferred)
        self.outline: np.ndarray | None = None
        self.figures: dict = {}
        self.marks: list[tuple[float, float]] = []
        self.setToolTip("The flat die-line a printer cuts, to scale; red: where the label cannot lie flat")

    def sizeHint(self):  # noqa: N802
        from PySide6.QtCore import QSize
        return QSize(THUMB_PX, THUMB_PX)

    def set_report(self, report):
        """Show ``report`` (a :class:`engine.appearance.report.LabelReport`, ``None``: nothing)."""
        if report is None:
            self.outline, self.figures, self.marks = None, {}, []
        else:
            self.outline = np.asarray(report.flat.outline(), float)
            self.figures = dict(report.flat.figures)
            self.marks = [(w.x_mm, w.y_mm) for w in report.warnings]
        self.update()

    @property
    def kind(self) -> str | None:
        return self.figures.get("kind")

    def paintEvent(self, event):  # noqa: N802
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        p.fillRect(self.rect(), QColor(250, 250, 248))
        if self.outline is None or len(self.outline) < 3:
            return
        lo, hi = self.outline.min(axis=0), self.outline.max(axis=0)
        span = np.maximum(hi - lo, 1e-6)
        margin = 10.0
        scale = min((self.width() - 2 * margin) / span[0], (self.height() - 2 * margin) / span[1])
        cx, cy = (lo + hi) / 2

        def to_px(x, y):
            return QPointF(self.width() / 2 + (x - cx) * scale, self.height() / 2 - (y - cy) * scale)

        path = QPainterPath()
        path.addPolygon(QPolygonF([to_px(x, y) for x, y in self.outline]))
        path.closeSubpath()
        p.setPen(QPen(QColor(20, 20, 20), 1.5))
        p.setBrush(QColor(255, 255, 255))
        p.drawPath(path)
        p.setPen(Qt.NoPen)
        p.setBrush(QColor(220, 30, 30))
        for x, y in self.marks:
            p.drawEllipse(to_px(x, y), 4, 4)


class LabelsPanel(QWidget):
    """Edits ``design.labels`` (and the assets their images are) through ``editor``.

    Signals
    -------
    message(str)
        Something to tell the designer (a refused image); the window shows it in the status bar.
    """

    message = Signal(str)

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self._thumbs: dict = {}
        self._art: np.ndarray | None = None  # the front artwork shown, sRGB uint8 RGBA
        self._select = self._select_region = None  # rows to show after an add, move or remove
        self.dieline_timer = QTimer(self)
        self.dieline_timer.setSingleShot(True)
        self.dieline_timer.setInterval(DIELINE_SETTLE_MS)
        self.dieline_timer.timeout.connect(self._show_dieline)
        self.report = None
        self.list = QListWidget()
        self.list.setToolTip("The labels on the bottle; later ones lie on top where they overlap")
        self.list.setMaximumHeight(72)
        self.add_button = QPushButton("Add\u2026")
        self.add_button.setToolTip("Add a label with an artwork image (PNG, JPEG, TIFF, EXR), "
                                   "embedded in the project; you can also drop an image on the preview")
        self.remove_button = QPushButton("Remove")
        self.up_button = QPushButton("\u2191")
        self.up_button.setToolTip("Earlier in the overlap order (under the labels after it)")
        self.down_button = QPushButton("\u2193")
        self.down_button.setToolTip("Later in the overlap order (on top of the labels before it)")
        self.problem = QLabel("")
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #b00020")
        for b in (self.up_button, self.down_button):
            b.setMaximumWidth(40)
        buttons = QHBoxLayout()
        for b in (self.add_button, self.remove_button, self.up_button, self.down_button):
            buttons.addWidget(b)

        self.name = QLineEdit()
        self.name.setToolTip("The label's name (unique in the design; the command line uses it)")
        self.surface = QComboBox()
        for key, text in SURFACE_WORDS.items():
            self.surface.addItem(text, key)
        self.surface.setToolTip("Where the label lies: on the bottle's wall, or printed on the "
                                "cap's flat top or its skirt (the design needs a cap)")
        self.z_mm = ef.spin(0, 5000, 1, 1.0, " mm", "Height of the label's centre above the standing "
                            "plane (on the cap's skirt: above the skirt's lower edge)")
        self.cap_x_mm = ef.spin(-500, 500, 1, 0.5, " mm", "Cap top: the print's centre, x from the axis")
        self.cap_y_mm = ef.spin(-500, 500, 1, 0.5, " mm", "Cap top: the print's centre, y from the axis")
        self.angle_deg = ef.spin(-360, 360, 1, 5.0, " \u00b0", "Azimuth of the label's centre about the "
                                 "axis, from +x towards +y (on the cap's top: where its reader "
                                 "stands, its bottom edge towards them)")
        self.height_mm = ef.spin(1, 5000, 1, 1.0, " mm", "Height along the wall (slant)")
        self.width_mm = ef.spin(1, 5000, 1, 1.0, " mm", "Arc length around the girth at mid-height")
        self.sheet = QComboBox()
        self.sheet.addItem("(custom)", None)
        for name in presets.SHEET_PRESETS:
            self.sheet.addItem(name, name)
        self.sheet.setToolTip("Coefficient sets of typical papers and films")
        self.diffuse = ef.spin(0, 1, 3, 0.01, tip="Diffuse reflectance K: multiplies the face colour")
        self.specular = ef.spin(0, 1, 3, 0.01, tip="Weight of the clear coat's highlight")
        self.transmission = ef.spin(0, 1, 3, 0.01, tip="Diffuse transmission of the sheet "
                                    "(diffuse + transmission at most 1)")
        self.front_image = QPushButton("Image\u2026")
        self.front_color = ef.LinearColorButton()
        self.back_image = QPushButton("Image\u2026")
        self.back_color = ef.LinearColorButton()
        self.front_text, self.back_text = QLabel(""), QLabel("")
        for b, side in ((self.front_image, "front"), (self.back_image, "back")):
            b.setToolTip(f"Print the {side} with an image")
        self.front_color.setToolTip("The front as a plain colour (no image)")
        self.back_color.setToolTip("The back as a plain colour (no image): seen through the bottle")

        self.artwork = ArtworkView()
        self.artwork.setToolTip("The front artwork; with the eyedropper on, click a colour to key a "
                                "finish region to it (Shift+click adds a key)")
        self.dieline = DielineView()
        self.figures = QLabel("")
        self.figures.setWordWrap(True)
        self.warnings = QLabel("")
        self.warnings.setWordWrap(True)
        self.warnings.setStyleSheet("color: #b00020")

        self.regions = QListWidget()
        self.regions.setMaximumHeight(60)
        self.regions.setToolTip("Finish regions of the front; later ones win where they overlap")
        self.region_preset = QComboBox()
        for name in presets.FINISH_PRESETS:
            self.region_preset.addItem(name, name)
        self.region_preset.setToolTip("The finish a new region gets, or the selected region takes")
        self.add_region = QPushButton("Add region")
        self.remove_region = QPushButton("Remove region")
        self.apply_preset = QPushButton("Apply preset")
        self.finish = QComboBox()
        for kind in FINISH_KINDS:
            self.finish.addItem(FINISH_WORDS[kind], kind)
        self.source = QComboBox()
        self.source.addItem("Chroma key", "chroma")
        self.source.addItem("Mask image", "mask")
        self.eyedropper = QCheckBox("Eyedropper")
        self.eyedropper.setToolTip("Click the artwork to make the colour under the pointer the "
                                   "region's key (Shift+click adds one)")
        self.keys_text = QLabel("")
        self.keys_text.setWordWrap(True)
        self.tolerance = ef.spin(0, 1, 3, 0.01, tip="How far (sRGB distance) a colour may be from a "
                                 "key and still belong to the region")
        self.mask_button = QPushButton("Mask image\u2026")
        self.mask_button.setToolTip("A separation image: where it is dark, the region applies")
        self.depth_mm = ef.spin(-2, 2, 2, 0.05, " mm", "Relief of an emboss (negative: debossed)")
        self.gloss = ef.spin(0, 1, 2, 0.05, tip="Smoothness: 0 matte .. 1 mirror")

        ef.compact(self.sheet, self.region_preset, self.finish, self.source)
        top = QVBoxLayout()
        top.addWidget(self.list)
        top.addLayout(buttons)
        top.addWidget(self.problem)
        self.details = QWidget()
        place_box = QGroupBox("Placement (on the surface)")
        pf = QFormLayout(place_box)
        pf.addRow("Name", self.name)
        pf.addRow("On", self.surface)
        for text, w in (("Centre height", self.z_mm), ("Centre x", self.cap_x_mm), ("Centre y", self.cap_y_mm),
                        ("Centre angle", self.angle_deg), ("Height", self.height_mm), ("Width", self.width_mm)):
            pf.addRow(text, w)
        sheet_box = QGroupBox("Sheet")
        sf = QFormLayout(sheet_box)
        sf.addRow("Preset", self.sheet)
        sf.addRow("Diffuse", self.diffuse)
        sf.addRow("Specular", self.specular)
        sf.addRow("Transmission", self.transmission)
        for text, image, colour, shown in (("Front", self.front_image, self.front_color, self.front_text),
                                           ("Back", self.back_image, self.back_color, self.back_text)):
            row = QHBoxLayout()
            row.addWidget(image)
            row.addWidget(colour)
            sf.addRow(text, row)
            sf.addRow("", shown)
        views = QHBoxLayout()
        views.addWidget(self.artwork, 1)
        views.addWidget(self.dieline, 1)
        view_box = QGroupBox("Artwork and die-line")
        vb = QVBoxLayout(view_box)
        vb.addLayout(views)
        vb.addWidget(self.figures)
        vb.addWidget(self.warnings)
        region_box = QGroupBox("Finish regions")
        rf = QFormLayout(region_box)
        rf.addRow(self.regions)
        rbuttons = QHBoxLayout()
        rbuttons.addWidget(self.region_preset, 1)
        rbuttons.addWidget(self.add_region)
        rf.addRow(rbuttons)
        rb2 = QHBoxLayout()
        rb2.addWidget(self.apply_preset)
        rb2.addWidget(self.remove_region)
        rf.addRow(rb2)
        rf.addRow("Finish", self.finish)
        rf.addRow("From", self.source)
        rf.addRow(self.eyedropper, self.keys_text)
        rf.addRow("Tolerance", self.tolerance)
        rf.addRow(self.mask_button)
        rf.addRow("Emboss depth", self.depth_mm)
        rf.addRow("Gloss", self.gloss)
        dl = QVBoxLayout(self.details)
        dl.setContentsMargins(0, 0, 0, 0)
        for box in (place_box, view_box, sheet_box, region_box):
            dl.addWidget(box)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(self.details)
        layout.addStretch(1)

        self.list.currentRowChanged.connect(lambda _: self.refresh(self.editor.design, self.editor.scene.assets))
        self.regions.currentRowChanged.connect(lambda _: self._show_region())
        self.add_button.clicked.connect(lambda: self.add_label())
        self.remove_button.clicked.connect(self.remove_label)
        self.up_button.clicked.connect(lambda: self.move_label(-1))
        self.down_button.clicked.connect(lambda: self.move_label(1))
        self.name.editingFinished.connect(self._rename)
        self.surface.currentIndexChanged.connect(lambda _: self.choose_surface(self.surface.currentData()))
        for w, key, text in ((self.z_mm, "z_mm", "Label height"), (self.angle_deg, "angle_deg", "Label angle"),
                             (self.cap_x_mm, "cap_x_mm", "Label centre x"),
                             (self.cap_y_mm, "cap_y_mm", "Label centre y"),
                             (self.height_mm, "height_mm", "Label size"), (self.width_mm, "width_mm", "Label width"),
                             (self.diffuse, "diffuse", "Label diffuse"), (self.specular, "specular", "Label specular"),
                             (self.transmission, "transmission", "Label transmission")):
            w.valueChanged.connect(lambda v, key=key, text=text: self._edit(text, key, **{key: v}))
        self.sheet.currentIndexChanged.connect(lambda _: self._sheet_preset(self.sheet.currentData()))
        self.front_image.clicked.connect(lambda: self.choose_side_image("front"))
        self.back_image.clicked.connect(lambda: self.choose_side_image("back"))
        self.front_color.clicked.connect(lambda: self.choose_side_color("front"))
        self.back_color.clicked.connect(lambda: self.choose_side_color("back"))
        self.artwork.picked.connect(self.pick_key)
        self.eyedropper.toggled.connect(
            lambda on: self.artwork.setCursor(Qt.CrossCursor if on else Qt.ArrowCursor))
        self.add_region.clicked.connect(lambda: self.add_finish_region(self.region_preset.currentData()))
        self.remove_region.clicked.connect(self.remove_finish_region)
        self.apply_preset.clicked.connect(lambda: self.apply_finish_preset(self.region_preset.currentData()))
        self.finish.currentIndexChanged.connect(lambda _: self._edit_region("Region finish", None,
                                                                             finish=self.finish.currentData()))
        self.source.currentIndexChanged.connect(lambda _: self._source_chosen(self.source.currentData()))
        self.tolerance.valueChanged.connect(lambda v: self._edit_region("Key tolerance", "tolerance", tolerance=v))
        self.depth_mm.valueChanged.connect(lambda v: self._edit_region("Emboss depth", "depth", depth_mm=v))
        self.gloss.valueChanged.connect(lambda v: self._edit_region("Region gloss", "gloss", gloss=v))
        self.mask_button.clicked.connect(self.choose_mask)
        self.refresh(editor.design, editor.scene.assets)

    # ---------------------------------------------------------------- replaceable asks
    def choose_image_file(self, title: str) -> str | None:
        """Ask for an image file; tests replace this method."""
        path, _ = QFileDialog.getOpenFileName(self, title, "", IMAGE_FILTER)
        return path or None

    def choose_color(self, initial_linear, title: str):
        """Ask for a colour (linear RGB) or ``None``; tests replace this method."""
        return ef.ask_linear_color(self, initial_linear, title)

    # ------------------------------------------------------------------- helpers
    @property
    def index(self) -> int:
        """The selected label (-1: none)."""
        i = self.list.currentRow()
        return i if 0 <= i < len(self.editor.design.labels) else -1

    @property
    def label(self) -> Label | None:
        i = self.index
        return self.editor.design.labels[i] if i >= 0 else None

    @property
    def region_index(self) -> int:
        lab = self.label
        k = self.regions.currentRow()
        return k if lab is not None and 0 <= k < len(lab.regions) else -1

    def _refuse(self, text: str):
        self.problem.setText(text)
        self.message.emit(f"Refused: {text}")

    def _image(self, path: str | None, title: str):
        """``(path, bytes)`` of a checked image file (asked for when ``path`` is ``None``);
        ``bytes`` is ``None`` when none was chosen or it was refused (and said why)."""
        path = path or self.choose_image_file(title)
        if not path:
            return path, None
        try:
            return path, read_checked_image(path)
        except (GlassbenchError, OSError, ValueError) as exc:
            self._refuse(str(exc))
            return path, None

    def _apply_labels(self, text: str, key, labels: tuple, assets: dict | None = None,
                      select: int | None = None) -> bool:
        self.problem.setText("")
        self._select = select  # the refresh that follows shows this one
        ok = self.editor.apply(text, key, assets=assets, labels=labels)
        self._select = None
        if not ok:
            self.refresh(self.editor.design, self.editor.scene.assets)
        return ok

    def _put(self, text: str, key, label: Label, assets: dict | None = None) -> bool:
        i = self.index
        return i >= 0 and self._apply_labels(text, key, ef.replaced(self.editor.design.labels, i, label), assets)

    def _edit(self, text: str, field: str, **fields) -> bool:
        lab = self.label
        if lab is None:
            return False
        return self._put(text, f"label-{self.index}-{field}", dataclasses.replace(lab, **fields))

    def _dropped_assets(self, new_design_labels: tuple, extra: dict | None = None) -> dict:
        """The labels' images no longer referred to once the labels are ``new_design_labels``
        (-> None: they leave the project; assets the labels never named stay)."""
        current = self.editor.design
        used = assets_in_use(dataclasses.replace(current, labels=new_design_labels))
        had = {n for lab in current.labels for n in lab.asset_names()}
        out = {n: None for n in had - used}
        out.update(extra or {})
        return out

    # ----------------------------------------------------------------- labels
    def new_label(self, name: str, data: bytes, asset: str, at=None) -> Label:
        """A label showing ``data`` (named ``asset``), sized from its aspect, placed at ``at``
        (``(z_mm, angle_deg)``) or facing the camera at the body's mid-height."""
        design = self.editor.design
        info = images.probe_image(data, name)
        shape = design.shape
        height = round(max(10.0, min(60.0, 0.3 * shape.z_top)), 1)
        z, angle = at if at is not None else (round(0.4 * shape.z_top, 1),
                                              round(camera_azimuth_deg(design.camera), 1))
        z = min(max(z, height / 2 + 2.0), shape.z_top - height / 2 - 2.0)
        width = round(height * info.width / info.height, 1)
        d, s, t = presets.SHEET_PRESETS[presets.DEFAULT_SHEET]
        label = Label(name, LabelSide(asset), LabelSide(), round(z, 1), angle, height, width, d, s, t)
        try:  # narrow it to the girth there (a label wraps at most once)
            from engine.appearance.frame import Placement, label_frame
            girth = label_frame(shape, Placement.of(label)).girth_mm
            if width > 0.9 * girth:
                label = dataclasses.replace(label, width_mm=round(0.9 * girth, 1))
        except (GlassbenchError, ValueError, ArithmeticError):
            pass  # the editor's check says what is wrong
        return label

    def add_label(self, path: str | None = None, at=None) -> bool:
        """Add a label with the image at ``path`` (asked for when ``None``) as its front, at
        ``at`` (``(z_mm, angle_deg)``) or facing the camera; one undo step."""
        path, data = self._image(path, "Label artwork")
        if data is None:
            return False
        design, assets = self.editor.design, self.editor.scene.assets
        names = {lab.name for lab in design.labels}
        base = os.path.splitext(os.path.basename(path))[0] or "label"
        name, k = base, 2
        while name in names:
            name, k = f"{base} {k}", k + 1
        asset = asset_name(name, "front", data, assets)
        label = self.new_label(name, data, asset, at)
        labels = design.labels + (label,)
        return self._apply_labels(f"Add label {name}", None, labels, {asset: data}, select=len(labels) - 1)

    def remove_label(self) -> bool:
        i = self.index
        if i < 0:
            return False
        labels = ef.removed(self.editor.design.labels, i)
        name = self.editor.design.labels[i].name
        return self._apply_labels(f"Remove label {name}", None, labels, self._dropped_assets(labels),
                                  select=min(i, len(labels) - 1))

    def move_label(self, step: int) -> bool:
        """Move the selected label ``step`` places in the overlap order."""
        i = self.index
        labels = ef.moved(self.editor.design.labels, i, step)
        if labels is None:
            return False
        return self._apply_labels(f"Reorder label {labels[i + step].name}", None, labels, select=i + step)

    def choose_surface(self, surface: str) -> bool:
        """Put the selected label on ``surface`` (:data:`SURFACE_WORDS`' keys), centred there
        and shrunk to fit (aspect kept); one undo step, refused by the engine with its message
        (a design without a cap, a crown's skirt)."""
        lab = self.label
        if lab is None or surface is None or surface == lab.surface:
            return False
        design = self.editor.design
        try:
            moved = placed_on(design, lab, surface)
        except (GlassbenchError, ValueError) as exc:
            self._refuse(str(exc))
            self.refresh(design, self.editor.scene.assets)
            return False
        return self._put(f"Label on the {SURFACE_WORDS[surface]}", None, moved)

    def place_selected(self, at, merge_key=None) -> bool:
        """Move the selected label's centre to ``at`` (``(z_mm, angle_deg)`` on the wall);
        ``merge_key`` makes a drag's moves one undo step. A print on the cap is placed by its
        numbers only."""
        lab = self.label
        if lab is None or lab.surface != "wall":
            return False
        z, angle = (round(float(v), 1) for v in at)
        return self._put("Move label", merge_key, dataclasses.replace(lab, z_mm=z, angle_deg=angle))

    def size_selected(self, at, merge_key=None) -> bool:
        """Size the selected label, kept centred, so that a corner lies at ``at`` (``(z_mm,
        angle_deg)`` on the surface: :meth:`engine.appearance.frame.LabelFrame.size_to`);
        ``merge_key`` makes a drag's sizes one undo step. At least 1 mm a side."""
        lab = self.label
        if lab is None or lab.surface != "wall":
            return False
        try:
            frame = label_frame(self.editor.design.shape, Placement.of(lab))
            height, width = frame.size_to(*at)
        except (GlassbenchError, ValueError, ArithmeticError):
            return False
        height, width = (round(max(1.0, v), 1) for v in (height, width))
        return self._put("Size label", merge_key, dataclasses.replace(lab, height_mm=height, width_mm=width))

    def _rename(self):
        lab = self.label
        if lab is not None and self.name.text() != lab.name:
            self._edit("Rename label", "name", name=self.name.text())

    def _sheet_preset(self, name):
        if name is None or self.label is None:
            return
        d, s, t = presets.SHEET_PRESETS[name]
        self._put(f"Sheet {name}", None, dataclasses.replace(self.label, diffuse=d, specular=s, transmission=t))

    def choose_side_image(self, side: str) -> bool:
        lab = self.label
        data = self._image(None, f"Label {side}")[1] if lab is not None else None
        if data is None:
            return False
        asset = asset_name(lab.name, side, data, self.editor.scene.assets)
        new = dataclasses.replace(lab, **{side: LabelSide(asset, getattr(lab, side).color)})
        labels = ef.replaced(self.editor.design.labels, self.index, new)
        return self._apply_labels(f"Label {side} image", None, labels, self._dropped_assets(labels, {asset: data}))

    def choose_side_color(self, side: str) -> bool:
        lab = self.label
        if lab is None:
            return False
        rgb = self.choose_color(getattr(lab, side).color, f"Label {side} colour")
        if rgb is None:
            return False
        new = dataclasses.replace(lab, **{side: LabelSide(None, tuple(rgb))})
        labels = ef.replaced(self.editor.design.labels, self.index, new)
        return self._apply_labels(f"Label {side} colour", None, labels, self._dropped_assets(labels))

    # ----------------------------------------------------------------- regions
    def _regions(self, text: str, key, regions: tuple, assets: dict | None = None, select=None) -> bool:
        lab = self.label
        if lab is None:
            return False
        self._select_region = select
        new = dataclasses.replace(lab, regions=regions)
        labels = ef.replaced(self.editor.design.labels, self.index, new)
        ok = self._apply_labels(text, key, labels, self._dropped_assets(labels, assets))
        self._select_region = None
        return ok

    def _edit_region(self, text: str, key, **fields) -> bool:
        lab, k = self.label, self.region_index
        if k < 0:
            return False
        region = dataclasses.replace(lab.regions[k], **fields)
        return self._regions(text, None if key is None else f"label-{self.index}-region-{k}-{key}",
                             ef.replaced(lab.regions, k, region))

    def _first_colour(self) -> tuple:
        """A starting key: the artwork's centre colour (sRGB), white without artwork."""
        px = self.artwork.pixels
        if px is None:
            return (1.0, 1.0, 1.0)
        h, w = px.shape[:2]
        return tuple(float(v) / 255.0 for v in px[h // 2, w // 2, :3])

    def add_finish_region(self, preset: str | None) -> bool:
        lab = self.label
        if lab is None or preset is None:
            return False
        region = presets.finish_preset(preset, keys=(self._first_colour(),))
        return self._regions(f"Add {preset}", None, lab.regions + (region,), select=len(lab.regions))

    def remove_finish_region(self) -> bool:
        k = self.region_index
        if k < 0:
            return False
        regions = ef.removed(self.label.regions, k)
        return self._regions("Remove region", None, regions, select=min(k, len(regions) - 1))

    def apply_finish_preset(self, preset: str | None) -> bool:
        if preset is None or self.region_index < 0:
            return False
        p = presets.FINISH_PRESETS[preset]
        return self._edit_region(f"Finish {preset}", None, finish=p.finish, depth_mm=p.depth_mm, gloss=p.gloss)

    def _source_chosen(self, source: str):
        k = self.region_index
        if k < 0 or source == self.label.regions[k].source:
            return
        region = self.label.regions[k]
        if source == "mask" and region.mask_asset is None:
            if not self.choose_mask():
                self._show_region()
            return
        keys = region.keys or (self._first_colour(),)
        self._edit_region("Region from a chroma key" if source == "chroma" else "Region from a mask",
                          None, source=source, keys=keys)

    def pick_key(self, srgb: tuple, add: bool = False) -> bool:
        """The eyedropper: make ``srgb`` (0..1) the selected region's key (``add``: one more)."""
        k = self.region_index
        if not self.eyedropper.isChecked() or k < 0:
            return False
        region = self.label.regions[k]
        key = tuple(round(v, 6) for v in srgb)
        keys = (region.keys + (key,)) if add and region.source == "chroma" else (key,)
        return self._edit_region("Pick key colour", None, source="chroma", keys=keys)

    def choose_mask(self) -> bool:
        k = self.region_index
        data = self._image(None, "Finish mask")[1] if k >= 0 else None
        if data is None:
            return False
        lab = self.label
        asset = asset_name(lab.name, f"mask{k}", data, self.editor.scene.assets)
        region = dataclasses.replace(lab.regions[k], source="mask", mask_asset=asset)
        return self._regions("Region mask", None, ef.replaced(lab.regions, k, region), {asset: data})

    # ------------------------------------------------------------------ model → view
    def _thumbnail(self, assets, asset: str | None):
        """sRGB uint8 RGBA of an asset (cached by content), or ``None``."""
        if asset is None or asset not in assets:
            return None
        data = assets[asset]
        key = (asset, hash(data))  # bytes cache their hash: cheap after the first time
        if key not in self._thumbs:
            try:
                rgba = images.decode_image(data, asset)
            except (GlassbenchError, ValueError):
                return None
            h, w = rgba.shape[:2]
            step = max(1, max(h, w) // 1024)  # a huge image is shown (and picked) decimated
            self._thumbs.clear()
            self._thumbs[key] = images.display_rgba8(rgba[::step, ::step])
        return self._thumbs[key]

    def refresh(self, design, assets=None):
        assets = self.editor.scene.assets if assets is None else assets
        widgets = (self.list, self.name, self.surface, self.z_mm, self.cap_x_mm, self.cap_y_mm, self.angle_deg,
                   self.height_mm, self.width_mm, self.sheet, self.diffuse, self.specular, self.transmission,
                   self.regions)
        blockers = [QSignalBlocker(w) for w in widgets]
        ef.show_rows(self.list, [lab.name for lab in design.labels],
                     self.list.currentRow() if self._select is None else self._select)
        lab = self.label
        self.details.setEnabled(lab is not None)
        for b in (self.remove_button, self.up_button, self.down_button):
            b.setEnabled(lab is not None)
        if lab is None:
            self.dieline_timer.stop()
            self.report = self._art = None
            self.artwork.set_pixels(None, "no label: Add\u2026 or drop an image on the preview")
            self.dieline.set_report(None)
            self.figures.setText("")
            self.warnings.setText("")
            self.regions.clear()
            del blockers
            return
        self.name.setText(lab.name)
        self.surface.setCurrentIndex(max(0, self.surface.findData(lab.surface)))
        self.z_mm.setEnabled(lab.surface != "cap-top")
        for w in (self.cap_x_mm, self.cap_y_mm):
            w.setEnabled(lab.surface == "cap-top")
        for w, v in ((self.z_mm, lab.z_mm), (self.cap_x_mm, lab.cap_x_mm), (self.cap_y_mm, lab.cap_y_mm),
                     (self.angle_deg, lab.angle_deg), (self.height_mm, lab.height_mm),
                     (self.width_mm, lab.width_mm), (self.diffuse, lab.diffuse), (self.specular, lab.specular),
                     (self.transmission, lab.transmission)):
            w.setValue(v)
        sheet = next((n for n, v in presets.SHEET_PRESETS.items()
                      if v == (lab.diffuse, lab.specular, lab.transmission)), None)
        self.sheet.setCurrentIndex(max(0, self.sheet.findData(sheet)) if sheet else 0)
        for side, colour, text in (("front", self.front_color, self.front_text),
                                   ("back", self.back_color, self.back_text)):
            face = getattr(lab, side)
            colour.set_linear(face.color)
            text.setText(f"image {face.asset}" if face.asset else "plain colour")
        self._art = self._thumbnail(assets, lab.front.asset)
        self.dieline_timer.start()  # after a pause: a free band's flattening takes a moment
        region_names = [f"{r.name} ({FINISH_WORDS.get(r.finish, r.finish)})" for r in lab.regions]
        ef.show_rows(self.regions, region_names,
                     self.regions.currentRow() if self._select_region is None else self._select_region)
        del blockers
        self._show_region()

    def dieline_pending(self) -> bool:
        """Whether the die-line shown is not yet that of the selected label as it is now."""
        return self.dieline_timer.isActive()

    def shutdown(self):
        self.dieline_timer.stop()

    def _show_dieline(self):
        design = self.editor.design
        if self.index < 0:
            return
        try:
            self.report = report.label_report(design, self.index)
        except (GlassbenchError, ValueError, ArithmeticError) as exc:
            self.report = None
            self.dieline.set_report(None)
            self.figures.setText("")
            self.warnings.setText(f"No die-line: {exc}")
            return
        self.dieline.set_report(self.report)
        r = self.report
        self.figures.setText(f"Die-line: {describe(r.flat.figures)}; {r.area_mm2:.0f} mm\u00b2 on the glass, "
                             f"largest strain {100 * r.max_strain:.2f} %")
        self.warnings.setText("\n".join(w.message for w in r.warnings))

    def _show_region(self):
        widgets = (self.finish, self.source, self.tolerance, self.depth_mm, self.gloss)
        blockers = [QSignalBlocker(w) for w in widgets]
        k = self.region_index
        for w in widgets + (self.keys_text, self.mask_button, self.remove_region, self.apply_preset,
                            self.eyedropper):
            w.setEnabled(k >= 0)
        if k >= 0:
            r = self.label.regions[k]
            self.finish.setCurrentIndex(self.finish.findData(r.finish))
            self.source.setCurrentIndex(self.source.findData(r.source))
            self.tolerance.setValue(r.tolerance)
            self.depth_mm.setValue(r.depth_mm)
            self.depth_mm.setEnabled(r.finish == "emboss")
            self.gloss.setValue(r.gloss)
            if r.source == "chroma":
                self.keys_text.setText("keys: " + ", ".join(
                    QColor.fromRgbF(*key).name() for key in r.keys))
            else:
                self.keys_text.setText(f"mask {r.mask_asset}")
            self.tolerance.setEnabled(r.source == "chroma")
        else:
            self.keys_text.setText("")
        del blockers
        lab = self.label
        if lab is not None:
            self.artwork.set_pixels(self._art, "front: plain colour", self._claimed(lab, k))

    def _claimed(self, lab, k: int):
        """Where region ``k`` of ``lab`` applies, at the thumbnail's size (``None``: nothing)."""
        if k < 0 or self._art is None:
            return None
        try:
            rmap = region_map(lab, self.editor.scene.assets)
        except (GlassbenchError, ValueError, KeyError):
            return None
        h, w = self._art.shape[:2]
        rows = np.arange(h) * rmap.shape[0] // h
        cols = np.arange(w) * rmap.shape[1] // w
        return rmap[rows[:, None], cols[None, :]] == k + 1


__all__ = ["LabelsPanel", "ArtworkView", "DielineView"]
