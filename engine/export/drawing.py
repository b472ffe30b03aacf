"""The glass plant's drawing of a design: one landscape sheet (A4 or A3) at a standard scale,
written as PDF, SVG or DXF.

Design rule: this module only *lays out*. The views are :mod:`.drawing_views`' curves at true
size, the figures of the table and the notes are :mod:`.drawing_table`'s words over the trade
numbers and the plant numbers (:func:`engine.plant.sheet.plant_numbers`), the three writers are
:mod:`.drawing_write`'s; here they are placed on one :class:`~.drawing_page.Page`:

    +----------------------------------------------------------+-----------------+
    |  height  +-----+ zones,    +-----+          +---+         | table           |
    |   dim    |half | fill pt.  |side |          |plan|        |  (capacity,     |
    |    |     |sect.|   |       |view |          +---+         |   glass,        |
    |    |     |     |   |       |     |                        |   stability,    |
    |          +-----+           +-----+                        |   stress, ...)  |
    |          body / width      depth                          | notes           |
    |                                                           | title block     |
    +----------------------------------------------------------+-----------------+

The scale is the largest of :data:`SCALES` at which the views and their dimension lanes fit the
drawing area, the plan beside the elevations or, for a squat bottle, above the front view (or
the scale asked for, refused with the sizes when it does not fit). Paper sizes,
margins and lanes are millimetres on paper; geometry is millimetres of the bottle
(``paper = origin + scale * model``). The side view appears only for a non-round plan; an
outline's plan is also measured across flats and corners and by its radii, whose geometry is
:mod:`.drawing_outline`'s. A file is written whole or not at all
(:func:`engine.io.atomic.replacing`).
"""
from __future__ import annotations

import datetime as _dt
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GlassbenchError
from ..io.atomic import replacing
from . import drawing_outline as outline
from . import drawing_table as table
from . import drawing_views as views
from .drawing_page import (EXT_GAP_MM, SHEETS, THICK_MM, TITLE_MM, Dim, Page, Polyline, Rule, Text,
                           parse_scale, scale_text)
from .drawing_write import WRITERS

#: Standard scales (paper / model), largest first (ISO 5455: 2:1, 1:1, 1:2, 1:5, 1:10, 1:20).
SCALES = (2.0, 1.0, 0.5, 0.2, 0.1, 0.05)
#: The frame's margins (mm on paper): 20 on the left for filing, 10 elsewhere (ISO 5457).
FRAME_LEFT_MM, FRAME_MM = 20.0, 10.0
#: Width (mm) of the right-hand column (table, notes, title block) per sheet.
COLUMN_MM = {"A4": 105.0, "A3": 130.0}
#: Spacing of dimension lanes (mm on paper) and the first lane's distance from the geometry.
LANE_MM, FIRST_LANE_MM = 9.0, 10.0
#: Space (mm on paper) between views, and below a view for its title.
GAP_MM, VIEW_TITLE_MM = 14.0, 9.0
#: A view's title's baseline below its lowest dimension line (mm on paper).
TITLE_BELOW_MM = 7.5
#: Space (mm on paper) kept above the elevations for the finish's dimensions.
ABOVE_MM = 2 * LANE_MM + FIRST_LANE_MM - 4.0
#: Space (mm on paper) below a plan stacked above the front view: its dimension and its title.
PLAN_GAP_MM = FIRST_LANE_MM + LANE_MM + VIEW_TITLE_MM


class DrawingError(GlassbenchError, ValueError):
    """A drawing that cannot be made as asked (unknown format or sheet, a scale that does not fit)."""


@dataclass(frozen=True)
class Plan:
    """Where everything goes (model mm unless named ``_mm``/paper): the front view's axis at
    ``x = 0``, the side view's at ``side_dx`` (``None``: no side view), the plan's centre."""

    scale: float
    origin: tuple
    side_dx: float | None
    plan_center: tuple


def write_drawing(design, path, sheet: str = "A3", scale=None, date: str | None = None) -> dict:
    """Write the plant drawing of ``design`` to ``path`` (PDF, SVG or DXF from its suffix).

    ``sheet`` is ``"A4"`` or ``"A3"`` (landscape); ``scale`` ``None`` (the largest standard scale
    that fits), a factor (paper / model) or text ``"1:2"``; ``date`` the title block's (today by
    default). Returns a report: ``path``, ``format``, ``sheet``, ``scale`` (``"1:2"``),
    ``scale_factor``, ``size_mm``, ``views`` (name -> paper bounding box ``[x0, y0, x1, y1]`` mm),
    ``dimensions`` (``tag``, ``text``, ``measured_mm``). Raises :class:`DrawingError` for an
    unknown suffix or sheet or a scale that does not fit, the geometry's errors for an invalid
    design, ``DesignError`` for a bottle drawings do not support yet, ``OSError`` when the file
    cannot be written (an existing file is then untouched).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in WRITERS:
        raise DrawingError(f"a drawing is written as {', '.join(sorted(WRITERS))}; "
                           f"{path.name!r} has {suffix or 'no suffix'}")
    page, boxes = layout(design, sheet, scale, date)
    with replacing(path, suffix=suffix) as tmp:
        WRITERS[suffix](page, tmp)
    return {"path": str(path), "format": suffix[1:], "sheet": sheet, "scale": scale_text(page.scale),
            "scale_factor": page.scale, "size_mm": list(page.size_mm), "views": boxes,
            "dimensions": [{"tag": d.tag, "text": d.text, "measured_mm": d.measured_mm()}
                           for d in page.dims]}


def layout(design, sheet: str = "A3", scale=None, date: str | None = None) -> tuple[Page, dict]:
    """The :class:`~.drawing_page.Page` of ``design`` and its views' paper boxes (see
    :func:`write_drawing` for the arguments and errors)."""
    from ..operations.trade import trade_numbers
    from ..plant.sheet import plant_numbers
    if sheet not in SHEETS:
        raise DrawingError(f"the sheet is one of {', '.join(SHEETS)}, got {sheet!r}")
    shape = design.shape
    shape.xs.require("drawing")  # why first: the trade numbers would pass, the views would not
    fig = views.figures(shape)
    zones = views.label_zones(design)
    trade, plant = trade_numbers(design), plant_numbers(design)
    w, h = SHEETS[sheet]
    col_x0 = w - FRAME_MM - COLUMN_MM[sheet]
    rows = table.table_rows(trade, plant)
    panel = bool(zones) and zones[0].panel   # no label: the clear label panel is shown
    # why: the notes' wording depends on the scale only through "1:N"; size them with the widest
    cut = views.section_words(shape)
    note_lines = table.notes(trade, plant, "1:20", panel, cut)
    in_column = _column_fits(rows, note_lines, col_x0, w, h)
    area_y0 = FRAME_MM + 4.0
    if not in_column:  # the notes go under the views, across the drawing area
        _, last = table.notes_block(note_lines, FRAME_LEFT_MM + 4.0, col_x0 - 4.0, 0.0)
        area_y0 += 2.0 - last
    area = (FRAME_LEFT_MM + 4.0, area_y0, col_x0 - 6.0, h - FRAME_MM - 4.0)
    fill_h = trade.get("fill_height_mm")
    lanes_right = len(zones) + (fill_h is not None)
    placed = _place(fig, not shape.xs.revolved, lanes_right, area, _scale(scale))
    page = Page(sheet, placed.scale, placed.origin)
    _frame(page, col_x0)
    boxes = _views(page, design, fig, placed, zones, fill_h, plant)
    label = scale_text(page.scale)
    note_lines = table.notes(trade, plant, label, panel, cut)
    title = {"name": design.name or "Untitled bottle", "date": date or _dt.date.today().isoformat(),
             "scale": label, "sheet": sheet, "bottom": FRAME_MM}
    col = table.column(rows, note_lines if in_column else [], col_x0 + 4.0, w - FRAME_MM,
                       h - FRAME_MM - 2.0, title)
    if col.bottom < FRAME_MM + table.title_height_mm() + 2.0:  # why: a table that long is a bug
        raise DrawingError(f"the table does not fit the {sheet} sheet's column; use A3")
    page.texts += col.texts
    page.rules += col.rules
    if not in_column:
        texts, _ = table.notes_block(note_lines, FRAME_LEFT_MM + 4.0, col_x0 - 4.0, area_y0 - 2.0)
        page.texts += texts
    return page, boxes


def _column_fits(rows, note_lines, col_x0: float, w: float, h: float) -> bool:
    """Whether the table and the notes fit the column above the title block."""
    title = {"name": "", "date": "", "scale": "", "sheet": "", "bottom": FRAME_MM}
    col = table.column(rows, note_lines, col_x0 + 4.0, w - FRAME_MM, h - FRAME_MM - 2.0, title)
    return col.bottom >= FRAME_MM + table.title_height_mm() + 2.0


# ------------------------------------------------------------------------- scale and places
def _scale(scale) -> float | None:
    if scale is None:
        return None
    try:
        s = parse_scale(scale) if isinstance(scale, str) else float(scale)
    except (TypeError, ValueError) as exc:
        raise DrawingError(str(exc)) from None
    if not (math.isfinite(s) and s > 0):
        raise DrawingError(f"a scale is a positive number or 1:N, got {scale!r}")
    return s


def _needs(fig, side: bool, lanes_right: int, s: float, stacked: bool = False) -> tuple[float, float, float]:
    """Paper mm ``(width, height, left)`` the views take at scale ``s``, dimension lanes included,
    ``left`` from the area's left edge to the front view's axis: the plan beside the elevations,
    or ``stacked`` above the front view (a squat bottle's larger scale)."""
    reach = fig.half_corner or max(fig.half_x, fig.half_y)
    plan_left = FIRST_LANE_MM + LANE_MM if side else 0.0   # the plan's depth dimension
    plan_w = plan_left + 2 * (reach + 4.0) * s + FIRST_LANE_MM + LANE_MM
    left = FIRST_LANE_MM + 6.0 + fig.half_x * s
    elevations = (left + fig.half_x * s + FIRST_LANE_MM + lanes_right * LANE_MM
                  + (GAP_MM + 2 * fig.half_y * s if side else 0.0))
    height = ABOVE_MM + fig.height * s + FIRST_LANE_MM + LANE_MM + VIEW_TITLE_MM
    if not stacked:
        return elevations + GAP_MM + plan_w, height, left
    left = max(left, plan_left + (reach + 4.0) * s + 4.0)
    width = max(elevations - (FIRST_LANE_MM + 6.0 + fig.half_x * s) + left,
                left + (reach + 4.0) * s + FIRST_LANE_MM + LANE_MM)
    return width, height + PLAN_GAP_MM + 2 * (reach + 4.0) * s, left


def _fits(fig, side, lanes_right, s, area) -> bool | None:
    """Whether the views fit ``area`` at scale ``s``: ``False`` (beside), ``True`` (stacked) or
    ``None`` (neither)."""
    aw, ah = area[2] - area[0], area[3] - area[1]
    for stacked in (False, True):
        w, h, _ = _needs(fig, side, lanes_right, s, stacked)
        if w <= aw + 1e-9 and h <= ah + 1e-9:
            return stacked
    return None


def _place(fig, side: bool, lanes_right: int, area, scale: float | None) -> Plan:
    """The scale and the views' places in ``area`` (paper ``x0, y0, x1, y1`` mm): the largest
    of :data:`SCALES` (or ``scale``) at which the plan fits beside the elevations, else above
    the front view."""
    aw, ah = area[2] - area[0], area[3] - area[1]
    if scale is None:
        scale = next((s for s in SCALES if _fits(fig, side, lanes_right, s, area) is not None), None)
        if scale is None:
            raise DrawingError("the bottle is too large for the smallest scale (1:20) of this sheet")
    stacked = _fits(fig, side, lanes_right, scale, area)
    if stacked is None:
        nw, nh, _ = _needs(fig, side, lanes_right, scale)
        raise DrawingError(f"at {scale_text(scale)} the views need {nw:.0f} x {nh:.0f} mm and the "
                           f"sheet gives {aw:.0f} x {ah:.0f} mm; choose a smaller scale or a larger sheet")
    nw, nh, left = _needs(fig, side, lanes_right, scale, stacked)
    s = scale
    x = area[0] + (aw - nw) / 2.0 + left  # the front axis, paper
    y = area[1] + (ah - nh) / 2.0 + VIEW_TITLE_MM + FIRST_LANE_MM + LANE_MM  # the standing plane
    right = fig.half_x * s + FIRST_LANE_MM + lanes_right * LANE_MM + GAP_MM   # axis to next view
    side_dx = None
    if side:
        side_dx = (right + fig.half_y * s) / s
        right += 2 * fig.half_y * s + GAP_MM
    reach = fig.half_corner or max(fig.half_x, fig.half_y)
    plan_left = FIRST_LANE_MM + LANE_MM if side else 0.0   # the plan's depth dimension
    if stacked:  # above the front view, clear of its finish's dimensions
        plan_center = (0.0, fig.height + (ABOVE_MM + PLAN_GAP_MM) / s + reach + 4.0)
    else:
        plan_center = ((right + plan_left + (reach + 4.0) * s) / s, fig.height - reach - 4.0)
    return Plan(s, (x, y), side_dx, plan_center)


def _frame(page: Page, col_x0: float) -> None:
    """The sheet's frame and the rule between the drawing area and the column."""
    w, h = page.size_mm
    x0, y0, x1, y1 = FRAME_LEFT_MM, FRAME_MM, w - FRAME_MM, h - FRAME_MM
    page.rules += [Rule((x0, y0), (x1, y0), THICK_MM), Rule((x1, y0), (x1, y1), THICK_MM),
                   Rule((x1, y1), (x0, y1), THICK_MM), Rule((x0, y1), (x0, y0), THICK_MM),
                   Rule((col_x0, y0), (col_x0, y1))]


# ------------------------------------------------------------------------- views
def _views(page: Page, design, fig, placed: Plan, zones, fill_h, plant) -> dict:
    """Draw and dimension the views; their paper boxes by name."""
    shape = design.shape
    tols = plant.get("tolerances") or {}
    boxes = {"section": _front(page, design, fig, zones, fill_h, tols)}
    if placed.side_dx is not None:
        boxes["side"] = _side(page, shape, fig, placed.side_dx)
    boxes["plan"] = _plan(page, shape, fig, placed.plan_center)
    # why: a title goes below the lowest dimension of its view, not below its geometry
    below = FIRST_LANE_MM + TITLE_BELOW_MM
    reach = fig.half_corner or max(fig.half_x, fig.half_y)
    bottoms = {"section": page.to_paper((0.0, 0.0))[1] - below,
               "side": page.to_paper((0.0, 0.0))[1] - below,
               "plan": page.to_paper((0.0, placed.plan_center[1] - reach - 4.0))[1] - below}
    for name, title in (("section", "Half section"), ("side", "Side view"), ("plan", "Plan, from above")):
        if name in boxes:
            x0, _, x1, _ = boxes[name]
            page.texts.append(Text(0.5 * (x0 + x1), bottoms[name], title, TITLE_MM, "center", bold=True))
    return boxes


def _box(page: Page, curves) -> list[float]:
    pts = page.to_paper(np.concatenate([c.sample() for c in curves]))
    return [float(pts[:, 0].min()), float(pts[:, 1].min()), float(pts[:, 0].max()), float(pts[:, 1].max())]


def _front(page: Page, design, fig, zones, fill_h, tols) -> list[float]:
    """The half view / half section at ``x = 0`` with its dimensions: height (left), body width
    (below), finish and bore (above), label zones and the fill point (right lanes)."""
    shape, s = design.shape, page.scale
    curves = views.half_section(shape, 0.0)
    box = _box(page, curves)
    for z in zones:
        page.curves.append(views.band(shape, z.z0, z.z1, 0.0))
    if fill_h is not None:
        r_in = float(views.reach(shape, np.array([fill_h]), 0.0, "inner")[0])
        page.curves.append(Polyline(((0.0, fill_h), (r_in, fill_h)), "SECTION", "hidden"))
    page.curves += curves
    page.curves.append(views.axis_line(0.0, -3.0 / s, fig.height + 3.0 / s))
    H, rx, top = fig.height, fig.half_x, fig.r_top
    round_ = shape.xs.revolved
    dia = "Ø" if round_ else ""
    page.dims.append(Dim((-fig.ring_x, 0.0), (-top, H), "y", -((rx - fig.ring_x) * s + FIRST_LANE_MM),
                         f"{H:.1f}{table.tol(tols.get('height_mm'))}", "height"))
    lo, hi = fig.span("x")
    body_tol = tols.get("diameter_mm") if round_ else _width_tol(H, lo + hi)
    page.dims.append(Dim((-lo, fig.z_x), (hi, fig.z_x), "x", -(fig.z_x * s + FIRST_LANE_MM),
                         f"{dia}{_mm(lo + hi)}{table.tol(body_tol)}", "body" if round_ else "width"))
    page.dims.append(Dim((-top, H), (top, H), "x", FIRST_LANE_MM + LANE_MM, f"{dia}{2 * top:.1f}", "finish"))
    page.dims.append(Dim((-fig.r_in_top, H), (fig.r_in_top, H), "x", FIRST_LANE_MM - 2.0,
                         f"{dia}{2 * fig.r_in_top:.1f}", "bore"))
    lane_x = rx + FIRST_LANE_MM / s   # model x of the first right lane
    for k, z in enumerate(zones):
        x = lane_x + k * LANE_MM / s
        name = "clear label panel" if z.panel else z.name
        r0, r1 = (float(r) for r in views.reach(shape, np.array([z.z0, z.z1]), 0.0))
        page.dims.append(Dim((r0, 0.0), (r0, z.z0), "y", (x - r0) * s, f"{z.z0:.1f}", f"zone-{k}-bottom"))
        page.dims.append(Dim((r0, z.z0), (r1, z.z1), "y", (x - r0) * s,
                             _named(z.z1 - z.z0, name, s), f"zone-{k}"))
    if fill_h is not None:
        x = lane_x + len(zones) * LANE_MM / s
        page.dims.append(Dim((top, H), (r_in, fill_h), "y", (x - top) * s, _named(H - fill_h, "fill point", s),
                             "fill-point"))
    return box


def _named(length_mm: float, name: str, scale: float) -> str:
    """A dimension's text with what it measures when that fits between its arrows, else the
    number alone (a text carried past a short dimension would run into its neighbours)."""
    from .drawing_page import text_width_mm
    text = f"{length_mm:.1f} {name}"
    return text if text_width_mm(text) + 8.0 <= length_mm * scale else f"{length_mm:.1f}"


def _mm(length_mm: float) -> str:
    """A length (mm) to 0.1 mm, its last bits of rounding dropped first: one length found two
    ways (a side view's depth, the plan's) prints alike even on a half."""
    return f"{round(length_mm, 9):.1f}"


def _width_tol(height_mm: float, width_mm: float) -> float:
    """The ISO 9058 tolerance (mm) of a body width or depth, as of a diameter of that size."""
    from ..plant.rules import dimension_tolerances
    return dimension_tolerances(height_mm, width_mm, None)["diameter_mm"]


def _side(page: Page, shape, fig, dx: float) -> list[float]:
    """The side elevation (a non-round plan's depth) at ``x = dx`` with its depth dimension."""
    s = page.scale
    curves = views.outside_view(shape, "side", dx)
    page.curves += curves
    page.curves.append(views.axis_line(dx, -3.0 / s, fig.height + 3.0 / s))
    lo, hi = fig.span("y")
    page.dims.append(Dim((dx - lo, fig.z_y), (dx + hi, fig.z_y), "x", -(fig.z_y * s + FIRST_LANE_MM),
                         f"{_mm(lo + hi)}{table.tol(_width_tol(fig.height, lo + hi))}", "depth"))
    return _box(page, curves)


def _plan(page: Page, shape, fig, center) -> list[float]:
    """The plan from above at ``center``; a round plan dimensions its standing ring, a
    non-round one its width and depth (and, with corners, the width across them); an outline
    (:func:`_plan_outline`) also across flats and corners and its radii."""
    s = page.scale
    curves = views.plan_view(shape, center)
    page.curves += curves
    cx, cy = center
    box = _box(page, [c for c in curves if c.layer == "OUTLINE" and c.style == "thick"])
    if shape.cross_section == "outline":
        _plan_outline(page, shape, fig, center)
        return box
    if shape.xs.revolved:
        r = fig.ring_x
        page.dims.append(Dim((cx - r, cy), (cx + r, cy), "x", -((fig.half_x + 4.0) * s + FIRST_LANE_MM),
                             f"Ø{2 * r:.1f} ring", "ring"))
        return box
    rx, ry = fig.half_x, fig.half_y
    reach = fig.half_corner or max(rx, ry)
    page.dims.append(Dim((cx - rx, cy), (cx + rx, cy), "x", -((reach + 4.0) * s + FIRST_LANE_MM),
                         f"{2 * rx:.1f}", "plan-width"))
    page.dims.append(Dim((cx, cy - ry), (cx, cy + ry), "y", -((reach + 4.0) * s + FIRST_LANE_MM),
                         f"{2 * ry:.1f}", "plan-depth"))
    if shape.cross_section == "rounded_square" and fig.half_corner is not None:
        # why: across the corners along the anti-diagonal, its line off the top-right corner
        c = fig.half_corner / math.sqrt(2.0)
        page.dims.append(Dim((cx + c, cy - c), (cx - c, cy + c), "aligned",
                             -(fig.half_corner * s + EXT_GAP_MM + 4.0),
                             f"{2 * fig.half_corner:.1f} across corners", "corners"))
    return box


def _plan_outline(page: Page, shape, fig, center) -> None:
    """An outline's plan dimensions (:mod:`.drawing_outline`): width below and depth left, as
    the other kinds', each saying whether it is across flats or corners; across flats or corners
    along their own direction off the upper right; one radius per distinct arc radius."""
    s, (cx, cy) = page.scale, center
    reach = fig.half_corner
    k, c = outline.section_at(shape, fig.z_widest)
    lanes = 0
    for w in outline.plan_widths(shape.plan, k, c):
        lo, hi = (cx + w.lo[0], cy + w.lo[1]), (cx + w.hi[0], cy + w.hi[1])
        text = _mm(w.mm) + (f" across {w.across}" if w.across else "")
        if w.tag == "plan-width":   # why: on the lane of a fixed kind's, whatever the points' y
            line = cy - reach - 4.0 - FIRST_LANE_MM / s
            page.dims.append(Dim(lo, hi, "x", (line - lo[1]) * s, text, w.tag))
        elif w.tag == "plan-depth":
            line = cx - reach - 4.0 - FIRST_LANE_MM / s
            page.dims.append(Dim(lo, hi, "y", (line - lo[0]) * s, text, w.tag))
        else:  # left to right, its line off the upper right beyond the plan's reach
            p1, p2 = (lo, hi) if w.hi[0] - w.lo[0] >= 0 else (hi, lo)
            d = np.subtract(p2, p1) / np.hypot(*np.subtract(p2, p1))
            n = np.array([-d[1], d[0]])
            side = 1.0 if n[0] + n[1] > 0 else -1.0
            stand = reach * s + EXT_GAP_MM + 4.0 + lanes * LANE_MM
            page.dims.append(Dim(p1, p2, "aligned", side * stand - float(np.subtract(p1, center) @ n) * s,
                                 text, w.tag))
            lanes += 1
    for j, r in enumerate(outline.plan_radii(shape.plan, k, c)):
        page.dims.append(Dim((cx + r.centre[0], cy + r.centre[1]), (cx + r.point[0], cy + r.point[1]),
                             "radius", 0.0, f"R{_mm(r.radius)}", f"radius-{j}"))


__all__ = ["DrawingError", "SCALES", "layout", "write_drawing"]
