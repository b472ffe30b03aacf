"""A label's die-line as a file for the printer: SVG, PDF or DXF, to scale, with dimensions.

Design rule: one drawing, three writers. :func:`drawing` lays a :class:`LabelReport` out on a
page in millimetres (y up): the cut line (a rectangle, an annular sector drawn as true arcs, or
the outline polygon), its dimensions, the numbered places of its warnings, a 10 mm scale bar
and a caption. :func:`write_dieline` renders it by the file's extension (SVG by hand, PDF
through matplotlib's PDF backend, DXF through ezdxf with ``$INSUNITS`` = mm), always 1:1, and
writes atomically (:mod:`engine.io.atomic`): a failed write leaves the previous file. Layers
(DXF) / classes (SVG): ``cut``, ``dimension``, ``warning``, ``text``.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from ..errors import GlassbenchError, shown
from ..io import atomic

FORMATS = (".svg", ".pdf", ".dxf")
#: Page margin around the shape (mm) and text height (mm).
MARGIN_MM = 15.0
TEXT_MM = 3.0


class DielineError(GlassbenchError, ValueError):
    """A die-line that cannot be written (unknown format, failed write)."""


@dataclass
class Drawing:
    """What goes on the page (mm, y up, page origin bottom-left): ``cut`` polylines, ``arcs``
    ``(cx, cy, r, a0_deg, a1_deg)``, ``lines`` (dimension lines), ``texts`` ``(x, y, text)``,
    ``marks`` ``(x, y, number)``, the page size."""

    width: float
    height: float
    cut: list = field(default_factory=list)
    arcs: list = field(default_factory=list)
    lines: list = field(default_factory=list)
    texts: list = field(default_factory=list)
    marks: list = field(default_factory=list)


def drawing(report, project_name: str = "") -> Drawing:
    """The page of ``report`` (an :class:`engine.appearance.report.LabelReport`)."""
    fig = report.flat.figures
    pts = report.flat.outline()
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    caption = 4 + len(report.warnings)
    dx, dy = MARGIN_MM - lo[0], MARGIN_MM + caption * 1.6 * TEXT_MM + 10.0 - lo[1]
    d = Drawing(float(hi[0] - lo[0] + 2 * MARGIN_MM), float(hi[1] + dy + MARGIN_MM))
    at = lambda p: (float(p[0] + dx), float(p[1] + dy))
    top, bottom = hi[1] + dy, lo[1] + dy
    if fig["kind"] == "sector":
        apex = _apex(report.flat, fig)
        cx, cy = at(apex)
        half = fig["angle_deg"] / 2
        mid = 90.0 if apex[1] < 0 else -90.0  # the sector opens away from its apex
        for r in (fig["r_inner_mm"], fig["r_outer_mm"]):
            d.arcs.append((cx, cy, r, mid - half, mid + half))
        for a in (mid - half, mid + half):
            c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
            d.cut.append([(cx + fig["r_inner_mm"] * c, cy + fig["r_inner_mm"] * s),
                          (cx + fig["r_outer_mm"] * c, cy + fig["r_outer_mm"] * s)])
        dims = [f"inner radius {fig['r_inner_mm']:.2f} mm, outer radius {fig['r_outer_mm']:.2f} mm",
                f"angle {fig['angle_deg']:.3f} deg, narrow end at the {fig['narrow_end']}"]
    else:
        d.cut.append([at(p) for p in pts] + [at(pts[0])])
        dims = [f"{fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm"
                + (" (bounding box)" if fig["kind"] == "outline" else "")]
        if fig.get("surface") == "cap-top":
            dims.append(f"printed on the cap's top, a flat disk {fig['disk_diameter_mm']:.2f} mm across")
        elif fig.get("surface") == "cap-skirt":
            dims.append(f"printed on the cap's skirt, {fig['skirt_girth_mm']:.2f} mm around, "
                        f"{fig['skirt_height_mm']:.2f} mm high")
    x0, x1 = lo[0] + dx, hi[0] + dx
    d.lines.append([(x0, bottom - 6), (x1, bottom - 6)])
    d.texts.append(((x0 + x1) / 2, bottom - 6 - 1.3 * TEXT_MM, f"{hi[0] - lo[0]:.2f} mm"))
    d.lines.append([(x1 + 6, bottom), (x1 + 6, top)])
    d.texts.append((x1 + 7, (top + bottom) / 2, f"{hi[1] - lo[1]:.2f} mm"))
    y = MARGIN_MM + (caption - 1) * 1.6 * TEXT_MM
    heading = f"{project_name}: " if project_name else ""
    for line in [f"{heading}label {report.name!r}, die-line ({fig['kind']}), scale 1:1, mm"] + dims + [
            f"area on the glass {report.area_mm2:.1f} mm2, largest strain {100 * report.max_strain:.2f} %"]:
        d.texts.append((MARGIN_MM, y, line))
        y -= 1.6 * TEXT_MM
    for n, w in enumerate(report.warnings, 1):
        d.marks.append((*at((w.x_mm, w.y_mm)), n))
        d.texts.append((MARGIN_MM, y, f"({n}) {w.message}"))
        y -= 1.6 * TEXT_MM
    d.lines.append([(MARGIN_MM, MARGIN_MM - 8), (MARGIN_MM + 10, MARGIN_MM - 8)])
    d.texts.append((MARGIN_MM + 12, MARGIN_MM - 9, "10 mm"))
    # Room for the vertical dimension beside the shape and for the longest caption line.
    widest = max(x + 0.62 * TEXT_MM * len(text) for x, _, text in d.texts)
    d.width = max(d.width + 20.0, widest + MARGIN_MM)
    return d


def _apex(flat, fig) -> np.ndarray:
    """The sector's apex in flat coordinates: on the centre column, ``r_inner`` beyond its
    narrow end."""
    nt, ns = flat.flat.shape[:2]
    narrow = flat.flat[0 if fig["narrow_end"] == "top" else -1, ns // 2]
    sign = 1.0 if fig["narrow_end"] == "top" else -1.0
    return narrow + np.array([0.0, sign * fig["r_inner_mm"]])


def write_dieline(report, path, project_name: str = "") -> None:
    """Write the die-line of ``report`` to ``path`` (``.svg``, ``.pdf`` or ``.dxf``) atomically."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in FORMATS:
        raise DielineError(f"the die-line must end in .svg, .pdf or .dxf, got {shown(path, 200)}")
    page = drawing(report, project_name)
    writer = {".svg": _svg, ".pdf": _pdf, ".dxf": _dxf}[ext]
    try:
        with atomic.replacing(path, suffix=ext) as tmp:
            writer(page, tmp)
    except OSError as exc:
        raise DielineError(f"cannot write {path}: {exc.strerror or exc}") from None


def _svg(d: Drawing, path: str) -> None:
    from xml.sax.saxutils import escape
    fy = lambda y: d.height - y
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{d.width:.3f}mm" height="{d.height:.3f}mm" '
           f'viewBox="0 0 {d.width:.4f} {d.height:.4f}">',
           '<style>.cut{fill:none;stroke:#d00;stroke-width:0.25}.dimension{fill:none;stroke:#000;'
           'stroke-width:0.15}.warning{fill:none;stroke:#f80;stroke-width:0.4}'
           f'text{{font-family:sans-serif;font-size:{TEXT_MM}px}}</style>']
    for poly in d.cut:
        pts = " ".join(f"{x:.4f},{fy(y):.4f}" for x, y in poly)
        out.append(f'<polyline class="cut" points="{pts}"/>')
    for cx, cy, r, a0, a1 in d.arcs:
        p0 = (cx + r * math.cos(math.radians(a0)), cy + r * math.sin(math.radians(a0)))
        p1 = (cx + r * math.cos(math.radians(a1)), cy + r * math.sin(math.radians(a1)))
        large = 1 if a1 - a0 > 180 else 0
        out.append(f'<path class="cut" d="M {p0[0]:.4f} {fy(p0[1]):.4f} A {r:.4f} {r:.4f} 0 {large} 0 '
                   f'{p1[0]:.4f} {fy(p1[1]):.4f}"/>')
    for line in d.lines:
        pts = " ".join(f"{x:.4f},{fy(y):.4f}" for x, y in line)
        out.append(f'<polyline class="dimension" points="{pts}"/>')
    for x, y, n in d.marks:
        out.append(f'<circle class="warning" cx="{x:.4f}" cy="{fy(y):.4f}" r="2"/>')
        out.append(f'<text x="{x + 2.5:.4f}" y="{fy(y) - 2.5 + 1.2 * TEXT_MM * (n - 1):.4f}">({n})</text>')
    for x, y, text in d.texts:
        out.append(f'<text x="{x:.4f}" y="{fy(y):.4f}">{escape(text)}</text>')
    out.append("</svg>\n")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(out))


def _pdf(d: Drawing, path: str) -> None:
    from matplotlib.figure import Figure
    from matplotlib.patches import Arc, Circle
    fig = Figure(figsize=(d.width / 25.4, d.height / 25.4))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(0, d.width)
    ax.set_ylim(0, d.height)
    ax.set_aspect("equal")
    ax.axis("off")
    pt = 72 / 25.4  # points per mm
    for poly in d.cut:
        ax.plot(*zip(*poly), color="#d00", lw=0.25 * pt)
    for cx, cy, r, a0, a1 in d.arcs:
        ax.add_patch(Arc((cx, cy), 2 * r, 2 * r, theta1=a0, theta2=a1, color="#d00", lw=0.25 * pt))
    for line in d.lines:
        ax.plot(*zip(*line), color="k", lw=0.15 * pt)
    for x, y, n in d.marks:
        ax.add_patch(Circle((x, y), 2, fill=False, color="#f80", lw=0.4 * pt))
        ax.text(x + 2.5, y + 2.5 - 1.2 * TEXT_MM * (n - 1), f"({n})", fontsize=TEXT_MM * pt)
    for x, y, text in d.texts:
        ax.text(x, y, text, fontsize=TEXT_MM * pt)
    fig.savefig(path, format="pdf")


def _dxf(d: Drawing, path: str) -> None:
    import ezdxf
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4  # millimetres
    for name, colour in (("cut", 1), ("dimension", 7), ("warning", 30), ("text", 7)):
        doc.layers.add(name, color=colour)
    msp = doc.modelspace()
    for poly in d.cut:
        msp.add_lwpolyline(poly, dxfattribs={"layer": "cut"})
    for cx, cy, r, a0, a1 in d.arcs:
        msp.add_arc((cx, cy), r, a0, a1, dxfattribs={"layer": "cut"})
    for line in d.lines:
        msp.add_lwpolyline(line, dxfattribs={"layer": "dimension"})
    for x, y, n in d.marks:
        msp.add_circle((x, y), 2, dxfattribs={"layer": "warning"})
        msp.add_text(f"({n})", height=TEXT_MM, dxfattribs={
            "layer": "warning", "insert": (x + 2.5, y + 2.5 - 1.2 * TEXT_MM * (n - 1))})
    for x, y, text in d.texts:
        msp.add_text(text, height=TEXT_MM, dxfattribs={"layer": "text", "insert": (x, y)})
    doc.saveas(path)
