"""Benchmark: does the wireframe follow a section drag without stalling the editor?

Drives a real window (the bundled sample, wireframe on, preview rendering unless
``--no-render``) through a paced drag of a joint, one event per frame (60 Hz), and reports:

* GUI-thread time per drag event: what the editor blocks for between two mouse moves (command,
  validation, scene notification, panel refreshes, trade numbers, render restart, wireframe
  request); a frame is 16.7 ms;
* edit-to-wireframe latency: from an edit's request to its wireframe shown (uploaded and
  rendered), for the edits that were shown (newer ones supersede older ones);
* the latency of the final edit after the drag stops, and how many uploads the drag caused.

Run: ``xvfb-run -a .venv/bin/python -m benchmarks.wireframe [--events 120] [--no-render]``;
prints a summary and writes the per-event times to ``benchmarks/out/wireframe.csv``.
"""
from __future__ import annotations

import argparse
import csv
import os
import statistics
import sys
import time


def _percentile(values, q):
    values = sorted(values)
    if not values:
        return float("nan")
    k = min(len(values) - 1, max(0, int(round(q * (len(values) - 1)))))
    return values[k]


def _pump(app, until: float):
    """Run the event loop until the wall clock reaches ``until`` (the rest of a frame)."""
    from PySide6.QtCore import QEventLoop
    while True:
        left_ms = int((until - time.perf_counter()) * 1000)
        if left_ms <= 0:
            app.processEvents()
            return
        app.processEvents(QEventLoop.AllEvents, left_ms)
        if time.perf_counter() < until:
            time.sleep(min(0.001, max(0.0, until - time.perf_counter())))


def run(events: int, render: bool, frame_s: float = 1 / 60) -> dict:
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    from app.sample_design import sample_design
    from app.window import MainWindow
    from widgets.section_editor import Handle

    app = QApplication.instance() or QApplication(sys.argv[:1])
    design, assets, _ = sample_design()
    settings = QSettings("/tmp/glassbench-bench.ini", QSettings.IniFormat)
    w = MainWindow(design, assets, None, settings=settings, wireframe=True, autosave_ms=0)
    w.resize(1500, 950)
    w.show()
    ctrl = w.wireframe_controller
    if not render:
        w.render_controller.shutdown()
        w.render_controller.start = lambda *a, **k: None
    deadline = time.perf_counter() + 120

    def settled():  # wireframe shown and, when rendering, the tracer past its setup
        return ctrl.is_idle() and (not render or w.preview.tiles_painted > 0)
    while not settled() and time.perf_counter() < deadline:
        _pump(app, time.perf_counter() + 0.01)
    ctrl.latencies_s.clear()
    uploads0 = w.wireframe.uploads

    sec = w.scene.design.shape.primary
    joint = 2 if len(sec.segments) > 3 else len(sec.segments) - 2
    canvas = w.section_panel.canvas
    canvas.begin_drag(Handle("joint", joint, sec.segments[joint].p1), "bench-drag")
    gui_ms = []
    for k in range(events):
        frame_end = time.perf_counter() + frame_s
        dz = 10.0 * (k + 1) / events  # a slow 10 mm stretch of the body
        t0 = time.perf_counter()
        canvas.drag_to((0.0, dz))
        gui_ms.append((time.perf_counter() - t0) * 1000)
        _pump(app, frame_end)
    canvas.end_drag()
    t_last = time.perf_counter()
    while not ctrl.is_idle() and time.perf_counter() < t_last + 30:
        _pump(app, time.perf_counter() + 0.002)
    final_ms = (time.perf_counter() - t_last) * 1000
    lat_ms = [x * 1000 for x in ctrl.latencies_s]
    result = {
        "events": events, "render": render,
        "gui_ms_median": statistics.median(gui_ms), "gui_ms_p95": _percentile(gui_ms, 0.95),
        "gui_ms_max": max(gui_ms),
        "latency_ms_median": statistics.median(lat_ms) if lat_ms else float("nan"),
        "latency_ms_p95": _percentile(lat_ms, 0.95), "final_edit_ms": final_ms,
        "uploads": w.wireframe.uploads - uploads0, "upload_ms_last": w.wireframe.last_upload_s * 1000,
        "undo_steps": w.undo_stack.count(), "gui_ms": gui_ms, "latency_ms": lat_ms,
    }
    w.undo_stack.setClean()
    w.close()
    return result


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--events", type=int, default=120)
    p.add_argument("--no-render", action="store_true", help="keep the preview tracer idle")
    args = p.parse_args(argv)
    r = run(args.events, not args.no_render)
    print(f"drag of {r['events']} events at 60 Hz, preview rendering: {r['render']}")
    print(f"GUI-thread time per drag event: median {r['gui_ms_median']:.1f} ms, "
          f"p95 {r['gui_ms_p95']:.1f} ms, max {r['gui_ms_max']:.1f} ms")
    print(f"edit-to-wireframe latency: median {r['latency_ms_median']:.0f} ms, "
          f"p95 {r['latency_ms_p95']:.0f} ms; final edit shown {r['final_edit_ms']:.0f} ms after release")
    print(f"wireframe uploads during the drag: {r['uploads']} (last upload {r['upload_ms_last']:.1f} ms); "
          f"undo steps: {r['undo_steps']}")
    out = os.path.join(os.path.dirname(__file__), "out")
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, "wireframe.csv")
    with open(path, "w", newline="") as f:
        rows = csv.writer(f)
        rows.writerow(["event", "gui_ms", "latency_ms_of_shown_edit"])
        for k, ms in enumerate(r["gui_ms"]):
            lat = r["latency_ms"][k] if k < len(r["latency_ms"]) else ""
            rows.writerow([k, f"{ms:.3f}", f"{lat:.3f}" if lat != "" else ""])
    print(f"per-event times: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
