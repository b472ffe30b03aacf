"""The whole design as one immutable value: what a project file holds and what the tracer renders.

Design rule: every part is a frozen dataclass of plain numbers, strings and tuples, so a
``Design`` hashes, compares by value and can be handed to worker threads as a snapshot. Edits
make a new value with ``dataclasses.replace``; :class:`engine.model.scene.Scene` holds the current
one and tells observers which top-level fields changed. Units: mm, 1/mm for absorption,
degrees where a name ends in ``_deg``. Parts that later issues fill in (bump tiles, cap) have
their place here so that the file format already carries them. Labels are complete values:
placement, faces, coefficients and finish regions (their mapping onto the glass is
:mod:`engine.appearance`).
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


#: What a finish region of a label turns its part of the artwork into (optics in
#: :mod:`engine.appearance.presets`): metal foils, clear film that lets the glass show (with or
#: without a white underprint), a relief that bends the normal, a gloss varnish.
FINISH_KINDS = ("gold_foil", "silver_foil", "clear_vinyl", "clear_vinyl_white", "emboss", "varnish")
#: Where a finish region comes from: artwork colours near key colours, or a separate mask image.
REGION_SOURCES = ("chroma", "mask")


@dataclass(frozen=True)
class LabelSide:
    """One face of a label sheet: artwork, or a plain colour.

    ``asset`` names an image embedded in the project (PNG, JPEG, TIFF, EXR; decoded to linear
    RGBA by :mod:`engine.appearance.images`); with ``asset`` ``None`` the face is the plain
    linear-RGB ``color`` (each channel 0..1). Either is multiplied by the label's ``diffuse``.
    """

    asset: str | None = None
    color: RGB = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class FinishRegion:
    """A part of the front artwork with a finish of its own.

    ``source`` ``"chroma"``: the texels whose sRGB colour lies within ``tolerance`` (Euclidean
    distance of sRGB values 0..1) of one of ``keys`` (sRGB 0..1, as an eyedropper reads them);
    ``"mask"``: the texels where the image ``mask_asset`` is inked (dark, as print separations
    are delivered; resampled to the artwork's size). ``finish`` is one of :data:`FINISH_KINDS`;
    ``depth_mm`` is the relief of ``"emboss"`` (mm, negative: debossed) and ``gloss`` (0 matte
    .. 1 mirror) the smoothness of foils, film and varnish. Later regions win where they overlap.
    """

    name: str = "foil"
    finish: str = "gold_foil"
    source: str = "chroma"
    keys: tuple[RGB, ...] = ()
    tolerance: float = 0.1
    mask_asset: str | None = None
    depth_mm: float = 0.0
    gloss: float = 0.9


@dataclass(frozen=True)
class Label:
    """A thin two-sided sheet of paper or film on the outer wall.

    Placement is measured on the surface (mm): ``z_mm`` is the height of the label's centre
    above the standing plane, ``angle_deg`` the azimuth of its centre about +z (world frame,
    from +x towards +y), ``height_mm`` its length along the wall (slant) and ``width_mm`` its
    arc length around the girth at mid-height (on a non-round body the cross-section's
    perimeter). Seen from outside, the front artwork's top is up and it reads left to right
    with increasing azimuth; the back is seen from inside the bottle, the right way round for
    a viewer there (:func:`engine.appearance.decal.back_coordinates`).

    ``diffuse`` (K) multiplies the face colour (artwork decoded from sRGB to linear),
    ``specular`` weights a clear coat, ``transmission`` is the diffuse transmission of the
    sheet; each is 0..1 and ``diffuse + transmission <= 1``. ``regions`` are finish regions of
    the front; the order of ``Design.labels`` is the overlap order (later on top).
    """

    name: str = "label"
    front: LabelSide = field(default_factory=LabelSide)
    back: LabelSide = field(default_factory=LabelSide)
    z_mm: float = 100.0
    angle_deg: float = -90.0
    height_mm: float = 60.0
    width_mm: float = 80.0
    diffuse: float = 0.85
    specular: float = 0.05
    transmission: float = 0.1
    regions: tuple[FinishRegion, ...] = ()

    def asset_names(self) -> tuple[str, ...]:
        """The assets the label refers to (front, back, masks), in that order, each once."""
        names = [self.front.asset, self.back.asset] + [r.mask_asset for r in self.regions]
        return tuple(dict.fromkeys(n for n in names if n is not None))


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
