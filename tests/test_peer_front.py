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
