"""The flat shape a printer cuts for each label, its area, its largest strain and its warnings.

Design rule: :func:`flat_shape` classifies a label's patch (:mod:`engine.appearance.frame`) by
the wall under it and flattens it the right way for that band:

=============  =================================================  ===========================
band           flat shape                                         figures (mm, degrees)
=============  =================================================  ===========================
cylinder,      rolled without stretch: a rectangle                ``width_mm``, ``height_mm``
straight prism
cone           unrolled: an annular sector, ``R1 = C1 L / (C2 -   ``r_inner_mm``,
               C1)`` for end girths ``C1 < C2`` and slant ``L``,  ``r_outer_mm``, ``angle_deg``
               angle ``width / R_mid`` (``C1 / R1`` all round)
anything else  least distortion (:mod:`engine.appearance.flatten`)  an ``outline`` polygon
=============  =================================================  ===========================

A flat shape is a grid over the artwork (rows ``t`` top -> bottom, columns ``s`` left -> right)
of flat points (mm; x right, y up, centre at the origin, seen from the printed side) with the
strain at each node (zero for the first two). :func:`label_report` adds the area on the glass
(mm^2) and the warnings where a label cannot lie flat: strain above
:data:`engine.limits.PAPER_STRAIN`, a shoulder (the wall turning more than
:data:`SHOULDER_TURN_DEG` under the label), a sharp corner (a section joint that is not
tangent, or a cross-section corner tighter than :data:`MIN_CORNER_MM`), each with where it is.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..geometry.segments import Line
from ..geometry.validate import body_profile
from .flatten import flatten
from .frame import Placement, label_frame

#: Turn of the wall (degrees, up a meridian) under a label that counts as crossing a shoulder.
SHOULDER_TURN_DEG = 8.0
#: A joint of the section turning more than this (degrees) is a sharp corner for paper.
CORNER_TURN_DEG = 1.0
#: Cross-section corners of a smaller radius (mm) than this are too tight for a label.
MIN_CORNER_MM = 3.0
#: Nodes along the longer side of a label's flat grid (odd: the centre is a node).
FLAT_NODES = 41


@dataclass(frozen=True, eq=False)
class FlatShape:
    """A label's flat shape (module rule): ``flat (nt, ns, 2)`` mm, ``strain (nt, ns)``,
    ``figures`` the die-line as ``glassbench labels --json`` gives it."""

    kind: str
    flat: np.ndarray
    strain: np.ndarray
    figures: dict

    def outline(self) -> np.ndarray:
        """Closed boundary ``(M, 2)`` mm: top edge left -> right, right edge down, bottom edge
        right -> left, left edge up (counter-clockwise seen from the printed side is reversed:
        clockwise, as the artwork reads)."""
        f = self.flat
        return np.concatenate([f[0, :-1], f[:-1, -1], f[-1, :0:-1], f[:0:-1, 0]])

    def at(self, s, t) -> np.ndarray:
        """Flat points (mm) of artwork points, bilinear in the grid."""
        return _bilinear(self.flat, s, t)


def _bilinear(grid, s, t):
    nt, ns = grid.shape[:2]
    fx = np.clip(np.asarray(s, float), 0.0, 1.0) * (ns - 1)
    fy = np.clip(np.asarray(t, float), 0.0, 1.0) * (nt - 1)
    j = np.minimum(np.floor(fx).astype(int), ns - 2)
    i = np.minimum(np.floor(fy).astype(int), nt - 2)
    ax, ay = fx - j, fy - i
    if grid.ndim == 3:
        ax, ay = ax[..., None], ay[..., None]
    top = grid[i, j] * (1 - ax) + grid[i, j + 1] * ax
    bottom = grid[i + 1, j] * (1 - ax) + grid[i + 1, j + 1] * ax
    return top * (1 - ay) + bottom * ay


def grid_shape(p: Placement) -> tuple[int, int]:
    """``(nt, ns)`` odd node counts, :data:`FLAT_NODES` along the longer side, 9 at least."""
    long, short = max(p.width_mm, p.height_mm), min(p.width_mm, p.height_mm)
    other = max(9, int(FLAT_NODES * short / long) | 1)
    return (FLAT_NODES, other) if p.height_mm >= p.width_mm else (other, FLAT_NODES)


def band_kind(frame) -> str:
    """``"cylinder"``, ``"cone"`` or ``"free"`` (round walls); ``"prism"`` or ``"free"`` (others)."""
    if frame.kind == "round":
        w = frame.wall
        segs = [w.segments[i] for i in range(len(w.segments))
                if w.cum[i] < frame.h1 - 1e-9 and w.cum[i + 1] > frame.h0 + 1e-9]
        if not all(isinstance(s, Line) for s in segs):
            return "free"
        tangents = np.array([s.tangent(0.0) for s in segs])
        if np.abs(tangents - tangents[0]).max() > 1e-12:
            return "free"
        return "cylinder" if abs(tangents[0][0]) < 1e-12 else "cone"
    for sp in body_profile(frame.shape).sections:
        for s in sp.outer_wall:
            z0, z1 = sorted((s.p0[1], s.p1[1]))
            if z0 < frame.h1 - 1e-9 and z1 > frame.h0 + 1e-9 and not (
                    isinstance(s, Line) and abs(s.p0[0] - s.p1[0]) < 1e-12):
                return "free"
    return "prism"


@lru_cache(maxsize=64)
def flat_shape(shape, p: Placement) -> FlatShape:
    """The :class:`FlatShape` of a label with placement ``p`` on ``shape`` (cached by value).
    The label must lie on the wall (:func:`engine.appearance.placement.check_one`)."""
    frame = label_frame(shape, p)
    nt, ns = grid_shape(p)
    s, t = np.meshgrid(np.linspace(0.0, 1.0, ns), np.linspace(0.0, 1.0, nt))
    kind = band_kind(frame)
    rect = np.stack([(s - 0.5) * p.width_mm, (0.5 - t) * p.height_mm], -1)
    if kind in ("cylinder", "prism"):
        figures = {"kind": "rectangle", "width_mm": p.width_mm, "height_mm": p.height_mm}
        return FlatShape("rectangle", rect, np.zeros(s.shape), figures)
    if frame.kind == "round":
        slope = float(frame.wall.at(frame.h_c)[2])  # dr/dh at the centre: the tangent cone
        if kind == "cone" or abs(slope) > 1e-3:
            sector, figures = _sector(frame, slope, s, t)
            if kind == "cone":
                return FlatShape("sector", sector, np.zeros(s.shape), figures)
            rect = sector
    flat, strain = flatten(frame.points(s, t), rect)
    outline = FlatShape("outline", flat, strain, {})
    pts = np.round(outline.outline(), 3)
    figures = {"kind": "outline", "points_mm": pts.tolist(),
               "width_mm": float(np.ptp(pts[:, 0])), "height_mm": float(np.ptp(pts[:, 1]))}
    return FlatShape("outline", flat, strain, figures)


def _sector(frame, slope: float, s, t):
    """The unrolled cone of slope ``dr/dh`` through the label's centre: flat grid and figures."""
    p = frame.placement
    rho_c = frame.r_c / abs(slope)
    angle = frame.span * abs(slope)
    h = frame.h1 - t * p.height_mm
    narrowing_up = slope < 0  # the apex lies above the label
    rho = rho_c - (h - frame.h_c) if narrowing_up else rho_c + (h - frame.h_c)
    phi = (s - 0.5) * angle
    apex_y = rho_c if narrowing_up else -rho_c
    y = apex_y - rho * np.cos(phi) if narrowing_up else apex_y + rho * np.cos(phi)
    flat = np.stack([rho * np.sin(phi), y], -1)
    r_in, r_out = rho_c - p.height_mm / 2, rho_c + p.height_mm / 2
    figures = {"kind": "sector", "r_inner_mm": r_in, "r_outer_mm": r_out,
               "angle_deg": math.degrees(angle), "narrow_end": "top" if narrowing_up else "bottom"}
    return flat, figures


@dataclass(frozen=True)
class LabelWarning:
    """Why a label cannot lie flat, and where: ``kind`` ``"strain"``, ``"shoulder"`` or
    ``"corner"``; on the bottle ``z_mm``, ``angle_deg``; on the artwork ``s``, ``t``; on the
    die-line ``x_mm``, ``y_mm``."""

    kind: str
    message: str
    z_mm: float
    angle_deg: float
    s: float
    t: float
    x_mm: float
    y_mm: float

    def to_json(self) -> dict:
        return {k: (round(v, 4) if isinstance(v, float) else v) for k, v in self.__dict__.items()}


__all__ = ["FlatShape", "LabelWarning", "band_kind", "flat_shape", "grid_shape"]
