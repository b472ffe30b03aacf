"""What a project's bump tiles and closure need beyond their values: images and a fit.

Design rule: :func:`check_finishes` runs inside :func:`engine.operations.check.check_design`
(on load, before every save, for the window's edits of tiles and cap), after the shape has been
validated. It refuses a relief tile whose image is missing, too large, corrupt or holds NaN
(:mod:`.relief_image`, cached by content so an edit does not decode again) and a closure that
cannot be fitted to the finish, each as one :class:`~engine.errors.ProjectError` naming the
field. A band outside the bottle is not an error: it shows nothing (the neck may have moved).
"""
from __future__ import annotations

from ..errors import GlassbenchError, ProjectError, shown
from .relief_image import ReliefImageError, check_relief_image


def check_finishes(design, assets) -> None:
    """Raise ``ProjectError`` for a tile's missing or unusable image or an unfittable cap."""
    for i, tile in enumerate(design.bumps):
        if tile.asset is None:
            continue
        if tile.asset not in assets:
            raise ProjectError(f"design.bumps[{i}] names asset {shown(tile.asset)}, which the "
                               f"project lacks")
        try:
            check_relief_image(tile.asset, assets[tile.asset])
        except ReliefImageError as exc:
            raise ReliefImageError(f"design.bumps[{i}]: {exc}") from None
    if design.cap is not None:
        from .closures import closure_geometry
        try:
            closure_geometry(design)
        except (GlassbenchError, ValueError, ArithmeticError) as exc:
            raise ProjectError(f"design.cap: a {design.cap.kind} closure does not fit this "
                               f"finish: {exc}") from None
