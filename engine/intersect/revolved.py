"""One entry point for the tracer: rays against any section segment revolved about z.

Design rule: each segment kind is sent to its exact solver (lines to
:func:`~engine.intersect.quadric.ray_cone_hits`, circular and elliptic arcs to
:func:`~engine.intersect.torus.ray_torus_hits` or, with the centre on the axis, to
:func:`~engine.intersect.quadric.ray_spheroid_hits`), and hits are then restricted to the
segment's extent using the segment's own parameterisation. The inner wall of an elliptic arc
(:class:`~engine.geometry.segments.OffsetEllipseArc`, a degree-8 surface) has no practical closed form;
:mod:`engine.intersect.offset_arc` brackets it numerically along the curve parameter. Normals are analytic and follow the
segment's outward normal ``n = (T_z, -T_r)`` revolved to world space.
"""
from __future__ import annotations

import math

import numpy as np

from ..geometry.segments import Arc, EllipseArc, Line, OffsetEllipseArc
from .offset_arc import offset_arc_bounds, offset_arc_parameter, ray_offset_arc_hits
from .quadric import EXTENT_SLACK, ray_cone_hits, ray_spheroid_hits
from .torus import ray_torus_hits

TWO_PI = 2.0 * math.pi


def _pad4(hits):
    out = np.full((hits.shape[0], 4), np.nan)
    out[:, : hits.shape[1]] = hits[:, :4]
    return out


def in_sweep(angle, angle0, sweep):
    """True where ``angle`` (rad) lies on the arc from ``angle0`` sweeping ``sweep`` (signed).

    A slack of ``EXTENT_SLACK`` of the sweep at either end lets neighbouring segments
    overlap by a hair rather than leave cracks.
    """
    rel = np.mod((np.asarray(angle) - angle0) * (1.0 if sweep >= 0 else -1.0), TWO_PI)
    slack = EXTENT_SLACK * abs(sweep)
    return (rel <= abs(sweep) + slack) | (rel >= TWO_PI - slack)


def _arc_like_hits(o, d, center, ar, az, angle0, sweep, tmin):
    """Hits on the revolved ellipse ``((r-cr)/ar)^2 + ((z-cz)/az)^2 = 1`` within the sweep."""
    cr, cz = center
    shifted = o - np.array([0.0, 0.0, cz])
    if abs(cr) < 1e-9 * ar:
        hits = _pad4(ray_spheroid_hits(shifted, d, ar, az, tmin=tmin))
        cr = 0.0
    else:
        hits = ray_torus_hits(shifted, d, abs(cr), ar, az, tmin=tmin,
                              sheet="outer" if cr > 0 else "inner")
    pts = o[:, None, :] + hits[..., None] * d[:, None, :]
    rho = np.hypot(pts[..., 0], pts[..., 1])
    ang = np.arctan2((pts[..., 2] - cz) / az, (rho - cr) / ar)
    hits = np.where(in_sweep(ang, angle0, sweep), hits, np.nan)
    hits.sort(axis=1)
    return hits


def revolved_hits(origins, directions, seg, tmin=None):
    """Hit distances of rays with ``seg`` (a section segment) revolved about the z axis.

    Parameters
    ----------
    origins, directions : array_like, shape (N, 3)
        Ray origins (mm) and unit directions, world frame (z is the bottle axis).
    seg : Line | Arc | EllipseArc | OffsetEllipseArc
        The meridian segment (mm, ``r >= 0``).
    tmin : float, optional
        Hits at ``t <= tmin`` (mm) are dropped; by default a tiny fraction of the segment's
        own size (1e-6 of a tube radius for arcs, 1e-9 of the size for lines), so a
        secondary ray leaving the surface does not re-hit it at its start.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Hit distances (mm) ascending, NaN-padded, restricted to the segment's extent (for
        arcs: their angular range in their own parameterisation).
    """
    o = np.asarray(origins, dtype=float).reshape(-1, 3)
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    if isinstance(seg, Line):
        return _pad4(ray_cone_hits(o, d, *seg.p0, *seg.p1, tmin=tmin))
    if isinstance(seg, Arc):
        return _arc_like_hits(o, d, seg.center, seg.radius, seg.radius, seg.angle0, seg.sweep, tmin)
    if isinstance(seg, EllipseArc):
        return _arc_like_hits(o, d, seg.center, seg.radius_r, seg.radius_z, seg.angle0, seg.sweep, tmin)
    if isinstance(seg, OffsetEllipseArc):
        return ray_offset_arc_hits(o, d, seg, tmin=tmin)
    raise TypeError(f"cannot intersect a {type(seg).__name__}")


def _meridian(points):
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    rho = np.hypot(p[:, 0], p[:, 1])
    # On the axis the radial direction is arbitrary; a valid section has n_r = 0 there.
    safe = np.where(rho > 0, rho, 1.0)
    er = np.where(rho[:, None] > 0, p[:, :2] / safe[:, None], np.array([1.0, 0.0]))
    return p, rho, er


def revolved_normals(points, seg):
    """Outward unit normals (N, 3) of ``seg`` revolved, at world ``points`` (mm) on it.

    The meridian normal is the segment's ``n = (T_z, -T_r)`` (outward from the glass for
    an outer wall), computed analytically from the point: constant for a line, radial
    about the centre for an arc (inverted for ``"cw"``), the ellipse gradient for an
    elliptic arc, and the base arc's normal at the foot parameter for an offset arc.
    """
    p, rho, er = _meridian(points)
    z = p[:, 2]
    if isinstance(seg, Line):
        (tr, tz) = seg.tangent(0.0)
        nr, nz = np.full_like(rho, tz), np.full_like(rho, -tr)
    elif isinstance(seg, (Arc, EllipseArc)):
        ar, az = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_r, seg.radius_z)
        sign = 1.0 if seg.direction == "ccw" else -1.0
        nr = sign * (rho - seg.center[0]) / (ar * ar)
        nz = sign * (z - seg.center[1]) / (az * az)
        norm = np.hypot(nr, nz)
        nr, nz = nr / norm, nz / norm
    elif isinstance(seg, OffsetEllipseArc):
        t = offset_arc_parameter(np.column_stack([rho, z]), seg)
        tan = seg.base.tangent(t)
        nr, nz = tan[:, 1], -tan[:, 0]
    else:
        raise TypeError(f"no normals for a {type(seg).__name__}")
    return np.column_stack([nr * er[:, 0], nr * er[:, 1], nz])


def segment_bounds(seg):
    """``(rmin, rmax, zmin, zmax)`` (mm) of ``seg``: a box in (r, z) holding all of it.

    Exact for lines and arcs (end points plus the axis-aligned extreme points inside the
    sweep); for an offset arc, from dense samples widened by the sample spacing.
    """
    if isinstance(seg, Line):
        rs, zs = [seg.p0[0], seg.p1[0]], [seg.p0[1], seg.p1[1]]
    elif isinstance(seg, (Arc, EllipseArc)):
        ar, az = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_r, seg.radius_z)
        cr, cz = seg.center
        rs, zs = [seg.p0[0], seg.p1[0]], [seg.p0[1], seg.p1[1]]
        for k in range(4):
            ang = k * math.pi / 2
            if in_sweep(ang, seg.angle0, seg.sweep):
                rs.append(cr + ar * math.cos(ang))
                zs.append(cz + az * math.sin(ang))
    elif isinstance(seg, OffsetEllipseArc):
        return offset_arc_bounds(seg)
    else:
        raise TypeError(f"no bounds for a {type(seg).__name__}")
    return (max(min(rs), 0.0), max(rs), min(zs), max(zs))
