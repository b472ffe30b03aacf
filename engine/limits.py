"""Every bound a design, a project file or a command line may take, in one place.

Design rule: a value a user can pass (in a project file, a panel, a DXF drawing or on the
command line) is checked against a bound here before any work starts, and the same bound is
applied when a project is written and when it is read, so glassbench never writes a file it
would then refuse. The bounds are chosen so that anything accepted renders in bounded memory
and time: the sizes of the largest real containers (a demijohn), the image sizes of print work,
and cut-offs that keep the ray tree finite. Units: mm, degrees, pixels, bytes.

:func:`check_range` is the one way a bound is applied: its error names the field and shows the
value and the range, both of bounded length.
"""
from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass
from typing import Mapping

from .errors import DesignError, ProjectError, shown

# ------------------------------------------------------------------------------ text and lists
#: Longest string anywhere in a design (name and notes included), in characters.
MAX_TEXT_CHARS = 100_000
#: Most items in any list of a design (lights, labels, bump tiles, per-segment walls).
MAX_LIST_ITEMS = 4096

# ----------------------------------------------------------------------------------- geometry
#: Most segments in one section (a DXF drawing is refused beyond this, before it is chained).
MAX_SEGMENTS = 1024
#: Largest coordinate (mm) of any segment end point, centre, thickness or cap: 2 m.
MAX_EXTENT_MM = 2000.0
#: Largest arc or ellipse radius (mm): an almost straight arc, a kilometre across.
MAX_RADIUS_MM = 1e6
#: Finest and coarsest chordal tolerance (mm) a tessellation may be asked for.
MIN_TOL_MM = 1e-3
MAX_TOL_MM = 10.0
#: Largest angle (degrees, either way) of a turn about +z (bottle rotation, environment turn).
MAX_TURN_DEG = 360.0

# ---------------------------------------------------------------------------------- materials
IOR_RANGE = (1.0, 5.0)
#: Absorption per RGB channel (1/mm): 1000/mm is opaque within a micrometre.
ABSORPTION_RANGE = (0.0, 1000.0)
#: Glass density (g/cm^3): soda-lime glass is 2.5, lead crystal 3.1, nothing real beyond 30.
DENSITY_RANGE = (0.1, 30.0)

# ------------------------------------------------------------------------- camera and lights
#: Largest distance (mm) of the camera's eye or target from the origin: 1 km.
MAX_CAMERA_MM = 1e6
#: Nearest the eye may be to its target (mm).
MIN_VIEW_DISTANCE_MM = 1e-3
#: Vertical field of view (degrees); 0 and 180 are no picture at all.
FOV_RANGE = (0.1, 170.0)
#: Smallest sine of the angle between the up vector and the viewing direction.
MIN_UP_SINE = 1e-6
#: Environment radiance scale; with :data:`MAX_TEXEL` it keeps radiance far below float32's
#: largest value (3.4e38) even summed over every sample of a pixel.
ENV_SCALE_RANGE = (0.0, 1e6)
LIGHT_INTENSITY_RANGE = (0.0, 1e6)
#: A light's apparent diameter (degrees): a point to a wide soft box.
LIGHT_ANGLE_RANGE = (0.0, 90.0)
LIGHT_COLOR_RANGE = (0.0, 1e3)

# ------------------------------------------------------------------------------- environment
#: Most texels (width x height) of an environment image: 8192 x 4096.
MAX_ENV_TEXELS = 1 << 25
#: Largest texel value kept; brighter texels (and +Inf) are clipped to it.
MAX_TEXEL = 1e9

# ------------------------------------------------------------------------------------ labels
#: Label height (slant) and width (girth arc) in mm: a millimetre-wide strip up to 2 m.
LABEL_SIZE_RANGE_MM = (1.0, MAX_EXTENT_MM)
#: Label coefficients (diffuse K, specular coat, diffuse transmission) and face colours
#: (linear RGB): fractions of the light; ``diffuse + transmission`` may not exceed 1 either.
LABEL_COEFFICIENT_RANGE = (0.0, 1.0)
LABEL_COLOR_RANGE = (0.0, 1.0)
#: Chroma-key tolerance: Euclidean distance of sRGB values (0..1 each); 1 keys most colours.
KEY_TOLERANCE_RANGE = (0.0, 1.0)
#: Most finish regions per label (region maps are uint8: 0 is plain paper) and key colours
#: per region.
MAX_LABEL_REGIONS = 32
MAX_KEY_COLORS = 16
#: Emboss relief (mm; negative: debossed) and finish gloss (0 matte .. 1 mirror).
EMBOSS_DEPTH_RANGE_MM = (-2.0, 2.0)
GLOSS_RANGE = (0.0, 1.0)
#: Artwork and mask images: bytes of one file, texels of one image (4096 x 4096, 256 MB as
#: linear float32 RGBA), its longest side, its shortest side (a 1 x 1 image is a plain colour:
#: give the colour), and texels of all label images of one design together.
MAX_ARTWORK_BYTES = 64 << 20
MAX_ARTWORK_TEXELS = 1 << 24
MAX_ARTWORK_SIDE = 16384
MIN_ARTWORK_SIDE = 2
MAX_DESIGN_ARTWORK_TEXELS = 1 << 25
#: Strain paper takes before it wrinkles or lifts (0.5 %): more is a warning, with where.
PAPER_STRAIN = 0.005
#: Most grid nodes along either side of a label's decal (its (s, t) table for the tracer).
MAX_DECAL_NODES = 256
# ------------------------------------------------------------------- bump tiles and closures
#: Deepest relief (mm) of a bump tile: deeper relief than this is geometry, not a finish.
MAX_BUMP_DEPTH_MM = 10.0
#: Pattern repeats around the girth (knurl grooves, flutes, facets, dots, image copies).
BUMP_REPEAT_RANGE = (1, 4096)
#: Microfacet roughness of frosted or satin glass (GGX alpha): 0.02 satin .. 0.5 deep etch.
GGX_ALPHA_RANGE = (0.02, 0.5)
#: Texels of a relief image (height, colour-code or normal map): 2048 x 2048 float texels
#: (48 MB as slopes); a larger image is refused from its header, before it is decoded.
MAX_RELIEF_TEXELS = 1 << 22
#: Longest side (texels) of a relief image, and the smallest (a map needs a neighbourhood).
RELIEF_SIDE_RANGE = (2, 8192)
#: Height of a closure above or along the finish (mm); 0 asks for the kind's standard size.
CAP_HEIGHT_RANGE = (0.0, 300.0)
#: Ridges, flutes or lugs on a closure; 0 asks for the kind's standard count.
CAP_COUNT_RANGE = (0, 720)
#: Lugs of a lug cap (twist-off), when given.
CAP_LUGS_RANGE = (2, 8)

# ------------------------------------------------------------------------------------- render
WIDTH_RANGE = (1, 16384)
HEIGHT_RANGE = (1, 16384)
#: Most pixels in one image (4096 x 4096): the film then needs about 1 GB.
MAX_PIXELS = 1 << 24
SPP_RANGE = (1, 1 << 16)
#: Boundaries a branch of the ray tree may cross; the deepest oracle renders use 256.
MAX_DEPTH_RANGE = (1, 1024)
#: Branch weight cut-off. Each level of the tree holds at most ``1 / min_weight`` branches
#: (weights split, never grow), so one camera sample traces at most ``max_depth / min_weight``
#: rays; 0 would never stop. On the Bordeaux sample (8 x 8 px, 1 spp) 1e-3 traces 45 rays per
#: pixel, 1e-5 (the deepest benchmark) 3,100 and 1e-6 150,000 (``python -m benchmarks.hostile``).
MIN_WEIGHT_RANGE = (1e-5, 1.0)


def check_range(field: str, value, bounds, unit: str = "", integer: bool = False) -> None:
    """Raise ``DesignError`` unless ``bounds[0] <= value <= bounds[1]`` (and ``value`` is finite).

    Parameters
    ----------
    field : str
        What the value is, as the user knows it (``design.render.spp``, ``--width``).
    value : int or float
        The value to check (ints are compared exactly, never converted to float).
    bounds : (lo, hi)
        Inclusive bounds.
    unit : str
        Shown after the range (``mm``, ``deg``).
    integer : bool
        The value must also be a whole number (an ``int``, not ``True``).
    """
    lo, hi = bounds
    kind = numbers.Integral if integer else numbers.Real
    ok = isinstance(value, kind) and not isinstance(value, bool)
    if ok and not integer:
        ok = math.isfinite(float(value))
    if not ok or not lo <= value <= hi:
        suffix = f" {unit}" if unit else ""
        raise DesignError(f"{field} = {shown(value)} is outside {lo:g}..{hi:g}{suffix}")


def check_image_size(width: int, height: int, spp: int, where: str = "design.render.") -> None:
    """Check an image size (pixels) and sample count against the render bounds.

    ``where`` prefixes the field names: ``design.render.`` for a project, ``--`` for the
    command line, so the message names what the user typed.
    """
    check_range(f"{where}width", width, WIDTH_RANGE, "px", integer=True)
    check_range(f"{where}height", height, HEIGHT_RANGE, "px", integer=True)
    check_range(f"{where}spp", spp, SPP_RANGE, integer=True)
    if width * height > MAX_PIXELS:
        raise DesignError(f"{where}width x {where}height = {width} x {height} is more than "
                          f"{MAX_PIXELS} pixels")


#: Asset names: plain file names (spaces and non-ASCII letters allowed) of at most 128
#: characters: no folder separators, colons or control characters, no leading dot.
ASSET_NAME = re.compile(r"^[^/\\:.\x00-\x1f\x7f][^/\\:\x00-\x1f\x7f]{0,127}\Z")


@dataclass(frozen=True)
class Limits:
    """Size limits of a project archive (bytes unless named otherwise), applied when it is
    written and when it is read; the design's own limits are in :mod:`engine.limits`.

    ``archive_bytes`` the file; ``members`` entries in it; ``json_bytes`` ``project.json``;
    ``asset_bytes`` one asset; ``total_bytes`` everything unpacked; ``json_depth`` nesting of
    ``project.json``; ``unpack_ratio``: beyond ``json_bytes``, the members may unpack to at most
    this many times the archive's size (a small file cannot claim much memory).
    """

    archive_bytes: int = 512 << 20
    members: int = 256
    json_bytes: int = 16 << 20
    asset_bytes: int = 256 << 20
    total_bytes: int = 512 << 20
    json_depth: int = 64
    unpack_ratio: int = 100


DEFAULT_LIMITS = Limits()


def check_assets(assets: Mapping[str, bytes], limits: Limits = DEFAULT_LIMITS) -> None:
    """Raise ``ProjectError`` unless ``assets`` could be stored: at most ``limits.members - 1``
    of them, plain file names (:data:`ASSET_NAME`), bytes of at most ``limits.asset_bytes``."""
    if len(assets) >= limits.members:
        raise ProjectError(f"a project holds at most {limits.members - 1} assets")
    for name, data in assets.items():
        if not isinstance(name, str) or not ASSET_NAME.match(name):
            raise ProjectError(f"asset name {shown(name)} is not a plain file name")
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise ProjectError(f"asset {shown(name)} must be bytes, got {type(data).__name__}")
        if len(data) > limits.asset_bytes:
            raise ProjectError(f"asset {shown(name)} is larger than {limits.asset_bytes} bytes")
