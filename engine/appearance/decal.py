"""A label's decal: its footprint in ``(theta, h)``, an ``(s, t)`` grid over it, the strain.

Design rule: a :class:`Decal` is what a kernel needs to know where a hit on the outer wall
falls on a label's artwork, with no geometry of its own: the footprint ``[theta0, theta1] x
[h0, h1]`` (``theta`` rad in the bottle frame, unwrapped, span at most ``2 pi``; ``h`` mm in the
tracer's convention, :mod:`engine.appearance.surface`) and a regular grid over it, node
``(i, j)`` at ``h = h0 + i (h1 - h0) / (nh - 1)``, ``theta = theta0 + j (theta1 - theta0) /
(nt - 1)``, holding the artwork ``(s, t)`` (float32; ``s`` left -> right with increasing
azimuth seen from outside, ``t`` top -> bottom) of the exact map
(:mod:`engine.appearance.frame`) and the paper strain there. The lookup is

1. ``theta' = theta0 + ((theta - theta0) mod 2 pi)``; outside ``[theta0, theta1] x [h0, h1]``:
   not on this label;
2. bilinear interpolation of the four nodes around ``(theta', h)``;
3. on the label iff ``0 <= s <= 1`` and ``0 <= t <= 1`` (NaN compares false, so a node the map
   does not reach can never be on a label).

Nodes outside the label carry the map's continuation (``s`` or ``t`` outside [0, 1]) rather than
NaN, so cells across an edge interpolate it exactly and the edge is sharp. The grid is made as
fine as the map needs (up to :data:`engine.limits.MAX_DECAL_NODES` a side): bilinear error at
every cell centre and edge midpoint at most :data:`TOLERANCE`, a quarter texel of a
4096-texel label. The tracer packs decals into its rows
(:func:`engine.tracer.tables.labels.pack_decals`) and looks them up compiled
(:func:`engine.tracer.kernels.labels.decal_lookup`); :meth:`Decal.lookup` is the same lookup,
vectorised, for tests and tools. The back face is seen from inside, so its
artwork coordinates are :func:`back_coordinates`.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .. import limits as L
from .dieline import _bilinear, flat_shape
from .frame import TWO_PI, Placement, label_frame

#: Largest bilinear error of ``(s, t)`` a decal grid allows: 1/4 texel at 4096 texels.
TOLERANCE = 0.25 / 4096
#: Nodes a side a decal starts from (and keeps, for its strain map, where the map is linear).
MIN_NODES = 17


@dataclass(frozen=True, eq=False)
class Decal:
    """One label's table (module rule). ``st`` is ``(nh, nt, 2)`` float32, ``strain`` ``(nh,
    nt)`` float32, both read-only; ``max_error`` the bilinear error the grid was checked to."""

    theta0: float
    theta1: float
    h0: float
    h1: float
    st: np.ndarray
    strain: np.ndarray
    kind: str
    max_error: float

    @property
    def shape(self) -> tuple[int, int]:
        """``(nh, nt)``: nodes along ``h`` and along ``theta``."""
        return self.st.shape[:2]

    def lookup(self, theta, h):
        """``(s, t)`` (float64) at surface points, NaN where not on the label (module rule)."""
        theta, h = np.broadcast_arrays(np.asarray(theta, float), np.asarray(h, float))
        nh, nt = self.shape
        th = self.theta0 + np.mod(theta - self.theta0, TWO_PI)
        fx = (th - self.theta0) / (self.theta1 - self.theta0) * (nt - 1)
        fy = (h - self.h0) / (self.h1 - self.h0) * (nh - 1)
        inside = (fx >= 0) & (fx <= nt - 1) & (fy >= 0) & (fy <= nh - 1)
        j = np.clip(np.floor(np.where(inside, fx, 0)).astype(np.int64), 0, nt - 2)
        i = np.clip(np.floor(np.where(inside, fy, 0)).astype(np.int64), 0, nh - 2)
        ax, ay = (np.where(inside, fx, 0) - j)[..., None], (np.where(inside, fy, 0) - i)[..., None]
        g = self.st.astype(np.float64)
        top = g[i, j] * (1 - ax) + g[i, j + 1] * ax
        bottom = g[i + 1, j] * (1 - ax) + g[i + 1, j + 1] * ax
        st = top * (1 - ay) + bottom * ay
        s, t = st[..., 0], st[..., 1]
        on = inside & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)
        return np.where(on, s, np.nan), np.where(on, t, np.nan)


def back_coordinates(s, t):
    """Artwork coordinates of the back face at a point whose front coordinates are ``(s, t)``:
    seen from inside the bottle the sheet reads the other way, so ``(1 - s, t)``."""
    return 1.0 - np.asarray(s, float), np.asarray(t, float)


def _grid(frame, nt: int, nh: int):
    theta = np.linspace(frame.theta0, frame.theta1, nt)
    h = np.linspace(frame.h0, frame.h1, nh)
    th, hh = np.meshgrid(theta, h)
    s, t = frame.st(th, hh)
    return np.stack([s, t], -1), theta, h


def _errors(frame, st, theta, h):
    """Largest bilinear error along theta (edge midpoints in theta), along h, and at centres."""
    tm, hm = 0.5 * (theta[1:] + theta[:-1]), 0.5 * (h[1:] + h[:-1])
    out = []
    for th, hh, ref in ((tm[None, :], h[:, None], 0.5 * (st[:, 1:] + st[:, :-1])),
                        (theta[None, :], hm[:, None], 0.5 * (st[1:] + st[:-1])),
                        (tm[None, :], hm[:, None], 0.25 * (st[1:, 1:] + st[1:, :-1] + st[:-1, 1:] + st[:-1, :-1]))):
        s, t = frame.st(*np.broadcast_arrays(th, hh))
        out.append(float(np.max(np.abs(np.stack([s, t], -1) - ref))))
    return out


def _refined(n: int) -> int:
    return min(2 * n - 1, L.MAX_DECAL_NODES)


@lru_cache(maxsize=64)
def placement_decal(shape, p: Placement) -> Decal:
    """The :class:`Decal` of a label placed at ``p`` on ``shape`` (cached by value: an artwork,
    finish or coefficient edit never rebuilds it). The label must lie on the wall."""
    frame = label_frame(shape, p)
    nt = nh = MIN_NODES
    st, theta, h = _grid(frame, nt, nh)
    err = 0.0
    if not frame.linear():
        while True:
            e_theta, e_h, e_mid = _errors(frame, st, theta, h)
            err = max(e_theta, e_h, e_mid)
            either = e_mid > TOLERANCE and e_theta <= TOLERANCE / 2 and e_h <= TOLERANCE / 2
            grow_t = (e_theta > TOLERANCE / 2 or either) and nt < L.MAX_DECAL_NODES
            grow_h = (e_h > TOLERANCE / 2 or either) and nh < L.MAX_DECAL_NODES
            if not (grow_t or grow_h):
                break
            nt, nh = (_refined(nt) if grow_t else nt), (_refined(nh) if grow_h else nh)
            st, theta, h = _grid(frame, nt, nh)
    flat = flat_shape(shape, p)
    strain = _bilinear(flat.strain, st[..., 0], st[..., 1]).astype(np.float32)
    st32 = np.ascontiguousarray(st, dtype=np.float32)
    for a in (st32, strain):
        a.setflags(write=False)
    return Decal(frame.theta0, frame.theta1, frame.h0, frame.h1, st32, strain,
                 flat.kind, err)


def label_decal(shape, label) -> Decal:
    """The :class:`Decal` of ``label`` (an ``engine.model.design.Label``) on ``shape``."""
    return placement_decal(shape, Placement.of(label))
