"""Finishes benchmark: frame-time cost of each finish against the plain bottle, and the error of
the bump approximation against true geometry for thread rings and for a helical screw thread,
in the same view.

Usage::

    python -m benchmarks.finishes [--quick]

* **cost**: the Bordeaux sample with one finish at a time (each procedural tile, frosting, an
  embossed logo, each closure kind), the same small frame (every pixel, the same samples),
  CPU time of the tracing thread, the minimum over repeats interleaved with the plain bottle's;
  reported as the ratio to the plain bottle, with the plain bottle's ratio to itself as the
  noise floor, with the ratio of boundaries met (a relief that spreads rays makes bigger trees:
  much of a finish's cost is the light it scatters, not the kernel). The plain design runs the
  kernels' plain path (no finish rows; bit-identical image): its cost against the code before
  finishes is one test per hit, measured by ``--plain-vs DIR`` (DIR a copy of the older tree,
  e.g. ``git archive f019c7d | tar -x -C DIR``): the plain frame timed in alternating
  processes of both trees, the minimum of each.
* **bump vs geometry**: a 28 mm neck with thread *rings* (the thread's bell-shaped ridge
  profile, 0.6 mm deep on a 4.23 mm pitch = 6 per inch, without the helix's lead so that the
  true surface is a revolved profile the tracer solves exactly) rendered twice in the same
  view: (a) true geometry, the ridge profile tessellated into 320 line segments of the outer
  section (0.05 mm apart; the wall is 0.3 mm thin so that its inner offset stays valid under the
  ridges' 0.45 mm crest radius), (b) the straight neck of the same bottle with the same profile
  as a height-map bump (a 1024-row 16-bit grey image, the relief kernels' bilinear height and
  slopes). The glass is black (20 /mm): the true wall's inner surface is corrugated too, which a
  bump on the outer surface is not meant to be, so only the outer surface is compared.
  Reported: the mean absolute error of (b) against (a) over the neck's pixels, relative to the
  mean radiance there, and against the plain neck (how much of the rings' look the bump
  recovers). What a bump cannot give, by design: the silhouette and the rings' occlusion of
  one another at grazing view, which is where the error sits (the error image is written).

* **thread, relief vs true helix**: a 28-400 screw thread (1.19 mm ridge, one turn) on a 28 mm
  neck with a 1.5 mm wall, in clear glass, rendered with ``geometry="true"`` (the helical ridge
  as glass, :mod:`engine.tracer.kernels.helix`) and ``geometry="relief"`` (the same ridge
  profile bending the shading normal) in the same view, and the plain neck. Reported: the
  relief's mean absolute error against the true geometry over the neck's pixels (relative to
  their mean radiance), the plain neck's, the relief's over the thread's own pixels (where the
  true thread changes the plain neck by over 1 %), and the CPU time of each frame (best of
  repeats) with the ratio true / relief. The cost table also has the Bordeaux's thread drawn true.

Writes ``benchmarks/out/finishes.csv``, ``finishes.png`` (cost bars; the three ring images
and the error) and ``finishes_thread.png``; prints last ``worst_cost=X bump_error=Y
thread_relief_error=Z thread_true_cost=W``.
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import time

import numpy as np

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "resources"))

#: The rings of the bump-vs-geometry comparison (mm).
RING_Z0, RING_Z1, RING_PITCH, RING_DEPTH, RING_WALL = 280.0, 296.0, 25.4 / 6.0, 0.6, 0.3


def _trace_cpu(design, assets, w, h, spp, repeats):
    """``(image (h, w, 3), best thread CPU seconds, boundaries met)`` of every pixel's samples
    ``0..spp-1``."""
    from engine.tracer.context import RenderContext, trace_pixels
    ctx = RenderContext.from_design(design, assets, w, h)
    ys, xs = np.mgrid[0:h, 0:w]
    best, res = math.inf, None
    for _ in range(repeats):
        t0 = time.thread_time()
        res = trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, spp)
        best = min(best, time.thread_time() - t0)
    assert res.counters[1] == 0 and res.counters[2] == 0, "leak or medium mismatch"
    return res.sums.reshape(h, w, 3) / spp, best, int(res.counters[6])


def finish_variants(design, assets):
    """``[(name, design, assets)]``: the plain bottle twice, then one finish at a time."""
    from engine.appearance.closure_shapes import default_cap
    from engine.operations.tiles import add_image_tile, new_tile
    from make_finish_samples import logo_png
    zt = design.shape.z_top
    out = [("plain", design, assets), ("plain again", design, assets)]
    for kind, z0, z1 in (("knurl", 2.0, 30.0), ("stipple", 2.0, 30.0), ("flutes", 40.0, 150.0),
                         ("facets", 40.0, 150.0), ("diamond", 40.0, 150.0), ("thread", zt - 18.0, zt - 2.0)):
        out.append((kind, dataclasses.replace(design, bumps=(new_tile(design, kind, z0, z1),)), assets))
    out.append(("thread true", dataclasses.replace(
        design, bumps=(new_tile(design, "thread", zt - 18.0, zt - 2.0, geometry="true"),)), assets))
    out.append(("frosted a=0.3", dataclasses.replace(
        design, bumps=(new_tile(design, "frosted", 15.0, 180.0, alpha=0.3),)), assets))
    logo = logo_png(128)
    tile, name = add_image_tile(design, {}, "emboss", "logo.png", logo, 80.0, 140.0, width_deg=70.0,
                                angle_deg=-90.0, depth=0.8)
    out.append(("emboss logo", dataclasses.replace(design, bumps=(tile,)), {**assets, name: logo}))
    for kind in ("screw", "crown", "cork", "ropp", "lug"):
        out.append((f"cap {kind}", dataclasses.replace(design, cap=default_cap(kind)), assets))
    return out


def measure_costs(w, h, spp, repeats):
    """Rows of frame cost per finish: each variant's repeats interleaved with the plain
    bottle's, so that load from other processes falls on both (the ratio is of the minima)."""
    from engine.files.project import load_project
    from engine.tracer.context import RenderContext, trace_pixels
    design, assets = load_project(os.path.join(ROOT, "resources", "bordeaux.glassbench"))
    ys, xs = np.mgrid[0:h, 0:w]
    xs, ys = xs.ravel(), ys.ravel()

    def timed(ctx):
        t0 = time.thread_time()
        res = trace_pixels(ctx, xs, ys, 0, spp)
        assert res.counters[1] == 0 and res.counters[2] == 0, "leak or medium mismatch"
        return time.thread_time() - t0, int(res.counters[6])

    plain = RenderContext.from_design(design, assets, w, h)
    rows = []
    for name, d, a in finish_variants(design, assets):
        ctx = RenderContext.from_design(d, a, w, h)
        p_best = v_best = math.inf
        for _ in range(repeats):
            p_sec, p_nodes = timed(plain)
            v_sec, v_nodes = timed(ctx)
            p_best, v_best = min(p_best, p_sec), min(v_best, v_sec)
        rows.append({"finish": name, "cpu_s": round(v_best, 4), "plain_cpu_s": round(p_best, 4),
                     "ratio_to_plain": round(v_best / p_best, 3), "boundaries_ratio": round(v_nodes / p_nodes, 3)})
        print(f"  {name:14s} {v_best * 1e3:8.1f} ms  x{v_best / p_best:.2f}  (boundaries x{v_nodes / p_nodes:.2f})")
    return rows


# ----------------------------------------------------------------------- bump vs geometry
def ring_profile(z):
    """Height (mm) of the rings at heights ``z``: a cos^2 ridge half a pitch wide per pitch,
    centred on the band, fading to nothing 1 mm inside the band's ends."""
    z = np.asarray(z, float)
    x = (z - 0.5 * (RING_Z0 + RING_Z1)) / RING_PITCH
    x = x - np.round(x)
    ridge = np.where(np.abs(x) < 0.25, np.cos(2.0 * np.pi * x) ** 2, 0.0)
    inside = (z > RING_Z0 + 1.0) & (z < RING_Z1 - 1.0)
    return RING_DEPTH * ridge * inside


def ring_designs():
    """``(true geometry design, bump design, plain design, bump assets)`` in the same view."""
    from make_samples import bordeaux_section, round_shape
    from engine.geometry.section import Section
    from engine.geometry.segments import Line
    from engine.model.design import BumpTile, Camera, Design, Glass, RenderSettings
    sec = bordeaux_section(190.0, neck_r=14.0, top=300.0)
    segs = list(sec.segments)
    neck = segs[-1]
    r, zc = neck.p0
    zs = np.linspace(RING_Z0, RING_Z1, 321)
    pts = [(r + float(hh), float(z)) for z, hh in zip(zs, ring_profile(zs))]
    rings = [Line((r, zc), (r, RING_Z0))] + [Line(a, b) for a, b in zip(pts[:-1], pts[1:])]
    rings.append(Line((r, RING_Z1), neck.p1))
    true_sec = Section(tuple(segs[:-1] + rings), tuple(sec.smooth) + (False,) * (len(rings) - 1))
    cam = Camera(eye=(0.0, -160.0, 300.0), target=(0.0, 0.0, 288.0), fov_y_deg=9.0)
    # black glass: the true 0.3 mm wall's inner surface follows the rings too (a uniform offset),
    # which a bump on the outer surface does not; absorbed, only the outer surface is compared
    base = Design(shape=round_shape(sec, RING_WALL, 4.0), glass=Glass(1.52, (20.0, 20.0, 20.0)), camera=cam,
                  render=RenderSettings(width=96, height=128, spp=4))
    true = dataclasses.replace(base, shape=round_shape(true_sec, RING_WALL, 4.0))
    png = _height_png(ring_profile(np.linspace(RING_Z0, RING_Z1, 1024)[::-1]) / RING_DEPTH)
    tile = BumpTile("rings", "height_map", RING_Z0, RING_Z1, repeat=1, depth=RING_DEPTH, asset="rings.png",
                    width_deg=360.0)
    return true, dataclasses.replace(base, bumps=(tile,)), base, {"rings.png": png}


def _height_png(column):
    """16-bit grey PNG bytes, 8 texels wide, rows = ``column`` (0..1, row 0 at the top)."""
    import io
    from PIL import Image
    img = np.repeat(np.round(np.clip(column, 0, 1) * 65535).astype(np.uint16)[:, None], 8, axis=1)
    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG")
    return buf.getvalue()


def bump_vs_geometry(w, h, spp):
    true, bump, plain, assets = ring_designs()
    a, t_true, _ = _trace_cpu(true, None, w, h, spp, 1)
    b, t_bump, _ = _trace_cpu(bump, assets, w, h, spp, 1)
    c, _, _ = _trace_cpu(plain, None, w, h, spp, 1)
    from engine.tracer.context import RenderContext, trace_pixels
    ctx = RenderContext.from_design(true, None, w, h)
    ys, xs = np.mgrid[0:h, 0:w]
    mask = (trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, 1).objects.reshape(h, w) & 1) == 1  # the neck
    level = float(a[mask].mean())
    err = float(np.abs(b - a)[mask].mean()) / level
    err_plain = float(np.abs(c - a)[mask].mean()) / level
    return {"bump_error": round(err, 4), "plain_error": round(err_plain, 4),
            "recovered": round(1.0 - err / err_plain, 3), "true_cpu_s": round(t_true, 4),
            "bump_cpu_s": round(t_bump, 4)}, (a, b, c, mask)


# ------------------------------------------------------------- thread: relief vs helix
#: The thread of the relief-vs-true comparison: a 28-400 finish on a 28 mm neck whose wall is
#: this thick (mm), so the 1.19 mm ridge is large against it ("auto" draws it as geometry).
THREAD_FINISH, THREAD_WALL = "28-400", 1.5


def thread_designs():
    """``(true geometry design, relief design, plain design)``: the same neck, thread and view."""
    from make_samples import bordeaux_section, round_shape
    from engine.operations.tiles import new_tile
    from engine.model.design import Camera, Design, RenderSettings
    sec = bordeaux_section(190.0, neck_r=14.0, top=300.0)
    cam = Camera(eye=(0.0, -160.0, 300.0), target=(0.0, 0.0, 289.0), fov_y_deg=16.0)  # both silhouettes
    base = Design(shape=round_shape(sec, THREAD_WALL, 4.0), camera=cam,
                  render=RenderSettings(width=96, height=128, spp=4))
    tile = new_tile(base, "thread", 280.0, 298.0, finish=THREAD_FINISH)
    true, relief = (dataclasses.replace(base, bumps=(dataclasses.replace(tile, geometry=g),))
                    for g in ("true", "relief"))
    return true, relief, base


def thread_relief_vs_true(w, h, spp, repeats):
    """The thread drawn both ways in the same view: the relief's mean absolute error against
    the true helical geometry over the neck's pixels (relative to their mean radiance), the
    plain neck's, and each frame's CPU time (best of ``repeats``)."""
    from engine.appearance.bands import thread_drawings
    from engine.tracer.context import RenderContext, trace_pixels
    true, relief, plain = thread_designs()
    assert thread_drawings(true)[0].mode == "true" and thread_drawings(relief)[0].mode == "relief"
    # the three frames interleaved, so that load from other processes falls on all of them
    runs = [_trace_cpu(d, None, w, h, spp, 1) for _ in range(repeats) for d in (true, relief, plain)]
    (a, _, n_true), (b, _, n_relief), (c, _, _) = runs[:3]
    t_true, t_relief, t_plain = (min(r[1] for r in runs[k::3]) for k in range(3))
    ctx = RenderContext.from_design(true, None, w, h)
    ys, xs = np.mgrid[0:h, 0:w]
    mask = (trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, 1).objects.reshape(h, w) & 1) == 1
    level = float(a[mask].mean())
    err = float(np.abs(b - a)[mask].mean()) / level
    err_plain = float(np.abs(c - a)[mask].mean()) / level
    # the thread's own pixels: where the true thread changes the plain neck by over 1 %
    thread = (np.abs(a - c).mean(-1) > 0.01 * level) & mask
    err_thread = float(np.abs(b - a)[thread].mean()) / float(a[thread].mean())
    return {"relief_error": round(err, 4), "plain_error": round(err_plain, 4),
            "recovered": round(1.0 - err / err_plain, 3), "relief_error_on_thread": round(err_thread, 4),
            "thread_pixels": int(thread.sum()), "neck_pixels": int(mask.sum()), "true_cpu_s": round(t_true, 4),
            "relief_cpu_s": round(t_relief, 4), "plain_cpu_s": round(t_plain, 4),
            "true_over_relief": round(t_true / t_relief, 3),
            "boundaries_true_over_relief": round(n_true / n_relief, 3)}, (a, b, c, mask)


_PLAIN_CHILD = """
import sys, time, numpy as np
from engine.files.project import load_project
from engine.tracer.context import RenderContext, trace_pixels
d, a = load_project(sys.argv[1])
ctx = RenderContext.from_design(d, a, 96, 128)
ys, xs = np.mgrid[0:128, 0:96]
trace_pixels(ctx, xs.ravel()[:8], ys.ravel()[:8], 0, 1)
best = 1e9
for _ in range(5):
    t = time.thread_time(); trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, 4); best = min(best, time.thread_time() - t)
print(best)
"""


def plain_vs(ref_dir, rounds=6):
    """``(before s, after s)``: the plain Bordeaux frame (96 x 128, 4 samples) in the tree at
    ``ref_dir`` and in this one, alternating processes, the minimum of each."""
    import subprocess
    project = os.path.join(ROOT, "resources", "bordeaux.glassbench")
    best = {ref_dir: math.inf, ROOT: math.inf}
    for _ in range(rounds):
        for tree in (ref_dir, ROOT):
            out = subprocess.run([sys.executable, "-c", _PLAIN_CHILD, project], cwd=tree, capture_output=True,
                                 text=True, env={**os.environ, "PYTHONPATH": tree}, check=True)
            best[tree] = min(best[tree], float(out.stdout.strip().splitlines()[-1]))
    return best[ref_dir], best[ROOT]


def main(argv=None) -> int:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from benchmarks.tracer import _write
    from engine.tracer.job import tonemap_srgb8
    from engine.tracer.warmup import warm_up
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller frames, one repeat")
    ap.add_argument("--plain-vs", metavar="DIR", help="also time the plain frame against the tree in DIR")
    args = ap.parse_args(argv)
    warm_up()
    if args.plain_vs:
        before, after = plain_vs(os.path.abspath(args.plain_vs))
        print(f"plain frame: before {before * 1e3:.1f} ms, now {after * 1e3:.1f} ms, x{after / before:.3f}")
    w, h, spp, rep = (48, 64, 2, 1) if args.quick else (72, 96, 4, 3)
    os.makedirs(OUT, exist_ok=True)
    print(f"frame cost, Bordeaux {w} x {h}, {spp} samples per pixel, best of {rep} (thread CPU):")
    rows = measure_costs(w, h, spp, rep)
    print("thread rings, bump against true geometry (same view):")
    summary, (a, b, c, mask) = bump_vs_geometry(96, 128, 4 if not args.quick else 2)
    for k, v in summary.items():
        print(f"  {k} = {v}")
    print("screw thread 28-400, relief against true helical geometry (same view):")
    helix, (ta, tb, tc, tmask) = thread_relief_vs_true(96, 128, 4 if not args.quick else 2, rep)
    for k, v in helix.items():
        print(f"  {k} = {v}")
    _write(rows + [{"finish": "rings: bump vs geometry", **summary},
                   {"finish": "thread: relief vs true helix", **helix}], os.path.join(OUT, "finishes.csv"))
    _thread_figure(plt, tonemap_srgb8, helix, ta, tb, tc, tmask)
    fig, ax = plt.subplots(1, 5, figsize=(15, 4.2), gridspec_kw={"width_ratios": [3, 1, 1, 1, 1]})
    ax[0].barh([r["finish"] for r in rows], [r["ratio_to_plain"] for r in rows], color="#4a7")
    ax[0].axvline(1.0, color="k", lw=0.8)
    ax[0].set_xlabel("frame time / plain bottle (same run)")
    ax[0].invert_yaxis()
    err = np.abs(b - a).mean(-1) * mask
    for i, (img, title) in enumerate(((a, "true geometry"), (b, "bump"), (c, "plain neck"))):
        ax[i + 1].imshow(tonemap_srgb8(img))
        ax[i + 1].set_title(title)
        ax[i + 1].axis("off")
    ax[4].imshow(err, cmap="magma")
    ax[4].set_title(f"|bump - true| ({summary['bump_error']:.1%})")
    ax[4].axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "finishes.png"), dpi=100)
    print(f"wrote {OUT}/finishes.csv and finishes.png")
    worst = max(r["ratio_to_plain"] for r in rows)
    print(f"worst_cost={worst:.2f} bump_error={summary['bump_error']:.4f} "
          f"thread_relief_error={helix['relief_error']:.4f} thread_true_cost={helix['true_over_relief']:.2f}")
    return 0


def _thread_figure(plt, tonemap, helix, a, b, c, mask):
    """``finishes_thread.png``: the thread true, as relief, the plain neck and the error."""
    fig, ax = plt.subplots(1, 4, figsize=(10, 4.2))
    err = np.abs(b - a).mean(-1) * mask
    for i, (img, title) in enumerate(((a, "true helix"), (b, "relief"), (c, "plain neck"))):
        ax[i].imshow(tonemap(img))
        ax[i].set_title(title)
        ax[i].axis("off")
    ax[3].imshow(err, cmap="magma")
    ax[3].set_title(f"|relief - true| ({helix['relief_error']:.1%})")
    ax[3].axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "finishes_thread.png"), dpi=100)


if __name__ == "__main__":
    raise SystemExit(main())
