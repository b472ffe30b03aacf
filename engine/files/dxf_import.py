"""DXF drawings of a bottle's half-section -> :class:`engine.geometry.section.Section`.

Design rule: the drawing's x is the radius ``r`` and its y the height ``z`` (mm after the
``$INSUNITS`` scale; a drawing that does not declare its units, or declares them unitless, is in
mm). LINE, ARC, ELLIPSE (axis-aligned) and LWPOLYLINE (with bulges) are
turned into pieces with two ends; the pieces must form one open chain (no gaps, no branches,
no loops) with one end on the axis ``r = 0``. The chain is walked from that end to the
other (the mouth), each piece oriented to the walking direction: a DXF arc always runs
counter-clockwise from its start to its end angle, so walked backwards it becomes a ``"cw"``
arc. The drawing is shifted in z so that its lowest point (the axis end of a flat base, the
standing ring of a punt) is at z = 0; the axis end gets r = 0 exactly; a drawing on the left
of the axis (x <= 0) is mirrored. Text, dimensions and points are ignored; any other entity is
an error.

Ends closer than ``JOIN_TOL_MM`` are one joint (found through a grid of that cell size, so the
import is linear in the drawing). At a joint a curve keeps its exact end and a line takes it; a
line within ``JOIN_TOL_MM`` of horizontal or vertical is made exactly so (a base or a finish
drawn a hair off). Smoothness comes from the drawing: a joint whose tangent turns by no more
than :data:`engine.geometry.validate.ANGLE_TOL_RAD` is smooth, any other is a corner the section
keeps. Input is bounded before work starts: the file's size, :data:`engine.limits.MAX_SEGMENTS`
curves, and coordinates within :data:`engine.limits.MAX_EXTENT_MM`. Whether the section is a
valid bottle is :mod:`engine.geometry.validate`'s business.

The reading, the pieces, the joints and the walk are public for :mod:`engine.files.dxf_plan`,
which reads a closed plan outline with them.
"""
from __future__ import annotations

import contextlib
import math
import os

from ..errors import GlassbenchError, InputFileError, bounded
from ..io.read import read_bounded
from ..geometry.section import Section
from ..geometry.segments import Arc, EllipseArc, Line
from ..geometry.validate import ANGLE_TOL_RAD
from ..limits import MAX_EXTENT_MM, MAX_SEGMENTS

#: Ends closer than this (mm) are one joint; farther apart they are a gap.
JOIN_TOL_MM = 1e-4
#: Relative tolerance for "axis-aligned" ellipses (major axis direction).
AXIS_TOL = 1e-9
#: mm per drawing unit for the DXF ``$INSUNITS`` codes we accept (0 = unitless: mm).
UNIT_SCALE = {0: 1.0, 1: 25.4, 2: 304.8, 4: 1.0, 5: 10.0, 6: 1000.0}
#: Entities that carry no geometry of the section.
IGNORED = {"TEXT", "MTEXT", "DIMENSION", "LEADER", "MLEADER", "POINT", "HATCH"}
#: Largest DXF file read (bytes): a section of MAX_SEGMENTS curves is a few hundred kB, and
#: ezdxf parses about 2 MB a second on a shared core before any curve can be counted.
MAX_DXF_BYTES = 16 << 20


class DxfImportError(GlassbenchError, ValueError):
    """A DXF file that cannot be turned into one section; the message says why and where."""


def section_from_dxf(path: str | os.PathLike) -> Section:
    """Read ``path`` and return its section (mm), walked from the axis to the mouth.

    Raises ``DxfImportError`` for unreadable, truncated or oversized files, unsupported entities
    or units, rotated ellipses, gaps, branches, loops or a drawing too large for a bottle; a
    fault of the drawing is named after the file (``"PATH: the drawing has gaps ..."``).
    """
    doc, declares_units = read_document(path, "a bottle section")
    with named_after(path):
        return section_from_document(doc, declares_units)


def read_document(path: str | os.PathLike, what: str):
    """``(doc, declares_units)``: the ``ezdxf`` document of ``path`` (at most ``MAX_DXF_BYTES``)
    and whether it holds ``$INSUNITS``. ``DxfImportError`` naming the file for a file that is
    missing, not regular, too large, truncated or damaged (``what`` the file should have been)."""
    import ezdxf
    path = os.fspath(path)
    try:
        try:
            declares_units = b"$INSUNITS" in read_bounded(path, MAX_DXF_BYTES, "DXF")
        except InputFileError as exc:
            raise DxfImportError(f"{exc}: not {what}") from None
        doc = ezdxf.readfile(path)
    except DxfImportError:
        raise
    except (StopIteration, EOFError):
        raise DxfImportError(f"cannot read DXF {path}: the file ends before the drawing does "
                             f"(truncated?)") from None
    except Exception as exc:  # why: ezdxf raises anything on a damaged file
        detail = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
        raise DxfImportError(f"cannot read DXF {path}: {detail}") from None
    return doc, declares_units


@contextlib.contextmanager
def named_after(path: str | os.PathLike):
    """Prefix the message of a ``DxfImportError`` raised inside with the file's path: a command
    reading two drawings must say which one is wrong."""
    try:
        yield
    except DxfImportError as exc:
        raise DxfImportError(f"{os.fspath(path)}: {exc}") from None


def drawing_scale(doc, declares_units: bool = True) -> float:
    """mm per drawing unit from ``$INSUNITS`` (a file without it, or unitless, is in mm)."""
    units = doc.header.get("$INSUNITS", 0) if declares_units else 0
    if units not in UNIT_SCALE:
        raise DxfImportError(f"unsupported drawing units ($INSUNITS = {bounded(str(units), 40)}); "
                             f"use mm, cm, m or in")
    return UNIT_SCALE[units]


def check_reach(pieces) -> None:
    """Refuse pieces (mm) reaching beyond ``MAX_EXTENT_MM`` from the origin (wrong units?)."""
    reach = max(max(abs(v) for v in p.p0 + p.p1) for p in pieces)
    if reach > MAX_EXTENT_MM:
        raise DxfImportError(f"the drawing reaches {reach:.6g} mm from its origin; a bottle fits "
                             f"within {MAX_EXTENT_MM:g} mm (are the drawing's units right?)")


def section_from_document(doc, declares_units: bool = True) -> Section:
    """The section drawn in an ``ezdxf`` document's model space (see :func:`section_from_dxf`).

    ``declares_units`` says whether the file held ``$INSUNITS`` (ezdxf fills in metres for a
    file without a HEADER); without it the drawing is in mm.
    """
    scale = drawing_scale(doc, declares_units)
    pieces = drawn_pieces(doc)
    mirror = -1.0 if all(max(p.p0[0], p.p1[0]) <= JOIN_TOL_MM / scale for p in pieces) else 1.0
    pieces = [p.transformed(scale, mirror, 0.0) for p in pieces]
    check_reach(pieces)
    chain = _snap_joints(_chain(pieces))
    # Stand the bottle on z = 0: its lowest point (the axis end, or the ring of a punt).
    z_low = min(_lowest_z(p.segment()) for p in chain)
    segs = [p.transformed(1.0, 1.0, -z_low).segment() for p in chain]
    return Section(tuple(segs), _drawn_smoothness(segs))


def drawn_pieces(doc, kinds=("LINE", "ARC", "ELLIPSE", "LWPOLYLINE"), what: str = "a section",
                 most: int = MAX_SEGMENTS) -> list:
    """Every curve of the model space as a ``Piece`` (drawing units); at most ``most``.

    ``kinds`` are the entity types ``what`` may be drawn with (text and dimensions are ignored,
    anything else is refused naming its handle)."""
    pieces = []
    for entity in doc.modelspace():
        kind = entity.dxftype()
        if kind in IGNORED:
            continue
        maker = _MAKERS.get(kind) if kind in kinds else None
        if maker is None:
            raise DxfImportError(f"unsupported DXF entity {kind} (handle {entity.dxf.handle}) in "
                                 f"{what}; use {', '.join(kinds[:-1])} or {kinds[-1]}")
        try:
            made = maker(entity)
        except DxfImportError:
            raise
        except Exception as exc:  # why: a damaged entity fails inside ezdxf in any way
            raise DxfImportError(f"entity {kind} {entity.dxf.get('handle', '?')} is damaged: "
                                 f"{str(exc) or type(exc).__name__}") from None
        for piece in made:
            if not all(math.isfinite(v) for v in piece.numbers()):
                raise DxfImportError(f"entity {piece.handle} has a coordinate that is not a finite number")
        pieces.extend(made)
        if len(pieces) > most:
            raise DxfImportError(f"the drawing holds more than {most} curves; {what} "
                                 f"holds at most {most} segments (join short lines into arcs)")
    if not pieces:
        names = [_PLURAL[k] for k in kinds]
        raise DxfImportError(f"the drawing holds no {', '.join(names[:-1])} or {names[-1]}")
    return pieces


def _drawn_smoothness(segs) -> tuple[bool, ...]:
    """Per joint: smooth where the drawing's tangent turns by at most ``ANGLE_TOL_RAD``."""
    flags = []
    for a, b in zip(segs, segs[1:]):
        ta, tb = a.tangent(1.0), b.tangent(0.0)
        turn = math.atan2(float(ta[0] * tb[1] - ta[1] * tb[0]), float(ta[0] * tb[0] + ta[1] * tb[1]))
        flags.append(abs(turn) <= ANGLE_TOL_RAD)
    return tuple(flags)


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


class Piece:
    """One drawn curve with its two ends; ``segment()`` builds it walked from p0 to p1."""

    def __init__(self, kind, p0, p1, center=None, radii=None, direction="ccw", handle="?"):
        self.kind, self.p0, self.p1 = kind, tuple(p0), tuple(p1)
        self.center, self.radii, self.direction, self.handle = center, radii, direction, handle

    def numbers(self) -> tuple:
        """Every coordinate and radius of the piece (for the finiteness check)."""
        return self.p0 + self.p1 + tuple(self.center or ()) + tuple(self.radii or ())

    def with_ends(self, p0, p1) -> "Piece":
        """The same curve between other end points (lines at snapped joints)."""
        return Piece(self.kind, p0, p1, self.center, self.radii, self.direction, self.handle)

    def reversed(self) -> "Piece":
        flip = {"ccw": "cw", "cw": "ccw"}[self.direction]
        return Piece(self.kind, self.p1, self.p0, self.center, self.radii, flip, self.handle)

    def transformed(self, scale: float, mirror: float, dz: float) -> "Piece":
        """Scale about the origin, mirror r by ``mirror`` (+-1), then shift z by ``dz`` (mm)."""
        def f(p):
            return None if p is None else (mirror * scale * p[0], scale * p[1] + dz)
        radii = None if self.radii is None else tuple(scale * r for r in self.radii)
        direction = self.direction if mirror > 0 else {"ccw": "cw", "cw": "ccw"}[self.direction]
        return Piece(self.kind, f(self.p0), f(self.p1), f(self.center), radii, direction, self.handle)

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
    return [Piece("line", s, e, handle=entity.dxf.handle)]


def _arc(entity):
    sign = _orientation(entity)
    # start_point / end_point are in world coordinates; the OCS centre needs mapping.
    c = _xy(entity.ocs().to_wcs(entity.dxf.center))
    piece = Piece("arc", _xy(entity.start_point), _xy(entity.end_point), c,
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
    return [Piece("ellipse", _xy(entity.start_point), _xy(entity.end_point),
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
            out.append(Piece("line", wa, wb, handle=entity.dxf.handle))
            continue
        theta = 4.0 * math.atan(bulge)  # signed included angle, > 0 counter-clockwise (OCS)
        radius = chord / (2.0 * abs(math.sin(theta / 2.0)))
        nx, ny = -(b[1] - a[1]) / chord, (b[0] - a[0]) / chord  # left of a -> b
        off = (chord / 2.0) / math.tan(theta / 2.0)
        c = ((a[0] + b[0]) / 2 + nx * off, (a[1] + b[1]) / 2 + ny * off)
        wc = _xy(ocs.to_wcs((c[0], c[1], 0.0)))
        ccw = (theta > 0) == (sign > 0)
        out.append(Piece("arc", wa, wb, wc, (radius,), "ccw" if ccw else "cw", entity.dxf.handle))
    return out


_MAKERS = {"LINE": _line, "ARC": _arc, "ELLIPSE": _ellipse, "LWPOLYLINE": _lwpolyline}
_PLURAL = {"LINE": "lines", "ARC": "arcs", "ELLIPSE": "ellipses", "LWPOLYLINE": "polylines"}


def joints_of(pieces: list[Piece]) -> tuple[list, list, dict]:
    """``(joints, ends, touching)``: the pieces' ends clustered into joints (ends closer than
    ``JOIN_TOL_MM`` are one), each piece's two joint numbers, and per joint the pieces touching
    it. Refuses a piece closed on itself and a joint where more than two pieces meet."""
    # A grid of cell size JOIN_TOL_MM: each end looks at its own and the 8 neighbouring cells
    # only, so this is linear in the ends.
    joints: list[tuple[float, float]] = []
    grid: dict[tuple[int, int], list[int]] = {}

    def joint_of(p):
        cx, cy = math.floor(p[0] / JOIN_TOL_MM), math.floor(p[1] / JOIN_TOL_MM)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for i in grid.get((cx + dx, cy + dy), ()):
                    if math.dist(p, joints[i]) <= JOIN_TOL_MM:
                        return i
        joints.append(p)
        grid.setdefault((cx, cy), []).append(len(joints) - 1)
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
    return joints, ends, touching


def walk(pieces: list[Piece], ends: list, touching: dict, start: int) -> list[Piece]:
    """The pieces connected to joint ``start`` (of :func:`joints_of`), walked from it along the
    lowest-numbered piece there, each oriented to the walking direction; it stops at a loose end
    or back at ``start``. (So from the start of piece 0 the walk runs along piece 0 first.)"""
    chain, used, current = [], set(), start
    while True:
        nxt = [k for k in touching[current] if k not in used]
        if not nxt:
            return chain
        k = nxt[0]
        used.add(k)
        forward = ends[k][0] == current
        chain.append(pieces[k] if forward else pieces[k].reversed())
        current = ends[k][1] if forward else ends[k][0]


def _chain(pieces: list[Piece]) -> list[Piece]:
    """Order and orient the pieces into one open chain starting on the axis."""
    joints, ends, touching = joints_of(pieces)
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
    chain = walk(pieces, ends, touching, min(on_axis, key=lambda j: joints[j][1]))
    if len(chain) != len(pieces):  # a separate closed loop elsewhere in the drawing
        raise DxfImportError(f"{len(pieces) - len(chain)} curve(s) are not connected to the section")
    return chain


def meeting_point(before: Piece | None, after: Piece | None) -> tuple[tuple[float, float], bool]:
    """``(point, fixed)``: the one point (mm) of the joint where ``before`` ends and ``after``
    starts (``None`` past a chain's end). A curve keeps its exact end and fixes the joint (the
    curve before wins where two meet: validation judges their gap); between lines the mean."""
    if before is not None and before.kind != "line":
        return before.p1, True
    if after is not None and after.kind != "line":
        return after.p0, True
    if after is None:
        return before.p1, False
    if before is None:
        return after.p0, False
    return ((before.p1[0] + after.p0[0]) / 2.0, (before.p1[1] + after.p0[1]) / 2.0), False


def _snap_joints(chain: list[Piece]) -> list[Piece]:
    """One exact point per joint: a curve's own end where a curve meets it, else the lines'
    mean; lines within ``JOIN_TOL_MM`` of horizontal or vertical made exactly so; the axis end
    at r = 0. Where two curves meet each keeps its end (validation judges the gap)."""
    n = len(chain)
    met = [meeting_point(chain[k - 1] if k > 0 else None, chain[k] if k < n else None) for k in range(n + 1)]
    pts, fixed = [list(p) for p, _ in met], [f for _, f in met]
    if not fixed[0]:
        pts[0][0] = 0.0
    locked = [[f, f] for f in fixed]  # per joint: r, z may no longer move
    locked[0][0] = True
    for k, piece in enumerate(chain):
        if piece.kind != "line":
            continue
        for axis in (1, 0):  # 1: near-horizontal (equal z), 0: near-vertical (equal r)
            a, b = pts[k], pts[k + 1]
            if abs(a[axis] - b[axis]) > JOIN_TOL_MM or abs(a[1 - axis] - b[1 - axis]) <= JOIN_TOL_MM:
                continue
            la, lb = locked[k][axis], locked[k + 1][axis]
            if not (la and lb):
                v = a[axis] if la else b[axis] if lb else (a[axis] + b[axis]) / 2.0
                a[axis] = b[axis] = v
                locked[k][axis] = locked[k + 1][axis] = True
    out = []
    for k, piece in enumerate(chain):
        out.append(piece.with_ends(tuple(pts[k]), tuple(pts[k + 1])) if piece.kind == "line" else piece)
    return out
