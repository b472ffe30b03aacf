"""DXF drawings of a bottle's half-section -> :class:`engine.geometry.section.Section`.

Design rule: the drawing's x is the radius ``r`` and its y the height ``z`` (mm after the
``$INSUNITS`` scale). LINE, ARC, ELLIPSE (axis-aligned) and LWPOLYLINE (with bulges) are
turned into pieces with two ends; the pieces must form one open chain (no gaps, no branches,
no loops) with one end on the axis ``r = 0``. The chain is walked from that end to the
other (the mouth), each piece oriented to the walking direction: a DXF arc always runs
counter-clockwise from its start to its end angle, so walked backwards it becomes a ``"cw"``
arc. The drawing is shifted in z so that its lowest point (the axis end of a flat base, the
standing ring of a punt) is at z = 0; the axis end gets r = 0 exactly; a drawing on the left
of the axis (x <= 0) is mirrored. Text, dimensions and points are ignored; any other entity is
an error. Whether the section is a valid bottle is :mod:`engine.geometry.validate`'s business.
"""
from __future__ import annotations

import math
import os

from ..errors import GlassbenchError
from ..geometry.section import Section
from ..geometry.segments import Arc, EllipseArc, Line

#: Ends closer than this (mm) are one joint; farther apart they are a gap.
JOIN_TOL_MM = 1e-4
#: Relative tolerance for "axis-aligned" ellipses (major axis direction).
AXIS_TOL = 1e-9
#: mm per drawing unit for the DXF ``$INSUNITS`` codes we accept (0 = unitless: mm).
UNIT_SCALE = {0: 1.0, 1: 25.4, 2: 304.8, 4: 1.0, 5: 10.0, 6: 1000.0}
#: Entities that carry no geometry of the section.
IGNORED = {"TEXT", "MTEXT", "DIMENSION", "LEADER", "MLEADER", "POINT", "HATCH"}


class DxfImportError(GlassbenchError, ValueError):
    """A DXF file that cannot be turned into one section; the message says why and where."""


def section_from_dxf(path: str | os.PathLike) -> Section:
    """Read ``path`` and return its section (mm), walked from the axis to the mouth.

    Raises ``DxfImportError`` for unreadable files, unsupported entities or units, rotated
    ellipses, gaps, branches or loops.
    """
    import ezdxf
    try:
        doc = ezdxf.readfile(os.fspath(path))
    except (OSError, ezdxf.DXFError, ValueError, UnicodeDecodeError) as exc:
        raise DxfImportError(f"cannot read DXF {os.fspath(path)}: {exc}") from None
    return section_from_document(doc)


def section_from_document(doc) -> Section:
    """The section drawn in an ``ezdxf`` document's model space (see :func:`section_from_dxf`)."""
    units = doc.header.get("$INSUNITS", 0)
    if units not in UNIT_SCALE:
        raise DxfImportError(f"unsupported drawing units ($INSUNITS = {units}); use mm, cm, m or in")
    pieces = []
    for entity in doc.modelspace():
        kind = entity.dxftype()
        if kind in IGNORED:
            continue
        maker = _MAKERS.get(kind)
        if maker is None:
            raise DxfImportError(f"unsupported DXF entity {kind} (handle {entity.dxf.handle}); "
                                 f"use LINE, ARC, ELLIPSE or LWPOLYLINE")
        pieces.extend(maker(entity))
    if not pieces:
        raise DxfImportError("the drawing holds no lines, arcs, ellipses or polylines")
    scale = UNIT_SCALE[units]
    if scale != 1.0:
        pieces = [p.transformed(scale, 1.0, 0.0) for p in pieces]
    chain = _chain(pieces)
    mirror = -1.0 if all(max(p.p0[0], p.p1[0]) <= JOIN_TOL_MM for p in chain) else 1.0
    # Stand the bottle on z = 0: its lowest point (the axis end, or the ring of a punt).
    z_low = min(_lowest_z(p.segment()) for p in chain)
    segs = [p.transformed(1.0, mirror, -z_low).segment() for p in chain]
    segs = _snap_lines(segs)
    return Section(tuple(segs))


def _lowest_z(seg) -> float:
    """Lowest height (mm) reached by a segment: an end, or the bottom of an arc's circle."""
    low = min(seg.p0[1], seg.p1[1])
    if isinstance(seg, (Arc, EllipseArc)):
        # Does the sweep pass through parameter angle -90 deg (the bottom)?
        turn = ((-math.pi / 2 - seg.angle0) * math.copysign(1.0, seg.sweep)) % (2 * math.pi)
        if turn < abs(seg.sweep):
            low = min(low, seg.center[1] - (seg.radius if isinstance(seg, Arc) else seg.radius_z))
    return low


def section_to_dxf(section: Section, path: str | os.PathLike) -> None:
    """Write ``section`` (mm) as a DXF drawing (LINE, ARC, ELLIPSE; ``$INSUNITS`` = mm).

    ``"cw"`` arcs are written as DXF arcs from their end to their start, since DXF arcs are
    always counter-clockwise. Used for sample files and import round trips.
    """
    import ezdxf
    doc = ezdxf.new(units=4)
    msp = doc.modelspace()
    for seg in section.segments:
        if isinstance(seg, Line):
            msp.add_line(seg.p0, seg.p1)
        elif isinstance(seg, Arc):
            a0 = math.degrees(math.atan2(seg.p0[1] - seg.center[1], seg.p0[0] - seg.center[0]))
            a1 = math.degrees(math.atan2(seg.p1[1] - seg.center[1], seg.p1[0] - seg.center[0]))
            start, end = (a0, a1) if seg.direction == "ccw" else (a1, a0)
            msp.add_arc(seg.center, seg.radius, start, end)
        elif isinstance(seg, EllipseArc):
            s0 = seg.angle0
            s1 = s0 + seg.sweep
            if seg.radius_r >= seg.radius_z:
                major, ratio, shift = (seg.radius_r, 0.0), seg.radius_z / seg.radius_r, 0.0
            else:  # major axis along +z: DXF parameter = ours - 90 deg
                major, ratio, shift = (0.0, seg.radius_z), seg.radius_r / seg.radius_z, -math.pi / 2
            start, end = (s0, s1) if seg.direction == "ccw" else (s1, s0)
            msp.add_ellipse(seg.center, major, ratio, start + shift, end + shift)
        else:
            raise DxfImportError(f"cannot write a {type(seg).__name__} to DXF")
    try:
        doc.saveas(os.fspath(path))
    except OSError as exc:
        raise DxfImportError(f"cannot write {os.fspath(path)}: {exc.strerror}") from None


class _Piece:
    """One drawn curve with its two ends; ``segment()`` builds it walked from p0 to p1."""

    def __init__(self, kind, p0, p1, center=None, radii=None, direction="ccw", handle="?"):
        self.kind, self.p0, self.p1 = kind, tuple(p0), tuple(p1)
        self.center, self.radii, self.direction, self.handle = center, radii, direction, handle

    def reversed(self) -> "_Piece":
        flip = {"ccw": "cw", "cw": "ccw"}[self.direction]
        return _Piece(self.kind, self.p1, self.p0, self.center, self.radii, flip, self.handle)

    def transformed(self, scale: float, mirror: float, dz: float) -> "_Piece":
        """Scale about the origin, mirror r by ``mirror`` (+-1), then shift z by ``dz`` (mm)."""
        def f(p):
            return None if p is None else (mirror * scale * p[0], scale * p[1] + dz)
        radii = None if self.radii is None else tuple(scale * r for r in self.radii)
        direction = self.direction if mirror > 0 else {"ccw": "cw", "cw": "ccw"}[self.direction]
        return _Piece(self.kind, f(self.p0), f(self.p1), f(self.center), radii, direction, self.handle)

    def segment(self):
        try:
            if self.kind == "line":
                return Line(self.p0, self.p1)
            if self.kind == "arc":
                return Arc(self.center, self.radii[0], self.p0, self.p1, self.direction)
            return EllipseArc(self.center, self.radii[0], self.radii[1], self.p0, self.p1,
                              self.direction)
        except ValueError as exc:
            raise DxfImportError(f"entity {self.handle}: {exc}") from None


def _xy(v) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def _orientation(entity) -> float:
    """+1 for drawings seen from +z (the normal case), -1 for a flipped extrusion (OCS)."""
    ex = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))
    if abs(ex[0]) > AXIS_TOL or abs(ex[1]) > AXIS_TOL:
        raise DxfImportError(f"entity {entity.dxf.handle} is not drawn in the xy plane")
    return 1.0 if ex[2] > 0 else -1.0


def _line(entity):
    s, e = _xy(entity.dxf.start), _xy(entity.dxf.end)
    if math.dist(s, e) <= JOIN_TOL_MM:
        return []  # a zero-length line joins nothing
    return [_Piece("line", s, e, handle=entity.dxf.handle)]


def _arc(entity):
    sign = _orientation(entity)
    # start_point / end_point are in world coordinates; the OCS centre needs mapping.
    c = _xy(entity.ocs().to_wcs(entity.dxf.center))
    piece = _Piece("arc", _xy(entity.start_point), _xy(entity.end_point), c,
                   (float(entity.dxf.radius),), "ccw" if sign > 0 else "cw", entity.dxf.handle)
    return [piece]


def _ellipse(entity):
    sign = _orientation(entity)
    major = entity.dxf.major_axis
    a = math.hypot(major[0], major[1])
    b = a * float(entity.dxf.ratio)
    if abs(major[1]) <= AXIS_TOL * a:
        radii = (a, b)
    elif abs(major[0]) <= AXIS_TOL * a:
        radii = (b, a)
    else:
        angle = math.degrees(math.atan2(major[1], major[0]))
        raise DxfImportError(f"ELLIPSE {entity.dxf.handle} is rotated by {angle:.3f} deg; "
                             f"only ellipses with axes along r and z can be imported")
    span = (entity.dxf.end_param - entity.dxf.start_param) % (2 * math.pi)
    if span < 1e-12:
        raise DxfImportError(f"ELLIPSE {entity.dxf.handle} is a full ellipse, not an arc")
    return [_Piece("ellipse", _xy(entity.start_point), _xy(entity.end_point),
                   _xy(entity.dxf.center), radii, "ccw" if sign > 0 else "cw", entity.dxf.handle)]


def _lwpolyline(entity):
    sign = _orientation(entity)
    ocs = entity.ocs()
    pts = [(float(x), float(y), float(b)) for x, y, b in entity.get_points("xyb")]
    if entity.closed and len(pts) > 1:
        pts.append(pts[0])
    out = []
    for (x0, y0, bulge), (x1, y1, _) in zip(pts, pts[1:]):
        a, b = (x0, y0), (x1, y1)
        chord = math.dist(a, b)
        if chord <= JOIN_TOL_MM:
            continue
        wa, wb = _xy(ocs.to_wcs((x0, y0, 0.0))), _xy(ocs.to_wcs((x1, y1, 0.0)))
        if abs(bulge) < 1e-12:
            out.append(_Piece("line", wa, wb, handle=entity.dxf.handle))
            continue
        theta = 4.0 * math.atan(bulge)  # signed included angle, > 0 counter-clockwise (OCS)
        radius = chord / (2.0 * abs(math.sin(theta / 2.0)))
        nx, ny = -(b[1] - a[1]) / chord, (b[0] - a[0]) / chord  # left of a -> b
        off = (chord / 2.0) / math.tan(theta / 2.0)
        c = ((a[0] + b[0]) / 2 + nx * off, (a[1] + b[1]) / 2 + ny * off)
        wc = _xy(ocs.to_wcs((c[0], c[1], 0.0)))
        ccw = (theta > 0) == (sign > 0)
        out.append(_Piece("arc", wa, wb, wc, (radius,), "ccw" if ccw else "cw", entity.dxf.handle))
    return out


_MAKERS = {"LINE": _line, "ARC": _arc, "ELLIPSE": _ellipse, "LWPOLYLINE": _lwpolyline}


def _chain(pieces: list[_Piece]) -> list[_Piece]:
    """Order and orient the pieces into one open chain starting on the axis."""
    # Cluster ends into joints (tolerance JOIN_TOL_MM); few pieces, so O(n^2) is fine.
    joints: list[tuple[float, float]] = []

    def joint_of(p):
        for i, q in enumerate(joints):
            if math.dist(p, q) <= JOIN_TOL_MM:
                return i
        joints.append(p)
        return len(joints) - 1
    ends = [(joint_of(p.p0), joint_of(p.p1)) for p in pieces]
    touching: dict[int, list[int]] = {}
    for k, (i, j) in enumerate(ends):
        if i == j:
            raise DxfImportError(f"entity {pieces[k].handle} is closed on itself")
        touching.setdefault(i, []).append(k)
        touching.setdefault(j, []).append(k)
    for j, ks in touching.items():
        if len(ks) > 2:
            x, y = joints[j]
            raise DxfImportError(f"the drawing branches at ({x:.4g}, {y:.4g}): "
                                 f"{len(ks)} curves meet there")
    free = [j for j, ks in touching.items() if len(ks) == 1]
    if not free:
        raise DxfImportError("the drawing is a closed loop; draw only the outer half-section "
                             "from the axis to the mouth")
    if len(free) > 2:
        shown = ", ".join(f"({joints[j][0]:.4g}, {joints[j][1]:.4g})" for j in free[:4])
        raise DxfImportError(f"the drawing has gaps: loose ends at {shown}")
    on_axis = [j for j in free if abs(joints[j][0]) <= JOIN_TOL_MM]
    if not on_axis:
        shown = " and ".join(f"({joints[j][0]:.4g}, {joints[j][1]:.4g})" for j in free)
        raise DxfImportError(f"neither end of the section lies on the axis x = 0 (ends at {shown})")
    # If both ends are on the axis (unlikely), start from the lower one.
    current = min(on_axis, key=lambda j: joints[j][1])
    chain, used = [], set()
    while True:
        nxt = [k for k in touching[current] if k not in used]
        if not nxt:
            break
        k = nxt[0]
        used.add(k)
        forward = ends[k][0] == current
        chain.append(pieces[k] if forward else pieces[k].reversed())
        current = ends[k][1] if forward else ends[k][0]
    if len(used) != len(pieces):  # a separate closed loop elsewhere in the drawing
        raise DxfImportError(f"{len(pieces) - len(used)} curve(s) are not connected to the section")
    return chain


def _snap_lines(segs: list) -> list:
    # Lines take their neighbours' exact end points so joints close to the last bit.
    out = list(segs)
    for i, s in enumerate(out):
        if isinstance(s, Line):
            p0 = (0.0, s.p0[1]) if i == 0 else out[i - 1].p1
            p1 = out[i + 1].p0 if i + 1 < len(out) else s.p1
            out[i] = Line(p0, p1)
    return out
