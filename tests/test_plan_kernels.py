"""The kernels' free plan outlines (engine.tracer.kernels.plans) against brute force.

The oracle: the section's boundary sampled densely (arcs every 2e-5 rad) as a polygon; the
signed distance of a point is its distance to that polygon, negative inside, less ``r``. Where
``r < 0`` the section is the outline eroded, which the same signed distance describes.
"""
from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

from engine.tracer.kernels.outlines import rrect_sd
from engine.tracer.kernels.plans import (PL_ENDS, PL_HLOW, PL_KIND, ROUND, plan_directions, plan_interval,
                                         plan_support_low, plan_trace, plan_value)
from engine.tracer.tables.plans import plan_table

ORACLE = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "oracle", "specs")


def _normalised(segments):
    """SPEC_outline's normalisation: every coordinate over R, the farthest point's distance."""
    r = 0.0
    for s in segments:
        r = max(r, np.hypot(*s["p0"]), np.hypot(*s["p1"]))
        if s["type"] == "arc":
            c = np.asarray(s["center"], float)
            a0 = math.atan2(s["p0"][1] - c[1], s["p0"][0] - c[0])
            a1 = math.atan2(s["p1"][1] - c[1], s["p1"][0] - c[0])
            a1 += 2 * math.pi if a1 <= a0 else 0.0
            ac = math.atan2(c[1], c[0]) if np.hypot(*c) > 0 else a0
            if any(a0 <= ac + 2 * math.pi * j <= a1 for j in (-1, 0, 1)) or np.hypot(*c) == 0:
                r = max(r, np.hypot(*c) + s["radius"])
    out = []
    for s in segments:
        t = dict(s, p0=[v / r for v in s["p0"]], p1=[v / r for v in s["p1"]])
        if s["type"] == "arc":
            t.update(center=[v / r for v in s["center"]], radius=s["radius"] / r)
        out.append(t)
    return out


def _spec_outline(name):
    with open(os.path.join(ORACLE, f"{name}.json")) as fh:
        return _normalised(json.load(fh)["bottle"]["cross_section"]["outline"])


def _rounded_square_outline(corner=0.2):
    """A square of half side ``a`` with corners of radius ``corner`` (lines and quarter arcs)."""
    h = 1.0  # half side
    c = corner
    pts = [((h, -h + c), (h, h - c), (h - c, h - c)), ((h - c, h), (-h + c, h), (-h + c, h - c)),
           ((-h, h - c), (-h, -h + c), (-h + c, -h + c)), ((-h + c, -h), (h - c, -h), (h - c, -h + c))]
    segs = []
    for k, (p0, p1, centre) in enumerate(pts):
        segs.append({"type": "line", "p0": p0, "p1": p1})
        nxt = pts[(k + 1) % 4][0]
        segs.append({"type": "arc", "center": centre, "radius": c, "p0": p1, "p1": nxt, "ccw": True})
    return _normalised(segs)


OUTLINES = {
    "hexagon": lambda: _spec_outline("outline_public_1"),
    "flask": lambda: _spec_outline("outline_public_2"),
    "rounded_square": _rounded_square_outline,
    "triangle": lambda: _normalised([{"type": "line", "p0": [math.cos(a), math.sin(a)],
                                      "p1": [math.cos(a + 2 * math.pi / 3), math.sin(a + 2 * math.pi / 3)]}
                                     for a in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)]),
}


def _polygon(segments, k, step=2e-5):
    """The boundary of ``k P``, densely sampled (ccw, closed)."""
    pts = []
    for s in segments:
        if s["type"] == "line":
            pts.append(np.asarray(s["p0"], float))
        else:
            c = np.asarray(s["center"], float)
            a0 = math.atan2(s["p0"][1] - c[1], s["p0"][0] - c[0])
            a1 = math.atan2(s["p1"][1] - c[1], s["p1"][0] - c[0])
            a1 += 2 * math.pi if a1 <= a0 else 0.0
            a = np.linspace(a0, a1, max(2, int((a1 - a0) / step)), endpoint=False)
            pts.extend(c + s["radius"] * np.stack([np.cos(a), np.sin(a)], 1))
    return k * np.array(pts)


def _brute_sd(poly, x, y):
    """Signed distance of ``(x, y)`` to the convex polygon ``poly`` (ccw)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    e = b - a
    p = np.array([x, y])
    t = np.clip(((p - a) * e).sum(1) / (e * e).sum(1), 0.0, 1.0)
    d = np.min(np.hypot(*(a + t[:, None] * e - p).T))
    inside = np.all(e[:, 0] * (p[1] - a[:, 1]) - e[:, 1] * (p[0] - a[:, 0]) >= 0.0)
    return -d if inside else d


@pytest.mark.parametrize("name", sorted(OUTLINES))
def test_the_section_value_is_the_signed_distance_inside_and_out(name):
    segments = OUTLINES[name]()
    plan = plan_table(segments)
    rng = np.random.default_rng(7)
    for k in (0.0, 1.0, 30.0):
        poly = _polygon(segments, k) if k > 0 else None
        for _ in range(60):
            x, y = rng.uniform(-1.6, 1.6, 2) * max(k, 1.0)
            r = rng.uniform(-0.2, 0.3) * max(k, 1.0) if k > 0 else rng.uniform(0.1, 2.0)
            f, gx, gy, dk = plan_value(plan, k, r, x, y)
            want = (_brute_sd(poly, x, y) if k > 0 else math.hypot(x, y)) - r
            assert f == pytest.approx(want, abs=1e-6 * max(k, 1.0)), (k, r, x, y)
            assert math.hypot(gx, gy) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("name", sorted(OUTLINES))
def test_the_value_falls_with_the_core_and_its_derivative_is_the_support_value(name):
    plan = plan_table(OUTLINES[name]())
    rng = np.random.default_rng(3)
    for _ in range(100):
        k, r = rng.uniform(5.0, 40.0), rng.uniform(-2.0, 5.0)
        x, y = rng.uniform(-60.0, 60.0, 2)
        f, _, _, dk = plan_value(plan, k, r, x, y)
        h = 1e-6
        fd = (plan_value(plan, k + h, r, x, y)[0] - plan_value(plan, k - h, r, x, y)[0]) / (2 * h)
        assert dk < 0.0
        assert dk == pytest.approx(fd, abs=1e-5)


def test_the_rounded_square_of_the_first_spec_is_a_special_case():
    # SPEC_outline 4: P the square of circumradius 1, k = sqrt2 p, c = q: the rounded square
    # of half width u = p + q and corner radius q
    square = _normalised([{"type": "line", "p0": p0, "p1": p1} for p0, p1 in
                          (((1, -1), (1, 1)), ((1, 1), (-1, 1)), ((-1, 1), (-1, -1)), ((-1, -1), (1, -1)))])
    plan = plan_table(square)
    rng = np.random.default_rng(11)
    for _ in range(200):
        p, q = rng.uniform(1.0, 30.0), rng.uniform(0.1, 10.0)
        x, y = rng.uniform(-50.0, 50.0, 2)
        f = plan_value(plan, math.sqrt(2.0) * p, q, x, y)[0]
        assert f == pytest.approx(rrect_sd(x, y, p + q, p + q, q)[0], abs=1e-12 * 50)


@pytest.mark.parametrize("name", sorted(OUTLINES))
def test_a_lines_interval_is_where_the_value_is_not_positive(name):
    plan = plan_table(OUTLINES[name]())
    rng = np.random.default_rng(5)
    hits = misses = 0
    for _ in range(300):
        k, r = rng.uniform(5.0, 40.0), rng.uniform(-1.5, 6.0)
        p = rng.uniform(-80.0, 80.0, 2)
        a = rng.uniform(0.0, 2 * math.pi)
        q = np.array([math.cos(a), math.sin(a)]) * rng.uniform(0.3, 3.0)
        t0, t1 = plan_interval(plan, k, r, p[0], p[1], q[0], q[1])
        ts = np.linspace(-200.0, 200.0, 4001)
        vals = np.array([plan_value(plan, k, r, *(p + t * q))[0] for t in ts])
        if t0 > t1:
            misses += 1
            assert vals.min() > -1e-9, "a line the interval calls a miss enters the section"
            continue
        hits += 1
        for t in (t0, t1):
            assert abs(plan_value(plan, k, r, *(p + t * q))[0]) < 1e-9 * max(k, 1.0) * 10
        inside = ts[vals <= 0.0]
        assert inside.min() >= t0 - 0.2 and inside.max() <= t1 + 0.2
        assert plan_value(plan, k, r, *(p + 0.5 * (t0 + t1) * q))[0] < 0.0
    assert hits > 50 and misses > 50


def test_a_point_is_inside_or_not():
    plan = plan_table(OUTLINES["hexagon"]())
    assert plan_interval(plan, 30.0, 2.0, 0.0, 0.0, 0.0, 0.0) == (-np.inf, np.inf)
    lo, hi = plan_interval(plan, 30.0, 2.0, 40.0, 0.0, 0.0, 0.0)
    assert lo > hi


@pytest.mark.parametrize("name", sorted(OUTLINES))
def test_a_rays_trace_through_a_ruled_slab_is_where_the_section_at_its_height_holds_it(name):
    # core and growth linear in the ray parameter (a ruled slab: planes and slanted cones);
    # the growth may change sign on the way (sharp inner corners turning round)
    from engine.tracer.kernels.plans import plan_trace
    plan = plan_table(OUTLINES[name]())
    rng = np.random.default_rng(9)
    hits = misses = 0
    for _ in range(200):
        k0, k1 = rng.uniform(10.0, 40.0), rng.uniform(-0.1, 0.1)
        r0, r1 = rng.uniform(-2.0, 6.0), rng.uniform(-0.08, 0.08)
        p = rng.uniform(-80.0, 80.0, 2)
        a = rng.uniform(0.0, 2 * math.pi)
        q = np.array([math.cos(a), math.sin(a)]) * rng.uniform(0.2, 2.0)
        t0, t1 = plan_trace(plan, (k0, k1), (r0, r1), (p[0], p[1], q[0], q[1]))
        ts = np.linspace(-150.0, 150.0, 3001)
        ts = ts[k0 + k1 * ts > 0.0]  # (a slab's core is never negative)
        vals = np.array([plan_value(plan, k0 + k1 * t, r0 + r1 * t, *(p + t * q))[0] for t in ts])
        inside = ts[vals <= 0.0]
        within = ts[(ts >= t0) & (ts <= t1)]
        if len(inside) == 0 and len(within) == 0:
            misses += 1
            continue
        hits += 1
        assert len(inside) and inside.min() >= t0 - 0.2 and inside.max() <= t1 + 0.2
        assert np.all(vals[(ts >= t0) & (ts <= t1)] <= 1e-9), "the trace holds only points of the sections"
        for t in (t0, t1):
            if ts[0] < t < ts[-1]:
                assert abs(plan_value(plan, k0 + k1 * t, r0 + r1 * t, *(p + t * q))[0]) < 1e-8
    assert hits > 30 and misses > 30


@pytest.mark.parametrize("name", sorted(OUTLINES))
def test_skipping_a_wedges_end_normals_between_two_lines_changes_nothing(name):
    """``PL_ENDS = 0`` lets the kernels skip a corner's end normals (its lines' own): the value,
    gradient and traces equal those of the same table with every end evaluated."""
    plan = plan_table(OUTLINES[name]())
    full = plan.copy()
    full[:, PL_ENDS] = np.where(full[:, PL_KIND] == ROUND, 1.0, 0.0)
    rng = np.random.default_rng(11)
    for _ in range(300):
        k, r = rng.uniform(0.5, 40.0), rng.uniform(-3.0, 5.0)
        x, y, qx, qy = rng.uniform(-60.0, 60.0, 4)
        assert plan_value(plan, k, r, x, y) == pytest.approx(plan_value(full, k, r, x, y), abs=1e-12)
        core, grow, foot = (k, rng.uniform(-0.2, 0.2)), (r, rng.uniform(-0.1, 0.1)), (x, y, qx, qy)
        assert plan_trace(plan, core, grow, foot) == pytest.approx(plan_trace(full, core, grow, foot), abs=1e-9)


def test_a_corner_between_two_lines_skips_its_end_normals_and_an_arc_after_an_arc_does_not():
    hexagon = plan_table(OUTLINES["hexagon"]())
    assert np.all(hexagon[hexagon[:, PL_KIND] == ROUND, PL_ENDS] == 0.0)
    flask = plan_table(OUTLINES["flask"]())
    rows = flask[flask[:, PL_KIND] == ROUND]
    assert np.any(rows[:, PL_ENDS] == 1.0)


@pytest.mark.parametrize("name", sorted(OUTLINES))
def test_three_cores_directions_in_one_pass_are_three_values_gradients(name):
    """plan_directions (the certificate's three cores in one pass over the pieces) gives, bit
    for bit, the gradients of three plan_value calls at growth 0: at random points, on the axis,
    at a corner's scaled vertex (where a wedge's own direction is undefined and its ends
    decide), with equal cores and a zero core; and PL_HLOW is the plan's support low bound."""
    plan = plan_table(OUTLINES[name]())
    assert np.all(plan[:, PL_HLOW] == plan_support_low(plan)) and 0.0 < plan[0, PL_HLOW] <= 1.0
    rng = np.random.default_rng(17)
    rounds = plan[plan[:, PL_KIND] == ROUND]
    points = [tuple(rng.uniform(-60.0, 60.0, 2)) for _ in range(400)] + [(0.0, 0.0)]
    points += [(10.0 * row[4], 10.0 * row[5]) for row in rounds]  # PL_CX, PL_CY at k = 10
    for x, y in points:
        for ks in (tuple(rng.uniform(0.0, 40.0, 3)), (10.0, 10.0, 10.0), (0.0, 10.0, 5.0), (10.0, 30.0, 20.0)):
            got = plan_directions(plan, *ks, x, y)
            want = sum((plan_value(plan, k, 0.0, x, y)[1:3] for k in ks), ())
            assert got == want, (x, y, ks)
