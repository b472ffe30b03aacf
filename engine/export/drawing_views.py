"""The views of the plant drawing as curves at true size: half view / half section, front and
side elevations, the plan from above; and the figures the views are dimensioned with.

Design rule: nothing here computes geometry of its own. The outlines are the validated body
profile's chains (:func:`engine.geometry.validate.body_profile`), drawn segment by segment (a
line stays a line, an arc an arc, so the DXF carries them exactly); heights and radii come from
:func:`~engine.geometry.chain.radius_at`, plan outlines from
the cross-section's ``boundary``, a label's edges from its
:func:`~engine.appearance.frame.label_frame`; an outline bottle's silhouettes and plan are
:mod:`.drawing_outline`'s exact curves. Views are drawn in the bottle's own frame
(``rotation_deg`` turns the bottle in a scene, not on a drawing): the front view looks along
its +y axis (the x-z silhouette: the ``profile``, ``u`` or ``half_width`` section; +x to the
right), the side view along its -x axis (``profile``, ``u`` or ``half_depth``; +y to the
right). Each half of an elevation shows what the bottle shows towards one plan direction
(:data:`HALVES`, :func:`elevation`): the same section on both sides for the fixed kinds, the
support function on each side for an outline. Units: mm; a view's origin is the foot of its
axis on the standing plane (the plan's: the axis).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..geometry.chain import radius_at, z_breaks
from ..geometry.plan_widths import widest_core
from ..geometry.segments import Line
from ..geometry.validate import body_profile
from . import drawing_outline as outline
from .drawing_page import Circle, Polyline, SegmentCurve

#: The section seen in the front (x-z) and side (y-z) views, and across the corners, per kind.
VIEW_SECTIONS = {"round": ("profile", "profile", None),
                 "rounded_square": ("u", "u", "v"),
                 "rounded_rect": ("half_width", "half_depth", None),
                 "oval": ("half_width", "half_depth", None)}
#: Plan directions (rad) each elevation's right and left half look out to.
HALVES = {"front": (0.0, math.pi), "side": (0.5 * math.pi, 1.5 * math.pi)}
#: Fill of the glass wall in section and of a label band (grey levels print on any plotter).
WALL_FILL, LABEL_FILL = "#6b6b6b", "#dcdcdc"
#: Samples of a height range (label bands, the widest height's search).
Z_SAMPLES = 2049
#: Samples around a non-round plan outline.
PLAN_SAMPLES = 720
#: A wall segment counts as vertical when its ends' radii agree to this (mm).
VERTICAL_TOL_MM = 1e-6


@dataclass(frozen=True)
class Figures:
    """What the views are dimensioned with (mm): ``height``; the largest half-width along x,
    along y and across the corners (``None`` for round and oval bottles) with the height each
    is reached at; the mouth's outer and inner radius; the standing ring's radius along x
    (round: its radius); the height of the widest cross-section. An outline's halves differ:
    ``half_x`` and ``half_y`` are then the largest reach to either side (what the layout makes
    room for), ``span_x`` and ``span_y`` the reach to the negative and the positive side at the
    height of the largest width, ``half_corner`` the largest reach in any direction and
    ``ring_x`` the standing line's reach to -x."""

    kind: str
    height: float
    half_x: float
    z_x: float
    half_y: float
    z_y: float
    half_corner: float | None
    z_corner: float | None
    r_top: float
    r_in_top: float
    ring_x: float
    z_widest: float
    span_x: tuple[float, float] | None = None
    span_y: tuple[float, float] | None = None

    def span(self, axis: str) -> tuple[float, float]:
        """``(to the negative side, to the positive side)`` (mm) of the largest width along
        ``axis`` (``"x"`` or ``"y"``), at ``z_x`` or ``z_y``."""
        half, span = (self.half_x, self.span_x) if axis == "x" else (self.half_y, self.span_y)
        return span if span is not None else (half, half)


def _chain(prof, name: str, which: str = "outer"):
    sp = prof.section(name)
    return sp.outer_wall if which == "outer" else sp.inner_wall


def _widest(chain) -> tuple[float, float]:
    """``(r, z)``: the largest radius of a chain and the height it is first reached at."""
    z = _heights(chain)
    r = radius_at(chain, z)
    j = int(np.nanargmax(r))
    return float(r[j]), float(z[j])


def _heights(chain) -> np.ndarray:
    """Every joint of ``chain`` and a dense grid between its ends (mm)."""
    ends = [s.p0[1] for s in chain] + [chain[-1].p1[1]]
    return np.unique(np.concatenate([np.linspace(chain[0].p0[1], chain[-1].p1[1], Z_SAMPLES), ends]))


def figures(shape) -> Figures:
    """The :class:`Figures` of a valid ``shape``."""
    shape.xs.require("drawing")
    prof = body_profile(shape)
    kind, xs = shape.cross_section, shape.xs
    if kind not in VIEW_SECTIONS:
        return _outline_figures(shape, prof)
    sx, sy, sc = VIEW_SECTIONS[kind]
    (rx, zx), (ry, zy) = _widest(_chain(prof, sx)), _widest(_chain(prof, sy))
    corner = _widest(_chain(prof, sc)) if sc else None
    if kind == "rounded_rect":  # why: its corner reach is no section of its own
        z = _heights(_chain(prof, sx))
        rc = xs.circumradius(_radii(prof, z))
        j = int(np.argmax(rc))
        corner = (float(rc[j]), float(z[j]))
    z = _heights(_chain(prof, sx))
    z_widest = float(z[int(np.argmax(xs.circumradius(_radii(prof, z))))])
    sp = prof.sections[0]
    return Figures(kind, float(prof.z_top), rx, zx, ry, zy,
                   None if corner is None else corner[0], None if corner is None else corner[1],
                   float(sp.r_top), float(sp.r_in_top), float(_chain(prof, sx)[0].p0[0]), z_widest)


def _outline_figures(shape, prof) -> Figures:
    """An outline's :class:`Figures`: its reach to +x, +y, -x, -y (the support function) and
    in any direction (the circumradius) at every joint of its profiles and densely between; its
    plan is drawn at the widest core, where the Plan tab quotes its widths
    (:func:`engine.geometry.plan_widths.widest_core`)."""
    walls = [sp.outer_wall for sp in prof.sections]
    top = float(prof.z_top)
    z = np.unique(np.concatenate([np.linspace(0.0, top, Z_SAMPLES), z_breaks(walls, 0.0, top)]))
    (right, left), (up, down) = ((outline.reach(shape, z, psi) for psi in HALVES[v]) for v in ("front", "side"))
    jx, jy = int(np.argmax(left + right)), int(np.argmax(down + up))
    far = shape.xs.circumradius(_radii(prof, z))
    jc = int(np.argmax(far))
    front = outline.elevation(shape, 0.0)
    return Figures("outline", top, float(max(right.max(), left.max())), float(z[jx]),
                   float(max(up.max(), down.max())), float(z[jy]), float(far[jc]), float(z[jc]),
                   float(front.r_top), float(front.r_in_top), float(left[0]), widest_core(shape).z,
                   (float(left[jx]), float(right[jx])), (float(down[jy]), float(up[jy])))


def _radii(prof, z, which: str = "outer"):
    """The section radii (mm) at heights ``z``, in ``SECTION_NAMES`` order (chain ends held)."""
    out = []
    for sp in prof.sections:
        chain = sp.outer_wall if which == "outer" else sp.inner_wall
        out.append(radius_at(chain, np.clip(z, chain[0].p0[1], chain[-1].p1[1])))
    return out


# ------------------------------------------------------------------------- elevations
def _curves(segs, layer: str, style: str, sx: float, dx: float) -> list:
    return [SegmentCurve(s, layer, style, sx, dx) for s in segs]


def elevation(shape, psi: float):
    """What the bottle shows towards plan direction ``psi`` (rad, one of :data:`HALVES`) as a
    :class:`~engine.geometry.offset.SectionProfile` in (reach, z) mm: a fixed kind's own section
    along x or y, an outline's silhouettes (:func:`.drawing_outline.elevation`)."""
    kind = shape.cross_section
    if kind not in VIEW_SECTIONS:
        return outline.elevation(shape, psi)
    return body_profile(shape).section(VIEW_SECTIONS[kind][0 if abs(math.cos(psi)) > 0.5 else 1])


def reach(shape, z, psi: float, which: str = "outer") -> np.ndarray:
    """The outer (or the cavity's, ``which="inner"``) reach (mm) towards ``psi`` at heights
    ``z`` (mm; a wall's ends held beyond it)."""
    if shape.cross_section not in VIEW_SECTIONS:
        return outline.reach(shape, z, psi, which)
    sp = elevation(shape, psi)
    chain = sp.outer_wall if which == "outer" else sp.inner_wall
    return radius_at(chain, np.clip(np.asarray(z, float), chain[0].p0[1], chain[-1].p1[1]))


def section_words(shape) -> str:
    """How the front view's right half is cut, in the notes' words: through the axis, or (an
    outline not symmetric about its x axis) where the outline reaches farthest to the right."""
    if shape.cross_section in VIEW_SECTIONS or outline.symmetric_about_x(shape.plan):
        return "cut through the axis"
    return "cut where the outline reaches farthest to the right"


def half_section(shape, dx: float) -> list:
    """The front view as half view / half section about the axis at ``x = dx``: the left half the
    outer outline, the right half cut with the glass wall filled (:func:`section_words`)."""
    prof = body_profile(shape)
    right, left = (elevation(shape, psi) for psi in HALVES["front"])
    out = _curves(left.outer_wall, "OUTLINE", "thick", -1.0, dx)
    ring, top = left.outer_wall[0].p0[0], prof.z_top
    out.append(Polyline(((dx - ring, 0.0), (dx, 0.0)), "OUTLINE"))          # standing line
    out.append(Polyline(((dx - left.r_top, top), (dx, top)), "OUTLINE"))     # the mouth's face
    out.append(Polyline(tuple(map(tuple, _wall_polygon(right, dx))), "HATCH", "fill", True, WALL_FILL))
    out += _curves(right.outer_base + right.outer_wall, "OUTLINE", "thick", 1.0, dx)
    out += _curves(right.inner_base + right.inner_wall, "SECTION", "thick", 1.0, dx)
    out.append(Polyline(((dx + right.r_in_top, top), (dx + right.r_top, top)), "OUTLINE"))
    return out


def _wall_polygon(sp, dx: float) -> np.ndarray:
    """The glass cut by the plane through the axis, right half: outer base and wall up, across
    the rim, inner wall and base down, closed along the axis (model mm)."""
    outer = [SegmentCurve(s, "", sx=1.0, dx=dx).sample(48) for s in sp.outer_base + sp.outer_wall]
    inner = [SegmentCurve(s, "", sx=1.0, dx=dx).sample(48)[::-1]
             for s in reversed(sp.inner_base + sp.inner_wall)]
    return np.concatenate(outer + inner)


def outside_view(shape, which: str, dx: float) -> list:
    """An elevation's outer outline about the axis at ``x = dx``: ``which`` ``"front"`` (x-z)
    or ``"side"`` (y-z)."""
    top = body_profile(shape).z_top
    right, left = (elevation(shape, psi) for psi in HALVES[which])
    out = _curves(left.outer_wall, "OUTLINE", "thick", -1.0, dx) + _curves(right.outer_wall, "OUTLINE", "thick", 1.0, dx)
    out.append(Polyline(((dx - left.outer_wall[0].p0[0], 0.0), (dx + right.outer_wall[0].p0[0], 0.0)), "OUTLINE"))
    out.append(Polyline(((dx - left.r_top, top), (dx + right.r_top, top)), "OUTLINE"))
    return out


def axis_line(dx: float, z0: float, z1: float) -> Polyline:
    """The view's centre line from ``z0`` to ``z1`` (mm)."""
    return Polyline(((dx, z0), (dx, z1)), "CENTRE", "centre")


def band(shape, z0: float, z1: float, dx: float) -> Polyline:
    """A label band on the front view: the silhouette between heights ``z0 < z1`` (mm), filled."""
    z = np.linspace(z0, z1, 97)
    r, ell = (reach(shape, z, psi) for psi in HALVES["front"])
    pts = np.concatenate([np.column_stack([dx + r, z]), np.column_stack([dx - ell, z])[::-1]])
    return Polyline(tuple(map(tuple, pts)), "LABELS", "band", True, LABEL_FILL)


# ------------------------------------------------------------------------- plan
def plan_view(shape, center: tuple[float, float]) -> list:
    """The view from above, centred at ``center`` (model mm): the outline at the widest height
    (thick), the standing ring (thin, dashed: it lies under the body), the finish's outer
    circle (thick) and its bore (thick), and the centre lines."""
    prof = body_profile(shape)
    fig = figures(shape)
    cx, cy = center
    out = [*_outline(shape, prof, fig.z_widest, center, "OUTLINE", "thick"),
           *_outline(shape, prof, 0.0, center, "OUTLINE", "hidden"),
           Circle(center, fig.r_top, "OUTLINE"), Circle(center, fig.r_in_top, "SECTION")]
    reach = (fig.half_corner or max(fig.half_x, fig.half_y)) + 4.0
    out.append(Polyline(((cx - reach, cy), (cx + reach, cy)), "CENTRE", "centre"))
    out.append(Polyline(((cx, cy - reach), (cx, cy + reach)), "CENTRE", "centre"))
    return out


def _outline(shape, prof, z: float, center, layer: str, style: str) -> list:
    """The cross-section at height ``z`` (mm): a circle (round), an outline's exact pieces or
    a closed polyline."""
    radii = [np.array(float(r)) for r in _radii(prof, np.array(z))]
    if z <= 0.0:  # the standing ring: where each section's wall starts
        radii = [np.array(sp.outer_wall[0].p0[0]) for sp in prof.sections]
    if shape.xs.revolved:
        return [Circle(center, float(radii[0]), layer, style)]
    if shape.cross_section not in VIEW_SECTIONS:
        return outline.section_curves(shape.plan, max(float(radii[0]), 0.0), float(radii[1]), center, layer, style)
    theta = np.linspace(0.0, 2.0 * math.pi, PLAN_SAMPLES, endpoint=False)
    x, y, _, _ = shape.xs.boundary(radii, theta)
    pts = np.column_stack([center[0] + x, center[1] + y])
    return [Polyline(tuple(map(tuple, pts)), layer, style, closed=True)]


# ------------------------------------------------------------------------- label areas
@dataclass(frozen=True)
class Zone:
    """A band of the wall to dimension (mm): a label's (its name) or the clear label panel."""

    name: str
    z0: float
    z1: float
    panel: bool = False


def label_zones(design) -> list[Zone]:
    """Each wall label's band (bottom and top edge heights at its centre azimuth, from its
    frame); labels on the closure are skipped. With no wall label, the clear label panel:
    :func:`straight_zone`, or nothing when the body has no straight part."""
    from ..appearance.frame import Placement, label_frame
    zones = []
    for label in design.labels:
        if label.surface != "wall":
            continue
        frame = label_frame(design.shape, Placement.of(label), label.name)
        z = frame.points(np.array([0.5, 0.5]), np.array([1.0, 0.0]))[:, 2]
        zones.append(Zone(label.name, float(z[0]), float(z[1])))
    if zones:
        return zones
    panel = straight_zone(design.shape)
    return [] if panel is None else [Zone("clear label panel", panel[0], panel[1], True)]


def straight_zone(shape) -> tuple[float, float] | None:
    """``(z0, z1)`` (mm): the longest height range over which the outer wall of every section is
    one vertical straight line (touching vertical lines at one radius merge); the finish (the
    last segment) is not body. ``None`` when there is none."""
    prof = body_profile(shape)
    common = None
    for sp in prof.sections:
        spans = _vertical_spans(sp.outer_wall[:-1])
        common = spans if common is None else _intersect(common, spans)
    if not common:
        return None
    z0, z1 = max(common, key=lambda s: s[1] - s[0])
    return (z0, z1) if z1 > z0 else None


def _vertical_spans(segs) -> list[tuple[float, float]]:
    spans = []
    for s in segs:
        if isinstance(s, Line) and abs(s.p1[0] - s.p0[0]) <= VERTICAL_TOL_MM:
            if spans and abs(spans[-1][1] - s.p0[1]) <= VERTICAL_TOL_MM and abs(spans[-1][2] - s.p0[0]) <= VERTICAL_TOL_MM:
                spans[-1] = (spans[-1][0], s.p1[1], s.p0[0])
            else:
                spans.append((s.p0[1], s.p1[1], s.p0[0]))
    return [(a, b) for a, b, _ in spans]


def _intersect(a, b) -> list[tuple[float, float]]:
    out = []
    for a0, a1 in a:
        for b0, b1 in b:
            lo, hi = max(a0, b0), min(a1, b1)
            if hi > lo:
                out.append((lo, hi))
    return out
