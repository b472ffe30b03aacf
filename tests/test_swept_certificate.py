"""Swept walls (rounded square, rounded rectangle, free plan outlines): the monotonicity
certificate that ends a band's contraction, and the crossings it leads to, checked against the geometry engine's own
numpy implicit function (:meth:`engine.geometry.body.BottleBody.wall_implicit`) sampled densely
along the rays."""
from __future__ import annotations

import numpy as np
import pytest

from engine.files.project import load_project
from engine.geometry.body import BottleBody
from engine.geometry.section import Section
from engine.geometry.segments import Arc, Line
from engine.geometry.shape import BottleShape
from engine.model.design import Design
from engine.tracer.kernels import intersect as K
from engine.geometry.plan import shield
from engine.tracer.kernels.bands import monotone_sign, outline_monotone_sign
from engine.tracer.kernels.outlines import OUTLINE
from engine.tracer.kernels.profile import wall_range
from engine.tracer.kernels.revolved import ray_box
from engine.tracer.kernels.records import Ray, Wall
from engine.tracer.kernels.swept import swept_roots, swept_wall
from engine.tracer.tables.render_objects import INNER_WALL, OUTER_WALL, render_geometry_for


def _square_sample():
    """The bundled rounded-square bottle: arcs at the heel and the shoulder."""
    return load_project("resources/square.glassbench")[0].shape


def _heel_section(r, a, r_neck):
    """Flat base, a heel arc of radius ``a`` leaving the base horizontally (infinite dr/dz at
    z = 0), a vertical body, a straight shoulder and a round finish of radius ``r_neck`` (mm)."""
    return Section((Line((0, 0), (r, 0)), Arc((r, a), a, (r, 0), (r + a, a), "ccw"), Line((r + a, a), (r + a, 100)),
                    Line((r + a, 100), (r_neck, 130)), Line((r_neck, 130), (r_neck, 160))),
                   (False, True, False, False))


def _curved_rounded_rect():
    secs = {"half_width": _heel_section(24.0, 6.0, 12.0), "half_depth": _heel_section(14.0, 6.0, 12.0),
            "corner": _heel_section(3.0, 6.0, 12.0)}
    return BottleShape("rounded_rect", secs, 2.0, 5.0, rotation_deg=20.0)


def _geometry(shape):
    """Render tables of a bare shape (no liquid) and its numpy body."""
    return render_geometry_for(Design(shape=shape)), BottleBody(shape)


def _flacon_sample():
    """The bundled hexagonal flacon: a curved shoulder where the core vanishes into the neck."""
    return load_project("resources/flacon.glassbench")[0].shape


def _sharp_shield():
    """A shield plan whose cavity has sharp corners (rounding 1 mm against a 3 mm wall) under a
    curved shoulder: near its inner wall the footprint lies inside the scaled plan, where the
    maximising direction jumps between pieces across the medial axis."""
    from resources.make_outline_samples import outline_shape
    return outline_shape(shield(), 30.0, 1.0, 60.0, (12.0, 70.0, 8.0), 9.0, 110.0, 3.0, 6.0)


#: Shapes whose ruled slabs use the rounded rectangle's cones (:func:`ruled_roots`); an
#: outline's are :func:`engine.tracer.kernels.plans.plan_ruled_roots` (tests/test_plan_kernels.py).
FIXED = {"rounded square sample": _square_sample, "curved rounded rectangle": _curved_rounded_rect}
SHAPES = {**FIXED, "flacon sample": _flacon_sample, "shield with sharp inner corners": _sharp_shield}
WALLS = ((OUTER_WALL, "outer"), (INNER_WALL, "inner"))


def _slab_rays(geom, seed, m, ruled=False):
    """For each swept wall's curved slab (its sections not all straight: band contraction; with
    ``ruled``, each ruled slab instead), ``m`` random rays that enter the slab's box: yields
    ``(k, part, j, o, d, lo, hi)``, ``lo..hi`` the ray's interval in the box without its
    padding (where the kernel clamps the slab's sections and the engine continues into the next
    ones)."""
    rng = np.random.default_rng(seed)
    pad = 3e-9 * geom.scale_mm
    for k, part in WALLS:
        first, count = geom.obj_i[k, K.O_FIRST], geom.obj_i[k, K.O_COUNT]
        for j in range(first, first + count):
            z0, z1, rmax, is_ruled = geom.slab_f[j, :4]
            if (is_ruled > 0.5) != ruled:
                continue
            # from around the bottle towards points near its wall, steep rays included (mm)
            o = rng.normal(size=(m, 3)) * [70.0, 70.0, 0.0]
            o[:, 2] = rng.uniform(z0 - 30.0, z1 + 30.0, m)
            ang, rad = rng.uniform(0.0, 2.0 * np.pi, m), rng.uniform(0.0, 30.0, m)
            d = np.stack([rad * np.cos(ang), rad * np.sin(ang), rng.uniform(z0, z1, m)], 1) - o
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            for i in range(m):
                lo, hi = ray_box(Ray(*o[i], *d[i]), 0.0, rmax, z0 + pad, z1 - pad, 0.0, np.inf)
                if lo < hi:
                    yield k, part, j, o[i], d[i], lo, hi


def _wall(geom, k):
    """``(kind, nsec, cos, sin, leaf)`` of swept wall object ``k``."""
    return (geom.obj_i[k, K.O_XS], geom.obj_i[k, K.O_NSEC], geom.obj_f[k, K.F_COS], geom.obj_f[k, K.F_SIN],
            geom.obj_f[k, K.F_LEAF])


@pytest.mark.parametrize("name", SHAPES)
def test_certified_windows_are_monotone(name):
    geom, body = _geometry(SHAPES[name]())
    rng = np.random.default_rng(5)
    certified = tried = 0
    for k, part, j, o, d, lo, hi in _slab_rays(geom, 5, 300):
        kind, nsec, c, s, _ = _wall(geom, k)
        rows = geom.slab_i[j]
        # a random window, from a micrometre to the whole interval
        length = (hi - lo) * 10.0 ** rng.uniform(-6.0, 0.0)
        a = rng.uniform(lo, hi - length)
        b = a + length
        za, zb = o[2] + a * d[2], o[2] + b * d[2]
        z_lo, z_hi = min(za, zb), max(za, zb)
        ranges = [wall_range(geom.seg, geom.tab, r, z_lo, z_hi) for r in rows]
        px, py = c * o[0] + s * o[1], -s * o[0] + c * o[1]
        qx, qy = c * d[0] + s * d[1], -s * d[0] + c * d[1]
        wall = Wall(geom.seg, geom.tab, rows[0], rows[1], rows[2], nsec, kind, c, s, geom.plan)
        foot, window = (px, py, qx, qy, d[2]), (a, b, z_lo, z_hi)
        if kind == OUTLINE:
            sign = outline_monotone_sign(wall, foot, window, (*ranges[0], *ranges[1]))
        else:
            sign = monotone_sign(wall, foot, window, (*ranges[0], *ranges[1], *ranges[2]))
        tried += 1
        if sign == 0:
            continue
        certified += 1
        t = np.linspace(a, b, 400)
        g, _ = body.wall_implicit(part, o + t[:, None] * d)
        steps = np.diff(g) * sign
        assert steps.min() >= -1e-11, (name, part, j, a, b, sign, steps.min())
    # the certificate is not vacuous: many windows on these walls pass it
    assert certified > 0.25 * tried, (certified, tried)


@pytest.mark.parametrize("name", SHAPES)
def test_swept_roots_find_every_crossing_a_dense_sampling_finds(name):
    geom, body = _geometry(SHAPES[name]())
    out, stack = np.zeros(16), np.zeros((64, 2))
    found = 0
    for k, part, j, o, d, lo, hi in _slab_rays(geom, 11, 150):
        kind, nsec, c, s, leaf = _wall(geom, k)
        n = swept_roots(swept_wall(geom.seg, geom.tab, geom.slab_i[j], kind, nsec, (c, s), geom.plan), Ray(*o, *d), lo, hi, leaf, out,
                        stack)
        roots = out[:n].copy()
        assert np.all(np.diff(roots) > 0.0) and np.all((roots >= lo) & (roots <= hi))
        t = np.linspace(lo, hi, 20001)
        g, _ = body.wall_implicit(part, o + t[:, None] * d)
        change = np.nonzero(np.sign(g[:-1]) != np.sign(g[1:]))[0]
        for q in change:  # every sampled crossing is found, to the sampling step
            assert np.any(np.abs(roots - t[q]) <= 1.01 * (t[1] - t[0])), (name, part, j, t[q], roots)
        found += len(change)
        # and every root lies on the wall (first-order distance, mm)
        gr, grad = body.wall_implicit(part, o + roots[:, None] * d)
        assert np.all(np.abs(gr) / np.linalg.norm(grad, axis=1) < 1e-9)
    assert found > 200


@pytest.mark.parametrize("name", FIXED)
def test_ruled_slabs_normals_are_the_walls_gradients(name):
    """In a ruled slab the normal comes from the slab's linear outline coefficients
    (:func:`~engine.tracer.kernels.swept.ruled_normal`), not from the sections: it is the
    numpy implicit function's unit gradient at the wall's crossings, slanted walls included."""
    from engine.tracer.kernels.swept import ruled_normal, ruled_roots

    geom, body = _geometry(SHAPES[name]())
    out = np.zeros(16)
    slanted = checked = 0
    for k, part, j, o, d, lo, hi in _slab_rays(geom, 13, 150, ruled=True):
        _, _, c, s, _ = _wall(geom, k)
        for t in out[:ruled_roots(geom.slab_f[j], c, s, Ray(*o, *d), lo, hi, out)]:
            p = o + t * d
            n = np.array(ruled_normal(geom.slab_f[j], c, s, *p))
            _, grad = body.wall_implicit(part, p)
            assert np.allclose(n, grad / np.linalg.norm(grad), rtol=0.0, atol=1e-9), (name, part, j, p)
            checked += 1
            slanted += abs(n[2]) > 1e-3
    assert checked > 100, checked
    if name == "curved rounded rectangle":  # its straight shoulder: radii falling with z
        assert slanted > 10, slanted


@pytest.mark.parametrize("name", FIXED)
def test_ruled_slabs_cross_where_the_certified_bands_do(name):
    """:func:`~engine.tracer.kernels.swept.ruled_roots` solves at most the cones of the corners
    where a ray enters and leaves the outline's box (the slab's solid is convex): its crossings
    are those of the general band search (:func:`swept_roots`, which knows nothing of that), for
    rays from around the bottle and for rays leaving a point of the wall in any direction (the
    start itself never found again), on flat sides, slanted shoulders and the round necks (an
    outline that is all corner)."""
    from engine.tracer.kernels.swept import SL_RMAX, SL_Z0, SL_Z1, ruled_roots

    geom, _ = _geometry(SHAPES[name]())
    out, ref, stack = np.zeros(16), np.zeros(16), np.zeros((64, 2))
    rng = np.random.default_rng(17)
    tol = 1e-7 * geom.scale_mm
    counts = {"around": 0, "from the wall": 0}
    for k, part, j, o, d, lo, hi in _slab_rays(geom, 17, 200, ruled=True):
        kind, nsec, c, s, leaf = _wall(geom, k)
        rays = [("around", o, d, lo, hi)]
        n = ruled_roots(geom.slab_f[j], c, s, Ray(*o, *d), lo, hi, out)
        if n:  # from the first crossing, any direction that stays in the slab's box for a while
            p, e = o + out[0] * d, rng.normal(size=3)
            e /= np.linalg.norm(e)
            a, b = ray_box(Ray(*p, *e), 0.0, geom.slab_f[j, SL_RMAX], geom.slab_f[j, SL_Z0], geom.slab_f[j, SL_Z1], 0.0,
                           np.inf)
            if a < b:
                rays.append(("from the wall", p, e, max(a, tol), b))
        for kind_of_ray, o_, d_, lo_, hi_ in rays:
            n = ruled_roots(geom.slab_f[j], c, s, Ray(*o_, *d_), lo_, hi_, out)
            m = swept_roots(swept_wall(geom.seg, geom.tab, geom.slab_i[j], kind, nsec, (c, s), geom.plan), Ray(*o_, *d_), lo_, hi_,
                            leaf, ref, stack)
            assert n == m and np.allclose(out[:n], ref[:m], rtol=0.0, atol=tol), \
                (name, j, kind_of_ray, out[:n], ref[:m])
            counts[kind_of_ray] += n
    assert min(counts.values()) > 100, counts


@pytest.mark.parametrize("name", ["flacon sample", "shield with sharp inner corners"])
def test_an_outline_profile_stays_within_its_chord_bound_along_any_band(name):
    """The chord bound that lets an outline's bands shrink quadratically
    (:func:`engine.tracer.kernels.bands._chord`) holds: along random bands of rays through
    every curved slab (rising, falling, beyond the slab's ends, where the profiles are clamped),
    the core and the growth sampled densely stay within ``dev`` of the chord and inside the
    range; and the bound is second order: on bands a hundred times shorter the deviation is at
    least a thousand times smaller on most (a band reaching a segment's end is first order)."""
    from engine.tracer.kernels.bands import _chord
    from engine.tracer.kernels.profile import wall_r

    geom, _ = _geometry(SHAPES[name]())
    rng = np.random.default_rng(5)
    ratios = []
    for k, _ in WALLS:
        first, count = geom.obj_i[k, K.O_FIRST], geom.obj_i[k, K.O_COUNT]
        for j in range(first, first + count):
            z0, z1, _, is_ruled = geom.slab_f[j, :4]
            if is_ruled > 0.5:
                continue
            for row in geom.slab_i[j][:2]:
                for _ in range(25):
                    length, dz = rng.uniform(0.05, 60.0), rng.uniform(-1.0, 1.0)
                    za = rng.uniform(z0 - 1.0, z1 + 1.0)
                    zb = za + dz * length
                    r0, m, dev, lo, hi = _chord(geom.seg, geom.tab, row, za, zb, dz, length)
                    t = np.linspace(0.0, length, 801)
                    r = np.array([wall_r(geom.seg, row, za + dz * s) for s in t])
                    assert lo - 1e-12 <= r.min() and r.max() <= hi + 1e-12, (name, j, row, lo, hi)
                    if not np.isfinite(dev):
                        continue
                    assert np.abs(r - (r0 + m * t)).max() <= dev, (name, j, row, dev)
                    short = _chord(geom.seg, geom.tab, row, za, za + dz * length / 100, dz, length / 100)[2]
                    ratios.append(short / dev)
    # (a band reaching a segment's end or a steep arc's turn is first order there: the median)
    assert len(ratios) > 100 and np.median(ratios) < 1e-3, (len(ratios), np.percentile(ratios, [10, 50, 90]))
