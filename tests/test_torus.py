"""Ray / torus intersection: the shared hard cases and seeded hard cases with 50-digit references."""
from __future__ import annotations

import json
import math
from collections import defaultdict

import mpmath as mp
import numpy as np
import pytest

from engine.intersect import ray_torus_hits
from benchmarks.paths import QUARTIC_CASES

CASES = QUARTIC_CASES
TOL_TUBE = 1e-6  # largest accepted error, in tube radii


def _first_hit(case):
    hits = ray_torus_hits(np.array([case["origin"]]), np.array([case["direction"]]),
                          case["R"], case["a"], case["b"], tmin=case["tau"])[0]
    hits = hits[np.isfinite(hits)]
    return float(hits[0]) if hits.size else None


def _first_hit_kernel(case):
    """The tracer's compiled solver, the one every arc of a render goes through."""
    from engine.tracer.kernels.records import Ray
    from engine.tracer.kernels.roots import torus_roots

    out, crit = np.zeros(4), np.zeros(5)
    n = torus_roots(Ray(*case["origin"], *case["direction"]), case["R"], case["a"], case["b"], False,
                    case["tau"], out, crit)
    return float(out[0]) if n else None


@pytest.mark.parametrize("first_hit", [_first_hit, _first_hit_kernel], ids=["numpy", "tracer kernel"])
def test_public_cases_have_no_miss_no_false_hit_and_tiny_error_per_category(first_hit):
    data = json.loads(CASES.read_text())
    stats = defaultdict(lambda: {"n": 0, "miss": 0, "false": 0, "err": 0.0})
    for case in data["cases"]:
        st = stats[case["category"]]
        st["n"] += 1
        acc = case["ref_exact"]["accept"]
        t = first_hit(case)
        accepted = [x for x in (acc["t_strict"], acc["t_next"]) if x is not None] + acc["graze"]
        if t is None:
            st["miss"] += acc["t_next"] is not None
        elif not accepted:
            st["false"] += 1
        else:
            st["err"] = max(st["err"], min(abs(t - x) for x in accepted) / case["a"])
    assert set(stats) == set(data["meta"]["categories"])
    for cat, st in stats.items():
        assert st["miss"] == 0, (cat, st)
        assert st["false"] == 0, (cat, st)
        assert st["err"] <= TOL_TUBE, (cat, st)


# ---------------------------------------------------------------- seeded hard cases

def _surface_point(rng, R, a, b, convex=False):
    """A point on the torus and its outward unit normal (world, mm)."""
    theta = rng.uniform(0, 2 * np.pi)
    phi = rng.uniform(-np.pi / 2.5, np.pi / 2.5) if convex else rng.uniform(-np.pi, np.pi)
    rho = R + a * np.cos(phi)
    p = np.array([rho * np.cos(theta), rho * np.sin(theta), b * np.sin(phi)])
    n2 = np.array([np.cos(phi) / a, np.sin(phi) / b])
    n2 /= np.hypot(*n2)
    return p, np.array([n2[0] * np.cos(theta), n2[0] * np.sin(theta), n2[1]])


def _unit(v):
    return v / np.linalg.norm(v)


def _make_case(kind, rng):
    """One hard ray of the given ``kind``: (origin, direction, R, a, b, tau)."""
    a = 10 ** rng.uniform(-1, 1)
    R, b, tau = a * rng.uniform(1.5, 5), a, 0.0
    if kind == "scale":
        s = 10 ** rng.uniform(-3, 3)
        a, R, b = a * s, R * s, a * s
    elif kind == "thin":
        R = a * 10 ** rng.uniform(1, 3)
    elif kind in ("spindle", "inner_sheet"):
        R = a * rng.uniform(0.05, 0.95)
    elif kind == "elliptic":
        b = a * 10 ** rng.uniform(-1, 1)
    p, n = _surface_point(rng, R, a, b, convex=kind in ("graze_in", "graze_out"))
    d = _unit(rng.normal(size=3))
    dist = a * rng.uniform(2, 20)
    if kind == "equatorial":
        p = np.array([R + a, 0.0, 0.0]) if rng.random() < 0.5 else np.array([R - a, 0.0, 0.0])
        ang = rng.uniform(0, 2 * np.pi)
        p = np.array([p[0] * np.cos(ang), p[0] * np.sin(ang), 0.0])
        d = _unit(np.array([*rng.normal(size=2), 0.0]))
    elif kind == "far":
        dist = a * 10 ** rng.uniform(3, 4)
    elif kind in ("graze_in", "graze_out"):
        d = _unit(np.cross(n, rng.normal(size=3)))
        p = p + (-1e-5 if kind == "graze_in" else 1e-6) * a * n
    elif kind == "on_surface":
        tau, dist = 1e-6 * a, 0.0
    return p - dist * d, d, R, a, b, tau


def _reference(o, d, R, a, b, tau, inner=False):
    """(required, allowed): 50-digit real outer-sheet roots > tau; near-pair roots only allowed."""
    with mp.workdps(50):
        o = [mp.mpf(float(v)) for v in o]
        d = [mp.mpf(float(v)) for v in d]
        R, a, b = mp.mpf(R), mp.mpf(a), mp.mpf(b)
        k = (a / b) ** 2
        # rho^2 and z as polynomials in t (ascending coefficients)
        rho2 = [o[0] ** 2 + o[1] ** 2, 2 * (o[0] * d[0] + o[1] * d[1]), d[0] ** 2 + d[1] ** 2]
        z2 = [o[2] ** 2, 2 * o[2] * d[2], d[2] ** 2]
        s = [rho2[i] + k * z2[i] for i in range(3)]
        s[0] += R * R - a * a
        quart = [mp.mpf(0)] * 5
        for i in range(3):
            for j in range(3):
                quart[i + j] += s[i] * s[j]
        for i in range(3):
            quart[i] -= 4 * R * R * rho2[i]
        roots = mp.polyroots(quart, maxsteps=400, extraprec=200, asc=True)
        required, allowed = [], []
        for i, rt in enumerate(roots):
            if abs(mp.im(rt)) > mp.mpf(10) ** -30 * max(1, abs(mp.re(rt))):
                continue
            t = mp.re(rt)
            x, y, z = (o[j] + t * d[j] for j in range(3))
            rho = mp.sqrt(x * x + y * y)
            g_out = ((rho - R) / a) ** 2 + (z / b) ** 2 - 1
            g_in = ((rho + R) / a) ** 2 + (z / b) ** 2 - 1
            if (abs(g_out) < abs(g_in) if inner else abs(g_out) > abs(g_in)) or t <= tau:
                continue
            paired = any(j != i and abs(rt - other) < 1e-4 * a for j, other in enumerate(roots))
            (allowed if paired else required).append(float(t))
    return required, allowed


KINDS = ["generic", "equatorial", "far", "thin", "spindle", "elliptic", "scale", "on_surface",
         "graze_in", "graze_out", "inner_sheet"]


def _seeded_case(kind, rng):
    """A hard case of ``kind`` and whether it aims at the mirror sheet ``hypot(x, y) + R``."""
    o, d, R, a, b, tau = _make_case(kind, rng)
    inner = kind == "inner_sheet"
    if inner:  # aim at the mirror sheet (hypot(x,y) + R)^2/a^2 + (z/b)^2 = 1 instead
        d = _unit(rng.normal(size=3))
        phi = rng.uniform(-0.9, 0.9) * np.arccos(R / a)
        theta = rng.uniform(0, 2 * np.pi)
        rho = a * np.cos(phi) - R
        o = np.array([rho * np.cos(theta), rho * np.sin(theta), b * np.sin(phi)]) - 3 * a * d
    return o, d, R, a, b, tau, inner


@pytest.mark.parametrize("kind", KINDS)
def test_seeded_hard_cases_match_50_digit_references(kind):
    rng = np.random.default_rng(KINDS.index(kind) + 7)
    for _ in range(8):
        o, d, R, a, b, tau, inner = _seeded_case(kind, rng)
        hits = ray_torus_hits(o[None], d[None], R, a, b, tmin=tau,
                              sheet="inner" if inner else "outer")[0]
        hits = hits[np.isfinite(hits)]
        required, allowed = _reference(o, d, R, a, b, tau, inner)
        for t in required:
            assert np.min(np.abs(hits - t), initial=np.inf) <= TOL_TUBE * a, (kind, t, hits)
        for t in hits:
            assert min((abs(t - x) for x in required + allowed), default=np.inf) <= TOL_TUBE * a, \
                (kind, t, required, allowed)
        if kind == "graze_in":
            assert len(required) >= 2  # the construction dips 1e-5 tube radii into the glass


@pytest.mark.parametrize("kind", KINDS)
def test_convex_sheet_solver_matches_50_digit_references_on_its_side(kind):
    """The solver of arcs on the outer side of their tube (and on the mirror sheet) finds every
    root there and reports nothing else: roots at ``hypot(x, y) < R`` belong to the other side
    (a hair of slack either way at ``hypot = R``, where both sides meet)."""
    from engine.tracer.kernels.records import Ray
    from engine.tracer.kernels.roots import SHEET_SLACK, convex_sheet_roots

    rng = np.random.default_rng(KINDS.index(kind) + 70)
    out = np.zeros(2)
    for _ in range(12):
        o, d, R, a, b, tau, inner = _seeded_case(kind, rng)
        hits = out[:convex_sheet_roots(Ray(*o, *d), R, a, b, inner, tau, np.inf, out)]
        required, allowed = _reference(o, d, R, a, b, tau, inner)
        side = lambda t: inner or (math.hypot(*(o + t * d)[:2]) - R) / a
        for t in required:
            if inner or side(t) > SHEET_SLACK:
                assert np.min(np.abs(hits - t), initial=np.inf) <= TOL_TUBE * a, (kind, t, hits)
        for t in hits:
            assert inner or side(t) >= -SHEET_SLACK, (kind, t)
            assert min((abs(t - x) for x in required + allowed), default=np.inf) <= TOL_TUBE * a, \
                (kind, t, required, allowed)


def test_convex_sheet_solver_agrees_with_the_quartic_on_the_shared_cases():
    """On the shared hard cases, every root the convex solver reports is one of the quartic's
    (to 1e-6 tube radii), and it reports every root of the outer side the quartic finds,
    except a touch: a pair closer than 1e-6 tube radii."""
    from engine.tracer.kernels.records import Ray
    from engine.tracer.kernels.roots import SHEET_SLACK, convex_sheet_roots, torus_roots

    out, crit, mine = np.zeros(4), np.zeros(5), np.zeros(2)
    for case in json.loads(CASES.read_text())["cases"]:
        o, d = np.array(case["origin"]), np.array(case["direction"])
        R, a, b, tau = case["R"], case["a"], case["b"], case["tau"]
        quartic = list(out[:torus_roots(Ray(*o, *d), R, a, b, False, tau, out, crit)])
        got = list(mine[:convex_sheet_roots(Ray(*o, *d), R, a, b, False, tau, np.inf, mine)])
        near = lambda t, ts: min((abs(t - x) for x in ts), default=np.inf) <= TOL_TUBE * a
        for t in got:
            assert near(t, quartic), (case["category"], got, quartic)
        for t in quartic:
            outer = (math.hypot(*(o + t * d)[:2]) - R) / a > SHEET_SLACK
            touch = near(t, [x for x in quartic if x != t])
            assert near(t, got) or not outer or touch, (case["category"], got, quartic)



def _on_hole_side(o, d, t, R, b):
    """Whether the ray's point at ``t`` lies on the side of the tube facing the axis, within the
    heights :func:`hole_sheet_roots` serves."""
    from engine.tracer.kernels.roots import HOLE_POLE

    p = o + t * d
    return math.hypot(p[0], p[1]) <= R and abs(p[2] / b) <= HOLE_POLE


@pytest.mark.parametrize("kind", [k for k in KINDS if k != "inner_sheet"])
def test_hole_sheet_solver_matches_50_digit_references_on_its_side(kind):
    """The solver of arcs on the side of their tube facing the axis (waists, shoulders into a
    neck) finds every root there and reports nothing else."""
    from engine.tracer.kernels.records import Ray
    from engine.tracer.kernels.roots import hole_sheet_roots

    rng = np.random.default_rng(KINDS.index(kind) + 700)
    out = np.zeros(4)
    for _ in range(16):
        o, d, R, a, b, tau, _ = _seeded_case(kind, rng)
        hits = out[:hole_sheet_roots(Ray(*o, *d), R, a, b, tau, np.inf, out)]
        required, allowed = _reference(o, d, R, a, b, tau)
        for t in required:
            if _on_hole_side(o, d, t, R, b):
                assert np.min(np.abs(hits - t), initial=np.inf) <= TOL_TUBE * a, (kind, t, hits)
        for t in hits:
            assert math.hypot(*(o + t * d)[:2]) <= R * (1 + 1e-9), (kind, t)
            assert min((abs(t - x) for x in required + allowed), default=np.inf) <= TOL_TUBE * a, \
                (kind, t, required, allowed)
        assert np.all(np.diff(hits) > 0)


def test_hole_sheet_solver_agrees_with_the_quartic_on_the_shared_cases():
    """On the shared hard cases (near-double roots, rays along and across the axis, far and
    thin tori) every root the hole-side solver reports is one of the quartic's, and it reports
    every root of its side the quartic finds, except a touch."""
    from engine.tracer.kernels.records import Ray
    from engine.tracer.kernels.roots import hole_sheet_roots, torus_roots

    out, crit, mine = np.zeros(4), np.zeros(5), np.zeros(4)
    for case in json.loads(CASES.read_text())["cases"]:
        o, d = np.array(case["origin"]), np.array(case["direction"])
        R, a, b, tau = case["R"], case["a"], case["b"], case["tau"]
        quartic = list(out[:torus_roots(Ray(*o, *d), R, a, b, False, tau, out, crit)])
        got = list(mine[:hole_sheet_roots(Ray(*o, *d), R, a, b, tau, np.inf, mine)])
        near = lambda t, ts: min((abs(t - x) for x in ts), default=np.inf) <= TOL_TUBE * a
        for t in got:
            assert near(t, quartic), (case["category"], got, quartic)
        for t in quartic:
            touch = near(t, [x for x in quartic if x != t])
            assert near(t, got) or not _on_hole_side(o, d, t, R, b) or touch, (case["category"], got, quartic)


@pytest.mark.parametrize("R, a, b", [(40.0, 7.0, 7.0), (69.09, 57.59, 57.59), (12.0, 3.0, 9.0)])
def test_hole_sheet_solver_where_its_pieces_degenerate(R, a, b):
    """Rays exactly through the axis (a kink of the distance from it), level rays (no split of
    convexity), vertical rays and rays nearly along the axis, against the quartic: the roots of
    the side facing the axis, to 1e-9 tube radii."""
    from engine.tracer.kernels.records import Ray
    from engine.tracer.kernels.roots import hole_sheet_roots, torus_roots

    rng = np.random.default_rng(11)
    out, crit, mine = np.zeros(4), np.zeros(5), np.zeros(4)
    rays = []
    for _ in range(60):
        z0, ang = rng.uniform(-0.9, 0.9) * b, rng.uniform(0, 2 * np.pi)
        tilt = rng.choice([0.0, rng.uniform(-1, 1), 1e-9])
        d = _unit(np.array([math.cos(ang), math.sin(ang), tilt]))
        rays.append((-3 * R * d + [0.0, 0.0, z0], d))  # through the axis (level when tilt = 0)
        rays.append((np.array([R - a * rng.uniform(0.3, 0.95), 0.0, 3 * b]),
                     _unit(np.array([rng.choice([0.0, 1e-7]), 0.0, -1.0]))))  # along the axis
    found = 0
    for o, d in rays:
        quartic = list(out[:torus_roots(Ray(*o, *d), R, a, b, False, 0.0, out, crit)])
        got = list(mine[:hole_sheet_roots(Ray(*o, *d), R, a, b, 0.0, np.inf, mine)])
        near = lambda t, ts: min((abs(t - x) for x in ts), default=np.inf) <= 1e-9 * a
        for t in quartic:
            assert near(t, got) or not _on_hole_side(o, d, t, R, b), (o, d, got, quartic)
        for t in got:  # (and a hair beyond HOLE_POLE, where the window ends)
            assert near(t, quartic) and math.hypot(*(o + t * d)[:2]) <= R, (o, d, got, quartic)
        found += len(got)
    assert found > 200


def test_per_ray_tori_in_one_call_match_single_calls():
    cases = json.loads(CASES.read_text())["cases"][::7]
    col = lambda key: np.array([c[key] for c in cases], dtype=float)
    batch = ray_torus_hits(col("origin"), col("direction"), col("R"), col("a"), col("b"),
                           tmin=col("tau"))
    single = np.array([ray_torus_hits(np.array([c["origin"]]), np.array([c["direction"]]),
                                      c["R"], c["a"], c["b"], tmin=c["tau"])[0] for c in cases])
    assert np.array_equal(batch, single, equal_nan=True)


def test_spheroid_limit_and_rays_along_the_axis():
    # R = 0: a spheroid of semi-axes 2 and 3 seen down the axis and across it
    o = np.array([[0.0, 0.0, 10.0], [10.0, 0.0, 0.0]])
    d = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])
    assert np.allclose(ray_torus_hits(o, d, 0.0, 2.0, 3.0)[:, :2], [[7, 13], [8, 12]], atol=1e-12)
    # spindle torus: a ray along the axis passes exactly through both cusps
    R, a = 1.0, 2.0
    cusp = math.sqrt(a * a - R * R)
    h = ray_torus_hits(o[:1], d[:1], R, a)[0]
    assert np.allclose(h[:2], [10 - cusp, 10 + cusp], rtol=0, atol=1e-12) and np.isnan(h[2])


def test_secondary_rays_never_report_their_own_start():
    rng = np.random.default_rng(3)
    R, a = 40.0, 7.0
    pts, normals = zip(*(_surface_point(rng, R, a, a) for _ in range(200)))
    pts, normals = np.array(pts), np.array(normals)
    d = rng.normal(size=pts.shape)
    d /= np.linalg.norm(d, axis=1)[:, None]
    hits = ray_torus_hits(pts, d, R, a, a)
    assert np.all(np.isnan(hits) | (hits > 1e-6 * a))
    # A ray leaving into the glass (against the outward normal) must hit the far wall.
    inward = np.einsum("ij,ij->i", d, normals) < -1e-3
    assert np.all(np.isfinite(hits[inward, 0]))


def test_output_is_ascending_nan_padded_and_scale_invariant():
    rng = np.random.default_rng(5)
    o = rng.normal(size=(500, 3)) * 12
    d = rng.normal(size=(500, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    h = ray_torus_hits(o, d, 6.0, 2.5, 1.5)
    assert h.shape == (500, 4)
    finite = np.isfinite(h)
    # NaNs only trail, and hits ascend
    assert np.all(finite[:, :-1] | ~finite[:, 1:])
    assert np.array_equal(np.sort(h, axis=1), h, equal_nan=True)
    for s in (1e-3, 1e3):
        hs = ray_torus_hits(o * s, d, 6.0 * s, 2.5 * s, 1.5 * s)
        assert np.array_equal(np.isfinite(hs), finite)
        assert np.allclose(hs[finite] / s, h[finite], rtol=0, atol=1e-10 * 2.5)


def test_empty_input_and_bad_parameters():
    assert ray_torus_hits(np.zeros((0, 3)), np.zeros((0, 3)), 3, 1, 1).shape == (0, 4)
    with pytest.raises(ValueError):
        ray_torus_hits(np.zeros((1, 3)), np.array([[0, 0, 1.0]]), 3, 0.0, 1)
    assert math.isnan(ray_torus_hits(np.array([[0, 0, 50.0]]), np.array([[1.0, 0, 0]]), 3, 1)[0, 0])
