"""Label values against their ranges: the cheap part of checking a label (no geometry).

Design rule: :func:`check_label_values` is called by :func:`engine.model.check.check_values` for
every edit, save and load, so it looks only at the numbers and names a label holds: sizes,
coefficients, colours, finish kinds and their parameters, region sources with what they need,
and names unique within the design (batch overrides and the command line name labels). Whether
a label lies on the glass (on the outer wall, at most once around) needs the geometry and is
:func:`engine.appearance.placement.check_label_placement`, run by
:func:`engine.operations.check.check_design`. Every error is a :class:`engine.errors.DesignError`
naming the field by its path in the project file (``design.labels[0].width_mm``).
"""
from __future__ import annotations

from .. import limits as L
from ..errors import DesignError, shown
from .design import FINISH_KINDS, LABEL_SURFACES, REGION_SOURCES


def check_label_values(labels) -> None:
    """Raise ``DesignError`` for the first label value outside its range.

    Parameters
    ----------
    labels : tuple of engine.model.design.Label
        ``Design.labels`` (overlap order).
    """
    seen: dict[str, int] = {}
    for i, label in enumerate(labels):
        where = f"design.labels[{i}]"
        if not label.name.strip():
            raise DesignError(f"{where}.name is empty; a label needs a name")
        if label.name in seen:
            raise DesignError(f"{where}.name {shown(label.name)} is already the name of "
                              f"design.labels[{seen[label.name]}]; label names must differ")
        seen[label.name] = i
        if label.surface not in LABEL_SURFACES:
            raise DesignError(f"{where}.surface must be one of {', '.join(LABEL_SURFACES)}, "
                              f"got {shown(label.surface)}")
        L.check_range(f"{where}.z_mm", label.z_mm, (0.0, L.MAX_EXTENT_MM), "mm")
        for key in ("cap_x_mm", "cap_y_mm"):
            L.check_range(f"{where}.{key}", getattr(label, key), (-L.MAX_EXTENT_MM, L.MAX_EXTENT_MM), "mm")
        L.check_range(f"{where}.angle_deg", label.angle_deg, (-L.MAX_TURN_DEG, L.MAX_TURN_DEG), "deg")
        for key in ("height_mm", "width_mm"):
            L.check_range(f"{where}.{key}", getattr(label, key), L.LABEL_SIZE_RANGE_MM, "mm")
        for key in ("diffuse", "specular", "transmission"):
            L.check_range(f"{where}.{key}", getattr(label, key), L.LABEL_COEFFICIENT_RANGE)
        if label.diffuse + label.transmission > 1.0 + 1e-12:
            raise DesignError(f"{where}: diffuse {label.diffuse:g} + transmission "
                              f"{label.transmission:g} is more than 1 (a sheet cannot give back "
                              f"more light than it receives)")
        for side in ("front", "back"):
            for c, v in enumerate(getattr(label, side).color):
                L.check_range(f"{where}.{side}.color[{c}]", v, L.LABEL_COLOR_RANGE)
        _check_regions(label.regions, where)


def _check_regions(regions, where: str) -> None:
    if len(regions) > L.MAX_LABEL_REGIONS:
        raise DesignError(f"{where}.regions has {len(regions)} regions (limit {L.MAX_LABEL_REGIONS})")
    for k, region in enumerate(regions):
        at = f"{where}.regions[{k}]"
        if region.finish not in FINISH_KINDS:
            raise DesignError(f"{at}.finish must be one of {', '.join(FINISH_KINDS)}, "
                              f"got {shown(region.finish)}")
        if region.source not in REGION_SOURCES:
            raise DesignError(f"{at}.source must be 'chroma' or 'mask', got {shown(region.source)}")
        if region.source == "chroma":
            if not region.keys:
                raise DesignError(f"{at} keys by colour but has no key colours")
            if len(region.keys) > L.MAX_KEY_COLORS:
                raise DesignError(f"{at}.keys has {len(region.keys)} colours (limit {L.MAX_KEY_COLORS})")
            for j, key in enumerate(region.keys):
                for c, v in enumerate(key):
                    L.check_range(f"{at}.keys[{j}][{c}]", v, L.LABEL_COLOR_RANGE)
        elif region.mask_asset is None:
            raise DesignError(f"{at} takes its shape from a mask image but names none")
        L.check_range(f"{at}.tolerance", region.tolerance, L.KEY_TOLERANCE_RANGE)
        L.check_range(f"{at}.depth_mm", region.depth_mm, L.EMBOSS_DEPTH_RANGE_MM, "mm")
        L.check_range(f"{at}.gloss", region.gloss, L.GLOSS_RANGE)
