"""Tracer benchmark: frame time against raw Embree on the same rays, thread scaling, latency,
cold start, truncation bias, and error against time on the oracle scenes.

Usage::

    python -m benchmarks.tracer [--quick] [--scenes bordeaux,square,public_1,...]

Every comparison is a ratio measured in the same run, on the same thread:

* **frame / Embree**: the whole frame (camera rays, exact intersection with the analytic
  render objects, Fresnel branching, absorption, environment, film sums) over the time raw
  Embree (embreex, one committed scene of the geometry engine's 0.02 mm tessellation) needs to
  intersect exactly the ray segments the frame traced (recorded in a second pass). Also the
  analytic intersection alone over Embree (the frame's queries, each in its medium).
  The same against Embree called one ray at a time from compiled code
  (:mod:`benchmarks.embree_kernel`), as a tracer with Embree inside its kernels would call it:
  reported beside, not in the printed figure.
* **Embree + refinement / analytic search**: an Embree tracer's whole nearest-hit search
  (:class:`benchmarks.embree_kernel.EmbreeSearch`) against the analytic one, on the frame's own
  queries, at three mesh tolerances and per surface; with the queries it answers differently
  (a crossing its mesh hides) and what a geometry edit would pay to build its mesh.
* **threads**: the same deterministic job (about two seconds on one thread) on 1 and 2 worker
  threads (images bit-identical).
* **latency**: first finished tile over the whole job, and the bundled sample's time to converge.
* **window**: the bundled sample at the window's preview size, converged with the window's
  display-space noise criterion and with the linear one, each with its error in display levels.
* **cold start**: a fresh process compiling the kernels into an empty cache, and then loading them.

CPU time of the measuring thread is used for the frame/Embree ratio (both single-threaded, each
the fastest of ``REPEATS`` runs), so other load on the machine cancels; wall time for the
threaded job. Writes
``benchmarks/out/tracer.csv`` and ``tracer.png``; prints last
``frame_over_embree=X thread_speedup=Y`` (the worst frame ratio over the scenes, and 2 threads
over 1).
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import glob
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from benchmarks.paths import ORACLE_SPECS

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: The bundled samples by name (``resources/NAME.glassbench``).
SAMPLES = {os.path.basename(p)[:-len(".glassbench")]: os.path.relpath(p, ROOT)
           for p in sorted(glob.glob(os.path.join(ROOT, "resources", "*.glassbench")))}


def load_scene(name, **render):
    """A design and its assets by name: a bundled sample or an oracle scene (``public_N``)."""
    if name in SAMPLES:
        from engine.files.project import load_project

        design, assets = load_project(os.path.join(ROOT, SAMPLES[name]))
    else:
        from benchmarks.oracle_spec import spec_to_design

        design, assets = spec_to_design(str(ORACLE_SPECS / f"{name}.json"))
    if render:
        design = dataclasses.replace(design, render=dataclasses.replace(design.render, **render))
    return design, assets


def embree_scene(design, tol_mm=0.02, with_mesh=False):
    """The raw-Embree peer: one committed embreex scene of the glass body (and the liquid's free
    surface) tessellated by the geometry engine at ``tol_mm``; returns ``(scene, triangles)``,
    and the ``(vertices, faces)`` with ``with_mesh``."""
    from embreex.mesh_construction import TriangleMesh
    from embreex.rtcore_scene import EmbreeScene

    from engine.geometry.tessellate import tessellate_body, tessellate_liquid
    from engine.model.fill import fill_height_of

    mesh = tessellate_body(design.shape, tol_mm)
    verts, faces = [mesh.vertices], [mesh.faces]
    h = fill_height_of(design)
    if h is not None:
        liq = tessellate_liquid(design.shape, h, tol_mm)
        f = liq.faces[liq.part == liq.part_names.index("surface")]
        faces.append(f + len(mesh.vertices))
        verts.append(liq.vertices)
    v = np.concatenate(verts).astype(np.float32)
    f = np.concatenate(faces).astype(np.int32)
    scene = EmbreeScene()
    TriangleMesh(scene, v, f)
    scene.run(np.zeros((1, 3), np.float32), np.array([[0, 0, 1]], np.float32))  # commit
    return (scene, len(f), (v, f)) if with_mesh else (scene, len(f))


#: Each timing of the frame/Embree comparison is the fastest of this many runs, for both sides,
#: interleaved (a slow phase of the machine slows both sides of the ratio): a frame of the small
#: scenes takes 30 ms of CPU, which a shared machine stretches by 10-40 %. Not covered: the
#: square sample's frame takes 94 ms in some processes and 127 ms in others, for every one of
#: the runs of a process (the same tables built again in the same process run fast).
REPEATS = 7


def _fastest_interleaved(runs, repeats=REPEATS):
    """The fastest thread CPU time (s) of each of ``runs`` (callables) over ``repeats`` rounds
    that run each once in turn."""
    best = [np.inf] * len(runs)
    for _ in range(repeats):
        for k, run in enumerate(runs):
            t0 = time.thread_time()
            run()
            best[k] = min(best[k], time.thread_time() - t0)
    return best


#: Embree called per ray as a mesh tracer casts (:func:`frame_vs_embree`): past this distance
#: (mm) from the segment's start, so that a cast from a surface point does not stop on that
#: surface's own triangles (the 0.02 mm mesh lies within it of the exact surface)
START_OFFSET_MM = 0.05
#: Embree + refinement (:func:`embree_methods`): the mesh tolerances (mm) it is measured at, each
#: with the distance (mm) from the ray's start Embree's hit is searched past (a ray leaving a
#: surface meets that surface's own triangles again within the chordal error) and the bracket
#: (mm) about Embree's hit the exact root is searched in
EMBREE_TOLERANCES = ((0.1, 0.25, 0.25), (0.02, 0.05, 0.05), (0.005, 0.02, 0.02))


def frame_vs_embree(name, size, spp):
    """One single-threaded frame (every pixel, anti-aliasing samples 1..spp) against raw Embree
    and against the analytic intersection alone, on the rays the frame traced; each the fastest
    of ``REPEATS`` runs, the three interleaved (a slow phase of the machine then slows all
    three, not one side of a ratio)."""
    from benchmarks.embree_kernel import Embree4Scene
    from engine.tracer.context import RenderContext, nearest_hits, trace_pixels

    design, assets = load_scene(name)
    ctx = RenderContext.from_design(design, assets, size, size)
    ys, xs = np.mgrid[0:size, 0:size]
    cols, rows = xs.ravel(), ys.ravel()
    trace_pixels(ctx, cols[:4], rows[:4], 1, 1)  # compiled and warm
    res = trace_pixels(ctx, cols, rows, 1, spp)
    n = int(res.counters[0])
    rec = (np.zeros((n, 9), np.float32), np.zeros(1, np.int64))
    trace_pixels(ctx, cols, rows, 1, spp, record=rec)
    rays = rec[0][:rec[1][0]]
    medium, last, side = (np.ascontiguousarray(rays[:, c].astype(np.int64)) for c in (6, 7, 8))
    scene, tris, mesh = embree_scene(design, with_mesh=True)
    o32, d32 = np.ascontiguousarray(rays[:, :3]), np.ascontiguousarray(rays[:, 3:6])
    o64, d64 = rays[:, :3].astype(float), rays[:, 3:6].astype(float)
    d64 /= np.linalg.norm(d64, axis=1, keepdims=True)
    def analytic():  # the frame's own queries: each in its medium, leaving its object
        return nearest_hits(ctx.geometry, o64, d64, medium, last, side)

    per_ray = Embree4Scene(*mesh)  # the same triangles, one rtcIntersect1 a ray from numba
    try:
        # per ray twice: from the segment's start, as the batch casts (a cast from a surface
        # point meets that surface's own triangles at once for a fifth to a third of the
        # segments, and stops there), and past START_OFFSET_MM, as a mesh tracer casts
        frame, emb, emb1, emb_off, isect = _fastest_interleaved(
            (lambda: trace_pixels(ctx, cols, rows, 1, spp), lambda: scene.run(o32, d32, output=1),
             lambda: per_ray.cast(o32, d32), lambda: per_ray.cast(o32, d32, tnear=START_OFFSET_MM), analytic))
        self_hits = float(np.mean(per_ray.cast(o32, d32)[0] < 0.01))
    finally:
        per_ray.close()
    methods = embree_methods(design, ctx.geometry, (o64, d64, medium, last, side), analytic)
    return {"scene": name, "kind": design.shape.cross_section, "size": size, "spp": spp, "segments": n,
            "frame_s": frame, "embree_s": emb, "intersect_s": isect, "frame_over_embree": frame / emb,
            "intersect_over_embree": isect / emb, "ns_per_segment": 1e9 * frame / n, "triangles": tris,
            "embree_per_ray_s": emb1, "frame_over_embree_per_ray": frame / emb1,
            "embree_offset_s": emb_off, "frame_over_embree_offset": frame / emb_off, "self_hits": self_hits,
            "intersect_over_embree_per_ray": isect / emb1, "embree_methods": methods}


def embree_methods(design, geometry, queries, analytic):
    """Embree + refinement against the analytic search on a frame's own ``queries`` (origins,
    unit directions, medium, object left, side left; mm): complete (:class:`~benchmarks.
    embree_kernel.EmbreeSearch`: triangle to part, bracket, fallback) at each of
    ``EMBREE_TOLERANCES``, and per surface at 0.02 mm (only the kinds where the complete search
    can come out faster meshed: elliptical and offset arcs, swept slabs that are not ruled,
    planes; the rest analytic). Each: time over the analytic search's (interleaved, fastest of
    5), the share of queries that fell back, the share whose answer differs from the exact
    search's and how many of those are *earlier* (a crossing the analytic search would have
    missed: none is expected), and what an edit of the geometry would pay first (tessellate,
    map the triangles to parts, build the BVH; s, wall time of one build)."""
    from benchmarks.embree_kernel import EmbreeSearch
    from engine.tracer.kernels.intersect import PLANE
    from engine.tracer.kernels.profile import ELLIPSE, OFFSET, S_KIND
    from engine.tracer.kernels.swept import SL_RULED

    t_ex, k_ex, _, _ = analytic()
    g = geometry
    masks = (np.isin(g.seg[:, S_KIND].astype(int), (ELLIPSE, OFFSET)), g.slab_f[:, SL_RULED] <= 0.5,
             g.obj_i[:, 0] == PLANE)
    out = []
    for label, (tol, tnear, bracket), m in ([("Embree + refinement", e, None) for e in EMBREE_TOLERANCES]
                                            + [("per surface", EMBREE_TOLERANCES[1], masks)]):
        start = time.perf_counter()
        _, _, mesh = embree_scene(design, tol, with_mesh=True)
        search = EmbreeSearch(g, *mesh, tnear=tnear, bracket=bracket, tol=tol, masks=m)
        build = time.perf_counter() - start
        try:
            t, k, _, fell = search.hits(*queries)
            with np.errstate(invalid="ignore"):  # inf - inf where both miss
                same = (k == k_ex) & ((np.abs(t - t_ex) <= 1e-6 * np.maximum(1.0, np.abs(t_ex))) | (t == t_ex))
            ana, mine = _fastest_interleaved((analytic, lambda: search.hits(*queries)), 5)
        finally:
            search.close()
        out.append({"method": label, "tol_mm": tol, "over_analytic": mine / ana, "fallback": float(fell.mean()),
                    "differ": float(1.0 - same.mean()), "earlier": int(np.sum(~same & (t < t_ex * (1 - 1e-6)))),
                    "meshed_triangles": search.triangles, "build_s": build})
    return out


def thread_speedup(name, size, spp, repeats=3):
    """Wall time of the same deterministic job on 1 and on 2 threads, alternated; median ratio."""
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling

    design, assets = load_scene(name)
    ratios, t1s, t2s, images = [], [], [], {}
    for _ in range(repeats):
        times = {}
        for threads in (1, 2):
            job = RenderJob(design, assets, width=size, height=size, spp=spp, threads=threads,
                            sampling=Sampling(adaptive=False)).start()
            job.wait()
            if job.error is not None:
                raise job.error
            times[threads] = job.seconds
            images[threads] = job.image()
        assert np.array_equal(images[1], images[2]), "the thread count changed the image"
        t1s.append(times[1])
        t2s.append(times[2])
        ratios.append(times[1] / times[2])
    return float(np.median(t1s)), float(np.median(t2s)), float(np.median(ratios))


def latency(name):
    """The window's job on a sample at its own size: first tile, whole job (s, 2 threads)."""
    from engine.tracer.job import RenderJob

    design, assets = load_scene(name)
    job = RenderJob(design, assets, threads=2).start()
    job.wait()
    return {"scene": name, "width": job.width, "height": job.height, "first_tile_s": job.first_tile_seconds,
            "converged_s": job.seconds, "first_over_frame": job.first_tile_seconds / job.seconds,
            "mean_spp": float(job.sample_counts().mean())}


#: The preview pane of the window at its default size (app.layout.DEFAULT_SIZE), device pixels.
WINDOW_SIZE = (715, 954)


#: Samples per edge pixel of the window's reference (:func:`window_convergence`).
REFERENCE_SPP = 256


def window_convergence(name, reference=True):
    """The window's job on a sample at the window's preview size (2 threads): seconds to converge
    with the window's display-space noise criterion and with the linear one of the references,
    each with its RMS error in display levels (of 255, tone-mapped as the window shows it)
    against a render with ``REFERENCE_SPP`` samples on its edges at 5x lower linear noise
    (``reference=False``: no error, no reference)."""
    from engine.tracer import adaptive
    from engine.tracer.job import RenderJob, tonemap_srgb8
    from engine.tracer.sampling import Sampling

    design, assets = load_scene(name)
    w, h = WINDOW_SIZE

    def run(sampling, d=design):
        job = RenderJob(d, assets, width=w, height=h, threads=2, sampling=sampling).start()
        job.wait()
        if job.error is not None:
            raise job.error
        return job

    ref = None
    if reference:  # REFERENCE_SPP samples on every edge pixel: the measured renders share at most
        # 1/16 of its sample positions (a reference at the window's own 16 would share them all
        # and flatter it: 0.31 display levels measured so, 0.38 against an independent one)
        d_ref = dataclasses.replace(design, render=dataclasses.replace(design.render, spp=REFERENCE_SPP))
        ref = tonemap_srgb8(run(Sampling(noise_target=adaptive.NOISE_TARGET / 5), d_ref).image()).astype(float)
    out = []
    for space, target in (("display", adaptive.DISPLAY_NOISE), ("linear", adaptive.NOISE_TARGET)):
        job = run(Sampling(noise_space=space, noise_target=target))
        err = (float(np.sqrt(np.mean((tonemap_srgb8(job.image()).astype(float) - ref) ** 2)))
               if reference else float("nan"))
        out.append({"scene": name, "width": w, "height": h, "noise_space": space, "noise_target": target,
                    "converged_s": job.seconds, "display_rmse_levels": err,
                    "segments": int(job.stats.rays_cast), "mean_spp": float(job.sample_counts().mean())})
    return out


def cold_start():
    """Seconds for a fresh process to render an 8x8 image with an empty kernel cache (compile)
    and again with the cache it left (load)."""
    code = ("import time; t=time.perf_counter(); from engine.tracer.warmup import warm_up; warm_up(); "
            "print(time.perf_counter()-t)")
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, GLASSBENCH_KERNEL_CACHE=cache)
        for what in ("compile", "load"):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, check=True, capture_output=True)
            out[what] = time.perf_counter() - t0
    return out


def truncation(name, size, spp, cuts):
    """Image change of each (max_depth, min_weight) against the deepest, same samples."""
    from benchmarks.oracle_render import rel_rmse
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling

    rows, deep = [], None
    for depth, weight in cuts:
        design, assets = load_scene(name, max_depth=depth, min_weight=weight)
        job = RenderJob(design, assets, width=size, height=size, spp=spp, threads=2,
                        sampling=Sampling(adaptive=False)).start()
        job.wait()
        img = job.image()
        deep = img if deep is None else deep
        rows.append({"scene": name, "max_depth": depth, "min_weight": weight, "seconds": job.seconds,
                     "segments": job.stats.rays_cast, "change_vs_deepest": rel_rmse(img, deep)})
        print(f"  depth {depth:4d} min_weight {weight:.0e}: {job.seconds:6.2f} s, "
              f"{job.stats.rays_cast / 1e6:6.2f} M segments, change vs deepest {rows[-1]['change_vs_deepest']:.5f}")
    return rows


def error_vs_time(names, configs):
    """rel RMSE against the reference and wall time (2 threads) per oracle scene and setting."""
    from benchmarks.oracle_render import reference_path, rel_rmse, render_spec, setting_sampling
    from engine.tracer.tables.environment import read_radiance_image

    rows = []
    for name in names:
        spec = str(ORACLE_SPECS / f"{name}.json")
        ref = read_radiance_image(reference_path(spec))
        render_spec(spec, 1, 2)  # geometry cached, kernels warm: the times are render times
        for spp, target in configs:
            img, secs, job = render_spec(spec, spp, 2, sampling=setting_sampling(target))
            err = rel_rmse(img, ref)
            rows.append({"scene": name, "spp": spp, "noise_target": target or 0, "seconds": secs,
                         "mean_spp": float(job.sample_counts().mean()), "rel_rmse": err})
            print(f"  {name}: spp {spp:3d} noise target {target or '-':>6}: rel RMSE {err:.4f} in {secs:6.2f} s "
                  f"(mean {rows[-1]['mean_spp']:.2f} spp)")
    return rows


def _write(rows, path):
    keys = sorted({k for r in rows for k in r})
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def main(argv=None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    p = argparse.ArgumentParser(prog="python -m benchmarks.tracer")
    p.add_argument("--quick", action="store_true", help="small sizes, fewer settings")
    p.add_argument("--scenes", default=None, help="comma-separated: bordeaux, square, jar, public_1..4")
    a = p.parse_args(argv)
    names = (a.scenes or "bordeaux,square,jar,public_1,public_2,public_3,public_4").split(",")
    oracle = [n for n in names if n.startswith("public_")]
    os.makedirs(OUT, exist_ok=True)
    size, spp = (96, 2) if a.quick else (160, 4)
    from engine.tracer.warmup import warm_up

    warm_up()
    rows = []
    print(f"frame against raw Embree on the same ray segments ({size}x{size}, {spp} AA samples, 1 thread, CPU time):")
    fr = []
    for name in names:
        r = frame_vs_embree(name, size, spp)
        fr.append(r)
        print(f"  {name:9s} ({r['kind']}): {r['segments'] / 1e3:7.1f} k segments, frame {r['frame_s']:.3f} s "
              f"({r['ns_per_segment']:.0f} ns/segment), Embree {r['embree_s']:.3f} s on {r['triangles']} triangles: "
              f"frame/Embree {r['frame_over_embree']:.2f}, analytic intersection/Embree {r['intersect_over_embree']:.2f}")
    print("the same against Embree called one ray at a time from compiled code (benchmarks.embree_kernel: "
          "rtcIntersect1 from numba, no batch arrays; how an Embree tracer's kernels would call it):")
    for r in fr:
        print(f"  {r['scene']:9s}: {1e9 * r['embree_per_ray_s'] / r['segments']:.0f} ns/segment "
              f"({r['embree_per_ray_s'] / r['embree_s']:.2f} of embreex's batch), frame/Embree "
              f"{r['frame_over_embree_per_ray']:.2f}, analytic intersection/Embree "
              f"{r['intersect_over_embree_per_ray']:.2f}; "
              f"cast past {START_OFFSET_MM} mm as a mesh tracer casts (from the start {100 * r['self_hits']:.0f} % of "
              f"the casts end within 0.01 mm, on the start's own triangles): frame/Embree "
              f"{r['frame_over_embree_offset']:.2f}")
    print(f"worst frame over Embree called per ray: {max(r['frame_over_embree_per_ray'] for r in fr):.2f} from the "
          f"segments' starts, {max(r['frame_over_embree_offset'] for r in fr):.2f} past {START_OFFSET_MM} mm "
          "(frame_over_embree below is against embreex's batch, the stack's binding)")
    print("Embree + refinement against the analytic search on the frame's own queries (complete: Embree per ray, "
          "triangle -> part, exact root in a bracket, the tracer's acceptance, the analytic search where that "
          "fails; time over the analytic search's, queries answered differently, of which earlier than the "
          "exact answer):")
    for r in fr:
        parts = [f"mesh {m['tol_mm']} mm {m['over_analytic']:.2f}" if m["method"] != "per surface" else
                 f"per surface ({m['meshed_triangles']} triangles meshed) {m['over_analytic']:.2f}"
                 for m in r["embree_methods"]]
        parts = [f"{p} ({100 * m['differ']:.3f} % differ, {m['earlier']} earlier; built in {m['build_s']:.2f} s)"
                 for p, m in zip(parts, r["embree_methods"])]
        print(f"  {r['scene']:9s} ({r['kind']}): " + "; ".join(parts))
    rows += [dict(section="embree", scene=r["scene"], kind=r["kind"], **m) for r in fr for m in r["embree_methods"]]
    for r in fr:
        del r["embree_methods"]
    rows += [dict(section="frame", **r) for r in fr]
    # a job of at least a second on one thread: a shorter one (192 x 192, 2 spp: 0.15 s since
    # the kernels run without reference counting) measures the pool's start and the film's
    # bookkeeping more than the kernels' scaling (1.49-1.72x there, 1.87-1.91x at a second).
    # The samples are raised as the kernels keep getting faster, aiming at two seconds: the
    # probe's single run pays the first job's start, so aiming at one gave 0.8 s jobs (1.59x)
    t_size, t_spp = 4 * size, max(spp, 4)
    t_probe, _, _ = thread_speedup(names[0], t_size, t_spp, repeats=1)
    t_spp = int(t_spp * max(1.0, np.ceil(2.0 / max(t_probe, 1e-3))))
    t1, t2, speedup = thread_speedup(names[0], t_size, t_spp)
    print(f"threads ({names[0]}, {t_size}x{t_size}, {t_spp} spp, median of 3): 1 thread {t1:.2f} s, "
          f"2 threads {t2:.2f} s: {speedup:.2f}x (images bit-identical)")
    rows.append(dict(section="threads", scene=names[0], t1_s=t1, t2_s=t2, speedup=speedup))
    lat = latency("bordeaux")
    print(f"latency (bordeaux sample at its {lat['width']}x{lat['height']}, 2 threads): first tile "
          f"{lat['first_tile_s']:.3f} s, converged {lat['converged_s']:.2f} s ({lat['first_over_frame']:.3f} of the "
          f"frame), mean {lat['mean_spp']:.2f} samples/pixel")
    rows.append(dict(section="latency", **lat))
    win = window_convergence("bordeaux")
    for r in win:
        print(f"window (bordeaux at the window's {r['width']}x{r['height']}, 2 threads, noise in {r['noise_space']} "
              f"space < {r['noise_target']:.4f}): converged {r['converged_s']:.2f} s, {r['segments'] / 1e6:.1f} M "
              f"segments, display error {r['display_rmse_levels']:.3f} levels RMS against a {REFERENCE_SPP}-sample reference")
    rows += [dict(section="window", **r) for r in win]
    cs = cold_start()
    print(f"cold start: compile the kernels {cs['compile']:.1f} s, load them from the cache {cs['load']:.1f} s "
          f"(fresh processes, each rendering 8x8 px)")
    rows.append(dict(section="cold_start", **cs))
    tr = []
    if "public_1" in names:
        print("truncation (public_1: light trapped by total internal reflection in the thick base):")
        cuts = [(256, 1e-5), (256, 2e-3), (64, 1e-3), (24, 1e-3)] if a.quick else \
            [(1024, 1e-5), (256, 1e-5), (256, 2e-3), (64, 1e-3), (64, 1e-2), (24, 1e-3)]
        tr = truncation("public_1", size, spp, cuts)
        rows += [dict(section="truncation", **r) for r in tr]
    ev = []
    if oracle:
        print("error against time (256x256 against the references, 2 threads):")
        configs = [(4, None), (16, None), (16, 0.01)] if a.quick else \
            [(1, None), (4, None), (16, None), (64, None), (16, 0.02), (16, 0.01), (16, 0.005)]
        ev = error_vs_time(oracle, configs)
        rows += [dict(section="error", **r) for r in ev]
    _write(rows, os.path.join(OUT, "tracer.csv"))

    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 4.5))
    x = np.arange(len(fr))
    ax0.bar(x - 0.2, [r["frame_over_embree"] for r in fr], 0.4, label="whole frame / Embree")
    ax0.bar(x + 0.2, [r["intersect_over_embree"] for r in fr], 0.4, label="analytic intersection / Embree")
    ax0.axhline(3.0, color="r", lw=0.8, label="target 3x")
    ax0.axhline(1.0, color="k", lw=0.5)
    ax0.set_xticks(x, [f"{r['scene']}\n{r['kind']}" for r in fr], fontsize=7)
    ax0.set_ylabel("time over raw Embree, same ray segments")
    ax0.legend(fontsize=7)
    for name in oracle:
        for adaptive, style in ((False, "o-"), (True, "s--")):
            pts = sorted((r["seconds"], r["rel_rmse"]) for r in ev if r["scene"] == name and bool(r["noise_target"]) == adaptive)
            if pts:
                ax1.plot(*zip(*pts), style, label=f"{name} {'adaptive' if adaptive else 'AA spp'}")
    ax1.axhline(0.012, color="r", lw=0.8, label="1.2 % bar")
    ax1.set_xscale("log")
    ax1.set_yscale("log")
    ax1.set_xlabel("render time (s, 2 threads, 256x256)")
    ax1.set_ylabel("rel RMSE against the reference")
    ax1.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "tracer.png"), dpi=110)
    print(f"wrote {OUT}/tracer.csv and tracer.png")
    print(f"frame_over_embree={max(r['frame_over_embree'] for r in fr):.2f} thread_speedup={speedup:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
