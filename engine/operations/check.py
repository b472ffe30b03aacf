"""The design check: everything a design must satisfy before it is shown, saved or rendered.

Design rule: :func:`check_design` is the one check every GUI edit (that can break it), every
save and every load runs, and the CLI and batch overrides run before they write: the values
(:mod:`engine.model.check`), the assets' names and sizes and those the design names, the
geometry (:mod:`engine.geometry.validate`), the fill level (:mod:`engine.model.fill`), the
labels on their surfaces and the relief images and the closure's fit
(:mod:`engine.appearance`). It lives beside the model and above the appearance it reads, not in
the file format: :mod:`engine.files.project` calls it, never the other way round.
"""
from __future__ import annotations

from typing import Mapping

from ..appearance.finish_check import check_finishes
from ..appearance.placement import check_label_placement
from ..errors import GlassbenchError, ProjectError, shown
from ..geometry.validate import body_profile
from ..limits import check_assets
from ..model.check import check_values
from ..model.design import Design
from ..model.fill import check_fill


def check_design(design: Design, assets: Mapping[str, bytes]) -> None:
    """Check what the value types cannot: ranges, sizes, asset references, geometry, fill level.

    The same check runs before a project is written and after it is read. In order: the
    values (:func:`engine.model.check.check_values`, the limits of :mod:`engine.limits`), the
    assets (:func:`check_assets`) and those named by the environment and labels, the geometry
    (:func:`engine.geometry.validate.validate_shape`), the liquid level
    (:func:`engine.model.fill.check_fill`), the labels on the wall
    (:func:`engine.appearance.placement.check_label_placement`; artwork images are checked
    when they are imported and decoded, :mod:`engine.appearance.images`), the relief images
    and the closure's fit (:func:`engine.appearance.finish_check.check_finishes`). Raises
    ``ProjectError`` (a ``DesignError`` for a value); ``SectionError`` / ``WallError`` from
    validation are wrapped with their message kept.
    """
    check_values(design)
    check_assets(assets)
    refs = [("environment", design.environment.asset)] + [
        (f"labels[{i}]", name) for i, lab in enumerate(design.labels) for name in lab.asset_names()]
    for where, name in refs:
        if name is not None and name not in assets:
            raise ProjectError(f"design.{where} names asset {shown(name)}, which the project lacks")
    validate_design_shape(design)
    check_fill(design.shape, design.liquid)
    check_label_placement(design)
    check_finishes(design, assets)


def validate_design_shape(design: Design) -> None:
    """Run :func:`engine.geometry.validate.validate_shape` (through the cached
    :func:`~engine.geometry.validate.body_profile`), wrapping its errors in ``ProjectError``."""
    try:
        body_profile(design.shape)  # validates; the profile is kept for the fill check
    except GlassbenchError as exc:
        raise ProjectError(f"invalid bottle shape: {exc}") from None
    except (ValueError, ArithmeticError) as exc:
        raise ProjectError(f"invalid bottle shape: {exc}") from None


#: Design fields whose edit can break what :func:`check_design` checks beyond the values: the
#: assets a field names, the fit of labels and closure, the fill level.
DESIGN_CHECKED = frozenset({"glass", "liquid", "render", "environment", "labels", "bumps", "cap"})


def check_edit(design: Design, changed, assets: Mapping[str, bytes]) -> None:
    """Check ``design`` after an edit of the fields ``changed``, only as far as they can break
    it (a GUI edit runs this at every step of a drag): the values always (cheap), the geometry
    for a shape edit, the whole :func:`check_design` for a field that names assets or must fit
    the bottle (and for a shape edit under labels or a closure), the fill for a liquid or shape
    edit. Raises what :func:`check_design` raises."""
    check_values(design)
    if "shape" in changed:
        body_profile(design.shape)
    if changed & DESIGN_CHECKED or ("shape" in changed and (design.labels or design.cap is not None)):
        check_design(design, assets)
    if changed & {"liquid", "shape"} and design.liquid is not None:
        check_fill(design.shape, design.liquid)
