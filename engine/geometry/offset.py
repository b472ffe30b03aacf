"""Inner sections and the derived body profile: the wall offset inwards, clipped at the inner base.

Design rule: pure functions of segments and thicknesses (mm). A section splits at the *standing
ring* (where it first reaches z = 0, :func:`split_at_ring`) into the **base part** (axis -> ring) and
the **wall part** (ring -> mouth). The inner wall is the wall part offset inwards in its own
(r, z) plane (SPEC 4.2: ``P(t) - w n(t)``) and clipped where it meets the inner base; the inner
base is the base part offset by ``base_thickness`` (flat base: exactly the plane
``z = base_thickness`` of the SPEC; punt: a raised dome). :class:`BodyProfile` gathers these
curves per named section for the tracer, tessellator and capacity code. This module knows
nothing of validation: :func:`engine.geometry.validate.body_profile` validates a shape first and
caches its profile per shape (shapes are hashable values).
"""
from __future__ import annotations

import math
import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import SectionError, WallError
from .crosssection import CrossSection, cross_section_of
from .chain import Z_TOL_MM, by_segment, locate, param_at_z, radius_at, subsegment
from .segments import Arc, EllipseArc, Line, Segment
from .shape import BottleShape

__all__ = ["BodyProfile", "SectionProfile", "Z_TOL_MM", "build_body_profile", "by_segment",
           "clip_from_z", "inner_section", "is_flat_base", "locate", "offset_chain", "param_at_z",
           "radius_at", "split_at_ring", "subsegment"]

#: Distance (mm) under which two points are the same joint.
JOINT_TOL_MM = 1e-9


# --------------------------------------------------------------------------- base / wall split
def split_at_ring(section):
    """``(base, wall, k)``: ``section`` cut at its standing ring, the first place it reaches z = 0.

    The ring is a joint at z = 0, or the lowest point of an arc / ellipse arc that touches z = 0
    inside (as a drawn heel often does); that segment is then split there. ``k`` is the section
    index of ``wall[0]``: ``wall[i]`` is (part of) segment ``k + i``, ``base[i]`` (part of)
    segment ``i``. A SPEC section gives ``k = 1``. ``SectionError`` when z = 0 is never reached.
    """
    segs = section.segments
    for i, s in enumerate(segs[:-1]):
        if abs(s.p1[1]) <= Z_TOL_MM:
            return segs[:i + 1], segs[i + 1:], i + 1
        if isinstance(s, (Arc, EllipseArc)):
            d = ((-math.pi / 2 - s.angle0) * math.copysign(1.0, s.sweep)) % (2 * math.pi)
            if 1e-9 < d < abs(s.sweep) - 1e-9 and abs(float(s.point(d / abs(s.sweep))[1])) <= Z_TOL_MM:
                t = d / abs(s.sweep)
                return segs[:i] + (subsegment(s, 0.0, t),), (subsegment(s, t, 1.0),) + segs[i + 1:], i
    raise SectionError(0, "the base never reaches the standing plane z = 0 before the finish")


# --------------------------------------------------------------------------- offsetting
def _offset(seg: Segment, w: float, index: int) -> Segment:
    try:  # Arc.offset raises SectionError for a radius <= 0: here that is the wall's fault
        return seg.offset(w)
    except SectionError as exc:
        raise WallError(f"segment {index}: {w:g} mm of glass is too thick for this arc ({exc})") from None


def _crossing(a: Segment, b: Segment):
    """Parameters ``(ta, tb)`` where ``a`` and ``b`` cross (the crossing nearest their joint),
    or ``None``: exact for two lines; otherwise chords of 128 pieces each, then Newton on
    ``a(ta) = b(tb)``."""
    if isinstance(a, Line) and isinstance(b, Line):
        return _line_crossing(a, b)
    t = np.linspace(0.0, 1.0, 129)
    pa, pb = a.point(t), b.point(t)
    da, db = np.diff(pa, axis=0)[:, None, :], np.diff(pb, axis=0)[None, :, :]
    c = pb[None, :-1, :] - pa[:-1, None, :]
    cross = lambda x, y: x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0]
    den = cross(da, db)
    with np.errstate(divide="ignore", invalid="ignore"):
        sa, sb = cross(c, db) / den, cross(c, da) / den
    hit = (den != 0) & (sa >= 0) & (sa <= 1) & (sb >= 0) & (sb <= 1)
    if not hit.any():
        return None
    i, j = np.nonzero(hit)
    ta_all, tb_all = (i + sa[i, j]) / 128.0, (j + sb[i, j]) / 128.0
    k = int(np.argmax(ta_all - tb_all))
    ta, tb, h = float(ta_all[k]), float(tb_all[k]), 1e-7
    for _ in range(30):  # Newton with central differences on a(ta) - b(tb) = 0
        f = a.point(ta) - b.point(tb)
        ja = (a.point(min(ta + h, 1.0)) - a.point(max(ta - h, 0.0))) / (min(ta + h, 1.0) - max(ta - h, 0.0))
        jb = (b.point(min(tb + h, 1.0)) - b.point(max(tb - h, 0.0))) / (min(tb + h, 1.0) - max(tb - h, 0.0))
        det = jb[0] * ja[1] - ja[0] * jb[1]
        if det == 0 or math.hypot(*f) < 1e-13:
            break
        ta = min(max(ta - (jb[0] * f[1] - f[0] * jb[1]) / det, 0.0), 1.0)
        tb = min(max(tb - (ja[0] * f[1] - ja[1] * f[0]) / det, 0.0), 1.0)
    return ta, tb


def _line_crossing(a: Line, b: Line):
    """Parameters ``(ta, tb)`` where two lines cross inside both, or ``None`` (parallel, apart)."""
    (ar, az), (br, bz) = a.p0, b.p0
    dar, daz = a.p1[0] - ar, a.p1[1] - az
    dbr, dbz = b.p1[0] - br, b.p1[1] - bz
    den = dar * dbz - daz * dbr
    if den == 0.0:
        return None
    cr, cz = br - ar, bz - az
    ta, tb = (cr * dbz - cz * dbr) / den, (cr * daz - cz * dar) / den
    if not (0.0 <= ta <= 1.0 and 0.0 <= tb <= 1.0):
        return None
    return ta, tb


def _join(a: Segment, b: Segment, corner, w_equal: float | None, index: int):
    """Join consecutive offset segments ``a``, ``b``: returns ``(a', bridge, b')``. Where they
    meet nothing changes; where they cross (inside a convex corner) both are trimmed there; a gap
    is bridged by the exact arc of radius ``w`` about the corner (equal walls), else by a line,
    or, where a thicker wall leaves ``b`` starting below ``a``'s end, by cutting ``b`` at that
    height and stepping across level."""
    (ar, az), (br, bz) = a.p1, b.p0
    gap = math.hypot(ar - br, az - bz)
    if gap <= 1e-5:  # tangent to 1e-6 rad (validation) times a sane wall: a tiny level step
        if bz < az and a.p0[1] < bz:  # a rising wall: cut a at b's height so nothing descends
            a = subsegment(a, 0.0, float(param_at_z(a, bz)))
        return a, ((Line(a.p1, b.p0),) if math.dist(a.p1, b.p0) > JOINT_TOL_MM else ()), b
    hit = _crossing(a, b)
    if hit is not None and 1e-12 < hit[0] and hit[1] < 1 - 1e-12:
        a2, b2 = subsegment(a, 0.0, hit[0]), subsegment(b, hit[1], 1.0)
        gap = math.hypot(a2.p1[0] - b2.p0[0], a2.p1[1] - b2.p0[1])
        return a2, ((Line(a2.p1, b2.p0),) if gap > JOINT_TOL_MM else ()), b2
    if w_equal is not None and abs(math.hypot(ar - corner[0], az - corner[1]) - w_equal) < 1e-6:
        turn = (ar - corner[0]) * (bz - corner[1]) - (az - corner[1]) * (br - corner[0])
        return a, (Arc(corner, w_equal, a.p1, b.p0, "ccw" if turn > 0 else "cw"),), b
    if bz >= az:
        return a, (Line(a.p1, b.p0),), b
    if w_equal is None and max(b.p0[1], b.p1[1]) > az + JOINT_TOL_MM:
        b2 = subsegment(b, float(param_at_z(b, az)), 1.0)
        return a, (Line(a.p1, b2.p0),), b2
    raise WallError(f"segment {index}: the inner wall folds over itself at this joint "
                    f"(wall too thick for the corner or for the change of thickness)")


def offset_chain(segments, walls, first_index: int = 0) -> tuple[Segment, ...]:
    """Offset a chain of segments inwards by ``walls`` (one thickness per segment, mm) and join it.

    See :func:`_join` for what happens at joints. ``first_index`` is the index of
    ``segments[0]`` in its section, used in error messages.
    """
    offs = [_offset(s, w, first_index + i) for i, (s, w) in enumerate(zip(segments, walls))]
    out: list[Segment] = [offs[0]]
    for i in range(1, len(offs)):
        w_eq = walls[i] if abs(walls[i] - walls[i - 1]) < 1e-12 else None
        a, bridge, b = _join(out[-1], offs[i], segments[i].p0, w_eq, first_index + i)
        out[-1:] = [a, *bridge, b]
    return tuple(out)


def clip_from_z(segments, z_clip: float, what: str = "inner wall") -> tuple[Segment, ...]:
    """The part of a z-rising chain above ``z_clip`` (mm); the first piece is a sub-segment."""
    if segments[0].p0[1] <= z_clip + Z_TOL_MM:
        for i, s in enumerate(segments):
            if s.p0[1] >= z_clip - 1e-12:  # starts at the clip height (within rounding)
                return tuple(segments[i:])
            t = float(param_at_z(s, z_clip)) if s.p1[1] > z_clip + 1e-12 else 1.0
            if t < 1.0 - 1e-13:
                return (subsegment(s, t, 1.0),) + tuple(segments[i + 1:])
    raise WallError(f"the {what} does not span the height {z_clip:g} mm "
                    f"(it runs from {segments[0].p0[1]:g} mm to {segments[-1].p1[1]:g} mm)")


def inner_section(section, wall, z_ib: float) -> tuple[Segment, ...]:
    """The inner wall curve of ``section``, from the inner base height up to the mouth.

    Parameters
    ----------
    section : Section
        A valid section (its wall part starts at the ring, :func:`split_at_ring`).
    wall : float or sequence of float
        Wall thickness (mm), or one per wall segment.
    z_ib : float
        Inner base height (mm) where the offset wall is clipped.

    Returns
    -------
    tuple of Segment
        A z-rising chain of ``Line`` / ``Arc`` / ``OffsetEllipseArc`` (each wall segment moved
        ``P - w n``, joints trimmed or bridged) from height ``z_ib`` to ``section.z_top``.
    """
    _, wall_segs, k = split_at_ring(section)
    walls = [float(wall)] * len(wall_segs) if np.ndim(wall) == 0 else [float(w) for w in wall]
    if len(walls) != len(wall_segs):
        raise WallError(f"{len(walls)} wall thicknesses given for {len(wall_segs)} wall segments")
    return clip_from_z(offset_chain(wall_segs, walls, k), float(z_ib))


# --------------------------------------------------------------------------- body profile
@dataclass(frozen=True)
class SectionProfile:
    """One named section split into its four curves (all in its own (r, z) plane, mm).

    ``outer_base`` runs from the axis to the standing ring (z = 0); ``outer_wall`` from the ring
    to the mouth (z rising strictly); ``inner_base`` from the axis to the foot of the inner wall
    (flat base: one ``Line`` at ``z = base_thickness``); ``inner_wall`` from there to the mouth
    (z rising). ``inner_base[-1].p1`` coincides with ``inner_wall[0].p0`` to 1e-9 mm.
    """

    name: str
    outer_base: tuple[Segment, ...]
    outer_wall: tuple[Segment, ...]
    inner_base: tuple[Segment, ...]
    inner_wall: tuple[Segment, ...]

    @property
    def r_top(self) -> float:  # outer radius at the mouth, mm
        return self.outer_wall[-1].p1[0]

    @property
    def r_in_top(self) -> float:  # inner radius at the mouth (the rim's inner edge), mm
        return self.inner_wall[-1].p1[0]


@dataclass(frozen=True)
class BodyProfile:
    """The derived curves of a whole bottle, for the tracer, tessellator and capacity code.

    ``sections`` follow ``engine.geometry.shape.SECTION_NAMES[cross_section]`` order. ``z_ib`` is the
    lowest height of the cavity (mm): the inner base plane ``base_thickness`` for a flat base,
    the foot of the inner wall for a punt. ``z_top`` is the mouth (mm). ``punt`` says whether the
    base rises into the bottle (round bottles only). ``rotation_deg`` turns non-round bottles.
    ``xs`` is the shape's :class:`~engine.geometry.crosssection.CrossSection` (the one to ask for
    areas, boundaries and distances of the sections' radii).
    """

    cross_section: str
    sections: tuple[SectionProfile, ...]
    z_ib: float
    z_top: float
    punt: bool
    rotation_deg: float = 0.0
    xs: CrossSection | None = None

    def section(self, name: str) -> SectionProfile:
        """The profile of the section called ``name`` (``KeyError`` if there is none)."""
        return {s.name: s for s in self.sections}[name]

    @property
    def r_top(self) -> float:  # outer radius of the (round) mouth, mm
        radii = [s.r_top for s in self.sections]
        return self.xs.round_radius(radii) if self.xs is not None else radii[0]


def is_flat_base(section) -> bool:
    """True when the base part is the SPEC flat base: one horizontal line at z = 0."""
    base = split_at_ring(section)[0]
    return (len(base) == 1 and isinstance(base[0], Line)
            and max(abs(base[0].p0[1]), abs(base[0].p1[1])) <= Z_TOL_MM)


def _punt_junction(inner_base, inner_wall_full, name):
    """Where the raised inner base meets the inner wall: ``(segment index, t, z)``.

    Walks the inner base outwards until it reaches the inner wall's radius at its height
    (a point below the inner wall's start counts as outside), then narrows the crossing by
    sampling it 64 times finer per step (vectorised: a few calls instead of 60 bisections,
    since every call of the wall's radius has a fixed cost).
    """
    z_start = inner_wall_full[0].p0[1]

    def outside(p):  # rho - r_in(z) >= 0, vectorised over points (..., 2)
        r_in = radius_at(inner_wall_full, np.maximum(p[..., 1], z_start))
        return (p[..., 1] < z_start) | (p[..., 0] >= r_in)

    t = np.linspace(0.0, 1.0, 65)
    if outside(inner_base[0].point(0.0)):
        raise WallError(f"{name} section: the inner base does not reach the axis inside the inner "
                        "wall (base or wall too thick)")
    for m, seg in enumerate(inner_base):
        hit = np.nonzero(outside(seg.point(t)))[0]
        if len(hit):
            lo, hi = t[hit[0] - 1], t[hit[0]]  # hit[0] > 0: t = 0 was inside (the previous end)
            for _ in range(10):  # each step 64x narrower: past float64 resolution after 10
                ts = np.linspace(lo, hi, 65)
                k = int(np.argmax(outside(seg.point(ts))[1:])) + 1  # the first sample outside
                lo, hi = ts[k - 1], ts[k]
                if hi - lo <= 1e-16:
                    break
            tj = 0.5 * (lo + hi)
            return m, tj, float(seg.point(tj)[1])
    raise WallError(f"{name} section: the inner base never meets the inner wall "
                    "(base thickness too small for the punt)")


def shifted(seg: Segment, dr: float) -> Segment:
    """``seg`` moved by ``dr`` mm along r (a translation, not an offset: shape unchanged)."""
    moved = {"p0": (seg.p0[0] + dr, seg.p0[1]), "p1": (seg.p1[0] + dr, seg.p1[1])}
    if not isinstance(seg, Line):
        moved["center"] = (seg.center[0] + dr, seg.center[1])
    return dataclasses.replace(seg, **moved)


def _outline_profile(shape: BottleShape) -> BodyProfile:
    """The :class:`BodyProfile` of an ``outline`` bottle (SPEC_outline 5): its inner section is
    the plan offset at the same height, core ``k`` and growth ``c - w``, so the inner walls are
    the core's wall and the rounding's wall moved by ``-w`` along r (not offset), both from the
    inner base plane up. The growth may be negative (sharp inner corners)."""
    bt, w = shape.base_thickness, shape.wall_thickness
    profiles = []
    for name, sec in shape.sections:
        base, wall, _ = split_at_ring(sec)
        moved = wall if name == "core" else tuple(shifted(s, -w) for s in wall)
        inner_wall = clip_from_z(moved, bt)
        inner_base = (Line((0.0, bt), (max(inner_wall[0].p0[0], 0.0), bt)),)
        profiles.append(SectionProfile(name, tuple(base), tuple(wall), inner_base, tuple(inner_wall)))
    return BodyProfile(shape.cross_section, tuple(profiles), float(bt), float(shape.z_top), False,
                       shape.rotation_deg, cross_section_of(shape))


def build_body_profile(shape: BottleShape) -> BodyProfile:
    """The :class:`BodyProfile` of ``shape``, not validated first (see
    :func:`engine.geometry.validate.body_profile`);
    raises ``WallError`` / ``SectionError`` on what it cannot build."""
    if shape.cross_section == "outline":
        return _outline_profile(shape)
    bt = shape.base_thickness
    flat = all(is_flat_base(sec) for _, sec in shape.sections)
    profiles = []
    z_ib = bt
    for name, sec in shape.sections:
        base, wall, k = split_at_ring(sec)
        walls = shape.wall_per_segment if shape.wall_per_segment is not None else shape.wall_thickness
        walls = [float(walls)] * len(wall) if np.ndim(walls) == 0 else list(walls)
        if len(walls) != len(wall):
            raise WallError(f"{len(walls)} wall thicknesses given for {len(wall)} wall segments")
        full = offset_chain(wall, walls, k)
        if flat:
            inner_wall = clip_from_z(full, bt)
            inner_base = (Line((0.0, bt), inner_wall[0].p0),)
        else:
            base_off = offset_chain(base, [bt] * len(base), 0)
            (re, ze), r_wall = base_off[-1].p1, float(radius_at(full, base_off[-1].p1[1]))
            if re < r_wall:  # ends inside the inner wall (thinner wall): go on level, as a flat base
                base_off += (Line((re, ze), (r_wall, ze)),)
            m, tj, z_ib = _punt_junction(base_off, full, name)
            inner_wall = clip_from_z(full, z_ib)
            inner_base = base_off[:m] + ((subsegment(base_off[m], 0.0, tj),) if tj > 1e-12 else ())
        profiles.append(SectionProfile(name, tuple(base), tuple(wall), tuple(inner_base), tuple(inner_wall)))
    return BodyProfile(shape.cross_section, tuple(profiles), float(z_ib), float(shape.z_top),
                       not flat, shape.rotation_deg, cross_section_of(shape))
