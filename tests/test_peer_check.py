"""The peer's convergence check (benchmarks.peer_check) and the benchmark's refusal, on made-up numbers."""
from __future__ import annotations

import math

import pytest

from benchmarks import peer, peer_check


def row(errors, noise=0.003, spps=peer_check.CHECK_SPPS):
    return {"spp": list(spps), "rel_rmse": list(errors), "seconds": [1.0] * len(spps), "noise_ref": noise}


def converging(e64, noise=0.003):
    """Errors of a scene that converges: e64 at 64 spp falling as 1/sqrt(spp), the reference's
    noise added in quadrature."""
    return [math.hypot(e64 * math.sqrt(64 / s), noise) for s in peer_check.CHECK_SPPS]


def test_the_verdict_passes_only_scenes_within_the_limit_at_4096_spp():
    good = {n: row(converging(0.04)) for n in peer_check.PUBLIC}
    assert peer_check.verdict(good) == []
    biased = dict(good, public_4=row([0.045, 0.027, 0.0205, 0.0201]))  # levels off at 2 %
    assert peer_check.verdict(biased)[0] == "public_4 at 4096 spp is 2.01 % rel RMSE from its reference (limit 0.8 %)"
    missing = {n: r for n, r in good.items() if n != "public_2"}
    assert peer_check.verdict(missing) == ["public_2 was not checked at 4096 spp"]
    short = dict(good, public_1=row([0.04, 0.02, 0.01], spps=(64, 256, 1024)))
    assert peer_check.verdict(short) == ["public_1 was not checked at 4096 spp"]
    assert len(peer_check.verdict(dict(good, public_3=row([0.04, 0.02, 0.01, float("nan")])))) >= 1


def test_a_bias_under_the_limit_is_refused_by_its_slope():
    """The old flat 0.005 mm scene (2.05 % at 4096 spp) fails both ways; a bias small enough to
    pass 0.8 % still shows as a flattening error, on any checked scene (a ground scene too)."""
    good = {n: row(converging(0.04)) for n in peer_check.PUBLIC}
    old = dict(good, public_1=row([0.045, 0.0284, 0.0221, 0.0205], noise=0.0025))
    assert len(peer_check.verdict(old)) == 2 and "spp^-0.19" in peer_check.verdict(old)[1]
    flat = dict(good, ground_public_1=row([0.03, 0.012, 0.0085, 0.0079], noise=0.003))
    assert peer_check.verdict(flat) == ["ground_public_1's error above its reference's noise falls as spp^-0.33, "
                                        "slower than spp^-0.4: a bias"]
    assert peer_check.verdict(dict(good, ground_public_1=row(converging(0.06, 0.0053), noise=0.0053))) == []


def test_the_slope_is_minus_a_half_above_the_reference_noise_and_flat_for_a_bias():
    spps = peer_check.CHECK_SPPS
    assert peer_check.slope(spps, [0.04 * math.sqrt(64 / s) for s in spps]) == pytest.approx(-0.5)
    assert peer_check.slope(spps, converging(0.04), 0.003) == pytest.approx(-0.5)
    assert -0.48 < peer_check.slope(spps, converging(0.04)) < -0.45  # the noise floor flattens the raw slope
    assert peer_check.slope(spps, [0.045, 0.027, 0.0215, 0.0205], 0.003) > -0.3


def test_the_check_renders_one_image_in_chunks_of_the_counts():
    assert peer_check.chunks((64, 256, 1024, 4096)) == [64, 192, 768, 3072]


def test_the_benchmark_refuses_to_print_a_ratio_when_the_peer_does_not_converge(monkeypatch, capsys):
    table = {n: row(converging(0.04)) for n in peer_check.PUBLIC}
    table["public_1"] = row([0.045, 0.028, 0.022, 0.0205])
    monkeypatch.setattr(peer, "mitsuba_available", lambda: None)
    monkeypatch.setattr(peer_check, "check", lambda names, force=False: table)
    assert peer.main(["--scenes", "public_1"]) != 0
    out = capsys.readouterr().out
    assert "public_1 at 4096 spp is 2.05 %" in out and "no ratio printed" in out
    assert "peer_speedup_min" not in out and "faster" not in out


def test_peer_speedup_min_is_over_the_public_scenes_at_256_and_1024_spp():
    speed = {"public_1": {64: 2.0, 256: 9.0, 1024: 12.0}, "public_2": {64: 1.5, 256: 8.5, 1024: 30.0},
             "thick_jar": {256: 1.0, 1024: 1.0}, "labelled": {256: 0.5}}
    assert peer.speedup_min(speed) == 8.5
    assert math.isnan(peer.speedup_min({"labelled": {256: 3.0}}))


def test_an_error_glassbench_never_reaches_is_a_zero_ratio_shown_as_such():
    g_pts = [(0.5, 0.05), (4.0, 0.014)]
    mt = [(64, 1.7, 0.05), (1024, 24.0, 0.0125)]  # the thick jar's 1024 spp: below glassbench's best
    assert peer.speedups(g_pts, mt) == [(64, 1.7 / 0.5), (1024, 0.0)]
    assert peer.shown_ratio(0.0) == "not reached" and peer.shown_ratio(3.4) == "3.4x"


def test_ground_speedup_is_the_smallest_ground_ratio_at_mitsubas_largest_sample_count():
    speed = {"ground_public_1": {64: 3.0, 256: 9.0, 1024: 14.5}, "ground_x": {64: 2.0, 1024: 11.0},
             "public_1": {1024: 1.0}}
    assert peer.ground_speedup(speed, ["ground_public_1", "ground_x"]) == 11.0
    assert peer.ground_speedup(speed, ["ground_public_1"]) == 14.5
    assert math.isnan(peer.ground_speedup(speed, ["ground_missing"]))


def test_a_spec_may_ask_for_exact_vertex_normals_and_the_thick_jar_does(tmp_path):
    """Flat facets are the public references' scene; the thick jar's reference carries exact
    vertex normals (flat ones moved its checker's edges through 7 mm of glass), so Mitsuba's
    renders of it must too; an explicit conversion still wins."""
    import json

    from benchmarks import peer_scene, thick_jar

    flat, smooth = tmp_path / "flat.json", tmp_path / "smooth.json"
    flat.write_text(json.dumps({"render": {"tessellation": {"max_turn_deg": 0.2}}}))
    smooth.write_text(json.dumps({"render": {"tessellation": {"max_turn_deg": 0.2, "vertex_normals": True}}}))
    assert peer_scene.spec_conversion(str(flat)) == peer_scene.CONVERSION
    assert peer_scene.spec_conversion(str(smooth))["vertex_normals"] is True
    assert peer_scene.spec_conversion(str(smooth), {"vertex_normals": False})["vertex_normals"] is False
    assert peer_scene.spec_conversion(thick_jar.spec_path())["vertex_normals"] is True
