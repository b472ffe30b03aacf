"""The stage's backdrop sweep: exact hits, energy, where it stands, and what it changes around it.

Where the method could fail: rays grazing the curve and the wall, a camera a hundred metres
away, the seam where the curve leaves the floor (the ground's grid must not read the sweep's
dark underside), a light behind the wall (no caustic may come through it), an orbit (the sweep
follows the camera, and the grids built for it must not be reused for another facing).
"""
from __future__ import annotations

import dataclasses
import math

import mpmath
import numpy as np
import pytest

from engine.model.design import Camera, Light, Stage
from engine.tracer.context import scene_tables
from engine.tracer.kernels import intersect as K
from engine.tracer.kernels.queries import hits
from engine.tracer.kernels.records import Geometry
from engine.tracer.picking import camera_hits
from engine.tracer.tables import sky as sky_tables
from engine.tracer.tables import stage as S
from engine.tracer.tables import sweep as sweep_tables
from engine.tracer.tables.sky import under_sweep_to_edge
from tests.test_stage import _caustic_flux, _lit, _on_stage, _pixels
from tests.test_tracer import WHITE

SWEPT = Stage(kind="table", color=(1.0, 1.0, 1.0), backdrop=True)


def _sweep(design):
    """``(object index, obj_f row)`` of ``design``'s sweep."""
    scene = scene_tables(design)[2]
    k = int(np.nonzero(scene.geom.obj_i[:, K.O_KIND] == K.SWEEP)[0][0])
    return k, scene.geom.obj_f[k]


def _only(row):
    """A geometry of the sweep ``row`` alone (its intersector needs no segments)."""
    oi = np.zeros((1, K.O_COLS), np.int64)
    oi[0, K.O_KIND], oi[0, K.O_XS_IN] = K.SWEEP, -1
    z = np.zeros((1, 1))
    return Geometry(z, z, z, np.zeros((1, 1), np.int64), oi, row[None, :].copy(), np.zeros((1, 11)))


def _surface_point(row, across, s):
    """The sweep's point ``across`` mm to the side of its centre line and ``s`` along its profile
    (0: where the curve leaves the floor), and its normal, in 50-digit arithmetic."""
    mpmath.mp.dps = 50
    c, sn = mpmath.mpf(row[K.F_COS]), mpmath.mpf(row[K.F_SIN])
    v0, r, z0 = mpmath.mpf(row[K.F_SW_START]), mpmath.mpf(row[K.F_SW_RADIUS]), mpmath.mpf(row[K.F_PZ])
    quarter = r * mpmath.pi / 2
    if s < quarter:
        a = s / r
        v, z, nv, nz = v0 + r * mpmath.sin(a), z0 + r - r * mpmath.cos(a), -mpmath.sin(a), mpmath.cos(a)
    else:
        v, z, nv, nz = v0 + r, z0 + r + (s - quarter), mpmath.mpf(-1), mpmath.mpf(0)
    u = mpmath.mpf(across)
    p = (c * v - sn * u, sn * v + c * u, z)
    return p, (c * nv, sn * nv, nz)


def test_rays_meet_the_sweep_where_50_digit_arithmetic_puts_them_grazing_and_from_afar():
    design = _on_stage(SWEPT, fill=40.0)
    row = _sweep(design)[1]
    geom = _only(row)
    rng = np.random.default_rng(3)
    r = row[K.F_SW_RADIUS]
    cases = []
    for _ in range(200):  # a camera's distance, from far away, at grazing angles
        across = rng.uniform(-3 * r, 3 * r)
        s = rng.choice([rng.uniform(0.0, 1.6 * r), rng.uniform(1e-6, 1e-3) * r, rng.uniform(1.5, 1.6) * r,
                        rng.uniform(2.0, 20.0) * r])
        p, n = _surface_point(row, across, mpmath.mpf(s))
        # an origin in front of the surface: along the normal, tilted up to grazing, near or a hundred metres off
        dist = rng.choice([50.0, 1e3, 1e5])
        tilt = rng.choice([0.2, 1.0, 1.5, 1.565])  # rad from the normal (1.565: 0.33 degrees from grazing)
        side = np.array([-row[K.F_SIN], row[K.F_COS], 0.0])
        nf = np.array([float(x) for x in n])
        w = math.cos(tilt) * nf + math.sin(tilt) * side
        o = [p[i] + mpmath.mpf(dist) * mpmath.mpf(w[i]) for i in range(3)]
        d = [p[i] - o[i] for i in range(3)]
        t = mpmath.sqrt(sum(x * x for x in d))
        cases.append(([float(x) for x in o], [float(x / t) for x in d], float(t), nf))
    mpmath.mp.dps = 50
    v0, rr, z0 = (mpmath.mpf(row[i]) for i in (K.F_SW_START, K.F_SW_RADIUS, K.F_PZ))
    c, sn = mpmath.mpf(row[K.F_COS]), mpmath.mpf(row[K.F_SIN])
    for eps in (1e-6, 1e-3, 0.5):  # skimming the floor into the foot of the curve: a glancing hit
        for back in (100.0, 1e5):
            o = (c * (v0 - back), sn * (v0 - back), z0 + mpmath.mpf(eps))
            dv = mpmath.sqrt(rr * rr - (rr - mpmath.mpf(eps)) ** 2)
            cases.append(([float(x) for x in o], [float(c), float(sn), 0.0], float(back + dv),
                          np.array([float(-c * dv / rr), float(-sn * dv / rr), float((rr - mpmath.mpf(eps)) / rr)])))
    o = np.array([c[0] for c in cases])
    d = np.array([c[1] for c in cases])
    n = len(cases)
    t, k, part, nrm = np.zeros(n), np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros((n, 3))
    hits(geom, o, d, np.zeros(n, np.int64), np.full(n, -1, np.int64), np.zeros(n, np.int64), t, k, part, nrm)
    t_ref = np.array([c[2] for c in cases])
    n_ref = np.array([c[3] for c in cases])
    assert (k == 0).all(), "every ray meets the sweep"
    # the exact point is the first crossing: the float64 ray's own rounding (1e-16 of its length) is the floor
    assert np.abs(t - t_ref).max() <= 1e-12 * t_ref.max() + 1e-9
    assert np.degrees(np.arccos(np.clip((nrm * n_ref).sum(axis=1), -1, 1))).max() < 1e-6


def test_a_ray_leaving_the_sweep_does_not_meet_it_again_and_one_from_behind_meets_its_back():
    design = _on_stage(SWEPT, fill=40.0)
    row = _sweep(design)[1]
    geom = _only(row)
    p, n = _surface_point(row, 0.0, mpmath.mpf(0.3 * row[K.F_SW_RADIUS]))
    p, n = np.array([float(x) for x in p]), np.array([float(x) for x in n])
    one = np.ones(1, np.int64)
    t, k, part, nrm = np.zeros(1), np.zeros(1, np.int64), np.zeros(1, np.int64), np.zeros((1, 3))
    hits(geom, p[None], n[None], np.zeros(1, np.int64), np.zeros(1, np.int64), one, t, k, part, nrm)
    assert k[0] == -1, "leaving the curve along its normal, the concave sheet is not met again"
    behind = p - 30.0 * n  # under the curve, looking out through it towards the bottle
    hits(geom, behind[None], n[None], np.zeros(1, np.int64), np.full(1, -1, np.int64), np.zeros(1, np.int64),
         t, k, part, nrm)
    assert k[0] == 0 and t[0] == pytest.approx(30.0, abs=1e-9) and (nrm[0] @ n) > 0.999
    # (the sheet's back: the ray and the normal agree, and the surface layer absorbs it there)


def test_a_white_sweep_and_ground_in_a_white_furnace_stay_white(monkeypatch):
    design = _on_stage(SWEPT, fill=40.0)
    # the grids' probes without Russian roulette: every probe's whole tree, so exactly white
    S.clear_stage_caches()
    monkeypatch.setattr(sky_tables, "ROULETTE", 0.0)
    monkeypatch.setattr(sweep_tables, "ROULETTE", 0.0)
    img, objects, ctx, st = _pixels(design, env=WHITE, grids=True)
    k, _ = _sweep(design)
    assert ((objects & (1 << k)) != 0).mean() > 0.1, "the sweep fills the top of the frame"
    assert ((objects & 1) != 0).any()
    # every pixel: the sweep, the ground, the glass in front of both: the control variates'
    # means (the sweep's open-sky table, the ground's whole-sky window) are exact in a white sky
    assert np.abs(img - 1.0).max() < 1e-9
    assert st.escaped_inside == 0 and st.mismatches == 0
    # the engine's grids play roulette in their probes: white to their noise, and unbiased
    S.clear_stage_caches()
    monkeypatch.undo()
    assert sky_tables.ROULETTE > 0.0
    img, _, _, st = _pixels(design, env=WHITE, grids=True)
    assert np.abs(img - 1.0).max() < 0.02
    assert abs(img.mean() - 1.0) < 1e-3
    assert np.abs(img - 1.0).max() > 1e-9, "(the probes did play roulette)"
    S.clear_stage_caches()


def test_the_sweep_stands_behind_the_bottle_as_the_camera_sees_it():
    base = _on_stage(SWEPT, fill=40.0)
    for eye in ((0, -220, 120), (300, 0, 80), (-150, 150, 200)):
        design = dataclasses.replace(base, camera=Camera(eye=eye, target=(0, 0, 20), fov_y_deg=40))
        k, row = _sweep(design)
        away = -np.array(eye[:2], float) / math.hypot(*eye[:2])
        assert np.allclose([row[K.F_COS], row[K.F_SIN]], away)
        w, h = 32, 24
        x, y = np.array([[0.5, w - 0.5, w / 2]]), np.array([[0.5, 0.5, 0.5]])
        _, hit, _ = camera_hits(design, w, h, x, y, scene_tables(design)[2])
        assert (hit == k).all(), "the top of the frame is the sweep, not the environment"
    top = Camera(eye=(0, 0, 500), target=(0, 0, 0), up=(0, 1, 0), fov_y_deg=30)
    assert S.sweep_facing(top) == (0.0, 1.0)
    assert S.sweep_facing(Camera(eye=(0, 0, 500), target=(10, 0, 0), up=(0, 0, 1))) == pytest.approx((1.0, 0.0))


def test_an_orbit_rebuilds_the_grids_only_when_a_sweep_follows_it():
    table = _on_stage(Stage(kind="table"), fill=40.0)
    swept = _on_stage(Stage(kind="table", backdrop=True), fill=40.0)
    orbit = Camera(eye=(220, 0, 120), target=(0, 0, 20), fov_y_deg=40)
    assert S._sky_key(table, None) == S._sky_key(dataclasses.replace(table, camera=orbit), None)
    assert S._sky_key(swept, None) != S._sky_key(dataclasses.replace(swept, camera=orbit), None)
    assert S._caustic_key(swept, None) != S._caustic_key(dataclasses.replace(swept, camera=orbit), None)
    # a kind that keeps the flag but draws no sweep keeps its grids on an orbit too
    caught = dataclasses.replace(swept, stage=dataclasses.replace(swept.stage, kind="shadow"))
    assert not caught.stage.draws_backdrop
    assert S._sky_key(caught, None) == S._sky_key(dataclasses.replace(caught, camera=orbit), None)
    assert scene_tables(caught)[2].geom.obj_i.shape[0] == scene_tables(table)[2].geom.obj_i.shape[0]


def test_grid_cells_under_the_sweep_are_read_on_its_edge_not_its_underside():
    design = _on_stage(SWEPT, fill=40.0)
    scene = scene_tables(design)[2]
    _, row = _sweep(design)
    facing = np.array([row[K.F_COS], row[K.F_SIN]])
    cells = np.array([[0.0, 0.0], [30.0, -40.0], *(facing * row[K.F_SW_START] * f for f in (0.5, 1.5, 20.0)),
                      facing * 2 * row[K.F_SW_START] + [50.0, 0.0]])
    moved = under_sweep_to_edge(scene, cells)
    v = moved @ facing
    assert np.array_equal(moved[:3], cells[:3]), "cells in front of the curve stay"
    assert np.allclose(v[3:], row[K.F_SW_START], rtol=2e-6) and (v[3:] < row[K.F_SW_START]).all()
    assert np.allclose(moved[3:] @ [-facing[1], facing[0]], cells[3:] @ [-facing[1], facing[0]])
    assert under_sweep_to_edge(scene_tables(_on_stage(Stage(kind="table"), fill=40.0))[2], cells) is cells


def test_a_light_behind_the_wall_lights_neither_the_ground_nor_its_caustic():
    behind = Light(direction=(0.0, 1.0, 0.6), intensity=2.0)  # 31 degrees up, beyond the wall
    open_table = _lit(Stage(kind="table", color=(1.0, 1.0, 1.0)), light=behind, fill=40.0)
    swept = dataclasses.replace(open_table, stage=SWEPT)
    assert _caustic_flux(open_table)[0] > 0.0
    assert _caustic_flux(swept)[0] == 0.0, "no photon starts in the wall's shadow"
    # and the ground in front of the bottle lies in the wall's shadow: the light adds there only
    # what probes bring back from ground so far off (over 6 m) that the light passes over the wall
    from tests.test_stage import _light_only
    pts = [(x, -50.0) for x in (-40.0, 0.0, 40.0)]
    open_light = _light_only(open_table, pts, 8)[[0, 2], 0]
    assert (open_light > 0.3).all()
    assert (_light_only(swept, pts, 8)[:, 0] < 0.25 * open_light.min()).all()


def test_the_sweeps_open_sky_table_is_the_open_sky_where_it_faces_up_and_one_in_a_white_sky():
    from engine.tracer.tables.environment import environment_from_design
    from engine.model.design import Environment
    env = environment_from_design(Environment())
    table = S.sweep_sky_irradiance(env, (0.0, 1.0))
    assert np.allclose(table[0], S.open_sky_irradiance(env), rtol=2e-3), "row 0 faces up: the ground's E_up"
    assert np.allclose(S.sweep_sky_irradiance(WHITE, (0.6, 0.8), (1.0, 1.0, 1.0)), 1.0, atol=1e-6)
    # a black floor: the wall sees the white sky over half its hemisphere (cosine-weighted)
    assert np.allclose(S.sweep_sky_irradiance(WHITE, (0.6, 0.8))[-1], 0.5, atol=1e-6)
    # a wall facing the studio's key light sees more than one facing away
    toward = S.sweep_sky_irradiance(env, (math.cos(math.radians(65)), math.sin(math.radians(65))))[-1].sum()
    away = S.sweep_sky_irradiance(env, (math.cos(math.radians(-115)), math.sin(math.radians(-115))))[-1].sum()
    assert toward > 2.0 * away


def test_the_sweep_grid_agrees_with_probing_per_hit_and_makes_its_pixels_noise_free():
    from engine.tracer.context import RenderContext, trace_rays
    from engine.tracer.kernels.backdrop import W_COLS
    design = _lit(Stage(kind="table", color=(0.8, 0.8, 0.8), backdrop=True),
                  light=Light(direction=(-0.4, -1.0, 0.8), intensity=1.5), fill=40.0)
    ctx = RenderContext.from_design(design, None, 8, 8, grids=True)
    assert ctx.finish.sweep_grid[1] > 0, "a sweep grid was built"
    probing = dataclasses.replace(ctx, finish=ctx.finish._replace(sweep_grid=np.zeros(W_COLS)))
    k, row = _sweep(design)
    r = row[K.F_SW_RADIUS]
    # points on the curve's foot, its middle, the wall, beside the bottle and in its shadow's way
    points = [(u, s * r) for u in (-150.0, 0.0, 60.0) for s in (0.02, 0.5, 1.2, 2.5)]
    repeats = 2048
    for u, s in points:
        p, n = _surface_point(row, u, mpmath.mpf(s))
        p, n = np.array([float(x) for x in p]), np.array([float(x) for x in n])
        o, d = np.tile(p + 10.0 * n, (repeats, 1)), np.tile(-n, (repeats, 1))
        grid, _ = trace_rays(ctx, o[:4], d[:4])
        assert np.ptp(grid, axis=0).max() == 0.0, "the grid's reading is the same for every sample"
        probed, _ = trace_rays(probing, o, d)
        mean, se = probed.mean(axis=0), probed.std(axis=0) / math.sqrt(repeats)
        assert np.all(np.abs(grid[0] - mean) < 4 * se + 0.02 * mean), (u, s, grid[0], mean, se)

