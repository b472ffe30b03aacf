"""Design <-> plain JSON-ready dictionaries, with strict checking on the way in.

Design rule: the dictionary form mirrors the frozen dataclasses of :mod:`engine.model.design`
field by field (names unchanged, tuples as lists, ``None`` as ``null``), so a new field in
``design.py`` is carried automatically. Reading trusts nothing: every value is checked for
its declared type (numbers finite, booleans not taken for numbers, no missing or unknown
keys) and every list for a sane length, and any problem raises
:class:`engine.errors.ProjectError` with the JSON path of the offending value. The shape is
special-cased because its sections are SPEC segment lists (see :mod:`engine.geometry.segments`).
Floats are written as Python floats; ``json`` writes them with ``repr``, which round-trips
float64 exactly.

A *document* is what ``project.json`` holds: ``{"format_version": N, "generator": str,
"design": {...}}``. Format 6 is current: format 5 with the shape's ``plan``, the free plan outline
of an ``outline`` bottle as its SPEC_outline segment list (``[{"type": "line", "p0", "p1"} |
{"type": "arc", "center", "radius", "p0", "p1", "ccw"}, ...]``) **normalised** (its farthest
point at distance 1, so the core and rounding sections are mm; the plan reads back bit for bit),
and ``null`` for every other kind; a format-5 shape gets ``null`` (it could not be an outline).
Format 5: format 4 with the design's ``plant`` (the proof
pressure, liquid density, closure and label masses and warning limits of :mod:`engine.plant`;
a format-4 project gets the defaults). Format 4: format 3 with the design's ``stage`` (what the bottle
stands on; a format-3 bottle floated: ``none``). Format 3: format 2 with fields added to labels and bump tiles
(a label's ``surface`` and cap-top centre ``cap_x_mm, cap_y_mm``; a tile's ``on`` and
``geometry``), filled in by :mod:`engine.files.migrate_fields` with what format 2 drew.
Format 2: labels with placement, faces, coefficients and finish regions; bump tiles and the
closure as real values. Format 1 had placeholder labels,
``{"name", "asset"}`` (:mod:`engine.files.migrate_labels`), and placeholder bump tiles and cap
(:mod:`engine.files.migrate_finishes`). Format 0, the prototype layout, is still read::

    {"format_version": 0, "name": str,
     "shape": {"cross_section": str, "sections": {NAME: [segment, ...]},
               "wall": mm, "base": mm, "rotation_deg": deg},
     "glass": {"ior": n, "absorption": [r, g, b]},
     "liquid": null | {"ior": n, "absorption": [r, g, b], "fill_height": mm},
     "camera": {"eye": [x, y, z], "target": [x, y, z], "up": [x, y, z], "fov_y_deg": deg},
     "render": {"width": px, "height": px, "spp": n}}

It had no smoothness flags (the defaults apply), environment, lights, labels, bumps, cap,
notes, glass density or tree cut-offs; migration fills in today's defaults. Each migration
is one function ``MIGRATIONS[n]`` from format ``n`` to ``n + 1``.
"""
from __future__ import annotations

import dataclasses
import math
import types
import typing
from functools import lru_cache

from ..errors import ProjectError, shown
from ..limits import MAX_LIST_ITEMS as LIST_LIMIT, MAX_SEGMENTS, MAX_TEXT_CHARS
from ..model.design import Design
from .migrate_fields import (migrate_2_to_3 as _migrate_2_to_3, migrate_3_to_4 as _migrate_3_to_4,
                             migrate_4_to_5 as _migrate_4_to_5, migrate_5_to_6 as _migrate_5_to_6)
from .migrate_finishes import migrate_1_to_2 as _finishes_1_to_2
from .migrate_labels import migrate_1_to_2 as _labels_1_to_2
from ..geometry.plan import MAX_SEGMENTS as MAX_PLAN_SEGMENTS, PlanOutline
from ..geometry.section import Section
from ..geometry.shape import SECTION_NAMES, BottleShape

#: The format this glassbench writes (``project.json``'s ``format_version``).
CURRENT_FORMAT = 6
#: Longest string accepted anywhere in a design (:data:`engine.limits.MAX_TEXT_CHARS`).
MAX_STRING_CHARS = MAX_TEXT_CHARS
#: Most items accepted in any list (:data:`engine.limits.MAX_LIST_ITEMS`); a section's
#: segments stop at :data:`engine.limits.MAX_SEGMENTS`.
MAX_LIST_ITEMS = LIST_LIMIT


def design_to_dict(design: Design) -> dict:
    """The design as a JSON-ready dictionary (lists, floats, strings, ``None``).

    Raises ``ProjectError`` if a number is not finite (JSON cannot carry NaN or Inf).
    """
    return _encode(design, "design")


def document_from_design(design: Design, generator: str = "glassbench") -> dict:
    """The current-format document (``project.json`` content) for ``design``."""
    return {"format_version": CURRENT_FORMAT, "generator": generator,
            "design": design_to_dict(design)}


def design_from_document(doc: object) -> Design:
    """Migrate a ``project.json`` document of any known format and build its design.

    Raises ``ProjectError`` for a missing or unknown ``format_version`` (a newer one is
    reported as made by a newer glassbench) or any problem in the design.
    """
    return design_from_dict(migrate_document(doc)["design"])


def migrate_document(doc: object) -> dict:
    """Bring a document up to :data:`CURRENT_FORMAT`, one step at a time."""
    if not isinstance(doc, dict):
        raise ProjectError(f"project.json must hold an object, got {_type_name(doc)}")
    version = doc.get("format_version")
    if isinstance(version, bool) or not isinstance(version, int):
        raise ProjectError("project.json lacks a whole-number format_version")
    if version > CURRENT_FORMAT:
        raise ProjectError(f"this project has format {version}: it was made by a newer glassbench "
                           f"(this one reads formats up to {CURRENT_FORMAT}); please upgrade")
    if version < 0:
        raise ProjectError(f"format_version {version} is not a glassbench format")
    while version < CURRENT_FORMAT:
        try:
            doc = MIGRATIONS[version](doc)
        except (ArithmeticError, TypeError, ValueError, KeyError, IndexError, AttributeError) as exc:
            # why: a migration reads the old layout before the strict decoder has checked it;
            # whatever a hostile old file makes it trip on is still one clear line
            if isinstance(exc, ProjectError):
                raise
            raise ProjectError(f"this format-{version} project cannot be brought up to date: its "
                               f"design is malformed ({type(exc).__name__})") from None
        version += 1
    _object(doc, "project.json", ("format_version", "design"), ("generator",))
    if "generator" in doc:
        _string(doc["generator"], "project.json.generator")
    return doc


def _migrate_0_to_1(doc: dict) -> dict:
    """Format 0 (prototype, top-level parts) -> format 1 (``design`` object, full fields)."""
    old = _object(doc, "project.json", ("format_version", "name", "shape", "glass", "liquid",
                                        "camera", "render"))
    shape = _object(old["shape"], "shape", ("cross_section", "sections", "wall", "base",
                                            "rotation_deg"))
    sections = _object(shape["sections"], "shape.sections", (), tuple(
        k for v in SECTION_NAMES.values() for k in v))
    glass = _object(old["glass"], "glass", ("ior", "absorption"))
    render = _object(old["render"], "render", ("width", "height", "spp"))
    liquid = old["liquid"]
    if liquid is not None:
        liquid = _object(liquid, "liquid", ("ior", "absorption", "fill_height"))
        liquid = {"ior": liquid["ior"], "absorption": liquid["absorption"],
                  "fill_mode": "height", "fill_value": liquid["fill_height"]}
    new_sections = {}
    for name, segs in sections.items():
        n = len(_list(segs, f"shape.sections.{name}"))
        # Format 0 had no flags: the default, every joint smooth but the base corner.
        new_sections[name] = {"segments": segs, "smooth": [i > 0 for i in range(max(n - 1, 0))]}
    defaults = design_to_dict(Design(shape=_PLACEHOLDER_SHAPE))
    design = dict(defaults)
    design.update(
        name=old["name"], notes="",
        shape={"cross_section": shape["cross_section"], "sections": new_sections,
               "wall_thickness": shape["wall"], "base_thickness": shape["base"],
               "rotation_deg": shape["rotation_deg"], "wall_per_segment": None},
        glass=dict(defaults["glass"], ior=glass["ior"], absorption=glass["absorption"]),
        liquid=liquid, camera=old["camera"],
        render=dict(defaults["render"], width=render["width"], height=render["height"],
                    spp=render["spp"]))
    return {"format_version": 1, "generator": "migrated from format 0", "design": design}


def design_from_dict(data: object) -> Design:
    """Build a :class:`Design` from its dictionary form; raises ``ProjectError`` naming the
    JSON path of the first problem (wrong type, missing/unknown key, NaN, absurd size).

    Geometry is only checked as far as the value types themselves check it; call
    :func:`engine.geometry.validate.validate_shape` for the section rules.
    """
    return _decode(data, Design, "design")


# ---------------------------------------------------------------------------- encoding

def _encode(value, path: str):
    if isinstance(value, BottleShape):
        return _encode_shape(value, path)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _encode(getattr(value, f.name), f"{path}.{f.name}")
                for f in dataclasses.fields(value)}
    if isinstance(value, (tuple, list)):
        return [_encode(v, f"{path}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, dict):
        return {str(k): _encode(v, f"{path}.{k}") for k, v in value.items()}
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ProjectError(f"{path} is {value!r}; a project can only hold finite numbers")
        return float(value)
    # numpy scalars and the like: keep their exact float value.
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise ProjectError(f"{path}: cannot store a {type(value).__name__} in a project") from None
    return _encode(f, path)


def _encode_shape(shape: BottleShape, path: str) -> dict:
    sections = {}
    for name, sec in shape.sections:
        try:
            segs = sec.to_dicts()
        except AttributeError:
            raise ProjectError(f"{path}.sections.{name}: only line, arc and ellipse_arc "
                               f"segments can be stored") from None
        sections[name] = {"segments": _encode(segs, f"{path}.sections.{name}.segments"),
                          "smooth": list(sec.smooth)}
    return {"cross_section": shape.cross_section, "sections": sections,
            "wall_thickness": _encode(shape.wall_thickness, f"{path}.wall_thickness"),
            "base_thickness": _encode(shape.base_thickness, f"{path}.base_thickness"),
            "rotation_deg": _encode(shape.rotation_deg, f"{path}.rotation_deg"),
            "wall_per_segment": _encode(shape.wall_per_segment, f"{path}.wall_per_segment"),
            "plan": None if shape.plan is None else _encode(shape.plan.to_dicts(), f"{path}.plan")}


# ---------------------------------------------------------------------------- decoding

@lru_cache(maxsize=None)
def _hints(cls) -> dict:
    # The design modules use ``from __future__ import annotations``: resolve the strings.
    return typing.get_type_hints(cls)


def _type_name(value) -> str:
    return "null" if value is None else {dict: "object", list: "list", str: "string",
                                         bool: "boolean"}.get(type(value), type(value).__name__)


def _decode(value, hint, path: str):
    if hint is BottleShape:
        return _decode_shape(value, path)
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        options = typing.get_args(hint)
        if value is None and type(None) in options:
            return None
        real = [o for o in options if o is not type(None)]
        if len(real) == 1:
            return _decode(value, real[0], path)
        raise ProjectError(f"{path}: unsupported union type {hint!r}")  # pragma: no cover
    if hint is type(None):
        if value is not None:
            raise ProjectError(f"{path} must be null, got {_type_name(value)}")
        return None
    if dataclasses.is_dataclass(hint):
        return _decode_dataclass(value, hint, path)
    if origin is tuple:
        return _decode_tuple(value, typing.get_args(hint), path)
    if hint is float:
        return _number(value, path)
    if hint is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ProjectError(f"{path} must be a whole number, got {_type_name(value)}")
        if abs(value) > 2 ** 53:
            raise ProjectError(f"{path} = {shown(value)} is absurdly large")
        return value
    if hint is bool:
        if not isinstance(value, bool):
            raise ProjectError(f"{path} must be true or false, got {_type_name(value)}")
        return value
    if hint is str:
        return _string(value, path)
    raise ProjectError(f"{path}: unsupported field type {hint!r}")  # pragma: no cover


def _number(value, path: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ProjectError(f"{path} must be a number, got {_type_name(value)}")
    try:
        f = float(value)
    except OverflowError:
        raise ProjectError(f"{path} = {shown(value)} is absurdly large") from None
    if not math.isfinite(f):
        raise ProjectError(f"{path} is {f!r}; only finite numbers are allowed")
    return f


def _string(value, path: str) -> str:
    if not isinstance(value, str):
        raise ProjectError(f"{path} must be a string, got {_type_name(value)}")
    if len(value) > MAX_STRING_CHARS:
        raise ProjectError(f"{path} is {len(value)} characters long (limit {MAX_STRING_CHARS})")
    return value


def _list(value, path: str, limit: int = LIST_LIMIT) -> list:
    if not isinstance(value, list):
        raise ProjectError(f"{path} must be a list, got {_type_name(value)}")
    if len(value) > limit:
        raise ProjectError(f"{path} has {len(value)} items (limit {limit})")
    return value


def _object(value, path: str, required, optional=()) -> dict:
    if not isinstance(value, dict):
        raise ProjectError(f"{path} must be an object, got {_type_name(value)}")
    missing = [k for k in required if k not in value]
    if missing:
        raise ProjectError(f"{path} lacks {', '.join(repr(k) for k in missing)}")
    unknown = [k for k in value if k not in required and k not in optional]
    if unknown:
        names = ", ".join(shown(k, 40) for k in unknown[:5])
        raise ProjectError(f"{path} has unknown field(s) {names}")
    return value


def _decode_tuple(value, args, path: str) -> tuple:
    items = _list(value, path)
    if len(args) == 2 and args[1] is Ellipsis:
        return tuple(_decode(v, args[0], f"{path}[{i}]") for i, v in enumerate(items))
    if len(items) != len(args):
        raise ProjectError(f"{path} must have {len(args)} items, got {len(items)}")
    return tuple(_decode(v, a, f"{path}[{i}]") for i, (v, a) in enumerate(zip(items, args)))


def _decode_dataclass(value, cls, path: str):
    names = [f.name for f in dataclasses.fields(cls)]
    obj = _object(value, path, names)
    hints = _hints(cls)
    kwargs = {n: _decode(obj[n], hints[n], f"{path}.{n}") for n in names}
    try:
        return cls(**kwargs)
    except (ValueError, TypeError) as exc:
        raise ProjectError(f"{path}: {exc}") from None


def _decode_shape(value, path: str) -> BottleShape:
    obj = _object(value, path, ("cross_section", "sections", "wall_thickness", "base_thickness",
                                "rotation_deg", "wall_per_segment", "plan"))
    kind = _string(obj["cross_section"], f"{path}.cross_section")
    if kind not in SECTION_NAMES:
        raise ProjectError(f"{path}.cross_section: unknown cross-section {kind[:60]!r}; "
                           f"expected one of {', '.join(SECTION_NAMES)}")
    secs_obj = _object(obj["sections"], f"{path}.sections", SECTION_NAMES[kind])
    sections = []
    for name in SECTION_NAMES[kind]:
        spath = f"{path}.sections.{name}"
        sec = _object(secs_obj[name], spath, ("segments", "smooth"))
        segs = _list(sec["segments"], f"{spath}.segments", MAX_SEGMENTS)
        smooth = [_decode(s, bool, f"{spath}.smooth[{i}]")
                  for i, s in enumerate(_list(sec["smooth"], f"{spath}.smooth"))]
        for i, seg in enumerate(segs):
            if isinstance(seg, dict):
                for key, v in seg.items():
                    if key in ("radius", "radius_r", "radius_z"):
                        _number(v, f"{spath}.segments[{i}].{key}")
                    elif key in ("p0", "p1", "center"):
                        _decode(v, tuple[float, float], f"{spath}.segments[{i}].{key}")
        try:
            sections.append((name, Section.from_dicts(segs, smooth)))
        except (ValueError, TypeError) as exc:
            raise ProjectError(f"{spath}: {exc}") from None
    wps = obj["wall_per_segment"]
    kwargs = dict(
        wall_thickness=_number(obj["wall_thickness"], f"{path}.wall_thickness"),
        base_thickness=_number(obj["base_thickness"], f"{path}.base_thickness"),
        rotation_deg=_number(obj["rotation_deg"], f"{path}.rotation_deg"),
        wall_per_segment=None if wps is None else _decode(wps, tuple[float, ...],
                                                          f"{path}.wall_per_segment"),
        plan=_decode_plan(obj["plan"], f"{path}.plan"))
    try:
        return BottleShape(kind, tuple(sections), **kwargs)
    except (ValueError, TypeError) as exc:
        raise ProjectError(f"{path}: {exc}") from None


def _decode_plan(value, path: str) -> PlanOutline | None:
    """``None`` or the plan outline of a shape's ``plan`` segment list, read and checked by
    :meth:`~engine.geometry.plan.PlanOutline.from_dicts` (SPEC_outline section 2's rules; its
    ``OutlineError`` names the segment) after the list's length is held to the plan's limit."""
    if value is None:
        return None
    items = _list(value, path, MAX_PLAN_SEGMENTS)
    try:
        return PlanOutline.from_dicts(items)
    except (ValueError, TypeError) as exc:
        raise ProjectError(f"{path}: {exc}") from None


# A minimal valid shape, only used to obtain the default values of the other parts.
_PLACEHOLDER_SHAPE = BottleShape("round", (("profile", Section.from_dicts([
    {"type": "line", "p0": [0.0, 0.0], "p1": [10.0, 0.0]},
    {"type": "line", "p0": [10.0, 0.0], "p1": [10.0, 10.0]}])),))

def _migrate_1_to_2(doc: dict) -> dict:
    """Format 1 -> 2: placeholder labels, then placeholder bump tiles and cap, become values."""
    return _finishes_1_to_2(_labels_1_to_2(doc))


MIGRATIONS = {0: _migrate_0_to_1, 1: _migrate_1_to_2, 2: _migrate_2_to_3, 3: _migrate_3_to_4,
              4: _migrate_4_to_5, 5: _migrate_5_to_6}
