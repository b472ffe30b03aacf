"""Arc length around an outline bottle's section: the girth a label's width is measured along.

Design rule: the boundary of the section ``S = {q : sd(q, k P) <= r}`` (mm) is the chain of
exact pieces :meth:`engine.geometry.plan.PlanOutline._section_pieces` gives (lines and arcs, in
counter-clockwise order), so the arc length from the chain's start to a boundary point is the
lengths of the pieces before it plus the length along its own piece. For ``r >= 0`` that is
Steiner's closed form read piece by piece: the boundary of ``k P (+) disc(r)`` has the length
element ``k ds_P + r dpsi`` (``psi`` the outward normal's angle), so a line of ``P`` keeps its
length ``k len``, an arc of radius ``rho`` becomes one of ``k rho + r`` and a sharp corner of
``P`` (exterior angle ``alpha``) an arc of length ``r alpha`` (none at ``r = 0``: a crease).

The *girth length* ``l(theta)`` is that arc length from polar angle 0 to ``theta`` (rad, any
real, the bottle's own frame), continuous and increasing, ``l(theta + 2 pi) = l(theta) + L``
(``L`` the perimeter). Whole turns are counted with the outward normal: ``S`` is convex and holds
the origin, so the normal's angle stays within ``pi / 2`` of the polar angle, and each piece's
normals lie in its own range of the chain's one turn (``[psi_0, psi_0 + 2 pi]``), which tells
how many times a point has passed the chain's start. :func:`theta_at_length` is the exact
inverse (the piece at a length, the point on it, its polar angle). Radii ``k >= 0`` and ``r``
(either sign: ``r < 0`` is the cavity's inner parallel set, its sharp corners joints of the chain)
broadcast against ``theta``. No Qt, no numba; float64.
"""
from __future__ import annotations

import math

import numpy as np

from .plan import TWO_PI, _ray_exit


def _wrapped(angle):
    """``angle`` (rad) turned by whole turns into ``[-pi, pi)``."""
    return np.remainder(np.asarray(angle) + math.pi, TWO_PI) - math.pi


def _chain(plan, k, r):
    """The section's pieces for 1-d ``k, r`` of one sign, with ``(lengths, starts, lo, hi)``:
    ``(m, n)`` arrays of each piece's length (mm), the chain length at its start, and its outward
    normals' angle range unwrapped along the chain from the first piece's start (rad)."""
    pieces = plan._section_pieces(k, r)
    lengths, lo, hi, prev = [], [], [], None
    for p in pieces:
        if p[0] == "line":
            _, ax, ay, bx, by, nx, ny = p
            length, a0 = np.hypot(bx - ax, by - ay), math.atan2(ny, nx)
            sweep = 0.0
        else:
            _, _, _, rho, a0, a1 = p
            length, sweep = rho * (a1 - a0), a1 - a0
        start = a0 if prev is None else prev + _wrapped(a0 - prev)  # why: joints turn < pi
        prev = start + sweep
        for out, v in ((lengths, length), (lo, start), (hi, prev)):
            out.append(np.broadcast_to(v, k.shape))
    lengths = np.array(lengths)
    starts = np.concatenate([np.zeros((1,) + k.shape), np.cumsum(lengths, axis=0)[:-1]])
    return pieces, lengths, starts, np.array(lo), np.array(hi)


def _per_sign(plan, k, r, shape, each):
    """``each(mask, pieces, lengths, starts, lo, hi)`` over the heights of each sign of ``r``
    (flat 1-d ``k, r``); returns the filled float array of ``shape``."""
    out = np.empty(k.size)

    def part(mask):
        out[mask] = each(mask, *_chain(plan, k[mask], r[mask]))

    plan._by_sign(r, part)
    return out.reshape(shape)


def _pick(table, idx):
    """``table[idx[j], j]`` for an ``(m, n)`` table and ``n`` piece indices."""
    return np.take_along_axis(table, idx[None, :], axis=0)[0]


def _chain_length(plan, theta, k, r):
    """Arc length (mm) from the chain's start to the boundary point at polar angle ``theta``,
    counting whole turns (``+ L`` per turn), for flat arrays of one size."""
    def each(mask, pieces, lengths, starts, lo, hi):
        th = theta[mask]
        _, _, nx, ny, piece, along = _ray_exit(pieces, np.cos(th), np.sin(th))
        psi = th + _wrapped(np.arctan2(ny, nx) - th)   # the normal's angle near theta
        idx = piece.astype(np.int64)
        # why round: a piece's normals span less than a turn about their middle, so the whole
        # turns between psi and that middle are the times the chain's start has been passed
        turns = np.round((psi - 0.5 * (_pick(lo, idx) + _pick(hi, idx))) / TWO_PI)
        return turns * lengths.sum(axis=0) + _pick(starts, idx) + along

    return _per_sign(plan, k, r, k.shape, each)


def _point_at(piece, along, length):
    """``(x, y, bend)``: the point ``along`` mm from the start of ``piece`` (of ``length`` mm)
    and how far (rad) the outward normal has turned there from the piece's start."""
    if piece[0] == "line":
        _, ax, ay, bx, by, _, _ = piece
        f = np.divide(along, length, out=np.zeros(along.shape), where=length > 0)
        return ax + f * (bx - ax), ay + f * (by - ay), np.zeros(along.shape)
    _, cx, cy, rho, a0, _ = piece
    bend = np.divide(along, rho, out=np.zeros(along.shape), where=rho > 0)
    return cx + rho * np.cos(a0 + bend), cy + rho * np.sin(a0 + bend), bend


def _flat(*arrays):
    """The arguments broadcast and flattened (float64), and their common shape."""
    b = np.broadcast_arrays(*(np.asarray(a, float) for a in arrays))
    return [a.ravel() for a in b], b[0].shape


def perimeter(plan, k, r) -> np.ndarray:
    """Perimeter (mm) of the section: the sum of its pieces (``k L + 2 pi r`` for ``r >= 0``)."""
    (kf, rf), shape = _flat(k, r)
    return _per_sign(plan, kf, rf, shape, lambda mask, pieces, lengths, *_: lengths.sum(axis=0))


def girth_length(plan, k, r, theta) -> np.ndarray:
    """Arc length (mm) of the section's boundary from polar angle 0 to ``theta`` (rad, any real),
    counter-clockwise (module rule); ``k``, ``r`` (mm) and ``theta`` broadcast."""
    (th, kf, rf), shape = _flat(theta, k, r)
    return (_chain_length(plan, th, kf, rf) - _chain_length(plan, np.zeros_like(th), kf, rf)).reshape(shape)


def theta_at_length(plan, k, r, length) -> np.ndarray:
    """The polar angle (rad) whose :func:`girth_length` is ``length`` (mm, any real): exact, from
    the piece at that length along the chain."""
    (ln, kf, rf), shape = _flat(length, k, r)
    target = ln + _chain_length(plan, np.zeros_like(ln), kf, rf)

    def each(mask, pieces, lengths, starts, lo, hi):
        total = lengths.sum(axis=0)
        turns = np.floor(target[mask] / total)
        rest = target[mask] - turns * total
        idx = np.clip(np.sum(starts <= rest[None, :], axis=0) - 1, 0, len(pieces) - 1)
        along = np.clip(rest - _pick(starts, idx), 0.0, _pick(lengths, idx))
        x, y, bend = np.empty(rest.shape), np.empty(rest.shape), np.empty(rest.shape)
        for i, p in enumerate(pieces):
            on = idx == i
            if on.any():
                part = (p[0], *(np.broadcast_to(v, rest.shape)[on] for v in p[1:]))
                x[on], y[on], bend[on] = _point_at(part, along[on], lengths[i][on])
        psi = _pick(lo, idx) + bend + TWO_PI * turns  # the normal's angle there, on its turn
        return psi + _wrapped(np.arctan2(y, x) - psi)   # the polar angle near it

    return _per_sign(plan, kf, rf, shape, each)
