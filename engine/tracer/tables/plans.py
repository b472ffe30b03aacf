"""The table of a free plan outline's pieces, as :mod:`engine.tracer.kernels.plans` reads it.

Design rule: the outline arrives normalised (its farthest point at distance 1 from the axis),
as SPEC_outline's segment dicts (``line``: ``p0``, ``p1``; ``arc``: ``center``, ``radius``,
``p0``, ``p1``, counter-clockwise), closed, convex and counter-clockwise (checked where the
outline is read: :mod:`engine.geometry.plan`). Each line gives one ``FLAT`` row; each arc and
each sharp corner (a joint where the direction turns) give ``ROUND`` rows, their wedge of
normals cut into pieces of at most :data:`MAX_WEDGE` so that every wedge's cone is convex.
The rows follow the outline counter-clockwise, so the girth terms (:func:`_girth_columns`) are
running sums along them.
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.plans import (FLAT, PL_COLS, PL_CX, PL_CY, PL_ENDS, PL_GK, PL_GR, PL_H, PL_HLOW, PL_KIND, PL_NX,
                             PL_NY, PL_PERIM, PL_RHO, PL_U0X, PL_U0Y, PL_U1X, PL_U1Y, ROUND, plan_support_low)

#: The widest wedge of normals (rad) one ``ROUND`` row holds.
MAX_WEDGE = 0.5 * math.pi
#: A joint whose direction turns by less than this (rad) is smooth: no corner row.
SMOOTH_TURN = 1e-9


def _angle(v) -> float:
    return math.atan2(v[1], v[0])


def _ends(seg) -> tuple:
    """``(start normal angle, end normal angle)`` (rad) of a segment's outward normals."""
    p0, p1 = np.asarray(seg["p0"], float), np.asarray(seg["p1"], float)
    if seg["type"] == "line":
        e = p1 - p0
        a = _angle((e[1], -e[0]))
        return a, a
    c = np.asarray(seg["center"], float)
    a0, a1 = _angle(p0 - c), _angle(p1 - c)
    if a1 <= a0:
        a1 += 2.0 * math.pi
    return a0, a1


def _round_rows(cx, cy, rho, a0, a1) -> list:
    """``ROUND`` rows for centre ``(cx, cy)``, radius ``rho`` over normal angles ``a0 -> a1``."""
    n = max(1, math.ceil((a1 - a0) / MAX_WEDGE - 1e-12))
    rows = []
    for j in range(n):
        b0, b1 = a0 + (a1 - a0) * j / n, a0 + (a1 - a0) * (j + 1) / n
        row = np.zeros(PL_COLS)
        row[PL_KIND] = ROUND
        row[PL_CX], row[PL_CY], row[PL_RHO] = cx, cy, rho
        row[PL_U0X], row[PL_U0Y] = math.cos(b0), math.sin(b0)
        row[PL_U1X], row[PL_U1Y] = math.cos(b1), math.sin(b1)
        rows.append(row)
    return rows


def plan_table(segments) -> np.ndarray:
    """The ``(m, PL_COLS)`` float64 table of the normalised outline ``segments`` (module doc)."""
    rows, lines = [], []
    n = len(segments)
    for i, seg in enumerate(segments):
        if seg["type"] == "line":
            p0, p1 = np.asarray(seg["p0"], float), np.asarray(seg["p1"], float)
            lines.append((p0, float(np.linalg.norm(p1 - p0))))
            e = (p1 - p0) / lines[-1][1]
            row = np.zeros(PL_COLS)
            row[PL_KIND] = FLAT
            row[PL_NX], row[PL_NY] = e[1], -e[0]
            row[PL_H] = row[PL_NX] * p0[0] + row[PL_NY] * p0[1]
            rows.append(row)
        else:
            c = seg["center"]
            a0, a1 = _ends(seg)
            rows += _round_rows(float(c[0]), float(c[1]), float(seg["radius"]), a0, a1)
        # the joint with the next segment: a sharp corner if the normal turns there
        out_end = _ends(seg)[1]
        in_next = _ends(segments[(i + 1) % n])[0]
        turn = (in_next - out_end) % (2.0 * math.pi)
        if SMOOTH_TURN < turn < 2.0 * math.pi - SMOOTH_TURN:
            v = seg["p1"]
            rows += _round_rows(float(v[0]), float(v[1]), 0.0, out_end, out_end + turn)
    table = np.array(rows, float).reshape(-1, PL_COLS)
    _girth_columns(table, lines)
    _end_flags(table)
    table = np.ascontiguousarray(table)
    table[:, PL_HLOW] = plan_support_low(table)
    return table


def _end_flags(table) -> None:
    """``PL_ENDS`` of each ``ROUND`` row, in place: 0 where the rows before and after it (the
    chain is closed) are ``FLAT``, whose normals are then its end normals (the chain's normals
    turn continuously), else 1."""
    kinds = table[:, PL_KIND]
    flat_before = np.roll(kinds, 1) == FLAT
    flat_after = np.roll(kinds, -1) == FLAT
    table[:, PL_ENDS] = np.where((kinds == ROUND) & ~(flat_before & flat_after), 1.0, 0.0)


def _girth_columns(table, lines) -> None:
    """Fill the girth terms of :func:`engine.tracer.kernels.plans.plan_girth` in place.

    Steiner, piece by piece: along the boundary of ``k P (+) disc(r)`` a line of ``P`` keeps
    ``k`` times its length and a wedge of normals of angle ``a`` (an arc of radius ``rho``, or
    a corner with ``rho = 0``) becomes an arc of length ``(k rho + r) a``; so the arc length
    at a row's start is ``k A + r B``, ``A`` the length of ``P`` and ``B`` the normals' turn
    before the row. The origin is moved to the boundary point whose normal points along +x
    (on a line facing +x, the foot of the perpendicular from the axis), the same point of
    the outline at every height; a ``FLAT`` row's ``A`` is stored less its start's coordinate
    along the line, so the kernel adds the point's own. ``lines``: each ``FLAT`` row's line as
    ``(start point, length)``, in row order."""
    a_len = b_turn = 0.0
    starts = []          # (unwrapped start normal angle, wedge angle) per row
    prev = None
    line_iter = iter(lines)
    for row in table:
        if row[PL_KIND] == FLAT:
            raw, wedge = math.atan2(row[PL_NY], row[PL_NX]), 0.0
        else:
            raw = math.atan2(row[PL_U0Y], row[PL_U0X])
            wedge = math.atan2(row[PL_U0X] * row[PL_U1Y] - row[PL_U0Y] * row[PL_U1X],
                               row[PL_U0X] * row[PL_U1X] + row[PL_U0Y] * row[PL_U1Y])
        start = raw if prev is None else prev + math.remainder(raw - prev, 2.0 * math.pi)
        prev = start + wedge
        starts.append((start, wedge))
        row[PL_GR] = b_turn
        if row[PL_KIND] == FLAT:
            p0, length = next(line_iter)
            row[PL_GK] = a_len - (-row[PL_NY] * p0[0] + row[PL_NX] * p0[1])
            a_len += length
        else:
            row[PL_GK] = a_len
            a_len += row[PL_RHO] * wedge
            b_turn += wedge
    table[:, PL_PERIM] = a_len
    # the origin: the normal angle 0 (mod 2 pi) first met along the chain, a flat facing it first
    first = starts[0][0]
    psi0 = first + (-first) % (2.0 * math.pi)
    origin = None
    for row, (start, _) in zip(table, starts):
        if row[PL_KIND] == FLAT and abs(math.remainder(start, 2.0 * math.pi)) < 1e-12:
            origin = (row[PL_GK], row[PL_GR])
            break
    if origin is None:
        for row, (start, wedge) in zip(table, starts):
            if row[PL_KIND] == ROUND and start - 1e-12 <= psi0 <= start + wedge + 1e-12:
                origin = (row[PL_GK] + row[PL_RHO] * (psi0 - start), row[PL_GR] + (psi0 - start))
                break
    table[:, PL_GK] -= origin[0]
    table[:, PL_GR] -= origin[1]

