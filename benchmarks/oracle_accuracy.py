"""Accuracy does not move backwards: glassbench's converged render of every oracle scene against its reference.

Usage::

    python -m benchmarks.oracle_accuracy [--scenes public_1,...,public_4,thick_jar] [--threads 2]

Design rule: one setting, glassbench's most converged one in the peer benchmark (``CONVERGED``:
16 anti-aliasing samples on edges, adaptive rounds to a 0.002 noise target, the oracle renders'
tree cut-offs), renders each scene once; its rel RMSE (SPEC 7) against the reference is printed
per scene with the reference's own noise, and last ``oracle_worst=X`` (the largest, as a
fraction; issue 26's target is <= 0.01). The public scenes' references are the oracle's; the thick
jar of :mod:`benchmarks.thick_jar` (7 mm wall, 12 mm base, seen from above) is checked against
Mitsuba's own 16384-spp render of it, made once and cached in ``benchmarks/out/oracle/refs``: there
glassbench and Mitsuba, two independent implementations of SPEC, check each other.
"""
from __future__ import annotations

import argparse

from benchmarks import thick_jar
from benchmarks.peer_check import PUBLIC, reference, spec_path

#: ``(label, anti-aliasing samples, noise target, tree cut)``: :data:`benchmarks.peer.GLASSBENCH_SETTINGS`' last.
CONVERGED = ("adaptive 0.002", 16, 0.002, None)


def accuracy(name: str, threads: int = 2) -> tuple[float, float, float]:
    """``(rel RMSE, seconds, reference noise)`` of glassbench's converged render of a scene."""
    from benchmarks.oracle_render import rel_rmse, render_setting

    ref, noise = reference(name)
    spec = spec_path(name)
    render_setting(spec, ("warm-up", 1, None, None), threads)  # kernels loaded, scene compiled
    img, secs, _ = render_setting(spec, CONVERGED, threads)
    return rel_rmse(img, ref), secs, noise


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.oracle_accuracy")
    p.add_argument("--scenes", default=",".join((*PUBLIC, thick_jar.NAME)))
    p.add_argument("--threads", type=int, default=2)
    a = p.parse_args(argv)
    worst = 0.0
    for name in a.scenes.split(","):
        err, secs, noise = accuracy(name, a.threads)
        worst = max(worst, err)
        print(f"{name}: rel RMSE {100 * err:.2f} % ({CONVERGED[0]}, {secs:.1f} s; the reference's own noise "
              f"{100 * noise:.2f} %)")
    print(f"oracle_worst={worst:.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
