"""The compiled relief and GGX functions (engine/tracer/kernels/bumps.py), tested directly:
slopes are the heights' derivatives, shading normals are unit and continuous across tile seams
and the 360 deg wrap, magnified 100x they stay smooth, GGX sampling follows its pdf, and
nothing is NaN at grazing angles or for hostile numbers."""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine.tracer.tables.bump_rows import tile_params
from engine.model.design import BumpTile
from engine.tracer.kernels import bumps as K

R = 30.0
NO_ATLAS = np.zeros((1, 3), np.float32)
TILES = {
    "knurl": BumpTile(kind="knurl", repeat=24, depth=0.4, width=0.0, sharpness=0.7),
    "straight knurl": BumpTile(kind="knurl", repeat=90, depth=0.3, width=1.0, sharpness=0.9),
    "stipple": BumpTile(kind="stipple", repeat=30, depth=0.3, width=0.6),
    "flutes": BumpTile(kind="flutes", repeat=16, depth=0.8, width=0.8),
    "facets": BumpTile(kind="facets", repeat=10, depth=1.5, sharpness=0.8),
    "shallow facets": BumpTile(kind="facets", repeat=8, depth=0.3, sharpness=0.9),
    "diamond": BumpTile(kind="diamond", repeat=20, depth=0.8, width=0.6, sharpness=0.8),
    "thread": BumpTile(kind="thread", repeat=1, depth=1.2, width=0.5, finish="28-400"),
    "buttress": BumpTile(kind="thread", repeat=2, depth=1.0, width=0.6, finish="38-430"),
}


def params(name, v0=0.0, v1=20.0):
    kind, p = tile_params(TILES[name], v0, v1, R, neck_diameter=2 * R)
    return kind, p


def png_bytes(grey01: np.ndarray) -> bytes:
    import io
    from PIL import Image
    buf = io.BytesIO()
    Image.fromarray(np.round(grey01 * 65535).astype(np.uint16)).save(buf, format="PNG")
    return buf.getvalue()


def smooth_height_png(w=64, h=48) -> bytes:
    """A 16-bit grey height map 0.5 + 0.5 sin(2 pi fu) sin^2(pi fv), row 0 at the top."""
    fu = (np.arange(w) + 0.5) / w
    fv = 1.0 - (np.arange(h) + 0.5) / h
    U, V = np.meshgrid(fu, fv)
    return png_bytes(0.5 + 0.5 * np.sin(2 * np.pi * U) * np.sin(np.pi * V) ** 2)


def map_params(wrap=True):
    """A relief-map tile (through the real texture builder) of :func:`smooth_height_png`."""
    from engine.tracer.tables.relief_textures import relief_texture
    tile = BumpTile(kind="height_map", repeat=3, depth=0.5, asset="m.png",
                    width_deg=120.0 if wrap else 60.0)
    tex, mode = relief_texture("m.png", smooth_height_png(), tile.kind, 0.0, tile_u=wrap)
    kind, p = tile_params(tile, 0.0, 20.0, R, texture=(0, tex.shape[1], tex.shape[0], mode))
    return kind, p, np.ascontiguousarray(tex.reshape(-1, 3))


def normal_on_cylinder(kind, p, atlas, theta, v):
    """Shading normal of the relief on a cylinder of radius R at (theta, v)."""
    c, s = math.cos(theta), math.sin(theta)
    su, sv = K.surface_slope(kind, p, atlas, theta, v, R)
    return np.array(K.perturb_normal(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0, su, sv))


def max_turn(kind, p, atlas, thetas, vs):
    """Largest angle (rad) between the normals at consecutive points of a path."""
    ns = np.array([normal_on_cylinder(kind, p, atlas, t, v) for t, v in zip(thetas, vs)])
    dots = np.clip(np.sum(ns[1:] * ns[:-1], axis=1), -1.0, 1.0)
    return float(np.max(np.arccos(dots)))


def wrapped(theta):
    return (np.asarray(theta) + np.pi) % (2 * np.pi) - np.pi


def paths(p, n, up_at=0.43):
    """Three paths of n points: around through the 360 deg wrap, up the band (at ``up_at`` of
    a period from the pattern's origin), diagonally."""
    period = 2 * np.pi / p[K.P_REPEAT]
    t = np.linspace(0.0, 1.0, n)
    v_mid = 0.5 * (p[K.P_V0] + p[K.P_V1])
    around = (wrapped(np.pi - 1.5 * period + 3 * period * t), np.full(n, v_mid + 0.37))
    up = (np.full(n, p[K.P_PHASE] + up_at * period), p[K.P_V0] - 0.5 + (p[K.P_V1] - p[K.P_V0] + 1.0) * t)
    diag = (wrapped(np.pi - period + 2 * period * t), p[K.P_V0] + 2.0 + 6.0 * t)
    return around, up, diag


@pytest.mark.parametrize("name", sorted(TILES))
def test_slopes_are_the_derivatives_of_the_height(name):
    kind, p = params(name)
    rng = np.random.default_rng(7)
    h = 1e-6
    worst = 0.0
    for u, v in zip(rng.uniform(-200, 200, 300), rng.uniform(-1.0, 21.0, 300)):
        su, sv = K.bump_slope(kind, p, u, v)
        fu = (K.bump_height(kind, p, u + h, v) - K.bump_height(kind, p, u - h, v)) / (2 * h)
        fv = (K.bump_height(kind, p, u, v + h) - K.bump_height(kind, p, u, v - h)) / (2 * h)
        worst = max(worst, abs(su - fu), abs(sv - fv))
    assert worst < 1e-4, worst
    heights = [K.bump_height(kind, p, u, v) for u in np.linspace(0, 2 * np.pi * R, 400)
               for v in np.linspace(0.0, 20.0, 41)]
    assert max(abs(x) for x in heights) > 0.5 * TILES[name].depth  # the relief is really there


@pytest.mark.parametrize("name", sorted(TILES) + ["map", "map (one copy)"])
def test_normals_are_continuous_across_seams_and_the_wrap(name):
    # A jump (at a seam, the wrap or a crease) stays the same size when the step shrinks;
    # a continuous normal field turns ten times less over ten times shorter steps.
    up_at = 0.43  # near a facet's or a dot's centre
    if name.startswith("map"):
        (kind, p, atlas), up_at = map_params(wrap=name == "map"), 0.07  # a copy is centred at 0
    else:
        (kind, p), atlas = params(name), NO_ATLAS
    for coarse, fine in zip(paths(p, 1500, up_at), paths(p, 15000, up_at)):
        big = max_turn(kind, p, atlas, *coarse)
        small = max_turn(kind, p, atlas, *fine)
        assert big > 1e-4, "the path crosses relief"
        assert small < big / 5.0, (name, big, small)


@pytest.mark.parametrize("name", ["knurl", "facets", "diamond", "thread"])
def test_magnified_100x_the_relief_stays_smooth(name):
    # A window of 1/100 of a period, 400 samples: the normal turns smoothly (no pixel steps),
    # its second differences are tiny against its first.
    kind, p = params(name)
    period = 2 * np.pi / p[K.P_REPEAT]
    for start in np.linspace(0.0, period, 7):
        thetas = start + np.linspace(0.0, period / 100.0, 400)
        ns = np.array([normal_on_cylinder(kind, p, NO_ATLAS, t, 9.5) for t in thetas])
        d1 = np.diff(ns, axis=0)
        d2 = np.diff(ns, n=2, axis=0)
        assert np.max(np.linalg.norm(d2, axis=1)) <= 0.05 * np.max(np.linalg.norm(d1, axis=1)) + 1e-12


def test_outside_the_band_and_for_frosting_there_is_no_relief():
    kind, p = params("knurl", 5.0, 15.0)
    assert K.surface_slope(kind, p, NO_ATLAS, 0.3, 4.99, R) == (0.0, 0.0)
    assert K.surface_slope(kind, p, NO_ATLAS, 0.3, 15.01, R) == (0.0, 0.0)
    assert K.surface_slope(kind, p, NO_ATLAS, 0.3, 10.0, R) != (0.0, 0.0)
    _, pf = tile_params(BumpTile(kind="frosted", alpha=0.3), 0.0, 20.0, R)
    assert K.bump_slope(K.FROSTED, pf, 3.0, 10.0) == (0.0, 0.0) and pf[K.P_ALPHA] == 0.3


def test_surface_slope_converts_to_the_true_radius():
    kind, p = params("flutes")
    su_ref, sv_ref = K.bump_slope(kind, p, 0.2 * R, 10.0)
    su, sv = K.surface_slope(kind, p, NO_ATLAS, 0.2, 10.0, 2 * R)
    assert su == pytest.approx(su_ref / 2) and sv == pytest.approx(sv_ref)


def test_image_map_follows_its_smooth_source():
    # Inside the map (away from its faded edges) height and slope follow the drawn function:
    # grey g = 0.5 + 0.5 f is the height (normalised to its peak, ~1) times the depth, 0.5 mm.
    kind, p, atlas = map_params()
    span = 2 * np.pi / 3 * R
    pts = [(0.1, 0.5), (0.3, 0.4), (0.77, 0.6), (0.52, 0.3)]
    out = np.zeros((len(pts), 3))
    K.relief_grid(kind, p, atlas, np.array([fu * span for fu, _ in pts]),
                  np.array([fv * 20.0 for _, fv in pts]), out)
    for (fu, fv), (h, hu, hv) in zip(pts, out):
        f = np.sin(2 * np.pi * fu) * np.sin(np.pi * fv) ** 2
        df_du = 2 * np.pi * np.cos(2 * np.pi * fu) * np.sin(np.pi * fv) ** 2 / span
        df_dv = np.sin(2 * np.pi * fu) * np.pi * np.sin(2 * np.pi * fv) / 20.0
        assert h == pytest.approx(0.5 * (0.5 + 0.5 * f), abs=3e-3)
        assert hu == pytest.approx(0.25 * df_du, abs=2e-3 * 0.25 * 2 * np.pi / span + 1e-4)
        assert hv == pytest.approx(0.25 * df_dv, abs=1e-3)


# ------------------------------------------------------------------------------ normals
def test_perturbed_normals_are_unit_and_finite_for_any_input():
    rng = np.random.default_rng(3)
    for _ in range(2000):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        tu, tv = rng.normal(size=3), rng.normal(size=3)
        su, sv = rng.normal(scale=10.0 ** rng.uniform(-3, 8), size=2)
        s = K.perturb_normal(*n, *tu, *tv, su, sv)
        assert np.all(np.isfinite(s)) and np.linalg.norm(s) == pytest.approx(1.0, abs=1e-12)
        assert np.dot(s, n) > 0.0  # a relief never turns the surface inside out
    n = np.array([0.0, 0.0, 1.0])
    for tu, tv in [(n, n), ((0, 0, 0), (0, 0, 0)), ((1, 0, 0), (1, 0, 0)), ((np.nan,) * 3, (0, 1, 0))]:
        s = K.perturb_normal(*n, *tu, *tv, 0.5, 0.5)
        assert np.all(np.isfinite(s)) and np.linalg.norm(s) == pytest.approx(1.0)
    assert K.perturb_normal(*n, 1, 0, 0, 0, 1, 0, np.inf, np.nan) == (0.0, 0.0, 1.0)


def test_consistent_normal_keeps_the_ray_on_the_geometric_side():
    rng = np.random.default_rng(5)
    for _ in range(3000):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        s = rng.normal(size=3) + 2 * n
        s /= np.linalg.norm(s)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        out = np.array(K.consistent_normal(*s, *n, *d))
        assert np.linalg.norm(out) == pytest.approx(1.0)
        assert np.sign(np.dot(d, out)) == np.sign(np.dot(d, n))
        if np.sign(np.dot(d, s)) == np.sign(np.dot(d, n)) and abs(np.dot(d, s)) >= 0.01 * abs(np.dot(d, n)):
            assert np.allclose(out, s)  # nothing to fix: untouched
    grazing = K.consistent_normal(0.0, 0.6, 0.8, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0)
    assert grazing == (0.0, 0.0, 1.0)


def test_onb_is_orthonormal_everywhere_including_the_south_pole():
    for n in [(0, 0, 1), (0, 0, -1), (0, 1e-300, -1), (1, 0, 0), (0.6, 0, -0.8)]:
        n = np.array(n, float) / np.linalg.norm(n)
        b1, b2 = map(np.array, K.onb(*n))
        frame = np.array([b1, b2, n])
        assert np.allclose(frame @ frame.T, np.eye(3), atol=1e-12)
        assert np.dot(np.cross(b1, b2), n) == pytest.approx(1.0)


# ---------------------------------------------------------------------------------- GGX
@pytest.mark.parametrize("alpha", [0.02, 0.1, 0.3, 0.5])
def test_ggx_sampling_matches_its_pdf(alpha):
    # Histogram of the sampled angle against the pdf integrated over each bin (midpoint rule
    # on a fine grid): the sampler and ggx_pdf agree, and the pdf integrates to 1.
    n = np.array([0.3, -0.2, 0.9])
    n /= np.linalg.norm(n)
    rng = np.random.default_rng(11)
    count = 40000
    cos = np.empty(count)
    for i, (u1, u2) in enumerate(rng.random((count, 2))):
        m = np.array(K.ggx_sample(alpha, *n, u1, u2))
        cos[i] = m @ n
    theta = np.arccos(np.clip(cos, -1, 1))
    top = min(np.pi / 2, 12 * alpha)
    edges = np.linspace(0.0, top, 13)
    hist = np.histogram(theta, edges)[0] / count
    fine = np.linspace(0.0, np.pi / 2, 200001)
    mid = 0.5 * (fine[1:] + fine[:-1])
    b1, _ = K.onb(*n)
    dens = np.array([K.ggx_pdf(alpha, *n, *(np.cos(t) * n + np.sin(t) * np.array(b1))) for t in mid[::50]])
    ring = dens * 2 * np.pi * np.sin(mid[::50]) * (fine[1] - fine[0]) * 50
    assert ring.sum() == pytest.approx(1.0, abs=3e-3)
    expected = np.histogram(mid[::50], edges, weights=ring)[0]
    sigma = np.sqrt(expected * (1 - expected) / count) + 1e-4
    assert np.all(np.abs(hist - expected) < 5 * sigma + 0.01 * expected), (hist, expected)
    assert np.all(cos > 0.0)


def test_ggx_is_finite_at_grazing_and_extreme_numbers():
    n = (0.0, 0.0, 1.0)
    for u1 in (0.0, 1e-300, 0.5, 1.0 - 1e-16, 1.0):
        for u2 in (0.0, 0.999999, 1.0):
            m = K.ggx_sample(0.5, *n, u1, u2)
            assert np.all(np.isfinite(m)) and np.linalg.norm(m) == pytest.approx(1.0)
    for wi in [(1.0, 0.0, 0.0), (1.0, 0.0, 1e-300), (-1.0, 0.0, 1e-9), (0.0, 1.0, -1e-12)]:
        wi = np.array(wi) / np.linalg.norm(wi)
        for m in [(0.0, 0.0, 1.0), (0.7071, 0.0, 0.7071), (1.0, 0.0, 0.0)]:
            m = np.array(m) / np.linalg.norm(m)
            wo = 2 * np.dot(wi, m) * m - wi
            d, g, w = K.ggx_eval(0.3, *(tuple(map(float, v)) for v in (n, wi, wo, m)))
            assert np.isfinite(d) and np.isfinite(g) and np.isfinite(w) and w >= 0.0
    assert K.ggx_g1(0.3, 0.0, 0.5) == 0.0 and K.ggx_d(0.3, -0.1) == 0.0


def test_ggx_weight_of_a_smooth_surface_is_one():
    # Almost no roughness: the sampled facet is the normal and the branch keeps its weight.
    n = (0.0, 0.0, 1.0)
    m = K.ggx_sample(0.02, *n, 0.3, 0.7)
    wi = np.array([0.5, 0.0, 0.8660254037844386])
    wo = 2 * np.dot(wi, m) * np.array(m) - wi
    _, g, w = K.ggx_eval(0.02, *(tuple(map(float, v)) for v in (n, wi, wo, m)))
    assert g == pytest.approx(1.0, abs=2e-3) and w == pytest.approx(1.0, abs=5e-3)
