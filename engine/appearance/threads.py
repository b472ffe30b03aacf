"""How a screw thread is drawn and laid on its band.

Design rule: the finishes themselves (the SPI/GPI table, ``"28-400"``) are design values of
:mod:`engine.model.thread_finishes`; this module holds the two rules that turn a thread tile
into something drawn: :func:`thread_rendering` (relief or true geometry) and
:func:`thread_layout` (pitch, turns and flanks on the band).

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
from dataclasses import dataclass

from ..model.thread_finishes import ThreadSpec, nearest_finish, parse_finish


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
