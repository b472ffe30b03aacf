"""The design as CAD solids for the mould shop: glass, liquid and closure, in STEP, IGES or BREP.

Design rule: the glass is one closed solid built from the same validated profile the capacity
and the tracer read (:func:`engine.geometry.validate.body_profile`), never from a mesh. A round
bottle is its meridian (outer base, outer wall, rim, inner wall and inner base walked back, the
axis) revolved a full turn (:mod:`engine.export.occ_profile`: exact planes, cones, tori and
ellipses; the offset of an ellipse arc a B-spline within ``tol_mm``); a non-round body is sewn
from B-spline patches (:mod:`engine.export.cad_nonround`), an outline (free plan) body from
planes, cylinders, cones, tori and B-spline patches, one per piece of its plan per height band
(:mod:`engine.export.cad_outline`). The liquid is its own solid (the
cavity up to the fill line), each closure part another, and every body carries its name
(``glass``, ``liquid``, ``closure <part>``) in STEP and IGES. A file is written to a temporary
name, read back by OpenCascade and checked (:mod:`engine.export.cad_check`: valid, closed,
volumes equal to ``glassbench info``'s to :data:`VOLUME_RTOL`) before it replaces the target,
so a file that arrives is one the kernel accepted. Units mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..appearance.closures import closure_geometry
from ..io.atomic import replacing
from ..geometry import capacity
from ..geometry.chain import locate, param_at_z, subsegment
from ..geometry.segments import Line, OffsetEllipseArc
from ..geometry.validate import body_profile
from ..model import fill
from .cad_check import VOLUME_RTOL, check_cad_file  # noqa: F401 - VOLUME_RTOL for callers
from .occ_profile import revolved_solid

FORMATS = (".step", ".stp", ".iges", ".igs", ".brep")
#: Default largest distance (mm) of a fitted B-spline surface from the exact one.
DEFAULT_TOL_MM = 0.001


@dataclass(frozen=True)
class CadBody:
    """One named solid (an OpenCascade ``TopoDS_Solid``), its kind (``glass``, ``liquid``,
    ``closure``), the volume (mm^3) the trade numbers expect of it (``None``: not checked) and
    the largest distance (mm) of any fitted surface from the exact one (0: all exact)."""

    name: str
    kind: str
    solid: object
    expected_mm3: float | None
    deviation_mm: float


def reversed_chain(chain) -> list:
    """The segments of ``chain`` walked backwards (an offset ellipse keeps its curve: the
    reversed base's normal is the opposite one, so the offset distance changes sign)."""
    out = []
    for s in reversed(chain):
        out.append(OffsetEllipseArc(s.base.reversed(), -s.w) if isinstance(s, OffsetEllipseArc)
                   else s.reversed())
    return out


def clipped_below(chain, z: float) -> list:
    """The part of a z-rising ``chain`` at or below height ``z`` (mm)."""
    out = []
    for s in chain:
        if s.p1[1] <= z:
            out.append(s)
            continue
        if s.p0[1] < z:
            t = float(param_at_z(s, z))
            if t > 1e-12:
                out.append(subsegment(s, 0.0, t))
        break
    return out


def glass_meridian(prof) -> list:
    """The closed meridian of a round bottle's glass, from the outer base's centre round the
    outside, across the rim and back down the inside (closed along the axis)."""
    sp = prof.sections[0]
    rim = Line(sp.outer_wall[-1].p1, sp.inner_wall[-1].p1)
    return [*sp.outer_base, *sp.outer_wall, rim, *reversed_chain(sp.inner_wall),
            *reversed_chain(sp.inner_base)]


def liquid_meridian(prof, height: float) -> list:
    """The closed meridian of the liquid standing at ``height`` mm in a round bottle: the inner
    base (from where the level cuts a punt's dome, if it does), the wetted inner wall, the
    free surface back to the axis or to the dome."""
    sp = prof.sections[0]
    base = list(sp.inner_base)
    if prof.punt and height < base[0].p0[1]:
        i, t = (float(v[0]) for v in locate(tuple(base), np.array([height])))
        i = int(i)
        base = ([subsegment(base[i], t, 1.0)] if t < 1.0 - 1e-12 else []) + base[i + 1:]
    wall = clipped_below(sp.inner_wall, height)
    top_r = float(wall[-1].p1[0])
    start = base[0].p0
    return [*base, *wall, Line((top_r, height), (float(start[0]), height))]


def glass_bodies(design, tol_mm: float = DEFAULT_TOL_MM, liquid: bool = True) -> list[CadBody]:
    """The design's solids: ``glass``, ``liquid`` (with ``liquid`` and a liquid in the design)
    and one ``closure <part>`` per closure part. Raises ``CadError`` where the kernel cannot and
    ``DesignError`` for a kind that refuses CAD export (:meth:`CrossSection.require`)."""
    shape = design.shape
    shape.xs.require("cad")
    prof = body_profile(shape)
    glass_mm3 = capacity.glass_volume_cm3(shape) * capacity.MM3_PER_ML
    height = fill.fill_height_mm(shape, design.liquid) if (liquid and design.liquid) else None
    liquid_mm3 = (fill.fill_volume_ml(shape, design.liquid) * capacity.MM3_PER_ML
                  if height is not None else None)
    bodies = []
    if shape.xs.revolved:
        solid, dev = revolved_solid(glass_meridian(prof), tol_mm, "glass")
        bodies.append(CadBody("glass", "glass", solid, glass_mm3, dev))
        if height is not None and height > prof.z_ib:
            solid, dev = revolved_solid(liquid_meridian(prof, height), tol_mm, "liquid")
            bodies.append(CadBody("liquid", "liquid", solid, liquid_mm3, dev))
    else:
        glass_solid, liquid_solid = _swept_builders(shape)
        solid, dev = glass_solid(shape, tol_mm)
        bodies.append(CadBody("glass", "glass", solid, glass_mm3, dev))
        if height is not None and height > prof.z_ib:
            solid, dev = liquid_solid(shape, height, tol_mm)
            bodies.append(CadBody("liquid", "liquid", solid, liquid_mm3, dev))
    geom = closure_geometry(design)
    for part in (geom.parts if geom is not None else ()):
        solid, dev = revolved_solid(part.chain, tol_mm, f"closure's {part.name}")
        bodies.append(CadBody(f"closure {part.name}", "closure", solid, None, dev))
    return bodies


def _swept_builders(shape):
    """``(glass, liquid)`` solid builders of a bottle that is not revolved: an outline's pieces
    (:mod:`engine.export.cad_outline`) or a fixed kind's patches (:mod:`engine.export.cad_nonround`)."""
    if shape.cross_section == "outline":
        from .cad_outline import outline_glass, outline_liquid
        return outline_glass, outline_liquid
    from .cad_nonround import nonround_glass, nonround_liquid
    return nonround_glass, nonround_liquid


def check_tolerance(tol_mm: float) -> float:
    """``tol_mm`` as a float in 1e-6 .. 1 mm, else ``ValueError`` (a fit's tolerance, mm)."""
    tol = float(tol_mm)
    if not (math.isfinite(tol) and 1e-6 <= tol <= 1.0):
        raise ValueError(f"the CAD tolerance must be 1e-06 to 1 mm, got {tol_mm!r}")
    return tol


def export_cad(design, path, tol_mm: float = DEFAULT_TOL_MM, liquid: bool = True,
               progress=None) -> dict:
    """Write ``design``'s solids to ``path`` (format from the suffix, :data:`FORMATS`), read
    the temporary file back and check it (:func:`engine.export.cad_check.check_cad_file`)
    before it replaces ``path``. Returns that check's report (bodies, volumes in mm^3 and
    their relative errors). Raises ``CadError`` (nothing written) if a check fails,
    ``ValueError`` for a bad suffix or tolerance, ``OSError`` if the file cannot be written."""
    from .cad_write import write_bodies
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"unknown CAD format {path.suffix!r}; use one of {', '.join(FORMATS)}")
    tol = check_tolerance(tol_mm)
    step = progress or (lambda f, m: None)
    step(0.05, "building solids")
    bodies = glass_bodies(design, tol, liquid)
    step(0.6, f"writing {suffix[1:].upper()}")
    with replacing(path, suffix=suffix) as tmp:
        write_bodies(bodies, tmp, suffix, design.name)
        step(0.8, "reading back")
        report = check_cad_file(tmp, bodies)
    step(1.0, "done")
    return report
