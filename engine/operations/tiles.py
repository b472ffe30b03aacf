"""New bump tiles with the sizes a designer would start from, and relief images as assets.

Design rule: the command line and the bump-tiles panel create tiles here, so both start from
the same numbers: a pattern's repeat follows the girth of its band (knurl about every 2 mm,
dots every 3 mm, diamonds every 8 mm), a thread takes its depth, pitch and ridge from the
finish standard nearest the neck (or the one named), frosting a satin-to-etched roughness.
An image is checked (:func:`engine.appearance.relief_image.check_relief_image`) before it
becomes an asset, under a plain file name that does not clash with the project's others.
"""
from __future__ import annotations

import dataclasses
import math
import os
import re

from ..errors import DesignError, shown
from ..model.design import IMAGE_BUMPS, BumpTile
from ..appearance.relief_image import check_relief_image
from ..model.thread_finishes import nearest_finish, parse_finish

#: Typical spacing (mm around the girth) of one repeat, and the depth (mm), per kind.
SPACING_MM = {"knurl": 2.0, "stipple": 3.0, "diamond": 8.0}
DEPTH_MM = {"knurl": 0.3, "stipple": 0.3, "flutes": 1.0, "facets": 1.0, "diamond": 0.8,
            "frosted": 0.0}
REPEAT = {"flutes": 16, "facets": 12, "frosted": 1, "thread": 1}
WIDTH = {"flutes": 0.8, "stipple": 0.6, "diamond": 0.6, "knurl": 0.0, "emboss": 0.05,
         "thread": 0.5}


def band_radius(design, z0: float, z1: float, on: str = "bottle") -> float:
    """Outer radius (mm) of the bottle at the middle of the band (its mouth radius if the band
    is outside the wall); with ``on="cap"`` the radius of the cap's straight skirt, else of
    the whole closure."""
    from ..appearance.bands import band_coordinates, cap_band
    from ..appearance.closures import closure_geometry
    if on == "cap" and design.cap is not None:
        band = cap_band(design, 0.0, 1e9)
        return band[3] if band is not None else closure_geometry(design).r_max
    band = band_coordinates(design, z0, z1)
    return band[2] if band is not None else float(design.shape.primary.r_top)


def new_tile(design, kind: str, z0: float, z1: float, **given) -> BumpTile:
    """A :class:`BumpTile` of ``kind`` on heights ``z0..z1`` (mm) with the kind's starting
    values, overridden by ``given`` (field name -> value; ``None`` values are ignored)."""
    given = {k: v for k, v in given.items() if v is not None}
    fields = {"name": kind.replace("_", " "), "kind": kind, "z0": float(z0), "z1": float(z1)}
    girth = 2.0 * math.pi * band_radius(design, z0, z1, given.get("on", "bottle"))
    if kind in SPACING_MM:
        fields["repeat"] = max(8, round(girth / SPACING_MM[kind]))
    elif kind in REPEAT:
        fields["repeat"] = REPEAT[kind]
    elif kind in IMAGE_BUMPS:
        fields["repeat"] = 1
    if kind in DEPTH_MM:
        fields["depth"] = DEPTH_MM[kind]
    if kind in WIDTH:
        fields["width"] = WIDTH[kind]
    if kind == "thread":
        finish = given.get("finish", "")
        spec = parse_finish(finish, "--finish") if finish else nearest_finish(
            2.0 * float(design.shape.primary.r_top))
        fields.update(depth=round(spec.depth_mm, 3), finish=spec.name)
    fields.update(given)
    return BumpTile(**fields)


def image_asset_name(filename: str, data: bytes, assets) -> str:
    """A plain asset name for the image file ``filename``: its base name (unsafe characters
    replaced), numbered if the project already holds different bytes under it."""
    base = re.sub(r"[^\w .()-]", "_", os.path.basename(str(filename)))[:100].lstrip(".") or "relief.png"
    stem, ext = os.path.splitext(base)
    name, k = base, 2
    while name in assets and bytes(assets[name]) != bytes(data):
        name = f"{stem}-{k}{ext}"
        k += 1
    return name


def add_image_tile(design, assets, kind: str, filename: str, data: bytes, z0: float, z1: float,
                   **given):
    """``(tile, asset name)`` of a relief image tile; the image is checked first
    (:class:`~engine.appearance.relief_image.ReliefImageError` if it cannot be used)."""
    if kind not in IMAGE_BUMPS:
        raise DesignError(f"{shown(kind)} is not an image relief ({', '.join(IMAGE_BUMPS)})")
    check_relief_image(os.path.basename(str(filename)), data)
    name = image_asset_name(filename, data, assets)
    tile = new_tile(design, kind, z0, z1, asset=name, **given)
    return dataclasses.replace(tile, name=given.get("name") or os.path.splitext(name)[0]), name
