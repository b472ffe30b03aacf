"""Outline (free plan) bodies as solids: exact planes, cylinders, cones and tori where the
profiles allow it, B-spline patches within the tolerance elsewhere.

Design rule: the section at height ``z`` is the plan ``P`` scaled by the core ``k(z)`` and grown
by the rounding ``r(z)`` (the outer wall's ``c``, the cavity's ``c - w``); its boundary is one
piece per segment of ``P`` (a line moved out, an arc of radius ``k rho + r``) and, where
``r >= 0``, a corner arc of radius ``r`` at each sharp corner of ``P``; where ``r < 0`` the pieces
meet in sharp creases instead (:meth:`engine.geometry.plan.PlanOutline.section_pieces`). A wall
is cut into bands at every joint of both profiles and where the cavity's ``r`` passes 0, so that
inside a band ``k`` and ``r`` are one profile segment each and the pieces keep their order.
Each piece of each band is one face, exact where its sweep is a known surface:

- a line piece where ``k`` and ``r`` are both straight: a plane (its corners move on lines);
- a line piece where ``k`` is constant and ``r >= 0``: ``r``'s profile segment swept along it
  (a prism: a plane, or a cylinder about a horizontal axis where ``r`` is an arc);
- an arc or corner piece whose centre and angles stay put (``k`` constant, or an arc of ``P``
  about the origin) and whose radius ``k rho + r`` is one profile segment: that segment revolved
  about the centre (a cylinder, cone or torus; the round neck, where ``k`` is 0, is one of these);
- an arc or corner piece where ``k`` and ``r`` are straight and ``r >= 0``: the ruled surface
  between its two end arcs, a rational B-spline that is exact (a circle's centre and radius
  move linearly, so each point of the arc does);
- anything else: the tensor B-spline interpolant of exact points, within a tenth of the
  tolerance (:func:`engine.export.cad_nonround.fitted_surface`).

Pieces without width over a whole band (the plan's lines in the round neck, a corner arc where
``r`` is 0) are left out; flat faces (base, cavity floor, rim, free surface) are bounded by the
section's exact lines and arcs. The faces are sewn into one solid, turned by ``rotation_deg``
(:func:`engine.export.cad_nonround.sewn_solid`). Units mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace,
                                BRepBuilderAPI_MakePolygon, BRepBuilderAPI_MakeVertex,
                                BRepBuilderAPI_MakeWire, BRepBuilderAPI_Transform)
from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism, BRepPrimAPI_MakeRevol
from OCP.Geom import Geom_BSplineSurface
from OCP.gp import gp_Ax1, gp_Ax2, gp_Circ, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.OCP.collections import Array2_double, Array2_gp_Pnt
from OCP.TopAbs import TopAbs_ShapeEnum
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from ..geometry.capacity import area_breaks  # the heights the capacity cuts at too
from ..geometry.offset import shifted
from ..geometry.outline_bands import Band, band_radii, bands
from ..geometry.segments import Line
from ..geometry.validate import body_profile
from .cad_nonround import band_heights, fitted_surface, occ_knots, radii_at, sewn_solid
from .occ_profile import CadError, pnt, segment_edge

#: A piece no wider than this (mm) anywhere in a band has vanished from it (the neck's lines).
WIDTH_EPS_MM = 1e-9
#: A radius changing by less than this (mm) over a band is constant; a corner off a straight
#: line by less than this (mm) moves on it.
STRAIGHT_MM = 1e-9
_UP = gp_Dir(0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Part:
    """One piece of the section's boundary: its place in the list of
    :meth:`~engine.geometry.plan.PlanOutline.section_pieces`, what it sweeps (``line``, ``arc``
    of ``P`` or ``corner`` of ``P``) and, for an arc or corner, the centre and radius it has in
    ``P`` (normalised; a corner's radius is 0)."""

    index: int
    kind: str
    centre: tuple | None = None
    rho: float = 0.0


def parts(plan, grown: bool) -> list[Part]:
    """The pieces of a section of ``plan``, in the order ``section_pieces`` lists them."""
    corners = {c.index: c.vertex for c in plan.corners}
    out = []
    for i, s in enumerate(plan.segments):
        if grown and i in corners:
            out.append(Part(len(out), "corner", corners[i], 0.0))
        out.append(Part(len(out), "line") if s.kind == "line"
                   else Part(len(out), "arc", s.center, s.radius))
    return out


def _along(piece, w):
    """Points ``(..., 2)`` at fraction ``w`` along a piece (lines from ``a`` to ``b``, arcs ccw)."""
    if piece[0] == "line":
        _, ax, ay, bx, by, _, _ = piece
        return np.stack(np.broadcast_arrays(ax + w * (bx - ax), ay + w * (by - ay)), -1)
    _, cx, cy, rho, a0, a1 = piece
    a = a0 + w * (a1 - a0)
    return np.stack(np.broadcast_arrays(cx + rho * np.cos(a), cy + rho * np.sin(a)), -1)


def _width(piece):
    """Length (mm) of a piece (arrays over heights)."""
    if piece[0] == "line":
        return np.hypot(piece[3] - piece[1], piece[4] - piece[2])
    return piece[3] * (piece[5] - piece[4])


def part_points(plan, band: Band, part: Part, z, w):
    """Exact wall points ``(len(w), len(z), 3)`` (mm) of ``part`` at heights ``z`` in the band
    and fractions ``w`` along it."""
    piece = plan.section_pieces(*band_radii(band, z), band.grown)[part.index]
    xy = _along(piece, np.asarray(w, float)[:, None])
    return np.concatenate([xy, np.broadcast_to(np.asarray(z, float)[None, :, None], xy.shape[:2] + (1,))], -1)


# ------------------------------------------------------------------------ exact faces
def _is_line(seg) -> bool:
    return isinstance(seg, Line)


def _is_constant(seg) -> bool:
    return _is_line(seg) and abs(seg.p1[0] - seg.p0[0]) <= STRAIGHT_MM


def exact_face(plan, band: Band, part: Part):
    """The face of ``part`` over ``band`` as an exact surface (see the module rule), or
    ``None`` where it has to be fitted."""
    k_const, straight = _is_constant(band.k), _is_line(band.k) and _is_line(band.r)
    if part.kind == "line":
        if straight and _corners_move_straight(plan, band, part):
            return _plane_face(plan, band, part)
        return _prism_face(plan, band, part) if (band.grown and k_const) else None
    about_origin = part.kind == "arc" and math.hypot(*part.centre) == 0.0
    angles_fixed = band.grown or (k_const and _is_constant(band.r))
    if (k_const or about_origin) and angles_fixed and (k_const or straight):
        return _revolved_face(plan, band, part, k_const)
    return _ruled_face(plan, band, part) if (band.grown and straight) else None


def _corners_move_straight(plan, band: Band, part: Part) -> bool:
    """Whether both ends of a line piece move on straight lines over the band (always where the
    section is grown; where it is eroded, not at a sharp joint with an arc)."""
    z = np.linspace(band.za, band.zb, 5)
    p = part_points(plan, band, part, z, np.array([0.0, 1.0]))
    f = ((z - band.za) / (band.zb - band.za))[None, :, None]
    line = p[:, :1] + f * (p[:, -1:] - p[:, :1])
    return float(np.max(np.abs(p - line))) <= STRAIGHT_MM


def _plane_face(plan, band: Band, part: Part):
    """The flat face of a line piece whose corners move on straight lines (a triangle where its
    width vanishes at one end)."""
    p = part_points(plan, band, part, np.array([band.za, band.zb]), np.array([0.0, 1.0]))
    ring = [p[0, 0], p[1, 0], p[1, 1], p[0, 1]]
    ring = [q for i, q in enumerate(ring) if np.linalg.norm(q - ring[i - 1]) > WIDTH_EPS_MM]
    poly = BRepBuilderAPI_MakePolygon()
    for q in ring:
        poly.Add(gp_Pnt(*map(float, q)))
    poly.Close()
    return _done(BRepBuilderAPI_MakeFace(poly.Wire(), True), band)


def _placed(seg, origin, angle: float):
    """The edge of the profile segment ``seg`` (radius, z; mm) standing at plan point ``origin``
    (mm) with its radius along the plan direction ``angle`` (rad)."""
    v0, v1 = (BRepBuilderAPI_MakeVertex(pnt(p)).Vertex() for p in (seg.p0, seg.p1))
    edge, _ = segment_edge(seg, v0, v1, 1.0)  # exact kinds only here: the tolerance is unused
    move, turn = gp_Trsf(), gp_Trsf()
    move.SetTranslation(gp_Vec(float(origin[0]), float(origin[1]), 0.0))
    turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), _UP), angle)
    move.Multiply(turn)  # turn first, then move
    return TopoDS.Edge(BRepBuilderAPI_Transform(edge, move, True).Shape())


def _prism_face(plan, band: Band, part: Part):
    """A line piece at constant core: the rounding's profile segment, standing at the line's
    start and facing its normal, swept along the line."""
    k0 = float(band.k.p0[0])
    _, ax, ay, bx, by, nx, ny = plan.section_pieces(np.array([k0]), np.array([0.0]), True)[part.index]
    ax, ay, bx, by = (float(np.ravel(v)[0]) for v in (ax, ay, bx, by))
    edge = _placed(band.r, (ax, ay), math.atan2(ny, nx))
    return _first_face(BRepPrimAPI_MakePrism(edge, gp_Vec(bx - ax, by - ay, 0.0)), band)


def _revolved_face(plan, band: Band, part: Part, k_const: bool):
    """An arc or corner piece about a fixed centre: its radius's profile segment revolved about
    the centre through the piece's angles."""
    z = np.array([0.5 * (band.za + band.zb)])
    piece = plan.section_pieces(*band_radii(band, z), band.grown)[part.index]
    a0, a1 = (float(np.ravel(v)[0]) for v in piece[4:6])
    if k_const:
        k0 = float(band.k.p0[0])
        centre = (k0 * part.centre[0], k0 * part.centre[1])
        meridian = shifted(band.r, k0 * part.rho)
    else:  # an arc of P about the origin, k and r straight: its radius is straight too
        centre = (0.0, 0.0)
        ends = [float(band.k.p0[0]) * part.rho + band.r.p0[0], float(band.k.p1[0]) * part.rho + band.r.p1[0]]
        meridian = Line((ends[0], band.za), (ends[1], band.zb))
    edge = _placed(meridian, centre, a0)
    axis = gp_Ax1(gp_Pnt(centre[0], centre[1], 0.0), _UP)
    return _first_face(BRepPrimAPI_MakeRevol(edge, axis, a1 - a0), band)


def arc_poles(centre, radius: float, a0: float, a1: float):
    """``(poles (n, 2), weights (n,), knots, mults)``: the circular arc about ``centre`` (mm)
    from angle ``a0`` to ``a1`` (rad, ccw) as an exact rational quadratic B-spline, in spans of at
    most 90 deg; two arcs of one sweep share weights and knots (a zero radius is a point)."""
    sweep = a1 - a0
    n = max(1, math.ceil(sweep / (0.5 * math.pi) - 1e-12))
    half = 0.5 * sweep / n
    ang = a0 + half * np.arange(2 * n + 1)
    reach = np.where(np.arange(2 * n + 1) % 2 == 1, radius / math.cos(half), radius)
    poles = np.stack([centre[0] + reach * np.cos(ang), centre[1] + reach * np.sin(ang)], -1)
    weights = np.where(np.arange(2 * n + 1) % 2 == 1, math.cos(half), 1.0)
    return poles, weights, np.linspace(0.0, 1.0, n + 1), [3] + [2] * (n - 1) + [3]


def _ruled_face(plan, band: Band, part: Part):
    """An arc or corner piece whose centre and radius move linearly (k, r straight, r >= 0):
    the rational ruled surface between its exact end arcs (degree 1 in height; both rows share
    the weights, so each point moves on a line as the section's does)."""
    z = (band.za, band.zb)
    _, cx, cy, rho, a0, a1 = plan.section_pieces(*band_radii(band, np.array(z)), True)[part.index]
    cx, cy, rho = (np.broadcast_to(v, (2,)) for v in (cx, cy, rho))
    a0, a1 = (float(np.ravel(v)[0]) for v in (a0, a1))
    rows = [arc_poles((cx[j], cy[j]), float(rho[j]), a0, a1) for j in range(2)]
    weights, knots, mults = rows[0][1:]
    n = len(weights)
    poles, w = Array2_gp_Pnt(1, n, 1, 2), Array2_double(1, n, 1, 2)
    for j, row in enumerate(rows):
        for i in range(n):
            poles.SetValue(i + 1, j + 1, gp_Pnt(float(row[0][i, 0]), float(row[0][i, 1]), z[j]))
            w.SetValue(i + 1, j + 1, float(weights[i]))
    uk, um = occ_knots(np.repeat(knots, mults))
    vk, vm = occ_knots(np.array([0.0, 0.0, 1.0, 1.0]))
    surface = Geom_BSplineSurface(poles, w, uk, vk, um, vm, 2, 1)
    return BRepBuilderAPI_MakeFace(surface, 1e-9).Face()


def _done(maker, band: Band):
    if not maker.IsDone():
        raise CadError(f"the CAD kernel cannot make an outline wall face between z {band.za:.6g} "
                       f"and {band.zb:.6g} mm")
    return maker.Face()


def _first_face(maker, band: Band):
    """The face a sweep of one edge made."""
    maker.Build()
    if not maker.IsDone():
        raise CadError(f"the CAD kernel cannot sweep an outline wall face between z {band.za:.6g} "
                       f"and {band.zb:.6g} mm")
    it = TopExp_Explorer(maker.Shape(), TopAbs_ShapeEnum.TopAbs_FACE)
    return TopoDS.Face(it.Current())


# ------------------------------------------------------------------------ walls, flat faces, solids
def part_face(plan, band: Band, part: Part, tol_mm: float):
    """``(face, deviation_mm)`` of ``part`` over ``band`` (deviation 0: exact), or ``None``
    where the piece has no width anywhere in the band."""
    z = band_heights(band.za, band.zb, np.linspace(0.0, 1.0, 33))
    probe = plan.section_pieces(*band_radii(band, z), band.grown)[part.index]
    if np.all(_width(probe) <= WIDTH_EPS_MM):
        return None
    face = exact_face(plan, band, part)
    if face is not None:
        return face, 0.0

    def grid(w, x):
        return part_points(plan, band, part, band_heights(band.za, band.zb, x), w)
    surface, dev = fitted_surface(grid, tol_mm, f"an outline wall piece between z {band.za:.6g} "
                                                f"and {band.zb:.6g} mm")
    return BRepBuilderAPI_MakeFace(surface, 1e-9).Face(), dev


def wall_faces(plan, chains, z_lo: float, z_hi: float, crossings, tol_mm: float):
    """``(faces, deviation_mm)``: the wall of core and rounding ``chains`` from ``z_lo`` to
    ``z_hi`` (mm), one face per piece per band."""
    faces, worst = [], 0.0
    for band in bands(chains, z_lo, z_hi, crossings):
        for part in parts(plan, band.grown):
            made = part_face(plan, band, part, tol_mm)
            if made is not None:
                faces.append(made[0])
                worst = max(worst, made[1])
    return faces, worst


def _ring(plan, k: float, r: float, z: float):
    """The exact closed outline (a wire) of the section with core ``k`` and rounding ``r`` at
    height ``z`` (mm)."""
    wire = BRepBuilderAPI_MakeWire()
    for piece in plan.section_pieces(np.array([max(k, 0.0)]), np.array([r]), r >= 0.0):
        if float(np.ravel(_width(piece))[0]) <= WIDTH_EPS_MM:
            continue
        v = [float(np.ravel(x)[0]) for x in piece[1:]]
        if piece[0] == "line":
            edge = BRepBuilderAPI_MakeEdge(gp_Pnt(v[0], v[1], z), gp_Pnt(v[2], v[3], z))
        else:
            circ = gp_Circ(gp_Ax2(gp_Pnt(v[0], v[1], z), _UP, gp_Dir(1.0, 0.0, 0.0)), v[2])
            edge = BRepBuilderAPI_MakeEdge(circ, v[3], v[4])
        wire.Add(edge.Edge())
        if not wire.IsDone():
            raise CadError(f"the outline's section at z {z:.6g} mm does not join up")
    return wire.Wire()


def flat_face(plan, outer, z: float, inner=None):
    """The flat face at height ``z`` (mm) inside the section of radii ``outer = (k, r)`` (less
    the inside of ``inner``: the rim)."""
    maker = BRepBuilderAPI_MakeFace(_ring(plan, *outer, z), True)
    if inner is not None:
        maker.Add(TopoDS.Wire(_ring(plan, *inner, z).Reversed()))
    if not maker.IsDone():
        raise CadError(f"the CAD kernel cannot make the outline's flat face at z {z:.6g} mm")
    return maker.Face()


def _walls(prof, which):
    return [sp.outer_wall if which == "outer" else sp.inner_wall for sp in prof.sections]


def _radii(chains, z: float):
    return tuple(float(v) for v in radii_at(chains, np.array(z)))


def outline_glass(shape, tol_mm: float):
    """``(solid, deviation_mm)``: the glass of an outline bottle."""
    prof, plan = body_profile(shape), shape.plan
    outer, inner = _walls(prof, "outer"), _walls(prof, "inner")
    top, z_ib = float(prof.z_top), float(prof.z_ib)
    f_out, d_out = wall_faces(plan, outer, 0.0, top, area_breaks(prof, "outer"), tol_mm)
    f_in, d_in = wall_faces(plan, inner, z_ib, top, area_breaks(prof, "inner"), tol_mm)
    faces = f_out + f_in + [flat_face(plan, _radii(outer, 0.0), 0.0),
                            flat_face(plan, _radii(inner, z_ib), z_ib),
                            flat_face(plan, _radii(outer, top), top, _radii(inner, top))]
    return sewn_solid(faces, tol_mm, prof.rotation_deg, "glass"), max(d_out, d_in)


def outline_liquid(shape, height: float, tol_mm: float):
    """``(solid, deviation_mm)``: the liquid standing at ``height`` mm in an outline bottle."""
    prof, plan = body_profile(shape), shape.plan
    inner, z_ib = _walls(prof, "inner"), float(prof.z_ib)
    faces, dev = wall_faces(plan, inner, z_ib, float(height), area_breaks(prof, "inner"), tol_mm)
    faces += [flat_face(plan, _radii(inner, z_ib), z_ib),
              flat_face(plan, _radii(inner, height), float(height))]
    return sewn_solid(faces, tol_mm, prof.rotation_deg, "liquid"), dev
