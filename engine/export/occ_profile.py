"""Section segments as exact OpenCascade curves, closed meridian faces and their revolved solids.

Design rule: a meridian curve in the (r, z) half-plane lies in the world's XZ plane
(``x = r``, ``y = 0``) and is walked from ``p0`` to ``p1``; the circle or ellipse of an arc is
built from its centre and radii (never through three points, which loses the digits of a
1 km radius), with its normal ``-y`` so that its parameter runs counter-clockwise in (r, z),
and a clockwise arc is the counter-clockwise edge from ``p1`` to ``p0`` reversed. So lines
revolve into planes, cylinders and cones, arcs into tori and spheres, ellipse arcs into
surfaces of revolution of exact ellipses. The inner wall's offset of an ellipse arc is no
conic: it becomes a B-spline fitted to the exact curve, refined until its largest measured
distance from it is a tenth of the tolerance (the rest of the tolerance stays for rounding).
Consecutive edges share one vertex per joint, so a closed chain is one closed wire whatever
the joints' rounding (to :data:`JOINT_TOL_MM`). Units mm.
"""
from __future__ import annotations

import math

import numpy as np
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace,
                                BRepBuilderAPI_MakeVertex, BRepBuilderAPI_MakeWire)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepPrimAPI import BRepPrimAPI_MakeRevol
from OCP.GeomAbs import GeomAbs_Shape
from OCP.GeomAPI import GeomAPI_PointsToBSpline, GeomAPI_ProjectPointOnCurve
from OCP.Message import Message, Message_Gravity
from OCP.gp import gp_Ax1, gp_Ax2, gp_Circ, gp_Dir, gp_Elips, gp_Pnt
from OCP.OCP.collections import Array1_gp_Pnt as TColgp_Array1OfPnt
from OCP.TopoDS import TopoDS

from ..errors import GlassbenchError
from ..geometry.segments import Arc, EllipseArc, Line, OffsetEllipseArc

#: Two chain ends closer than this (mm) are one joint; a segment shorter than this is dropped.
JOINT_TOL_MM = 1e-6
#: Most points a B-spline fit of one offset curve may take (beyond: refused, tolerance too fine).
MAX_FIT_POINTS = 4097
#: The normal of every meridian plane's circles: ``-y`` makes their parameter counter-clockwise
#: in (r, z) (local x along +r or +z, local y = normal x local x).
_NORMAL = gp_Dir(0.0, -1.0, 0.0)
_AXIS = gp_Ax1(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(0.0, 0.0, 1.0))


def quiet_kernel() -> None:
    """Keep OpenCascade's readers and writers from printing their statistics on stdout (a
    command's output is its own): only failures reach the kernel's printers."""
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)


quiet_kernel()


class CadError(GlassbenchError, ValueError):
    """The CAD kernel cannot make (or refuses) a solid of this design; says which and why."""


def pnt(p) -> gp_Pnt:
    """The world point of the meridian point ``p = (r, z)`` (mm)."""
    return gp_Pnt(float(p[0]), 0.0, float(p[1]))


def _conic_edge(conic, seg, v0, v1):
    """The edge of ``conic`` walked from ``seg.p0`` (vertex ``v0``) to ``seg.p1`` (``v1``)."""
    if seg.direction == "ccw":
        return BRepBuilderAPI_MakeEdge(conic, v0, v1)
    return _reversed(BRepBuilderAPI_MakeEdge(conic, v1, v0))


def _reversed(maker):
    if not maker.IsDone():
        return maker
    edge = maker.Edge()
    return _Done(TopoDS.Edge(edge.Reversed()))


class _Done:
    """A finished edge in the shape of a ``BRepBuilderAPI_MakeEdge`` (``IsDone``, ``Edge``)."""

    def __init__(self, edge):
        self._edge = edge

    def IsDone(self):  # noqa: N802 - OpenCascade's spelling
        return True

    def Edge(self):  # noqa: N802
        return self._edge


def _ellipse(seg: EllipseArc):
    """The full ellipse of ``seg`` (major axis along r or z, whichever radius is larger)."""
    c = pnt(seg.center)
    if seg.radius_r >= seg.radius_z:
        return gp_Elips(gp_Ax2(c, _NORMAL, gp_Dir(1.0, 0.0, 0.0)), seg.radius_r, seg.radius_z)
    return gp_Elips(gp_Ax2(c, _NORMAL, gp_Dir(0.0, 0.0, 1.0)), seg.radius_z, seg.radius_r)


def offset_bspline(seg: OffsetEllipseArc, tol_mm: float):
    """``(curve, deviation_mm)``: a B-spline through the exact offset curve ``seg`` whose largest
    distance from it, measured at the midpoints of the fitted samples and projected onto the
    curve, is at most ``tol_mm / 10``; ``CadError`` if :data:`MAX_FIT_POINTS` do not get there."""
    n = 33
    while n <= MAX_FIT_POINTS:
        t = np.linspace(0.0, 1.0, n)
        pts = seg.point(t)
        arr = TColgp_Array1OfPnt(1, n)
        for i, p in enumerate(pts):
            arr.SetValue(i + 1, pnt(p))
        fit = GeomAPI_PointsToBSpline(arr, 3, 8, GeomAbs_Shape.GeomAbs_C2, 0.01 * tol_mm)
        if fit.IsDone():
            curve = fit.Curve()
            dev = curve_deviation(curve, seg.point(0.5 * (t[1:] + t[:-1])))
            if dev <= 0.1 * tol_mm:
                return curve, dev
        n = 2 * n - 1
    raise CadError(f"the inner wall's offset of an ellipse arc cannot be fitted within "
                   f"{tol_mm:g} mm by {MAX_FIT_POINTS} points; choose a coarser tolerance")


def curve_deviation(curve, points_rz) -> float:
    """Largest distance (mm) from the meridian points ``points_rz (n, 2)`` to ``curve``."""
    worst = 0.0
    for p in points_rz:
        proj = GeomAPI_ProjectPointOnCurve(pnt(p), curve)
        worst = max(worst, proj.LowerDistance() if proj.NbPoints() else math.inf)
    return worst


def segment_edge(seg, v0, v1, tol_mm: float):
    """``(edge, deviation_mm)``: ``seg`` as an edge from vertex ``v0`` to ``v1``; exact
    (deviation 0) for lines, arcs and ellipse arcs, a fitted B-spline for an offset ellipse."""
    if isinstance(seg, Line):
        maker, dev = BRepBuilderAPI_MakeEdge(v0, v1), 0.0
    elif isinstance(seg, Arc):
        circ = gp_Circ(gp_Ax2(pnt(seg.center), _NORMAL, gp_Dir(1.0, 0.0, 0.0)), seg.radius)
        maker, dev = _conic_edge(circ, seg, v0, v1), 0.0
    elif isinstance(seg, EllipseArc):
        maker, dev = _conic_edge(_ellipse(seg), seg, v0, v1), 0.0
    elif isinstance(seg, OffsetEllipseArc):
        curve, dev = offset_bspline(seg, tol_mm)
        maker = BRepBuilderAPI_MakeEdge(curve, v0, v1)
    else:
        raise CadError(f"no CAD curve for a segment of kind {type(seg).__name__}")
    if not maker.IsDone():
        raise CadError(f"the CAD kernel rejects a {seg.kind} from {_at(seg.p0)} to {_at(seg.p1)} mm")
    return maker.Edge(), dev


def _at(p) -> str:
    return f"(r {p[0]:.6g}, z {p[1]:.6g})"


def closed_chain(segments) -> list:
    """``segments`` with those shorter than :data:`JOINT_TOL_MM` dropped and, where the last
    does not end where the first starts, a line closing it (along the axis for a meridian
    chain that runs from the axis back to it)."""
    segs = [s for s in segments if math.dist(s.p0, s.p1) > JOINT_TOL_MM]
    if not segs:
        raise CadError("an empty meridian chain has no solid")
    if math.dist(segs[-1].p1, segs[0].p0) > JOINT_TOL_MM:
        segs.append(Line(segs[-1].p1, segs[0].p0))
    return segs


def meridian_face(segments, tol_mm: float):
    """``(face, deviation_mm)``: the planar face a closed chain of segments bounds in the XZ
    plane (closed by :func:`closed_chain`); each joint is one shared vertex."""
    segs = closed_chain(segments)
    joints = [segs[i - 1].p1 if i else segs[-1].p1 for i in range(len(segs))]
    verts = [BRepBuilderAPI_MakeVertex(pnt(p)).Vertex() for p in joints]
    wire = BRepBuilderAPI_MakeWire()
    worst = 0.0
    for i, seg in enumerate(segs):
        edge, dev = segment_edge(seg, verts[i], verts[(i + 1) % len(segs)], tol_mm)
        worst = max(worst, dev)
        wire.Add(edge)
        if not wire.IsDone():
            raise CadError(f"the meridian does not join up at {_at(seg.p0)} mm")
    face = BRepBuilderAPI_MakeFace(wire.Wire(), True)
    if not face.IsDone():
        raise CadError("the meridian is not a flat closed outline the CAD kernel accepts")
    return face.Face(), worst


def revolved_solid(segments, tol_mm: float, what: str):
    """``(solid, deviation_mm)``: the closed meridian chain ``segments`` revolved a full turn
    about the z axis; ``CadError`` naming ``what`` if the kernel's result is not a valid solid."""
    face, dev = meridian_face(segments, tol_mm)
    revol = BRepPrimAPI_MakeRevol(face, _AXIS, 2.0 * math.pi)
    if not revol.IsDone():
        raise CadError(f"the CAD kernel cannot revolve the {what}'s section")
    solid = revol.Shape()
    if not BRepCheck_Analyzer(solid).IsValid():
        raise CadError(f"the CAD kernel rejects the {what}: its revolved section is not a valid solid")
    return solid, dev
