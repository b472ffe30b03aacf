"""The designer's words for the engine's names: what the window shows instead of raw keys.

Design rule: the engine and the project file speak in keys (``rounded_square``, ``u``,
``ellipse_arc``, ``ccw``); the window shows these words and keeps the key as the item's data,
so a combo box or a table cell always hands the engine its key. Every name the interface shows
comes from here, with the tooltip that explains it.
"""
from __future__ import annotations

from PySide6.QtCore import QSignalBlocker, Qt

CROSS_SECTIONS = {
    "round": ("Round", "One section turned about the axis"),
    "rounded_square": ("Rounded square", "A square with rounded corners: two sections, across "
                                         "the flats (u) and across the corners (v)"),
    "rounded_rect": ("Rounded rectangle", "Half width, half depth and corner radius, each a section"),
    "oval": ("Oval", "An ellipse at every height: half width and half depth, each a section"),
    "outline": ("Plan outline", "A free convex plan outline, scaled by the core section and rounded "
                                "by the rounding section (read from a SPEC_outline scene)"),
}

SECTIONS = {
    "profile": ("Profile", "The bottle's one section, from the base centre to the mouth"),
    "u": ("u \u2014 across the flats", "Half width of the rounded square across its flat sides "
                                      "(at 0\u00b0, along x)"),
    "v": ("v \u2014 across the corners", "Radius of the rounded square across its corners "
                                        "(on the diagonal, at 45\u00b0)"),
    "half_width": ("Half width (x)", "Half the width, along x"),
    "half_depth": ("Half depth (y)", "Half the depth, along y"),
    "corner": ("Corner radius", "Radius of the rounded corners"),
    "core": ("Core scale", "How large the plan outline is at each height (mm from the axis to its "
                           "farthest point; 0 where the neck is round)"),
    "round": ("Rounding", "The radius the plan outline is rounded by at each height"),
}

SEGMENT_KINDS = {
    "line": ("Line", "A straight segment"),
    "arc": ("Arc", "A circular arc"),
    "ellipse_arc": ("Ellipse arc", "An arc of an ellipse with radii along r and z"),
}

DIRECTIONS = {
    "ccw": ("convex", "Bulges outwards (counter-clockwise in the r-z plane)"),
    "cw": ("concave", "Curves inwards (clockwise in the r-z plane)"),
}

FILL_MODES = {
    "height": ("Height (mm)", "The liquid's surface at a height above the standing plane"),
    "volume": ("Volume (ml)", "A volume of liquid; its height follows from the cavity"),
}

ENVIRONMENTS = {
    "studio": ("Studio", "The built-in studio light"),
    "file": ("Image file", "An equirectangular image embedded in the project (EXR, HDR, PNG)"),
}

#: What the bottle stands on (``Stage.kind``), in the order the Stage panel lists them.
STAGES = {
    "none": ("None", "No ground: the bottle floats in its environment"),
    "shadow": ("Shadow catcher", "The environment's own background, with the bottle's shadow, "
                                 "caustic and reflection on it"),
    "table": ("Table", "A matte surface of the stage colour"),
    "glossy": ("Glossy riser", "A riser of the stage colour under a clear coat: acrylic when "
                               "white, black glass when black"),
    "mirror": ("Mirror", "A mirror tinted with the stage colour"),
}


def word(table: dict, key: str) -> str:
    """The word for ``key`` in ``table`` (the key itself when the table has none)."""
    return table.get(key, (key, ""))[0]


def fill_combo(combo, table: dict, keys=None):
    """Fill ``combo`` with the words of ``keys`` (default: all of ``table``), each item holding
    its key as data and its explanation as tooltip."""
    with QSignalBlocker(combo):
        combo.clear()
        for key in (keys if keys is not None else table):
            text, tip = table.get(key, (key, ""))
            combo.addItem(text, key)
            combo.setItemData(combo.count() - 1, tip, Qt.ToolTipRole)


def select_key(combo, key: str) -> bool:
    """Make the item whose data is ``key`` current (signals as usual); ``False`` if none is."""
    index = combo.findData(key)
    if index >= 0:
        combo.setCurrentIndex(index)
    return index >= 0


def keys_of(combo) -> list[str]:
    """The keys of ``combo``'s items, in order."""
    return [combo.itemData(i) for i in range(combo.count())]
