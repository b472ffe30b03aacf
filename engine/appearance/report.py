"""What the printer needs of one label: area, flat die-line, largest strain and warnings.

Design rule: one :class:`LabelReport` per label, made by :func:`label_report` from the flat
shape (:mod:`.dieline`) and the warnings on it (:mod:`.warnings`), or for a print on the closure
the flat rectangle it is (:mod:`.cap_surfaces`); ``glassbench labels``,
``glassbench dieline`` and the labels panel all show this one report. Units mm.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import math

import numpy as np

from .cap_surfaces import cap_surface
from .dieline import FlatShape, flat_shape, grid_shape
from .frame import Placement
from .warnings import area_mm2, label_warnings


@dataclass(frozen=True)
class LabelReport:
    """What the printer needs of one label (see :func:`label_report`)."""

    index: int
    name: str
    area_mm2: float
    flat: FlatShape
    max_strain: float
    warnings: tuple = field(default=())

    def to_json(self) -> dict:
        return {"index": self.index, "name": self.name, "area_mm2": round(self.area_mm2, 3),
                "dieline": self.flat.figures, "max_strain": round(self.max_strain, 6),
                "warnings": [w.to_json() for w in self.warnings]}


def label_report(design, index: int) -> LabelReport:
    """Area (mm^2 on the glass), flat die-line, largest strain and warnings of
    ``design.labels[index]`` (which must lie on its surface)."""
    label = design.labels[index]
    if label.surface != "wall":
        return _cap_report(design, index, label)
    p = Placement.of(label)
    flat = flat_shape(design.shape, p)
    return LabelReport(index, label.name, area_mm2(design.shape, p, flat), flat,
                       float(flat.strain.max()), label_warnings(design.shape, p, flat))


def _cap_report(design, index: int, label) -> LabelReport:
    """The report of a print on the closure: a flat rectangle with no strain and no warnings
    (the top is flat, the skirt a cylinder), its figures naming the surface it is printed on:
    the top's flat disk (``disk_diameter_mm``) or the skirt (``skirt_height_mm``,
    ``skirt_girth_mm``)."""
    p = Placement.of(label)
    nt, ns = grid_shape(p)
    s, t = np.meshgrid(np.linspace(0.0, 1.0, ns), np.linspace(0.0, 1.0, nt))
    rect = np.stack([(s - 0.5) * p.width_mm, (0.5 - t) * p.height_mm], -1)
    surf = cap_surface(design, label.surface)
    figures = {"kind": "rectangle", "width_mm": p.width_mm, "height_mm": p.height_mm,
               "surface": label.surface}
    if label.surface == "cap-top":
        figures["disk_diameter_mm"] = round(2.0 * surf.radius, 3)
    else:
        figures["skirt_height_mm"] = round(surf.height_mm, 3)
        figures["skirt_girth_mm"] = round(2.0 * math.pi * surf.radius, 3)
    flat = FlatShape("rectangle", rect, np.zeros(s.shape), figures)
    return LabelReport(index, label.name, p.width_mm * p.height_mm, flat, 0.0, ())


def describe(fig: dict) -> str:
    """A die-line's figures in words."""
    if fig.get("surface") == "cap-top":
        return (f"rectangle {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm on the cap's top "
                f"(a flat disk {fig['disk_diameter_mm']:.2f} mm across)")
    if fig.get("surface") == "cap-skirt":
        return (f"rectangle {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm on the cap's skirt "
                f"({fig['skirt_girth_mm']:.2f} mm around, {fig['skirt_height_mm']:.2f} mm high)")
    if fig["kind"] == "rectangle":
        return f"rectangle {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm"
    if fig["kind"] == "sector":
        return (f"sector r {fig['r_inner_mm']:.2f}..{fig['r_outer_mm']:.2f} mm, "
                f"{fig['angle_deg']:.2f} deg")
    return f"outline {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm"
