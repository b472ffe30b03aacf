"""The peer benchmark's reading of glassbench's time-against-error curve."""
import math

from benchmarks.peer import fastest_runs, pareto_front, time_to_reach

POINTS = [(1.0, 0.08), (4.0, 0.02), (3.0, 0.05), (16.0, 0.01), (20.0, 0.012)]


def test_the_front_keeps_only_points_no_other_beats():
    assert pareto_front(POINTS) == [(1.0, 0.08), (3.0, 0.05), (4.0, 0.02), (16.0, 0.01)]


def test_time_is_interpolated_in_log_log_between_bracketing_points():
    t = time_to_reach(POINTS, math.sqrt(0.02 * 0.01))  # halfway in log error
    assert math.isclose(t, math.sqrt(4.0 * 16.0), rel_tol=1e-12)
    assert time_to_reach(POINTS, 0.02) == 4.0
    assert time_to_reach(POINTS, 0.5) == 1.0  # the fastest point already reaches it


def test_an_error_below_the_best_point_is_never_reached():
    assert time_to_reach(POINTS, 0.009) == math.inf
    assert time_to_reach([], 0.1) == math.inf


def test_repeated_runs_keep_each_settings_fastest():
    first = [("AA 4", 0.9, 0.02, 1.5), ("AA 16", 2.0, 0.01, 3.5)]
    second = [("AA 4", 0.7, 0.02, 1.5), ("AA 16", 2.4, 0.01, 3.5)]
    assert fastest_runs([first, second]) == [("AA 4", 0.7, 0.02, 1.5), ("AA 16", 2.0, 0.01, 3.5)]
    assert fastest_runs([first]) == first


def test_glassbench_points_time_each_wave_of_each_setting():
    """Every setting gives its finished render and its image after each earlier wave, timed
    from the same start: the progressive points come before the finished one, with more
    samples each, and a draft's cut is passed to the render (fewer segments, another image)."""
    import dataclasses

    import numpy as np

    from benchmarks.oracle_render import render_spec
    from benchmarks.oracle_spec import spec_to_design
    from benchmarks.paths import ORACLE_SPECS
    from benchmarks.peer import glassbench_points
    from engine.tracer.sampling import Sampling

    spec = str(ORACLE_SPECS / "public_1.json")
    design, assets = spec_to_design(spec)
    design = dataclasses.replace(design, render=dataclasses.replace(design.render, width=40, height=40))
    scene = (design, assets)
    ref = render_spec(spec, 16, 1, sampling=Sampling(noise_target=0.01), scene=scene)[0]
    settings = (("AA 4 adaptive 0.1", 4, 0.1, None), ("draft", 4, 0.1, 0.05))
    points, progressive = glassbench_points(spec, ref, settings, 1, scene=scene)
    assert [p[0] for p in points] == ["AA 4 adaptive 0.1", "draft"]
    for label, secs, err, mean in points:
        waves = [p for p in progressive if p[0].startswith(label + " after wave ")]
        assert [p[0] for p in waves] == [f"{label} after wave {k}" for k in range(len(waves))]
        assert len(waves) >= 3  # preview, centres, anti-aliasing, then the adaptive rounds
        times, means = [p[1] for p in waves] + [secs], [p[3] for p in waves] + [mean]
        assert times == sorted(times) and means == sorted(means) and means[1] == 1.0
        assert all(np.isfinite(p[2]) and p[2] > 0 for p in waves) and 0 < err < waves[0][2]
    assert points[0][2] != points[1][2]  # the draft's cut changed the image
