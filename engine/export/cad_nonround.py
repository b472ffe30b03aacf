"""Non-round bodies (rounded square, rounded rectangle, oval) as solids sewn from B-spline patches.

Design rule: a non-round wall is cut where its structure changes, so that each patch is
smooth: in height at every joint of every section (so each radius is one analytic segment
inside a piece), around the girth where a side meets a corner (sides ``x = +-a``, ``y = +-b``,
corner arcs of radius ``c``; an oval's quarters). Each patch is the tensor-product cubic
interpolant of exact surface points (:mod:`engine.geometry.crosssection` at the sections'
radii) over fixed parameters: the side's fraction, the corner's angle, and height through
``z = za + (zb - za)(1 - cos(pi x)) / 2`` (as the capacity integrates: a section turning
horizontal at a piece's end stays smooth in ``x``). The grid is doubled until the patch's
largest distance from the exact surface, measured at every cell's centre and edges'
midpoints, is a tenth of the tolerance. Bases, rim and free surface are exact planes bounded
by exact lines, arcs, circles or ellipses. The faces are sewn (at a tenth of the tolerance)
into one closed shell, made a solid oriented outwards, and turned by ``rotation_deg``. Sides
that vanish (a rounded square turning round into its neck) are left out where they have no
width over a whole piece. Units mm.
"""
from __future__ import annotations

import math

import numpy as np
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace,
                                BRepBuilderAPI_MakeSolid, BRepBuilderAPI_MakeWire,
                                BRepBuilderAPI_Sewing, BRepBuilderAPI_Transform)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.Geom import Geom_BSplineSurface
from OCP.gp import gp_Ax1, gp_Ax2, gp_Circ, gp_Dir, gp_Elips, gp_Pnt, gp_Trsf
from OCP.OCP.collections import Array1_double, Array1_int, Array2_gp_Pnt
from OCP.TopAbs import TopAbs_ShapeEnum
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from scipy.interpolate import BSpline, make_interp_spline

from ..geometry import crosssection
from ..geometry.body import chain_state
from ..geometry.chain import z_breaks
from ..geometry.validate import body_profile
from .occ_profile import CadError

#: Nodes a patch starts from along each parameter, and the most it may grow to.
START_NODES, MAX_NODES = 9, 257
#: Half-widths (mm) below which a side has vanished.
SIDE_EPS_MM = 1e-9


def radii_at(chains, z):
    """The sections' radii (mm) at heights ``z`` (mm), each chain clamped to its range."""
    return [chain_state(c, z)[0] for c in chains]


def _rect(kind, radii):
    """``(a, b, c)`` (mm) of the rounded rectangle a rounded square or rectangle is."""
    return crosssection.of_kind(kind).as_rect(radii)


def patch_kinds(kind: str) -> list[tuple]:
    """The patches around the girth: ``("side", axis, sign)`` or ``("corner", quadrant)`` for
    rounded kinds, ``("quarter", k)`` for an oval; counter-clockwise from +x."""
    if kind == "oval":
        return [("quarter", k) for k in range(4)]
    return [p for k in range(4) for p in (("side", k), ("corner", k))]


def patch_points(kind, part, radii, w):
    """Exact points ``(..., 3)`` (mm, bottle frame) of ``part`` at parameter ``w`` in [0, 1]
    (broadcast against the radii, which are arrays over height)."""
    if kind == "oval":
        a, b = radii
        phi = (part[1] + w) * (math.pi / 2)
        return np.stack([a * np.cos(phi), b * np.sin(phi)], -1)
    a, b, c = _rect(kind, radii)
    k = part[1]
    if part[0] == "corner":
        phi = (k + w) * (math.pi / 2)
        cx, cy = (a - c) * (1 if k in (0, 3) else -1), (b - c) * (1 if k in (0, 1) else -1)
        return np.stack([cx + c * np.cos(phi), cy + c * np.sin(phi)], -1)
    s = 2.0 * w - 1.0  # -1 .. 1 along the side, counter-clockwise
    half = (b - c) if k % 2 == 0 else (a - c)
    along = s * half
    pts = {0: (a + 0 * along, along), 1: (-along, b + 0 * along),
           2: (-a + 0 * along, -along), 3: (along, -b + 0 * along)}[k]
    return np.stack(pts, -1)


def side_width(kind, part, radii) -> np.ndarray:
    """Half-length (mm) of a side patch at the given radii (corners and quarters: infinity)."""
    if part[0] != "side":
        return np.full(np.shape(radii[0]), np.inf)
    a, b, c = _rect(kind, radii)
    return (b - c) if part[1] % 2 == 0 else (a - c)


def occ_knots(t):
    """OpenCascade's ``(knots, multiplicities)`` arrays of the full knot vector ``t``."""
    vals, mults = np.unique(np.round(t, 14), return_counts=True)
    kn, mu = Array1_double(1, len(vals)), Array1_int(1, len(vals))
    for i, (v, m) in enumerate(zip(vals, mults)):
        kn.SetValue(i + 1, float(v))
        mu.SetValue(i + 1, int(m))
    return kn, mu


def interpolant(w, x, pts):
    """The cubic splines ``(sw, sx)`` of the tensor interpolant through ``pts (nw, nx, 3)`` at
    parameters ``w``, ``x``: ``sw`` along ``w`` per row, ``sx`` its coefficients along ``x``."""
    sw = make_interp_spline(w, pts, k=3, axis=0)
    return sw, make_interp_spline(x, sw.c, k=3, axis=1)


def bspline_surface(sw, sx):
    """The OpenCascade B-spline surface of the tensor interpolant :func:`interpolant` made
    (``u`` along ``w``, ``v`` along ``x``; scipy keeps the interpolated axis first)."""
    poles = np.moveaxis(sx.c, 0, 1)
    arr = Array2_gp_Pnt(1, poles.shape[0], 1, poles.shape[1])
    for i in range(poles.shape[0]):
        for j in range(poles.shape[1]):
            arr.SetValue(i + 1, j + 1, gp_Pnt(*map(float, poles[i, j])))
    (uk, um), (vk, vm) = occ_knots(sw.t), occ_knots(sx.t)
    return Geom_BSplineSurface(arr, uk, vk, um, vm, 3, 3)


def band_heights(za, zb, x):
    """Heights (mm) at parameters ``x`` in [0, 1] between ``za`` and ``zb``: the cosine spacing
    (``(1 - cos(pi x)) / 2``) that keeps a section turning horizontal at an end smooth in ``x``."""
    return za + (zb - za) * (1.0 - np.cos(math.pi * x)) / 2.0


def _grid_points(kind, part, chains, za, zb, w, x):
    """Exact points ``(len(w), len(x), 3)`` of a patch at parameters ``w`` and ``x``."""
    z = band_heights(za, zb, x)
    xy = patch_points(kind, part, [r[None, :] for r in radii_at(chains, z)], w[:, None])
    return np.concatenate([xy, np.broadcast_to(z[None, :, None], xy.shape[:2] + (1,))], -1)


def fitted_patch(kind, part, chains, za, zb, tol_mm):
    """``(surface, deviation_mm)`` of one patch between heights ``za`` and ``zb`` (mm)."""
    return fitted_surface(lambda w, x: _grid_points(kind, part, chains, za, zb, w, x), tol_mm,
                          f"a {kind.replace('_', ' ')} wall patch between z {za:.6g} and {zb:.6g} mm")


def fitted_surface(grid, tol_mm, what: str):
    """``(surface, deviation_mm)``: the tensor interpolant of the exact points ``grid(w, x)``
    (``(len(w), len(x), 3)`` mm at parameters in [0, 1]) within a tenth of ``tol_mm``; the
    grid grows along whichever parameter's midpoints are off by more than half the limit.
    ``CadError`` naming ``what`` past :data:`MAX_NODES`."""
    nw = nx = START_NODES
    limit = 0.1 * tol_mm
    while True:
        w, x = np.linspace(0.0, 1.0, nw), np.linspace(0.0, 1.0, nx)
        sw, sx = interpolant(w, x, grid(w, x))
        e_w, e_x, e_c = _deviations(grid, sw, sx, w, x)
        either = e_c > limit and e_w <= limit / 2 and e_x <= limit / 2
        grow_w, grow_x = e_w > limit / 2 or either, e_x > limit / 2 or either
        if not (grow_w or grow_x):
            return bspline_surface(sw, sx), max(e_w, e_x, e_c)
        if (grow_w and nw >= MAX_NODES) or (grow_x and nx >= MAX_NODES):
            raise CadError(f"{what} cannot be fitted within {tol_mm:g} mm; choose a coarser tolerance")
        nw, nx = (2 * nw - 1 if grow_w else nw), (2 * nx - 1 if grow_x else nx)


def _deviations(grid, sw, sx, w, x):
    """Largest distances (mm) between the interpolant and the exact surface at the midpoints
    along ``w``, along ``x`` and at the cells' centres."""
    wm, xm = 0.5 * (w[1:] + w[:-1]), 0.5 * (x[1:] + x[:-1])
    out = []
    for wq, xq in ((wm, x), (w, xm), (wm, xm)):
        exact = grid(wq, xq)
        coef = sx(xq)  # the tensor interpolant: the w-basis times the x-interpolated coefficients
        basis = BSpline(sw.t, np.eye(coef.shape[0]), 3)(wq)
        fit = (basis @ coef.reshape(coef.shape[0], -1)).reshape(len(wq), len(xq), 3)
        out.append(float(np.max(np.linalg.norm(fit - exact, axis=-1))))
    return out


# ------------------------------------------------------------------------ faces and solid
def _plane_ring(kind, radii, z: float):
    """The exact closed outline (a wire) of the cross-section with ``radii`` at height ``z``."""
    radii = [float(r) for r in radii]
    wire = BRepBuilderAPI_MakeWire()
    up = gp_Dir(0.0, 0.0, 1.0)
    if kind == "oval":
        a, b = radii
        x_dir = gp_Dir(1.0, 0.0, 0.0) if a >= b else gp_Dir(0.0, 1.0, 0.0)
        wire.Add(BRepBuilderAPI_MakeEdge(gp_Elips(gp_Ax2(gp_Pnt(0, 0, z), up, x_dir),
                                                  max(a, b), min(a, b))).Edge())
        return wire.Wire()
    a, b, c = _rect(kind, radii)
    a, b, c = float(a), float(b), float(c)
    if a - c <= SIDE_EPS_MM and b - c <= SIDE_EPS_MM:
        wire.Add(BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, z), up), c)).Edge())
        return wire.Wire()
    for k in range(4):
        for part in (("side", k), ("corner", k)):
            if part[0] == "side" and side_width(kind, part, [a, b, c] if kind != "rounded_square"
                                                else radii) <= SIDE_EPS_MM:
                continue
            ends = patch_points(kind, part, radii, np.array([0.0, 0.5, 1.0]))
            p0, pm, p1 = (gp_Pnt(float(x), float(y), z) for x, y in ends)
            if part[0] == "side":
                wire.Add(BRepBuilderAPI_MakeEdge(p0, p1).Edge())
            else:
                sx, sy = (1 if k in (0, 3) else -1), (1 if k in (0, 1) else -1)
                circ = gp_Circ(gp_Ax2(gp_Pnt(sx * (a - c), sy * (b - c), z), up), c)
                wire.Add(BRepBuilderAPI_MakeEdge(circ, p0, p1).Edge())
    return wire.Wire()


def plane_face(kind, outer_radii, z: float, inner_radii=None):
    """The flat face at height ``z`` inside the outline of ``outer_radii`` (less the inside
    of ``inner_radii``: the rim)."""
    maker = BRepBuilderAPI_MakeFace(_plane_ring(kind, outer_radii, z), True)
    if inner_radii is not None:
        maker.Add(TopoDS.Wire(_plane_ring(kind, inner_radii, z).Reversed()))
    if not maker.IsDone():
        raise CadError(f"the CAD kernel cannot make the flat face at z {z:.6g} mm")
    return maker.Face()


def wall_faces(kind, chains, z_lo, z_hi, tol_mm):
    """``(faces, deviation_mm)``: the wall's patches between heights ``z_lo`` and ``z_hi``."""
    faces, worst = [], 0.0
    zs = z_breaks(chains, z_lo, z_hi)
    for za, zb in zip(zs[:-1], zs[1:]):
        probe = radii_at(chains, np.linspace(za, zb, 33))
        for part in patch_kinds(kind):
            if np.all(side_width(kind, part, probe) <= SIDE_EPS_MM):
                continue
            surface, dev = fitted_patch(kind, part, chains, za, zb, tol_mm)
            faces.append(BRepBuilderAPI_MakeFace(surface, 1e-9).Face())
            worst = max(worst, dev)
    return faces, worst


def sewn_solid(faces, tol_mm: float, rotation_deg: float, what: str):
    """The solid the ``faces`` close, sewn at a tenth of ``tol_mm``, oriented outwards and
    turned ``rotation_deg`` about +z; ``CadError`` if it is not one valid closed solid."""
    sewing = BRepBuilderAPI_Sewing(0.1 * tol_mm)
    for f in faces:
        sewing.Add(f)
    sewing.Perform()
    shells = TopExp_Explorer(sewing.SewedShape(), TopAbs_ShapeEnum.TopAbs_SHELL)
    if not shells.More():
        raise CadError(f"the {what}'s faces do not sew into a shell")
    shell = TopoDS.Shell(shells.Current())
    shells.Next()
    if shells.More() or sewing.NbFreeEdges() or not BRep_Tool_closed(shell):
        raise CadError(f"the {what}'s faces do not close ({sewing.NbFreeEdges()} free edges)")
    solid = BRepBuilderAPI_MakeSolid(shell).Solid()
    BRepLib.OrientClosedSolid_s(solid)
    if rotation_deg:
        turn = gp_Trsf()
        turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(rotation_deg))
        solid = TopoDS.Solid(BRepBuilderAPI_Transform(solid, turn, True).Shape())
    if not BRepCheck_Analyzer(solid).IsValid():
        raise CadError(f"the CAD kernel rejects the {what}: its sewn faces are not a valid solid")
    return solid


def BRep_Tool_closed(shell) -> bool:  # noqa: N802 - named after the OpenCascade call it makes
    from OCP.BRep import BRep_Tool
    return bool(BRep_Tool.IsClosed_s(shell))


def _walls(prof, which):
    return [sp.outer_wall if which == "outer" else sp.inner_wall for sp in prof.sections]


def nonround_glass(shape, tol_mm: float):
    """``(solid, deviation_mm)``: the glass of a non-round (flat-based) bottle."""
    prof = body_profile(shape)
    kind, outer, inner = prof.cross_section, _walls(prof, "outer"), _walls(prof, "inner")
    f_out, d_out = wall_faces(kind, outer, 0.0, prof.z_top, tol_mm)
    f_in, d_in = wall_faces(kind, inner, prof.z_ib, prof.z_top, tol_mm)
    top = float(prof.z_top)
    faces = f_out + f_in + [
        plane_face(kind, radii_at(outer, np.array(0.0)), 0.0),
        plane_face(kind, radii_at(inner, np.array(prof.z_ib)), float(prof.z_ib)),
        plane_face(kind, radii_at(outer, np.array(top)), top, radii_at(inner, np.array(top)))]
    return sewn_solid(faces, tol_mm, prof.rotation_deg, "glass"), max(d_out, d_in)


def nonround_liquid(shape, height: float, tol_mm: float):
    """``(solid, deviation_mm)``: the liquid standing at ``height`` mm in a non-round bottle."""
    prof = body_profile(shape)
    kind, inner = prof.cross_section, _walls(prof, "inner")
    faces, dev = wall_faces(kind, inner, prof.z_ib, float(height), tol_mm)
    faces += [plane_face(kind, radii_at(inner, np.array(prof.z_ib)), float(prof.z_ib)),
              plane_face(kind, radii_at(inner, np.array(height)), float(height))]
    return sewn_solid(faces, tol_mm, prof.rotation_deg, "liquid"), dev
