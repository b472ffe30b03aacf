"""The table of a free plan outline's pieces, as :mod:`engine.tracer.kernels.plans` reads it.

Design rule: the outline arrives normalised (its farthest point at distance 1 from the axis),
as SPEC_outline's segment dicts (``line``: ``p0``, ``p1``; ``arc``: ``center``, ``radius``,
``p0``, ``p1``, counter-clockwise), closed, convex and counter-clockwise (checked where the
outline is read: :mod:`engine.geometry.plan`). Each line gives one ``FLAT`` row; each arc and
each sharp corner (a joint where the direction turns) give ``ROUND`` rows, their wedge of
normals cut into pieces of at most :data:`MAX_WEDGE` so that every wedge's cone is convex.
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.plans import (FLAT, PL_COLS, PL_CX, PL_CY, PL_H, PL_KIND, PL_NX, PL_NY, PL_RHO, PL_U0X, PL_U0Y,
                             PL_U1X, PL_U1Y, ROUND)

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
    rows = []
    n = len(segments)
    for i, seg in enumerate(segments):
        if seg["type"] == "line":
            p0, p1 = np.asarray(seg["p0"], float), np.asarray(seg["p1"], float)
            e = (p1 - p0) / np.linalg.norm(p1 - p0)
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
    return np.ascontiguousarray(np.array(rows, float).reshape(-1, PL_COLS))
