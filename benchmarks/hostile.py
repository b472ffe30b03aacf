"""Hostile inputs at their limits (issue 11): how long the engine takes to refuse or to accept them.

Usage::

    python -m benchmarks.hostile [--slow]

Prints one row per case and writes ``benchmarks/out/hostile.csv``. The suite's tests assert only
outcomes, counts and memory; the timings of the largest inputs live here: the JSON that hung
the loader, projects and DXF drawings of the largest section allowed (and beyond it), the
largest bottle allowed, an
archive that declares far more than it holds, a save (with its read-back check), environment
decoding on a render restart, and the ray tree at the ray-weight cut-offs (``--slow`` adds
``min_weight = 1e-6``, below the allowed range: about three minutes). Times are untraced; peak
memory (where shown) is the Python allocator's peak over a second run (``tracemalloc``, which
numpy reports to).
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import math
import os
import tempfile
import time
import tracemalloc

from tests.test_project_fuzz import zip_bytes  # the suite's own builders: the same inputs, full size

OUT = os.path.join(os.path.dirname(__file__), "out")


def measure(fn, memory: bool):
    """``(seconds, peak MB or None, result or refusal text)``: timed untraced, then (``memory``)
    run again under ``tracemalloc`` for the peak, since tracing slows Python-heavy code."""
    def run():
        try:
            return fn()
        except Exception as exc:  # why: a refusal is the expected result of most cases
            return f"refused: {type(exc).__name__}: {str(exc)[:90]}"
    t0 = time.perf_counter()
    result = run()
    secs = time.perf_counter() - t0
    peak = None
    if memory:
        tracemalloc.start()
        run()
        peak = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.stop()
    return secs, peak, result


def section_project(folder, n, kind="round"):
    from engine.files.project import save_project
    from engine.model.design import Design
    from tests.test_resources import polyline_shape
    path = os.path.join(folder, f"{kind}{n}.glassbench")
    save_project(path, Design(polyline_shape(n, kind)), {})
    return path


def dxf_of_lines(folder, n):
    import ezdxf
    doc = ezdxf.new(units=4)
    msp = doc.modelspace()
    msp.add_line((0, 0), (30, 0))
    for k in range(n - 2):
        msp.add_line((30 + math.sin(k / n), 100 * k / n), (30 + math.sin((k + 1) / n), 100 * (k + 1) / n))
    msp.add_line((30 + math.sin((n - 2) / n), 100 * (n - 2) / n), (30 + math.sin((n - 2) / n), 120))
    path = os.path.join(folder, f"lines{n}.dxf")
    doc.saveas(path)
    return path


def largest_bottle():
    """2 m tall, 2 m across: base, heel, body, a 900 mm shoulder arc, neck (the extent limit)."""
    from engine.geometry.section import Section
    from engine.geometry.segments import Arc, Line
    from engine.geometry.shape import BottleShape
    segs = (Line((0, 0), (950, 0)), Arc((950, 50), 50, (950, 0), (1000, 50), "ccw"),
            Line((1000, 50), (1000, 1000)), Arc((100, 1000), 900, (1000, 1000), (100, 1900), "ccw"),
            Line((100, 1900), (100, 2000)))
    return BottleShape("round", (("profile", Section(segs, (False, True, True, False))),), 5.0, 10.0)


def ray_tree(depth, weight):
    from app.sample_design import built_in_design
    from engine.model.design import RenderSettings
    from engine.tracer.job import RenderJob
    from engine.tracer.sampling import Sampling
    design = dataclasses.replace(built_in_design(), render=RenderSettings(8, 8, 1, depth, weight))
    job = RenderJob(design, threads=1, sampling=Sampling(adaptive=False)).start()
    job.wait()
    return f"{job.stats.rays_cast / 64:.0f} rays per pixel"


def cases(folder, slow):
    from engine.files.dxf_import import section_from_dxf
    from engine.files.project import load_project, load_project_bytes, save_project
    from engine.files.serialize import document_from_design
    from engine.geometry.tessellate import tessellate_body
    from engine.model.design import Design, Environment
    from engine.tracer.tables.environment import environment_from_design
    from tests.test_resources import polyline_shape

    quotes = zip_bytes([("project.json", '{"design": "' + '\\"' * 60_000)])
    yield "60,000 escaped quotes (hung before)", lambda: load_project_bytes(quotes), True
    big = zip_bytes([("project.json", '{"design": "' + '\\"' * (7 << 20))])
    yield "16 MiB of escaped quotes", lambda: load_project_bytes(big), True
    for kind in ("round", "rounded_square"):
        path = section_project(folder, 1024, kind)
        yield f"load a {kind} project of 1,024 segments", lambda p=path: load_project(p) and "loaded", True
        shape = polyline_shape(1024, kind)
        yield ("tessellate it at 0.02 mm (the tracer's mesh)",
               lambda s=shape: f"{len(tessellate_body(s, 0.02).faces)} faces", True)
    tall = largest_bottle()
    yield ("tessellate a 2 m bottle (the extent limit) at 0.02 mm",
           lambda: f"{len(tessellate_body(tall, 0.02).faces)} faces", True)
    for n in (1024, 4000, 20_000):
        path = dxf_of_lines(folder, n)
        yield f"DXF of {n:,} lines", lambda p=path: f"{len(section_from_dxf(p).segments)} segments", False
    doc = json.dumps(document_from_design(Design(polyline_shape(4))))
    bomb = zip_bytes([("project.json", doc)] + [(f"assets/a{i}.exr", b"\0" * (255 << 20)) for i in range(4)])
    yield f"{len(bomb) / 1e6:.1f} MB archive declaring 4 x 255 MB", lambda: load_project_bytes(bomb), True
    from app.sample_design import built_in_design
    target = os.path.join(folder, "sample.glassbench")
    yield ("save the Bordeaux sample (with read-back)",
           lambda: save_project(target, built_in_design(), {}) or "saved", False)
    env_path = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "oracle", "env", "studio.exr")
    if os.path.exists(env_path):
        data = open(env_path, "rb").read()
        env = Environment("file", "studio.exr", 1.0, 0.0)
        yield ("environment image, first render",
               lambda: environment_from_design(env, {"studio.exr": data}) and "decoded", False)
        yield ("environment image, render restart",
               lambda: environment_from_design(env, {"studio.exr": data}) and "cached", False)
    for depth, weight in ((64, 1e-3), (256, 1e-5)) + (((1024, 1e-6),) if slow else ()):
        yield (f"8 x 8 render of the sample, depth {depth}, min_weight {weight:g}",
               lambda d=depth, w=weight: ray_tree(d, w), False)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.hostile")
    p.add_argument("--slow", action="store_true", help="also the 1e-6 ray-weight cut-off (minutes)")
    a = p.parse_args(argv)
    os.makedirs(OUT, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, fn, memory in cases(folder, a.slow):
            secs, peak, result = measure(fn, memory)
            shown = "" if peak is None else f"{peak:.0f}"
            rows.append((name, f"{secs:.3f}", shown, result))
            print(f"{name:<58} {secs:8.3f} s {shown:>6} MB  {result}", flush=True)
    with open(os.path.join(OUT, "hostile.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "seconds", "peak_mb", "result"])
        w.writerows(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
