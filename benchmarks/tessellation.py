"""Tessellation: triangles and time vs measured chordal error, against a uniform-step peer.

Usage::

    python -m benchmarks.tessellation [--tols 0.4,0.2,0.1,0.05,0.025]

For each oracle bottle (round, rounded square, ellipse foot), a rounded square whose inner corner
(0.3 mm) is a tenth of its outer one, and each tolerance, times
:func:`engine.geometry.tessellate.tessellate_body` (best of 3) and measures the largest distance of the
outer and inner walls' triangles (centroids and edge middles) from the exact surfaces. The peer
spends the same budget on the outer wall (same number of angles and rings) spread uniformly in
angle and height, as a fixed-step mesher would; a second peer splits arcs at a fixed turning step (as the
SPEC's reference mesher does) with lines in one piece, scaled to about the same ring count. The
ratio peer error / our error at (about) equal triangles is the figure of merit. Writes ``benchmarks/out/tessellation.csv`` and ``tessellation.png``.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import time

import numpy as np
from scipy.spatial import cKDTree

from engine.geometry.body import BottleBody
from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape
from engine.geometry.tessellate import tessellate_body
from benchmarks.oracle_spec import shape_from_spec
from benchmarks.paths import ORACLE_SPECS

OUT = os.path.join(os.path.dirname(__file__), "out")
SPECS = str(ORACLE_SPECS / "public_{}.json")


def spec_shape(n: int) -> BottleShape:
    """The bottle of oracle scene ``public_n``."""
    return shape_from_spec(json.load(open(SPECS.format(n)))["bottle"])


def sharp_inner_corner_shape() -> BottleShape:
    """A rounded square (u 18.7 mm, v 25.1 mm; 3.3 mm corners) with 3.06 mm walls: its inner
    corners are 0.28 mm, the case that once made the tessellator take gigabytes."""
    def stepped(r):
        pts = [(0.0, 0.0), (r, 0.0), (r, 90.0), (13.119, 120.0), (13.119, 150.0)]
        return Section(tuple(Line(a, b) for a, b in zip(pts, pts[1:])), (False,) * 3)
    return BottleShape("rounded_square", {"u": stepped(18.719), "v": stepped(18.719 * 1.3404)}, 3.056, 5.056)


def _probe_points(vertices, faces):
    v = vertices[faces]
    return np.concatenate([v.mean(axis=1), 0.5 * (v[:, 0] + v[:, 1]), 0.5 * (v[:, 1] + v[:, 2]),
                           0.5 * (v[:, 2] + v[:, 0])])


def wall_deviation(body: BottleBody, q, part: str = "outer") -> float:
    """Largest distance (mm) of points ``q`` from the exact ``outer`` or ``inner`` wall."""
    if body.xs.revolved:
        sp = body.profile.sections[0]
        chain = sp.outer_wall if part == "outer" else sp.inner_wall
        tree = cKDTree(np.concatenate([s.point(np.linspace(0, 1, 20001)) for s in chain]))
        return float(tree.query(np.stack([np.hypot(q[:, 0], q[:, 1]), q[:, 2]], 1))[0].max())
    rot = math.radians(body.shape.rotation_deg)
    x = math.cos(rot) * q[:, 0] + math.sin(rot) * q[:, 1]
    y = -math.sin(rot) * q[:, 0] + math.cos(rot) * q[:, 1]
    states = body.wall_radii(part, q[:, 2])
    sd, gx, gy, d = body.xs.signed_distance([s[0] for s in states], x, y)
    gz = sum(d[j] * states[j][1] / np.maximum(states[j][2], 1e-9) for j in range(len(states)))
    steep = np.min([s[2] for s in states], axis=0) > 0.2  # first-order distance is reliable there
    return float((np.abs(sd) / np.sqrt(gx ** 2 + gy ** 2 + gz ** 2))[steep].max())


def uniform_peer(body: BottleBody, n_theta: int, n_rings: int):
    """Outer wall on a uniform grid: ``n_theta`` angles by ``n_rings`` heights (vertices, faces)."""
    theta = np.linspace(0.0, 2 * math.pi, n_theta, endpoint=False)
    z = np.linspace(0.0, body.profile.z_top, n_rings)
    p, _ = body.wall("outer", theta[None, :], z[:, None])
    return _grid_faces(p)


def _turn(seg) -> float:
    """Tangent turning (rad) along a segment (monotone on wall segments)."""
    if seg.kind == "line":
        return 0.0
    a, b = seg.tangent(0.0), seg.tangent(1.0)
    return abs(math.atan2(a[0] * b[1] - a[1] * b[0], float(np.dot(a, b))))


def turn_peer(body: BottleBody, n_theta: int, n_rings: int):
    """Outer wall meshed like the SPEC's reference mesher: a fixed turning step per arc (scaled
    to about ``n_rings`` rings), lines in one piece, ``n_theta`` uniform angles."""
    chains = [sp.outer_wall for sp in body.profile.sections]
    total = sum(_turn(seg) for c in chains for seg in c)
    n_joints = sum(len(c) for c in chains) + 1
    step = max(total / max(n_rings - n_joints, 1), 1e-12)  # all lines: one piece each
    z = np.unique(np.concatenate([seg.point(np.linspace(0, 1, max(1, math.ceil(_turn(seg) / step)) + 1))[:, 1]
                                  for c in chains for seg in c]))
    theta = np.linspace(0.0, 2 * math.pi, n_theta, endpoint=False)
    p, _ = body.wall("outer", theta[None, :], z[:, None])
    return _grid_faces(p)


def _grid_faces(p):
    idx = np.arange(p.shape[0] * p.shape[1]).reshape(p.shape[:2])
    a0, b0 = idx[:-1], idx[1:]
    a1, b1 = np.roll(a0, -1, axis=1), np.roll(b0, -1, axis=1)
    faces = np.concatenate([np.stack([a0, a1, b1], -1).reshape(-1, 3), np.stack([a0, b1, b0], -1).reshape(-1, 3)])
    return p.reshape(-1, 3), faces


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tols", default="0.4,0.2,0.1,0.05,0.025")
    args = ap.parse_args(argv)
    tols = [float(t) for t in args.tols.split(",")]
    os.makedirs(OUT, exist_ok=True)
    rows = []
    bottles = (("round", spec_shape(1)), ("rounded square", spec_shape(3)), ("ellipse foot", spec_shape(4)),
               ("sharp inner", sharp_inner_corner_shape()))
    for label, shape in bottles:
        body = BottleBody(shape)
        for tol in tols:
            best = math.inf
            for _ in range(3):
                t0 = time.perf_counter()
                mesh = tessellate_body(shape, tol)
                best = min(best, time.perf_counter() - t0)
            outer = mesh.faces[mesh.part == 0]
            err = wall_deviation(body, _probe_points(mesh.vertices, outer))
            inner_err = wall_deviation(body, _probe_points(mesh.vertices, mesh.faces[mesh.part == 1]), "inner")
            n_theta = len(np.unique(np.round(np.arctan2(mesh.vertices[outer][..., 1],
                                                        mesh.vertices[outer][..., 0]), 9)))
            n_rings = len(outer) // (2 * n_theta) + 1
            pv, pf = uniform_peer(body, n_theta, n_rings)
            peer_err = wall_deviation(body, _probe_points(pv, pf))
            tv, tf = turn_peer(body, n_theta, n_rings)
            turn_err = wall_deviation(body, _probe_points(tv, tf))
            rows.append((label, tol, len(mesh.faces), len(outer), best * 1e3, err, peer_err,
                         len(tf), turn_err, inner_err))
    print(f"{'bottle':15s} {'tol mm':>7s} {'triangles':>9s} {'outer':>7s} {'time ms':>8s} "
          f"{'max err':>8s} {'uniform':>8s} {'ratio':>6s} {'turn tri':>8s} {'turn err':>8s} {'ratio':>6s} "
          f"{'inner err':>9s}")
    for r in rows:
        print(f"{r[0]:15s} {r[1]:7.3f} {r[2]:9d} {r[3]:7d} {r[4]:8.1f} {r[5]:8.4f} {r[6]:8.4f} "
              f"{r[6] / r[5]:6.1f} {r[7]:8d} {r[8]:8.4f} {r[8] / r[5]:6.1f} {r[9]:9.4f}")
    with open(os.path.join(OUT, "tessellation.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["bottle", "tol_mm", "triangles", "outer_triangles", "time_ms", "max_err_mm",
                    "uniform_peer_err_mm", "turn_peer_triangles", "turn_peer_err_mm", "inner_max_err_mm"])
        w.writerows(rows)
    _chart(rows)
    return 0


def _chart(rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label in dict.fromkeys(r[0] for r in rows):
        rr = [r for r in rows if r[0] == label]
        line, = ax.loglog([r[3] for r in rr], [r[5] for r in rr], "o-", label=f"{label}: chordal tolerance")
        ax.loglog([r[3] for r in rr], [r[6] for r in rr], "x--", color=line.get_color(),
                  label=f"{label}: uniform peer")
        ax.loglog([r[7] for r in rr], [r[8] for r in rr], "^:", color=line.get_color(),
                  label=f"{label}: fixed-turn peer")
    ax.set_xlabel("outer-wall triangles")
    ax.set_ylabel("max distance to exact surface (mm)")
    ax.set_title("Tessellation error vs triangles")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "tessellation.png"), dpi=120)


if __name__ == "__main__":
    raise SystemExit(main())
