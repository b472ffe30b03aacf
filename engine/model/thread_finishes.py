"""Screw-thread finishes from the standards: the SPI/GPI table and the names the trade uses.

Design rule: a finish is named as the trade names it, ``"28-400"`` (nominal neck size in mm,
series), and looked up in :data:`FINISHES`; nothing else in glassbench knows thread numbers.
SPI/GPI dimensions are the mid-tolerance values of the published tables (inches converted to
mm): ``T`` the thread's outer diameter, ``E`` the neck's outer diameter under it, ``H`` the
finish height, ``S`` the top of the finish to the first thread, threads per inch. The series
fixes the number of turns (400: 1, 410: 1.5, 415: 2, 425: 2 narrow, 430: 1.5 buttress) and the
ridge profile (half-widths of the lower and upper flank as fractions of the pitch). Rows
marked ``approximate`` (sizes past 33 mm, the 425 and 430 series, the wine and beverage
finishes) are nominal values good for pictures, not for tooling. These are design values (a
tile's ``finish`` names one): how a thread is drawn is :mod:`engine.appearance.threads`'.
"""
from __future__ import annotations

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
