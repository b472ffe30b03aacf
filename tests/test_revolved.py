"""Rays against revolved section segments, checked against a brute-force sampling reference."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from engine.intersect import (ray_cone_hits, rays_touching_bounds, revolved_hits,
                              revolved_normals, segment_bounds, stable_quadratic_roots)
from engine.geometry.segments import Arc, EllipseArc, Line, normal

ROOT375 = math.sqrt(375.0)
SEGMENTS = {
    "cone": Line((30.0, 0.0), (20.0, 40.0)),
    "cylinder": Line((30.0, 0.0), (30.0, 40.0)),
    "disc": Line((0.0, 0.0), (30.0, 0.0)),
    "annulus_inward": Line((30.0, 40.0), (10.0, 40.0)),
    "shoulder_arc": Arc((20.0, 40.0), 10.0, (30.0, 40.0), (20.0, 50.0), "ccw"),
    "concave_arc": Arc((40.0, 60.0), 10.0, (30.0, 60.0), (40.0, 70.0), "cw"),
    "dome_on_axis": Arc((0.0, 50.0), 50.0, (0.0, 0.0), (30.0, 10.0), "ccw"),
    "spindle_arc": Arc((5.0, 40.0), 20.0, (0.0, 40.0 - ROOT375), (25.0, 40.0), "ccw"),
    "behind_axis_arc": Arc((-5.0, 40.0), 20.0, (0.0, 40.0 - ROOT375), (15.0, 40.0), "ccw"),
    "ellipse_dome": EllipseArc((0.0, 40.0), 30.0, 10.0, (30.0, 40.0), (0.0, 50.0), "ccw"),
    "ellipse_shoulder": EllipseArc((20.0, 40.0), 10.0, 25.0, (30.0, 40.0), (20.0, 65.0), "ccw"),
    "ellipse_concave": EllipseArc((40.0, 40.0), 10.0, 20.0, (30.0, 40.0), (40.0, 60.0), "cw"),
}
SEGMENTS["offset_dome"] = SEGMENTS["ellipse_dome"].offset(3.0)
SEGMENTS["offset_shoulder"] = SEGMENTS["ellipse_shoulder"].offset(2.5)
SEGMENTS["offset_concave"] = SEGMENTS["ellipse_concave"].offset(2.0)


def _random_rays(seg, rng, n):
    """Rays from a shell around the segment, aimed at random points near its surface."""
    rmin, rmax, zmin, zmax = segment_bounds(seg)
    t = rng.uniform(0, 1, n)
    q = seg.point(t)
    theta = rng.uniform(0, 2 * np.pi, n)
    target = np.column_stack([q[:, 0] * np.cos(theta), q[:, 0] * np.sin(theta), q[:, 1]])
    target += rng.normal(scale=0.5, size=target.shape)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    start = target - d * rng.uniform(60, 120, n)[:, None]
    return start, d


def _brute_hits(o, d, seg, smax=250.0, samples=12001, curve_points=6001):
    """Hits by sampling: sign changes of the signed distance to a dense meridian polyline.

    Returns (hits, ambiguous): ``ambiguous`` flags rays that come within 0.05 mm of the
    surface away from a clean crossing, or cross twice within 0.5 mm (grazing rays), where
    sampling cannot decide.
    """
    poly = seg.point(np.linspace(0, 1, curve_points))
    chords = np.diff(poly, axis=0)
    clen = np.hypot(*chords.T)
    tang = chords / clen[:, None]
    s = np.linspace(0.0, smax, samples)
    step = s[1] - s[0]
    p = o[:, None, :] + s[None, :, None] * d[:, None, :]
    m = np.stack([np.hypot(p[..., 0], p[..., 1]), p[..., 2]], axis=-1).reshape(-1, 2)
    # only samples within 1 mm of the curve can take part in a crossing
    _, k = cKDTree(poly).query(m, distance_upper_bound=1.0)
    close = k < len(poly)
    best_sd = np.full(m.shape[0], np.inf)
    best_abs = np.full(m.shape[0], np.inf)
    interior = np.zeros(m.shape[0], bool)
    for j in (k - 1, k):
        j = np.where(close, j, 0)
        j = np.clip(j, 0, len(chords) - 1)
        rel = m - poly[j]
        u = np.einsum("ij,ij->i", rel, tang[j]) / clen[j]
        foot = poly[j] + np.clip(u, 0, 1)[:, None] * chords[j]
        dist = np.hypot(*(m - foot).T)
        sd = np.sign(rel[:, 0] * tang[j][:, 1] - rel[:, 1] * tang[j][:, 0]) * dist
        better = (dist < best_abs) & close
        best_abs = np.where(better, dist, best_abs)
        best_sd = np.where(better, sd, best_sd)
        inside = ((u >= 0) | (j > 0)) & ((u <= 1) | (j < len(chords) - 1))
        interior = np.where(better, inside, interior)
    best_sd, best_abs, interior = (a.reshape(len(o), samples) for a in (best_sd, best_abs, interior))
    hits, ambiguous = [], []
    window = int(0.5 / step)
    for sd, ab, inn in zip(best_sd, best_abs, interior):
        cross = (np.sign(sd[:-1]) != np.sign(sd[1:])) & inn[:-1] & inn[1:] & (ab[:-1] + ab[1:] <= 2.01 * step)
        i = np.nonzero(cross)[0]
        hits.append(s[i] + sd[i] / (sd[i] - sd[i + 1]) * step)
        away = np.ones(samples, bool)
        for c in i:
            away[max(c - window, 0): c + window + 2] = False
        grazing = bool(np.any(away & inn & (ab < 0.05)))
        ambiguous.append(grazing or (i.size > 1 and np.min(np.diff(i)) < window))
    return hits, ambiguous


@pytest.mark.parametrize("name", list(SEGMENTS))
def test_hits_match_brute_force_sampling(name):
    seg = SEGMENTS[name]
    rng = np.random.default_rng(sorted(SEGMENTS).index(name))
    o, d = _random_rays(seg, rng, 60)
    got = revolved_hits(o, d, seg)
    ref, ambiguous = _brute_hits(o, d, seg)
    checked = 0
    for i in range(len(o)):
        if ambiguous[i]:
            continue
        mine = got[i][np.isfinite(got[i])]
        assert mine.size == ref[i].size, (name, i, mine, ref[i])
        assert np.allclose(mine, ref[i], atol=2e-3), (name, i, mine, ref[i])
        checked += 1
    assert checked >= 45
    assert sum(r.size for r in ref) >= 30  # the rays really do hit


@pytest.mark.parametrize("name", list(SEGMENTS))
def test_hits_lie_on_the_segment_and_normals_are_exact(name):
    seg = SEGMENTS[name]
    rng = np.random.default_rng(11)
    o, d = _random_rays(seg, rng, 200)
    hits = revolved_hits(o, d, seg)
    assert np.array_equal(np.sort(hits, axis=1), hits, equal_nan=True)
    ok = np.isfinite(hits)
    pts = (o[:, None, :] + hits[..., None] * d[:, None, :])[ok]
    m = np.column_stack([np.hypot(pts[:, 0], pts[:, 1]), pts[:, 2]])
    dense = seg.point(np.linspace(0, 1, 200001))  # vertex spacing < 1e-3 mm
    dist, _ = cKDTree(dense).query(m)
    assert dist.max() < 1e-3
    # analytic normals against the segment's own normal at known parameters
    t = rng.uniform(0, 1, 300)
    theta = rng.uniform(0, 2 * np.pi, 300)
    q = seg.point(t)
    world = np.column_stack([q[:, 0] * np.cos(theta), q[:, 0] * np.sin(theta), q[:, 1]])
    n2 = normal(seg, t)
    expected = np.column_stack([n2[:, 0] * np.cos(theta), n2[:, 0] * np.sin(theta), n2[:, 1]])
    got = revolved_normals(world, seg)
    assert np.allclose(np.linalg.norm(got, axis=1), 1.0, atol=1e-12)
    assert np.abs(got - expected).max() < 1e-9


@pytest.mark.parametrize("name", list(SEGMENTS))
def test_bounds_hold_the_segment_and_culling_keeps_every_hitting_ray(name):
    seg = SEGMENTS[name]
    rmin, rmax, zmin, zmax = segment_bounds(seg)
    q = seg.point(np.linspace(0, 1, 5001))
    assert q[:, 0].min() >= rmin - 1e-9 and q[:, 0].max() <= rmax + 1e-9
    assert q[:, 1].min() >= zmin - 1e-9 and q[:, 1].max() <= zmax + 1e-9
    rng = np.random.default_rng(4)
    o = rng.uniform(-150, 150, size=(2000, 3))
    d = rng.normal(size=(2000, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    hits = revolved_hits(o, d, seg)
    mask = rays_touching_bounds(o, d, (rmin, rmax, zmin, zmax))
    assert np.all(mask[np.isfinite(hits[:, 0])])
    assert mask.mean() < 0.9  # it does cull


def test_secondary_rays_leaving_a_surface_do_not_rehit_at_start():
    rng = np.random.default_rng(8)
    for seg in SEGMENTS.values():
        t = rng.uniform(0.05, 0.95, 100)
        theta = rng.uniform(0, 2 * np.pi, 100)
        q = seg.point(t)
        p = np.column_stack([q[:, 0] * np.cos(theta), q[:, 0] * np.sin(theta), q[:, 1]])
        n = revolved_normals(p, seg)
        d = rng.normal(size=(100, 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        d = np.where(np.einsum("ij,ij->i", d, n)[:, None] > 0, d, -d)  # leaving outwards
        d = _unit_rows(d + 0.2 * n)
        hits = revolved_hits(p, d, seg)
        assert np.all(np.isnan(hits) | (hits > 1e-6)), type(seg).__name__


def _unit_rows(v):
    return v / np.linalg.norm(v, axis=1)[:, None]


def test_axis_rays_hit_the_axis_end_of_a_section():
    down = np.array([[0.0, 0.0, -1.0]])
    top = np.array([[0.0, 0.0, 200.0]])
    for name in ("disc", "dome_on_axis", "spindle_arc", "behind_axis_arc", "ellipse_dome",
                 "offset_dome"):
        seg = SEGMENTS[name]
        end = seg.p0 if abs(seg.p0[0]) < 1e-9 else seg.p1
        hits = revolved_hits(top, down, seg)[0]
        assert np.isclose(hits[0], 200.0 - end[1], atol=1e-9), (name, hits)


def test_cone_and_quadratic_edge_cases():
    r = stable_quadratic_roots(np.array([1.0, 0.0, 1.0]), np.array([-3.0, 2.0, 0.0]),
                               np.array([2.0, -4.0, 1.0]))
    # t^2 - 6t + 2 = 0 -> 3 -+ sqrt 7 ; 4t - 4 = 0 -> 1 ; t^2 + 1 = 0 -> none
    assert np.allclose(r[0], [3 - math.sqrt(7), 3 + math.sqrt(7)], rtol=1e-15)
    assert r[1, 0] == 1.0 and np.isnan(r[1, 1]) and np.all(np.isnan(r[2]))
    # a far-away ray keeps its digits: cylinder of radius 1 seen from 1e7 mm
    far = ray_cone_hits(np.array([[1e7, 0.3, 0.5]]), np.array([[-1.0, 0, 0]]), 1, 0, 1, 1)
    assert np.allclose(far[0], [1e7 - math.sqrt(1 - 0.09), 1e7 + math.sqrt(1 - 0.09)], rtol=0, atol=1e-8)
    with pytest.raises(ValueError):
        ray_cone_hits(np.zeros((1, 3)), np.array([[0, 0, 1.0]]), 1, 1, 1, 1)


@pytest.mark.parametrize("name", ["offset_dome", "offset_concave"])
def test_offset_arc_hits_are_exact_and_no_pair_hides_between_samples(name, monkeypatch):
    import engine.intersect.offset_arc as offset_arc
    from engine.intersect import offset_arc_parameter

    seg = SEGMENTS[name]
    rng = np.random.default_rng(21)
    o, d = _random_rays(seg, rng, 4000)
    coarse = revolved_hits(o, d, seg)
    ok = np.isfinite(coarse)
    pts = (o[:, None, :] + coarse[..., None] * d[:, None, :])[ok]
    m = np.column_stack([np.hypot(pts[:, 0], pts[:, 1]), pts[:, 2]])
    foot = seg.point(offset_arc_parameter(m, seg))
    assert np.hypot(*(m - foot).T).max() < 1e-8  # on the offset curve to 10 nm
    # 16x finer sampling finds exactly the same hits (pairs a step apart included)
    monkeypatch.setattr(offset_arc, "_OFFSET_SAMPLES", 1024)
    offset_arc._offset_grid.cache_clear()
    try:
        fine = revolved_hits(o, d, seg)
    finally:
        offset_arc._offset_grid.cache_clear()
    assert np.array_equal(np.isfinite(fine), ok)
    assert np.nanmax(np.abs(fine - coarse)) < 1e-8
