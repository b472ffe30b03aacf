"""The tracer against the independent Mitsuba references (SPEC section 7 metric, <= 2 %)."""
from __future__ import annotations

import numpy as np
import pytest

from benchmarks.oracle_render import reference_path, rel_rmse, render_spec
from engine.tracer.sampling import Sampling
from engine.tracer.tables.environment import read_radiance_image
from benchmarks.paths import ORACLE_SPECS

SPECS = str(ORACLE_SPECS)


@pytest.mark.parametrize("name", ["public_1", "public_2", "public_3", "public_4"])
def test_public_scene_matches_its_reference_within_two_percent(name):
    spec = f"{SPECS}/{name}.json"
    # A looser adaptive target than the oracle default keeps the test quick (measured ~1.2 % worst).
    img, secs, job = render_spec(spec, threads=2, sampling=Sampling(noise_target=0.03))
    ref = read_radiance_image(reference_path(spec))
    assert img.shape == ref.shape == (256, 256, 3)
    assert np.all(np.isfinite(img)) and img.min() >= 0
    err = rel_rmse(img, ref)
    print(f"{name}: rel RMSE {err:.4f} in {secs:.1f} s, mean {job.sample_counts().mean():.1f} spp")
    assert err <= 0.02
    # No light may leak out of a medium through the tessellation.
    assert job.stats.escaped_inside == 0


def test_rel_rmse_is_the_spec_metric():
    ref = np.zeros((2, 2, 3))
    ref[0, 0] = [1, 1, 1]
    ref[1, 1] = [0, 0, 2]
    img = ref.copy()
    img[0, 0, 0] = 1.5
    img[0, 1] = 9.0  # ignored: the reference is zero there
    assert abs(rel_rmse(img, ref) - np.sqrt(0.25 / 7.0)) < 1e-15


def test_measuring_smooth_pixels_on_the_bottle_finds_the_detail_the_edge_test_misses(monkeypatch):
    """Public_3 (a rounded-square flask with liquid): caustics inside pixels whose neighbouring
    centres agree. Without the measurement their centres stood for them (1.09 % rel RMSE at 4
    samples, tolerance 0.01); with it 0.92 %. Renders are deterministic: the margin is fixed."""
    from engine.tracer import adaptive

    spec = f"{SPECS}/public_3.json"
    ref = read_radiance_image(reference_path(spec))
    err = {}
    for measure in (0, adaptive.MEASURE_AA):
        monkeypatch.setattr(adaptive, "MEASURE_AA", measure)
        img, _, _ = render_spec(spec, threads=2, spp=4, sampling=Sampling(noise_target=0.01), min_weight=0.01)
        err[measure] = rel_rmse(img, ref)
    assert err[adaptive.MEASURE_AA] < err[0] - 0.001
