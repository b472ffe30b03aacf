"""Screw threads as true geometry: the helical ridge's hits against a dense float64 reference
(grazing rays at the crests, rays along the axis, flanks from above and below), exact unit
normals, the same ridge as the relief, no leaks in a render, relief renders unchanged, the
choice rule, and the project and command line carrying the choice."""
from __future__ import annotations

import dataclasses
import json
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest

from engine.appearance.bands import band_coordinates, thread_drawings
from engine.tracer.tables.bump_rows import tile_params
from engine.appearance.threads import WALL_FRACTION, thread_rendering
from engine.operations.tiles import new_tile
from engine.errors import DesignError
from engine.files.project import load_project, save_project
from engine.model.check import check_values
from engine.tracer.context import RenderContext, trace_pixels
from engine.tracer.kernels import profile as R
from engine.tracer.kernels.bumps import THREAD, bump_height
from engine.tracer.kernels.helix import MAX_ROOTS, helix_field, helix_normal, helix_roots
from engine.tracer.tables.render_objects import OUTER_WALL
from engine.model.design import Camera
from engine.tracer.kernels.records import Ray
from tests.test_tracer import WHITE
from tests.test_tracer_properties import tall
from tests.reference_images import assert_within_half_rounding

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def bordeaux():
    return load_project(ROOT / "resources" / "bordeaux.glassbench")


def _threaded(design, geometry="true", finish="", **given):
    zt = design.shape.z_top
    tile = new_tile(design, "thread", zt - 18.0, zt - 2.0, angle_deg=3.0, geometry=geometry,
                    finish=finish or None, **given)
    cam = dataclasses.replace(design.camera, target=(0.0, 0.0, zt - 10.0), fov_y_deg=12.0)
    return dataclasses.replace(design, bumps=(tile,), cap=None, camera=cam)


@pytest.fixture(scope="module")
def helix(bordeaux):
    """``(design, segment table, HELIX row index)`` of the Bordeaux with a true 33-400 thread."""
    design, assets = bordeaux
    d = _threaded(design)
    seg = RenderContext.from_design(d, assets, 8, 8).scene.geom.seg
    rows = np.flatnonzero(seg[:, R.S_KIND] == R.HELIX)
    assert len(rows) == 1
    return d, seg, int(rows[0])


# ------------------------------------------------------------------ the reference surface
def _bell(x, w):
    return np.where(np.abs(x) < 0.5 * w, np.cos(np.pi * x / w) ** 2, 0.0)


def _ramp(t):
    t = np.clip(t, 0.0, 1.0)
    return t ** 3 * (t * (6 * t - 15) + 10)


def _ref_height(row, theta, z):
    """The thread's ridge (mm) from its definition, in numpy: a bell across the helical
    phase, faded over the run-out at both ends of the turns."""
    R_, n = row[R.H_REF], row[R.H_STARTS]
    circ = 2 * np.pi * R_
    uu = theta * R_ - row[R.H_PHASE] * R_
    uw = uu - circ * np.floor(uu / circ)
    v = row[R.S_V0] + (z - row[R.S_Z0]) * row[R.S_LEN] / (row[R.S_Z1] - row[R.S_Z0])
    s = (v - row[R.H_START]) / row[R.H_PITCH] - n * uw / circ
    k = np.floor(s + 0.5)
    x = s - k
    prof = _bell(x, 2 * np.where(x >= 0, row[R.H_FLANK_HI], row[R.H_FLANK_LO]))
    tau = (k + n * uw / circ) / n
    turns, fade = row[R.H_TURNS], row[R.H_RUNOUT]
    e = np.where((tau >= 0) & (tau <= turns), _ramp(tau / fade) * _ramp((turns - tau) / fade), 0.0)
    return row[R.H_DEPTH] * e * prof


def _ref_field(row, p):
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    base = row[R.S_R0] + (z - row[R.S_Z0]) * (row[R.S_R1] - row[R.S_R0]) / (row[R.S_Z1] - row[R.S_Z0])
    return np.hypot(x, y) - base - _ref_height(row, np.arctan2(y, x), z)


def _ref_roots(row, o, d, samples=400_001):
    """Every crossing of the reference surface by the ray within the row's heights and box:
    sign changes of ``F`` on a dense grid (steps of about 1e-4 mm), each bisected to 1e-13."""
    z0, z1 = row[R.S_Z0], row[R.S_Z1]
    lo, hi = 0.0, 1e3
    if d[2] != 0.0:
        ta, tb = (z0 - o[2]) / d[2], (z1 - o[2]) / d[2]
        lo, hi = max(lo, min(ta, tb)), min(hi, max(ta, tb))
    E = d[0] ** 2 + d[1] ** 2
    if E > 0:
        s = -(o[0] * d[0] + o[1] * d[1]) / E
        m2 = (o[0] + s * d[0]) ** 2 + (o[1] + s * d[1]) ** 2
        h = math.sqrt(max(row[R.S_RMAX] ** 2 + 1.0 - m2, 0.0) / E)
        lo, hi = max(lo, s - h), min(hi, s + h)
    t = np.linspace(lo, hi, samples)
    f = _ref_field(row, o + t[:, None] * d)
    idx = np.flatnonzero(np.signbit(f[:-1]) != np.signbit(f[1:]))
    a, b, fa = t[idx], t[idx + 1], f[idx]
    for _ in range(60):
        m = 0.5 * (a + b)
        fm = _ref_field(row, o + m[:, None] * d)
        same = np.signbit(fm) == np.signbit(fa)
        a, b = np.where(same, m, a), np.where(same, b, m)
    return 0.5 * (a + b)


def _kernel_roots(seg, j, o, d):
    out = np.zeros(16)
    n = helix_roots(seg, j, Ray(*o, *d), 0.0, np.inf, out, MAX_ROOTS)
    return out[:n]


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _crest(row, theta):
    """Height (mm) and radius of the ridge's crest at polar angle ``theta``."""
    zs = np.linspace(row[R.H_Z0], row[R.H_Z1], 200_001)
    h = _ref_height(row, np.full_like(zs, theta), zs)
    k = int(np.argmax(h))
    return zs[k], row[R.S_R0] + h[k]


def _assert_same_roots(seg, j, o, d):
    o, d = np.asarray(o, float), _unit(d)
    got, ref = _kernel_roots(seg, j, o, d), _ref_roots(seg[j], o, d)
    assert len(got) == len(ref), (o, d, got, ref)
    assert np.all(np.abs(got - ref) < 1e-8), (got, ref)
    return got


# ------------------------------------------------------------------------- intersections
def test_the_ridge_is_the_reliefs_thread_to_rounding(helix):
    """True geometry and relief draw the same thread: the HELIX row's height field is the
    relief row's height, and both are the reference's."""
    d, seg, j = helix
    row = seg[j]
    tile = d.bumps[0]
    v0, v1, radius = band_coordinates(d, tile.z0, tile.z1)
    kind, p = tile_params(tile, v0, v1, radius, neck_diameter=2 * row[R.S_R0])
    assert kind == THREAD
    rng = np.random.default_rng(3)
    th, z = rng.uniform(-np.pi, np.pi, 400), rng.uniform(row[R.H_Z0], row[R.H_Z1], 400)
    ref = _ref_height(row, th, z)
    assert ref.max() > 0.9 * tile.depth
    relief = np.array([bump_height(THREAD, p, a * radius, v0 + (b - tile.z0)) for a, b in zip(th, z)])
    rho = row[R.S_R0] + ref
    field = np.array([helix_field(seg, j, r * math.cos(a), r * math.sin(a), b)[0] for a, b, r in zip(th, z, rho)])
    assert np.max(np.abs(relief - ref)) < 1e-12 and np.max(np.abs(field)) < 1e-12


def test_rays_into_the_thread_hit_where_the_dense_reference_does(helix):
    _, seg, j = helix
    row = seg[j]
    rng = np.random.default_rng(7)
    found = 0
    for _ in range(40):
        th = rng.uniform(-np.pi, np.pi)
        z = rng.uniform(row[R.H_Z0], row[R.H_Z1])
        p = np.array([row[R.S_R0] * math.cos(th), row[R.S_R0] * math.sin(th), z])
        d = _unit(-p * [1, 1, 0] + rng.normal(0.0, 4.0, 3))
        found += len(_assert_same_roots(seg, j, p - 60.0 * d, d))
    assert found >= 40


def test_a_two_start_thread_of_several_turns_hits_where_the_reference_does(bordeaux):
    """Two starts of a 28-415 thread (about 1.6 turns each) on the Bordeaux neck: random rays
    and rays along the axis crossing several ridges."""
    design, assets = bordeaux
    d = _threaded(design, finish="28-415", repeat=2)
    seg = RenderContext.from_design(d, assets, 8, 8).scene.geom.seg
    j = int(np.flatnonzero(seg[:, R.S_KIND] == R.HELIX)[0])
    row = seg[j]
    assert row[R.H_STARTS] == 2 and row[R.H_TURNS] > 1.0
    rng = np.random.default_rng(5)
    for _ in range(25):
        th, z = rng.uniform(-np.pi, np.pi), rng.uniform(row[R.H_Z0], row[R.H_Z1])
        p = np.array([row[R.S_R0] * math.cos(th), row[R.S_R0] * math.sin(th), z])
        d = _unit(-p * [1, 1, 0] + rng.normal(0.0, 6.0, 3))
        _assert_same_roots(seg, j, p - 60.0 * d, d)
    crossings = 0
    for th in np.linspace(-3.0, 3.0, 5):
        r = row[R.S_R0] + 0.5 * row[R.H_DEPTH]
        o = np.array([r * math.cos(th), r * math.sin(th), row[R.H_Z0] - 1.0])
        crossings += len(_assert_same_roots(seg, j, o, [0.0, 0.0, 1.0]))
    assert crossings >= 5 * 4          # at least two ridges crossed on every ray


@pytest.mark.parametrize("delta", [-1e-3, -1e-5, 1e-5, 1e-3])
@pytest.mark.parametrize("along", ["girth", "crest"])
def test_grazing_rays_at_the_crest_hit_or_miss_as_the_reference_does(helix, delta, along):
    """Rays tangent to the ridge's crest, a hair inside (two crossings) or outside (none),
    across the girth or along the helical crest itself."""
    _, seg, j = helix
    row = seg[j]
    th = 2.0
    z, rc = _crest(row, th)
    er, et = np.array([math.cos(th), math.sin(th), 0.0]), np.array([-math.sin(th), math.cos(th), 0.0])
    lead = row[R.H_PITCH] * row[R.H_STARTS] / (2 * np.pi * rc)
    d = _unit(et + (lead * np.array([0, 0, 1.0]) if along == "crest" else 0.0))
    p = (rc + delta) * er + np.array([0, 0, z])
    got = _assert_same_roots(seg, j, p - 8.0 * d, d)
    assert (len(got) >= 2) == (delta < 0)


@pytest.mark.parametrize("dz", [1.0, -1.0])
def test_rays_along_the_axis_meet_the_flanks_from_below_and_above(helix, dz):
    _, seg, j = helix
    row = seg[j]
    counts = []
    for th in np.linspace(-3.0, 3.0, 7):
        for frac in (0.2, 0.6, 0.95):
            r = row[R.S_R0] + frac * row[R.H_DEPTH]
            o = np.array([r * math.cos(th), r * math.sin(th), row[R.H_Z0] - 1.0 if dz > 0 else row[R.H_Z1] + 1.0])
            counts.append(len(_assert_same_roots(seg, j, o, [0.0, 0.0, dz])))
    # one turn: in through one flank and out through the other, except where the run-out at
    # the turn's ends keeps the ridge lower than the ray
    assert set(counts) <= {0, 2} and counts.count(2) >= 15
    assert len(_kernel_roots(seg, j, np.array([0.0, 0.0, 200.0]), np.array([0.0, 0.0, 1.0]))) == 0


@pytest.mark.parametrize("dz", [0.6, -0.6])
def test_slanted_rays_hit_the_flanks_from_below_and_above(helix, dz):
    _, seg, j = helix
    row = seg[j]
    for th in np.linspace(-2.5, 2.5, 6):
        z, rc = _crest(row, th)
        er = np.array([math.cos(th), math.sin(th), 0.0])
        target = (rc - 0.5 * row[R.H_DEPTH]) * er + np.array([0, 0, z - math.copysign(0.8, dz)])
        d = _unit(-er + np.array([0, 0, dz]))
        assert len(_assert_same_roots(seg, j, target - 20.0 * d, d)) >= 1


def test_normals_are_unit_and_the_gradient_of_the_surface(helix):
    _, seg, j = helix
    row = seg[j]
    rng = np.random.default_rng(11)
    for _ in range(60):
        th, z = rng.uniform(-np.pi, np.pi), rng.uniform(row[R.H_Z0], row[R.H_Z1])
        r = row[R.S_R0] + _ref_height(row, np.array(th), np.array(z))
        p = np.array([r * math.cos(th), r * math.sin(th), z])
        n = np.array(helix_normal(seg, j, *p))
        g = np.array([(_ref_field(row, p + e) - _ref_field(row, p - e)) / 2e-6 for e in np.eye(3) * 1e-6])
        assert abs(np.linalg.norm(n) - 1.0) < 1e-12
        assert np.linalg.norm(n - g / np.linalg.norm(g)) < 1e-6
        assert np.dot(n, p * [1, 1, 0]) > 0.0          # towards the air
    # where the ridge is bare the normal is the plain wall's
    p = np.array([row[R.S_R0], 0.0, row[R.H_Z0] + 0.01])
    assert np.allclose(helix_normal(seg, j, *p), [1.0, 0.0, 0.0], atol=1e-15)


# ------------------------------------------------------------------------------- renders
def test_a_ridge_thicker_than_the_wall_stays_exactly_white_in_a_furnace_without_leaks():
    """A 1.2 mm ridge on a 0.5 mm neck wall (auto: true geometry): R + T = 1 at every hit and
    no branch travels in a medium it is not in, through ridge, wall and bore."""
    d = tall(0.5, fill=120.0)
    tile = new_tile(d, "thread", 280.0, 298.0, finish="28-400")
    cam = Camera(eye=(0.0, -260.0, 300.0), target=(0.0, 0.0, 289.0), fov_y_deg=8.0)
    d = dataclasses.replace(d, bumps=(tile,), camera=cam)
    assert thread_drawings(d)[0].mode == "true"
    ctx = RenderContext.from_design(d, None, 24, 32, environment=WHITE)
    assert ctx.finish.obj_rows[OUTER_WALL, 1] == 0           # no relief row: the thread is glass
    rows, cols = np.mgrid[0:32, 0:24]
    res = trace_pixels(ctx, cols.ravel(), rows.ravel(), 1, 2)
    assert res.counters[1] == 0 and res.counters[2] == 0
    assert res.counters[6] > 3000                      # plenty of boundaries crossed
    assert np.all(np.abs(res.sums / 2 - 1.0) < 1e-9)


def test_a_true_thread_renders_without_leaks_in_a_real_environment(bordeaux):
    design, assets = bordeaux
    ctx = RenderContext.from_design(_threaded(design), assets, 24, 32)
    rows, cols = np.mgrid[0:32, 0:24]
    res = trace_pixels(ctx, cols.ravel(), rows.ravel(), 0, 2)
    assert res.counters[1] == 0 and res.counters[2] == 0 and np.all(np.isfinite(res.sums))
    assert np.count_nonzero(res.objects & (1 << OUTER_WALL)) > 100


def test_a_relief_thread_renders_as_before(bordeaux):
    """The reference was rendered by the tracer before true threads (commit 187750e) with the
    same relief thread; ``geometry="relief"`` must give the same image: the same bits until
    the intersectors' search windows changed (see
    ``test_finish_render.test_a_plain_design_renders_as_before_finishes``), now within 1e-13,
    with every sample's dominant path the same. (Re-rendered at that commit with today's
    ``kernels/sampling.py`` patched in when sample positions became Owen-scrambled Sobol.)"""
    design, assets = bordeaux
    ref = np.load(ROOT / "tests" / "data" / "thread_relief_bordeaux_32x40.npz")
    d = _threaded(design, "relief", finish="33-400")
    ctx = RenderContext.from_design(d, assets, 32, 40)
    assert ctx.finish.obj_rows[OUTER_WALL, 1] == 1 and not np.any(ctx.scene.geom.seg[:, R.S_KIND] == R.HELIX)
    ys, xs = np.mgrid[0:40, 0:32]
    res = trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, 2)
    assert_within_half_rounding(res.sums.reshape(40, 32, 3), ref["image"])  # (float32 texels then)
    assert np.array_equal(res.signature.reshape(40, 32), ref["signature"])


# ----------------------------------------------------------------------------- the rule
def test_the_rule_takes_true_geometry_when_the_ridge_is_large_against_the_wall():
    assert thread_rendering("auto", 1.2, 2.0).mode == "true"
    assert thread_rendering("auto", 0.9, 2.0).mode == "relief"
    assert thread_rendering("auto", WALL_FRACTION * 2.0, 2.0).mode == "relief"
    assert thread_rendering("relief", 3.0, 1.0).mode == "relief"
    assert thread_rendering("true", 0.1, 5.0).mode == "true"
    blocked = thread_rendering("true", 1.0, 1.0, "a round neck")
    assert blocked.mode == "relief" and "round neck" in blocked.reason
    assert "wall" in thread_rendering("auto", 1.2, 2.0).reason


def test_thread_drawings_read_the_wall_and_say_why(bordeaux):
    design, _ = bordeaux
    auto = thread_drawings(_threaded(design, "auto"))[0]
    assert auto.mode == "relief" and auto.wall_mm == pytest.approx(3.0) and "auto" in auto.reason
    thin = dataclasses.replace(design, shape=dataclasses.replace(design.shape, wall_thickness=2.0))
    assert thread_drawings(_threaded(thin, "auto"))[0].mode == "true"
    inverted = thread_drawings(_threaded(design, "true", inverted=True))[0]
    assert inverted.mode == "relief" and "raised" in inverted.reason
    zt = design.shape.z_top
    low = dataclasses.replace(design, bumps=(new_tile(design, "thread", 30.0, zt - 2.0, geometry="true"),))
    assert "one straight piece" in thread_drawings(low)[0].reason
    knurl = dataclasses.replace(design, bumps=(new_tile(design, "knurl", 40.0, 80.0),))
    assert thread_drawings(knurl) == (None,)
    square, _ = load_project(ROOT / "resources" / "square.glassbench")
    zt = square.shape.z_top
    on_square = dataclasses.replace(square, bumps=(new_tile(square, "thread", zt - 12.0, zt - 1.0, geometry="true"),))
    drawing = thread_drawings(on_square)[0]
    assert drawing.mode == "relief" and "round neck" in drawing.reason


def test_a_bad_geometry_value_is_refused_by_name(bordeaux):
    design, _ = bordeaux
    d = _threaded(design, "helical")
    with pytest.raises(DesignError, match=r"bumps\[0\]\.geometry"):
        check_values(d)


# ------------------------------------------------------------------- project and CLI
def test_the_choice_is_saved_and_format_2_files_draw_their_threads_as_relief(bordeaux, tmp_path):
    design, assets = bordeaux
    d = _threaded(design, "true")
    path = tmp_path / "t.glassbench"
    save_project(path, d, assets)
    back, _ = load_project(path)
    assert back.bumps[0].geometry == "true" and back == d
    with zipfile.ZipFile(path) as z:
        names = {n: z.read(n) for n in z.namelist()}
    doc = json.loads(names["project.json"])
    doc["format_version"] = 2  # before the field: a thread was always relief
    for key in ("geometry", "on"):
        del doc["design"]["bumps"][0][key]
    names["project.json"] = json.dumps(doc).encode()
    old = tmp_path / "old.glassbench"
    with zipfile.ZipFile(old, "w") as z:
        for n, data in names.items():
            z.writestr(n, data)
    assert load_project(old)[0].bumps[0].geometry == "relief"


def test_the_command_line_adds_a_true_thread_and_lists_how_it_is_drawn(bordeaux, tmp_path, capsys):
    from engine.cli import main
    design, assets = bordeaux
    path = tmp_path / "b.glassbench"
    save_project(path, design, assets)
    zt = design.shape.z_top
    assert main(["bump", str(path), "add", "thread", "--z0", str(zt - 18), "--z1", str(zt - 2),
                 "--geometry", "true"]) == 0
    assert load_project(path)[0].bumps[-1].geometry == "true"
    capsys.readouterr()
    assert main(["bump", str(path), "list"]) == 0
    assert "true geometry, as chosen" in capsys.readouterr().out
    assert main(["bump", str(path), "add", "knurl", "--z0", "40", "--z1", "80", "--geometry", "true"]) == 2
    assert "threads only" in capsys.readouterr().err
    assert len(load_project(path)[0].bumps) == 1


@pytest.mark.parametrize("cap", ["screw", "crown", "lug", None])
def test_a_true_thread_under_a_cap_renders_without_leaks_or_mismatches(cap):
    """The closure is sized from the thread's depth, so the glass ridge never meets its skirt."""
    from engine.appearance.closure_shapes import default_cap
    design, assets = load_project(ROOT / "resources" / "threaded_bottle.glassbench")
    zt = design.shape.z_top
    tile = dataclasses.replace(design.bumps[0], geometry="true")
    cam = dataclasses.replace(design.camera, target=(0.0, 0.0, zt - 10.0), fov_y_deg=6.0)
    d = dataclasses.replace(design, bumps=(tile,), cap=default_cap(cap) if cap else None, camera=cam)
    ctx = RenderContext.from_design(d, assets, 24, 30)
    assert np.count_nonzero(ctx.scene.geom.seg[:, R.S_KIND] == R.HELIX) == 1
    ys, xs = np.mgrid[0:30, 0:24]
    res = trace_pixels(ctx, xs.ravel(), ys.ravel(), 0, 2)
    assert res.counters[1] == 0 and res.counters[2] == 0
    assert np.count_nonzero(res.objects & (1 << OUTER_WALL)) > 100
