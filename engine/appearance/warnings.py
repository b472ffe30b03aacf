"""Where a label cannot lie flat, and how much glass it covers.

Design rule: pure functions of a shape, a label's :class:`~engine.appearance.frame.Placement`
and its :class:`~engine.appearance.dieline.FlatShape`, used by
:func:`engine.appearance.report.label_report` (the CLI and the panel show the same words).
Each warning carries its place three ways: on the bottle (``z_mm`` above the standing plane,
``angle_deg`` azimuth in the world frame), on the artwork (``s``, ``t``) and on the die-line
(``x_mm``, ``y_mm``). The area is exact quadrature on round walls (the label's angle times the
integral of the radius up the section) and the sum of exact-surface triangles elsewhere.
"""
from __future__ import annotations

import math

import numpy as np

from .. import limits as L
from ..geometry.validate import body_profile
from .dieline import CORNER_TURN_DEG, MIN_CORNER_MM, SHOULDER_TURN_DEG, FlatShape, LabelWarning
from .frame import Placement, label_frame

_GL_X, _GL_W = np.polynomial.legendre.leggauss(32)
#: Points up the label's centre line at which the wall's slope is sampled.
SLOPE_SAMPLES = 257
#: Heights across a label at which an outline bottle's tight corners are looked for.
CORNER_ROWS = 17
#: An outline's plan corner rounded less than this (mm) is a crease for paper.
CREASE_MM = 0.05


def area_mm2(shape, p: Placement, flat: FlatShape) -> float:
    """Area (mm^2) the label covers on the glass (module rule)."""
    frame = label_frame(shape, p)
    if frame.kind == "round":
        w = frame.wall
        cuts = np.unique(np.clip(np.concatenate([[frame.h0, frame.h1], w.cum]), frame.h0, frame.h1))
        total = 0.0
        for a, b in zip(cuts[:-1], cuts[1:]):
            h = a + (b - a) * (_GL_X + 1.0) / 2.0
            total += (b - a) / 2.0 * float(np.dot(_GL_W, w.at(h)[0]))
        return frame.span * total
    if flat.kind == "rectangle":
        return p.width_mm * p.height_mm
    nt, ns = flat.flat.shape[:2]
    s, t = np.meshgrid(np.linspace(0, 1, 2 * ns - 1), np.linspace(0, 1, 2 * nt - 1))
    q = frame.points(s, t)
    a, b, c, d = q[:-1, :-1], q[:-1, 1:], q[1:, :-1], q[1:, 1:]
    tri = lambda u, v, w: 0.5 * np.linalg.norm(np.cross(v - u, w - u), axis=-1)
    return float(np.sum(tri(a, b, d) + tri(a, d, c)))


def _place(shape, frame, flat, kind, message, s, t) -> LabelWarning:
    theta, h = frame.surface(s, t)
    if frame.kind == "round":
        z, angle = float(frame.wall.at(h)[1]), math.degrees(float(theta))
    else:
        z, angle = float(h), math.degrees(float(theta)) + shape.rotation_deg
    angle = (angle + 180.0) % 360.0 - 180.0
    x, y = (float(v) for v in flat.at(s, t))
    return LabelWarning(kind, f"{message} at z = {z:.1f} mm, {angle:.0f} deg", z, angle,
                        float(s), float(t), x, y)


def label_warnings(shape, p: Placement, flat: FlatShape) -> tuple[LabelWarning, ...]:
    """The warnings of one label (module rule), in the order strain, shoulder, corners."""
    frame = label_frame(shape, p)
    out = []
    if flat.strain.max() > L.PAPER_STRAIN:
        i, j = np.unravel_index(int(np.argmax(flat.strain)), flat.strain.shape)
        nt, ns = flat.strain.shape
        out.append(_place(shape, frame, flat, "strain",
                          f"strain {100 * flat.strain.max():.2f} % (paper takes about "
                          f"{100 * L.PAPER_STRAIN:g} %)", j / (ns - 1), i / (nt - 1)))
    t = np.linspace(0.0, 1.0, SLOPE_SAMPLES)
    slope = _slope_deg(frame, t)
    turn = float(slope.max() - slope.min())
    if turn > SHOULDER_TURN_DEG:
        k = int(np.argmax(np.abs(np.diff(slope))))
        out.append(_place(shape, frame, flat, "shoulder", f"crosses a shoulder (the wall turns "
                          f"{turn:.0f} deg under the label)", 0.5, 0.5 * (t[k] + t[k + 1])))
    for t_joint, degrees in _joints(frame):
        out.append(_place(shape, frame, flat, "corner", f"crosses a sharp corner of the section "
                          f"({degrees:.0f} deg)", 0.5, t_joint))
    out.extend(_cross_section_corners(shape, frame, flat))
    return tuple(out)


def _slope_deg(frame, t) -> np.ndarray:
    """Angle (degrees) of the wall from horizontal, up the label's centre line."""
    if frame.kind == "round":
        _, h = frame.surface(np.full(t.shape, 0.5), t)
        _, _, tr, tz = frame.wall.at(h)
        return np.degrees(np.arctan2(tz, tr))
    q = frame.points(np.full(t.shape, 0.5), t)
    rho, z = np.hypot(q[:, 0], q[:, 1]), q[:, 2]
    mid = np.degrees(np.arctan2(np.diff(z), np.diff(rho)))
    return np.concatenate([mid[:1], mid])


def _joints(frame):
    """``(t, turn_deg)`` of section joints under the label that are not tangent."""
    if frame.kind == "round":
        found = [(h, turn) for h, turn in frame.wall.joints()]
        return [(float((frame.h1 - h) / frame.placement.height_mm), turn) for h, turn in found
                if frame.h0 < h < frame.h1 and turn > CORNER_TURN_DEG]
    out = {}
    for sp in body_profile(frame.shape).sections:
        for a, b in zip(sp.outer_wall[:-1], sp.outer_wall[1:]):
            z = a.p1[1]
            ta, tb = a.tangent(1.0), b.tangent(0.0)
            turn = abs(math.degrees(math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(np.dot(ta, tb)))))
            if frame.h0 < z < frame.h1 and turn > CORNER_TURN_DEG:
                key = round(z, 6)
                out[key] = max(out.get(key, 0.0), turn)
    return [(float(frame.t_of_z(z)), turn) for z, turn in sorted(out.items())]


def _cross_section_corners(shape, frame, flat):
    """Warnings for corners of a rounded square / rectangle tighter than :data:`MIN_CORNER_MM`
    that the label wraps at its centre height (an outline's: :func:`_plan_corners`)."""
    xs = shape.xs
    if xs.name == "outline":
        return _plan_corners(shape, frame, flat)
    if not hasattr(xs, "as_rect"):  # why: only rounded squares and rectangles have such corners
        return []
    a, b, c = (float(v) for v in xs.as_rect(frame.wall.radii(frame.h_c)))
    if c >= MIN_CORNER_MM:
        return []
    mid = math.atan2(b - c + c * math.sqrt(0.5), a - c + c * math.sqrt(0.5))
    out = []
    for corner in (mid, math.pi - mid, math.pi + mid, 2 * math.pi - mid):
        theta = frame.theta0 + (corner - frame.theta0) % (2 * math.pi)
        s, _ = frame.st(np.array([theta]), np.array([frame.h_c]))
        if 0.0 <= s[0] <= 1.0:
            out.append(_place(shape, frame, flat, "corner", f"wraps a corner of {c:.1f} mm radius "
                              f"(tighter than {MIN_CORNER_MM:g} mm)", float(s[0]), 0.5))
    return out


def _plan_corners(shape, frame, flat):
    """Warnings for the arcs of an outline bottle's outer section tighter than
    :data:`MIN_CORNER_MM` that the label wraps, one per arc at the height under the label where
    it is tightest (the centre height first, where it is as tight): a sharp corner of the plan
    is an arc of the rounding's radius ``c``, a crease where ``c`` is below :data:`CREASE_MM`."""
    t_rows = np.concatenate([[0.5], np.linspace(0.0, 1.0, CORNER_ROWS)])
    _, z_rows = frame.surface(np.full(t_rows.shape, 0.5), t_rows)
    tightest = {}
    for t, z in zip(t_rows, z_rows):
        k, c = (float(r) for r in frame.wall.radii(z))
        if k <= 0.0:
            continue  # the round neck: no corners
        for i, piece in enumerate(shape.plan.outer_pieces(k, c)):
            if piece.kind != "arc" or piece.radius >= min(MIN_CORNER_MM, tightest.get(i, (math.inf,))[0]):
                continue
            x, y = piece.point(0.5 * (piece.theta0 + piece.theta1))
            theta = frame.theta0 + (math.atan2(y, x) - frame.theta0) % (2 * math.pi)
            s, _ = frame.st(np.array([theta]), np.array([z]))
            if 0.0 <= s[0] <= 1.0:
                tightest[i] = (piece.radius, math.degrees(piece.theta1 - piece.theta0), float(s[0]), float(t))
    out = []
    for radius, degrees, s, t in tightest.values():
        words = (f"crosses a sharp corner of the plan ({degrees:.0f} deg, a crease)" if radius < CREASE_MM else
                 f"wraps a corner of {radius:.1f} mm radius (tighter than {MIN_CORNER_MM:g} mm)")
        out.append(_place(shape, frame, flat, "corner", words, s, t))
    return out
