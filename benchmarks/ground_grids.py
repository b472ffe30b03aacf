"""Ground grids benchmark: the sky, sweep and caustic grids' settings, time against error.

Usage::

    python -m benchmarks.ground_grids [--width 715] [--height 953] [--threads 2] [--quick]

The tabled Bordeaux (``resources/bordeaux_table.glassbench``) with and without its backdrop: for
each setting of the grids' knobs (:mod:`engine.tracer.tables.sky`, :mod:`~engine.tracer.tables.caustics`)
the grids are built from nothing (their time, the fastest of two builds) and the design is
rendered at the window's size with its pixel centres alone (one fixed ray per pixel: the images
differ by the grids alone). The error is the distance, in display levels RMS and 99th percentile,
to the same render with a reference grid of many more probes (photons) and no Russian roulette:
the engine's own method converged, against which each setting's noise and cell size show. (The
sky grid against the ground's per-hit probe, an independent method, is
``tests/test_sky_grid.py``'s check.) Writes ``benchmarks/out/ground_grids.csv`` and
``ground_grids.png`` (time against error per grid); prints one line per setting and last
``ground_grid_seconds=S ground_grid_levels=L`` (the engine's settings: the grids' time on the
tabled Bordeaux and their error there).
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

#: ``(grid, label, {module constant: value})``: the settings measured; ``{}`` is the engine's.
SKY = "sky"
CAUSTICS = "caustics"
SETTINGS = (
    (SKY, "engine", {}),
    (SKY, "no roulette", {"ROULETTE": 0.0}),
    (SKY, "roulette 0.05", {"ROULETTE": 0.05}),
    (SKY, "roulette 0.5", {"ROULETTE": 0.5}),
    (SKY, "roulette 1", {"ROULETTE": 1.0}),
    (SKY, "12 cells a radius", {"CELLS_PER_RADIUS": 12}),
    (SKY, "2 batches at most", {"MAX_BATCHES": 2}),
    (CAUSTICS, "engine", {}),
    (CAUSTICS, "32 photons a cell", {"PHOTONS_PER_CELL": 32}),
    (CAUSTICS, "16 cells a radius", {"CELLS_PER_RADIUS": 16}),
)
QUICK = ("engine", "no roulette")
#: The reference grids' settings (many more probes and photons, no roulette).
REFERENCE = {SKY: {"PROBES_SIDE": 16, "OUTER_PROBES_SIDE": 8, "MAX_BATCHES": 8, "SE_TOL": 0.004, "ROULETTE": 0.0},
             CAUSTICS: {"PHOTONS_PER_CELL": 512}}


def _module(grid):
    from engine.tracer.tables import caustics, sky, sweep
    return (sky, sweep) if grid == SKY else (caustics,)


def _with(grid, values):
    """Set ``values`` on the grid's modules; returns what they were."""
    old = {}
    for mod in _module(grid):
        for k, v in values.items():
            if hasattr(mod, k):
                old[(mod, k)] = getattr(mod, k)
                setattr(mod, k, v)
    return old


def _restore(old):
    for (mod, k), v in old.items():
        setattr(mod, k, v)


def _grids_seconds(design, assets, w, h) -> dict:
    """``{grid: seconds}``: the time to build ``design``'s ground grids from nothing, per grid
    (the sky grid's with the backdrop's sweep grid)."""
    from engine.tracer import context
    from engine.tracer.context import RenderContext
    from engine.tracer.tables.stage import clear_stage_caches

    spent = {SKY: 0.0, CAUSTICS: 0.0}
    names = {"stage_sky": SKY, "stage_sweep": SKY, "stage_caustics": CAUSTICS}
    saved = {n: getattr(context, n) for n in names}

    def timed(name):
        def call(*args, **kw):
            t0 = time.perf_counter()
            try:
                return saved[name](*args, **kw)
            finally:
                spent[names[name]] += time.perf_counter() - t0
        return call

    clear_stage_caches()
    for n in names:
        setattr(context, n, timed(n))
    try:
        RenderContext.from_design(design, assets, w, h)
    finally:
        for n, fn in saved.items():
            setattr(context, n, fn)
    return spent


def centres(design, assets, w, h, threads):
    """Display levels ``(h, w, 3)`` of ``design`` rendered with its pixel centres alone, with the
    ground grids of the modules' current settings (built now, timed apart)."""
    from benchmarks.window_converge import levels, render, window_sampling
    job, _ = render(design, assets, w, h, threads, window_sampling(adaptive=False), spp=1)
    return levels(job.image())


def measure(design, assets, grid, values, w, h, threads, ref):
    """``(seconds, levels RMS, p99)`` of one setting: grids' build (the faster of two) and the
    centres' distance to ``ref``."""
    old = _with(grid, values)
    try:
        secs = min(_grids_seconds(design, assets, w, h)[grid] for _ in range(2))
        img = centres(design, assets, w, h, threads)
    finally:
        _restore(old)
    d = np.abs(img - ref).mean(axis=2)
    return secs, float(np.sqrt((d ** 2).mean())), float(np.percentile(d, 99))


def chart(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5))
    for (scene, grid), marker in zip(sorted({(r[0], r[1]) for r in rows}), "osD^v"):
        pts = [r for r in rows if (r[0], r[1]) == (scene, grid)]
        ax.scatter([r[3] for r in pts], [r[4] for r in pts], marker=marker, label=f"{scene}: {grid} grid")
        for r in pts:
            ax.annotate(r[2], (r[3], r[4]), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("grids' build (s, 2 threads)")
    ax.set_ylabel("display levels RMS against the reference grid")
    ax.set_title("Ground grids on the tabled Bordeaux, 715 x 953 centres: time against error")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.ground_grids")
    p.add_argument("--width", type=int, default=715)
    p.add_argument("--height", type=int, default=953)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--quick", action="store_true", help="the engine's settings and no roulette only")
    a = p.parse_args(argv)
    from engine.files.project import load_project
    from engine.tracer.tables.stage import clear_stage_caches
    from engine.tracer.warmup import warm_up

    warm_up()
    design, assets = load_project(os.path.join(REPO, "resources", "bordeaux_table.glassbench"))
    scenes = {"table": design,
              "table with backdrop": dataclasses.replace(design, stage=dataclasses.replace(design.stage, backdrop=True))}
    rows = []
    for scene, d in scenes.items():
        for grid in (SKY, CAUSTICS):
            if grid == CAUSTICS and scene != "table":
                continue  # (the backdrop does not change the photons' grid)
            old = _with(grid, REFERENCE[grid])
            try:
                clear_stage_caches()
                ref = centres(d, assets, a.width, a.height, a.threads)
            finally:
                _restore(old)
            for g, label, values in SETTINGS:
                if g != grid or (a.quick and label not in QUICK):
                    continue
                secs, rms, p99 = measure(d, assets, grid, values, a.width, a.height, a.threads, ref)
                rows.append((scene, grid, label, secs, rms, p99))
                print(f"{scene:20s} {grid:8s} {label:20s} {secs:6.2f} s  {rms:.3f} levels RMS  p99 {p99:.2f}",
                      flush=True)
            clear_stage_caches()
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "ground_grids.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "grid", "setting", "seconds", "levels_rms", "levels_p99"])
        w.writerows(rows)
    chart(rows, os.path.join(OUT, "ground_grids.png"))
    engine = [r for r in rows if r[0] == "table" and r[2] == "engine"]
    secs = sum(r[3] for r in engine)
    rms = float(np.sqrt(sum(r[4] ** 2 for r in engine)))
    print(f"wrote {os.path.join(OUT, 'ground_grids.csv')} and ground_grids.png")
    print(f"ground_grid_seconds={secs:.2f} ground_grid_levels={rms:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
