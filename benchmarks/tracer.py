"""Tracer benchmark: ray throughput, overhead over raw Embree, thread scaling, error vs time.

The frame / Embree ratio is the cost of everything around the BVH: refining each hit onto
the exact surface (analytic roots, Newton on non-round walls) and shading. The mesh-tolerance
sweep shows what a coarser render mesh costs in accuracy and gains in speed.

Usage::

    python -m benchmarks.tracer [--quick] [--scenes public_1,public_2,...]

Prints the figures, writes ``benchmarks/out/tracer.csv`` and ``benchmarks/out/tracer.png``
(rel RMSE vs render time per oracle scene). Every comparison is a ratio measured in the same
run: the whole frame's time over the time raw Embree needs for exactly the rays the frame
cast (intersection only), 2 threads over 1, truncated trees against a deep tree with the
same samples (so noise cancels and only the truncation bias remains).
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import time

import numpy as np
from benchmarks.paths import ORACLE_SPECS

SPECS = str(ORACLE_SPECS)
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")


def _design(name, **render):
    from benchmarks.oracle_spec import spec_to_design

    design, assets = spec_to_design(f"{SPECS}/{name}.json")
    render = {"max_depth": 64, "min_weight": 2e-3, **render}
    return dataclasses.replace(design, render=dataclasses.replace(design.render, **render)), assets


class _Recorder:
    """Wraps an EmbreeTriangles and keeps a copy of every ray batch it is asked to trace."""

    def __init__(self, tri):
        self.tri, self.batches = tri, []

    def intersect(self, o, d):
        self.batches.append((np.asarray(o, np.float32), np.asarray(d, np.float32)))
        return self.tri.intersect(o, d)


def throughput(name, size, spp):
    """Rays/s of one single-threaded frame and its time over raw Embree on the same rays."""
    from engine.tracer.integrator import TraceStats
    from engine.tracer.tiles import RenderContext, trace_tile_samples

    design, assets = _design(name)
    ctx = RenderContext.from_design(design, assets, size, size)
    rec = _Recorder(ctx.geometry.triangles)
    object.__setattr__(ctx.geometry, "triangles", rec)
    try:
        ys, xs = np.mgrid[0:size, 0:size]
        st = TraceStats()
        t0 = time.perf_counter()
        trace_tile_samples(ctx, xs.ravel(), ys.ravel(), np.zeros(xs.size), np.full(xs.size, spp), st)
        frame = time.perf_counter() - t0
    finally:
        object.__setattr__(ctx.geometry, "triangles", rec.tri)
    scene = rec.tri._scene
    t0 = time.perf_counter()
    for o, d in rec.batches:  # same batches, same ray count, intersection only
        scene.run(o, d, output=1)
    raw = time.perf_counter() - t0
    return {"scene": name, "rays": st.rays_cast, "frame_s": frame, "embree_s": raw,
            "rays_per_s": st.rays_cast / frame, "frame_over_embree": frame / raw,
            "triangles": rec.tri.n_triangles}


def mesh_tolerance(name, size, spp, tols):
    """Frame time and image change against the finest tolerance, per render-mesh tolerance.

    Hits are refined onto the exact surfaces, so the tolerance only moves silhouettes and
    which candidate Embree finds; same samples each time, so noise cancels in the change.
    """
    from benchmarks.oracle_render import rel_rmse
    from engine.tracer import geometry as geo
    from engine.tracer.integrator import TraceStats
    from engine.tracer.tiles import RenderContext, trace_tile_samples

    design, assets = _design(name)
    ys, xs = np.mgrid[0:size, 0:size]
    rows, ref, saved = [], None, geo.MESH_TOL_MM
    try:
        for tol in sorted(tols):
            geo.MESH_TOL_MM = tol
            geo._CACHE.clear()
            t0 = time.perf_counter()
            ctx = RenderContext.from_design(design, assets, size, size)
            build = time.perf_counter() - t0
            st = TraceStats()
            t0 = time.perf_counter()
            sums, _ = trace_tile_samples(ctx, xs.ravel(), ys.ravel(), np.zeros(xs.size), np.full(xs.size, spp), st)
            frame = time.perf_counter() - t0
            img = sums.reshape(size, size, 3)
            ref = img if ref is None else ref
            rows.append({"scene": name, "tol_mm": tol, "triangles": ctx.geometry.triangles.n_triangles,
                         "build_s": build, "frame_s": frame, "change_vs_finest": rel_rmse(img, ref),
                         "escaped_inside": st.escaped_inside})
            print(f"  {name} tol {tol:g} mm: {rows[-1]['triangles']} triangles, build {build:.2f} s, "
                  f"frame {frame:.2f} s, change vs finest {rows[-1]['change_vs_finest']:.5f}")
    finally:
        geo.MESH_TOL_MM = saved
        geo._CACHE.clear()
    return rows


def thread_speedup(name, size, spp):
    """Wall time of the same (deterministic) job on 1 and on 2 threads."""
    from engine.tracer.job import RenderJob

    design, assets = _design(name)
    times, images = {}, {}
    for threads in (1, 2):
        job = RenderJob(design, assets, width=size, height=size, spp=spp, threads=threads, tile=32,
                        adaptive=False).start()
        job.wait()
        times[threads], images[threads] = job.seconds, job.image()
    assert np.array_equal(images[1], images[2]), "thread count changed the image"
    return times[1], times[2], times[1] / times[2]


def error_vs_time(names, configs):
    """rel RMSE and time per scene for each (spp, adaptive noise target or None)."""
    from benchmarks.oracle_render import reference_path, rel_rmse, render_spec
    from engine.tracer.environment import read_radiance_image

    rows = []
    for name in names:
        spec = f"{SPECS}/{name}.json"
        ref = read_radiance_image(reference_path(spec))
        render_spec(spec, 1, 2)  # warm the geometry cache so times are render times
        for spp, target in configs:
            kw = {"noise_target": target} if target else {}
            if target is None:
                img, secs, job = _uniform(spec, spp)
            else:
                img, secs, job = render_spec(spec, spp, 2, **kw)
            err = rel_rmse(img, ref)
            rows.append({"scene": name, "spp": spp, "adaptive": target or 0, "seconds": secs,
                         "mean_spp": float(job.sample_counts().mean()), "rel_rmse": err,
                         "rays": job.stats.rays_cast})
            print(f"  {name}: spp {spp:3d} adaptive {target or '-':>5} -> rel RMSE {err:.4f} "
                  f"in {secs:6.1f} s (mean {rows[-1]['mean_spp']:.1f} spp)")
    return rows


def _uniform(spec, spp):
    from benchmarks.oracle_spec import spec_to_design
    from benchmarks.oracle_render import ORACLE_MAX_DEPTH, ORACLE_MIN_WEIGHT
    from engine.tracer.job import RenderJob

    design, assets = spec_to_design(spec)
    design = dataclasses.replace(design, render=dataclasses.replace(
        design.render, spp=spp, max_depth=ORACLE_MAX_DEPTH, min_weight=ORACLE_MIN_WEIGHT))
    job = RenderJob(design, assets, threads=2, tile=64, adaptive=False).start()
    job.wait()
    return job.image(), job.seconds, job


def truncation(name, size, spp, cuts):
    """Image change of each (max_depth, min_weight) against the deepest, with the same samples."""
    from benchmarks.oracle_render import rel_rmse
    from engine.tracer.job import RenderJob

    out, deep = [], None
    for depth, weight in cuts:
        design, assets = _design(name, max_depth=depth, min_weight=weight)
        job = RenderJob(design, assets, width=size, height=size, spp=spp, threads=2, tile=64,
                        adaptive=False).start()
        job.wait()
        img = job.image()
        deep = img if deep is None else deep
        out.append({"scene": name, "max_depth": depth, "min_weight": weight, "seconds": job.seconds,
                    "rays": job.stats.rays_cast, "bias_vs_deepest": rel_rmse(img, deep)})
        print(f"  depth {depth:4d} min_weight {weight:.0e}: {job.seconds:6.1f} s, "
              f"{job.stats.rays_cast / 1e6:6.2f} M rays, change vs deepest {out[-1]['bias_vs_deepest']:.5f}")
    return out


def main(argv=None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    p = argparse.ArgumentParser(prog="python -m benchmarks.tracer")
    p.add_argument("--quick", action="store_true", help="small sizes, fewer configurations")
    p.add_argument("--scenes", default="public_1,public_2,public_3,public_4")
    a = p.parse_args(argv)
    names = a.scenes.split(",")
    os.makedirs(OUT, exist_ok=True)
    size = 96 if a.quick else 160

    print(f"throughput ({size}x{size}, 2 spp, 1 thread):")
    tp = []
    for name in names:
        r = throughput(name, size, 2)
        tp.append(r)
        print(f"  {name}: {r['rays'] / 1e6:.2f} M rays in {r['frame_s']:.2f} s = {r['rays_per_s'] / 1e6:.2f} M rays/s; "
              f"raw Embree on the same rays {r['embree_s']:.2f} s; frame / Embree = {r['frame_over_embree']:.2f} "
              f"({r['triangles']} triangles)")
    print(f"render-mesh tolerance (hits refined onto the exact surfaces; {size}x{size}, 2 spp, 1 thread):")
    mt = []
    for name in names:
        mt += mesh_tolerance(name, size, 2, [0.005, 0.02, 0.05, 0.2] if not a.quick else [0.01, 0.05, 0.2])
    t1, t2, speedup = thread_speedup(names[0], size, 4)
    print(f"threads ({names[0]}, {size}x{size}, 4 spp): 1 thread {t1:.2f} s, 2 threads {t2:.2f} s, "
          f"speed-up {speedup:.2f}x (images bit-identical)")

    print("truncation (public_1 base region is the worst case: trapped TIR paths):")
    cuts = [(256, 1e-5), (64, 1e-4), (64, 2e-3), (24, 1e-3), (64, 1e-2), (16, 2e-3)]
    tr = truncation("public_1", size, 4, cuts[:4] if a.quick else cuts)

    print("error vs time (256x256 vs the Mitsuba references):")
    configs = [(2, None), (8, None), (8, 0.03), (8, 0.015)] if a.quick else \
        [(1, None), (2, None), (4, None), (8, None), (16, None), (4, 0.03), (8, 0.03), (8, 0.015)]
    ev = error_vs_time(names, configs)

    with open(os.path.join(OUT, "tracer.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["section", "key", "value"])
        for r in tp:
            for k, v in r.items():
                w.writerow(["throughput", f"{r['scene']}.{k}", v])
        for r in mt:
            w.writerow(["mesh_tol", f"{r['scene']}.tol{r['tol_mm']:g}",
                        f"{r['frame_s']:.3f};{r['change_vs_finest']:.5f};{r['triangles']}"])
        w.writerow(["threads", "t1_s", t1])
        w.writerow(["threads", "t2_s", t2])
        w.writerow(["threads", "speedup", speedup])
        for r in tr:
            w.writerow(["truncation", f"depth{r['max_depth']}_w{r['min_weight']:g}", r["bias_vs_deepest"]])
        for r in ev:
            w.writerow(["error", f"{r['scene']}.spp{r['spp']}.adaptive{r['adaptive']}",
                        f"{r['rel_rmse']:.5f};{r['seconds']:.2f}"])
    fig, ax = plt.subplots(figsize=(7, 5))
    for name in names:
        for adaptive, marker in ((0, "o-"), (1, "s--")):
            pts = sorted((r["seconds"], r["rel_rmse"]) for r in ev
                         if r["scene"] == name and bool(r["adaptive"]) == bool(adaptive))
            if pts:
                ax.plot(*zip(*pts), marker, label=f"{name} {'adaptive' if adaptive else 'uniform'}")
    ax.axhline(0.02, color="r", lw=0.8)
    ax.axhline(0.01, color="g", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("render time (s, 2 threads, 256x256)")
    ax.set_ylabel("rel RMSE vs reference")
    ax.legend(fontsize=7)
    fig.savefig(os.path.join(OUT, "tracer.png"), dpi=110, bbox_inches="tight")
    print(f"wrote {OUT}/tracer.csv and tracer.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
