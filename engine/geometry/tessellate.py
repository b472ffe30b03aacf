"""Tessellation by chordal tolerance: watertight, consistently oriented meshes with exact normals.

Design rule: a body is a stack of *rings* (one closed loop of vertices per height on a wall, per
base station on a punt) sharing one set of polar angles ``theta``, so neighbouring rings join by
simple bands and parts share their edge rings position for position (edge rings are copied, not
recomputed, so the welded mesh is closed exactly). Vertices lie on the exact surfaces and carry
the exact unit normals of :class:`engine.geometry.body.BottleBody`; a crease vertex (base edge, rim edge)
appears once per part with that part's normal, so :meth:`Mesh.welded` merges positions for
topology checks and export.

Spacing follows the chord-sag rule ``sag ~ L * turn / 8`` (chord length times tangent turning):
samples are placed so that every chord's sag is about ``SAG_SHARE * tol_mm`` in each direction
(around and along the section), denser where curvature is high, none on straight stretches beyond
a floor that keeps bands from spanning more than ``MAX_DTHETA``. Flat parts are exact.

Size (bounded resources): around, the rule gives ``n_theta ~ (integral of sqrt(curvature) ds) /
sqrt(8 SAG_SHARE tol)``, at most ``sqrt(2 pi P / (8 SAG_SHARE tol))`` for a convex ring of
perimeter ``P`` (mm), plus ``2 pi / MAX_DTHETA = 24`` from the floor, plus the intervals halved
at corners sharper than the rule sees (never more than ``_FINE_ANGLES`` in all). Along, a
segment of length ``L`` (mm) turning ``T`` (rad) gets at most ``sqrt(L T / (8 SAG_SHARE tol)) + 1``
rings, plus the bands :func:`refine_heights` halves where a corner sweeps round with height.
A wall has about ``2 n_theta n_rings`` triangles, growing as ``1 / tol``: some 10^4 for a
60 mm wide, 200 mm tall bottle at 0.1 mm. A wall needing more than ``MAX_WALL_TRIANGLES`` is
refused with a ``ValueError`` naming the least tolerance that could fit, before its memory is
spent (only tolerances near ``MIN_TOL_MM`` on large bottles get there). It is refused rather
than quietly meshed coarser: an exported mesh is a promise about its tolerance, and the
designer can choose the coarser figure knowingly.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import shown
from ..limits import MAX_TOL_MM, MIN_TOL_MM
from .body import BottleBody
from .chain import locate, param_at_z

BODY_PARTS = ("outer", "inner", "base_outer", "base_inner", "rim")
LIQUID_PARTS = ("wall", "base", "surface")
#: Share of the tolerance given to each direction; the two sags add up at a triangle's inside.
SAG_SHARE = 0.45
#: Largest angular step (rad) even where the cross-section is straight.
MAX_DTHETA = math.radians(15.0)
#: Heights whose boundaries are sampled at once when choosing the polar angles (bounds memory).
_HEIGHTS_PER_BLOCK = 64
#: Angles of the fine grid (per turn, 0.125 degree steps) on which the chord sag around a ring is
#: measured; only the first quarter where the cross-section is symmetric about both axes.
_FINE_ANGLES = 2880
#: Rounds of halving sagging angle intervals: log2(MAX_DTHETA / two fine steps) < 6.
_MAX_SPLIT_ROUNDS = 8
#: Rounds of looking between checked heights: down to 1/64 of their spacing where needed.
_MAX_BETWEEN_ROUNDS = 6
#: Rounds of halving bands of a non-round wall (a band 2^16 times thinner is well below a micron).
_MAX_REFINE_ROUNDS = 16
#: Share of ``SAG_SHARE * tol`` below which a band's twist no longer splits it (see refine_heights).
_TWIST_FLOOR = 0.25
#: Most triangles one wall may have (about 50 MB of vertices and faces); finer is refused.
MAX_WALL_TRIANGLES = 2_000_000


@dataclass(frozen=True, eq=False)
class Mesh:
    """Triangles (mm) with exact per-vertex unit normals and a part id per face.

    ``vertices (N, 3) float64``, ``faces (M, 3) int64`` (counter-clockwise seen from the side the
    normals face), ``normals (N, 3)`` unit, ``part (M,) int`` indexing ``part_names``.
    """

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray
    part: np.ndarray
    part_names: tuple[str, ...]

    def welded(self):
        """``(vertices, faces)`` with vertices at identical positions merged (crease copies)."""
        uniq, inv = np.unique(self.vertices, axis=0, return_inverse=True)
        return uniq, inv.reshape(-1)[self.faces]

    def is_watertight(self) -> bool:
        """Every edge of the welded mesh is shared by exactly two faces, in opposite directions."""
        _, f = self.welded()
        e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        directed = np.unique(e, axis=0, return_counts=True)[1]
        undirected = np.unique(np.sort(e, axis=1), axis=0, return_counts=True)[1]
        return bool(np.all(directed == 1) and np.all(undirected == 2))

    def signed_volume(self) -> float:
        """Enclosed volume (mm^3) by the divergence theorem; positive when oriented outwards."""
        v = self.vertices[self.faces]
        return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0)


# --------------------------------------------------------------------------- sampling
def _equidistribute(density, n_out: int):
    """Positions in [0, 1] (fractions of the fine intervals) with equal shares of ``density``."""
    cum = np.concatenate([[0.0], np.cumsum(density)])
    targets = np.linspace(0.0, cum[-1], n_out + 1)
    return np.interp(targets, cum, np.linspace(0.0, 1.0, len(cum)))


def _sag_density(points, normals):
    """``sqrt(chord * turn)`` per fine interval of a sampled curve (points, unit normals)."""
    chord = np.linalg.norm(np.diff(points, axis=0), axis=-1)
    dots = np.clip(np.sum(normals[:-1] * normals[1:], axis=-1), -1.0, 1.0)
    return np.sqrt(chord * np.arccos(dots))


def theta_samples(body: BottleBody, tol_mm: float) -> np.ndarray:
    """Polar angles (rad) shared by every ring: chord sag <= ``SAG_SHARE * tol_mm`` around.

    Both walls count: the inner wall's corners are the outer's minus the wall thickness, so a
    rounded square's inner corner can be far sharper than its outer one. The angles first follow
    the sag rule (:func:`_sag_density`, equidistributed), then every interval whose measured sag
    on a fine grid of angles still exceeds the share is halved (:func:`_split_sagging`): the rule
    assumes the turning is spread over a chord, and underestimates a corner much smaller than
    the chord. The halving adds at most ``_FINE_ANGLES`` angles, whatever the shape; the sag is
    measured at the heights of :func:`_deciding_heights` and between them
    (:func:`_split_between_heights`). A cross-section symmetric about both axes (every fixed
    kind) is sampled on its first quarter turn and mirrored (:func:`_four_quarters`): a quarter
    of the work, and rings exactly four-fold symmetric; any other (a free plan outline) on the
    whole turn.
    """
    quarters = body.xs.mirror_quarters
    span = 0.5 * math.pi if quarters else 2.0 * math.pi
    fine = np.linspace(0.0, span, (_FINE_ANGLES // 4 if quarters else _FINE_ANGLES) + 1)
    heights = _deciding_heights(body)
    step = math.sqrt(8.0 * SAG_SHARE * tol_mm)
    dens = step * np.diff(fine) / MAX_DTHETA  # the floor: no band wider than MAX_DTHETA
    for x, y, nx, ny in _boundary_blocks(body, fine, heights):
        pts, nrm = np.stack(np.broadcast_arrays(x, y), -1), np.stack(np.broadcast_arrays(nx, ny), -1)
        dens = np.maximum(dens, np.max([_sag_density(p, n) for p, n in zip(pts, nrm)], axis=0))
    n = max(int(math.ceil(dens.sum() / step)), 2)
    angles = _equidistribute(dens, n) * span  # both ends included
    angles = _split_sagging(body, angles, fine, SAG_SHARE * tol_mm, heights)[0]
    angles = _split_between_heights(body, angles, fine, SAG_SHARE * tol_mm, heights)
    return _four_quarters(angles) if quarters else angles[:-1]


def _four_quarters(quarter) -> np.ndarray:
    """All angles in [0, 2 pi) from those of the first quarter (``0`` and ``pi / 2`` included),
    mirrored about both axes (a cross-section symmetric about them)."""
    back = quarter[::-1][:-1]  # from pi / 2 down to the first angle after 0
    return np.concatenate([quarter[:-1], math.pi - back, math.pi + quarter[:-1], 2 * math.pi - back])


def _deciding_heights(body: BottleBody):
    """``{part: heights (mm)}`` at which the walls' boundaries decide the angles: 9 per segment
    of every section (where radii and corners change); ``None`` for a round bottle, whose rings
    are circles (its widest one decides)."""
    if body.xs.revolved:
        return None
    out = {}
    for part in ("outer", "inner"):
        chains = [sp.outer_wall if part == "outer" else sp.inner_wall for sp in body.profile.sections]
        out[part] = np.unique(np.concatenate([s.point(np.linspace(0, 1, 9))[:, 1] for c in chains for s in c]))
    return out


def _boundary_blocks(body: BottleBody, angles, heights):
    """Boundary ``(x, y, nx, ny)`` (mm, unit; each ``(heights, len(angles))``) of the walls at
    ``heights`` (``{part: z}``, see :func:`_deciding_heights`), part by part and in blocks of
    ``_HEIGHTS_PER_BLOCK`` heights (bounded memory)."""
    if heights is None:
        widest = max(float(np.max(s.point(np.linspace(0, 1, 9))[:, 0]))
                     for s in body.profile.sections[0].outer_wall)
        yield body.xs.boundary([np.array([[widest]])], angles[None, :])
        return
    for part, z in heights.items():
        for lo in range(0, len(z), _HEIGHTS_PER_BLOCK):
            radii = [st[0][:, None] for st in body.wall_radii(part, z[lo:lo + _HEIGHTS_PER_BLOCK])]
            yield body.xs.boundary(radii, angles[None, :])


def _split_sagging(body: BottleBody, theta, fine, limit_mm: float, heights):
    """``(theta, sag_by_height)``: ``theta`` with every interval halved while its chord sags more
    than ``limit_mm`` (mm) from the boundary at some ``fine`` angle inside it, at any of
    ``heights``; and the largest sag (mm) at each height (in ``heights`` order) before halving.

    Bounded: an interval narrower than two fine steps is never split (the fine grid cannot see
    inside it), so at most ``len(fine)`` angles are added in at most ``log2(MAX_DTHETA / fine
    step)`` rounds. After the first round only the new halves are measured again.
    """
    min_width = 2.0 * (fine[1] - fine[0])
    dirty = np.ones(len(theta) - 1, bool)
    sag = np.zeros(len(theta) - 1)
    by_height = None
    for _ in range(_MAX_SPLIT_ROUNDS):
        sag[dirty], at_heights = _chord_sag(body, theta, fine, dirty, heights)
        by_height = at_heights if by_height is None else by_height
        split = (sag > limit_mm) & (np.diff(theta) >= min_width)
        if not split.any():
            break
        # a split interval's two halves follow it in the sorted angles: both to be measured
        theta = np.sort(np.concatenate([theta, 0.5 * (theta[:-1] + theta[1:])[split]]))
        sag, dirty = np.repeat(sag, 1 + split), np.repeat(split, 1 + split)
    return theta, by_height


def _split_between_heights(body: BottleBody, theta, fine, limit_mm: float, heights) -> np.ndarray:
    """``theta`` split (:func:`_split_sagging`) also half-way between the checked ``heights``,
    and again half-way next to every height where that found too much sag.

    A corner moves round as the radii change with height, so between two checked heights it can
    sit between the angles it had at both. At most ``_MAX_BETWEEN_ROUNDS`` rounds, each looking
    only next to the heights the previous one added.
    """
    if heights is None:  # circles: the widest one is the worst
        return theta
    heights = dict(heights)
    between = {part: 0.5 * (z[:-1] + z[1:]) for part, z in heights.items()}
    for _ in range(_MAX_BETWEEN_ROUNDS):
        theta, sag = _split_sagging(body, theta, fine, limit_mm, between)
        found, start = {}, 0
        for part, zb in between.items():
            found[part] = zb[sag[start:start + len(zb)] > limit_mm]
            start += len(zb)
        if not any(len(zf) for zf in found.values()):
            break
        for part, zf in found.items():
            z = heights[part] = np.unique(np.concatenate([heights[part], zf]))
            i = np.searchsorted(z, zf)  # each found height has checked neighbours on both sides
            between[part] = np.unique(np.concatenate([0.5 * (z[i - 1] + z[i]), 0.5 * (z[i] + z[i + 1])]))
    return theta


def _chord_sag(body: BottleBody, theta, fine, which, heights):
    """``(sag, sag_by_height)``: largest sag (mm) of the chords ``theta[i] -> theta[i + 1]``
    selected by the mask ``which``, over the ``fine`` angles inside them at every height; and
    the largest over those chords at each height."""
    k = np.clip(np.searchsorted(theta, fine, side="right") - 1, 0, len(theta) - 2)
    probe = which[k]
    k = k[probe]
    sag, by_height = np.zeros(len(theta) - 1), []
    for x, y, _, _ in _boundary_blocks(body, np.concatenate([theta, fine[probe]]), heights):
        x, y = np.broadcast_arrays(x, y)
        ax, ay = x[:, :len(theta) - 1], y[:, :len(theta) - 1]  # chord ends, then the probes
        bx, by = x[:, 1:len(theta)], y[:, 1:len(theta)]
        px, py = x[:, len(theta):], y[:, len(theta):]
        cx, cy = (bx - ax)[:, k], (by - ay)[:, k]
        off = np.abs(cx * (py - ay[:, k]) - cy * (px - ax[:, k])) / np.hypot(cx, cy)
        np.maximum.at(sag, k, off.max(axis=0, initial=0.0))
        by_height.append(off.max(axis=1, initial=0.0))
    return sag[which], np.concatenate(by_height)


def segment_samples(seg, tol_mm: float) -> np.ndarray:
    """Parameters ``t`` (0 and 1 included) along one segment: sag <= ``SAG_SHARE * tol_mm``."""
    if seg.kind == "line":
        return np.array([0.0, 1.0])
    t = np.linspace(0.0, 1.0, 257)
    tan = seg.tangent(t)
    dens = _sag_density(seg.point(t), np.stack([tan[:, 1], -tan[:, 0]], -1))
    n = max(int(math.ceil(dens.sum() / math.sqrt(8.0 * SAG_SHARE * tol_mm))), 1)
    return _equidistribute(dens, n)


def wall_heights(chains, tol_mm: float, z_lo: float, z_hi: float) -> np.ndarray:
    """Ring heights (mm) for walls: the union over sections of each segment's samples."""
    zs = [seg.point(segment_samples(seg, tol_mm))[:, 1] for c in chains for seg in c]
    z = np.unique(np.clip(np.concatenate(zs + [np.array([z_lo, z_hi])]), z_lo, z_hi))
    keep = np.concatenate([[True], np.diff(z) > 1e-7])  # one ring where sections' joints coincide
    z = z[keep]
    z[-1] = z_hi
    return z


def section_stations(chain, tol_mm: float, z_hi: float | None = None, z_lo: float | None = None):
    """Samples ``(r, z, T_r, T_z)`` along a rising chain up to height ``z_hi`` (from ``z_lo``).

    Used for round walls: rings come straight from the section (no inversion of r(z)), which
    also keeps a horizontal step of a per-segment wall as two rings at one height. A smooth
    joint is sampled once; a corner twice, at the same position, with each side's tangent (so
    both sides shade with their own exact normal).
    """
    out = []
    for i, seg in enumerate(chain):
        if z_hi is not None and seg.p0[1] >= z_hi - 1e-12 and i > 0:
            break
        t = segment_samples(seg, tol_mm)
        last = z_hi is not None and seg.p1[1] > z_hi
        if last:
            t_fill = float(param_at_z(seg, z_hi))
            t = np.append(t[t < t_fill - 1e-9], t_fill)
        p, tan = seg.point(t), seg.tangent(t)
        rows = np.column_stack([p, tan])
        if i > 0:
            prev = out[-1][-1]
            if abs(prev[2] * tan[0, 1] - prev[3] * tan[0, 0]) <= 1e-6:  # smooth: joint once
                rows = rows[1:]
            else:
                rows[0, :2] = prev[:2]  # same position bit for bit, the new side's tangent
        out.append(rows)
        if last:
            break
    st = np.concatenate(out)
    if z_lo is not None and z_lo > st[0, 1]:
        # the same arithmetic as the z_hi cut above, so that the ring on a cut shared by two
        # meshes (the fill line) is the same to the last bit in both
        seg = next(sg for sg in chain if sg.p1[1] > z_lo)
        t_cut = np.atleast_1d(float(param_at_z(seg, z_lo)))
        first = np.column_stack([seg.point(t_cut), seg.tangent(t_cut)])
        st = np.concatenate([first, st[st[:, 1] > first[0, 1] + 1e-9]])
    return st[:, 0], st[:, 1], st[:, 2], st[:, 3]


def chain_stations(chain, tol_mm: float) -> np.ndarray:
    """Base-chain parameters ``s`` in [0, 1] (equal share per segment) for punt rings."""
    n = len(chain)
    return np.unique(np.concatenate([(i + segment_samples(seg, tol_mm)) / n for i, seg in enumerate(chain)]))


def refine_heights(body: BottleBody, part: str, z, theta, tol_mm: float) -> np.ndarray:
    """Split bands (non-round walls) until the surface half-way up each band is within
    ``SAG_SHARE * tol_mm`` of the band's straight interpolation at every ``theta``, and within
    twice that of the middle of each band's diagonals.

    Needed because on a non-round wall the boundary point at a fixed angle can move between a
    side and a corner as the radii change with height, which the sections' curvature alone
    does not see.

    The diagonal's error is the ring's own chord sag around (set by ``theta``, which no thinner
    band changes) plus the twist between neighbouring angles (which halves with the band). A band
    is split for it only while its twist exceeds ``_TWIST_FLOOR`` of the share: where the angles
    are too coarse the splitting then still ends. (Without that floor every band of a wall once
    split 16 times over: 65536 times the rings, gigabytes.) It stops anyway after
    ``_MAX_REFINE_ROUNDS`` rounds, and :func:`_check_size` refuses a wall growing past
    ``MAX_WALL_TRIANGLES``.
    """
    if body.xs.revolved:
        return z
    limit = SAG_SHARE * tol_mm
    # the band's triangles meet along the diagonal (k, j) - (k + 1, j + 1): check its middle too
    theta_mid = theta + 0.5 * np.diff(np.append(theta, theta[0] + 2 * math.pi))
    p, _ = body.wall(part, theta[None, :], z[:, None])
    for _ in range(_MAX_REFINE_ROUNDS):
        zm = 0.5 * (z[:-1] + z[1:])
        pm, nm = body.wall(part, theta[None, :], zm[:, None])
        dev = np.abs(np.sum((pm - 0.5 * (p[:-1] + p[1:])) * nm, axis=-1))
        pd, nd = body.wall(part, theta_mid[None, :], zm[:, None])
        diag = 0.5 * (p[:-1] + np.roll(p[1:], -1, axis=1))
        dev_diag = np.abs(np.sum((pd - diag) * nd, axis=-1))
        # the diagonal's middle minus the chord's middle at the same height: the twist alone
        twist = np.abs(np.sum((0.5 * (pm + np.roll(pm, -1, axis=1)) - diag) * nd, axis=-1))
        curable = (dev_diag > 2 * limit) & (twist > _TWIST_FLOOR * limit)
        split = (dev.max(axis=1) > limit) | curable.any(axis=1)
        if not split.any():
            break
        z = np.sort(np.concatenate([z, zm[split]]))
        _check_size(2 * (len(z) - 1) * len(theta), tol_mm)
        p, _ = body.wall(part, theta[None, :], z[:, None])
    return z


def _check_size(n_triangles: int, tol_mm: float) -> None:
    """Refuse (``ValueError``) a wall of more than ``MAX_WALL_TRIANGLES`` triangles.

    The message names the least tolerance (mm) that could fit: counts grow at most as ``1 / tol``
    (angles and rings each as ``1 / sqrt(tol)``), slower where a floor or the section's own
    joints set the spacing, so the figure is a lower bound, not a promise.
    """
    if n_triangles > MAX_WALL_TRIANGLES:
        least = tol_mm * n_triangles / MAX_WALL_TRIANGLES
        unit = 10.0 ** (math.floor(math.log10(least)) - 1)  # two significant digits, rounded up
        raise ValueError(f"a chordal tolerance of {tol_mm:g} mm needs at least {n_triangles:,} triangles "
                         f"on one wall of this bottle, more than the {MAX_WALL_TRIANGLES:,} a wall may "
                         f"have; choose a coarser tolerance (at least {math.ceil(least / unit) * unit:.2g} mm)")


# --------------------------------------------------------------------------- assembly
class _Builder:
    """Collects vertex blocks and faces per part. Winding is fixed by construction (which side
    a band or fan faces follows from the walking direction), never guessed from the vertex
    normals: at a crease those can point almost anywhere."""

    def __init__(self, names):
        self.names, self.v, self.n, self.f, self.p, self.count = names, [], [], [], [], 0

    def add(self, pts, nrm) -> np.ndarray:
        pts, nrm = np.asarray(pts, float).reshape(-1, 3), np.asarray(nrm, float).reshape(-1, 3)
        idx = np.arange(self.count, self.count + len(pts))
        self.v.append(pts), self.n.append(nrm)
        self.count += len(pts)
        return idx

    def faces(self, part: str, tris) -> None:
        self.f.append(np.asarray(tris, np.int64).reshape(-1, 3))
        self.p.append(np.full(len(self.f[-1]), self.names.index(part)))

    def band(self, part, ring_a, ring_b, flip: bool = False) -> None:
        """Faces between two rings (angles increasing). Walking the section from ``ring_a`` to
        ``ring_b``, they face the section's outward side ``n = (T_z, -T_r)``; ``flip`` turns them."""
        a0, b0 = ring_a, ring_b
        a1, b1 = np.roll(ring_a, -1), np.roll(ring_b, -1)
        tris = np.concatenate([np.stack([a0, a1, b1], 1), np.stack([a0, b1, b0], 1)])
        self.faces(part, tris[:, ::-1] if flip else tris)

    def fan(self, part, centre: int, ring, flip: bool = False) -> None:
        """Faces from a centre vertex to a ring (angles increasing): facing +z unless ``flip``."""
        tris = np.stack([np.full(len(ring), centre), ring, np.roll(ring, -1)], 1)
        self.faces(part, tris[:, ::-1] if flip else tris)

    def grid(self, part, pts, nrm, flip: bool = False) -> list:
        """Rings from a ``(K, M, 3)`` block, banded together (not where two rings coincide: a
        crease's two copies); returns the ring index arrays."""
        idx = self.add(pts, nrm).reshape(pts.shape[:2])
        for k in range(len(idx) - 1):
            if not np.array_equal(pts[k], pts[k + 1]):
                self.band(part, idx[k], idx[k + 1], flip)
        return list(idx)

    def mesh(self) -> Mesh:
        v, n = np.concatenate(self.v), np.concatenate(self.n)
        return Mesh(v, np.concatenate(self.f), n, np.concatenate(self.p), self.names)


def _wall(b, body, part, label, theta, tol, z_lo, z_hi, flip=1.0):
    """Rings of a wall from ``z_lo`` to ``z_hi`` banded together; returns the ring indices.

    Round walls revolve the section's own samples; other walls take ring heights from every
    section (:func:`wall_heights`, :func:`refine_heights`). ``flip`` -1 turns the normals round
    (a liquid faces out of the cavity). Faces face the way the normals do.
    """
    faces_in = (part == "inner") == (flip > 0)  # the glass's inner wall faces against n
    chains = [sp.outer_wall if part == "outer" else sp.inner_wall for sp in body.profile.sections]
    if body.xs.revolved:
        r, z, tr, tz = section_stations(chains[0], tol, z_hi, z_lo)
        _check_size(2 * (len(z) - 1) * len(theta), tol)
        sign = flip * (1.0 if part == "outer" else -1.0)  # the inner wall faces the cavity
        c, s = np.cos(theta)[None, :], np.sin(theta)[None, :]
        pts = np.stack(np.broadcast_arrays(r[:, None] * c, r[:, None] * s, z[:, None]), axis=-1)
        nrm = np.stack(np.broadcast_arrays(sign * tz[:, None] * c, sign * tz[:, None] * s,
                                           -sign * tr[:, None] + 0 * c), axis=-1)
        return b.grid(label, pts, nrm, faces_in)
    z = wall_heights(chains, tol, z_lo, z_hi)
    _check_size(2 * (len(z) - 1) * len(theta), tol)
    z = refine_heights(body, part, z, theta, tol)
    pts, nrm = body.wall(part, theta[None, :], z[:, None])
    corners = np.nonzero(np.isin(z, _corner_heights(chains)))[0]
    if len(corners):  # a second ring at each corner: same positions, the upper side's normals
        _, n_up = body.wall(part, theta[None, :], z[corners, None], above=True)
        pts = np.insert(pts, corners + 1, pts[corners], axis=0)
        nrm = np.insert(nrm, corners + 1, n_up, axis=0)
    return b.grid(label, pts, flip * nrm, faces_in)


def _corner_heights(chains) -> np.ndarray:
    """Heights (mm) of the joints where some section's tangent turns (more than 1e-6 rad)."""
    zs = []
    for c in chains:
        for a, b in zip(c[:-1], c[1:]):
            ta, tb = a.tangent(1.0), b.tangent(0.0)
            if abs(ta[0] * tb[1] - ta[1] * tb[0]) > 1e-6:
                zs.append(a.p1[1])
    return np.array(zs)


def _copy_ring(b: _Builder, ring, normals) -> np.ndarray:
    """A copy of an existing ring's positions with other normals (a crease between parts)."""
    pts = np.concatenate(b.v)[ring]
    return b.add(pts, np.broadcast_to(normals, pts.shape))


def _base(b, body, part, label, theta, edge_ring, tol_mm, s_stop=None):
    """A base ending at ``edge_ring``: a flat fan, or punt rings (round bottles).

    With ``s_stop`` the punt rings start at that base parameter instead of the axis (a liquid
    surface below the top of the punt) and the first ring is returned. ``label`` "base" is the
    liquid's base, whose normals face down, out of the liquid.
    """
    flip = -1.0 if label == "base" else 1.0
    # Bands walked outwards from the axis face down (n of the base chain); fans face up.
    down = part == "base_outer" or label == "base"
    if not body.profile.punt:
        normal = body.point_normal(part, 0.0, 0.5)[1] * flip
        ring = _copy_ring(b, edge_ring, normal)
        centre = np.concatenate(b.v)[edge_ring[0]] * [0.0, 0.0, 1.0]
        b.fan(label, int(b.add(centre, normal)[0]), ring, flip=down)
        return None
    chain = body.profile.sections[0].outer_base if part == "base_outer" else body.profile.sections[0].inner_base
    s = chain_stations(chain, tol_mm)
    start = 0.0 if s_stop is None else s_stop
    mid = s[(s > start + 1e-9) & (s < 1.0 - 1e-9)]
    _check_size(2 * len(mid) * len(theta), tol_mm)
    rings = []
    if len(mid):
        pts, nrm = body.point_normal(part, theta[None, :], mid[:, None])
        rings = [b.add(pts[k], flip * nrm[k]) for k in range(len(mid))]
    rings.append(_copy_ring(b, edge_ring, flip * body.point_normal(part, theta, 1.0)[1]))
    first = None
    if s_stop is None:
        p0, n0 = body.point_normal(part, 0.0, 0.0)
        b.fan(label, int(b.add(p0, flip * n0)[0]), rings[0], flip=down)
    else:
        p0, n0 = body.point_normal(part, theta, s_stop)
        first = b.add(p0, flip * n0)
        rings.insert(0, first)
    for ring_a, ring_b in zip(rings[:-1], rings[1:]):
        b.band(label, ring_a, ring_b, flip=not down)
    return first


def _check_tol(tol_mm: float) -> float:
    """The tolerance as a float in ``engine.limits.MIN_TOL_MM..MAX_TOL_MM``, else ``ValueError``."""
    tol = float(tol_mm)
    if not (math.isfinite(tol) and MIN_TOL_MM <= tol <= MAX_TOL_MM):
        raise ValueError(f"the chordal tolerance must be {MIN_TOL_MM:g} to {MAX_TOL_MM:g} mm, "
                         f"got {shown(tol_mm)}")
    return tol


def tessellate_body(shape, tol_mm: float = 0.05) -> Mesh:
    """The closed glass shell of ``shape`` as a :class:`Mesh` within ``tol_mm`` of the surfaces.

    Parameters
    ----------
    shape : BottleShape
        The bottle; validated here.
    tol_mm : float
        Largest distance (mm) of any triangle from the exact surface (chordal tolerance).

    Returns
    -------
    Mesh
        Parts ``BODY_PARTS`` (outer wall, inner wall, outer base, inner base, rim); faces and
        normals face out of the glass; the welded mesh is watertight.

    Raises
    ------
    SectionError, WallError
        For an invalid shape.
    ValueError
        For a tolerance that is not a positive number.
    """
    tol = _check_tol(tol_mm)
    body = BottleBody(shape)
    prof = body.profile
    theta = theta_samples(body, tol)
    b = _Builder(BODY_PARTS)
    outer = _wall(b, body, "outer", "outer", theta, tol, 0.0, prof.z_top)
    inner = _wall(b, body, "inner", "inner", theta, tol, prof.z_ib, prof.z_top)
    _base(b, body, "base_outer", "base_outer", theta, outer[0], tol)
    _base(b, body, "base_inner", "base_inner", theta, inner[0], tol)
    up = np.array([0.0, 0.0, 1.0])
    b.band("rim", _copy_ring(b, inner[-1], up), _copy_ring(b, outer[-1], up), flip=True)  # walked outwards
    return b.mesh()


INTERFACE_NAMES = ("glass_air", "glass_liquid", "liquid_air")


def tessellate_interfaces(shape, fill_height, tol_mm: float = 0.05) -> dict:
    """The optical interfaces of ``shape`` filled to ``fill_height`` (mm, or ``None``), as
    separate meshes for a renderer that needs one surface per pair of media.

    ``glass_air``: outer wall, outer base, rim and the inner wall above the liquid (and the inner
    base when empty), facing out of the glass; ``glass_liquid``: the wetted inner wall and the
    inner base, facing out of the glass (into the liquid); ``liquid_air``: the free surface,
    facing up. Rings on the fill line coincide bit for bit across meshes.
    """
    tol = _check_tol(tol_mm)
    body = BottleBody(shape)
    prof = body.profile
    theta = theta_samples(body, tol)
    wet = fill_height is not None and fill_height > prof.z_ib
    h = float(fill_height) if wet else prof.z_ib
    out = {}
    b = _Builder(BODY_PARTS)
    outer = _wall(b, body, "outer", "outer", theta, tol, 0.0, prof.z_top)
    _base(b, body, "base_outer", "base_outer", theta, outer[0], tol)
    inner = _wall(b, body, "inner", "inner", theta, tol, h if wet else prof.z_ib, prof.z_top)
    if not wet:
        _base(b, body, "base_inner", "base_inner", theta, inner[0], tol)
    up = np.array([0.0, 0.0, 1.0])
    b.band("rim", _copy_ring(b, inner[-1], up), _copy_ring(b, outer[-1], up), flip=True)
    out["glass_air"] = b.mesh()
    if wet:
        b = _Builder(BODY_PARTS)
        inner = _wall(b, body, "inner", "inner", theta, tol, prof.z_ib, h)
        _base(b, body, "base_inner", "base_inner", theta, inner[0], tol)
        out["glass_liquid"] = b.mesh()
        liq = tessellate_liquid(shape, h, tol)
        keep = liq.part == liq.part_names.index("surface")
        used = np.unique(liq.faces[keep])
        remap = np.full(len(liq.vertices), -1, np.int64)
        remap[used] = np.arange(len(used))
        out["liquid_air"] = Mesh(liq.vertices[used], remap[liq.faces[keep]], liq.normals[used],
                                 np.zeros(int(keep.sum()), np.int64), ("surface",))
    return out


def tessellate_liquid(shape, fill_height: float, tol_mm: float = 0.05) -> Mesh:
    """The closed liquid volume filled to ``fill_height`` (mm above z = 0) as a :class:`Mesh`.

    Parts (``LIQUID_PARTS``): the inner wall below the fill, the inner base, the flat free
    surface (a disk, or an annulus when the level is below the top of a punt). Normals face out
    of the liquid. Requires ``z_ib < fill_height <= z_top``.
    """
    tol = _check_tol(tol_mm)
    body = BottleBody(shape)
    prof = body.profile
    fill = float(fill_height)
    if not (prof.z_ib < fill <= prof.z_top):
        raise ValueError(f"fill height {fill:g} mm is outside the cavity ({prof.z_ib:g} to {prof.z_top:g} mm)")
    theta = theta_samples(body, tol)
    b = _Builder(LIQUID_PARTS)
    wall = _wall(b, body, "inner", "wall", theta, tol, prof.z_ib, fill, flip=-1.0)
    up = np.array([0.0, 0.0, 1.0])
    base_chain = prof.sections[0].inner_base
    if prof.punt and fill < base_chain[0].p0[1]:
        i, t = locate(base_chain, np.array([fill]))
        first = _base(b, body, "base_inner", "base", theta, wall[0], tol, float((i[0] + t[0]) / len(base_chain)))
        b.band("surface", _copy_ring(b, first, up), _copy_ring(b, wall[-1], up), flip=True)
    else:
        _base(b, body, "base_inner", "base", theta, wall[0], tol)
        ring = _copy_ring(b, wall[-1], up)
        b.fan("surface", int(b.add([0.0, 0.0, fill], up)[0]), ring)
    return b.mesh()
