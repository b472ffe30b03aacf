"""What the printer needs of one label: area, flat die-line, largest strain and warnings.

Design rule: one :class:`LabelReport` per label, made by :func:`label_report` from the flat
shape (:mod:`.dieline`) and the warnings on it (:mod:`.warnings`); ``glassbench labels``,
``glassbench dieline`` and the labels panel all show this one report. Units mm.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .dieline import FlatShape, flat_shape
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
    ``design.labels[index]`` (which must lie on the wall)."""
    label = design.labels[index]
    p = Placement.of(label)
    flat = flat_shape(design.shape, p)
    return LabelReport(index, label.name, area_mm2(design.shape, p, flat), flat,
                       float(flat.strain.max()), label_warnings(design.shape, p, flat))
