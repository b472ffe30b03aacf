"""Views of a batch: turntable frames about the bottle's axis, and named cameras.

Design rule: a view is a value that turns a variant's own camera into the camera of one frame,
so variants and views combine freely (a variant's camera override moves the whole turntable).
A named camera (``[cameras.NAME]`` in a job file, eye and target required, ``up`` +z and
``fov_y_deg`` 30 by default) replaces the variant's camera.
A turntable frame ``k`` of ``n`` orbits eye, target and up by ``360 k / n`` degrees about the
world z axis (the bottle's axis); the environment is not turned, so even a round bottle shows
its reflections move. Frame 0 is the variant's camera exactly. Units: mm and degrees.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..model.design import Camera


@dataclass(frozen=True)
class View:
    """One view: ``name`` (a file-name stem) and either a turntable angle or a fixed camera.

    ``angle_deg`` orbits the variant's camera about the z axis; ``camera`` (when not ``None``)
    replaces it. With neither, the view is the variant's own camera.
    """

    name: str
    angle_deg: float = 0.0
    camera: Camera | None = None

    def camera_for(self, own: Camera) -> Camera:
        """The camera of this view for a variant whose own camera is ``own``."""
        if self.camera is not None:
            return self.camera
        return orbit_about_axis(own, self.angle_deg)


def orbit_about_axis(camera: Camera, angle_deg: float) -> Camera:
    """``camera`` turned by ``angle_deg`` (counter-clockwise seen from +z) about the z axis.

    Eye, target and up turn together, so the view of the bottle is the same picture seen from
    another side; an angle of 0 returns ``camera`` itself.
    """
    if angle_deg % 360.0 == 0.0:
        return camera
    a = math.radians(angle_deg)
    c, s = math.cos(a), math.sin(a)

    def turn(v):
        x, y, z = v
        return (c * x - s * y, s * x + c * y, z)
    return Camera(eye=turn(camera.eye), target=turn(camera.target), up=turn(camera.up),
                  fov_y_deg=camera.fov_y_deg)


def turntable_views(frames: int, prefix: str = "frame_") -> tuple[View, ...]:
    """``frames`` views ``prefix0000 ...`` at ``360 k / frames`` degrees, k = 0 .. frames-1."""
    if not isinstance(frames, int) or isinstance(frames, bool) or frames < 1:
        raise ValueError(f"a turntable needs a whole number of frames >= 1, got {frames!r}")
    return tuple(View(f"{prefix}{k:04d}", angle_deg=360.0 * k / frames) for k in range(frames))


def job_views(tree, data: dict, turntable: int | None, check_name) -> tuple[View, ...]:
    """The views of a job file: ``turntable`` frames, then its ``[cameras.NAME]`` tables.

    ``check_name(key_path, name)`` refuses names that cannot be file names; a job with no
    views has one, ``view``, the variant's own camera. Raises the file's ``JobError``.
    """
    from .overrides import camera_from_table
    views = list(turntable_views(turntable)) if turntable else []
    cams = data.get("cameras", {})
    if not isinstance(cams, dict):
        raise tree.error(("cameras",), "cameras must be a table of named cameras")
    for name, table in cams.items():
        where = ("cameras", name)
        check_name(where, name)
        if any(v.name == name for v in views):
            raise tree.error(where, f"camera name {name!r} is also a turntable frame's name")
        if not isinstance(table, dict) or not {"eye", "target"} <= set(table):
            raise tree.error(where, f"camera {name!r} needs eye and target ([x, y, z] in mm)")
        cam = camera_from_table(table, Camera(),
                                lambda m, w=where, n=name: tree.error(w, f"camera {n!r}: {m}"))
        views.append(View(name, camera=cam))
    return tuple(views) or (View("view"),)
