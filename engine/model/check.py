"""Design values against their physics and the limits of :mod:`engine.limits`.

Design rule: :func:`check_values` is the one check of the numbers, texts and list sizes a
:class:`~engine.model.design.Design` holds, run before a project is written, after it is read
and before a panel's edit is accepted. It is cheap (linear in the design's size, no geometry):
section validity and the fill level need the geometry and are checked by
:func:`engine.operations.check.check_design`, which calls this first. Every error is a
:class:`engine.errors.DesignError` naming the field by its path in the project file
(``design.camera.fov_y_deg``) and showing the value and its range, bounded in length.
"""
from __future__ import annotations

import dataclasses
import math

from .. import limits as L
from ..errors import DesignError, shown
from ..geometry.segments import Arc, EllipseArc
from ..geometry.shape import BottleShape
from .fill import check_fill_mode
from .label_values import check_label_values
from .design import STAGE_KINDS
from .finish_values import check_finish_values

ENVIRONMENT_KINDS = ("studio", "file")


def check_values(design) -> None:
    """Raise ``DesignError`` for the first value of ``design`` outside its range.

    Checks, in order: every text (length, encodable as UTF-8) and list (length) anywhere in the
    design; the shape's sizes (segments per section, coordinates, radii, thicknesses, turn);
    the glass and liquid; the camera (distinct eye and target, an up vector off the viewing
    direction, the field of view); the environment; the lights; the labels
    (:func:`engine.model.label_values.check_label_values`); the bump tiles and the closure
    (:func:`~engine.model.finish_values.check_finish_values`); the render settings.
    """
    _check_texts_and_lists(design, "design")
    _check_shape(design.shape)
    _check_media(design)
    _check_camera(design.camera)
    env = design.environment
    if env.kind not in ENVIRONMENT_KINDS:
        raise DesignError(f"design.environment.kind must be 'studio' or 'file', got {shown(env.kind)}")
    if env.kind == "file" and env.asset is None:
        raise DesignError("design.environment.kind is 'file' but no asset is named")
    L.check_range("design.environment.scale", env.scale, L.ENV_SCALE_RANGE)
    turn = (-L.MAX_TURN_DEG, L.MAX_TURN_DEG)
    L.check_range("design.environment.rotation_deg", env.rotation_deg, turn, "deg")
    for i, light in enumerate(design.lights):
        where = f"design.lights[{i}]"
        _check_vector(f"{where}.direction", light.direction, L.MAX_CAMERA_MM, nonzero=True)
        for c, v in enumerate(light.color):
            L.check_range(f"{where}.color[{c}]", v, L.LIGHT_COLOR_RANGE)
        L.check_range(f"{where}.intensity", light.intensity, L.LIGHT_INTENSITY_RANGE)
        L.check_range(f"{where}.angle_deg", light.angle_deg, L.LIGHT_ANGLE_RANGE)
    check_label_values(design.labels)
    check_finish_values(design)
    _check_stage(design.stage)
    _check_plant(design.plant)
    r = design.render
    L.check_image_size(r.width, r.height, r.spp)
    L.check_range("design.render.max_depth", r.max_depth, L.MAX_DEPTH_RANGE, integer=True)
    L.check_range("design.render.min_weight", r.min_weight, L.MIN_WEIGHT_RANGE)


def _check_texts_and_lists(value, path: str) -> None:
    """Every string and tuple anywhere in the value tree (dataclasses, tuples), in one walk."""
    if isinstance(value, str):
        check_text(path, value)
    elif isinstance(value, BottleShape):
        return  # its sizes are checked by _check_shape (segments are not texts)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            _check_texts_and_lists(getattr(value, f.name), f"{path}.{f.name}")
    elif isinstance(value, (tuple, list)):
        if len(value) > L.MAX_LIST_ITEMS:
            raise DesignError(f"{path} has {len(value)} items (limit {L.MAX_LIST_ITEMS})")
        for i, item in enumerate(value):
            _check_texts_and_lists(item, f"{path}[{i}]")


def check_text(path: str, text: str) -> None:
    """Raise ``DesignError`` for a text longer than :data:`engine.limits.MAX_TEXT_CHARS` or one
    that cannot be written as UTF-8 (a lone surrogate such as ``"\\ud800"``)."""
    if len(text) > L.MAX_TEXT_CHARS:
        raise DesignError(f"{path} is {len(text)} characters long (limit {L.MAX_TEXT_CHARS})")
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise DesignError(f"{path} holds a character that cannot be stored "
                          f"({shown(text[exc.start:exc.end])} at {exc.start})") from None


def _check_shape(shape: BottleShape) -> None:
    ext = L.MAX_EXTENT_MM
    for name, sec in shape.sections:
        where = f"design.shape.sections.{name}.segments"
        if len(sec.segments) > L.MAX_SEGMENTS:
            raise DesignError(f"{where} has {len(sec.segments)} segments (limit {L.MAX_SEGMENTS})")
        for i, seg in enumerate(sec.segments):
            for key in ("p0", "p1"):
                _check_vector(f"{where}[{i}].{key}", getattr(seg, key), ext)
            if isinstance(seg, (Arc, EllipseArc)):
                _check_vector(f"{where}[{i}].center", seg.center, L.MAX_RADIUS_MM + ext)
                radii = ("radius",) if isinstance(seg, Arc) else ("radius_r", "radius_z")
                for key in radii:
                    L.check_range(f"{where}[{i}].{key}", getattr(seg, key), (0.0, L.MAX_RADIUS_MM), "mm")
    for key in ("wall_thickness", "base_thickness"):
        L.check_range(f"design.shape.{key}", getattr(shape, key), (0.0, ext), "mm")
    for i, w in enumerate(shape.wall_per_segment or ()):
        L.check_range(f"design.shape.wall_per_segment[{i}]", w, (0.0, ext), "mm")
    L.check_range("design.shape.rotation_deg", shape.rotation_deg, (-L.MAX_TURN_DEG, L.MAX_TURN_DEG), "deg")


def _check_media(design) -> None:
    media = [("glass", design.glass)] + ([("liquid", design.liquid)] if design.liquid else [])
    for name, medium in media:
        L.check_range(f"design.{name}.ior", medium.ior, L.IOR_RANGE)
        for c, a in enumerate(medium.absorption):
            L.check_range(f"design.{name}.absorption[{c}]", a, L.ABSORPTION_RANGE, "1/mm")
    L.check_range("design.glass.density_g_cm3", design.glass.density_g_cm3, L.DENSITY_RANGE, "g/cm3")
    liquid = design.liquid
    if liquid is not None:
        check_fill_mode(liquid)


def _check_camera(cam) -> None:
    for key in ("eye", "target"):
        _check_vector(f"design.camera.{key}", getattr(cam, key), L.MAX_CAMERA_MM)
    _check_vector("design.camera.up", cam.up, L.MAX_CAMERA_MM, nonzero=True)
    view = [t - e for t, e in zip(cam.target, cam.eye)]
    dist = math.hypot(*view)
    if dist < L.MIN_VIEW_DISTANCE_MM:
        raise DesignError(f"design.camera.eye and design.camera.target are {dist:.3g} mm apart "
                          f"(at least {L.MIN_VIEW_DISTANCE_MM:g} mm): the camera looks nowhere")
    up = cam.up
    cross = (view[1] * up[2] - view[2] * up[1], view[2] * up[0] - view[0] * up[2],
             view[0] * up[1] - view[1] * up[0])
    if math.hypot(*cross) < L.MIN_UP_SINE * dist * math.hypot(*up):
        raise DesignError("design.camera.up is parallel to the viewing direction (eye to target)")
    L.check_range("design.camera.fov_y_deg", cam.fov_y_deg, L.FOV_RANGE, "deg")


def _check_vector(path: str, vec, bound: float, nonzero: bool = False) -> None:
    for c, v in enumerate(vec):
        L.check_range(f"{path}[{c}]", v, (-bound, bound))
    if nonzero and not any(v != 0.0 for v in vec):
        raise DesignError(f"{path} must not be the zero vector")


#: ``(field, (lo, hi), unit)`` of each of the plant's settings (:class:`~engine.model.design.Plant`).
PLANT_RANGES = (("proof_pressure_mpa", (0.0, 50.0), "MPa"),
                ("liquid_density_g_ml", (0.5, 3.0), "g/ml"),
                ("closure_mass_g", (0.0, 1000.0), "g"),
                ("label_gsm", (0.0, 1000.0), "g/m^2"),
                ("min_tip_deg", (0.0, 89.0), "deg"),
                ("max_stress_mpa", (0.0, 1000.0), "MPa"),
                ("min_glass_mass_g", (0.0, 100000.0), "g"))


def _check_plant(plant) -> None:
    """The plant's settings within :data:`PLANT_RANGES`."""
    for name, bounds, unit in PLANT_RANGES:
        L.check_range(f"design.plant.{name}", getattr(plant, name), bounds, unit)


def _check_stage(stage) -> None:
    """Kind, colour and gloss of the ``Stage``."""
    if stage.kind not in STAGE_KINDS:
        raise DesignError(f"design.stage.kind {shown(stage.kind)} is not one of {', '.join(STAGE_KINDS)}")
    for c, v in enumerate(stage.color):
        L.check_range(f"design.stage.color[{c}]", v, (0.0, 1.0))
    L.check_range("design.stage.gloss", stage.gloss, (0.0, 1.0))
    L.check_range("design.stage.z_mm", stage.z_mm, (-10.0, -1e-4), "mm")
    L.check_range("design.stage.half_size_mm", stage.half_size_mm, (10.0, 1e6), "mm")
    if not isinstance(stage.backdrop, bool):
        raise DesignError(f"design.stage.backdrop must be true or false, got {shown(stage.backdrop)}")
