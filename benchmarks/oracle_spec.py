"""The one mapping from an oracle scene (``/work/shared/oracle/SPEC.md``) to a glassbench design.

Design rule: :func:`spec_to_design` turns the neutral SPEC scene into a ``Design`` plus its
assets; the converter and the command line (:mod:`benchmarks.oracle`), the oracle renderer
(:mod:`benchmarks.oracle_render`) and the benchmarks all use it, and it imports none of them,
so the benchmark modules form no import circle. Every SPEC feature
maps one to one: camera and image size, environment file (embedded as an asset) and scale,
round or rounded-square bottle with rotation, glass and liquid IOR and ``sigma_a`` (1/mm)
as absorption. Only ``air_ior = 1`` is meaningful for glassbench; anything else is refused.
"""
from __future__ import annotations

import json
import math
import os

from engine.model.design import Camera, Design, Environment, Glass, Liquid, RenderSettings, Stage
from engine.errors import ProjectError
from engine.geometry.section import Section
from engine.geometry.shape import BottleShape

#: Samples per pixel written into converted projects (the references used far more).
DEFAULT_SPP = 64
#: Deepest tree the converted project asks for (the SPEC's 1024 is a path-tracing depth).
MAX_DEPTH = 256


def _get(obj, key, where, kinds=(dict,)):
    if not isinstance(obj, dict) or key not in obj:
        raise ProjectError(f"SPEC {where} lacks {key!r}")
    value = obj[key]
    if kinds and not isinstance(value, kinds):
        raise ProjectError(f"SPEC {where}.{key} has the wrong type ({type(value).__name__})")
    return value


def _num(obj, key, where) -> float:
    v = _get(obj, key, where, (int, float))
    if isinstance(v, bool) or not math.isfinite(float(v)):
        raise ProjectError(f"SPEC {where}.{key} must be a finite number")
    return float(v)


def _vec(obj, key, where, n) -> tuple:
    v = _get(obj, key, where, (list,))
    if len(v) != n or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                              and math.isfinite(float(x)) for x in v):
        raise ProjectError(f"SPEC {where}.{key} must be {n} finite numbers")
    return tuple(float(x) for x in v)


def _section(items, where) -> Section:
    try:
        return Section.from_dicts(items)
    except (ValueError, TypeError) as exc:
        raise ProjectError(f"SPEC {where}: {exc}") from None


def shape_from_spec(bottle: dict) -> BottleShape:
    """The ``BottleShape`` of a SPEC ``bottle`` object (sections, wall, base, rotation in mm/deg).

    Raises ``ProjectError`` naming the first missing or malformed field.
    """
    xs = _get(bottle, "cross_section", "bottle")
    kind = _get(xs, "kind", "bottle.cross_section", (str,))
    if kind == "round":
        sections = (("profile", _section(_get(bottle, "profile", "bottle", (list,)), "bottle.profile")),)
    elif kind in ("rounded_square", "outline"):
        keys = (("u", "profile_u"), ("v", "profile_v")) if kind == "rounded_square" else \
            (("core", "profile_core"), ("round", "profile_round"))
        sections = tuple((name, _section(_get(xs, key, "bottle.cross_section", (list,)),
                                         f"bottle.cross_section.{key}"))
                         for name, key in keys)
    else:
        raise ProjectError(f"SPEC cross-section kind {kind!r} is not round, rounded_square or outline")
    plan = None
    if kind == "outline":  # SPEC_outline: the plan outline, normalised by its reader
        from engine.geometry.plan import PlanOutline
        plan = PlanOutline.from_dicts(_get(xs, "outline", "bottle.cross_section", (list,)))
    return BottleShape(kind, sections, wall_thickness=_num(bottle, "wall_thickness", "bottle"),
                       base_thickness=_num(bottle, "base_thickness", "bottle"),
                       rotation_deg=_num(bottle, "rotation_deg", "bottle")
                       if "rotation_deg" in bottle else 0.0, plan=plan)


def spec_to_design(spec_path: str | os.PathLike, spp: int = DEFAULT_SPP
                   ) -> tuple[Design, dict[str, bytes]]:
    """Read a SPEC scene file; returns ``(design, assets)`` with the environment map embedded.

    Lengths stay in mm, ``sigma_a`` (1/mm) becomes ``absorption``; the camera's ``look_at``
    becomes ``target`` and its ``width``/``height`` the render size. Raises ``ProjectError``
    naming the first problem (missing field, ``air_ior != 1``, unknown cross-section).
    """
    spec_path = os.fspath(spec_path)
    try:
        with open(spec_path, encoding="utf-8") as fh:
            spec = json.load(fh)
    except (OSError, ValueError) as exc:
        raise ProjectError(f"cannot read SPEC {spec_path}: {exc}") from None
    if not isinstance(spec, dict):
        raise ProjectError("a SPEC scene must be a JSON object")
    air = _num(spec, "air_ior", "scene")
    if air != 1.0:
        raise ProjectError(f"SPEC air_ior must be 1 (glassbench renders in air), got {air}")

    cam = _get(spec, "camera", "scene")
    camera = Camera(eye=_vec(cam, "eye", "camera", 3), target=_vec(cam, "look_at", "camera", 3),
                    up=_vec(cam, "up", "camera", 3), fov_y_deg=_num(cam, "fov_y_deg", "camera"))
    width, height = (_get(cam, k, "camera", (int,)) for k in ("width", "height"))
    max_depth = spec.get("render", {}).get("max_depth", MAX_DEPTH) if isinstance(spec.get("render"), dict) else MAX_DEPTH
    render = RenderSettings(width=int(width), height=int(height), spp=int(spp),
                            max_depth=int(min(max(int(max_depth), 1), MAX_DEPTH)))

    env = _get(spec, "environment", "scene")
    env_file = _get(env, "file", "environment", (str,))
    env_path = os.path.join(os.path.dirname(os.path.abspath(spec_path)), env_file)
    try:
        with open(env_path, "rb") as fh:
            env_bytes = fh.read()
    except OSError as exc:
        raise ProjectError(f"cannot read the SPEC environment {env_path}: {exc.strerror}") from None
    asset = os.path.basename(env_path)
    environment = Environment(kind="file", asset=asset,
                              scale=_num(env, "scale", "environment") if "scale" in env else 1.0)

    bottle = _get(spec, "bottle", "scene")
    shape = shape_from_spec(bottle)
    g = _get(bottle, "glass", "bottle")
    glass = Glass(ior=_num(g, "ior", "glass"), absorption=_vec(g, "sigma_a", "glass", 3))

    liq = spec.get("liquid")
    liquid = None
    if liq is not None:
        liquid = Liquid(ior=_num(liq, "ior", "liquid"), absorption=_vec(liq, "sigma_a", "liquid", 3),
                        fill_mode="height", fill_value=_num(liq, "fill_height", "liquid"))
    stage = Stage()
    ground = spec.get("ground")
    if ground is not None:  # SPEC_ground.md: a Lambertian square under the bottle
        stage = Stage(kind="table", color=_vec(ground, "albedo", "ground", 3), z_mm=_num(ground, "z", "ground"),
                      half_size_mm=_num(ground, "half_size", "ground"))
    design = Design(shape=shape, glass=glass, liquid=liquid, camera=camera,
                    environment=environment, render=render, stage=stage, lights=(),
                    name=str(spec.get("name", os.path.splitext(os.path.basename(spec_path))[0])),
                    notes=str(spec.get("note", "")))
    return design, {asset: env_bytes}
