"""The window benchmark's reading of the preview's error on the way to converged."""
import math

import numpy as np
import pytest

from benchmarks.window_converge import own_error, progress_errors, time_within


def test_the_other_render_s_own_error_is_taken_out_in_quadrature():
    seen = [(0.1, 5.0), (0.5, math.hypot(3.0, 1.0)), (2.0, 1.0), (3.0, 0.8)]
    got = progress_errors(seen, 1.0)
    assert [t for t, _ in got] == [0.1, 0.5, 2.0, 3.0]
    assert math.isclose(got[0][1], math.sqrt(24.0))
    assert math.isclose(got[1][1], 3.0)
    assert got[2][1] == 0.0 and got[3][1] == 0.0  # a distance below the other's error is its noise


def test_the_time_within_a_bound_is_where_the_error_stays_below_it():
    progress = [(0.1, 9.0), (0.4, 2.5), (0.9, 3.2), (1.5, 1.4), (3.0, 0.9)]
    assert time_within(progress, 3.0) == 1.5  # under 3 at 0.4 s, above again at 0.9 s
    assert time_within(progress, 1.5) == 1.5
    assert time_within(progress, 10.0) == 0.1
    assert time_within(progress, 0.5) is None
    assert time_within([], 1.0) is None


def test_a_render_s_progress_falls_to_its_own_error():
    """On a real design at a small size: one point per wave, in time order, the error after the
    first wave (a coarse preview) far above the last, which is the render's own error (the
    distance of two converged renders on independent samples, over sqrt 2)."""
    from benchmarks.window_converge import render
    from engine.files.project import load_project

    design, assets = load_project("resources/jar.glassbench")
    job, _ = render(design, assets, 60, 80, 2)
    rms, p99, progress = own_error(design, assets, 60, 80, 2, job.image(), "split")
    times = [t for t, _ in progress]
    assert len(progress) >= 3 and times == sorted(times) and times[0] >= 0.0
    assert progress[0][1] > 4.0 * rms
    assert math.isclose(progress[-1][1], rms, rel_tol=1e-6)
    assert np.isfinite(p99) and p99 >= 0.0


def test_a_render_past_the_limit_is_cancelled_and_its_sample_counts_as_never_converged(monkeypatch, capsys):
    """The benchmark ends on every sample: a render still running at ``--limit`` is cancelled
    (its worker stops) and the sample is named, with inf in the figure line, while the others
    keep their figures."""
    import benchmarks.window_converge as wc
    from engine.files.project import load_project

    from engine.tracer.job import RenderJob

    design, assets = load_project("resources/flacon.glassbench")
    monkeypatch.setattr(wc, "LIMIT_S", 0.05)
    jobs, start = [], RenderJob.start
    monkeypatch.setattr(RenderJob, "start", lambda self: jobs.append(self) or start(self))
    with pytest.raises(wc.NotConverged) as caught:  # (a flacon at 120 x 160 takes seconds)
        wc.render(design, assets, 120, 160, 2)
    assert caught.value.seconds == 0.05 and str(caught.value) == "120x160 render not converged within 0 s"
    assert len(jobs) == 1 and jobs[0].cancelled and jobs[0].wait(0)  # stopped, not left running
    rows = [{"sample": "jar", "policy": "split", "seconds": 2.0, "ready_s": 1.0, "first_s": 0.1}]
    wc.print_summary(rows, ["split"], ["flacon"])
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last == ("window_first_worst=0.10 window_ready_worst=inf window_ready_median=inf "
                    "window_converge_worst=inf window_converge_median=inf")
