"""Capacity quadrature vs a dense-sampling peer: time and relative error against closed forms.

Usage::

    python -m benchmarks.capacity [--repeat N]

Prints a table, writes ``benchmarks/out/capacity.csv`` and ``benchmarks/out/capacity.png``.
The engine's method (:mod:`engine.geometry.capacity`: Gauss-Legendre per piece between joints, cosine
substitution) is timed cold (a fresh shape: validation, offsetting and quadrature, what the GUI
pays on every edit) and warm (cached); the peer samples the cavity area at N uniform heights
and integrates with the trapezoid rule. Errors are relative to closed-form cavity volumes.
"""
from __future__ import annotations

import argparse
import csv
import math
import os
import time

import numpy as np

from engine.geometry import capacity
from engine.geometry.validate import body_profile
from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.shape import BottleShape
from benchmarks.paths import ORACLE_SPECS

OUT = os.path.join(os.path.dirname(__file__), "out")


def _round(segs, smooth, wall=3.0, base=6.0):
    return BottleShape("round", {"profile": Section(tuple(segs), tuple(smooth))}, wall, base)


def cases():
    """``(name, shape, exact cavity volume mm^3)`` with closed forms."""
    out = []
    shape = _round([Line((0, 0), (30, 0)), Line((30, 0), (30, 150))], [False])
    out.append(("cylinder", shape, math.pi * 27.0 ** 2 * 144.0))
    rb, c, h = 20.0, 30.0, 120.0
    big = math.hypot(rb, c)
    shape = _round([Line((0, 0), (rb, 0)), Arc((0, c), big, (rb, 0), (big, c), "ccw"),
                    Line((big, c), (big, h))], [False, True])
    rho = big - 3.0
    out.append(("sphere cap", shape, math.pi * (rho ** 2 * (c - 6.0) + (6.0 - c) ** 3 / 3.0)
                + math.pi * rho ** 2 * (h - c)))
    rb, a, h, w, bt = 20.0, 8.0, 100.0, 3.0, 4.0
    shape = _round([Line((0, 0), (rb, 0)), Arc((rb, a), a, (rb, 0), (rb + a, a), "ccw"),
                    Line((rb + a, a), (rb + a, h))], [False, True], w, bt)
    rho = a - w

    def prim(y):
        s = math.sqrt(max(rho * rho - y * y, 0.0))
        return math.pi * (rb * rb * y + rb * (y * s + rho * rho * math.asin(y / rho)) + rho * rho * y - y ** 3 / 3)

    out.append(("torus section", shape, prim(0.0) - prim(bt - a) + math.pi * (rb + rho) ** 2 * (h - a)))
    return out


def peer_volume(shape, n: int) -> float:
    """Dense-sampling peer: cavity area at ``n`` uniform heights, trapezoid rule (mm^3)."""
    prof = body_profile(shape)
    z = np.linspace(prof.z_ib, prof.z_top, n)
    return float(np.trapezoid(capacity._area_at(prof, z, "inner"), z))


def _best(fn, repeat):
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


_FRESH = [0]


def _fresh(shape):
    """A new shape (wall changed by a few 1e-10 mm), so that no cache can answer."""
    _FRESH[0] += 1
    return BottleShape(shape.cross_section, shape.sections, shape.wall_thickness + 1e-10 * _FRESH[0],
                       shape.base_thickness, shape.rotation_deg)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    os.makedirs(OUT, exist_ok=True)
    rows = []
    for name, shape, exact in cases():
        ours = capacity.brimful_ml(shape) * 1000
        cold = _best(lambda: capacity.brimful_ml(_fresh(shape)), args.repeat)  # new shape each call
        prof = body_profile(shape)  # the peer also starts from the built profile: compare like with like
        warm = _best(lambda: capacity._integrate(prof, "inner", prof.z_ib, prof.z_top)[1].sum(), args.repeat)
        rows.append((name, "quadrature (cold)", 0, cold * 1e3, abs(ours - exact) / exact))
        rows.append((name, "quadrature (profile built)", 0, warm * 1e3, abs(ours - exact) / exact))
        for n in (100, 1000, 10000, 100000):
            v = peer_volume(shape, n)
            t = _best(lambda: peer_volume(shape, n), max(1, args.repeat // 2))
            rows.append((name, "dense peer", n, t * 1e3, abs(v - exact) / exact))
    print(f"{'case':14s} {'method':26s} {'N':>7s} {'time ms':>9s} {'rel error':>10s}")
    for r in rows:
        print(f"{r[0]:14s} {r[1]:26s} {r[2]:7d} {r[3]:9.3f} {r[4]:10.2e}")
    for name, _, _ in cases():
        ours = [r for r in rows if r[0] == name and r[1] == "quadrature (cold)"][0]
        peer = [r for r in rows if r[0] == name and r[1] == "dense peer" and r[2] == 100000][0]
        built = [r for r in rows if r[0] == name and r[1] == "quadrature (profile built)"][0]
        print(f"{name}: time ratio peer(N=1e5) / quadrature: x{peer[3] / built[3]:.0f} (profile built), "
              f"x{peer[3] / ours[3]:.1f} (cold); error quadrature {ours[4]:.1e} vs peer {peer[4]:.1e}")
    typical = BottleShape("rounded_square", oracle_square_bottle().sections, 2.5, 5.5)

    def both():
        fresh = _fresh(typical)
        return capacity.brimful_ml(fresh), capacity.glass_mass_g(fresh)

    t_typ = _best(both, args.repeat)
    print(f"typical square bottle, cold brimful + mass: {t_typ * 1e3:.2f} ms")
    with open(os.path.join(OUT, "capacity.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "method", "n", "time_ms", "rel_error"])
        w.writerows(rows)
    _chart(rows)
    return 0


def oracle_square_bottle():
    """The rounded-square bottle of oracle scene public_3 (u and v sections)."""
    import json
    b = json.load(open(ORACLE_SPECS / "public_3.json"))["bottle"]["cross_section"]
    return BottleShape("rounded_square", {"u": Section.from_dicts(b["profile_u"]),
                                          "v": Section.from_dicts(b["profile_v"])}, 2.5, 5.5)


def _chart(rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, _, _ in cases():
        peer = [r for r in rows if r[0] == name and r[1] == "dense peer"]
        ax.loglog([r[3] for r in peer], [max(r[4], 1e-17) for r in peer], "o--", label=f"{name}: dense peer")
        ours = [r for r in rows if r[0] == name and r[1].startswith("quadrature (cold)")][0]
        ax.loglog([ours[3]], [max(ours[4], 1e-17)], "s", ms=9, label=f"{name}: quadrature (cold)")
    ax.set_xlabel("time per call (ms)")
    ax.set_ylabel("relative error vs closed form")
    ax.set_title("Brimful capacity: quadrature vs dense sampling")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "capacity.png"), dpi=120)


if __name__ == "__main__":
    raise SystemExit(main())
