"""Batch benchmark: frames per minute on 1 and 2 local Dask workers, the scheduling overhead
per task against task size, and a paper projection of a 36-frame x 20-variant review.

Usage::

    python -m benchmarks.batch [--quick] [--review 120x160x16] [--bandwidth-mb-s 125]

Everything is measured in this run on the Bordeaux sample; nothing about the tracer's speed is
assumed (it is being made much faster, and the projection follows whatever it measures).

* Throughput: the same turntable batch (``run_batch``: render, atomic writes, manifest,
  contact sheet, summary) on a warm LocalCluster of 1 and of 2 single-threaded workers.
* Overhead: on one worker with tasks queued as in a batch, the per-task time of tasks of known
  length (sleeps from 0 to 1 s) minus their length, the cost of sending a frame back, and real
  frame tasks from 8x8 to 64x64 pixels against the same frames rendered in this process.
* Projection: 720 frames at the ``--review`` size, from the measured single-thread frame time,
  the measured 2-worker efficiency, the measured per-task overhead, and the measured bytes of
  a variant payload (once per worker), a task message and a result (to the client). Only the
  network bandwidth is a parameter (``--bandwidth-mb-s``), as no cluster network exists here.

Writes ``benchmarks/out/batch.csv`` and ``benchmarks/out/batch.png``; prints last the line
``batch_speedup_2_workers=X``.
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import os
import pickle
import tempfile
import time

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
PROJECT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "resources",
                       "bordeaux.glassbench")
REVIEW_FRAMES, REVIEW_VARIANTS = 36, 20
MACHINES = (1, 8, 64)


def throughput(workers: int, frames: int, size, spp: int) -> dict:
    """Frames per minute of a real batch on a warm LocalCluster of ``workers`` workers."""
    from engine.batch.execute import open_client
    from engine.batch.jobfile import turntable_job
    from engine.batch.run import run_batch
    t0 = time.perf_counter()
    with open_client(workers=workers) as client, tempfile.TemporaryDirectory() as tmp:
        client.wait_for_workers(workers, timeout=120)
        start_s = time.perf_counter() - t0
        # Warm-up: every worker builds its render geometry once (as any real batch's first frames).
        run_batch(turntable_job(PROJECT, workers, os.path.join(tmp, "warm"), width=size[0], height=size[1],
                                spp=spp), client=client)
        job = turntable_job(PROJECT, frames, os.path.join(tmp, "run"), width=size[0], height=size[1], spp=spp)
        report = run_batch(job, client=client)
    return {"workers": workers, "frames": frames, "seconds": report.seconds, "cluster_start_s": start_s,
            "frames_per_minute": 60.0 * frames / report.seconds}


def overhead(durations, frame_sizes, result_sides) -> dict:
    """Scheduling overhead per task on one single-threaded worker, tasks queued as in a batch.

    * ``sleep``: tasks of known length (``time.sleep(d)``, immune to the load of a shared
      machine): per-task time minus ``d``, for each ``d`` in ``durations`` (s).
    * ``result``: tasks that return a float32 ``(side, side, 3)`` frame: the cost of sending a
      frame back, per megabyte.
    * ``frame``: real frame tasks (:func:`engine.batch.task.render_frame`, ``frame_sizes``
      pixels square, 1 spp) against the same frame rendered here; best of 3 each, so only a
      sanity check on a loaded machine.
    """
    import numpy as np

    from engine.batch.execute import open_client
    from engine.batch.task import render_frame
    from engine.files.project import load_project
    design, assets = load_project(PROJECT)
    out = {"sleep": [], "result": [], "frame": []}
    with open_client(workers=1) as client:
        client.submit(time.sleep, 0, pure=False).result()
        for d in durations:
            n = max(5, min(200, int(2.0 / max(d, 0.01))))
            t0 = time.perf_counter()
            client.gather([client.submit(time.sleep, d, pure=False) for _ in range(n)])
            per_task = (time.perf_counter() - t0) / n
            out["sleep"].append({"task_s": d, "tasks": n, "per_task_s": per_task,
                                 "overhead_s": per_task - d, "overhead_fraction": (per_task - d) / per_task})
        for side in result_sides:
            n = 5
            t0 = time.perf_counter()
            client.gather([client.submit(np.zeros, (side, side, 3), np.float32, pure=False)
                           for _ in range(n)])
            per_task = (time.perf_counter() - t0) / n
            mb = side * side * 12 / 1e6
            out["result"].append({"side": side, "megabytes": mb, "per_task_s": per_task,
                                  "s_per_mb": per_task / mb})
        payload = client.scatter([(design, assets)], broadcast=True)[0]
        for s in frame_sizes:
            render = dataclasses.replace(design.render, width=s, height=s, spp=1)
            args = (design.camera, render, False, 1)
            render_frame((design, assets), *args)  # warm: geometry built here and on the worker
            client.submit(render_frame, payload, *args, pure=False).result()
            dask, local = [], []
            for _ in range(3):
                t0 = time.perf_counter()
                client.submit(render_frame, payload, *args, pure=False).result()
                dask.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                render_frame((design, assets), *args)
                local.append(time.perf_counter() - t0)
            out["frame"].append({"size": f"{s}x{s}", "local_s": min(local), "dask_s": min(dask),
                                 "overhead_s": min(dask) - min(local)})
    return out


def data_sizes(review) -> dict:
    """Bytes of a variant payload, of one task's own arguments, and of one result frame."""
    import numpy as np
    from engine.files.project import load_project
    design, assets = load_project(PROJECT)
    w, h, _ = review
    return {"payload_bytes": len(pickle.dumps((design, assets))),
            "task_bytes": len(pickle.dumps((design.camera, design.render, False, 1, "topic",
                                            "v/frame_0000.png"))),
            "result_bytes": len(pickle.dumps(np.zeros((h, w, 3), np.float32)))}


def review_frame_s(review) -> float:
    """Seconds of one review frame, one thread, geometry already built (as on a warm worker)."""
    from engine.files.project import load_project
    from engine.tracer.job import render_image
    design, assets = load_project(PROJECT)
    w, h, spp = review
    render_image(design, assets, width=8, height=8, spp=1, threads=1)
    t0 = time.perf_counter()
    render_image(design, assets, width=w, height=h, spp=spp, threads=1)
    return time.perf_counter() - t0


def projection(frame_s, efficiency, task_overhead_s, sizes, cores, bandwidth) -> list:
    """Wall time of the review on 1, 8 and 64 machines of ``cores`` workers each (seconds)."""
    n = REVIEW_FRAMES * REVIEW_VARIANTS
    rows = []
    for m in MACHINES:
        workers = m * cores
        rounds = math.ceil(n / workers)
        compute = rounds * (frame_s / efficiency + task_overhead_s)
        results = n * sizes["result_bytes"] / bandwidth  # every frame comes back to the client
        payloads = REVIEW_VARIANTS * workers * sizes["payload_bytes"] / bandwidth
        messages = n * sizes["task_bytes"] / bandwidth
        total = max(compute, results) + payloads + messages
        rows.append({"machines": m, "workers": workers, "rounds": rounds, "compute_s": compute,
                     "result_transfer_s": results, "payload_s": payloads, "total_s": total,
                     "bound": "compute" if compute >= results else "network"})
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="fewer and smaller frames")
    p.add_argument("--review", default=None, help="review frame WxHxSPP (default 120x160x16; quick 48x64x4)")
    p.add_argument("--bandwidth-mb-s", type=float, default=125.0,
                   help="assumed cluster network bandwidth, MB/s (default 125 = 1 Gbit/s)")
    p.add_argument("--cores-per-machine", type=int, default=2, help="workers per machine in the projection")
    a = p.parse_args(argv)
    review = tuple(int(v) for v in (a.review or ("48x64x4" if a.quick else "120x160x16")).split("x"))
    frames, size, spp = (4, (32, 40), 1) if a.quick else (8, (48, 64), 2)
    sizes = (8, 16, 32) if a.quick else (8, 16, 32, 64)
    os.makedirs(OUT, exist_ok=True)

    print(f"throughput: {frames}-frame turntable, {size[0]}x{size[1]} px, {spp} spp, warm LocalCluster")
    tp = [throughput(n, frames, size, spp) for n in (1, 2)]
    for r in tp:
        print(f"  {r['workers']} worker(s): {r['seconds']:.2f} s = {r['frames_per_minute']:.1f} frames/min "
              f"(cluster start {r['cluster_start_s']:.1f} s)")
    speedup = tp[1]["frames_per_minute"] / tp[0]["frames_per_minute"]
    print(f"  speed-up with 2 workers: {speedup:.2f}x")

    print("scheduling overhead per task (1 worker, tasks queued):")
    ov = overhead((0.0, 0.001, 0.01, 0.1, 1.0) if not a.quick else (0.0, 0.01, 0.1),
                  sizes, (64, 256, 1024) if not a.quick else (64, 256))
    for r in ov["sleep"]:
        print(f"  {1e3 * r['task_s']:7.1f} ms task: {1e3 * r['per_task_s']:8.2f} ms each, overhead "
              f"{1e3 * r['overhead_s']:.2f} ms = {100 * r['overhead_fraction']:.1f} % of the task")
    for r in ov["result"]:
        print(f"  returning a {r['side']}x{r['side']} float frame ({r['megabytes']:.2f} MB): "
              f"{1e3 * r['per_task_s']:.1f} ms per task")
    for r in ov["frame"]:
        print(f"  {r['size']:>7} frame render: here {r['local_s']:.3f} s, as a task {r['dask_s']:.3f} s "
              f"(difference {1e3 * r['overhead_s']:+.0f} ms; best of 3 on a shared machine)")
    task_overhead = ov["sleep"][0]["overhead_s"]

    ds = data_sizes(review)
    frame_s = review_frame_s(review)
    efficiency = min(1.0, speedup / 2.0)
    bandwidth = a.bandwidth_mb_s * 1e6
    pr = projection(frame_s, efficiency, task_overhead, ds, a.cores_per_machine, bandwidth)
    print(f"projection: {REVIEW_FRAMES} frames x {REVIEW_VARIANTS} variants at {review[0]}x{review[1]} px, "
          f"{review[2]} spp; measured frame {frame_s:.2f} s (1 thread), 2-worker efficiency "
          f"{efficiency:.2f}, task overhead {1e3 * task_overhead:.1f} ms, payload {ds['payload_bytes']} B, "
          f"task {ds['task_bytes']} B, result {ds['result_bytes']} B; "
          f"network {a.bandwidth_mb_s:g} MB/s (assumed)")
    for r in pr:
        print(f"  {r['machines']:>2} machine(s), {r['workers']:>3} workers: {r['total_s'] / 60:8.1f} min "
              f"({r['rounds']} rounds, {r['bound']}-bound; "
              f"results {r['result_transfer_s']:.1f} s on the wire)")

    with open(os.path.join(OUT, "batch.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["section", "key", "value"])
        for r in tp:
            for k, v in r.items():
                w.writerow(["throughput", f"workers{r['workers']}.{k}", v])
        w.writerow(["throughput", "speedup_2_workers", speedup])
        for kind, rows in ov.items():
            for i, r in enumerate(rows):
                for k, v in r.items():
                    w.writerow(["overhead", f"{kind}{i}.{k}", v])
        for k, v in ds.items():
            w.writerow(["data", k, v])
        w.writerow(["projection", "review_frame_s", frame_s])
        for r in pr:
            for k, v in r.items():
                w.writerow(["projection", f"machines{r['machines']}.{k}", v])
    chart(ov, pr)
    print(f"wrote {OUT}/batch.csv and batch.png")
    print(f"batch_speedup_2_workers={speedup:.2f}")
    return 0


def chart(ov, pr) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    pts = [(r["task_s"], 100 * r["overhead_fraction"]) for r in ov["sleep"] if r["task_s"] > 0]
    left.plot(*zip(*pts), "o-", label="sleep tasks")
    frames = [(r["local_s"], max(100 * r["overhead_s"] / r["dask_s"], 0.1)) for r in ov["frame"]]
    left.plot(*zip(*frames), "s", label="frame tasks (noisy; <= 0 drawn at 0.1 %)")
    left.set_xscale("log")
    left.set_yscale("log")
    left.set_xlabel("task length (s)")
    left.set_ylabel("Dask overhead (% of task time)")
    left.set_title("scheduling overhead per task")
    left.legend(fontsize=8)
    bars = right.bar([str(r["machines"]) for r in pr], [r["total_s"] / 60 for r in pr])
    right.bar_label(bars, labels=[f"{r['total_s'] / 60:.1f} min" for r in pr], fontsize=8)
    right.set_yscale("log")
    right.set_xlabel("machines")
    right.set_ylabel("minutes (projected)")
    right.set_title(f"{REVIEW_FRAMES} frames x {REVIEW_VARIANTS} variants")
    fig.savefig(os.path.join(OUT, "batch.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
