"""The plant drawing's words: the table of figures, the notes and the title block, on paper.

Design rule: every figure printed comes from the trade numbers
(:func:`engine.operations.trade.trade_numbers`) or the plant numbers
(:func:`engine.plant.sheet.plant_numbers`) as handed in; nothing is computed here but the
layout. A part of the plant numbers that is ``None`` (a figure that could not be computed, a
design with no liquid) prints a dash, never a guess. A rule is quoted in the words the plant
numbers give it. Layout is in paper mm inside a column ``[x0, x1]``: the table from the top
down, the notes below it, the title block at the foot; text widths are measured in the font
the PDF embeds (:func:`.drawing_page.text_width_mm`) so nothing runs past the column.
"""
from __future__ import annotations

from dataclasses import dataclass

from .drawing_page import NAME_MM, TEXT_MM, THICK_MM, THIN_MM, TITLE_MM, Rule, Text, text_width_mm

DASH = "-"
#: Line pitch as a multiple of the cap height.
PITCH = 1.75
#: Title block rows' heights (mm): the name, the cells, the foot.
TITLE_ROWS_MM = (12.0, 11.0, 7.0)
#: Stability columns: title, key of a state, digits.
STATE_COLUMNS = (("State", "state", None), ("Mass g", "mass_g", 1), ("CG z mm", "cg_z_mm", 1),
                 ("Tip °", "tip_deg", 1), ("Frozen °", "tip_frozen_deg", 1))


def num(value, digits: int = 1, unit: str = "") -> str:
    """``value`` with ``digits`` decimals and its unit, or a dash for ``None``."""
    if value is None:
        return DASH
    text = f"{float(value):.{digits}f}"
    return f"{text} {unit}" if unit else text


def tol(value, digits: int = 1) -> str:
    """`` ±1.6`` (a leading space) for a tolerance, ``""`` for ``None``."""
    if value is None:
        return ""
    digits = digits if float(value) >= 0.1 else 2
    return f" ±{float(value):.{digits}f}"


def _get(d, *keys):
    """``d[k0][k1]...`` or ``None`` where any part is missing or ``None``."""
    for k in keys:
        if not isinstance(d, dict) or d.get(k) is None:
            return None
        d = d[k]
    return d


# ------------------------------------------------------------------------- contents
def table_rows(trade: dict, plant: dict | None) -> list:
    """The table as rows: ``("head", title)``, ``("row", label, value)``, ``("states", rows)``."""
    p = plant or {}
    band, ratio = p.get("capacity_band"), p.get("weight_to_capacity")
    rows = [("head", "Capacity"),
            ("row", "Brimful capacity", num(trade.get("brimful_ml"), 1, "ml"))]
    nominal = _get(band, "nominal_ml") if band else trade.get("fill_ml")
    rows.append(("row", "Nominal capacity", num(nominal, 1, "ml") + (tol(_get(band, "tolerance_ml")) + " ml" if band else "")))
    rows.append(("row", "Fill point below brim", num(trade.get("fill_point_below_top_mm"), 1, "mm")))
    if band:
        rows.append(("row", "  within tolerance", f"{num(band.get('fill_point_min_mm'))} .. {num(band.get('fill_point_max_mm'), 1, 'mm')}"))
    rows.append(("row", "Fill height", num(trade.get("fill_height_mm"), 1, "mm")))
    if band:
        rows.append(("row", "  within tolerance", f"{num(band.get('fill_height_min_mm'))} .. {num(band.get('fill_height_max_mm'), 1, 'mm')}"))
    rows += [("head", "Glass"),
             ("row", "Glass weight", num(trade.get("glass_mass_g"), 1, "g")),
             ("row", "Glass volume", num(trade.get("glass_volume_cm3"), 1, "cm³")),
             ("row", "Weight to capacity", DASH if not ratio else
              f"{num(ratio.get('ratio_g_per_ml'), 3, 'g/ml')} ({ratio.get('basis', '')})")]
    rows += [("head", "Stability"), ("states", p.get("states") or [])]
    least = p.get("least_tip")
    rows.append(("row", "Least tip angle", DASH if not least else
                 f"{num(least.get('deg'), 1, '°')} ({least.get('state', '')}, towards {num(least.get('direction_deg'), 0, '°')})"))
    ring = p.get("ring")
    if ring:
        rows.append(("row", "Standing ring", f"Ø{num(2 * ring['radius_mm'], 1, 'mm')}"
                     if ring.get("radius_mm") is not None else
                     f"edge {num(ring.get('least_mm'), 1, 'mm')} from the axis at least"))
    stress = p.get("stress")
    rows.append(("head", f"Membrane stress at {num(_get(stress, 'pressure_mpa'), 2, 'MPa')}"))
    rows += [("row", "Max hoop", num(_get(stress, "max_hoop_mpa"), 2, "MPa")),
             ("row", "Max meridional", num(_get(stress, "max_meridional_mpa"), 2, "MPa"))]
    where = _get(stress, "max_at_z_mm")
    rows.append(("row", "Highest", DASH if _get(stress, "max_mpa") is None else
                 f"{num(stress['max_mpa'], 2, 'MPa')} {stress.get('max_kind') or ''}"
                 + (f" at z = {num(where, 1, 'mm')}" if where is not None else "")))
    marking = p.get("marking")
    rows += [("head", "Marking"), ("row", "On the bottle", _get(marking, "text") or DASH)]
    return rows


def notes(trade: dict, plant: dict | None, scale_label: str, panel: bool,
          cut: str = "cut through the axis") -> list[str]:
    """The drawing's notes, in order: units and views (``cut``: how the section's right half
    is cut), each tolerance with its rule, the stress figures' note, what the band shown is
    (``panel``: the clear label panel of a design without labels), the plant numbers' warnings."""
    p = plant or {}
    tols = p.get("tolerances") or {}
    rules = tols.get("rules") or {}
    out = [f"Dimensions in mm, scale {scale_label}. Section: left half outside view, right half "
           f"{cut}, the glass wall filled.",
           f"Height tolerance{tol(tols.get('height_mm')) or ' ' + DASH} mm: {rules.get('height', DASH)}.",
           f"Diameter tolerance{tol(tols.get('diameter_mm')) or ' ' + DASH} mm: {rules.get('diameter', DASH)}."]
    band = p.get("capacity_band")
    cap_tol = tols.get("capacity_ml") if tols.get("capacity_ml") is not None else _get(band, "tolerance_ml")
    out.append(f"Capacity tolerance{tol(cap_tol) or ' ' + DASH} ml: "
               f"{rules.get('capacity') or _get(band, 'rule') or DASH}.")
    marking = p.get("marking")
    if marking and marking.get("rule"):
        out.append(f"Marking: {marking['rule']}.")
    if _get(p, "stress", "note"):
        out.append(f"Stress: {p['stress']['note'].rstrip('.')}.")
    if panel:
        out.append("No label in the design: the band shown is the body's longest straight part.")
    out.append("Dimensions without a tolerance are for reference.")
    out += [f"Warning: {w}" for w in p.get("warnings") or ()]
    return out


# ------------------------------------------------------------------------- layout
@dataclass
class Column:
    """Paper items of the right-hand column and the lowest y (mm) its table and notes reach."""

    texts: list
    rules: list
    bottom: float


def wrap(text: str, width_mm: float, cap_mm: float = TEXT_MM) -> list[str]:
    """``text`` broken at spaces into lines no wider than ``width_mm`` (a word longer than the
    width is cut with an ellipsis)."""
    lines, line = [], ""
    for word in text.split():
        trial = f"{line} {word}".strip()
        if line and text_width_mm(trial, cap_mm) > width_mm:
            lines.append(line)
            trial = word
        line = trial
    if line:
        lines.append(line)
    return [_fit(s, width_mm, cap_mm) for s in lines]


def _fit(text: str, width_mm: float, cap_mm: float = TEXT_MM, bold: bool = False) -> str:
    """``text`` cut with an ellipsis to at most ``width_mm``."""
    if text_width_mm(text, cap_mm, bold) <= width_mm:
        return text
    while text and text_width_mm(text + "…", cap_mm, bold) > width_mm:
        text = text[:-1]
    return text + "…"


def column(rows, note_lines, x0: float, x1: float, top: float, title: dict) -> Column:
    """Lay the table, the notes (none: ``[]``) and the title block out in the column ``x0..x1``
    (paper mm) from ``top`` down; the title block sits on ``title["bottom"]``."""
    texts, rules, pitch = [], [], PITCH * TEXT_MM
    y, width, value_x = top, x1 - x0, x0 + 0.42 * (x1 - x0)
    for row in rows:
        if row[0] == "head":
            y -= pitch * 1.25
            texts.append(Text(x0, y, _fit(row[1], width, bold=True), bold=True))
            rules.append(Rule((x0, y - 1.2), (x1, y - 1.2)))
        elif row[0] == "row":
            y -= pitch
            texts.append(Text(x0, y, _fit(row[1], value_x - x0 - 2.0)))
            texts.append(Text(value_x, y, _fit(row[2], x1 - value_x)))
        else:
            y = _states(row[1], texts, x0, x1, y)
    if note_lines:
        note_texts, y = notes_block(note_lines, x0, x1, y - pitch * 0.5)
        texts += note_texts
    tb_texts, tb_rules = title_block(x0, x1, title)
    return Column(texts + tb_texts, rules + tb_rules, y - 1.0)


def notes_block(note_lines, x0: float, x1: float, top: float) -> tuple[list, float]:
    """The numbered notes under a "Notes" heading, wrapped to ``x0..x1`` from ``top`` down
    (paper mm); the texts and the last baseline (mm)."""
    texts, pitch = [], PITCH * TEXT_MM
    y = top - pitch
    texts.append(Text(x0, y, "Notes", bold=True))
    for i, note in enumerate(note_lines, 1):
        for j, line in enumerate(wrap(note, x1 - x0 - 6.0)):
            y -= pitch
            if j == 0:
                texts.append(Text(x0, y, f"{i}."))
            texts.append(Text(x0 + 6.0, y, line))
    return texts, y


def _states(states, texts, x0: float, x1: float, y: float) -> float:
    """The per-state stability rows (a small table); returns the new baseline (mm)."""
    pitch = PITCH * TEXT_MM
    xs = [x0 + f * (x1 - x0) for f in (0.0, 0.22, 0.42, 0.64, 0.82)]
    y -= pitch
    for x, (title, _, _) in zip(xs, STATE_COLUMNS):
        texts.append(Text(x, y, title))
    if not states:
        y -= pitch
        texts.append(Text(x0, y, DASH))
    for state in states:
        y -= pitch
        for x, (_, key, digits) in zip(xs, STATE_COLUMNS):
            v = state.get(key)
            texts.append(Text(x, y, str(v) if digits is None else num(v, digits)))
    return y


def title_block(x0: float, x1: float, title: dict) -> tuple[list, list]:
    """The title block (ISO 7200's essentials) on ``title["bottom"]``: the design's name; date,
    units, scale and sheet; the program. ``title`` holds ``name``, ``date``, ``scale``,
    ``sheet``, ``bottom``."""
    h_name, h_cells, h_foot = TITLE_ROWS_MM
    y0 = title["bottom"]
    y1, y2, y3 = y0 + h_foot, y0 + h_foot + h_cells, y0 + h_foot + h_cells + h_name
    rules = [Rule((x0, y), (x1, y), THICK_MM if y in (y0, y3) else THIN_MM) for y in (y0, y1, y2, y3)]
    rules += [Rule((x, y0), (x, y3), THICK_MM) for x in (x0, x1)]
    texts = [Text(x0 + 2.5, y2 + 3.5, _fit(title["name"], x1 - x0 - 5.0, NAME_MM, True), NAME_MM, bold=True)]
    cells = (("Date", title["date"]), ("Units", "mm"), ("Scale", title["scale"]),
             ("Sheet", title["sheet"]))
    cw = (x1 - x0) / len(cells)
    for i, (head, value) in enumerate(cells):
        cx = x0 + i * cw
        if i:
            rules.append(Rule((cx, y1), (cx, y2)))
        texts.append(Text(cx + 2.0, y2 - 4.0, head))
        texts.append(Text(cx + 2.0, y1 + 2.0, _fit(value, cw - 3.0, TEXT_MM, True), bold=True))
    texts.append(Text(x0 + 2.5, y0 + 2.3, "glassbench", TEXT_MM, bold=True))
    texts.append(Text(x1 - 2.5, y0 + 2.3, "glass container drawing", ha="right"))
    return texts, rules


def title_height_mm() -> float:
    """Height (mm) of the title block."""
    return float(sum(TITLE_ROWS_MM))


__all__ = ["column", "notes", "notes_block", "table_rows", "title_block", "title_height_mm", "wrap", "TITLE_MM"]
