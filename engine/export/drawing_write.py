"""The plant drawing's three writers: PDF and SVG through matplotlib, DXF through ezdxf.

Design rule: a writer draws a :class:`~.drawing_page.Page` and nothing else; it decides no
position. PDF and SVG draw on one axes that spans the figure with data units of paper
millimetres (``xlim = (0, W)``, ``ylim = (0, H)``, the figure exactly ``W x H`` mm), so a model
length ``L`` is ``L * scale`` mm on the sheet to the last bit; paths are neither snapped nor
simplified. Text is DejaVu Sans: embedded as TrueType in a PDF (``pdf.fonttype`` 42), kept as
text in an SVG (``svg.fonttype`` ``none``), whose width and height are given in mm. The DXF is
model space at 1:1 (``$INSUNITS`` mm): lines, arcs and ellipses as the section draws them,
fills as solid hatches, dimensions as real linear dimension entities, and the paper's
annotation placed at ``(paper - origin) / scale`` with heights divided by the scale, so it
plots back to the sheet at the drawing's scale.
"""
from __future__ import annotations

import io
import math
import re

import numpy as np

from .drawing_page import (ARROW_HALF_MM, ARROW_MM, EXT_GAP_MM, EXT_OVER_MM, LAYERS,
                           POINTS_PER_MM, TEXT_MM, THICK_MM, THIN_MM, Circle, Dim, Page,
                           Polyline, SegmentCurve, em_mm, text_width_mm)

#: Line width (mm on paper), dash pattern (matplotlib) and DXF linetype of each curve style.
STYLES = {"thick": (THICK_MM, "-", "CONTINUOUS"), "thin": (THIN_MM, "-", "CONTINUOUS"),
          "centre": (THIN_MM, (0, (12, 3, 2, 3)), "CENTER"),
          "hidden": (THIN_MM, (0, (4, 2)), "DASHED"),
          "band": (THIN_MM, "-", "CONTINUOUS"), "fill": (0.0, "-", "CONTINUOUS")}
#: Space (mm) between a dimension line and its text.
TEXT_GAP_MM = 0.9
RC = {"pdf.fonttype": 42, "svg.fonttype": "none", "font.family": "DejaVu Sans",
      "path.simplify": False, "lines.solid_capstyle": "butt", "svg.hashsalt": "glassbench"}


# ------------------------------------------------------------------------- matplotlib
def figure(page: Page):
    """The page as a matplotlib ``Figure`` (no pyplot, no GUI backend)."""
    from matplotlib.figure import Figure
    w, h = page.size_mm
    fig = Figure(figsize=(w / 25.4, h / 25.4))
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(0.0, w)
    ax.set_ylim(0.0, h)
    ax.axis("off")
    for curve in page.curves:
        _draw_curve(ax, page, curve)
    for rule in page.rules:
        _line(ax, [rule.p0, rule.p1], rule.width_mm)
    for dim in page.dims:
        _draw_dim(ax, page, dim)
    for t in page.texts:
        _text(ax, t.x, t.y, t.text, t.size_mm, t.ha, t.va, t.rotation, t.bold)
    return fig


def _line(ax, pts, width_mm: float, dash="-", zorder: float = 3.0) -> None:
    from matplotlib.lines import Line2D
    pts = np.asarray(pts, float)
    ax.add_line(Line2D(pts[:, 0], pts[:, 1], lw=width_mm * POINTS_PER_MM, color="black",
                       linestyle=dash, snap=False, clip_on=False, zorder=zorder,
                       solid_joinstyle="round", solid_capstyle="butt"))


def _draw_curve(ax, page: Page, curve) -> None:
    from matplotlib.patches import Polygon
    pts = page.to_paper(curve.sample())
    width, dash, _ = STYLES[curve.style]
    if isinstance(curve, Polyline) and curve.fill:
        ax.add_patch(Polygon(pts, closed=True, facecolor=curve.fill, edgecolor="none",
                             snap=False, clip_on=False, zorder=1.0 if curve.style == "band" else 1.5))
        if width == 0.0:
            return
    if isinstance(curve, Polyline) and curve.closed:
        pts = np.vstack([pts, pts[:1]])
    _line(ax, pts, width, dash, 2.5 if curve.style == "thick" else 2.0)


def _text(ax, x, y, text, size_mm, ha="left", va="baseline", rotation=0.0, bold=False) -> None:
    ax.text(x, y, text, fontsize=em_mm(size_mm) * POINTS_PER_MM, ha=ha, va=va,
            rotation=rotation, rotation_mode="anchor", fontweight="bold" if bold else "normal",
            color="black", clip_on=False, zorder=4.0)


def dim_geometry(page: Page, dim: Dim) -> dict:
    """Where a dimension goes on paper (mm): the dimension line's ends ``l1``, ``l2``, its
    direction ``d`` and the side its text stands on ``up``; ``a``, ``b`` the measured points."""
    a, b = page.to_paper(dim.p1), page.to_paper(dim.p2)
    d, n = dim.direction(), dim.normal()
    l1 = a + n * dim.offset_mm
    l2 = l1 + d * float((b - a) @ d)
    if float((l2 - l1) @ d) < 0:  # why: keep l1 -> l2 along d, so text reads the right way
        l1, l2 = l2, l1
    up = np.array([-d[1], d[0]])
    return {"a": a, "b": b, "l1": l1, "l2": l2, "d": d, "up": up}


def _arrow(ax, tip, point) -> None:
    """A closed, filled arrowhead (paper mm) with its tip at ``tip``, pointing along the unit
    vector ``point``."""
    from matplotlib.patches import Polygon
    base = tip - point * ARROW_MM
    side = np.array([-point[1], point[0]]) * ARROW_HALF_MM
    ax.add_patch(Polygon([tip, base + side, base - side], closed=True, facecolor="black",
                         edgecolor="none", snap=False, clip_on=False, zorder=3.0))


def _draw_radius(ax, page: Page, dim: Dim) -> None:
    """A radius (``dim.p1`` the centre, ``dim.p2`` on the arc): a leader along the radius from
    outside, its arrowhead on the arc pointing at the centre, the text along the leader and
    reading from the left (ISO 129's form for a radius too small to hold its text; a large
    radius's far centre needs no line either)."""
    a, b = page.to_paper(dim.p1), page.to_paper(dim.p2)
    out = (b - a) / float(np.hypot(*(b - a)))
    width = text_width_mm(dim.text)
    _arrow(ax, b, -out)
    _line(ax, [b, b + out * (ARROW_MM + 3.0 + width)], THIN_MM)
    forward = out[0] >= 0.0
    read = out if forward else -out
    at = b + out * (ARROW_MM + 1.5) + np.array([-read[1], read[0]]) * TEXT_GAP_MM
    _text(ax, at[0], at[1], dim.text, TEXT_MM, "left" if forward else "right", "baseline",
          math.degrees(math.atan2(read[1], read[0])))


def _draw_dim(ax, page: Page, dim: Dim) -> None:
    """Extension lines, the dimension line (one straight piece between the extension lines),
    closed arrowheads (inside when they fit, else outside) and the text along the line; a
    radius as :func:`_draw_radius`."""
    if dim.axis == "radius":
        _draw_radius(ax, page, dim)
        return
    g = dim_geometry(page, dim)
    l1, l2, d, up = g["l1"], g["l2"], g["d"], g["up"]
    for p in (g["a"], g["b"]):
        v = l1 + d * float((p - l1) @ d) - p   # from the point to its foot on the line
        length = float(np.hypot(*v))
        if length > EXT_GAP_MM:
            u = v / length
            _line(ax, [p + u * EXT_GAP_MM, p + v + u * EXT_OVER_MM], THIN_MM)
    _line(ax, [l1, l2], THIN_MM)
    span = float(np.hypot(*(l2 - l1)))
    inside = span >= 2.0 * ARROW_MM + 1.0
    for tip, way in ((l1, -d), (l2, d)):
        point = way if inside else -way   # the direction the arrow points
        _arrow(ax, tip, point)
        if not inside:
            _line(ax, [tip, tip - point * (ARROW_MM + 2.0)], THIN_MM)
    angle = math.degrees(math.atan2(d[1], d[0]))
    width = text_width_mm(dim.text)
    if width + 2.0 <= span:
        at, ha = 0.5 * (l1 + l2) + up * TEXT_GAP_MM, "center"
    else:  # why: a narrow dimension carries its text beyond its end, on the line's extension
        at, ha = l2 + d * (ARROW_MM + 2.5) + up * TEXT_GAP_MM, "left"
        _line(ax, [l2, l2 + d * (ARROW_MM + 2.5 + width)], THIN_MM)
    _text(ax, at[0], at[1], dim.text, TEXT_MM, ha, "baseline", angle)


def write_pdf(page: Page, path: str) -> None:
    """The page as a PDF of the sheet's size, fonts embedded."""
    import matplotlib
    with matplotlib.rc_context(RC):
        figure(page).savefig(path, format="pdf", metadata={"Creator": "glassbench"})


def write_svg(page: Page, path: str) -> None:
    """The page as an SVG whose width and height are the sheet's in mm, text kept as text."""
    import matplotlib
    buf = io.StringIO()
    with matplotlib.rc_context(RC):
        figure(page).savefig(buf, format="svg", metadata={"Date": None})
    w, h = page.size_mm
    # why: matplotlib states the size in pt; a plotter and a browser read mm the same, and the
    # viewBox (pt) keeps every coordinate, so only the root's two attributes change.
    text = re.sub(r'(<svg[^>]*?)\swidth="[^"]*"\s+height="[^"]*"',
                  lambda m: f'{m.group(1)} width="{w:g}mm" height="{h:g}mm"', buf.getvalue(), count=1)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)


# ------------------------------------------------------------------------- DXF
def write_dxf(page: Page, path: str) -> None:
    """The page as DXF model space at 1:1 (mm), layers :data:`~.drawing_page.LAYERS`."""
    import ezdxf
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4       # millimetres
    doc.header["$LTSCALE"] = 1.0 / page.scale
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    _dimstyle(doc, page.scale)
    msp = doc.modelspace()
    for curve in page.curves:
        _dxf_curve(msp, curve)
    for rule in page.rules:
        msp.add_line(*(tuple(page.to_model(p)) for p in (rule.p0, rule.p1)),
                     dxfattribs={"layer": rule.layer, "lineweight": int(round(rule.width_mm * 100))})
    for dim in page.dims:
        _dxf_dim(msp, page, dim)
    for t in page.texts:
        _dxf_text(msp, page, t)
    doc.saveas(path)


def _dimstyle(doc, scale: float) -> None:
    """A dimension style whose text, arrows and gaps plot at the paper sizes of the PDF."""
    s = 1.0 / scale
    doc.dimstyles.new("GLASSBENCH", dxfattribs={
        "dimtxt": TEXT_MM * s, "dimasz": ARROW_MM * s, "dimexo": EXT_GAP_MM * s,
        "dimexe": EXT_OVER_MM * s, "dimgap": TEXT_GAP_MM * s, "dimtad": 1, "dimtih": 0,
        "dimtoh": 0, "dimdec": 1, "dimblk": "", "dimclrd": 5, "dimclre": 5, "dimclrt": 7})


def _dxf_curve(msp, curve) -> None:
    _, _, linetype = STYLES[curve.style]
    attribs = {"layer": curve.layer, "linetype": linetype}
    if isinstance(curve, Circle):
        msp.add_circle(curve.center, curve.radius, dxfattribs=attribs)
    elif isinstance(curve, Polyline):
        pts = [tuple(map(float, p)) for p in curve.points]
        if curve.fill:
            hatch = msp.add_hatch(color=LAYERS[curve.layer], dxfattribs={"layer": curve.layer})
            hatch.paths.add_polyline_path(pts, is_closed=True)
            if curve.style == "fill":
                return
        msp.add_lwpolyline(pts, close=curve.closed, dxfattribs=attribs)
    else:
        _dxf_segment(msp, curve, attribs)


def _dxf_segment(msp, c: SegmentCurve, attribs: dict) -> None:
    """A section segment as LINE, ARC or ELLIPSE (mirrored by ``c.sx``); an offset ellipse,
    which is no conic, as a fine LWPOLYLINE."""
    seg = c.seg
    if seg.kind == "line":
        p = c.sample()
        msp.add_line(tuple(p[0]), tuple(p[1]), dxfattribs=attribs)
        return
    if seg.kind not in ("arc", "ellipse_arc"):
        msp.add_lwpolyline([tuple(p) for p in c.sample(256)], dxfattribs=attribs)
        return
    a0, sweep = seg.angle0, seg.sweep
    if c.sx < 0:  # mirrored about the axis: angle a becomes pi - a, the sweep turns round
        a0, sweep = math.pi - a0, -sweep
    start, end = (a0, a0 + sweep) if sweep > 0 else (a0 + sweep, a0)
    center = (c.sx * seg.center[0] + c.dx, seg.center[1] + c.dy)
    if seg.kind == "arc":
        msp.add_arc(center, seg.radius, math.degrees(start), math.degrees(end), dxfattribs=attribs)
        return
    rr, rz = seg.radius_r, seg.radius_z
    if rr >= rz:
        msp.add_ellipse(center, (rr, 0.0, 0.0), rz / rr, start, end, dxfattribs=attribs)
    else:  # why: DXF wants the major axis; along z the parameter runs a quarter turn behind
        msp.add_ellipse(center, (0.0, rz, 0.0), rr / rz, start - math.pi / 2, end - math.pi / 2,
                        dxfattribs=attribs)


def _dxf_dim(msp, page: Page, dim: Dim) -> None:
    attribs = {"layer": "DIMENSIONS"}
    if dim.axis == "radius":  # the text outside the arc, where the PDF's leader has it
        out = np.subtract(dim.p2, dim.p1) / float(np.hypot(*np.subtract(dim.p2, dim.p1)))
        where = np.add(dim.p2, out * (ARROW_MM + 1.5 + text_width_mm(dim.text) / 2) / page.scale)
        msp.add_radius_dim(center=tuple(dim.p1), radius=dim.measured_mm(), location=tuple(where),
                           text=dim.text, dimstyle="GLASSBENCH", dxfattribs=attribs).render()
        return
    g = dim_geometry(page, dim)
    base = tuple(page.to_model(g["l1"]))
    if dim.axis == "aligned":
        dist = dim.offset_mm / page.scale
        msp.add_aligned_dim(p1=tuple(dim.p1), p2=tuple(dim.p2), distance=dist, text=dim.text,
                            dimstyle="GLASSBENCH", dxfattribs=attribs).render()
        return
    msp.add_linear_dim(base=base, p1=tuple(dim.p1), p2=tuple(dim.p2),
                       angle=0.0 if dim.axis == "x" else 90.0, text=dim.text,
                       dimstyle="GLASSBENCH", dxfattribs=attribs).render()


_ALIGN = {("left", "baseline"): "LEFT", ("center", "baseline"): "CENTER",
          ("right", "baseline"): "RIGHT", ("left", "center"): "MIDDLE_LEFT",
          ("center", "center"): "MIDDLE_CENTER", ("right", "center"): "MIDDLE_RIGHT",
          ("left", "top"): "TOP_LEFT", ("center", "top"): "TOP_CENTER", ("right", "top"): "TOP_RIGHT"}


def _dxf_text(msp, page: Page, t) -> None:
    from ezdxf.enums import TextEntityAlignment
    align = TextEntityAlignment[_ALIGN.get((t.ha, t.va), "LEFT")]
    text = msp.add_text(t.text, height=t.size_mm / page.scale, rotation=t.rotation,
                        dxfattribs={"layer": t.layer})
    text.set_placement(tuple(page.to_model((t.x, t.y))), align=align)


WRITERS = {".pdf": write_pdf, ".svg": write_svg, ".dxf": write_dxf}
