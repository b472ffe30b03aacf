"""The named operations on a design's labels: one door for the command line, the panel and batches.

Design rule: each operation takes the current ``Design`` (and the project's assets where images
are named) and returns an :class:`~engine.operations.edit.Edit`: the new design, the assets it adds or replaces (bytes)
or lets go (``None``: no longer used by anything), the words an undo stack shows, and the label
to select. Nothing is saved or applied here and nothing is checked beyond what the operation
itself needs: the caller applies the edit (the window's undoable
:class:`~app.commands.DesignEditor`, the CLI's save, a batch variant) and the design check runs
there (:func:`engine.operations.check.check_design`). Units mm and degrees; colours linear RGB.
"""
from __future__ import annotations

import dataclasses
import math
import os
import re
from typing import Mapping

from ..appearance import images, presets
from ..appearance.cap_surfaces import cap_surface
from ..appearance.frame import Placement, label_frame
from ..errors import DesignError, GlassbenchError, shown
from ..model.design import Label, LabelSide
from .edit import Edit, assets_in_use, swapped  # noqa: F401  (Edit is this module's result type)


def asset_name(name: str, role: str, data, taken) -> str:
    """A plain file name for a label image (``label-NAME-ROLE.ext``), unused in ``taken``."""
    stem = re.sub(r"[^\w\- ]+", "_", name).strip(" _.")[:80] or "label"
    ext = images.image_extension(data)
    base = f"label-{stem}-{role}"
    out, k = base + ext, 2
    while out in taken:
        out, k = f"{base}-{k}{ext}", k + 1
    return out


def unique_name(design, base: str) -> str:
    """``base``, or ``base 2``, ``base 3`` ... : a label name the design does not use yet."""
    names = {lab.name for lab in design.labels}
    name, k = base or "label", 2
    while name in names:
        name, k = f"{base} {k}", k + 1
    return name


def camera_azimuth_deg(camera) -> float:
    """Azimuth (deg, from +x towards +y) of the camera's eye about the z axis: a label there
    faces the camera (the front, -90, for an eye on the axis)."""
    x, y = camera.eye[0], camera.eye[1]
    return math.degrees(math.atan2(y, x)) if math.hypot(x, y) > 1e-9 else -90.0


def find_label(design, key: str) -> int:
    """Index of the label called ``key`` (or numbered ``key`` from 0); ``DesignError`` else."""
    names = [lab.name for lab in design.labels]
    if key in names:
        return names.index(key)
    if str(key).isdigit() and int(key) < len(names):
        return int(key)
    have = ", ".join(repr(n) for n in names[:8]) or "none"
    raise DesignError(f"the design has no label {shown(key)} (its labels: {have})")


def _with_labels(design, labels: tuple, text: str, extra: Mapping | None = None, select=None) -> Edit:
    """An :class:`Edit` setting ``labels``; the label images no longer used leave the project."""
    new = dataclasses.replace(design, labels=labels)
    had = {n for lab in design.labels for n in lab.asset_names()}
    out = {n: None for n in had - assets_in_use(new)}
    out.update(extra or {})
    return Edit(new, text, out, select)


def new_label(design, name: str, front: LabelSide, *, aspect=None, at=None, height_mm=None, width_mm=None,
              back=None, coefficients=None, surface="wall", cap_xy=(0.0, 0.0), exact=False) -> Label:
    """A label called ``name`` with face ``front``.

    ``at`` is ``(z_mm, angle_deg)`` of its centre (default: on the wall at 40 % of the height,
    facing the camera). ``height_mm`` defaults to 30 % of the bottle's height (10 to 60 mm);
    ``width_mm`` to the height times the artwork's ``aspect`` (width / height), and a label so
    sized wider than 90 % of the girth there is narrowed to it. Unless ``exact`` (numbers a
    designer typed), the centre is rounded to 0.1 mm and kept 2 mm inside the body.
    ``coefficients`` ``(diffuse, specular, transmission)`` default to the default sheet.
    """
    shape = design.shape
    height = round(max(10.0, min(60.0, 0.3 * shape.z_top)), 1) if height_mm is None else float(height_mm)
    z, angle = at if at is not None else (round(0.4 * shape.z_top, 1), round(camera_azimuth_deg(design.camera), 1))
    if not exact and surface == "wall":
        z = round(min(max(z, height / 2 + 2.0), shape.z_top - height / 2 - 2.0), 1)
    width = float(width_mm) if width_mm is not None else round(height * (aspect or 1.0), 1)
    d, s, t = coefficients if coefficients is not None else presets.SHEET_PRESETS[presets.DEFAULT_SHEET]
    label = Label(name, front, back if back is not None else LabelSide(), z, angle, height, width,
                  d, s, t, surface=surface, cap_x_mm=cap_xy[0], cap_y_mm=cap_xy[1])
    if surface == "wall" and width_mm is None:
        try:  # narrow it to the girth there (a label wraps at most once)
            girth = label_frame(shape, Placement.of(label)).girth_mm
            if width > 0.9 * girth:
                label = dataclasses.replace(label, width_mm=round(0.9 * girth, 1))
        except (GlassbenchError, ValueError, ArithmeticError):
            pass  # the design check says what is wrong
    return label


def add_label(design, assets, front: bytes, *, name=None, filename="label", back=None, **placement) -> Edit:
    """Add a label printed with the image bytes ``front`` (decoded in full and checked:
    ``ArtworkError``), named ``name`` or after ``filename`` (made unique), on top of the others,
    sized from the artwork's aspect unless told. ``back`` is a colour (linear RGB), image bytes or
    ``None`` (white). A print on the cap without ``at`` sits half-way up the skirt, or at its
    ``cap_xy`` on the top. ``placement``: the keywords of :func:`new_label`."""
    base = name or os.path.splitext(os.path.basename(str(filename)))[0] or "label"
    name = name or unique_name(design, base)
    images.decode_image(front, name)  # why: decoded in full where it enters (a damaged body, NaN)
    info = images.probe_image(front, name)
    front_asset = asset_name(name, "front", front, assets)
    added = {front_asset: front}
    back_side = LabelSide()
    if isinstance(back, (bytes, bytearray)):
        images.decode_image(back, f"{name} back")
        back_asset = asset_name(name, "back", back, {**assets, **added})
        added[back_asset] = bytes(back)
        back_side = LabelSide(back_asset)
    elif back is not None:
        back_side = LabelSide(color=tuple(back))
    surface = placement.get("surface", "wall")
    if placement.get("at") is None and surface != "wall":
        z = 0.5 * cap_surface(design, "cap-skirt", f"label {name!r}").height_mm if surface == "cap-skirt" else 0.0
        placement["at"] = (z, camera_azimuth_deg(design.camera))
    label = new_label(design, name, LabelSide(front_asset), aspect=info.width / info.height, back=back_side,
                      **placement)
    labels = design.labels + (label,)
    return _with_labels(design, labels, f"Add label {name}", added, select=len(labels) - 1)


def remove_label(design, i: int) -> Edit:
    """Remove label ``i``; images nothing else uses leave the project."""
    labels = design.labels[:i] + design.labels[i + 1:]
    return _with_labels(design, labels, f"Remove label {design.labels[i].name}", select=min(i, len(labels) - 1))


def move_label(design, i: int, step: int) -> Edit | None:
    """Label ``i`` moved ``step`` places in the overlap order (``None`` if it cannot move)."""
    labels = swapped(design.labels, i, step)
    if labels is None:
        return None
    return _with_labels(design, labels, f"Reorder label {labels[i + step].name}", select=i + step)


def replace_label(design, i: int, label: Label, text: str, assets: Mapping | None = None) -> Edit:
    """Label ``i`` becomes ``label`` (with the images in ``assets`` added)."""
    return _with_labels(design, design.labels[:i] + (label,) + design.labels[i + 1:], text, assets, select=i)


def set_face_image(design, assets, i: int, side: str, data: bytes) -> Edit:
    """Print face ``side`` (``"front"``/``"back"``) of label ``i`` with image bytes ``data``."""
    lab = design.labels[i]
    images.decode_image(data, f"{lab.name} {side}")
    asset = asset_name(lab.name, side, data, assets)
    new = dataclasses.replace(lab, **{side: LabelSide(asset, getattr(lab, side).color)})
    return replace_label(design, i, new, f"Label {side} image", {asset: data})


def set_face_colour(design, i: int, side: str, rgb) -> Edit:
    """Face ``side`` of label ``i`` as the plain colour ``rgb`` (linear), without an image."""
    lab = design.labels[i]
    return replace_label(design, i, dataclasses.replace(lab, **{side: LabelSide(None, tuple(rgb))}),
                         f"Label {side} colour")


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


def set_front_artwork(design, assets, name: str, data: bytes) -> Edit:
    """The label called ``name`` printed with new front artwork ``data`` (a batch variant)."""
    return set_face_image(design, assets, find_label(design, name), "front", data)
