"""Least-distortion flattening of a patch of surface: as-rigid-as-possible, with its strain.

Design rule: a label that cannot be unrolled (a doubly curved band: a shoulder, a heel, a
swelling body) is flattened the way a sheet of paper would settle on it: the flat shape that
minimises the elastic energy of the map, the sum over triangles of ``area * ||J - R||^2`` with
``J`` the triangle's Jacobian and ``R`` the nearest rotation (as-rigid-as-possible, the
local/global iteration of Liu et al. 2008 with cotangent weights). It is exact (zero strain)
for every developable patch, so it agrees with rolling on a cylinder and unrolling on a cone,
and elsewhere it spreads the unavoidable stretch the way an elastic sheet does, instead of
piling it on the edges as a single tangent cone would. A conformal map in ``(theta, h)``
was rejected: it keeps angles but lets lengths grow without bound along the band and is not
exact on cones in length. The input is a grid of exact surface points (rows = artwork ``t``,
columns = ``s``); the output the flat point of each node (mm, x right, y up, the centre at
the origin, the centre column vertical) and the strain at each node: the largest
``|surface length / flat length - 1|`` over the triangles around it.
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.linalg import splu

#: Iterations at most, and the change (fraction of the patch's size) that ends them sooner.
MAX_ITERATIONS = 300
TOLERANCE = 1e-8


def _triangles(nt: int, ns: int) -> np.ndarray:
    """``(T, 3)`` node indices, two per grid cell, the diagonal alternating (no bias)."""
    idx = np.arange(nt * ns).reshape(nt, ns)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    even = (np.add.outer(np.arange(nt - 1), np.arange(ns - 1)) % 2 == 0)
    first = np.where(even[..., None], np.stack([a, b, d], -1), np.stack([a, b, c], -1))
    second = np.where(even[..., None], np.stack([a, d, c], -1), np.stack([b, d, c], -1))
    return np.concatenate([first.reshape(-1, 3), second.reshape(-1, 3)])


def _rest(points: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Each triangle laid flat in its own plane: ``(T, 3, 2)``, vertex 0 at the origin."""
    e1 = points[tri[:, 1]] - points[tri[:, 0]]
    e2 = points[tri[:, 2]] - points[tri[:, 0]]
    l1 = np.linalg.norm(e1, axis=1)
    u = e1 / l1[:, None]
    along = np.sum(e2 * u, axis=1)
    across = np.linalg.norm(e2 - along[:, None] * u, axis=1)
    x = np.zeros((len(tri), 3, 2))
    x[:, 1, 0] = l1
    # Grid triangles run clockwise in the flat frame (x with s, y against t): so do these, or
    # the nearest rotations would mirror the shape.
    x[:, 2, 0], x[:, 2, 1] = along, -across
    return x


def _cotangents(x: np.ndarray) -> np.ndarray:
    """``(T, 3)``: cotangent of the angle at vertex k, the weight of the edge opposite it."""
    out = np.empty(x.shape[:2])
    for k in range(3):
        a = x[:, (k + 1) % 3] - x[:, k]
        b = x[:, (k + 2) % 3] - x[:, k]
        out[:, k] = np.sum(a * b, axis=1) / np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    return np.maximum(out, 1e-6)  # near-right grid triangles: never a negative weight


#: Edges of a triangle as (i, j, k): from vertex i to j, opposite vertex k.
_EDGES = ((0, 1, 2), (1, 2, 0), (2, 0, 1))


def flatten(points, init) -> tuple[np.ndarray, np.ndarray]:
    """As-rigid-as-possible flattening of a grid of surface points (module rule).

    Parameters
    ----------
    points : ndarray, shape (nt, ns, 3)
        Exact surface points (mm), ``nt, ns >= 3`` and odd (so the centre is a node); row 0 is
        the artwork's top edge, column 0 its left edge.
    init : ndarray, shape (nt, ns, 2)
        A starting flat shape with the same orientation (x with the columns, y against the
        rows), e.g. the unrolled tangent cone.

    Returns
    -------
    flat : ndarray, shape (nt, ns, 2)
        Flat points (mm).
    strain : ndarray, shape (nt, ns)
        Paper strain at each node (fraction).
    """
    points = np.asarray(points, float)
    nt, ns, _ = points.shape
    tri = _triangles(nt, ns)
    x = _rest(points.reshape(-1, 3), tri)
    w = _cotangents(x)
    n = nt * ns
    rows, cols, vals = [], [], []
    for i, j, k in _EDGES:
        a, b, wk = tri[:, i], tri[:, j], w[:, k]
        rows += [a, b, a, b]
        cols += [a, b, b, a]
        vals += [wk, wk, -wk, -wk]
    centre = (nt // 2) * ns + ns // 2
    pin = 1e3 * float(np.mean(w))
    lap = coo_matrix((np.concatenate(vals + [[pin]]), (np.concatenate(rows + [[centre]]),
                      np.concatenate(cols + [[centre]]))), shape=(n, n)).tocsc()
    solve = splu(lap).solve
    # rhs = scatter of the weighted rotated rest edges: +e at an edge's start, -e at its end.
    t_idx = np.arange(len(tri))
    scatter = coo_matrix((np.concatenate([np.ones(3 * len(tri)), -np.ones(3 * len(tri))]),
                          (np.concatenate([tri[:, i] for i, _, _ in _EDGES] + [tri[:, j] for _, j, _ in _EDGES]),
                           np.tile(np.concatenate([t_idx + m * len(tri) for m in range(3)]), 2))),
                         shape=(n, 3 * len(tri))).tocsr()
    u = np.asarray(init, float).reshape(-1, 2).copy()
    anchor = u[centre].copy()
    size = float(np.ptp(u, axis=0).max()) or 1.0
    for _ in range(MAX_ITERATIONS):
        s = np.zeros((len(tri), 2, 2))
        for i, j, k in _EDGES:
            du = u[tri[:, i]] - u[tri[:, j]]
            dx = x[:, i] - x[:, j]
            s += w[:, k, None, None] * du[:, :, None] * dx[:, None, :]
        # The rotation nearest a 2 x 2 matrix (maximising trace(R^T S)) in closed form.
        angle = np.arctan2(s[:, 1, 0] - s[:, 0, 1], s[:, 0, 0] + s[:, 1, 1])
        c, sn = np.cos(angle), np.sin(angle)
        rot = np.stack([np.stack([c, -sn], -1), np.stack([sn, c], -1)], -2)
        edges = np.concatenate([w[:, k, None] * np.einsum("tab,tb->ta", rot, x[:, i] - x[:, j])
                                for i, j, k in _EDGES])
        rhs = scatter @ edges
        rhs[centre] += pin * anchor
        new = np.column_stack([solve(rhs[:, 0]), solve(rhs[:, 1])])
        change = float(np.abs(new - u).max())
        u = new
        if change < TOLERANCE * size:
            break
    flat = _aligned(u.reshape(nt, ns, 2))
    return flat, _strain(flat.reshape(-1, 2), x, tri, n).reshape(nt, ns)


def _aligned(flat: np.ndarray) -> np.ndarray:
    """``flat`` moved so the centre node is the origin and the centre column points up."""
    nt, ns, _ = flat.shape
    flat = flat - flat[nt // 2, ns // 2]
    up = flat[0, ns // 2] - flat[-1, ns // 2]
    angle = np.arctan2(up[0], up[1])  # turn by +angle brings `up` onto +y
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * flat[..., 0] - s * flat[..., 1], s * flat[..., 0] + c * flat[..., 1]], -1)


def _strain(u: np.ndarray, x: np.ndarray, tri: np.ndarray, n: int) -> np.ndarray:
    flat_edges = np.stack([u[tri[:, 1]] - u[tri[:, 0]], u[tri[:, 2]] - u[tri[:, 0]]], axis=2)
    rest_edges = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]], axis=2)
    jac = flat_edges @ np.linalg.inv(rest_edges)  # surface -> flat
    sv = np.linalg.svd(jac, compute_uv=False)
    per_tri = np.max(np.abs(1.0 / sv - 1.0), axis=1)
    out = np.zeros(n)
    for k in range(3):
        np.maximum.at(out, tri[:, k], per_tri)
    return out
