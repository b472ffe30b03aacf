"""The whole design as one immutable value: what a project file holds and what the tracer renders.

Design rule: every part is a frozen dataclass of plain numbers, strings and tuples, so a
``Design`` hashes, compares by value and can be handed to worker threads as a snapshot. Edits
make a new value with ``dataclasses.replace``; :class:`engine.model.scene.Scene` holds the current
one and tells observers which top-level fields changed. Units: mm, 1/mm for absorption,
degrees where a name ends in ``_deg``. Parts that later issues fill in (labels, bump tiles,
cap) have their place here as tuples so that the file format already carries them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..geometry.shape import BottleShape

RGB = tuple[float, float, float]


@dataclass(frozen=True)
class Glass:
    """Glass optics and mass: refractive index, absorption (1/mm per RGB), density (g/cm^3)."""

    ior: float = 1.52
    absorption: RGB = (0.0, 0.0, 0.0)
    density_g_cm3: float = 2.52


@dataclass(frozen=True)
class Liquid:
    """A liquid filled to a level: ``fill_mode`` ``"height"`` (``fill_value`` in mm above z = 0)
    or ``"volume"`` (``fill_value`` in ml, solved to a height by :mod:`engine.geometry.capacity`)."""

    ior: float = 1.333
    absorption: RGB = (0.02, 0.006, 0.002)
    fill_mode: str = "height"
    fill_value: float = 100.0


@dataclass(frozen=True)
class Camera:
    """Pinhole camera (SPEC section 2): eye and target in mm, vertical field of view."""

    eye: tuple[float, float, float] = (0.0, -600.0, 180.0)
    target: tuple[float, float, float] = (0.0, 0.0, 150.0)
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fov_y_deg: float = 30.0


@dataclass(frozen=True)
class Environment:
    """Light from far away: the built-in ``"studio"`` or an equirectangular ``"file"``
    (``asset`` names an image embedded in the project), scaled and turned about +z."""

    kind: str = "studio"
    asset: str | None = None
    scale: float = 1.0
    rotation_deg: float = 0.0


@dataclass(frozen=True)
class Light:
    """A distant light for the diffuse parts (labels, cap): direction towards the light."""

    direction: tuple[float, float, float] = (-0.5, -1.0, 1.0)
    color: RGB = (1.0, 1.0, 1.0)
    intensity: float = 1.0


@dataclass(frozen=True)
class RenderSettings:
    """Image size (pixels), anti-aliasing samples per pixel and the tree cut-offs.

    A branch of the reflection/refraction tree ends when its weight (product of Fresnel terms
    and absorption) falls below ``min_weight`` or after ``max_depth`` boundaries. Light trapped
    by total internal reflection in a thick base needs many bounces: on the oracle's public_1
    scene depth 24 darkens the image by 6.9 % and depth 64 by 3.0 % against depth 256
    (``python -m benchmarks.tracer``), so 64 is the default.
    """

    width: int = 480
    height: int = 640
    spp: int = 16
    max_depth: int = 64
    min_weight: float = 1e-3


@dataclass(frozen=True)
class Label:
    """A paper or vinyl label (filled in by the labels issue)."""

    name: str = "label"
    asset: str | None = None


@dataclass(frozen=True)
class BumpTile:
    """A bump tile: knurling, threads, cut pattern, frosting, emboss (later issue)."""

    name: str = "bump"
    kind: str = "frosted"


@dataclass(frozen=True)
class Cap:
    """A metal cap on the finish (later issue)."""

    height: float = 20.0


@dataclass(frozen=True)
class Design:
    """Everything a design is. Compare with ``==``; hash for caches; never mutate."""

    shape: BottleShape
    glass: Glass = field(default_factory=Glass)
    liquid: Liquid | None = None
    camera: Camera = field(default_factory=Camera)
    environment: Environment = field(default_factory=Environment)
    lights: tuple[Light, ...] = (Light(),)
    render: RenderSettings = field(default_factory=RenderSettings)
    labels: tuple[Label, ...] = ()
    bumps: tuple[BumpTile, ...] = ()
    cap: Cap | None = None
    name: str = "Untitled"
    notes: str = ""
