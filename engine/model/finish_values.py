"""The values of bump tiles and of the closure against their ranges (no geometry, no images).

Design rule: like :func:`engine.model.check.check_values`, which calls :func:`check_finish_values`,
this is cheap enough for every edit and names the field by its path in the project file
(``design.bumps[2].depth``). What needs the shape or the embedded images (a relief image that
is corrupt, too large or holds NaN; a thread standard the neck cannot carry) is checked by
:func:`engine.appearance.finish_check.check_finish_assets`, called from
:func:`engine.operations.check.check_design`.
"""
from __future__ import annotations

from .. import limits as L
from ..errors import DesignError, shown
from .design import BUMP_KINDS, BUMP_SURFACES, CAP_KINDS, CAP_MATERIALS, IMAGE_BUMPS, THREAD_GEOMETRY
from .thread_finishes import parse_finish

_TURN = (-L.MAX_TURN_DEG, L.MAX_TURN_DEG)


def check_finish_values(design) -> None:
    """Raise ``DesignError`` for the first bump tile or closure value outside its range."""
    for i, tile in enumerate(design.bumps):
        check_bump_values(tile, f"design.bumps[{i}]")
    if design.cap is not None:
        check_cap_values(design.cap, "design.cap")


def check_bump_values(tile, where: str) -> None:
    """Kind, band, repeat, depth, shape fields and image reference of one ``BumpTile``."""
    if tile.kind not in BUMP_KINDS:
        raise DesignError(f"{where}.kind {shown(tile.kind)} is not one of {', '.join(BUMP_KINDS)}")
    ext = (-L.MAX_EXTENT_MM, L.MAX_EXTENT_MM)
    L.check_range(f"{where}.z0", tile.z0, ext, "mm")
    L.check_range(f"{where}.z1", tile.z1, ext, "mm")
    if not tile.z1 > tile.z0:
        raise DesignError(f"{where}: the band's top z1 = {tile.z1:g} mm is not above its bottom "
                          f"z0 = {tile.z0:g} mm")
    L.check_range(f"{where}.repeat", tile.repeat, L.BUMP_REPEAT_RANGE, integer=True)
    if tile.kind == "facets" and tile.repeat < 3:
        raise DesignError(f"{where}.repeat = {tile.repeat}: facets need at least 3 around")
    L.check_range(f"{where}.depth", tile.depth, (0.0, L.MAX_BUMP_DEPTH_MM), "mm")
    L.check_range(f"{where}.angle_deg", tile.angle_deg, _TURN, "deg")
    L.check_range(f"{where}.pitch", tile.pitch, (0.0, L.MAX_EXTENT_MM), "mm")
    L.check_range(f"{where}.width", tile.width, (0.0, 1.0))
    L.check_range(f"{where}.sharpness", tile.sharpness, (0.0, 1.0))
    L.check_range(f"{where}.alpha", tile.alpha, L.GGX_ALPHA_RANGE)
    L.check_range(f"{where}.width_deg", tile.width_deg, (1e-3, 360.0), "deg")
    if tile.kind in IMAGE_BUMPS and tile.asset is None:
        raise DesignError(f"{where} is a {tile.kind} but names no image asset")
    if tile.kind not in IMAGE_BUMPS and tile.asset is not None:
        raise DesignError(f"{where} is a {tile.kind}, which takes no image (asset {shown(tile.asset)})")
    if tile.on not in BUMP_SURFACES:
        raise DesignError(f"{where}.on {shown(tile.on)} is not one of {', '.join(BUMP_SURFACES)}")
    if tile.on == "cap" and tile.kind == "thread":
        raise DesignError(f"{where} is a thread on the cap: a thread belongs to the glass finish "
                          f"(the cap's own thread is inside it, never seen)")
    if tile.geometry not in THREAD_GEOMETRY:
        raise DesignError(f"{where}.geometry {shown(tile.geometry)} is not one of "
                          f"{', '.join(THREAD_GEOMETRY)}")
    if tile.kind == "thread" and tile.finish:
        parse_finish(tile.finish, f"{where}.finish")


def check_cap_values(cap, where: str) -> None:
    """Kind, material, colour, height and count of the ``Cap``."""
    if cap.kind not in CAP_KINDS:
        raise DesignError(f"{where}.kind {shown(cap.kind)} is not one of {', '.join(CAP_KINDS)}")
    if cap.material not in CAP_MATERIALS:
        raise DesignError(f"{where}.material {shown(cap.material)} is not one of "
                          f"{', '.join(CAP_MATERIALS)}")
    for c, v in enumerate(cap.color):
        L.check_range(f"{where}.color[{c}]", v, (0.0, 1.0))
    L.check_range(f"{where}.height", cap.height, L.CAP_HEIGHT_RANGE, "mm")
    L.check_range(f"{where}.count", cap.count, L.CAP_COUNT_RANGE, integer=True)
    if cap.kind == "lug" and cap.count:
        L.check_range(f"{where}.count", cap.count, L.CAP_LUGS_RANGE, integer=True)
    if cap.kind == "crown" and 0 < cap.count < 3:
        raise DesignError(f"{where}.count = {cap.count}: a crown needs at least 3 flutes")
