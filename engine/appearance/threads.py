"""Screw-thread finishes from the standards, and when a thread needs true geometry.

Design rule: a finish is named as the trade names it, ``"28-400"`` (nominal neck size in mm,
series), and looked up in :data:`FINISHES`; nothing else in glassbench knows thread numbers.
SPI/GPI dimensions are the mid-tolerance values of the published tables (inches converted to
mm): ``T`` the thread's outer diameter, ``E`` the neck's outer diameter under it, ``H`` the
finish height, ``S`` the top of the finish to the first thread, threads per inch. The series
fixes the number of turns (400: 1, 410: 1.5, 415: 2, 425: 2 narrow, 430: 1.5 buttress) and the
ridge profile (half-widths of the lower and upper flank as fractions of the pitch). Rows
marked ``approximate`` (sizes past 33 mm, the 425 and 430 series, the wine and beverage
finishes) are nominal values good for pictures, not for tooling.

A thread is drawn either as relief (the shading normal bent by :mod:`engine.tracer.kernels.bumps`)
or as true geometry (the helical ridge raised on the neck as glass, :mod:`engine.tracer.kernels.helix`,
the same ridge profile); :func:`thread_rendering` is the one rule that picks, and says why:
``auto`` takes true geometry when the ridge is deeper than :data:`WALL_FRACTION` of the wall.
Measured by ``python -m benchmarks.finishes`` (a 28-400 thread on a 28 mm neck, 1.5 mm wall,
same close view): the relief is off the true helix by 2.9 % of the neck's radiance, 25 % over
the thread's own pixels (silhouette, self-occlusion at grazing view, the path through the
ridge), and the true thread's frame costs about 1.7 x the relief's there.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..errors import DesignError, shown

INCH = 25.4
#: Series: (turns, lower flank, upper flank half-width as fractions of the pitch, approximate).
SERIES = {"400": (1.0, 0.3, 0.3, False), "410": (1.5, 0.3, 0.3, False),
          "415": (2.0, 0.3, 0.3, False), "425": (2.0, 0.22, 0.22, True),
          "430": (1.5, 0.4, 0.12, True), "bvs": (2.5, 0.28, 0.28, True),
          "ropp": (2.5, 0.28, 0.28, True)}
# SPI/GPI table (inches, mid-tolerance): size: (T, E, H400, H410, H415, S, TPI). None: no
# such finish in that series.
_SPI = {13: (.508, .448, None, None, .452, .037, 12), 15: (.575, .515, None, None, .557, .037, 12),
        18: (.696, .612, .371, .523, .617, .037, 8), 20: (.775, .691, .371, .554, .742, .037, 8),
        22: (.854, .770, .371, .585, .837, .037, 8), 24: (.932, .848, .400, .646, .957, .046, 8),
        28: (1.078, .984, .400, .708, 1.082, .046, 6), 30: (1.117, 1.023, .403, None, None, .046, 6),
        33: (1.253, 1.159, .403, None, None, .046, 6)}
# Larger sizes (approximate): size: (T, E) inches; H400 .403 (to 48) or .435, S .046, 6 TPI.
_SPI_LARGE = {38: (1.464, 1.370), 43: (1.642, 1.548), 48: (1.842, 1.748), 53: (2.035, 1.915),
              58: (2.221, 2.101), 63: (2.431, 2.311), 70: (2.714, 2.594), 89: (3.464, 3.344)}
# Wine and beverage finishes (mm, approximate): name: (T, E, H, S, TPI).
_BEVERAGE = {"30-bvs": (29.9, 27.6, 20.0, 2.0, 8.0), "28-ropp": (27.7, 25.5, 18.0, 1.6, 8.0)}


@dataclass(frozen=True)
class ThreadSpec:
    """One standard finish (mm): see the module table."""

    name: str
    t_mm: float
    e_mm: float
    h_mm: float
    s_mm: float
    tpi: float
    turns: float
    flank_low: float
    flank_high: float
    approximate: bool

    @property
    def pitch_mm(self) -> float:
        """Axial distance (mm) between neighbouring turns: 25.4 / threads per inch."""
        return INCH / self.tpi

    @property
    def depth_mm(self) -> float:
        """How far the thread stands off the neck (mm): ``(T - E) / 2``."""
        return 0.5 * (self.t_mm - self.e_mm)


def _spec(size: int, series: str) -> ThreadSpec | None:
    turns, lo, hi, approx = SERIES[series]
    if f"{size}-{series}" in _BEVERAGE:
        t, e, h, s, tpi = _BEVERAGE[f"{size}-{series}"]
        return ThreadSpec(f"{size}-{series}", t, e, h, s, tpi, turns, lo, hi, True)
    if series in ("bvs", "ropp"):
        return None
    if size in _SPI:
        t, e, h400, h410, h415, s, tpi = _SPI[size]
        h = {"400": h400, "410": h410, "415": h415, "425": h415, "430": h410}[series]
        if h is None:
            return None
        return ThreadSpec(f"{size}-{series}", t * INCH, e * INCH, h * INCH, s * INCH, tpi,
                          turns, lo, hi, approx)
    if size in _SPI_LARGE and series in ("400", "430"):
        t, e = _SPI_LARGE[size]
        h = .403 if size <= 48 else .435
        return ThreadSpec(f"{size}-{series}", t * INCH, e * INCH, h * INCH, .046 * INCH, 6.0,
                          turns, lo, hi, True)
    return None


def all_finishes() -> tuple[ThreadSpec, ...]:
    """Every finish in the tables, by size then series."""
    sizes = sorted(set(_SPI) | set(_SPI_LARGE) | {int(k.split("-")[0]) for k in _BEVERAGE})
    found = (_spec(size, series) for size in sizes for series in SERIES)
    return tuple(s for s in found if s is not None)


FINISHES = {s.name: s for s in all_finishes()}


def parse_finish(text: str, where: str = "finish") -> ThreadSpec:
    """The :class:`ThreadSpec` named ``text`` (``"28-400"``, ``"28/410"``, ``"30-bvs"``);
    ``DesignError`` naming ``where`` for anything else."""
    m = re.fullmatch(r"\s*(\d{1,3})\s*[-/]\s*([0-9a-z]{3,4})\s*", str(text).lower())
    spec = FINISHES.get(f"{int(m.group(1))}-{m.group(2)}") if m else None
    if spec is None:
        raise DesignError(f"{where} {shown(text)} is not a finish glassbench knows "
                          f"(e.g. 28-400, 24-410, 38-430, 30-bvs)")
    return spec


def nearest_finish(neck_diameter_mm: float, series: str = "400") -> ThreadSpec:
    """The finish of ``series`` whose neck diameter ``E`` is nearest ``neck_diameter_mm``."""
    options = [s for s in FINISHES.values() if s.name.endswith("-" + series)]
    if not options:
        raise DesignError(f"no finishes in series {shown(series)}")
    return min(options, key=lambda s: abs(s.e_mm - neck_diameter_mm))


@dataclass(frozen=True)
class ThreadRendering:
    """How a thread tile is drawn: ``mode`` ``"relief"`` (the shading normal is bent, the
    wall stays smooth) or ``"true"`` (the helical ridge is real glass); ``reason`` says why,
    in words for the designer. ``depth_mm`` and ``wall_mm`` are the numbers the rule read,
    ``z0``/``z1`` (mm) the band on the wall (``nan`` when the band misses the wall)."""

    mode: str
    reason: str
    depth_mm: float
    wall_mm: float
    z0: float = math.nan
    z1: float = math.nan


#: ``geometry="auto"`` draws a thread as true geometry when its ridge stands off the wall by
#: more than this fraction of the wall's thickness: a normal perturbation keeps the smooth
#: wall's path length through the glass and its silhouette, and both are then visibly wrong.
WALL_FRACTION = 0.5


def thread_rendering(geometry: str, depth_mm: float, wall_mm: float, obstacle: str = "",
                     z0: float = math.nan, z1: float = math.nan) -> ThreadRendering:
    """The one rule for how a thread is drawn: ``geometry`` is the tile's choice (``"auto"``,
    ``"relief"`` or ``"true"``), ``depth_mm`` its ridge, ``wall_mm`` the glass under it and
    ``obstacle`` why true geometry cannot be built there (``""``: it can). ``"auto"`` takes
    true geometry when ``depth_mm > WALL_FRACTION * wall_mm``."""
    ratio = f"{depth_mm:.2f} mm ridge on a {wall_mm:.2f} mm wall"
    if geometry == "relief":
        return ThreadRendering("relief", f"relief, as chosen ({ratio})", depth_mm, wall_mm, z0, z1)
    if obstacle:
        return ThreadRendering("relief", f"relief: true geometry needs {obstacle}", depth_mm, wall_mm, z0, z1)
    if geometry == "true":
        return ThreadRendering("true", f"true geometry, as chosen ({ratio})", depth_mm, wall_mm, z0, z1)
    if depth_mm > WALL_FRACTION * wall_mm:
        return ThreadRendering("true", f"true geometry (auto): {ratio}, more than {WALL_FRACTION:g} of it, "
                               "so a relief would miss its silhouette and the glass light crosses",
                               depth_mm, wall_mm, z0, z1)
    return ThreadRendering("relief", f"relief (auto): {ratio}, at most {WALL_FRACTION:g} of it, "
                           "so bending the normal is faithful", depth_mm, wall_mm, z0, z1)


@dataclass(frozen=True)
class ThreadLayout:
    """Where a thread tile's ridges run on its band (mm): ``pitch``, ``turns`` per start,
    half-widths of the lower and upper flank (fractions of the pitch), the first ridge's
    centre ``start`` above the band's bottom and the run-out at each end (turns)."""

    spec: ThreadSpec
    pitch: float
    turns: float
    flank_low: float
    flank_high: float
    start: float
    runout: float


def thread_layout(tile, band_mm: float, neck_diameter_mm: float) -> ThreadLayout:
    """Lay thread ``tile`` on a band ``band_mm`` long on a neck of ``neck_diameter_mm``.

    The standard is ``tile.finish`` (or the 400 finish nearest the neck); the pitch is
    ``tile.pitch`` or the standard's; the ridge is ``tile.width`` of the pitch wide, split
    between the flanks as the series shapes them (430: a steep upper, load-bearing flank); the
    turns are the series' unless the band is too short for them (then as many as fit).
    """
    spec = parse_finish(tile.finish) if tile.finish else nearest_finish(neck_diameter_mm)
    pitch = tile.pitch if tile.pitch > 0.0 else spec.pitch_mm
    width = min(max(tile.width, 0.05), 0.96)
    share = spec.flank_low / (spec.flank_low + spec.flank_high)
    low, high = min(width * share, 0.48), min(width * (1.0 - share), 0.48)
    starts = max(int(tile.repeat), 1)
    fit = (band_mm / pitch - low - high - 0.1) / starts
    turns = max(0.0, min(spec.turns, fit))
    return ThreadLayout(spec, pitch, turns, low, high, (low + 0.05) * pitch, min(0.15, turns / 3.0))
