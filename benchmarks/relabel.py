"""Relabel benchmark: swap a label's artwork and re-render only what the label touched.

Usage::

    python -m benchmarks.relabel [--width 240] [--height 320] [--spp 4] [--repeats 3]

The Bordeaux sample with the sample label (:mod:`engine.appearance.sample`), the camera closed
in so that the label covers about 15 % of the image. Measured in one run, on one worker thread,
as process CPU time (other load on the machine cancels): a full render of the design (artwork
variant 0), a relabel to artwork variant 1 (``RenderJob(replaces=Replaces(previous,
{"labels", "assets"}))``), and a full render of the new design from nothing; the relabelled image is
compared with the full one (``relabel_max_diff``, the largest difference of any pixel channel;
0 means bit for bit). Writes ``benchmarks/out/relabel.csv``, ``relabel.png`` (the times) and the
two images; prints ``label_coverage`` (pixels whose trees met the label over all pixels),
``relabel_max_diff=D`` and last ``relabel_fraction=X`` (relabel time over full frame time, the
median over the repeats).
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")


def scene(variant: int = 1):
    """``(design, assets, new design, new assets)``: the sample label (artwork variant 0), and
    its artwork swapped for ``variant`` (same size, alpha and gold band: another colour)."""
    from engine.appearance.sample import labelled, png_bytes, sample_artwork
    from engine.files.project import load_project

    design, assets = load_project(os.path.join(REPO, "resources", "bordeaux.glassbench"))
    cam = dataclasses.replace(design.camera, target=(0.0, 0.0, 110.0), fov_y_deg=17.0)
    design = dataclasses.replace(design, camera=cam)
    a_design, a_assets = labelled(design, assets, variant=0)
    b_assets = dict(a_assets)
    b_assets["label_front_b.png"] = png_bytes(sample_artwork(variant))
    lab = a_design.labels[0]
    b_design = dataclasses.replace(a_design, labels=(dataclasses.replace(
        lab, front=dataclasses.replace(lab.front, asset="label_front_b.png")),))
    return a_design, a_assets, b_design, b_assets


def _timed(fn):
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn()
    return out, time.process_time() - c0, time.perf_counter() - w0


def _job(design, assets, kw, **more):
    from engine.tracer.job import RenderJob

    job = RenderJob(design, assets, **kw, **more).start()
    job.wait()
    if job.error is not None:
        raise job.error
    return job


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--width", type=int, default=240)
    ap.add_argument("--height", type=int, default=320)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from engine.files.images import save_image
    from engine.tracer.job_options import Replaces
    from engine.tracer.kernels.labels import LABEL_BIT0

    os.makedirs(OUT, exist_ok=True)
    kw = dict(width=args.width, height=args.height, spp=args.spp, threads=1)
    a_design, a_assets, b_design, b_assets = scene(3)
    warm = _job(a_design, a_assets, kw)  # warm: kernels loaded (tracing and replay), tables cached
    _job(b_design, b_assets, kw, replaces=Replaces(warm, {"labels", "assets"}))
    rows, diffs = [], []
    for r in range(max(1, args.repeats)):
        # a new artwork each repeat, so its decoding is part of every relabel measured
        a_design, a_assets, b_design, b_assets = scene(1 + r % 2)
        first, full_a, _ = _timed(lambda: _job(a_design, a_assets, kw))
        rel, t_rel, w_rel = _timed(lambda: _job(b_design, b_assets, kw,
                                               replaces=Replaces(first, {"labels", "assets"})))
        full, t_full, w_full = _timed(lambda: _job(b_design, b_assets, kw))
        diff = float(np.max(np.abs(rel.image().astype(np.float64) - full.image())))
        diffs.append(diff)
        coverage = float(np.mean((first.film.objects >> LABEL_BIT0) & 1))
        rows.append(dict(repeat=r, full_a_cpu_s=full_a, relabel_cpu_s=t_rel, relabel_wall_s=w_rel,
                         full_b_cpu_s=t_full, full_b_wall_s=w_full, relabelled_pixels=rel.relabelled_pixels,
                         pixels=args.width * args.height, label_coverage=coverage, max_diff=diff,
                         fraction=t_rel / t_full))
        print(f"repeat {r}: full {t_full:.3f} s cpu, relabel {t_rel:.3f} s cpu "
              f"({rel.relabelled_pixels} of {args.width * args.height} pixels re-traced), "
              f"fraction {t_rel / t_full:.4f}, max diff {diff:g}")
    save_image(os.path.join(OUT, "relabel_before.png"), first.image())
    save_image(os.path.join(OUT, "relabel_after.png"), rel.image())
    with open(os.path.join(OUT, "relabel.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    fig, ax = plt.subplots(figsize=(5, 3.2))
    med = {k: float(np.median([row[k] for row in rows])) for k in ("full_b_cpu_s", "relabel_cpu_s")}
    ax.bar(["full frame", "relabel"], [med["full_b_cpu_s"], med["relabel_cpu_s"]], color=["#777", "#c63"])
    ax.set_ylabel("CPU s (median)")
    ax.set_title(f"relabel, {args.width}x{args.height}, {args.spp} spp")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "relabel.png"), dpi=110)
    print(f"wrote {OUT}/relabel.csv and relabel.png")
    print(f"label_coverage={float(np.median([row['label_coverage'] for row in rows])):.4f}")
    print(f"relabel_recoloured_pixels={rel.recoloured_pixels} relabel_retraced_pixels={rel.relabelled_pixels}")
    print(f"relabel_max_diff={max(diffs):g}")
    print(f"relabel_fraction={float(np.median([row['fraction'] for row in rows])):.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
