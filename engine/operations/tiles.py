"""The named operations on a design's bump tiles: one door for the command line and the panel.

Design rule: each operation takes the current ``Design`` (and the project's assets where an
image is named) and returns an :class:`~engine.operations.edit.Edit`; the caller applies it
(the panel through the undoable editor, ``glassbench bump`` by saving). So both doors start a
tile from the same numbers, refuse the same tiles with the same words (the model's own,
:func:`engine.model.finish_values.check_bump_values`, and the cap's skirt here), and let an
image that no tile uses any more leave the project. New tiles start from what a designer
would: a pattern's repeat follows the girth of its band (knurl about every 2 mm,
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

from ..appearance.relief_image import check_relief_image
from ..errors import DesignError, shown
from ..model.design import IMAGE_BUMPS, BumpTile
from ..model.finish_values import check_bump_values
from ..model.thread_finishes import nearest_finish, parse_finish
from .edit import Edit, released, replaced, swapped

#: Typical spacing (mm around the girth) of one repeat, and the depth (mm), per kind.
SPACING_MM = {"knurl": 2.0, "stipple": 3.0, "diamond": 8.0}
DEPTH_MM = {"knurl": 0.3, "stipple": 0.3, "flutes": 1.0, "facets": 1.0, "diamond": 0.8,
            "frosted": 0.0}
REPEAT = {"flutes": 16, "facets": 12, "frosted": 1, "thread": 1}
WIDTH = {"flutes": 0.8, "stipple": 0.6, "diamond": 0.6, "knurl": 0.0, "emboss": 0.05,
         "thread": 0.5}
#: Each kind in a designer's words (the panel's list and the undo stack's).
KIND_WORDS = {"knurl": "Knurl", "stipple": "Stipple (dots)", "flutes": "Flutes", "facets": "Facets",
              "diamond": "Diamond cut", "thread": "Screw thread", "frosted": "Frosted / satin",
              "height_map": "Image: height map", "colour_code": "Image: colour code",
              "normal_gl": "Image: normal map (OpenGL)", "normal_dx": "Image: normal map (DirectX)",
              "emboss": "Image: embossed logo"}
#: The fields a tile keeps when it moves between the glass and the cap.
KEPT_ON_MOVE = ("name", "asset", "angle_deg", "inverted", "depth", "width", "sharpness", "alpha",
                "pitch", "width_deg")


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
    return band[2] if band is not None else float(design.shape.r_mouth)


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
            2.0 * float(design.shape.r_mouth))
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


# ------------------------------------------------------------------------- where tiles go
def default_band(design, kind: str) -> tuple[float, float]:
    """Where a new tile of ``kind`` goes on the glass (mm): a thread on the finish, frosting over
    the body, a logo at mid-height, other patterns on the heel."""
    top = float(design.shape.z_top)
    if kind == "thread":
        return round(top - 14.0, 1), round(top - 3.0, 1)
    if kind == "frosted":
        return round(0.05 * top, 1), round(0.6 * top, 1)
    if kind in IMAGE_BUMPS:
        return round(0.3 * top, 1), round(0.45 * top, 1)
    return 2.0, round(min(12.0, 0.2 * top), 1)


def default_cap_band(design) -> tuple[float, float] | None:
    """Where a tile moved onto the cap goes (mm above the lower edge of its straight skirt):
    the skirt less a sixth at each end (clear of the rounded edges); ``None`` without a cap or
    a straight skirt."""
    from ..appearance.bands import cap_band
    band = cap_band(design, 0.0, 1e9) if design.cap is not None else None
    if band is None:
        return None
    height = band[2] - band[1]
    return round(height / 6.0, 1), round(5.0 * height / 6.0, 1)


def check_tile(design, tile: BumpTile, where: str = "the tile") -> None:
    """``DesignError`` for a tile ``design`` could not draw: the model's rules (ranges, a thread
    on the cap), and on the cap a cap with a straight skirt that the band meets."""
    check_bump_values(tile, where)
    if tile.on != "cap":
        return
    from ..appearance.cap_surfaces import cap_surface
    if design.cap is None:
        raise DesignError(f"{where} is on the cap but the design has no cap: put one on first")
    skirt = cap_surface(design, "cap-skirt", where)
    if not (tile.z1 > 0.0 and tile.z0 < skirt.height_mm):
        raise DesignError(f"{where}: heights {tile.z0:g}..{tile.z1:g} mm above the lower edge of the "
                          f"cap's skirt miss it (its straight skirt is {skirt.height_mm:.1f} mm tall)")


# ------------------------------------------------------------------------- the operations
def _with_bumps(design, bumps: tuple, text: str, added=None, select=None) -> Edit:
    """An :class:`Edit` setting ``bumps`` (each checked); images no longer used leave."""
    new = dataclasses.replace(design, bumps=tuple(bumps))
    for i, tile in enumerate(new.bumps):
        if i >= len(design.bumps) or tile != design.bumps[i]:
            check_tile(new, tile, f"tile {tile.name!r}")
    return Edit(new, text, released(design, new, added), select)


def add_tile(design, assets, kind: str, z0: float | None = None, z1: float | None = None, *,
             image: bytes | None = None, filename: str = "relief.png", **given) -> Edit:
    """Add a tile of ``kind`` on heights ``z0..z1`` (mm; default :func:`default_band`, on the cap
    :func:`default_cap_band`) with ``given`` fields; an image kind takes ``image`` (bytes of the
    file ``filename``, checked: ``ReliefImageError``)."""
    if z0 is None or z1 is None:
        band = default_cap_band(design) if given.get("on") == "cap" else default_band(design, kind)
        if band is None:
            raise DesignError("the design has no cap with a straight skirt: put one on first")
        z0, z1 = band
    added = None
    if kind in IMAGE_BUMPS:
        if image is None:
            raise DesignError(f"{KIND_WORDS[kind].lower()} needs its image")
        tile, name = add_image_tile(design, assets, kind, filename, image, z0, z1, **given)
        added = {name: bytes(image)}
    else:
        tile = new_tile(design, kind, z0, z1, **given)
    bumps = design.bumps + (tile,)
    return _with_bumps(design, bumps, f"Add {KIND_WORDS.get(kind, kind).lower()}", added, len(bumps) - 1)


def remove_tile(design, i: int) -> Edit:
    """Remove tile ``i``; its image leaves the project unless something else uses it."""
    _index(design, i)
    bumps = design.bumps[:i] + design.bumps[i + 1:]
    return _with_bumps(design, bumps, "Remove tile", select=min(i, len(bumps) - 1))


def move_tile(design, i: int, step: int) -> Edit | None:
    """Tile ``i`` moved ``step`` places in the list (``None`` if it cannot move)."""
    bumps = swapped(design.bumps, i, step)
    return None if bumps is None else _with_bumps(design, bumps, "Reorder tile", select=i + step)


def edit_tile(design, i: int, text: str, **fields) -> Edit | None:
    """Tile ``i`` with ``fields`` changed (``None`` when nothing changes)."""
    tile = design.bumps[_index(design, i)]
    if all(getattr(tile, k) == v for k, v in fields.items()):
        return None
    return _with_bumps(design, replaced(design.bumps, i, dataclasses.replace(tile, **fields)), text, select=i)


def set_tile_kind(design, assets, i: int, kind: str, image: bytes | None = None,
                  filename: str = "relief.png") -> Edit | None:
    """Tile ``i`` made ``kind`` on the same band with that kind's usual numbers (keeping its turn
    and sense); an image kind keeps the tile's image or takes ``image``."""
    tile = design.bumps[_index(design, i)]
    if kind == tile.kind:
        return None
    given = {"angle_deg": tile.angle_deg, "inverted": tile.inverted, "on": tile.on}
    added = None
    if kind in IMAGE_BUMPS and tile.asset is not None and image is None:
        new = new_tile(design, kind, tile.z0, tile.z1, asset=tile.asset, name=tile.name, **given)
    elif kind in IMAGE_BUMPS:
        if image is None:
            raise DesignError(f"{KIND_WORDS[kind].lower()} needs its image")
        new, name = add_image_tile(design, assets, kind, filename, image, tile.z0, tile.z1, **given)
        added = {name: bytes(image)}
    else:
        new = new_tile(design, kind, tile.z0, tile.z1, **given)
    return _with_bumps(design, replaced(design.bumps, i, new),
                       f"Tile kind {KIND_WORDS.get(kind, kind).lower()}", added, i)


def set_tile_surface(design, i: int, on: str) -> Edit | None:
    """Tile ``i`` moved onto the glass (``"bottle"``) or the cap's skirt (``"cap"``): its default
    band there, its repeat sized for that girth; ``DesignError`` for a thread or without a cap."""
    tile = design.bumps[_index(design, i)]
    if on == tile.on:
        return None
    if on == "cap":
        check_bump_values(dataclasses.replace(tile, on="cap"), f"tile {tile.name!r}")  # the model's words
        band = default_cap_band(design)
        if band is None:
            raise DesignError("the design has no cap with a straight skirt: put one on in the Cap tab first")
    else:
        band = default_band(design, tile.kind)
    keep = {f: getattr(tile, f) for f in KEPT_ON_MOVE}
    new = new_tile(design, tile.kind, *band, on=on, **keep)
    return _with_bumps(design, replaced(design.bumps, i, new), f"Tile on the {on}", select=i)


def set_tile_image(design, assets, i: int, filename: str, data: bytes) -> Edit:
    """Tile ``i`` (an image kind) relieved by the image bytes ``data`` of file ``filename``
    (checked: ``ReliefImageError``); the old image leaves unless something else uses it."""
    tile = design.bumps[_index(design, i)]
    if tile.kind not in IMAGE_BUMPS:
        raise DesignError(f"tile {tile.name!r} is a {tile.kind}, which takes no image")
    made, name = add_image_tile(design, assets, tile.kind, filename, data, tile.z0, tile.z1)
    new = dataclasses.replace(tile, asset=made.asset)
    return _with_bumps(design, replaced(design.bumps, i, new), "Tile image", {name: bytes(data)}, i)


def _index(design, i: int) -> int:
    if not 0 <= i < len(design.bumps):
        raise DesignError(f"the design has no bump tile {i} (it has {len(design.bumps)})")
    return i
