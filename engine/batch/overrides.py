"""Variant overrides: the job file's vocabulary for changing a project without editing it.

Design rule: an override is a key of a variant table, checked completely and applied to the
frozen ``Design`` with ``dataclasses.replace``; the project file is never touched. Every
problem (an unknown key, a wrong type, a fill the bottle cannot hold, a label the design lacks,
artwork that is not an image) raises the :class:`~engine.batch.source.JobError` of the line
that holds it, and the final design is checked as a project would be on save. Units: mm, ml,
1/mm for absorption, degrees for ``fov_y_deg``.

==================  ==================================================================
key                 meaning
==================  ==================================================================
``glass_tint``      glass absorption ``[r, g, b]`` in 1/mm (``Glass.absorption``)
``liquid_color``    liquid absorption ``[r, g, b]`` in 1/mm (``Liquid.absorption``)
``fill_height_mm``  liquid surface height above the bottom (mm)
``fill_ml``         liquid volume (ml), solved to a height by the capacity engine
``empty``           ``true``: no liquid
``labels``          ``{label name = "artwork.png"}``: replaces the front artwork of that label
``camera``          ``{eye, target, up, fov_y_deg}``: replaces those camera fields
``stage``           ``{kind, colour = "#rrggbb" (sRGB) or color = [r, g, b] (linear 0..1),
                    gloss (0..1), backdrop}``: replaces those fields of the design's stage
==================  ==================================================================
"""
from __future__ import annotations

import dataclasses
import difflib
import math
import os

from ..color import hex_to_linear
from ..errors import DesignError, GlassbenchError, InputFileError
from ..io.read import read_bounded
from ..model.design import Camera, Liquid, Stage
from ..operations.labels import set_front_artwork
from ..operations.stage import KIND_NAMES, stage_kind, staged

OVERRIDE_KEYS = ("glass_tint", "liquid_color", "fill_height_mm", "fill_ml", "empty", "labels",
                 "camera", "stage")
#: The keys of a ``stage`` override (``colour``: sRGB hex; ``color``: linear RGB, as stored).
STAGE_KEYS = ("kind", "colour", "color", "gloss", "backdrop")
#: Largest label artwork read (bytes).
MAX_ARTWORK_BYTES = 64 << 20
#: Leading bytes of the image formats label artwork may have.
IMAGE_MAGIC = {b"\x89PNG\r\n\x1a\n": ".png", b"\xff\xd8\xff": ".jpg", b"II*\x00": ".tif",
               b"MM\x00*": ".tif", b"v/1\x01": ".exr"}


def apply_overrides(design, assets: dict, table: dict, tree, key_path: tuple, base_dir: str):
    """``(design, assets)`` with the overrides in ``table`` applied (new values; inputs untouched).

    Parameters
    ----------
    table : dict
        The variant's keys other than ``name`` (see the module table).
    tree : engine.batch.source.SourceTree
        The job file, for errors that name the line (``key_path`` locates ``table``).
    base_dir : str
        Folder that relative artwork paths start from (the job file's).
    """
    def fail(key, message):
        return tree.error(key_path + (key,), f"{key}: {message}")

    for key in table:
        if key not in OVERRIDE_KEYS:
            hint = _did_you_mean(key, OVERRIDE_KEYS)
            raise tree.error(key_path + (key,), f"unknown override {key!r}{hint}")
    assets = dict(assets)
    if "glass_tint" in table:
        design = dataclasses.replace(design, glass=dataclasses.replace(
            design.glass, absorption=_absorption(table["glass_tint"], lambda m: fail("glass_tint", m))))
    design = _apply_liquid(design, table, fail)
    if "labels" in table:
        design = _apply_labels(design, assets, table["labels"], base_dir, fail)
    if "camera" in table:
        cam = camera_from_table(table["camera"], design.camera, lambda m: fail("camera", m))
        design = dataclasses.replace(design, camera=cam)
    if "stage" in table:
        stage = stage_from_table(table["stage"], design.stage, lambda m: fail("stage", m))
        design = dataclasses.replace(design, stage=stage)
    return design, assets


def _absorption(value, fail):
    if (not isinstance(value, list) or len(value) != 3
            or not all(_is_number(v) and v >= 0 for v in value)):
        raise fail(f"must be three numbers >= 0 (absorption, 1/mm per RGB), got {_show(value)}")
    return tuple(float(v) for v in value)


def _apply_liquid(design, table, fail):
    from ..geometry import capacity
    given = [k for k in ("fill_height_mm", "fill_ml", "empty") if k in table]
    if len(given) > 1:
        raise fail(given[1], f"{given[0]!r} and {given[1]!r} cannot both be given")
    if "empty" in table:
        if table["empty"] is not True:
            raise fail("empty", "must be true (leave it out for a filled bottle), "
                                f"got {_show(table['empty'])}")
        if "liquid_color" in table:
            raise fail("liquid_color", "an empty bottle has no liquid to colour")
        return dataclasses.replace(design, liquid=None)
    liquid = design.liquid
    shape = design.shape
    if "fill_height_mm" in table:
        h = table["fill_height_mm"]
        if not (_is_number(h) and shape.base_thickness < h < shape.z_top):
            raise fail("fill_height_mm", f"must lie between the inner base ({shape.base_thickness:g} mm) "
                                         f"and the mouth ({shape.z_top:g} mm), got {_show(h)}")
        liquid = dataclasses.replace(liquid or Liquid(), fill_mode="height", fill_value=float(h))
    if "fill_ml" in table:
        v = table["fill_ml"]
        brimful = capacity.brimful_ml(shape)
        if not (_is_number(v) and 0 < v < brimful):
            raise fail("fill_ml", f"must lie between 0 and the brimful capacity ({brimful:.1f} ml), "
                                  f"got {_show(v)}")
        liquid = dataclasses.replace(liquid or Liquid(), fill_mode="volume", fill_value=float(v))
    if "liquid_color" in table:
        if liquid is None:
            raise fail("liquid_color", "the project has no liquid; give fill_ml or fill_height_mm too")
        liquid = dataclasses.replace(
            liquid, absorption=_absorption(table["liquid_color"], lambda m: fail("liquid_color", m)))
    return dataclasses.replace(design, liquid=liquid)


def _apply_labels(design, assets, value, base_dir, fail):
    if not isinstance(value, dict) or not value:
        raise fail("labels", f"must be a table of label name = \"artwork file\", got {_show(value)}")
    names = [lab.name for lab in design.labels]
    for name, art in value.items():
        if name not in names:
            have = ", ".join(repr(n) for n in names) if names else "none"
            raise fail("labels", f"the design has no label {name!r} (its labels: {have})")
        if not isinstance(art, str) or not art:
            raise fail("labels", f"label {name!r}: the artwork must be a file name, got {_show(art)}")
        data, _ = _read_artwork(os.path.join(base_dir, art),
                                lambda m, n=name: fail("labels", f"label {n!r}: {m}"))
        edit = set_front_artwork(design, assets, name, data)  # the operation the panel and the CLI use
        design = edit.design
        for k, v in edit.assets.items():  # (the caller's asset dict, changed in place)
            if v is None:
                assets.pop(k, None)
            else:
                assets[k] = v
    return design


def _read_artwork(path, fail):
    try:
        data = read_bounded(path, MAX_ARTWORK_BYTES, "artwork")
    except OSError as exc:
        raise fail(f"cannot read {path}: {exc.strerror or exc}") from None
    except InputFileError as exc:
        raise fail(str(exc)) from None
    for magic, ext in IMAGE_MAGIC.items():
        if data.startswith(magic):
            break
    else:
        raise fail(f"{path} is not a PNG, JPEG, TIFF or EXR image")
    from ..appearance.images import ArtworkError, decode_image
    try:  # decoded in full (the size from the header first): a damaged body or NaN stops here
        decode_image(data, os.path.basename(path))
    except ArtworkError as exc:
        raise fail(str(exc)) from None
    return data, ext


def camera_from_table(value, base: Camera, fail) -> Camera:
    """``base`` with the fields of a ``{eye, target, up, fov_y_deg}`` table replaced, checked."""
    if not isinstance(value, dict):
        raise fail(f"must be a table of eye, target, up, fov_y_deg, got {_show(value)}")
    fields = {}
    for key, v in value.items():
        if key in ("eye", "target", "up"):
            if not (isinstance(v, list) and len(v) == 3 and all(_is_number(c) for c in v)):
                raise fail(f"{key} must be three numbers (mm), got {_show(v)}")
            fields[key] = tuple(float(c) for c in v)
        elif key == "fov_y_deg":
            if not (_is_number(v) and 0 < v < 180):
                raise fail(f"fov_y_deg must be a number of degrees in (0, 180), got {_show(v)}")
            fields[key] = float(v)
        else:
            raise fail(f"unknown camera field {key!r} (known: eye, target, up, fov_y_deg)")
    cam = dataclasses.replace(base, **fields)
    problem = camera_problem(cam)
    if problem:
        raise fail(problem)
    return cam


def stage_from_table(value, base: Stage, fail) -> Stage:
    """``base`` with the fields of a ``{kind, colour | color, gloss, backdrop}`` table replaced,
    checked: a kind of :mod:`engine.operations.stage` (its alias too), ``colour`` an sRGB hex
    string or ``color`` three linear numbers in 0..1, ``gloss`` a number in 0..1, ``backdrop``
    true or false, and nothing the resulting kind would not draw."""
    if not isinstance(value, dict) or not value:
        raise fail(f"must be a table of {', '.join(STAGE_KEYS)}, got {_show(value)}")
    if "colour" in value and "color" in value:
        raise fail("give colour (\"#rrggbb\", sRGB) or color ([r, g, b], linear), not both")
    fields = {}
    for key, v in value.items():
        if key == "kind":
            fields["kind"] = stage_kind(v)
            if fields["kind"] is None:
                raise fail(f"kind must be one of {KIND_NAMES}, got {_show(v)}")
        elif key == "colour":
            fields["color"] = hex_to_linear(v) if isinstance(v, str) else None
            if fields["color"] is None:
                raise fail(f"colour must be an sRGB colour like \"#8c8c8c\", got {_show(v)}")
        elif key == "color":
            if not (isinstance(v, list) and len(v) == 3 and all(_is_number(c) and 0 <= c <= 1 for c in v)):
                raise fail(f"color must be three numbers in 0..1 (linear RGB), got {_show(v)}")
            fields["color"] = tuple(float(c) for c in v)
        elif key == "gloss":
            if not (_is_number(v) and 0 <= v <= 1):
                raise fail(f"gloss must be a number in 0..1, got {_show(v)}")
            fields["gloss"] = float(v)
        elif key == "backdrop":
            if not isinstance(v, bool):
                raise fail(f"backdrop must be true or false, got {_show(v)}")
            fields["backdrop"] = v
        else:
            raise fail(f"unknown stage field {key!r}{_did_you_mean(key, STAGE_KEYS)}")
    try:  # the stage operation every door uses: the same refusal, in the words typed here
        return staged(base, fields, {"color": "colour"} if "colour" in value else None)
    except DesignError as exc:
        raise fail(str(exc)) from None


def camera_problem(cam: Camera) -> str | None:
    """Why the tracer could not use ``cam`` (eye on the target, up along the view), or ``None``."""
    d = [t - e for t, e in zip(cam.target, cam.eye)]
    n = math.sqrt(sum(c * c for c in d))
    if n < 1e-9:
        return "the eye and the target are the same point"
    u = cam.up
    cross = (d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0])
    if math.sqrt(sum(c * c for c in cross)) < 1e-9 * n * max(1e-300, math.sqrt(sum(c * c for c in u))):
        return "the up vector is parallel to the viewing direction (or zero)"
    return None


def check_variant_design(design, assets, tree, key_path: tuple) -> None:
    """Refuse a variant the project format would refuse (ranges, assets, geometry)."""
    from ..operations.check import check_design
    try:
        check_design(design, assets)
    except (GlassbenchError, ValueError) as exc:
        raise tree.error(key_path, f"the variant is not a valid design: {exc}") from None


def _did_you_mean(key, known) -> str:
    """The end of an "unknown key" message: the nearest of ``known``, or all of them."""
    near = difflib.get_close_matches(str(key), known, n=1)
    return f"; did you mean {near[0]!r}?" if near else f" (known: {', '.join(known)})"


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _show(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
