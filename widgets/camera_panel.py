"""Camera and environment controls: orbit (azimuth, elevation, distance), target height, field
of view, environment strength and turn, render size and samples.

Design rule: the camera is stored as eye/target/up (SPEC section 2); this panel shows it as an
orbit about the target, which is how a designer turns a bottle. The conversion is the engine's
(:mod:`engine.model.orbit`); the panel only binds spin boxes to it.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

from PySide6.QtCore import QSignalBlocker, Signal
from PySide6.QtWidgets import (QComboBox, QFileDialog, QFormLayout, QGroupBox,
                               QPushButton, QSpinBox, QVBoxLayout, QWidget)

from engine.errors import GlassbenchError
from engine.io.read import read_bounded
from engine.limits import DEFAULT_LIMITS
from engine.model.orbit import camera_to_orbit, orbit_to_camera
from widgets import edit_fields, words


def _spin(lo, hi, step, suffix, decimals=1, tip=""):
    return edit_fields.spin(lo, hi, decimals, step, suffix, tip)


class CameraPanel(QWidget):
    """Edits ``design.camera``, ``design.environment`` and ``design.render`` through ``editor``.

    Signals
    -------
    syncFromWireframe()
        The designer asked to copy the 3D view's camera into the design.
    """

    syncFromWireframe = Signal()

    #: The design fields the panel shows (it follows the scene for them itself).
    FIELDS = frozenset({"camera", "environment", "render"})

    def __init__(self, editor, parent=None):
        super().__init__(parent)
        self.editor = editor
        self.azimuth = _spin(-180, 180, 5, " \u00b0", tip="Turn of the camera about the bottle "
                             "(degrees; 0 looks at the front)")
        self.azimuth.setWrapping(True)
        self.elevation = _spin(-89, 89, 2, " \u00b0", tip="Height of the camera above the target, "
                               "as an angle (degrees)")
        self.distance = _spin(10, 20000, 10, " mm", tip="Distance from the camera to the target (mm)")
        self.target_z = _spin(-1000, 5000, 5, " mm", tip="Height on the bottle's axis the camera looks "
                              "at (mm)")
        self.fov = _spin(1, 120, 1, " \u00b0", tip="Vertical field of view (degrees): smaller is a "
                         "longer lens")
        self.env_kind = QComboBox()
        words.fill_combo(self.env_kind, words.ENVIRONMENTS)
        self.env_kind.setToolTip("The light around the bottle")
        self.env_load = QPushButton("Load environment image\u2026")
        self.env_load.setToolTip("Embed an equirectangular image (EXR, HDR, PNG) in the project and "
                                 "light the bottle with it")
        self.env_scale = _spin(0, 100, 0.1, "", 2, tip="Brightness of the environment (1: as it is)")
        self.env_rotation = _spin(-180, 180, 5, " \u00b0", tip="Turn of the environment about the "
                                  "vertical axis (degrees)")
        self.width_px = QSpinBox()
        self.height_px = QSpinBox()
        self.spp = QSpinBox()
        for s, hi, tip in ((self.width_px, 8192, "Width of rendered images (px): glassbench render, "
                            "Final image; the preview renders at its pane's size in this shape"),
                           (self.height_px, 8192, "Height of rendered images (px), as the width"),
                           (self.spp, 4096, "Samples per pixel: more is smoother and slower")):
            s.setRange(1, hi)
            s.setKeyboardTracking(False)
            s.setToolTip(tip)
        self.sync_button = QPushButton("Camera from 3D view")
        self.sync_button.setToolTip("Make the design's camera the 3D view's (one undoable step); the "
                                    "3D view always starts from the design's camera")
        cam_box = QGroupBox("Camera")
        cf = QFormLayout(cam_box)
        for label, w in (("Azimuth", self.azimuth), ("Elevation", self.elevation),
                         ("Distance", self.distance), ("Target height", self.target_z),
                         ("Field of view", self.fov)):
            cf.addRow(label, w)
        cf.addRow(self.sync_button)
        env_box = QGroupBox("Environment")
        ef = QFormLayout(env_box)
        ef.addRow("Light", self.env_kind)
        ef.addRow(self.env_load)
        ef.addRow("Strength", self.env_scale)
        ef.addRow("Turn", self.env_rotation)
        image_box = QGroupBox("Images")
        imf = QFormLayout(image_box)
        imf.addRow("Width", self.width_px)
        imf.addRow("Height", self.height_px)
        imf.addRow("Samples / px", self.spp)
        for form in (cf, ef, imf):
            form.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        layout = QVBoxLayout(self)
        layout.addWidget(cam_box)
        layout.addWidget(env_box)
        layout.addWidget(image_box)
        layout.addStretch(1)
        for w in (self.azimuth, self.elevation, self.distance, self.target_z):
            w.valueChanged.connect(self._orbit_changed)
        self.fov.valueChanged.connect(lambda v: self.editor.apply(
            "Field of view", "camera-fov", camera=dataclasses.replace(self.editor.design.camera, fov_y_deg=v)))
        self.env_scale.valueChanged.connect(lambda v: self._env("Light strength", "env-scale", scale=v))
        self.env_rotation.valueChanged.connect(lambda v: self._env("Turn environment", "env-rot", rotation_deg=v))
        self.width_px.valueChanged.connect(lambda v: self._render("Image width", width=v))
        self.height_px.valueChanged.connect(lambda v: self._render("Image height", height=v))
        self.spp.valueChanged.connect(lambda v: self._render("Samples per pixel", spp=v))
        self.sync_button.clicked.connect(self.syncFromWireframe)
        self.env_kind.currentIndexChanged.connect(lambda _: self._env_kind_chosen(self.env_kind.currentData()))
        self.env_load.clicked.connect(self.load_environment)
        edit_fields.follow(self, editor, self.FIELDS, lambda d, a: self.refresh(d))

    def choose_environment_file(self) -> str | None:
        """Ask for an equirectangular image (EXR/HDR/PNG); tests replace this method."""
        path, _ = QFileDialog.getOpenFileName(self, "Environment image", "",
                                              "Images (*.exr *.hdr *.png *.jpg *.tif)")
        return path or None

    def load_environment(self) -> bool:
        """Embed an image in the project and light the scene with it (one undo step)."""
        path = self.choose_environment_file()
        if not path:
            return False
        try:
            data = read_bounded(path, DEFAULT_LIMITS.asset_bytes, "environment image")
        except (OSError, GlassbenchError) as exc:
            self.env_load.setToolTip(str(exc))
            return False
        name = Path(path).name
        env = dataclasses.replace(self.editor.design.environment, kind="file", asset=name)
        return self.editor.apply(f"Environment {name}", None, assets={name: data}, environment=env)

    def _env_kind_chosen(self, kind: str):
        env = self.editor.design.environment
        if not kind or kind == env.kind:
            return
        if kind == "file" and not env.asset:
            if not self.load_environment():
                self.refresh(self.editor.design)
            return
        self._env(f"Environment {words.word(words.ENVIRONMENTS, kind).lower()}", None, kind=kind)

    def refresh(self, design):
        widgets = (self.azimuth, self.elevation, self.distance, self.target_z, self.fov,
                   self.env_kind, self.env_scale, self.env_rotation, self.width_px, self.height_px, self.spp)
        blockers = [QSignalBlocker(w) for w in widgets]
        az, el, dist = camera_to_orbit(design.camera)
        self.azimuth.setValue(az)
        self.elevation.setValue(el)
        self.distance.setValue(dist)
        self.target_z.setValue(design.camera.target[2])
        self.fov.setValue(design.camera.fov_y_deg)
        words.select_key(self.env_kind, design.environment.kind)
        self.env_scale.setValue(design.environment.scale)
        self.env_rotation.setValue(design.environment.rotation_deg)
        self.width_px.setValue(design.render.width)
        self.height_px.setValue(design.render.height)
        self.spp.setValue(design.render.spp)
        del blockers

    def _orbit_changed(self, _value=None):
        cam = orbit_to_camera(self.editor.design.camera, self.azimuth.value(), self.elevation.value(),
                              self.distance.value(), self.target_z.value())
        self.editor.apply("Orbit camera", "camera-orbit", camera=cam)

    def _env(self, label, key, **fields):
        self.editor.apply(label, key, environment=dataclasses.replace(self.editor.design.environment, **fields))

    def _render(self, label, **fields):
        self.editor.apply(label, f"render-{label}", render=dataclasses.replace(self.editor.design.render, **fields))
