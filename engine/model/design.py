"""The whole design as one immutable value: what a project file holds and what the tracer renders.

Design rule: every part is a frozen dataclass of plain numbers, strings and tuples, so a
``Design`` hashes, compares by value and can be handed to worker threads as a snapshot. Edits
make a new value with ``dataclasses.replace``; :class:`engine.model.scene.Scene` holds the current
one and tells observers which top-level fields changed. Units: mm, 1/mm for absorption,
degrees where a name ends in ``_deg``. Labels are complete values: placement, faces,
coefficients and finish regions. Bump tiles and the closure are plain numbers too. What they
look like is derived from them (and from the shape: a cap follows the finish, a label lies on
the wall) by :mod:`engine.appearance`.
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
    """A distant light: direction towards the light, colour, ``intensity`` (the irradiance of a
    surface facing it, in the environment's units) and apparent diameter ``angle_deg`` (degrees;
    0 a point at infinity, 0.53 the sun). It lights the diffuse parts (labels, closure, the
    stage's ground) and casts the glass's caustic on the ground; the glass itself shows the
    environment, not these lights."""

    direction: tuple[float, float, float] = (-0.5, -1.0, 1.0)
    color: RGB = (1.0, 1.0, 1.0)
    intensity: float = 1.0
    angle_deg: float = 0.0


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


#: Where a label lies: the bottle's outer wall, or printed on the closure's flat top or on
#: its straight skirt (:mod:`engine.appearance.cap_surfaces`).
LABEL_SURFACES = ("wall", "cap-top", "cap-skirt")


@dataclass(frozen=True)
class Label:
    """A thin two-sided sheet of paper or film on the outer wall, or a print on the closure.

    Placement is measured on the surface (mm) named by ``surface``:

    ``"wall"`` (the default)
        ``z_mm`` is the height of the label's centre above the standing plane, ``angle_deg``
        the azimuth of its centre about +z (world frame, from +x towards +y), ``height_mm``
        its length along the wall (slant) and ``width_mm`` its arc length around the girth at
        mid-height (on a non-round body the cross-section's perimeter).
    ``"cap-skirt"``
        the same on the closure's straight skirt, except that ``z_mm`` is the height of the
        centre above the skirt's lower edge (so the print follows the cap when the neck
        changes).
    ``"cap-top"``
        a flat rectangle ``width_mm x height_mm`` on the closure's top disk, centred at
        ``(cap_x_mm, cap_y_mm)`` from the axis (world x, y), read from azimuth ``angle_deg``:
        its bottom edge faces that way (the default -90 reads upright from the front).

    Seen from outside, the front artwork's top is up and it reads left to right with
    increasing azimuth; the back is seen from inside the bottle, the right way round for
    a viewer there (:func:`engine.appearance.decal.back_coordinates`); a print on the closure
    is seen from outside only (the closure is opaque).

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
    surface: str = "wall"
    cap_x_mm: float = 0.0
    cap_y_mm: float = 0.0

    def asset_names(self) -> tuple[str, ...]:
        """The assets the label refers to (front, back, masks), in that order, each once."""
        names = [self.front.asset, self.back.asset] + [r.mask_asset for r in self.regions]
        return tuple(dict.fromkeys(n for n in names if n is not None))


#: Procedural bump kinds (relief from formulas: smooth at any magnification).
PROCEDURAL_BUMPS = ("knurl", "stipple", "flutes", "facets", "diamond", "thread", "frosted")
#: Bump kinds read from an embedded image (``BumpTile.asset``): a grey height map, the original
#: system's colour code (red = vertical, green:blue = horizontal deviation of the normal), a
#: tangent-space normal map in the OpenGL (green up) or DirectX (green down) convention, and an
#: embossed logo or text (the image's ink raised with a rounded bevel).
IMAGE_BUMPS = ("height_map", "colour_code", "normal_gl", "normal_dx", "emboss")
BUMP_KINDS = PROCEDURAL_BUMPS + IMAGE_BUMPS
#: Where a bump tile lies: the glass's outer surface, or the closure's outer skirt.
BUMP_SURFACES = ("bottle", "cap")
#: How a thread tile is drawn (``BumpTile.geometry``).
THREAD_GEOMETRY = ("auto", "relief", "true")


@dataclass(frozen=True)
class BumpTile:
    """Relief on a band of the outer surface: it bends the shading normal (a thread may instead
    be drawn as true geometry, ``geometry`` below).

    The band runs from height ``z0`` to ``z1`` (mm above z = 0, ``z0 < z1``) all around the
    bottle; the pattern repeats ``repeat`` times around the girth, turned by ``angle_deg``
    about the axis. ``depth`` (mm, >= 0) is the relief's size: cut kinds (``knurl``,
    ``flutes``, ``facets``, ``diamond``) go into the glass, raised kinds (``stipple``,
    ``thread``, image kinds) stand out of it, and ``inverted`` swaps the two (a debossed logo,
    pressed lugs). Meaning of the shape fields per kind (``engine.tracer.tables.bump_rows``):

    ``pitch`` (mm)
        vertical period: knurl and stipple rows (0: square cells), thread pitch (0: from the
        finish standard).
    ``width`` (0..1 of one period)
        flute, dot or groove width; thread: half-width of each flank; knurl: 0 diamond, 1
        straight (vertical ridges); emboss: bevel as a fraction of the band height.
    ``sharpness`` (0..1)
        how crisp ridges, groove bottoms and facet edges are (1: nearly sharp; always rounded
        enough that the normal stays continuous).
    ``alpha``
        ``frosted``: GGX roughness 0.02 (satin) to 0.5 (deep etch).
    ``finish``
        ``thread``: a standard finish ``"28-400"`` (neck size mm - series); ``""`` takes the
        standard size nearest to the neck, series 400.
    ``asset``, ``width_deg``
        image kinds: the embedded image, and the angle one copy spans around the axis
        (360 / repeat or more: the copies tile seamlessly).
    ``on``
        ``"bottle"``: the glass's outer surface, ``z0..z1`` above the standing plane;
        ``"cap"``: the closure's straight skirt, ``z0..z1`` above its lower edge (as a skirt
        print is placed), so the band follows the cap when the finish moves (no cap, or a
        crown, which has no straight skirt: the tile is kept, not drawn; a thread belongs to
        the glass finish, never to the cap).
    ``geometry``
        ``thread``: how it is drawn: ``"relief"`` bends the shading normal only, ``"true"``
        raises the helical ridge as real glass, ``"auto"`` (default) picks by the rule of
        :func:`engine.appearance.threads.thread_rendering` (true geometry when the ridge is
        large relative to the wall). Other kinds ignore it.
    """

    name: str = "bump"
    kind: str = "knurl"
    z0: float = 0.0
    z1: float = 10.0
    repeat: int = 24
    depth: float = 0.3
    angle_deg: float = 0.0
    pitch: float = 0.0
    width: float = 0.5
    sharpness: float = 0.7
    alpha: float = 0.2
    finish: str = ""
    asset: str | None = None
    width_deg: float = 360.0
    inverted: bool = False
    on: str = "bottle"
    geometry: str = "auto"


#: Closure kinds: screw cap with a knurled skirt, crown cork, cork with a capsule, aluminium
#: roll-on pilfer-proof screwcap, lug (twist-off) cap.
CAP_KINDS = ("screw", "crown", "cork", "ropp", "lug")
#: ``metal``: aluminium (a conductor) under a lacquer of ``Cap.color``; ``plastic``: a
#: dielectric over a diffuse base of ``Cap.color``.
CAP_MATERIALS = ("metal", "plastic")


@dataclass(frozen=True)
class Cap:
    """The closure on the finish. It follows the finish: its size comes from the neck's outer
    radius and the mouth's height (:func:`engine.appearance.closures.closure_geometry`), so an
    edit of the neck moves and resizes it. ``color`` is linear RGB in 0..1: the lacquer's tint
    over bare aluminium for metal, the base colour for plastic. ``height`` (mm) is the cap's
    height from its top to the skirt's edge (for a cork: the cork's length) and ``count`` the
    knurl ridges, crown flutes or lugs; 0 takes the kind's standard. ``capsule`` puts a foil
    capsule (of ``material`` and ``color``) over a cork."""

    kind: str = "screw"
    material: str = "plastic"
    color: RGB = (0.9, 0.9, 0.88)
    height: float = 0.0
    count: int = 0
    capsule: bool = True


#: What the bottle stands on: ``none`` (it floats in the environment), ``shadow`` (a shadow
#: catcher: the environment's own background with the bottle's shadow, caustic and reflection
#: on it), ``table`` (a matte surface of ``Stage.color``), ``glossy`` (a riser under a clear
#: coat: acrylic when white, black glass when black), ``mirror`` (a mirror tinted ``color``).
STAGE_KINDS = ("none", "shadow", "table", "glossy", "mirror")
#: The kinds whose sheet rises behind the bottle in a backdrop sweep when ``Stage.backdrop`` is
#: on (a shadow catcher shows the environment there, a mirror's sweep would show nothing useful).
BACKDROP_KINDS = ("table", "glossy")


@dataclass(frozen=True)
class Stage:
    """The ground the bottle stands on, at its standing plane (a hair below ``z = 0``, so no
    two surfaces coincide), and as wide as the scene needs. ``color`` is linear RGB in 0..1 (the
    table's or the riser's base albedo, the mirror's tint); ``gloss`` in 0..1 how sharp a
    glossy riser's coat reflects (1: a mirror-sharp coat). ``backdrop`` raises the table's or
    riser's sheet behind the bottle, as seen from the camera, in a cyclorama sweep (a curve and
    a wall: :func:`engine.tracer.tables.stage.sweep_row`; other kinds keep the flag but draw none). The ground is the square of half-side
    ``half_size_mm`` in the plane ``z = z_mm`` (mm; below 0, where the bottle stands; the SPEC
    ground's numbers by default but wide enough to reach the horizon). The environment's turn
    and strength stay ``Design.environment``'s."""

    kind: str = "none"
    color: RGB = (0.55, 0.55, 0.55)
    gloss: float = 1.0
    backdrop: bool = False
    z_mm: float = -0.05

    @property
    def is_diffuse_ground(self) -> bool:
        """Whether the stage is a diffuse ground (a shadow catcher, a table, a glossy riser's
        base) that the sky and the lights light, so its grids and caustics are worked out; the
        mirror and no stage have none."""
        return self.kind not in ("none", "mirror")

    @property
    def draws_backdrop(self) -> bool:
        """Whether this stage draws its backdrop sweep (on, and a kind of :data:`BACKDROP_KINDS`)."""
        return bool(self.backdrop) and self.kind in BACKDROP_KINDS
    half_size_mm: float = 100000.0


@dataclass(frozen=True)
class Plant:
    """What the glass plant's numbers need beyond the shape (:mod:`engine.plant`), and the
    limits the designer wants warned about. ``proof_pressure_mpa`` is the internal pressure
    (MPa) the membrane stresses are given at (1.2 MPa: the usual proof test of a carbonated
    drink's bottle); ``liquid_density_g_ml`` the liquid's density (g/ml, water 1.0) for the
    filled states' mass; ``closure_mass_g`` the closure's mass (g; 0: not known, not counted)
    and ``label_gsm`` the label stock's grammage (g/m^2; 0: not known, labels not counted).
    The limits warn when a figure passes them, 0 meaning no limit: ``min_tip_deg`` the least
    tip angle (deg), ``max_stress_mpa`` the highest membrane stress (MPa), ``min_glass_mass_g``
    the lowest glass weight (g)."""

    proof_pressure_mpa: float = 1.2
    liquid_density_g_ml: float = 1.0
    closure_mass_g: float = 0.0
    label_gsm: float = 0.0
    min_tip_deg: float = 10.0
    max_stress_mpa: float = 0.0
    min_glass_mass_g: float = 0.0


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
    stage: Stage = field(default_factory=Stage)
    plant: Plant = field(default_factory=Plant)
    name: str = "Untitled"
    notes: str = ""
