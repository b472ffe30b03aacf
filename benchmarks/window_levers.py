"""The window's adaptive rounds: sample cap and Russian roulette, charted cost against honesty.

Usage::

    python -m benchmarks.window_levers [--samples knurled_jar,cut_decanter,jar,frosted_logo]
                                       [--threads 2]

The window's split policy (:mod:`engine.tracer.adaptive`) has two levers for the pixels that
need the most samples (relief, and thick glass seen through it): how far a pixel may be raised
(``SPLIT_FACTOR x spp``) and below which weight a sample's branches into glass play Russian
roulette (``SPLIT_ROULETTE``: cheaper samples, each noisier). Each setting renders each sample at
the honesty check's size (119 x 159, :mod:`benchmarks.window_converge`) and is compared, in
display levels RMS, with that benchmark's reference (the classic policy at half a display level
and 4 x the samples, which neither lever touches). Rays (intersection queries) are the cost: on
a shared machine they do not move between runs; seconds are printed beside them.

Writes ``benchmarks/out/window_levers.csv`` and ``window_levers.png`` (levels RMS against rays
per sample, the engine's setting ringed) and prints last
``window_levers_rms_max=X window_levers_rays_ratio=Y``: the largest RMS over the samples with the
engine's setting, and its rays over those of the setting before it (16, 0.05), summed over the
samples.
"""
from __future__ import annotations

import argparse
import csv
import os

import numpy as np

from benchmarks.window_converge import OUT, levels, reference, render, samples, window_sampling

#: (cap factor, roulette weight): the setting before stop 33 first.
SETTINGS = ((16, 0.05), (16, 0.2), (24, 0.2), (32, 0.05), (32, 0.2), (32, 0.3), (64, 0.05))
CHECK_SIZE = (119, 159)


def measure(design, assets, ref, factor, roulette, threads):
    """``(seconds, rays, levels RMS, p99)`` of the window's render of ``design`` at
    :data:`CHECK_SIZE` with the split policy's cap factor and roulette set to these."""
    from engine.tracer import adaptive

    keep = adaptive.SPLIT_FACTOR, adaptive.SPLIT_ROULETTE
    adaptive.SPLIT_FACTOR, adaptive.SPLIT_ROULETTE = factor, roulette
    try:
        job, seconds = render(design, assets, *CHECK_SIZE, threads, window_sampling(policy="split"))
    finally:
        adaptive.SPLIT_FACTOR, adaptive.SPLIT_ROULETTE = keep
    diff = np.abs(levels(job.image()) - levels(ref))
    return seconds, job.stats.rays_cast, float(np.sqrt(np.mean(diff ** 2))), float(np.percentile(diff, 99))


def chart(rows, chosen, path) -> None:
    """Levels RMS against rays per pixel, one panel per sample, the engine's setting ringed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(r["sample"] for r in rows))
    fig, axes = plt.subplots(1, len(names), figsize=(4 * len(names), 3.6), squeeze=False)
    px = CHECK_SIZE[0] * CHECK_SIZE[1]
    for ax, name in zip(axes[0], names):
        mine = [r for r in rows if r["sample"] == name]
        for rr in sorted({r["roulette"] for r in mine}):
            pts = sorted((r["rays"] / px, r["rms"]) for r in mine if r["roulette"] == rr)
            ax.plot(*zip(*pts), "o-", ms=4, label=f"roulette {rr:g}")
        for r in mine:
            ax.annotate(f"{r['factor']}x", (r["rays"] / px, r["rms"]), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
            if (r["factor"], r["roulette"]) == chosen:
                ax.plot(r["rays"] / px, r["rms"], "o", ms=12, mfc="none", mec="#b03030")
        ax.axhline(1.5, color="#b03030", ls="--", lw=1)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("rays per pixel")
    axes[0][0].set_ylabel("levels RMS from the reference")
    axes[0][0].legend(fontsize=7)
    fig.suptitle("The window's sample cap and roulette: cost against honesty (ringed: the engine's)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    from engine.files.project import load_project
    from engine.tracer import adaptive
    from engine.tracer.warmup import warm_up

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", default="knurled_jar,cut_decanter,jar,frosted_logo")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args(argv)
    warm_up()
    chosen = (adaptive.SPLIT_FACTOR, adaptive.SPLIT_ROULETTE)
    rows = []
    for path in samples([s for s in args.samples.split(",") if s]):
        name = os.path.basename(path)[:-len(".glassbench")]
        design, assets = load_project(path)
        ref = reference(design, assets, *CHECK_SIZE, args.threads)
        for factor, roulette in SETTINGS:
            seconds, rays, rms, p99 = measure(design, assets, ref, factor, roulette, args.threads)
            rows.append(dict(sample=name, factor=factor, roulette=roulette, seconds=round(seconds, 2),
                             rays=rays, rms=round(rms, 3), p99=round(p99, 2)))
            print(f"{name:16s} cap {factor:2d}x roulette {roulette:<4g} {seconds:6.2f} s "
                  f"{rays / 1e6:7.1f} M rays  {rms:5.2f} levels RMS  p99 {p99:5.1f}", flush=True)
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "window_levers.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    chart(rows, chosen, os.path.join(OUT, "window_levers.png"))
    mine = [r for r in rows if (r["factor"], r["roulette"]) == chosen]
    before = [r for r in rows if (r["factor"], r["roulette"]) == SETTINGS[0]]
    ratio = sum(r["rays"] for r in mine) / max(1, sum(r["rays"] for r in before))
    print(f"window_levers_rms_max={max(r['rms'] for r in mine):.2f} window_levers_rays_ratio={ratio:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
