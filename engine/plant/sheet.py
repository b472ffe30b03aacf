"""The plant's numbers of a design as one dict: what ``info --json``, the trade panel, batches and
the drawing show.

Design rule: :func:`plant_numbers` is the one door; each part comes from its module
(:mod:`.stability`, :mod:`.membrane`, :mod:`.rules`) and nothing here computes geometry. Strict
(the command line: a number that cannot be computed is an error) or tolerant (the window while a
design is edited: that part is ``None``, the others still show). The dict is JSON-ready (floats,
strings, lists, ``None``); units are in the keys' names.

Keys::

    ring:       {"kind": "round" | "plan", "radius_mm": float | None,
                 "least_mm": float, "least_direction_deg": float}
                (the standing ring: the outermost points of the base on the plane z = 0;
                 radius_mm for a round plan, least_mm the nearest its edge comes to the axis)
    states:     [{"state": "empty" | "filled" | "brimful", "mass_g": float, "cg_z_mm": float,
                  "cg_plan_mm": [x, y], "tip_deg": float, "tip_direction_deg": float,
                  "tip_frozen_deg": float}, ...]
                (empty always; filled when the design has a liquid; brimful always. cg_plan_mm
                 the centre's foot in the plan, the bottle's turn included ([0, 0] but for an
                 outline that is not centrally symmetric); tip_deg with the liquid's surface
                 level as the bottle tilts (capped: nothing spills), tip_frozen_deg with the
                 liquid frozen in place; direction in the plan, deg from +x counter-clockwise,
                 the bottle's turn included: where the ring's edge is nearest the centre's foot)
    least_tip:  {"deg": float, "state": str, "direction_deg": float}
    weight_to_capacity: {"ratio_g_per_ml": float, "capacity_ml": float, "basis": "fill" | "brimful"}
    capacity_band: None (no liquid) | {"nominal_ml", "tolerance_ml", "rule",
                 "fill_height_min_mm", "fill_height_max_mm",
                 "fill_point_min_mm", "fill_point_max_mm"}   (fill point: mm below the brim)
    marking:    None | {"nominal_ml", "brimful_ml", "fill_point_mm", "text", "rule"}
    tolerances: {"height_mm": float, "diameter_mm": float, "capacity_ml": float | None,
                 "rules": {"height": str, "diameter": str, "capacity": str}}   (each +-)
    stress:     {"pressure_mpa": float, "max_hoop_mpa": float | None,
                 "max_meridional_mpa": float | None, "max_mpa": float | None,
                 "max_at_z_mm": float | None, "max_kind": "hoop" | "meridional" | None,
                 "note": str,
                 "points": [{"s_mm", "z_mm", "r_mm", "t_mm", "hoop_mpa", "meridional_mpa",
                             "reason"}, ...]}
                (points along the outer profile from the standing ring to the mouth; where
                 membrane theory does not hold hoop_mpa and meridional_mpa are None and reason
                 says why; a non-round plan has every point marked)
    thin_wall:  [{"z_from_mm", "z_to_mm", "least_mm", "at_z_mm", "direction_deg", "share"}, ...]
                (an outline bottle's sloped walls where the glass is thinner along its normal
                 than 90 % of the wall: engine.plant.thickness; empty for every other kind, and
                 where the wall keeps it; direction in the plan with the bottle's turn)
    warnings:   [str]   (a part the kind does not support yet, the thin walls, then the
                 designer's limits of Design.plant that a figure passes)
"""
from __future__ import annotations

import contextlib
import math

from ..errors import GlassbenchError, NotSupportedError
from ..geometry import capacity
from ..model import fill
from . import mass, membrane, rules, stability, thickness


def plant_numbers(design, tolerant: bool = False) -> dict:
    """The plant's numbers of ``design`` (module docstring; mm, g, ml, MPa, deg).

    Raises the geometry's errors for an invalid shape unless ``tolerant``: then each part that
    cannot be computed is ``None`` (``states`` an empty list) and the others still show. A part
    the bottle's kind does not support yet (an outline's stability and stress) is ``None`` in
    either mode, its one-line reason first among the ``warnings``.
    """
    out = {"ring": None, "states": [], "least_tip": None, "weight_to_capacity": None,
           "capacity_band": None, "marking": None, "tolerances": None, "stress": None,
           "thin_wall": None, "warnings": []}
    refused = []

    def put(key, fn):
        try:
            out[key] = fn()
        except NotSupportedError as exc:  # why in both modes: no fault of this design's values
            refused.extend([str(exc)] if str(exc) not in refused else [])
        except (GlassbenchError, ValueError, ArithmeticError):
            if not tolerant:
                raise  # why tolerant only: one part that fails must not hide the others

    shape, plant = design.shape, design.plant
    fill_h = fill.fill_height_mm(shape, design.liquid) if design.liquid is not None else None
    nominal = fill.fill_volume_ml(shape, design.liquid) if design.liquid is not None else None
    put("ring", lambda: _ring(shape))
    put("states", lambda: _states(design, fill_h))
    if out["states"]:
        least = min(out["states"], key=lambda s: s["tip_deg"])
        out["least_tip"] = {"deg": least["tip_deg"], "state": least["state"],
                            "direction_deg": least["tip_direction_deg"]}
    put("weight_to_capacity", lambda: _weight_to_capacity(design, nominal))
    if nominal is not None:
        put("capacity_band", lambda: rules.capacity_band(shape, nominal))
        put("marking", lambda: rules.marking(shape, nominal, fill_h))
    put("tolerances", lambda: rules.dimension_tolerances(capacity.height_mm(shape),
                                                         capacity.max_diameter_mm(shape), nominal))
    put("stress", lambda: membrane.membrane_stresses(shape, plant.proof_pressure_mpa))
    put("thin_wall", lambda: _thin_wall(shape))
    out["warnings"] = refused + thickness.warnings(out["thin_wall"] or (), shape.wall_thickness) \
        + plant_warnings(design, out)
    return out


def _thin_wall(shape) -> list[dict]:
    """The thin runs of an outline's sloped walls (:func:`.thickness.thin_walls`), their
    direction with the bottle's turn."""
    return [{**run, "direction_deg": _world_deg(shape, math.radians(run["direction_deg"]))}
            for run in thickness.thin_walls(shape)]


def _ring(shape) -> dict:
    psi, reach = stability.least_direction(shape)
    radius = stability.ring_radii(shape)[0] if shape.xs.revolved else None
    return {"kind": "round" if radius is not None else "plan", "radius_mm": radius,
            "least_mm": reach, "least_direction_deg": _world_deg(shape, psi)}


def _world_deg(shape, psi: float) -> float:
    """A plan direction (rad, the bottle's own frame) in degrees with the bottle's turn, 0-360."""
    return (math.degrees(psi) + shape.rotation_deg) % 360.0


def _world_xy(shape, x: float, y: float) -> list[float]:
    """A plan point (mm, the bottle's own frame) with the bottle's turn."""
    a = math.radians(shape.rotation_deg)
    return [x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)]


def _states(design, fill_h) -> list[dict]:
    """Empty, filled (with a liquid) and brimful: mass, centre of gravity, tip angles; each
    state tips where the ring's edge is nearest to its centre's foot (the axis, unless an
    outline's plan puts the centre off it)."""
    shape, plant = design.shape, design.plant
    fixed = mass.combined([mass.glass_part(shape, design.glass.density_g_cm3),
                           mass.closure_part(design), mass.labels_part(design)])
    rows = [_row("empty", fixed, shape)]
    if fill_h is not None:
        liquid = mass.liquid_part(shape, fill_h, plant.liquid_density_g_ml)
        upright = mass.combined([fixed, liquid])
        psi, _ = stability.least_direction(shape, (upright.cg_x_mm, upright.cg_y_mm))
        moving = stability.moving_tip(shape, fixed, mass.liquid_volume_mm3(shape, fill_h),
                                      plant.liquid_density_g_ml, psi,
                                      float(stability.ring_support(shape, psi)))
        rows.append(_row("filled", upright, shape, math.degrees(moving)))
    brim = mass.liquid_part(shape, shape.z_top, plant.liquid_density_g_ml)
    rows.append(_row("brimful", mass.combined([fixed, brim]), shape))
    return rows


def _row(state, part, shape, moving_deg=None) -> dict:
    psi, margin = stability.least_direction(shape, (part.cg_x_mm, part.cg_y_mm))
    frozen = stability.frozen_tip_deg(margin, part.cg_z_mm)
    return {"state": state, "mass_g": part.mass_g, "cg_z_mm": part.cg_z_mm,
            "cg_plan_mm": _world_xy(shape, part.cg_x_mm, part.cg_y_mm),
            "tip_deg": frozen if moving_deg is None else moving_deg,
            "tip_direction_deg": _world_deg(shape, psi), "tip_frozen_deg": frozen}


def _weight_to_capacity(design, nominal) -> dict:
    glass = capacity.glass_mass_g(design.shape, design.glass.density_g_cm3)
    basis, ml = ("fill", nominal) if nominal is not None else ("brimful", capacity.brimful_ml(design.shape))
    return {"ratio_g_per_ml": glass / ml, "capacity_ml": ml, "basis": basis}


def plant_warnings(design, numbers: dict) -> list[str]:
    """The designer's limits (``Design.plant``; 0: none) that the figures pass, in words."""
    plant, out = design.plant, []
    least = numbers.get("least_tip")
    if plant.min_tip_deg > 0 and least is not None and least["deg"] < plant.min_tip_deg:
        out.append(f"Tips at {least['deg']:.1f}\u00b0 ({least['state']}): "
                   f"less than the {plant.min_tip_deg:g}\u00b0 limit")
    stress = numbers.get("stress") or {}
    if plant.max_stress_mpa > 0 and stress.get("max_mpa") is not None \
            and stress["max_mpa"] > plant.max_stress_mpa:
        out.append(f"Membrane stress {stress['max_mpa']:.1f} MPa ({stress['max_kind']}, z = "
                   f"{stress['max_at_z_mm']:.0f} mm) at {stress['pressure_mpa']:g} MPa: over the "
                   f"{plant.max_stress_mpa:g} MPa limit")
    if plant.min_glass_mass_g > 0:
        with contextlib.suppress(GlassbenchError, ValueError, ArithmeticError):
            glass = capacity.glass_mass_g(design.shape, design.glass.density_g_cm3)
            if glass < plant.min_glass_mass_g:
                out.append(f"Glass weight {glass:.0f} g: under the {plant.min_glass_mass_g:g} g limit")
    return out


#: The plant's figures a batch summary and ``info``'s table give per design: key -> (label, unit).
SUMMARY_FIGURES = {"least_tip_deg": ("Least tip angle", "deg"), "least_tip_state": ("Least tip state", ""),
                   "tip_empty_deg": ("Tip angle empty", "deg"), "tip_filled_deg": ("Tip angle filled", "deg"),
                   "tip_brimful_deg": ("Tip angle brimful", "deg"),
                   "cg_empty_mm": ("CG height empty", "mm"), "cg_filled_mm": ("CG height filled", "mm"),
                   "weight_to_capacity_g_per_ml": ("Weight/capacity", "g/ml"),
                   "max_stress_mpa": ("Max membrane stress", "MPa")}


def summary_figures(numbers: dict) -> dict:
    """The flat figures of :data:`SUMMARY_FIGURES` from :func:`plant_numbers`' dict (``None``
    where a figure is not given: no liquid, no membrane point, a part that failed)."""
    states = {s["state"]: s for s in numbers.get("states") or []}
    least = numbers.get("least_tip") or {}
    wtc = numbers.get("weight_to_capacity") or {}
    stress = numbers.get("stress") or {}
    return {"least_tip_deg": least.get("deg"), "least_tip_state": least.get("state"),
            **{f"tip_{k}_deg": states.get(k, {}).get("tip_deg") for k in ("empty", "filled", "brimful")},
            "cg_empty_mm": states.get("empty", {}).get("cg_z_mm"),
            "cg_filled_mm": states.get("filled", {}).get("cg_z_mm"),
            "weight_to_capacity_g_per_ml": wtc.get("ratio_g_per_ml"),
            "max_stress_mpa": stress.get("max_mpa")}


def format_plant(numbers: dict) -> str:
    """The plant's figures as lines under ``glassbench info``'s table."""
    lines = ["  Plant"]
    for key, value in summary_figures(numbers).items():
        label, unit = SUMMARY_FIGURES[key]
        text = "-" if value is None else value if isinstance(value, str) else f"{value:10.2f} {unit}"
        lines.append(f"  {label:<22}{text}")
    band = numbers.get("capacity_band")
    if band:
        lines.append(f"  {'Capacity band':<22}{band['nominal_ml']:.1f} +- {band['tolerance_ml']:.1f} ml "
                     f"(75/107/EEC)")
    lines += [f"  warning: {w}" for w in numbers.get("warnings") or []]
    return "\n".join(lines)
