"""The rules a glass plant quotes: the capacity band, the marking, the dimension tolerances.

Design rule: each figure comes with the rule it follows, spelled once here, so the trade panel,
``info --json`` and the drawing's notes cite the same text.

* **Capacity** (:func:`capacity_tolerance_ml`): the maximum permissible error of a measuring
  container bottle's nominal capacity, Council Directive 75/107/EEC, Annex I (the same table
  ISO 9058 takes over, and OIML R 138 for measuring container bottles): 50-100 ml +-3 ml,
  100-200 ml +-3 %, 200-300 ml +-6 ml, 300-500 ml +-2 %, 500-1000 ml +-10 ml, 1-5 l +-1 %.
  The table is continuous at its joints (3 % of 100 ml is 3 ml, ...), so a capacity on a joint
  has one tolerance. Outside 50 ml - 5 l the directive does not apply: ``None``.
* **The fill-height range** (:func:`capacity_band`): the heights at which the bottle holds the
  nominal volume less and plus that error; the filler's level must stay inside it.
* **Marking** (:func:`marking`): 75/107/EEC Annex I, 5: the nominal capacity, and the distance in
  mm from the brim to the fill level (or the brimful capacity in cl), with the reversed epsilon
  of a measuring container bottle.
* **Height and diameter** (:func:`dimension_tolerances`): ISO 9058 (after CETIE's data sheet DT 2)
  for bottles: height +-(0.6 + 0.004 H) mm, body diameter +-(0.5 + 0.012 D) mm. ISO 9058 is for
  round bottles; for a non-round plan its diameter rule is applied to the widest width, as an
  estimate (ISO 12818 covers flaconnage widths).
Units: ml, mm.
"""
from __future__ import annotations

from ..geometry import capacity

CAPACITY_RULE = "75/107/EEC Annex I (maximum permissible error of the nominal capacity)"
MARKING_RULE = "75/107/EEC Annex I, 5 (OIML R 138): nominal capacity, brim-to-fill distance, reversed epsilon"
HEIGHT_RULE = "ISO 9058: +-(0.6 + 0.004 H) mm"
DIAMETER_RULE = "ISO 9058: +-(0.5 + 0.012 D) mm"
#: The measuring container bottle's mark (a reversed epsilon).
MEASURING_MARK = "\u03f6"

#: ``(from ml, to ml, tolerance, "ml" | "%")`` rows of 75/107/EEC Annex I.
CAPACITY_TABLE = ((50.0, 100.0, 3.0, "ml"), (100.0, 200.0, 3.0, "%"), (200.0, 300.0, 6.0, "ml"),
                  (300.0, 500.0, 2.0, "%"), (500.0, 1000.0, 10.0, "ml"), (1000.0, 5000.0, 1.0, "%"))


def capacity_tolerance_ml(nominal_ml: float) -> float | None:
    """The maximum permissible error (ml, +-) of a nominal capacity under 75/107/EEC, or
    ``None`` outside the directive's 50 ml - 5 l."""
    for lo, hi, value, unit in CAPACITY_TABLE:
        if lo <= nominal_ml <= hi:
            return value if unit == "ml" else value * nominal_ml / 100.0
    return None


def capacity_band(shape, nominal_ml: float) -> dict | None:
    """The band of 75/107/EEC around ``nominal_ml`` and the fill heights (mm above the standing
    plane) and fill points (mm below the brim) it allows; a bound the bottle cannot hold is
    ``None``. ``None`` when the directive does not apply."""
    tol = capacity_tolerance_ml(nominal_ml)
    if tol is None:
        return None
    brimful = capacity.brimful_ml(shape)

    def height(ml):
        return capacity.fill_height_for_volume(shape, ml) if 0.0 < ml <= brimful else None

    lo, hi = height(nominal_ml - tol), height(nominal_ml + tol)
    return {"nominal_ml": float(nominal_ml), "tolerance_ml": float(tol), "rule": CAPACITY_RULE,
            "fill_height_min_mm": lo, "fill_height_max_mm": hi,
            "fill_point_min_mm": None if hi is None else shape.z_top - hi,
            "fill_point_max_mm": None if lo is None else shape.z_top - lo}


def marking(shape, nominal_ml: float, fill_height_mm: float) -> dict:
    """The bottle's marking: nominal capacity (cl when whole, else ml), the fill point (mm below
    the brim) and the measuring mark, as one text (``75 cl  62 mm  ϶``)."""
    brimful = capacity.brimful_ml(shape)
    point = shape.z_top - fill_height_mm
    cl = nominal_ml / 10.0
    volume = f"{cl:g} cl" if abs(cl - round(cl, 1)) < 1e-9 else f"{nominal_ml:.0f} ml"
    return {"nominal_ml": float(nominal_ml), "brimful_ml": float(brimful), "fill_point_mm": float(point),
            "text": f"{volume}  {point:.0f} mm  {MEASURING_MARK}", "rule": MARKING_RULE}


def dimension_tolerances(height_mm: float, diameter_mm: float, nominal_ml: float | None) -> dict:
    """The +- tolerances (mm, ml) on height, body diameter and capacity, with their rules."""
    return {"height_mm": 0.6 + 0.004 * height_mm, "diameter_mm": 0.5 + 0.012 * diameter_mm,
            "capacity_ml": None if nominal_ml is None else capacity_tolerance_ml(nominal_ml),
            "rules": {"height": HEIGHT_RULE, "diameter": DIAMETER_RULE, "capacity": CAPACITY_RULE}}
