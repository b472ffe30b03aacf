"""The plant drawing's page as plain data: curves at true size, dimensions, paper texts.

Design rule: one page, three writers (:mod:`.drawing_write`). Two frames of coordinates meet
here, related by one similarity: **model** millimetres (the bottle's own, every view placed at
true size side by side; what a DXF holds) and **paper** millimetres (origin at the sheet's
lower-left corner, y up; what a PDF or SVG shows): ``paper = origin + scale * model``. Geometry
(outlines, the wall, label bands) lives in model coordinates, so the DXF is 1:1 and the PDF is
exactly to scale; annotation (texts, the table, the frame, the title block) lives in paper
coordinates, so its size on the sheet does not depend on the scale. A dimension is measured
between model points and stands off the geometry by a paper distance.

Layers (DXF) are :data:`LAYERS`; every item names one. Line weights follow ISO 128: thick
(visible outline) :data:`THICK_MM`, thin (dimensions, centre lines, hatch) :data:`THIN_MM`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

#: Sheet sizes, landscape (mm): width, height (ISO 216).
SHEETS = {"A4": (297.0, 210.0), "A3": (420.0, 297.0)}
#: DXF layers and their colours (AutoCAD colour index).
LAYERS = {"OUTLINE": 7, "SECTION": 7, "HATCH": 8, "CENTRE": 1, "LABELS": 3, "DIMENSIONS": 5,
          "TEXT": 7, "FRAME": 7}
#: Line widths (mm on paper): ISO 128 thick and thin lines.
THICK_MM, THIN_MM = 0.5, 0.25
#: Cap height (mm on paper) of ordinary text, dimension text and titles: at least 2.5 mm
#: (ISO 3098), legible on A4 and A3.
TEXT_MM, TITLE_MM, NAME_MM = 2.5, 3.5, 5.0
#: Cap height of DejaVu Sans as a fraction of its em (the font size).
CAP_PER_EM = 0.729
#: Arrowhead length and half-width (mm on paper): closed, filled, about 1:3.
ARROW_MM, ARROW_HALF_MM = 2.5, 0.45
#: Gap between geometry and an extension line, and overshoot past the dimension line (mm).
EXT_GAP_MM, EXT_OVER_MM = 1.0, 1.5
POINTS_PER_MM = 72.0 / 25.4


def em_mm(cap_mm: float) -> float:
    """The font size (em, mm) whose capitals are ``cap_mm`` high."""
    return cap_mm / CAP_PER_EM


@lru_cache(maxsize=4096)
def text_width_mm(text: str, cap_mm: float = TEXT_MM, bold: bool = False) -> float:
    """Width (mm) of ``text`` set in DejaVu Sans with capitals ``cap_mm`` high (the font's own
    advance widths, so layout decisions match what the PDF shows)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath
    if not text:
        return 0.0
    prop = FontProperties(family="DejaVu Sans", weight="bold" if bold else "normal")
    path = TextPath((0, 0), text.replace(" ", "\u00a0"), size=em_mm(cap_mm), prop=prop)
    ext = path.get_extents()
    return float(ext.x1) if math.isfinite(ext.x1) else 0.0


# ------------------------------------------------------------------------- model items
@dataclass(frozen=True)
class SegmentCurve:
    """An engine segment (Line, Arc, EllipseArc or an offset of one) drawn at
    ``(sx * r + dx, z + dy)`` model mm: ``sx`` is +1 or -1 (the left half mirrors)."""

    seg: object
    layer: str
    style: str = "thick"
    sx: float = 1.0
    dx: float = 0.0
    dy: float = 0.0

    def sample(self, n: int = 96) -> np.ndarray:
        """Points (N, 2), model mm: a line's two ends, a curve's ``n + 1`` samples."""
        t = np.array([0.0, 1.0]) if self.seg.kind == "line" else np.linspace(0.0, 1.0, n + 1)
        p = np.asarray(self.seg.point(t), float).reshape(-1, 2)
        return np.column_stack([self.sx * p[:, 0] + self.dx, p[:, 1] + self.dy])


@dataclass(frozen=True)
class Polyline:
    """Straight pieces through ``points`` (model mm); ``fill`` a colour closes and fills it."""

    points: tuple
    layer: str
    style: str = "thick"
    closed: bool = False
    fill: str | None = None

    def sample(self, n: int = 0) -> np.ndarray:
        return np.asarray(self.points, float).reshape(-1, 2)


@dataclass(frozen=True)
class Circle:
    """A circle (model mm)."""

    center: tuple
    radius: float
    layer: str
    style: str = "thick"

    def sample(self, n: int = 256) -> np.ndarray:
        a = np.linspace(0.0, 2.0 * math.pi, n + 1)
        return np.column_stack([self.center[0] + self.radius * np.cos(a),
                                self.center[1] + self.radius * np.sin(a)])


@dataclass(frozen=True)
class Dim:
    """A linear dimension between model points ``p1`` and ``p2`` (mm).

    ``axis`` ``"x"`` measures the horizontal distance, ``"y"`` the vertical one, ``"aligned"``
    the straight distance, ``"radius"`` an arc's radius from its centre ``p1`` to the point
    ``p2`` on it (drawn as a leader from outside the arc; ``offset_mm`` unused). The dimension
    line stands ``offset_mm`` (paper mm, signed) from ``p1`` along the normal: +y for ``"x"``,
    +x for ``"y"``, the left normal of ``p1 -> p2`` for ``"aligned"``. ``tag`` names it for readers (tests, the README): ``"height"``,
    ``"body"``, ``"finish"``, ... The text reads along the dimension line (ISO 129 method 1).
    """

    p1: tuple
    p2: tuple
    axis: str
    offset_mm: float
    text: str
    tag: str = ""

    def direction(self) -> np.ndarray:
        """Unit vector along the dimension line."""
        if self.axis == "x":
            return np.array([1.0, 0.0])
        if self.axis == "y":
            return np.array([0.0, 1.0])
        d = np.subtract(self.p2, self.p1)
        return d / float(np.hypot(*d))

    def normal(self) -> np.ndarray:
        """Unit normal the offset goes along (left of the direction for ``"x"``/aligned)."""
        d = self.direction()
        return np.array([1.0, 0.0]) if self.axis == "y" else np.array([-d[1], d[0]])

    def measured_mm(self) -> float:
        """The measured distance (model mm)."""
        d = np.subtract(self.p2, self.p1)
        return float(abs(d @ self.direction()))


# ------------------------------------------------------------------------- paper items
@dataclass(frozen=True)
class Text:
    """Text on paper: at ``(x, y)`` mm, capitals ``size_mm`` high, anchored ``ha``/``va``
    (matplotlib's names), turned ``rotation`` degrees counter-clockwise."""

    x: float
    y: float
    text: str
    size_mm: float = TEXT_MM
    ha: str = "left"
    va: str = "baseline"
    rotation: float = 0.0
    bold: bool = False
    layer: str = "TEXT"


@dataclass(frozen=True)
class Rule:
    """A straight line on paper (mm): the frame, the table's and title block's rules."""

    p0: tuple
    p1: tuple
    width_mm: float = THIN_MM
    layer: str = "FRAME"


@dataclass
class Page:
    """One sheet: its size and scale, where model (0, 0) lies on paper, and what is drawn."""

    sheet: str
    scale: float
    origin: tuple
    curves: list = field(default_factory=list)
    dims: list = field(default_factory=list)
    texts: list = field(default_factory=list)
    rules: list = field(default_factory=list)

    @property
    def size_mm(self) -> tuple[float, float]:
        return SHEETS[self.sheet]

    def to_paper(self, p) -> np.ndarray:
        """Model points (..., 2) -> paper points (mm)."""
        return np.asarray(self.origin, float) + self.scale * np.asarray(p, float)

    def to_model(self, p) -> np.ndarray:
        """Paper points (..., 2) -> model points (mm): how the DXF places annotation."""
        return (np.asarray(p, float) - np.asarray(self.origin, float)) / self.scale


def scale_text(scale: float) -> str:
    """``1:2``, ``1:2.5``, ``1:1``: a reduction scale as drawings print it."""
    n = 1.0 / scale
    return f"1:{n:g}" if n >= 1 else f"{scale:g}:1"


def parse_scale(text: str) -> float:
    """The scale factor (paper / model) of ``"1:N"`` (``N`` a positive number); ``ValueError``
    with the rule otherwise."""
    parts = str(text).strip().split(":")
    try:
        a, b = (float(p) for p in parts)
    except ValueError:
        raise ValueError(f"a scale is written 1:N (1:1, 1:2, 1:2.5, 1:5), got {text!r}") from None
    if not (a > 0 and b > 0 and math.isfinite(a) and math.isfinite(b)):
        raise ValueError(f"a scale is written 1:N with N > 0, got {text!r}")
    return a / b
