"""The selected label's artwork and its flat die-line, with the printer's figures and warnings.

Design rule: a part of the labels panel (:mod:`widgets.labels.panel`), made with the editor and
the selected label (:class:`~widgets.labels.selection.SelectedLabel`). The die-line and its
warnings are :func:`engine.appearance.report.label_report`'s, the same the ``glassbench labels``
command prints, drawn once the label has held still for :data:`DIELINE_SETTLE_MS` (a drag does
not flatten at every step). The artwork is decoded once per content and shown decimated when
huge; a click on it reports its sRGB colour to the eyedropper.
"""
from __future__ import annotations

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QGroupBox, QHBoxLayout, QLabel, QVBoxLayout

from engine.appearance import images, report
from engine.errors import GlassbenchError
from widgets.labels.views import ArtworkView, DielineView

#: How long (ms) a label must hold still before its die-line is drawn again (flattening a
#: doubly curved band takes about half a second).
DIELINE_SETTLE_MS = 150


class PreviewBox(QGroupBox):
    """Artwork and die-line of the label ``selection`` (a
    :class:`~widgets.labels.selection.SelectedLabel` of ``editor``'s design)."""

    def __init__(self, editor, selection):
        super().__init__("Artwork and die-line")
        self.editor = editor
        self.selection = selection
        self._thumbs: dict = {}
        self.art = None  # the front artwork shown, sRGB uint8 RGBA
        self.report = None
        self.timer = QTimer(self)
        self.timer.setSingleShot(True)
        self.timer.setInterval(DIELINE_SETTLE_MS)
        self.timer.timeout.connect(self.show_dieline)
        self.artwork = ArtworkView()
        self.artwork.setToolTip("The front artwork; with the eyedropper on, click a colour to key a "
                                "finish region to it (Shift+click adds a key)")
        self.dieline = DielineView()
        self.figures = QLabel("")
        self.figures.setWordWrap(True)
        self.warnings = QLabel("")
        self.warnings.setWordWrap(True)
        self.warnings.setStyleSheet("color: #b00020")
        views = QHBoxLayout()
        views.addWidget(self.artwork, 1)
        views.addWidget(self.dieline, 1)
        box = QVBoxLayout(self)
        box.addLayout(views)
        box.addWidget(self.figures)
        box.addWidget(self.warnings)

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

    def show_label(self, lab, assets) -> None:
        """Take ``lab``'s artwork; its die-line follows once it holds still."""
        self.art = self._thumbnail(assets, lab.front.asset)
        self.timer.start()

    def show_artwork(self, claimed=None) -> None:
        """Draw the artwork, with where the selected region applies (``claimed``) outlined."""
        self.artwork.set_pixels(self.art, "front: plain colour", claimed)

    def clear(self) -> None:
        self.timer.stop()
        self.report = self.art = None
        self.artwork.set_pixels(None, "no label: Add\u2026 or drop an image on the preview")
        self.dieline.set_report(None)
        self.figures.setText("")
        self.warnings.setText("")

    def show_dieline(self) -> None:
        """Flatten the selected label and show its die-line, figures and warnings."""
        i = self.selection.index
        if i < 0:
            return
        try:
            self.report = report.label_report(self.editor.design, i)
        except (GlassbenchError, ValueError, ArithmeticError) as exc:
            self.report = None
            self.dieline.set_report(None)
            self.figures.setText("")
            self.warnings.setText(f"No die-line: {exc}")
            return
        self.dieline.set_report(self.report)
        r = self.report
        self.figures.setText(f"Die-line: {report.describe(r.flat.figures)}; {r.area_mm2:.0f} mm\u00b2 on the glass, "
                             f"largest strain {100 * r.max_strain:.2f} %")
        self.warnings.setText("\n".join(w.message for w in r.warnings))
