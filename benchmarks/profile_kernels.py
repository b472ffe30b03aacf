"""Where a frame's time goes, per compiled kernel: ``perf`` with a map of the kernels' code.

Usage::

    python -m benchmarks.profile_kernels [--scene bordeaux] [--seconds 8] [--top 25]
                                         [--counts COUNTS.npy --min-samples 256]

numba's machine code is not in any file ``perf`` can read, so its samples come out as bare
addresses. This renders the scene's frame (160 x 160, 2 samples per pixel, one thread) in a
loop, writes ``/tmp/perf-PID.map`` (the address and size of every function compiled into
the render kernel's library, which ``perf`` reads for code it cannot otherwise name), and
runs ``perf record`` on the loop, then prints ``perf report``'s table of self time per
function. The kernels are compiled into a fresh cache folder first (about a minute): a
library loaded from numba's disk cache keeps no module to list its functions from.

With ``--counts`` (an ``(H, W)`` array of samples per pixel, e.g. a window render's
``film.samples()``) it traces instead every fourth pixel of that size that took at least
``--min-samples`` samples, 8 anti-aliasing samples each with the adaptive rounds' roulette:
where the window's last rounds spend their time (thick bases, shoulders), not a frame's average.

Kernels marked ``inline="always"`` are counted in their callers. Needs ``perf`` (Debian's
``linux-perf``) and permission to record a process (``perf_event_paranoid`` <= 2 for one's
own processes). Writes ``benchmarks/out/profile_SCENE.txt``; prints last
``top_kernel=NAME share=X``.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_MANGLED = re.compile(r"_ZN6engine6tracer7kernels\d+([a-z_]+)\d+([A-Za-z_][A-Za-z_0-9]*?)B\d")


def _short(symbol: str) -> str:
    """``module.function`` of a numba-mangled kernel name (other symbols unchanged)."""
    m = _MANGLED.search(symbol)
    return f"{m.group(1)}.{m.group(2)}" if m else symbol


def write_perf_map(library, path: str) -> int:
    """Write ``perf``'s map of every function defined in a numba code ``library`` to ``path``
    (``START SIZE NAME`` in hex, a function's size reaching the next one's start); returns
    how many functions it lists."""
    engine = library._codegen._engine
    entries = []
    for fn in library._final_module.functions:
        if fn.is_declaration:
            continue
        addr = engine.get_function_address(fn.name)
        if addr:
            entries.append((addr, _short(fn.name)))
    entries.sort()
    with open(path, "w") as fh:
        for (start, name), nxt in zip(entries, entries[1:] + [(entries[-1][0] + 65536, "")]):
            fh.write(f"{start:x} {max(16, min(nxt[0] - start, 1 << 22)):x} {name}\n")
    return len(entries)


def frame_loop(scene: str, seconds: float, ready: str, counts: str | None = None, min_samples: int = 256) -> None:
    """Render ``scene``'s frame in a loop for ``seconds`` after writing the perf map and the
    file ``ready`` (which holds this process's id); with ``counts`` only its heavy pixels
    (module doc)."""
    import numpy as np

    from benchmarks.tracer import load_scene
    from engine.tracer.adaptive import SPLIT_ROULETTE
    from engine.tracer.context import RenderContext, trace_pixels
    from engine.tracer.kernels.tile import render_pixels

    design, assets = load_scene(scene)
    if counts is None:
        ctx = RenderContext.from_design(design, assets, 160, 160)
        ys, xs = np.mgrid[0:160, 0:160]
        xs, ys, spp, roulette = xs.ravel(), ys.ravel(), 2, 0.0
    else:
        c = np.load(counts)
        ctx = RenderContext.from_design(design, assets, c.shape[1], c.shape[0])
        ys, xs = np.nonzero(c >= min_samples)
        xs, ys, spp, roulette = xs[::4], ys[::4], 8, SPLIT_ROULETTE
        if len(xs) == 0:
            raise SystemExit(f"no pixel of {counts} took {min_samples} samples")
    trace_pixels(ctx, xs, ys, 1, spp, roulette=roulette)  # compiled
    count = sum(write_perf_map(c.library, f"/tmp/perf-{os.getpid()}.map") for c in render_pixels.overloads.values())
    print(f"{count} functions mapped", flush=True)
    with open(ready, "w") as fh:
        fh.write(str(os.getpid()))
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        trace_pixels(ctx, xs, ys, 1, spp, roulette=roulette)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.profile_kernels")
    p.add_argument("--scene", default="bordeaux", help="a bundled sample (resources/NAME.glassbench) or public_1..4")
    p.add_argument("--seconds", type=float, default=8.0, help="recording time")
    p.add_argument("--top", type=int, default=25, help="rows of the table")
    p.add_argument("--counts", default=None, help="samples per pixel (.npy): profile only the heavy pixels")
    p.add_argument("--min-samples", type=int, default=256, help="with --counts: the heavy pixels' least samples")
    p.add_argument("--loop", default=None, help=argparse.SUPPRESS)  # the child: its ready file
    a = p.parse_args(argv)
    if a.loop:
        frame_loop(a.scene, a.seconds + 30.0, a.loop, a.counts, a.min_samples)
        return 0
    if shutil.which("perf") is None:
        raise SystemExit("benchmarks.profile_kernels needs perf (apt-get install linux-perf)")
    os.makedirs(OUT, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        ready = os.path.join(tmp, "ready")
        env = dict(os.environ, GLASSBENCH_KERNEL_CACHE=os.path.join(tmp, "kernels"), PYTHONPATH=ROOT)
        heavy = ["--counts", os.path.abspath(a.counts), "--min-samples", str(a.min_samples)] if a.counts else []
        child = subprocess.Popen([sys.executable, "-m", "benchmarks.profile_kernels", "--scene", a.scene,
                                  "--seconds", str(a.seconds), "--loop", ready, *heavy], cwd=ROOT, env=env)
        try:
            while not os.path.exists(ready):
                if child.poll() is not None:
                    raise SystemExit("the frame loop ended before it was ready")
                time.sleep(0.5)
            pid = open(ready).read().strip()
            data = os.path.join(tmp, "perf.data")
            subprocess.run(["perf", "record", "-F", "2000", "-p", pid, "-o", data, "--", "sleep", str(a.seconds)],
                           check=True, capture_output=True)
            report = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", "sym", "--stdio"],
                                    check=True, capture_output=True, text=True).stdout
        finally:
            child.kill()
            child.wait()
            for f in (f"/tmp/perf-{child.pid}.map",):
                if os.path.exists(f):
                    os.remove(f)
    rows = []
    for line in report.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+\[[.k]\]\s+(\S+)", line)
        if m:
            rows.append((float(m.group(1)), _short(m.group(2))))
    rows = rows[:a.top]
    text = "\n".join(f"{share:6.2f} %  {name}" for share, name in rows)
    what = (f"pixels of {os.path.basename(a.counts)} with >= {a.min_samples} samples (8 spp, roulette)"
            if a.counts else "frame (160x160, 2 spp)")
    print(f"self time per function, {a.scene} {what}, 1 thread:\n{text}")
    with open(os.path.join(OUT, f"profile_{a.scene}.txt"), "w") as fh:
        fh.write(text + "\n")
    if not rows:
        raise SystemExit("perf recorded no samples")
    print(f"top_kernel={rows[0][1]} share={rows[0][0] / 100:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
