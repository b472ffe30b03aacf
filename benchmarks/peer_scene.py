"""Mitsuba 3 scenes of SPEC oracle scenes, tessellated the way the references were (SPEC section 6).

Design rule: the peer renders the scene the references show, so it is built from the SPEC file
alone, as SPEC section 6 says the references were made: flat triangles with their vertices
exactly on the surfaces, every facet turning at most ``max_turn_deg`` (0.2 degrees) from its
neighbour. Round bottles revolve their profile at ``ceil(360 / max_turn_deg)`` (1800) points per
ring; profile arcs and ellipse arcs are split every ``max_turn_deg`` of tangent turning, lines
every ``max_seg_mm``; rounded squares use rings of four corner arcs split every ``max_turn_deg``
and straight sides split every ``max_seg_mm``, at the heights where either profile has a sample.
Outline bottles (SPEC_outline, smooth plans only: :func:`outline_rings`) put each plan arc's
points every ``max_turn_deg`` at the same angles at every height, at the heights where the core or
the rounding has a sample and wherever else the surface's normal would turn more between rings.
Inner curves are the outer samples offset by the wall (an offset keeps the tangent, so it turns
as little per facet), cut exactly at the inner base and the fill line. Nothing here uses the
engine's geometry: a bug shared by glassbench and its peer would go unseen by the comparison.

A coarser mesh with flat facets is a different scene: a 0.005 mm chord on a 35 mm radius turns
1.9 degrees per facet, and refraction through such facets converged to 2.05 % rel RMSE from
public_1's reference, where this conversion's error keeps falling with the samples
(:mod:`benchmarks.peer_check` proves it before the peer benchmark prints a ratio).

Meshes (one per pair of media, faces oriented towards the exterior medium, rings on a shared
cut the same to the last bit): ``glass_air`` (outer wall and base, rim, inner wall above the
liquid, inner base when empty), ``glass_liquid`` (wetted inner wall and inner base, facing into
the liquid), ``liquid_air`` (the free surface, facing up). A SPEC_ground ``ground`` block becomes
a one-sided ``rectangle`` with a ``diffuse`` BSDF (its underside is black, as SPEC_ground says).
Units: mm.
"""
from __future__ import annotations

import glob
import json
import math
import os
import time
from dataclasses import dataclass

import numpy as np

#: SPEC section 6 tessellation, used where a spec's ``render.tessellation`` does not say.
DEFAULT_TESSELLATION = {"max_turn_deg": 0.2, "max_seg_mm": 1000.0, "n_theta_min": 64}
#: The peer's scene conversion: SPEC section 6's facets, flat (the references' own scene).
CONVERSION = {"max_turn_deg": 0.2, "vertex_normals": False}
#: Slack of the split rule ``ceil(turn / max_turn - slack)``: the fewest pieces, so a turn that
#: computes to 450.00000000000006 steps is split in 450. SPEC_outline 8's references were split by
#: plain ``ceil`` (slack 0: the hip flask's base rounding in 451, as its rings count), and its flat
#: facets are not a statistical texture: the two meshes' bases differ by 4.6 % rel RMSE, the one
#: with 451 matches the reference to its noise (benchmarks/facet_bias.py). A tessellation's
#: ``split_slack`` overrides it (profile pieces and plan arcs).
SPLIT_SLACK = 1e-9
#: The references' integrator (SPEC section 6): no Russian roulette before max_depth.
MAX_DEPTH = 1024
LLVM_CANDIDATES = ("/usr/lib/x86_64-linux-gnu/libLLVM-19.so", "/usr/lib/llvm-19/lib/libLLVM-19.so",
                   "/usr/lib/aarch64-linux-gnu/libLLVM-19.so")
#: SPEC section 3: Mitsuba's envmap frame (y up) turned onto the SPEC world (z up).
ENV_TO_WORLD = [[0, 0, -1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]


def mitsuba_available() -> str | None:
    """Import Mitsuba with the LLVM 19 back end; ``None`` if it works, else why not."""
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        for p in LLVM_CANDIDATES + tuple(glob.glob("/usr/lib/*/libLLVM-19*.so*")):
            if os.path.exists(p):
                os.environ["DRJIT_LIBLLVM_PATH"] = p
                break
    try:
        import mitsuba as mi

        mi.set_variant("llvm_ad_rgb")
    except Exception as exc:  # noqa: BLE001 - any failure means: no peer here
        return f"{type(exc).__name__}: {exc}"
    return None


# ------------------------------------------------------------------------------ profile pieces
@dataclass(frozen=True)
class Piece:
    """One SPEC profile segment as a function of ``t`` in [0, 1]: points ``(r, z)`` and the
    outward normal ``n = (T_z, -T_r)``. Arcs run linearly in their angle, ellipse arcs in their
    parameter; ``a0, a1`` are those (unwrapped in the walking direction)."""

    kind: str
    p0: tuple
    p1: tuple
    centre: tuple = (0.0, 0.0)
    radii: tuple = (0.0, 0.0)
    a0: float = 0.0
    a1: float = 0.0

    @staticmethod
    def from_spec(seg: dict) -> "Piece":
        kind, p0, p1 = seg["type"], tuple(map(float, seg["p0"])), tuple(map(float, seg["p1"]))
        if kind == "line":
            return Piece(kind, p0, p1)
        c = tuple(map(float, seg["center"]))
        radii = (float(seg["radius"]),) * 2 if kind == "arc" else (float(seg["radius_r"]), float(seg["radius_z"]))
        a0, a1 = (math.atan2((p[1] - c[1]) / radii[1], (p[0] - c[0]) / radii[0]) for p in (p0, p1))
        ccw = seg["direction"] == "ccw"
        a1 = a0 + (a1 - a0) % (2 * math.pi) if ccw else a0 - (a0 - a1) % (2 * math.pi)
        return Piece(kind, p0, p1, c, radii, a0, a1)

    @property
    def ccw(self) -> bool:
        return self.a1 > self.a0

    def at(self, t):
        """``(r, z, n_r, n_z)`` at parameters ``t`` (arrays)."""
        t = np.asarray(t, float)
        if self.kind == "line":
            d = np.subtract(self.p1, self.p0)
            tr, tz = d / np.hypot(*d)
            return self.p0[0] + t * d[0], self.p0[1] + t * d[1], tz + 0 * t, -tr + 0 * t
        a = self.a0 + t * (self.a1 - self.a0)
        (cr, cz), (ra, rb), s = self.centre, self.radii, 1.0 if self.ccw else -1.0
        tr, tz = -s * ra * np.sin(a), s * rb * np.cos(a)  # tangent, walking direction
        norm = np.hypot(tr, tz)
        return cr + ra * np.cos(a), cz + rb * np.sin(a), tz / norm, -tr / norm

    def tangent_angle(self, t):
        r, z, nr, nz = self.at(t)
        return np.arctan2(nr, -nz)  # T = (-n_z, n_r)

    def samples(self, max_turn: float, max_seg: float, slack: float = SPLIT_SLACK) -> np.ndarray:
        """Parameters (0 and 1 included): tangent turning at most ``max_turn`` (rad) and chords
        of at most ``max_seg`` (mm) between neighbours (``slack``: :data:`SPLIT_SLACK`)."""
        if self.kind == "line":
            return np.linspace(0.0, 1.0, max(1, math.ceil(math.dist(self.p0, self.p1) / max_seg)) + 1)
        psi0, psi1 = (float(self.tangent_angle(t)) for t in (0.0, 1.0))
        turn = (psi1 - psi0) % (2 * math.pi) if self.ccw else (psi0 - psi1) % (2 * math.pi)
        length = max(self.radii) * abs(self.a1 - self.a0)  # bounds the arc length
        n = max(1, math.ceil(turn / max_turn - slack), math.ceil(length / max_seg))
        if self.kind == "arc":  # the tangent turns with the angle
            return np.linspace(0.0, 1.0, n + 1)
        return self._ellipse_params(psi0 + np.linspace(0.0, 1.0, n + 1) * turn * (1 if self.ccw else -1))

    def _ellipse_params(self, psi) -> np.ndarray:
        """Parameters ``t`` where an ellipse arc's tangent angle is ``psi`` (exact inversion)."""
        ra, rb = self.radii
        s = 1.0 if self.ccw else -1.0  # T = s (-ra sin a, rb cos a) ∝ (cos psi, sin psi)
        a = np.arctan2(-s * np.cos(psi) / ra, s * np.sin(psi) / rb)
        t_lin = np.linspace(0.0, 1.0, len(psi))
        a_lin = self.a0 + t_lin * (self.a1 - self.a0)
        a += 2 * math.pi * np.round((a_lin - a) / (2 * math.pi))
        t = (a - self.a0) / (self.a1 - self.a0)
        t[0], t[-1] = 0.0, 1.0
        return np.clip(t, 0.0, 1.0)


def pieces_of(profile) -> list[Piece]:
    return [Piece.from_spec(seg) for seg in profile]


def wall_stations(pieces, tess) -> tuple:
    """Samples of the walls' segments (1..n): ``(r, z, n_r, n_z, piece index, t)`` arrays, a
    joint once (the lower segment's end)."""
    max_turn, max_seg = math.radians(tess["max_turn_deg"]), float(tess["max_seg_mm"])
    rows = []
    for k, pc in enumerate(pieces[1:], start=1):
        t = pc.samples(max_turn, max_seg, tess.get("split_slack", SPLIT_SLACK))
        if rows:
            t = t[1:]
        rows.append(np.column_stack([*pc.at(t), np.full(len(t), k), t]))
    st = np.concatenate(rows)
    return tuple(st[:, i] for i in range(6))


def offset_z(piece: Piece, t, w: float):
    """Height (mm) of ``piece``'s point at ``t`` offset inwards by ``w``."""
    _, z, _, nz = piece.at(t)
    return z - w * nz


def param_at_height(pieces, w: float, z) -> tuple:
    """``(piece index, t)`` of the points at heights ``z`` on the wall curve offset by ``w`` (0:
    the outer wall), by bisection: every wall curve rises (SPEC 4.1 rule 4 and 6)."""
    z = np.atleast_1d(np.asarray(z, float))
    idx, t = np.full(z.shape, -1), np.zeros(z.shape)
    for k, pc in enumerate(pieces[1:], start=1):
        lo_z, hi_z = float(offset_z(pc, 0.0, w)), float(offset_z(pc, 1.0, w))
        here = (idx < 0) & (z >= lo_z - 1e-9) & (z <= hi_z + 1e-9)
        if not here.any():
            continue
        lo, hi = np.zeros(here.sum()), np.ones(here.sum())
        for _ in range(64):  # 2^-64: the parameter to the last bit
            mid = 0.5 * (lo + hi)
            below = offset_z(pc, mid, w) < z[here]
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        idx[here], t[here] = k, 0.5 * (lo + hi)
    if (idx < 0).any():
        raise ValueError(f"heights {z[idx < 0][:3]} mm are off the wall (offset {w} mm)")
    return idx, t


def radius_at(pieces, w: float, z) -> tuple[np.ndarray, np.ndarray]:
    """Radius (mm) and its slope ``dr/dz`` of the wall curve offset by ``w`` at heights ``z``
    (an offset keeps the normal, so the slope is the outer curve's at the same parameter)."""
    idx, t = param_at_height(pieces, w, z)
    r, slope = np.empty(len(z)), np.empty(len(z))
    for k in np.unique(idx):
        sel = idx == k
        rr, _, nr, nz = pieces[k].at(t[sel])
        r[sel], slope[sel] = rr - w * nr, -nz / nr  # T = (-n_z, n_r): walls rise, n_r > 0
    return r, slope


def _merge_heights(z) -> np.ndarray:
    z = np.unique(np.asarray(z, float))
    return z[np.concatenate([[True], np.diff(z) > 1e-9])]


# ------------------------------------------------------------------------------ rings
@dataclass(frozen=True)
class Rings:
    """A wall as rings of one vertex layout: ``xy (K, M, 2)`` (world frame, mm), ``z (K,)``,
    and the exact unit normals ``n (K, M, 3)`` facing away from the axis (SPEC's ``n``)."""

    xy: np.ndarray
    z: np.ndarray
    n: np.ndarray

    def points(self, k) -> np.ndarray:
        return np.column_stack([self.xy[k], np.full(len(self.xy[k]), self.z[k])])

    def between(self, z_lo: float, z_hi: float) -> "Rings":
        sel = (self.z >= z_lo - 1e-12) & (self.z <= z_hi + 1e-12)
        return Rings(self.xy[sel], self.z[sel], self.n[sel])


def round_layout(tess) -> np.ndarray:
    """Polar angles (rad) of a round bottle's rings: ``max_turn_deg`` apart (1800 at 0.2)."""
    n = max(math.ceil(360.0 / tess["max_turn_deg"] - 1e-9), int(tess.get("n_theta_min", 0)))
    return 2 * math.pi * np.arange(n) / n


def square_ring(u, v, du, dv, tess, rotation_deg) -> tuple[np.ndarray, np.ndarray]:
    """Rounded-square rings ``(K, M, 2)`` for radii ``u, v (K,)`` and their unit normals
    ``(K, M, 3)`` from the slopes ``du, dv`` (d/dz): each corner arc split every
    ``max_turn_deg``, each side every ``max_seg_mm`` (the same layout at every height).

    A corner's point at angle ``phi`` moves with height along its normal by ``p' (cos phi +
    sin phi) + q'`` (``p``, ``q`` are linear in ``u``, ``v``), so its normal is ``(cos phi,
    sin phi, -that)``; a side's is its corners' end normal."""
    u, v = np.asarray(u, float), np.asarray(v, float)
    # a round neck (u = v) has sides of length 0: the two radii come from two bisections, and
    # their last-bit difference would make slivers of either orientation there
    round_here = np.abs(v - u) <= 1e-9 * u
    p = np.where(round_here, 0.0, (math.sqrt(2) + 1) * (v - u))
    q = np.where(round_here, u, (math.sqrt(2) + 1) * (math.sqrt(2) * u - v))
    dp, dq = (math.sqrt(2) + 1) * (dv - du), (math.sqrt(2) + 1) * (math.sqrt(2) * du - dv)
    n_corner = math.ceil(90.0 / tess["max_turn_deg"] - 1e-9)
    n_side = max(1, math.ceil(2 * float(p.max(initial=0.0)) / float(tess["max_seg_mm"])))
    # a quarter's cosines, its sines the same reversed: the corners' end points are exact (no
    # sin(2 pi) = -2e-16), so a round neck's sides have length 0, not a sliver of any normal
    c = np.cos(np.linspace(0.0, 0.5 * math.pi, n_corner + 1))
    c[-1] = 0.0
    s = c[::-1]
    x, y = p[:, None] + q[:, None] * c, p[:, None] + q[:, None] * s
    nz = np.broadcast_to(-(dp[:, None] * (c + s) + dq[:, None]), x.shape)
    nx, ny = np.broadcast_to(c, x.shape), np.broadcast_to(s, x.shape)
    turns = lambda a, b: ((a, b), (-b, a), (-a, -b), (b, -a))  # noqa: E731 - 90 degree turns: exact
    corners = [np.stack(xy, -1) for xy in turns(x, y)]
    normals = [np.stack([*nxy, nz], -1) for nxy in turns(nx, ny)]
    f = np.arange(1, n_side)[None, :, None] / n_side
    parts, nparts = [], []
    for j, (corner, normal) in enumerate(zip(corners, normals)):
        # then the side to the next corner's first point, without its ends
        end, start = corner[:, -1], corners[(j + 1) % 4][:, 0]
        parts += [corner, end[:, None] + f * (start - end)[:, None]]
        nparts += [normal, np.repeat(normal[:, -1:], n_side - 1, axis=1)]
    xy, n = np.concatenate(parts, axis=1), np.concatenate(nparts, axis=1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    c, s = math.cos(math.radians(rotation_deg)), math.sin(math.radians(rotation_deg))
    turn = lambda a: np.stack([c * a[..., 0] - s * a[..., 1], s * a[..., 0] + c * a[..., 1]], -1)  # noqa: E731
    return turn(xy), np.concatenate([turn(n), n[..., 2:]], -1)


def _revolved(r, z, nr, nz, theta) -> Rings:
    c, s = np.cos(theta)[None, :], np.sin(theta)[None, :]
    xy = np.stack([r[:, None] * c, r[:, None] * s], -1)
    n = np.stack(np.broadcast_arrays(nr[:, None] * c, nr[:, None] * s, nz[:, None]), -1)
    return Rings(xy, z, n)


def _square_rings(pu, pv, w, z, tess, rotation_deg) -> Rings:
    (u, du), (v, dv) = radius_at(pu, w, z), radius_at(pv, w, z)
    xy, n = square_ring(u, v, du, dv, tess, rotation_deg)
    return Rings(xy, z, n)


# ------------------------------------------------------------------------------ plan outlines
@dataclass(frozen=True)
class PlanPiece:
    """One segment of a SPEC_outline plan ``P``, normalised (SPEC_outline 2, rule 5): a line
    ``p0 -> p1`` or an arc about ``centre`` of ``radius`` from angle ``a0`` to ``a1 > a0`` (rad,
    counter-clockwise). Its points are ``A`` with outward unit normals ``u``; the section of core
    ``k`` grown by ``r`` puts each at ``k A + r u`` (SPEC_outline 4, 5 where ``r >= 0``)."""

    kind: str
    p0: tuple
    p1: tuple
    centre: tuple = (0.0, 0.0)
    radius: float = 0.0
    a0: float = 0.0
    a1: float = 0.0

    @staticmethod
    def from_spec(seg: dict, scale: float) -> "PlanPiece":
        p0, p1 = (tuple(float(x) / scale for x in seg[k]) for k in ("p0", "p1"))
        if seg["type"] == "line":
            return PlanPiece("line", p0, p1)
        if seg["type"] != "arc" or not seg.get("ccw", False):
            raise ValueError(f"plan segment {seg} is neither a line nor a ccw arc (SPEC_outline 2)")
        c, rho = tuple(float(x) / scale for x in seg["center"]), float(seg["radius"]) / scale
        a0, a1 = (math.atan2(p[1] - c[1], p[0] - c[0]) for p in (p0, p1))
        span = (a1 - a0) % (2 * math.pi)
        return PlanPiece("arc", p0, p1, c, rho, a0, a0 + (span if span > 1e-12 else 2 * math.pi))

    def normal_angles(self) -> tuple[float, float]:
        """Angles (rad) of the outward normal at the start and at the end."""
        if self.kind == "arc":
            return self.a0, self.a1
        a = math.atan2(self.p1[1] - self.p0[1], self.p1[0] - self.p0[0]) - 0.5 * math.pi  # n = (e_y, -e_x)
        return a, a

    def layout(self, max_turn: float, max_len: float, slack: float = SPLIT_SLACK) -> tuple[np.ndarray, np.ndarray]:
        """Points ``A (m, 2)`` and normals ``u (m, 2)`` from the start up to, not including, the
        end: an arc every ``max_turn`` (rad) of turning (``slack``: :data:`SPLIT_SLACK`), a line in
        pieces of at most ``max_len`` (its length in P units)."""
        if self.kind == "line":
            n = max(1, math.ceil(math.dist(self.p0, self.p1) / max_len))
            f = np.arange(n)[:, None] / n
            a = self.normal_angles()[0]
            return np.add(self.p0, f * np.subtract(self.p1, self.p0)), np.tile([math.cos(a), math.sin(a)], (n, 1))
        n = max(1, math.ceil((self.a1 - self.a0) / max_turn - slack))
        a = self.a0 + (self.a1 - self.a0) * np.arange(n) / n
        u = np.column_stack([np.cos(a), np.sin(a)])
        return np.add(self.centre, self.radius * u), u


def plan_scale(outline) -> float:
    """SPEC_outline 2, rule 5: the largest distance (the file's units) from the origin to the chain."""
    far = max(math.hypot(*seg[k]) for seg in outline for k in ("p0", "p1"))
    for pc in (PlanPiece.from_spec(seg, 1.0) for seg in outline if seg["type"] == "arc"):
        # an arc reaches past its ends where it crosses the ray from the origin through its centre
        towards = math.atan2(pc.centre[1], pc.centre[0])
        if math.hypot(*pc.centre) == 0.0 or (towards - pc.a0) % (2 * math.pi) <= pc.a1 - pc.a0:
            far = max(far, math.hypot(*pc.centre) + pc.radius)
    return far


def plan_pieces(outline) -> list[PlanPiece]:
    """The normalised pieces of a SPEC_outline plan, checked closed and smooth: a sharp corner
    (a joint where the normal jumps) raises NotImplementedError, since its rounded outer corner
    and sharp inner one are not built here."""
    pieces = [PlanPiece.from_spec(seg, plan_scale(outline)) for seg in outline]
    for j, (a, b) in enumerate(zip(pieces, pieces[1:] + pieces[:1])):
        if math.dist(a.p1, b.p0) > 1e-6:
            raise ValueError(f"plan segments {j} and {j + 1} do not meet (SPEC_outline 2, rule 1)")
        jump = (b.normal_angles()[0] - a.normal_angles()[1] + math.pi) % (2 * math.pi) - math.pi
        if abs(jump) > 1e-6:
            raise NotImplementedError(
                f"plan joint {j} -> {(j + 1) % len(pieces)} is a sharp corner ({math.degrees(jump):.3f} deg): "
                "the peer builds smooth outlines only (every joint tangent)")
    return pieces


def plan_layout(pieces, max_turn_deg: float, max_len: float,
                slack: float = SPLIT_SLACK) -> tuple[np.ndarray, np.ndarray]:
    """A ring's layout, the same at every height: points ``A (M, 2)`` of P and normals ``u``."""
    parts = [pc.layout(math.radians(max_turn_deg), max_len, slack) for pc in pieces]
    return np.concatenate([a for a, _ in parts]), np.concatenate([u for _, u in parts])


def profile_at(pieces, z) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A SPEC_outline profile's ``r`` (mm) and its unit normal ``(n_r, n_z)`` at heights ``z``
    (its own walls, no offset: SPEC_outline 3)."""
    idx, t = param_at_height(pieces, 0.0, z)
    r, nr, nz = np.empty(len(t)), np.empty(len(t)), np.empty(len(t))
    for k in np.unique(idx):
        sel = idx == k
        r[sel], _, nr[sel], nz[sel] = pieces[k].at(t[sel])
    return r, nr, nz


def _outline_normal_rz(h, core, rnd) -> tuple[np.ndarray, np.ndarray]:
    """Plan and height parts ``(a, b) (K, M)`` of the unit normal ``a u + b e_z`` at support
    values ``h (M,)`` and profile normals ``core = (n_r, n_z)``, ``rnd`` (each ``(K,)``).

    SPEC_outline 4: the normal is along ``(u, -(h k' + c'))``; with ``k' = -n_zk / n_rk`` and
    ``c' = -n_zc / n_rc`` multiplied through by ``n_rk n_rc`` it stays finite where a profile's
    tangent is horizontal (the rounded base edge at ``z = 0``). The offset ``c - w`` of the inner
    wall has the same slope, so the same normal."""
    (nrk, nzk), (nrc, nzc) = core, rnd
    a = np.broadcast_to((nrk * nrc)[:, None], (len(nrk), len(h)))
    b = h[None, :] * (nzk * nrc)[:, None] + (nzc * nrk)[:, None]
    norm = np.hypot(a, b)
    return a / norm, b / norm


def _refine_heights(z, normal_rz, max_turn: float, rounds: int = 40) -> np.ndarray:
    """Heights ``z`` with more between neighbours whose normals (``normal_rz(z) -> (a, b) (K,
    M)``) turn by more than ``max_turn`` (rad) at some plan point. Where the core narrows while
    the rounding grows (a shoulder into a round neck) ``h k' + c'`` passes 0 and the surface
    turns faster than either profile: each profile's own samples are not enough there."""
    for _ in range(rounds):
        a, b = normal_rz(z)
        turn = np.abs(np.arctan2(a[:-1] * b[1:] - b[:-1] * a[1:], a[:-1] * a[1:] + b[:-1] * b[1:])).max(axis=1)
        over = np.flatnonzero(turn > max_turn * (1 + 1e-9))
        if not len(over):
            return z
        extra = [z[i] + (z[i + 1] - z[i]) * np.arange(1, m) / m
                 for i, m in zip(over, np.ceil(turn[over] / max_turn).astype(int))]
        z = _merge_heights(np.concatenate([z, *extra]))
    raise ValueError(f"the profiles turn by more than {math.degrees(max_turn)} deg between heights "
                     f"{rounds} refinements on")


def outline_rings(b: dict, tess: dict, fill) -> tuple[Rings, Rings, float]:
    """The outer and inner walls of a SPEC_outline bottle with a smooth plan (:func:`plan_pieces`)
    as rings ``(outer, inner, z_top)``: each arc split every ``max_turn_deg`` at the same angles
    at every height; heights where either profile has a sample (SPEC 6's splitting of each) and
    more where the surface turns faster than both (:func:`_refine_heights`); the inner wall at
    the outer heights inside the cavity plus the inner base, the fill line and the mouth.

    The cavity must keep ``c - w > 0`` (rounded inner corners, SPEC_outline 5 with ``t > 0``);
    otherwise NotImplementedError."""
    xs, w, z_ib = b["cross_section"], float(b["wall_thickness"]), float(b["base_thickness"])
    pk, pc = pieces_of(xs["profile_core"]), pieces_of(xs["profile_round"])
    z_top = pk[-1].p1[1]
    pieces = plan_pieces(xs["outline"])
    k_max = max(max(p.p0[0], p.p1[0]) for p in pk)  # lines reach their widest at an end
    anchor, u = plan_layout(pieces, tess["max_turn_deg"], float(tess["max_seg_mm"]) / max(k_max, 1e-12),
                            tess.get("split_slack", SPLIT_SLACK))
    h = np.einsum("ij,ij->i", anchor, u)  # the support value of P along each normal

    def normal_rz(z):
        return _outline_normal_rz(h, profile_at(pk, z)[1:], profile_at(pc, z)[1:])

    z = _merge_heights(np.concatenate([wall_stations(p, tess)[1] for p in (pk, pc)]))
    z = _refine_heights(z, normal_rz, math.radians(tess["max_turn_deg"]))
    zi = _merge_heights(np.concatenate([z[(z > z_ib) & (z < z_top)],
                                        [c for c in (z_ib, fill, z_top) if c is not None]]))
    rot = math.radians(float(b.get("rotation_deg", 0.0)))
    rings = []
    for heights, wall in ((z, 0.0), (zi, w)):
        k, nrk, nzk = profile_at(pk, heights)
        c, nrc, nzc = profile_at(pc, heights)
        grow = c - wall
        if wall > 0.0 and grow.min() <= 0.0:
            raise NotImplementedError(
                f"the cavity's rounding c - w reaches {grow.min():.4g} mm at z = {heights[grow.argmin()]:.4g} mm: "
                "sharp inner corners are not built by the peer (SPEC_outline 5, t < 0)")
        xy = k[:, None, None] * anchor[None] + grow[:, None, None] * u[None]
        a, bz = _outline_normal_rz(h, (nrk, nzk), (nrc, nzc))
        n = np.concatenate([a[..., None] * u[None], bz[..., None]], axis=-1)
        rings.append(Rings(_turned(xy, rot), heights, np.concatenate([_turned(n[..., :2], rot), n[..., 2:]], -1)))
    return rings[0], rings[1], z_top


def _turned(xy, angle: float) -> np.ndarray:
    """Plan vectors ``(..., 2)`` turned by ``angle`` (rad) counter-clockwise (SPEC_outline 7)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.stack([c * xy[..., 0] - s * xy[..., 1], s * xy[..., 0] + c * xy[..., 1]], -1)


def bottle_rings(spec: dict) -> dict:
    """The rings of a SPEC bottle: ``{"outer", "inner": Rings}`` (the inner wall from the inner
    base to the mouth, with a ring at the fill line) and the heights ``z_ib``, ``fill``, ``z_top``."""
    b = spec["bottle"]
    tess = {**DEFAULT_TESSELLATION, **(spec.get("render") or {}).get("tessellation", {})}
    w, z_ib = float(b["wall_thickness"]), float(b["base_thickness"])
    fill = (spec.get("liquid") or {}).get("fill_height")
    kind = b["cross_section"]["kind"]
    if kind == "round":
        prof = pieces_of(b["profile"])
        z_top = prof[-1].p1[1]
        theta = round_layout(tess)
        r, z, nr, nz, _, _ = wall_stations(prof, tess)
        ri, zi = r - w * nr, z - w * nz
        cuts = [c for c in (z_ib, fill) if c is not None]
        keep = zi > z_ib + 1e-9
        if fill is not None:
            keep &= np.abs(zi - fill) > 1e-9
        rc, slope = radius_at(prof, w, np.array(cuts))
        norm = np.hypot(1.0, slope)
        ri, zi = np.concatenate([ri[keep], rc]), np.concatenate([zi[keep], cuts])
        nr_i, nz_i = np.concatenate([nr[keep], 1.0 / norm]), np.concatenate([nz[keep], -slope / norm])
        order = np.argsort(zi, kind="stable")
        outer = _revolved(r, z, nr, nz, theta)
        inner = _revolved(ri[order], zi[order], nr_i[order], nz_i[order], theta)
    elif kind == "rounded_square":
        xs = b["cross_section"]
        pu, pv = pieces_of(xs["profile_u"]), pieces_of(xs["profile_v"])
        z_top = pu[-1].p1[1]
        rot = float(b.get("rotation_deg", 0.0))
        z = _merge_heights(np.concatenate([wall_stations(pc, tess)[1] for pc in (pu, pv)]))
        outer = _square_rings(pu, pv, 0.0, z, tess, rot)
        zi = np.concatenate([st[1] - w * st[3] for st in (wall_stations(pc, tess) for pc in (pu, pv))])
        zi = _merge_heights(np.concatenate([zi[(zi > z_ib) & (zi < z_top)],
                                            [c for c in (z_ib, fill, z_top) if c is not None]]))
        inner = _square_rings(pu, pv, w, zi, tess, rot)
    elif kind == "outline":
        outer, inner, z_top = outline_rings(b, tess, fill)
    else:
        raise ValueError(f"cross-section kind {kind!r} is not in SPEC 4 nor SPEC_outline")
    if fill is not None and not z_ib < fill < z_top:
        raise ValueError(f"fill height {fill} mm is not between the inner base and the mouth")
    return {"outer": outer, "inner": inner, "z_ib": z_ib, "fill": fill, "z_top": z_top}


# ------------------------------------------------------------------------------ meshes
class MeshBuilder:
    """Vertices, exact unit normals (facing the way the faces do) and triangles of one
    interface. Rings are copied in, so rings shared by two meshes stay equal to the last bit,
    and a crease (base edge, rim, fill line) has a copy of its ring per side, with that side's
    normal."""

    def __init__(self):
        self.v, self.n, self.f, self.count = [], [], [], 0

    def add(self, pts, normals) -> np.ndarray:
        pts = np.asarray(pts, float).reshape(-1, 3)
        self.v.append(pts)
        self.n.append(np.broadcast_to(np.asarray(normals, float), pts.shape))
        self.count += len(pts)
        return np.arange(self.count - len(pts), self.count)

    def bands(self, rings: Rings, towards_axis: bool) -> None:
        """Triangles between consecutive rings (walked upwards): facing away from the axis, or
        towards it."""
        sign = -1.0 if towards_axis else 1.0
        idx = [self.add(rings.points(k), sign * rings.n[k]) for k in range(len(rings.z))]
        for a, b in zip(idx[:-1], idx[1:]):
            self.band(a, b, flip=towards_axis)

    def band(self, a, b, flip: bool) -> None:
        a1, b1 = np.roll(a, -1), np.roll(b, -1)
        tris = np.concatenate([np.stack([a, a1, b1], 1), np.stack([a, b1, b], 1)])
        self.f.append(tris[:, ::-1] if flip else tris)

    def disk(self, ring_pts, up: bool) -> None:
        """A fan from the axis to a ring (a flat base or free surface), facing up or down."""
        normal = [0.0, 0.0, 1.0 if up else -1.0]
        ring = self.add(ring_pts, normal)
        centre = self.add([[0.0, 0.0, float(ring_pts[0, 2])]], normal)[0]
        tris = np.stack([np.full(len(ring), centre), ring, np.roll(ring, -1)], 1)
        self.f.append(tris if up else tris[:, ::-1])

    def annulus_up(self, inner_pts, outer_pts) -> None:
        up = [0.0, 0.0, 1.0]
        self.band(self.add(inner_pts, up), self.add(outer_pts, up), flip=True)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(vertices, faces, normals)``, without the faces of zero area a round neck's sides of
        zero length leave (two corners at one position)."""
        v, n, f = np.concatenate(self.v), np.concatenate(self.n), np.concatenate(self.f).astype(np.int64)
        p = v[f]
        same = (np.all(p[:, 0] == p[:, 1], axis=1) | np.all(p[:, 1] == p[:, 2], axis=1)
                | np.all(p[:, 2] == p[:, 0], axis=1))
        return v, f[~same], n


def spec_meshes(spec: dict) -> dict:
    """``{interface: (vertices (N, 3), faces (M, 3), normals (N, 3))}`` of a SPEC bottle (see
    the module doc)."""
    rg = bottle_rings(spec)
    outer, inner, z_ib, fill, z_top = rg["outer"], rg["inner"], rg["z_ib"], rg["fill"], rg["z_top"]
    out = {}
    ga = MeshBuilder()
    ga.bands(outer, towards_axis=False)
    ga.disk(outer.points(0), up=False)
    dry = inner.between(fill if fill is not None else z_ib, z_top)
    ga.bands(dry, towards_axis=True)
    ga.annulus_up(dry.points(len(dry.z) - 1), outer.points(len(outer.z) - 1))
    if fill is None:
        ga.disk(inner.points(0), up=True)
    out["glass_air"] = ga.arrays()
    if fill is not None:
        gl = MeshBuilder()
        wet = inner.between(z_ib, fill)
        gl.bands(wet, towards_axis=True)
        gl.disk(wet.points(0), up=True)
        out["glass_liquid"] = gl.arrays()
        la = MeshBuilder()
        la.disk(wet.points(len(wet.z) - 1), up=True)
        out["liquid_air"] = la.arrays()
    return out


def facet_turn_deg(vertices, faces, crease_deg: float = 10.0) -> tuple[float, int]:
    """Largest angle (degrees) between the normals of two faces sharing an edge, creases (more
    than ``crease_deg``: base edge, rim, inner base) left out, and the number of crease edges.
    Degenerate faces (a side of zero length where a rounded square's neck is round) are skipped."""
    uniq, inv = np.unique(vertices, axis=0, return_inverse=True)
    f = inv.reshape(-1)[faces]
    v = uniq[f]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    area = np.linalg.norm(n, axis=1)
    ok = area > 1e-12 * max(1.0, float(area.max()))
    n = n / np.where(ok, area, 1.0)[:, None]
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    owner = np.tile(np.arange(len(f)), 3)
    key = np.sort(e, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key, owner = key[order], owner[order]
    pair = np.all(key[1:] == key[:-1], axis=1)
    fa, fb = owner[:-1][pair], owner[1:][pair]
    good = ok[fa] & ok[fb]
    ang = np.degrees(np.arccos(np.clip(np.sum(n[fa[good]] * n[fb[good]], axis=1), -1.0, 1.0)))
    smooth = ang <= crease_deg
    return float(ang[smooth].max(initial=0.0)), int((~smooth).sum())


# ------------------------------------------------------------------------------ Mitsuba
def write_ply(path, vertices, faces, normals=None) -> None:
    """Binary little-endian PLY of a mesh's vertices (and vertex normals) and faces (what
    Mitsuba loads fastest)."""
    v = vertices if normals is None else np.concatenate([vertices, normals], axis=1)
    v = np.ascontiguousarray(v, dtype="<f4")
    f = np.ascontiguousarray(faces, dtype="<i4")
    props = "xyz" if normals is None else ("x", "y", "z", "nx", "ny", "nz")
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\n"
              + "".join(f"property float {p}\n" for p in props)
              + f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    rows = np.empty(len(f), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rows["n"], rows["i"] = 3, f
    with open(path, "wb") as fh:
        fh.write(header)
        fh.write(v.tobytes())
        fh.write(rows.tobytes())


def _medium(sigma):
    return {"type": "homogeneous", "sigma_t": {"type": "rgb", "value": [float(s) for s in sigma]},
            "albedo": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}


def spec_conversion(spec_path, conversion=None) -> dict:
    """The conversion of a SPEC file's scene: :data:`CONVERSION`, then the spec's own
    ``render.tessellation.vertex_normals`` where it has one (the thick jar's reference carries
    exact vertex normals: :mod:`benchmarks.thick_jar`), then ``conversion``'s keys."""
    tess = (json.load(open(spec_path)).get("render") or {}).get("tessellation", {})
    own = {"vertex_normals": bool(tess["vertex_normals"])} if "vertex_normals" in tess else {}
    return {**CONVERSION, **own, **(conversion or {})}


def scene_dict(spec_path, folder, extra_shapes=None, conversion=None) -> tuple[dict, int]:
    """Mitsuba's scene dictionary of a SPEC file (meshes written into ``folder``) and its
    triangle count; ``extra_shapes`` (name: shape dict) are added as they are (labels).
    ``conversion`` (default :data:`CONVERSION`, with the spec's own ``render.tessellation.
    vertex_normals`` where it has one) is the facets' turning, whether they carry the exact
    vertex normals and, optionally, the split rule's ``split_slack`` (:data:`SPLIT_SLACK`)."""
    import mitsuba as mi

    conv = spec_conversion(spec_path, conversion)
    spec = json.load(open(spec_path))
    tess = (spec.get("render") or {}).get("tessellation", {})
    spec["render"] = {**(spec.get("render") or {}),
                      "tessellation": {**DEFAULT_TESSELLATION, **tess, "max_turn_deg": conv["max_turn_deg"],
                                       **{k: conv[k] for k in ("split_slack",) if k in conv}}}
    cam, b, liq = spec["camera"], spec["bottle"], spec.get("liquid")
    env_file = os.path.join(os.path.dirname(os.path.abspath(spec_path)), spec["environment"]["file"])
    d = {"type": "scene",
         "integrator": {"type": "volpathmis", "max_depth": MAX_DEPTH, "rr_depth": MAX_DEPTH},
         "sensor": {"type": "perspective", "fov_axis": "y", "fov": float(cam["fov_y_deg"]),
                    "to_world": mi.ScalarTransform4f().look_at(origin=cam["eye"], target=cam["look_at"], up=cam["up"]),
                    "film": {"type": "hdrfilm", "width": int(cam["width"]), "height": int(cam["height"]),
                             "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                    "sampler": {"type": "independent", "sample_count": 1}},
         "env": {"type": "envmap", "filename": env_file, "scale": float(spec["environment"].get("scale", 1.0)),
                 "to_world": mi.ScalarTransform4f(ENV_TO_WORLD)},
         "glass_medium": _medium(b["glass"]["sigma_a"])}
    n_glass, n_liq = float(b["glass"]["ior"]), float(liq["ior"]) if liq else 1.0
    if liq:
        d["liquid_medium"] = _medium(liq["sigma_a"])
    sides = {"glass_air": (n_glass, 1.0, "glass_medium", None),
             "glass_liquid": (n_glass, n_liq, "glass_medium", "liquid_medium"),
             "liquid_air": (n_liq, 1.0, "liquid_medium", None)}
    tris = 0
    for name, (v, f, n) in spec_meshes(spec).items():
        path = os.path.join(folder, f"{name}.ply")
        write_ply(path, v, f, n if conv["vertex_normals"] else None)
        tris += len(f)
        n_int, n_ext, m_int, m_ext = sides[name]
        shape = {"type": "ply", "filename": path, "face_normals": not conv["vertex_normals"],
                 "bsdf": {"type": "dielectric", "int_ior": n_int, "ext_ior": n_ext},
                 "interior": {"type": "ref", "id": m_int}}
        if m_ext is not None:
            shape["exterior"] = {"type": "ref", "id": m_ext}
        d[name] = shape
    if spec.get("ground"):
        d["ground"] = ground_shape(spec["ground"])
    d.update(extra_shapes or {})
    return d, tris


def ground_shape(ground: dict) -> dict:
    """SPEC_ground's ground: the square ``|x|, |y| <= half_size`` at ``z``, Lambertian on top;
    Mitsuba's ``diffuse`` is one-sided, so a ray from below ends there, black."""
    h, z = float(ground["half_size"]), float(ground["z"])
    if not z < 0.0:
        raise ValueError(f"SPEC_ground: the ground's z must be below the bottle (< 0), got {z}")
    import mitsuba as mi

    return {"type": "rectangle",
            "to_world": mi.ScalarTransform4f().translate([0.0, 0.0, z]).scale([h, h, 1.0]),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [float(a) for a in ground["albedo"]]}}}


def load_scene(spec_path, folder, extra_shapes=None, conversion=None):
    """A loaded Mitsuba scene of a SPEC file; returns ``(scene, seconds to build and load, triangles)``."""
    import mitsuba as mi

    t0 = time.perf_counter()
    d, tris = scene_dict(spec_path, folder, extra_shapes, conversion)
    return mi.load_dict(d), time.perf_counter() - t0, tris


def render_chunks(scene, chunks, seed0: int = 1):
    """Running means of renders of ``chunks`` samples per pixel each (seeds ``seed0``,
    ``seed0 + 1``, ...): after each chunk ``(total spp, image (H, W, 3), seconds of that chunk)``.
    Independent seeds make the running mean a render at the total sample count."""
    import mitsuba as mi

    total, acc = 0, None
    for k, spp in enumerate(chunks):
        t0 = time.perf_counter()
        img = np.array(mi.render(scene, spp=int(spp), seed=seed0 + k), dtype=np.float64)
        secs = time.perf_counter() - t0
        acc = img * spp if acc is None else acc + img * spp
        total += spp
        yield total, acc / total, secs
