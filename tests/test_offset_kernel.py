"""The compiled offset-arc rows (inner walls of ellipse arcs) against the numpy intersector.

The kernel reads a crossing's sign from each table piece's band beside its chord instead of
solving the curve (:func:`engine.tracer.tables.render_objects._piece_band`); the band must hold the
curve, and the hits must be those of :func:`engine.intersect.revolved_hits`, an independent
implementation (sampled grid + Newton in numpy).
"""
from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from engine.intersect import offset_arc_parameter, revolved_hits
from engine.tracer.kernels.profile import S_RMAX, S_RMIN, S_ZMAX, S_ZMIN
from engine.tracer.kernels.revolved import PARAM_SLOT, ray_box, segment_hits, segment_normal
from engine.tracer.kernels.records import Ray
from engine.tracer.tables.render_objects import _segment_row
from tests.test_revolved import SEGMENTS, _random_rays

OFFSETS = ["offset_dome", "offset_shoulder", "offset_concave"]


def _row(name, wall=True):
    """The kernel's row (a wall's, z-rising; else a base's, r-rising) and its table."""
    tables = []
    row = _segment_row(SEGMENTS[name], 0.0, wall, tables)
    return row[None, :].copy(), np.ascontiguousarray(tables[0])


@njit(cache=False)
def _ray_roots(seg, tab, ox, oy, oz, dx, dy, dz, roots, crit, stack):
    """Roots of row 0 along the ray as the tracer asks for them (inside the row's box)."""
    ray = Ray(ox, oy, oz, dx, dy, dz)
    a, b = ray_box(ray, seg[0, S_RMIN], seg[0, S_RMAX], seg[0, S_ZMIN], seg[0, S_ZMAX],
                   0.0, np.inf)
    if a > b:
        return 0
    return segment_hits(seg, tab, 0, ray, 0.0, np.inf, a, b, roots, crit, stack)


@njit(cache=False)
def _kernel_hits(seg, tab, o, d, out):
    roots, crit, stack = np.zeros(16), np.zeros(5), np.zeros((64, 2))
    for q in range(o.shape[0]):
        ox, oy, oz, dx, dy, dz = o[q, 0], o[q, 1], o[q, 2], d[q, 0], d[q, 1], d[q, 2]
        n = _ray_roots(seg, tab, ox, oy, oz, dx, dy, dz, roots, crit, stack)
        for j in range(min(n, out.shape[1])):
            out[q, j] = roots[j]


@njit(cache=False)
def _kernel_normals(seg, p, out):
    for q in range(p.shape[0]):
        out[q, 0], out[q, 1], out[q, 2] = segment_normal(seg, 0, p[q, 0], p[q, 1], p[q, 2])


@pytest.mark.parametrize("name", OFFSETS)
def test_every_table_piece_lies_in_its_band(name):
    seg, tab = _row(name)
    sg = SEGMENTS[name]
    assert np.all(np.isfinite(tab[:-1, 3])), "a regular offset arc has a finite band on every piece"
    for k in range(len(tab) - 1):
        p0, p1 = tab[k, :2], tab[k + 1, :2]
        e = (p1 - p0) / np.hypot(*(p1 - p0))
        q = sg.point(np.linspace(tab[k, 2], tab[k + 1, 2], 201))
        v = (q - p0) @ np.array([e[1], -e[0]])
        h = tab[k, 3]
        assert v.min() >= min(0.0, h) - 1e-12 and v.max() <= max(0.0, h) + 1e-12
        # and the band is not loose: at most twice the sagitta (the tangents' apex)
        assert abs(h) <= 2.01 * np.abs(v).max() + 1e-12


@pytest.mark.parametrize("name", OFFSETS)
def test_kernel_hits_match_the_numpy_intersector(name):
    seg, tab = _row(name)
    rng = np.random.default_rng(5)
    o, d = _random_rays(SEGMENTS[name], rng, 3000)
    ref = revolved_hits(o, d, SEGMENTS[name])
    got = np.full((len(o), ref.shape[1]), np.nan)
    _kernel_hits(seg, tab, o, d, got)
    ref_n, got_n = np.isfinite(ref).sum(1), np.isfinite(got).sum(1)
    assert ref_n.sum() > 1000
    # only a graze may be missed: a pair of crossings whose middle lies within a band (a few
    # micrometres) of the curve
    band = np.abs(tab[:-1, 3]).max()
    for q in np.nonzero(ref_n != got_n)[0]:
        r = np.sort(ref[q][np.isfinite(ref[q])])
        kept = got[q][np.isfinite(got[q])]
        lost = np.array([x for x in r if not np.any(np.abs(kept - x) < 1e-8)])
        assert len(lost) == 2 and len(kept) == len(r) - 2, (r, kept)
        p = o[q] + lost.mean() * d[q]
        m = np.array([[np.hypot(p[0], p[1]), p[2]]])
        depth = np.hypot(*(m - SEGMENTS[name].point(offset_arc_parameter(m, SEGMENTS[name]))).T)[0]
        assert depth <= band, (lost, depth, band)
    same = ref_n == got_n
    assert np.count_nonzero(~same) <= 2
    assert np.nanmax(np.abs(np.sort(got[same], 1) - np.sort(ref[same], 1))) < 1e-8


@pytest.mark.parametrize("name", OFFSETS)
def test_kernel_normals_are_the_curve_normals(name):
    from engine.geometry.segments import normal

    seg, _ = _row(name)
    sg = SEGMENTS[name]
    t = np.linspace(0.0, 1.0, 97)
    q = sg.point(t)
    phi = np.linspace(0.0, 2 * np.pi, 97)
    p = np.column_stack([q[:, 0] * np.cos(phi), q[:, 0] * np.sin(phi), q[:, 1]])
    got = np.zeros_like(p)
    _kernel_normals(seg, p, got)
    n = normal(sg.base, t)  # the offset's normal is its base's
    want = np.column_stack([n[:, 0] * np.cos(phi), n[:, 0] * np.sin(phi), n[:, 1]])
    assert np.abs(got - want).max() < 1e-9


@njit(cache=False)
def _hit_normals(seg, tab, o, d, out):
    """Per ray and hit: the normal from the root solve's base angle, the normal solved again
    from the hit point, and whether the angle was known (columns 0-2, 3-5, 6)."""
    roots, crit, stack = np.zeros(16), np.zeros(5), np.zeros((64, 2))
    m = 0
    for q in range(o.shape[0]):
        ox, oy, oz, dx, dy, dz = o[q, 0], o[q, 1], o[q, 2], d[q, 0], d[q, 1], d[q, 2]
        n = _ray_roots(seg, tab, ox, oy, oz, dx, dy, dz, roots, crit, stack)
        for j in range(n):
            if m == out.shape[0]:
                return m
            px, py, pz = ox + roots[j] * dx, oy + roots[j] * dy, oz + roots[j] * dz
            s = roots[PARAM_SLOT + j]
            out[m, 0], out[m, 1], out[m, 2] = segment_normal(seg, 0, px, py, pz, s)
            out[m, 3], out[m, 4], out[m, 5] = segment_normal(seg, 0, px, py, pz)
            out[m, 6] = 1.0 if np.isfinite(s) else 0.0
            m += 1
    return m


@pytest.mark.parametrize("name", OFFSETS)
def test_a_hits_base_angle_from_its_root_solve_gives_its_normal(name):
    """The root solve hands on each hit's base angle (:data:`PARAM_SLOT`), so the hit's normal
    needs no second solve: it is the normal solved from the point, and almost always known."""
    seg, tab = _row(name)
    o, d = _random_rays(SEGMENTS[name], np.random.default_rng(9), 2000)
    out = np.zeros((4000, 7))
    m = _hit_normals(seg, tab, o, d, out)
    out = out[:m]
    assert m > 500
    assert out[:, 6].mean() > 0.95
    known = out[:, 6] > 0
    assert np.abs(out[known, :3] - out[known, 3:6]).max() < 1e-9


def test_rays_along_and_near_the_axis_meet_an_offset_dome_once():
    """A dome's offset reaches the axis (a punt's inner dome: a base row, whose residual is a
    height over the radius; a wall ends at the mouth, never on the axis): a ray down the axis
    (and a hair beside it) meets it once, at the offset's apex height, as numpy says."""
    seg, tab = _row("offset_dome", wall=False)
    sg = SEGMENTS["offset_dome"]
    apex_z = float(sg.point(1.0)[1])
    o = np.array([[0.0, 0.0, 120.0], [1e-9, 0.0, 120.0], [1e-4, -1e-4, 120.0], [0.0, 0.0, -50.0]])
    d = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])
    got = np.full((4, 4), np.nan)
    _kernel_hits(seg, tab, o, d, got)
    ref = revolved_hits(o, d, sg)
    assert np.array_equal(np.isfinite(got).sum(1), np.isfinite(ref).sum(1))
    assert np.nanmax(np.abs(np.sort(got, 1) - np.sort(ref, 1))) < 1e-8
    assert abs(120.0 - got[0, 0] - apex_z) < 1e-9
