"""The 3D wireframe of the bottle (pyvistaqt ``QtInteractor``).

Design rule: the view only uploads finished line sets (built off the GUI thread by
:mod:`app.wireframe_controller`) into one persistent ``PolyData`` and renders once; it never
tessellates. It looks through the design's camera (:meth:`set_camera`, called whenever the
design's camera changes, so the two views stay in step: the same eye, target and vertical field
of view); the designer may orbit it freely, and "Camera from 3D view" copies it back. ``auto_update`` is off on purpose: the view renders when it gets new lines or
the user orbits, not on a timer. ``grab_framebuffer`` returns what VTK drew, so the window
can paint it into a ``QWidget.grab`` (which cannot see the OpenGL surface by itself).
"""
from __future__ import annotations

import math
import time

import numpy as np
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QVBoxLayout, QWidget

from engine.model.design import Camera


class WireframeView(QWidget):
    """A VTK view of the current wireframe; ``shutdown()`` closes the plotter."""

    def __init__(self, parent=None):
        super().__init__(parent)
        import pyvista as pv
        from pyvistaqt import QtInteractor
        self._pv = pv
        # why: multisampling costs ~20x per frame on software GL (Xvfb, remote desktops); a
        # wireframe of thin lines does not need it, and drags must stay smooth
        self.plotter = QtInteractor(self, auto_update=False, multi_samples=0)
        self.plotter.set_background("#202428")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.plotter.interactor)
        self.poly = None
        self.actor = None
        self.camera: Camera | None = None  # the design camera shown (None: frame the bottle)
        self.setToolTip("The bottle's outer glass through the design's camera: drag to orbit, "
                        "wheel to zoom; \u201cCamera from 3D view\u201d copies this view")
        self.last_upload_s = 0.0
        self.uploads = 0
        self._closed = False

    def show_lines(self, points: np.ndarray, edges: np.ndarray):
        """Replace the wireframe by ``edges`` (M, 2) between ``points`` (N, 3) in mm."""
        if self._closed:
            return
        t0 = time.perf_counter()
        cells = np.empty((len(edges), 3), dtype=np.int64)
        cells[:, 0] = 2
        cells[:, 1:] = edges
        new = self._pv.PolyData(np.asarray(points, dtype=float), lines=cells.ravel())
        if self.poly is None:
            self.poly = new
            self.actor = self.plotter.add_mesh(self.poly, color="#d8e4f0", line_width=1.0,
                                               reset_camera=False)
            if self.camera is None:
                self.plotter.view_xz()
                self.plotter.reset_camera()
            else:
                self._apply_camera()
        else:
            self.poly.copy_from(new)
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.render()
        self.uploads += 1
        self.last_upload_s = time.perf_counter() - t0

    def current_camera(self, template: Camera) -> Camera:
        """The view's camera as a design camera (keeps ``template``'s other fields)."""
        cam = self.plotter.camera
        eye, target, up = tuple(cam.position), tuple(cam.focal_point), tuple(cam.up)
        return Camera(eye=tuple(map(float, eye)), target=tuple(map(float, target)),
                      up=tuple(map(float, up)), fov_y_deg=float(cam.view_angle) or template.fov_y_deg)

    def set_camera(self, camera: Camera):
        """Look through the design's ``camera`` (eye, target, up in mm; vertical field of view)."""
        if self._closed:
            return
        self.camera = camera
        self._apply_camera()
        self.plotter.render()

    def _apply_camera(self):
        cam, c = self.plotter.camera, self.camera
        cam.position, cam.focal_point, cam.up = c.eye, c.target, c.up
        cam.view_angle = c.fov_y_deg
        self.plotter.renderer.ResetCameraClippingRange()

    def grab_framebuffer(self) -> QImage:
        """What VTK drew, as a QImage the size of the view (for window screenshots)."""
        if self._closed or self.poly is None:
            return QImage()
        self.plotter.render()
        img = np.ascontiguousarray(self.plotter.screenshot(return_img=True)[..., :3])
        h, w = img.shape[:2]
        return QImage(img.data, w, h, 3 * w, QImage.Format_RGB888).copy()

    def shutdown(self):
        """Close the plotter (releases the render window); safe to call twice."""
        if not self._closed:
            self._closed = True
            self.plotter.close()
            # why: the interactor keeps its GL surface as a plain QSurface wrapper, which PySide
            # cannot tell is deleted with the widget; left alive, its stale address entry is
            # handed out for the next Qt object born at that address (a section table's
            # selection model came back as a "QSurface": a flaky GUI test). Closed, the
            # interactor needs the surface no more.
            if getattr(self.plotter, "_surface", None) is not None:
                self.plotter._surface = None


def wireframe_extent(points: np.ndarray) -> float:
    """Largest distance (mm) of a point from the z axis, for framing."""
    return float(math.sqrt(np.max(points[:, 0] ** 2 + points[:, 1] ** 2))) if len(points) else 0.0
