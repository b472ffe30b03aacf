"""Ray/torus quartic solvers: time against accuracy on the shared hard cases, per category.

Methods (all float64, all vectorised over rays):

* ``ferrari``: textbook Ferrari on coefficients formed from the raw ray (absolute epsilons
  of 1e-9 as in the classic graphics-gems solvers);
* ``companion``: eigenvalues of the 4x4 companion matrices (what ``numpy.roots`` does),
  batched through ``numpy.linalg.eigvals``; a root is real when ``|imag| <= 1e-8 max(1, |re|)``;
* ``robust``: :func:`engine.intersect.ray_torus_hits` (bracketed roots of the geometric
  quartic in the unit-tube frame);
* ``tracer_kernel``: the tracer's own compiled solver (the same algorithm, one ray at a time,
  numba), the one every arc of a render goes through.

Accuracy uses the tolerant rule of ``/work/shared/quartic`` (README): error
``|t - t_accepted| / a`` in tube radii, misses, false hits. Throughput: each category's rays
are tiled to ``--rays`` rays and timed (best of 3). Writes ``benchmarks/out/quartic.csv`` and
``benchmarks/out/quartic.png`` (time per ray against largest error, log-log).

Run: ``.venv/bin/python benchmarks/quartic.py [--rays 20000]``
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from engine.intersect import ray_torus_hits  # noqa: E402
from benchmarks.paths import QUARTIC_CASES

CASES = QUARTIC_CASES
OUT = ROOT / "benchmarks" / "out"
EPS = 1e-9


def torus_coefficients(o, d, R, a, b):
    """Textbook quartic coefficients [c4..c0] (N, 5) straight from the raw ray (mm)."""
    k = (a / b) ** 2
    rho2 = [o[:, 0] ** 2 + o[:, 1] ** 2, 2 * (o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]),
            d[:, 0] ** 2 + d[:, 1] ** 2]
    z2 = [o[:, 2] ** 2, 2 * o[:, 2] * d[:, 2], d[:, 2] ** 2]
    s = [rho2[i] + k * z2[i] for i in range(3)]
    s[0] = s[0] + R * R - a * a
    c = [np.zeros_like(R) for _ in range(5)]  # ascending powers
    for i in range(3):
        for j in range(3):
            c[i + j] = c[i + j] + s[i] * s[j]
    for i in range(3):
        c[i] = c[i] - 4 * R * R * rho2[i]
    return np.stack(c[::-1], axis=1)


def _cubic_one_root(a2, a1, a0):
    """One real root of ``x^3 + a2 x^2 + a1 x + a0`` (Cardano, absolute epsilons)."""
    sub = a2 / 3.0
    p = a1 / 3.0 - sub * sub
    q = (2 * sub ** 3 - sub * a1 + a0) / 2.0  # x = y - sub: y^3 + 3p y + 2q = 0
    disc = q * q + p ** 3
    with np.errstate(invalid="ignore", divide="ignore"):
        sq = np.sqrt(np.maximum(disc, 0.0))
        one = np.cbrt(sq - q) - np.cbrt(sq + q)
        phi = np.arccos(np.clip(-q / np.sqrt(np.maximum(-p, 1e-300) ** 3), -1, 1)) / 3.0
        three = 2 * np.sqrt(np.maximum(-p, 0.0)) * np.cos(phi)
    y = np.where(np.abs(disc) < EPS, np.where(np.abs(q) < EPS, 0.0, 2 * np.cbrt(-q)),
                 np.where(disc > 0, one, three))
    return y - sub


def _quadratic(b, c):
    """Real roots of ``x^2 + b x + c`` (textbook formula), NaN where none."""
    disc = b * b / 4 - c
    with np.errstate(invalid="ignore"):
        sq = np.sqrt(np.where(disc > -EPS, np.maximum(disc, 0.0), np.nan))
    return -b / 2 - sq, -b / 2 + sq


def ferrari_textbook(coeffs):
    """All real roots (N, 4) of the quartics by textbook Ferrari (float64, absolute EPS)."""
    c4 = coeffs[:, 0]
    A, B, C, D = (coeffs[:, i] / c4 for i in range(1, 5))
    sq_a = A * A
    p = -3.0 / 8 * sq_a + B
    q = 1.0 / 8 * sq_a * A - 0.5 * A * B + C
    r = -3.0 / 256 * sq_a * sq_a + 1.0 / 16 * sq_a * B - 0.25 * A * C + D
    z = _cubic_one_root(-0.5 * p, -r, 0.5 * r * p - 0.125 * q * q)
    u = z * z - r
    v = 2 * z - p
    u = np.where(np.abs(u) < EPS, 0.0, u)
    v = np.where(np.abs(v) < EPS, 0.0, v)
    with np.errstate(invalid="ignore"):
        u, v = np.sqrt(np.where(u >= 0, u, np.nan)), np.sqrt(np.where(v >= 0, v, np.nan))
    sv = np.where(q < 0, -v, v)
    r1, r2 = _quadratic(sv, z - u)
    r3, r4 = _quadratic(-sv, z + u)
    # r = 0: y (y^3 + p y + q) = 0 is the textbook special case
    y0 = _cubic_one_root(np.zeros_like(p), p, q)
    small = np.abs(r) < EPS
    roots = np.where(small[:, None], np.column_stack([np.zeros_like(p), y0, np.full_like(p, np.nan),
                                                      np.full_like(p, np.nan)]),
                     np.column_stack([r1, r2, r3, r4]))
    return roots - A[:, None] / 4


def companion_roots(coeffs):
    """Real roots (N, 4) from eigenvalues of the companion matrices (numpy.roots, batched)."""
    monic = coeffs[:, 1:] / coeffs[:, :1]
    n = coeffs.shape[0]
    comp = np.zeros((n, 4, 4))
    comp[:, 0, :] = -monic
    comp[:, 1, 0] = comp[:, 2, 1] = comp[:, 3, 2] = 1.0
    ev = np.linalg.eigvals(comp)
    real = np.abs(ev.imag) <= 1e-8 * np.maximum(1.0, np.abs(ev.real))
    return np.where(real, ev.real, np.nan)


def first_hit(roots, tau):
    """Smallest root > tau per ray, NaN if none."""
    r = np.where(roots > tau[:, None], roots, np.nan)
    with np.errstate(invalid="ignore"):
        out = np.nanmin(np.where(np.isfinite(r), r, np.inf), axis=1)
    return np.where(np.isfinite(out), out, np.nan)




_BATCH = None


def torus_hits_kernel(o, d, R, a, b, tau):
    """Hits (N, 4) of the tracer's own compiled solver (:func:`engine.tracer.kernels.roots.
    torus_roots`, one ray at a time, the function the renderer calls for every arc)."""
    global _BATCH
    if _BATCH is None:
        import numba

        from engine.tracer.kernels.records import Ray
        from engine.tracer.kernels.roots import torus_roots

        @numba.njit(nogil=True)
        def batch(o, d, R, a, b, tau, out):
            buf, crit = np.zeros(4), np.zeros(5)
            for i in range(o.shape[0]):
                n = torus_roots(Ray(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2]), R[i], a[i], b[i],
                                False, tau[i], buf, crit)
                for j in range(n):
                    out[i, j] = buf[j]

        _BATCH = batch
    out = np.full((o.shape[0], 4), np.nan)
    _BATCH(np.ascontiguousarray(o), np.ascontiguousarray(d), np.ascontiguousarray(R), np.ascontiguousarray(a),
           np.ascontiguousarray(b), np.ascontiguousarray(tau), out)
    return out


def method_first_hits(name, o, d, R, a, b, tau):
    if name == "robust":
        return first_hit(ray_torus_hits(o, d, R, a, b, tmin=tau), tau)
    if name == "tracer_kernel":
        return first_hit(torus_hits_kernel(o, d, R, a, b, tau), tau)
    coeffs = torus_coefficients(o, d, R, a, b)
    roots = ferrari_textbook(coeffs) if name == "ferrari" else companion_roots(coeffs)
    return first_hit(roots, tau)


def score(cases, hits):
    """(max error, median error, misses, false hits) under the tolerant rule, tube radii."""
    errs, misses, false = [], 0, 0
    for c, t in zip(cases, hits):
        acc = c["ref_exact"]["accept"]
        accepted = [x for x in (acc["t_strict"], acc["t_next"]) if x is not None] + acc["graze"]
        if not np.isfinite(t):
            misses += acc["t_next"] is not None
        elif not accepted:
            false += 1
        else:
            errs.append(min(abs(t - x) for x in accepted) / c["a"])
    errs = np.array(errs) if errs else np.array([0.0])
    return float(errs.max()), float(np.median(errs)), misses, false


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=20000, help="rays per timed batch")
    ap.add_argument("--methods", default="ferrari,companion,robust,tracer_kernel")
    args = ap.parse_args(argv)
    if "tracer_kernel" in args.methods:  # compile outside the timings
        torus_hits_kernel(np.zeros((1, 3)), np.array([[0, 0, 1.0]]), np.ones(1), np.ones(1), np.ones(1), np.zeros(1))
    data = json.loads(CASES.read_text())
    methods = args.methods.split(",")
    rows = []
    by_cat = {cat: [c for c in data["cases"] if c["category"] == cat] for cat in data["meta"]["categories"]}
    by_cat["ALL"] = data["cases"]
    for cat, cases in by_cat.items():
        col = lambda key: np.array([c[key] for c in cases], dtype=float)  # noqa: E731
        o, d, R, a, b, tau = (col(k) for k in ("origin", "direction", "R", "a", "b", "tau"))
        reps = max(1, args.rays // len(cases))
        tiled = [np.tile(x, (reps, 1)) if x.ndim == 2 else np.tile(x, reps) for x in (o, d, R, a, b, tau)]
        for m in methods:
            hits = method_first_hits(m, o, d, R, a, b, tau)
            mx, med, miss, false = score(cases, hits)
            best = math.inf
            for _ in range(3):
                t0 = time.perf_counter()
                method_first_hits(m, *tiled)
                best = min(best, time.perf_counter() - t0)
            n = len(tiled[0])
            rows.append(dict(method=m, category=cat, rays=n, rays_per_s=n / best, ns_per_ray=1e9 * best / n,
                             max_err=mx, median_err=med, misses=miss, false_hits=false))
    OUT.mkdir(parents=True, exist_ok=True)
    with open(OUT / "quartic.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"{'category':12s} {'method':13s} {'Mrays/s':>8s} {'max err':>9s} {'med err':>9s} {'miss':>5s} {'false':>5s}")
    for r in rows:
        print(f"{r['category']:12s} {r['method']:13s} {r['rays_per_s'] / 1e6:8.3f} {r['max_err']:9.2e} "
              f"{r['median_err']:9.2e} {r['misses']:5d} {r['false_hits']:5d}")
    overall = {r["method"]: r for r in rows if r["category"] == "ALL"}
    if "robust" in overall:
        base = overall["robust"]["ns_per_ray"]
        print("time per ray relative to robust (numpy):",
              ", ".join(f"{m} {r['ns_per_ray'] / base:.2f}x" for m, r in overall.items()))
    _chart(overall)


def _chart(overall):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for m, r in overall.items():
        err = max(r["max_err"], 1e-17)
        ax.loglog(r["ns_per_ray"], err, "o", ms=8)
        ax.annotate(f"{m}\nmiss {r['misses']}, false {r['false_hits']}", (r["ns_per_ray"], err),
                    textcoords="offset points", xytext=(6, 4), fontsize=8)
    ax.axhline(1e-6, ls="--", c="grey", lw=0.8, label="acceptance bar (1e-6 tube radii)")
    ax.margins(x=0.3, y=0.3)
    ax.legend(loc="center right", fontsize=8)
    ax.set_xlabel("time per ray (ns), all 600 public cases tiled")
    ax.set_ylabel("largest error of reported hits (tube radii)")
    ax.set_title("ray/torus quartic solvers: time vs accuracy")
    fig.tight_layout()
    fig.savefig(OUT / "quartic.png", dpi=120)


if __name__ == "__main__":
    main()
