"""The oracle renders' tree cut-offs (``benchmarks.oracle_render``) against a tree traced to the end.

A branch lighter than ``min_weight`` is closed with the environment along its direction, which is
not what lies behind the glass: on the clear flacon of outline_public_1 the closures at
``min_weight = 2e-3`` dropped every ghost reflected twice inside a wall (about 0.04^2 = 1.6e-3) and
took 0.3-0.6 % of the light out of every row of the body (0.39 % of this strip, 0.33 % summed over
the bottle, 0.2 % rel RMSE of the image), a bias that no number of samples removes. The check
traces the same sample positions (no Russian roulette) at the oracle's cut-offs and at depth 1024,
weight 1e-6, on a strip of the body where the loss was largest.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from benchmarks.oracle_render import ORACLE_MAX_DEPTH, ORACLE_MIN_WEIGHT
from benchmarks.oracle_spec import spec_to_design
from benchmarks.paths import ORACLE_SPECS
from engine.tracer.context import RenderContext, trace_pixels


def _strip_radiance(max_depth: int, min_weight: float, cols, rows, samples: int = 2) -> np.ndarray:
    """Mean radiance ``(P, 3)`` of anti-aliasing samples ``1..samples`` of pixels ``(cols, rows)``
    of outline_public_1 with the given tree cut-offs (no roulette: the whole tree above them)."""
    design, assets = spec_to_design(ORACLE_SPECS / "outline_public_1.json")
    render = dataclasses.replace(design.render, max_depth=max_depth, min_weight=min_weight)
    design = dataclasses.replace(design, render=render)
    ctx = RenderContext.from_design(design, assets, render.width, render.height)
    return trace_pixels(ctx, cols, rows, 1, samples).sums / samples


def test_the_oracle_cut_offs_keep_the_light_of_the_flacons_body():
    rows, cols = (a.ravel() for a in np.mgrid[112:176:4, 70:190:4])
    deep = _strip_radiance(1024, 1e-6, cols, rows)
    on = deep.sum(axis=1) > 0
    assert on.sum() > 300  # (the strip crosses the bottle: its pixels' trees met glass)
    cut = _strip_radiance(ORACLE_MAX_DEPTH, ORACLE_MIN_WEIGHT, cols, rows)
    lost = 1.0 - cut[on].sum() / deep[on].sum()
    rms = np.sqrt(np.sum((cut[on] - deep[on]) ** 2) / np.sum(deep[on] ** 2))
    assert abs(lost) < 1e-3, f"the cut-offs lose {100 * lost:.3f} % of the light"
    assert rms < 1e-3, f"the cut-offs move the strip by {100 * rms:.3f} % rel RMS"
