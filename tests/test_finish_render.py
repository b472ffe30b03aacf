"""Finishes in the tracer: relief normals at hits, no leaks with relief, the plain render kept
(to its last bits), caps drawn and following the finish, frosted glass deterministic and bounded,
hostile relief images refused."""
from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from engine.appearance.closure_shapes import default_cap
from engine.appearance.relief_image import ReliefImageError
from engine.operations.tiles import new_tile
from engine.files.project import load_project
from engine.model.design import BumpTile, Cap, Design, Light, Liquid
from engine.tracer.tables import finishes
from engine.tracer.context import RenderContext, nearest_hits, trace_pixels, trace_rays
from engine.tracer.tables.environment import EnvironmentMap
from engine.tracer.tables.ggx_albedo import albedo_tables, conductor_average, dielectric_average
from engine.tracer.kernels import microfacet as MF
from engine.tracer.kernels.finish import shading_frame
from engine.tracer.kernels.materials import MF_ALBEDO, MF_COAT_IOR, fresnel_conductor, fresnel_dielectric
from engine.tracer.tables.render_objects import OUTER_WALL, render_geometry_for
from tests.test_tracer import WHITE, _furnace
from tests.test_tracer_properties import tall
from tests.reference_images import assert_within_half_rounding

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "resources"))
from make_samples import bordeaux_section, round_shape  # noqa: E402


@pytest.fixture(scope="module")
def bordeaux():
    return load_project(ROOT / "resources" / "bordeaux.glassbench")


def _image(design, assets=None, w=32, h=44, first=0, count=1, env=None):
    ctx = RenderContext.from_design(design, assets, w, h, environment=env)
    ys, xs = np.mgrid[0:h, 0:w]
    res = trace_pixels(ctx, xs.ravel(), ys.ravel(), first, count)
    return res.sums.reshape(h, w, 3), res, ctx


def _wall_normals(design, thetas, z, assets=None):
    """Shading and geometric normals of the outer wall at polar angles ``thetas`` and height
    ``z`` (rays shot horizontally at the axis from outside)."""
    ctx = RenderContext.from_design(design, assets, 8, 8)
    d = np.stack([-np.cos(thetas), -np.sin(thetas), np.zeros_like(thetas)], 1)
    o = -200 * d + np.array([0, 0, z])
    t, k, part, n = nearest_hits(ctx.geometry, o, d)
    assert np.all(k == OUTER_WALL)
    p = o + t[:, None] * d
    s = np.array([shading_frame(ctx.finish, ctx.scene.geom, int(k[i]), int(part[i]), *p[i], *n[i])
                  for i in range(len(t))])
    return s[:, :3], n


@pytest.mark.parametrize("kind", ["knurl", "flutes", "facets", "diamond", "stipple", "thread"])
def test_relief_normals_at_hits_are_unit_bent_and_continuous_across_seams_and_the_wrap(bordeaux, kind):
    design, _ = bordeaux
    z0, z1 = (design.shape.z_top - 18.0, design.shape.z_top - 2.0) if kind == "thread" else (40.0, 120.0)
    tile = new_tile(design, kind, z0, z1, angle_deg=3.0)
    d = dataclasses.replace(design, bumps=(tile,), cap=None)
    z = z0 + 3.0 if kind == "thread" else 0.5 * (z0 + z1)   # a 400 thread is one turn from its foot
    # a fine sweep over two repeats, at two resolutions, and separately across theta = +-pi
    span = 4 * math.pi / tile.repeat
    s, n = _wall_normals(d, np.linspace(0.0, span, 4001), z)
    assert np.allclose(np.linalg.norm(s, axis=1), 1.0, atol=1e-12)
    assert np.max(np.linalg.norm(s - n, axis=1)) > 1e-3          # the relief does bend it
    assert np.all(np.sum(s * n, axis=1) > 0.0)                      # never faces into the glass
    # continuity: halving the step halves the largest jump between neighbours (a seam or a
    # kink-free crease would keep it)
    fine, _ = _wall_normals(d, np.linspace(0.0, span, 8001), z)
    coarse_jump = np.max(np.linalg.norm(np.diff(s, axis=0), axis=1))
    fine_jump = np.max(np.linalg.norm(np.diff(fine, axis=0), axis=1))
    assert fine_jump < 0.6 * coarse_jump
    eps = 1e-9
    sw, _ = _wall_normals(d, np.array([math.pi - eps, -math.pi + eps]), z)
    assert np.linalg.norm(sw[0] - sw[1]) < 1e-5


def test_no_leaks_or_mismatches_with_relief_on_a_half_millimetre_wall():
    """A white furnace stays exactly 1 with relief on a 0.5 mm wall: bent shading normals keep
    R + T = 1, and no branch travels in a medium it is not in."""
    d = tall(0.5, fill=120.0)
    tiles = tuple(BumpTile(k, k, 20.0, 190.0, repeat=40, depth=0.4, sharpness=0.9)
                  for k in ("knurl", "diamond")) + (BumpTile("f", "flutes", 195.0, 290.0, repeat=18, depth=0.8),)
    plain, _ = _furnace(d, spp=2)
    img, st = _furnace(dataclasses.replace(d, bumps=tiles), spp=2)
    assert st.boundaries > 1000
    assert st.escaped_inside == 0 and st.mismatches == 0
    assert np.all(np.abs(img - 1.0) < 1e-9)
    ctx = RenderContext.from_design(dataclasses.replace(d, bumps=tiles), None, 24, 32)
    assert ctx.finish.obj_rows[OUTER_WALL, 1] == 3


def test_a_plain_design_renders_as_before_finishes(bordeaux):
    """The reference was rendered by the tracer before finishes existed (commit f019c7d: the
    40 x 56 Bordeaux, samples 0-2 of every pixel) on this machine's toolchain (numba without
    fastmath, glibc's libm); a machine whose libm rounds differently must re-render it from
    that commit. Re-rendered there when the sample positions became Owen-scrambled Sobol points
    and the environment's arc tangents a polynomial (today's ``kernels/sampling.py`` patched
    into that commit's tree: the pre-finishes tracer with today's sampler). Bit for bit until the intersectors' search windows changed (a ray in the
    liquid no longer meets the outer wall first, whose hit narrowed the window of the inner
    wall's solve; the torus solve starts on the factor that vanishes): the roots then differ
    in their last bits, the radiance by 7e-12, every sample's dominant path is the same."""
    design, assets = bordeaux
    ref = np.load(ROOT / "tests" / "data" / "plain_bordeaux_40x56.npz")
    img, res, ctx = _image(design, assets, 40, 56, 0, 3)
    assert_within_half_rounding(img, ref["bordeaux"])  # (the reference read float32 texels)
    assert np.abs(img - ref["bordeaux"]).max() > 0.0  # and this one half floats
    assert np.array_equal(res.signature.reshape(56, 40), ref["bordeaux_sig"])
    assert ctx.finish.obj_rows[:, 1].sum() == 0 and ctx.cap is None


def test_a_cap_is_drawn_and_a_metal_cap_reflects_like_aluminium(bordeaux):
    design, assets = bordeaux
    plain, _, _ = _image(design, assets)
    capped, res, ctx = _image(dataclasses.replace(design, cap=default_cap("ropp")), assets)
    n_bottle = render_geometry_for(design).obj_i.shape[0]
    on_cap = (res.objects.reshape(plain.shape[:2]) >> n_bottle) & 1 == 1
    assert on_cap.sum() > 5
    assert np.all(np.abs(capped - plain).sum(-1)[on_cap] > 1e-6)
    assert np.array_equal(capped[~on_cap], plain[~on_cap])   # trees that never met the cap
    # straight down onto the flat top: the conductor Fresnel at normal incidence x tint (its
    # GGX gloss of alpha 0.05 moves the microfacet's Fresnel and masking by ~1e-6 only), times
    # what the multiple scattering between microfacets adds: 1 + k (1 - E) / E with E the
    # albedo of that gloss at normal incidence, k = F_avg E_avg / (1 - F_avg (1 - E_avg)), ~1e-3
    white = dataclasses.replace(design, cap=Cap("ropp", "metal", (1.0, 0.8, 0.5)))
    wctx = RenderContext.from_design(white, assets, 8, 8, environment=WHITE)
    top = wctx.cap.z_max
    out, counters = trace_rays(wctx, [[0.3, 0.2, top + 50.0]], [[0.0, 0.0, -1.0]])
    want = []
    for n, k, t in zip((1.57, 1.07, 0.61), (7.74, 6.78, 5.37), (1.0, 0.8, 0.5)):
        gain = _scattering_gain(t * conductor_average(n, k), 0.05)
        assert 1e-4 < gain < 3e-3
        want.append(fresnel_conductor(1.0, n, k) * t * (1.0 + gain))
    assert np.allclose(out[0], want, atol=1e-4)


def _scattering_gain(f_avg, alpha):
    """What multiple scattering adds to a glossy mirror of mean Fresnel ``f_avg`` seen at normal
    incidence, relative to its single bounce: ``k (1 - E) / E``, ``k = F_avg E_avg / (1 - F_avg
    (1 - E_avg))`` (E the F = 1 albedo, from the stored table)."""
    _, mirror, mirror_avg = albedo_tables()
    alphas = np.linspace(0.0, MF.ALPHA_MAX, MF.N_ALPHA)
    e, e_avg = np.interp(alpha, alphas, mirror[:, -1]), np.interp(alpha, alphas, mirror_avg)
    return f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg)) * (1.0 - e) / e


def test_a_plastic_cap_is_lit_by_the_environment_and_bounded_in_a_white_furnace(bordeaux):
    design, assets = bordeaux
    d = dataclasses.replace(design, cap=Cap("screw", "plastic", (0.8, 0.2, 0.1)), lights=())
    ctx = RenderContext.from_design(d, assets, 8, 8, environment=WHITE)
    out, _ = trace_rays(ctx, [[0.3, 0.2, ctx.cap.z_max + 50.0]], [[0.0, 0.0, -1.0]])
    r = ((1.49 - 1) / (1.49 + 1)) ** 2   # coat reflectance at normal incidence
    gain = _scattering_gain(dielectric_average(1.49), 0.1)   # its gloss's multiple scattering: 7e-4
    assert 1e-4 < gain < 2e-3
    assert np.allclose(out[0], r * (1.0 + gain) + (1 - r) * np.array([0.8, 0.2, 0.1]), atol=1e-5)
    lit = RenderContext.from_design(dataclasses.replace(d, lights=(Light((0, 0, 1), (1, 1, 1), 2.0),)),
                                    assets, 8, 8, environment=WHITE)
    out2, _ = trace_rays(lit, [[0.3, 0.2, ctx.cap.z_max + 50.0]], [[0.0, 0.0, -1.0]])
    assert np.allclose(out2[0] - out[0], (1 - r) * np.array([0.8, 0.2, 0.1]) * 2.0 / math.pi, atol=1e-5)


def test_a_cap_follows_the_finish_and_its_tables_are_apart_from_the_bottle(bordeaux):
    design, assets = bordeaux
    cap = default_cap("screw")
    lo = dataclasses.replace(design, shape=round_shape(bordeaux_section(190.0, top=280.0)), cap=cap)
    hi = dataclasses.replace(design, shape=round_shape(bordeaux_section(190.0, top=300.0)), cap=cap)
    a = RenderContext.from_design(lo, assets, 8, 8)
    b = RenderContext.from_design(hi, assets, 8, 8)
    assert b.cap.z_max - a.cap.z_max == pytest.approx(20.0, abs=1e-6)   # rows padded by 1e-9 of size
    assert b.cap.z_min - a.cap.z_min == pytest.approx(20.0, abs=1e-6)
    k = a.geometry.obj_i.shape[0]
    from engine.tracer.kernels.intersect import F_ZMAX
    assert b.scene.geom.obj_f[k, F_ZMAX] - a.scene.geom.obj_f[k, F_ZMAX] == pytest.approx(20.0, abs=1e-6)
    # a cap edit keeps the bottle's tables; a bottle edit that keeps the finish keeps the cap's
    other = RenderContext.from_design(dataclasses.replace(hi, cap=default_cap("ropp")), assets, 8, 8)
    assert other.geometry is b.geometry and other.cap is not b.cap
    builds = finishes.BUILDS[0]
    refilled = dataclasses.replace(hi, liquid=dataclasses.replace(hi.liquid, fill_value=600.0))
    c = RenderContext.from_design(refilled, assets, 8, 8)
    assert c.geometry is not b.geometry and c.cap is b.cap and finishes.BUILDS[0] == builds


@pytest.mark.parametrize("alpha, lost_before", [(0.2, 0.11), (0.4, 0.26)])
def test_frosted_glass_is_deterministic_and_keeps_its_energy_in_a_white_furnace(alpha, lost_before):
    """A view through a bottle frosted all over crosses several rough interfaces from both
    sides (total internal reflection inside the wall included): the mean over the bottle's
    pixels stays 1 within 1.5 % (before the multiple-scattering compensation it lost
    ``lost_before``: 0.89 and 0.74). 16 samples: at 4 a pixel's lobes from a net of four points
    left 2.2 % of noise in the mean over the bottle (1.000-1.002 at 64)."""
    d = tall(3.0, fill=None)
    frost = dataclasses.replace(d, bumps=(BumpTile("frost", "frosted", 10.0, 290.0, repeat=1, alpha=alpha),))
    img, st = _furnace(frost, spp=16)
    again, _ = _furnace(frost, spp=16)
    assert np.array_equal(img, again)
    assert st.escaped_inside == 0 and st.mismatches == 0
    ctx = RenderContext.from_design(frost, None, d.render.width, d.render.height, environment=WHITE)
    rows, cols = np.mgrid[0:d.render.height, 0:d.render.width]
    on = trace_pixels(ctx, cols.ravel(), rows.ravel(), 1, 1).objects != 0   # pixels that met the bottle
    assert on.sum() > 100
    mean = img[on].mean()
    assert abs(mean - 1.0) < 0.015, mean
    assert abs(mean - 1.0) < lost_before / 5
    plain, _ = _furnace(d, spp=4)
    assert not np.array_equal(plain, img)


def test_frosted_glass_scatters_a_view_through_it(bordeaux):
    """A frosted band blurs: neighbouring pixels through it differ less from their mean
    (smooth environment gradients stay) but the image differs from the clear one."""
    design, assets = bordeaux
    f = dataclasses.replace(design, bumps=(BumpTile("frost", "frosted", 20.0, 200.0, repeat=1, alpha=0.3),))
    a, _, _ = _image(design, assets)
    b, res, _ = _image(f, assets)
    assert np.abs(a - b).sum() > 1.0
    assert res.counters[1] == 0 and res.counters[2] == 0


def test_a_frosted_pixel_draws_its_lobes_from_a_net_unbiased_and_with_less_scatter():
    """Through the frosted sample's band, a pixel's anti-aliasing samples draw each rough
    surface's lobe from a net over the samples (:func:`~engine.tracer.kernels.surface.lobe_uniforms`).
    Against the same sample positions traced with independent lobes (query rays, each from its
    own stream; one batch, so no two pixels share streams): the means agree within their
    standard errors (no bias), and the means of blocks of 64 samples scatter less (measured at
    179 x 238: 0.06-0.56 of the variance)."""
    from engine.tracer.kernels.sampling import C_EYE, camera_ray, pixel_offsets_batch
    design, assets = load_project(ROOT / "resources" / "frosted_logo.glassbench")
    w, h, n, blocks = 60, 80, 64, 16
    pixels = ((30, 47), (27, 53), (33, 50), (23, 40), (32, 33), (28, 45), (31, 38), (26, 58))
    ctx = RenderContext.from_design(design, assets, w, h)
    ks = np.arange(1, 1 + blocks * n, dtype=np.int64)
    dirs = []
    for c, r in pixels:
        off = np.zeros((len(ks), 2))
        pixel_offsets_batch(np.full(len(ks), r * w + c, np.int64), ks, off)
        dirs += [camera_ray(ctx.cam, c + fx, r + fy) for fx, fy in off]
    out, _ = trace_rays(ctx, np.tile(ctx.cam[C_EYE:C_EYE + 3], (len(dirs), 1)), np.array(dirs))
    free_all = out.mean(axis=1).reshape(len(pixels), blocks, n).mean(axis=2)
    z, ratio = [], []
    for (c, r), free in zip(pixels, free_all):
        net = np.array([trace_pixels(ctx, [c], [r], 1 + b * n, n).sums[0].mean() / n for b in range(blocks)])
        z.append((net.mean() - free.mean()) / (math.hypot(net.std(ddof=1), free.std(ddof=1)) / math.sqrt(blocks)))
        ratio.append(net.var(ddof=1) / free.var(ddof=1))
    assert max(abs(v) for v in z) < 4.0, z
    assert abs(np.mean(z)) < 4.0 / math.sqrt(len(z)), z
    assert np.mean(ratio) < 0.8, ratio


@pytest.mark.parametrize("data, words", [(b"\x89PNG\r\n\x1a\n not really", "cannot be decoded"),
                                         (b"", "cannot be decoded")])
def test_a_hostile_relief_image_is_refused_with_a_clear_error(bordeaux, data, words):
    design, assets = bordeaux
    tile = BumpTile("logo", "emboss", 80.0, 140.0, repeat=1, asset="logo.png", width_deg=60.0)
    d = dataclasses.replace(design, bumps=(tile,))
    with pytest.raises(ReliefImageError, match=words) as info:
        RenderContext.from_design(d, {**assets, "logo.png": data}, 8, 8)
    assert "logo.png" in str(info.value)


def test_an_embossed_logo_bends_normals_only_where_it_is():
    from make_finish_samples import frosted_logo, logo_png
    d, assets = frosted_logo(logo_png(64))
    d = dataclasses.replace(d, bumps=d.bumps[1:])     # the logo alone
    tile = d.bumps[0]
    th = np.linspace(-math.pi, math.pi, 721)[:-1]
    s, n = _wall_normals(d, th, 0.5 * (tile.z0 + tile.z1), assets)
    bent = np.linalg.norm(s - n, axis=1) > 1e-6
    centre = math.radians(tile.angle_deg)
    inside = np.abs(np.angle(np.exp(1j * (th - centre)))) < math.radians(tile.width_deg) / 2
    assert bent.any() and not bent[~inside].any()


def test_a_design_edit_of_bumps_or_cap_renders_anew():
    from engine.tracer.job import VISUAL_FIELDS
    assert {"bumps", "cap"} <= VISUAL_FIELDS


@pytest.mark.parametrize("kind", ["screw", "crown", "cork", "ropp", "lug"])
def test_every_closure_renders_without_leaks_or_mismatches(bordeaux, kind):
    """Skirts and corks keep 0.3 mm of air from the glass cylinder they follow: at 0.05 mm the
    roll-on cap's skirt caught grazing rays until one was on the wrong side."""
    design, assets = bordeaux
    _, res, ctx = _image(dataclasses.replace(design, cap=default_cap(kind)), assets, 60, 80, 0, 2)
    assert res.counters[1] == 0 and res.counters[2] == 0
    assert ((res.objects >> ctx.geometry.obj_i.shape[0]) != 0).sum() > 20


@pytest.mark.parametrize("name, cap, bumps", [("knurled_jar", "lug", 1), ("threaded_bottle", "screw", 1),
                                               ("cut_decanter", None, 3), ("frosted_logo", None, 2)])
def test_the_finish_samples_load_and_render_without_leaks(name, cap, bumps):
    from engine.appearance.closures import closure_trade
    design, assets = load_project(ROOT / "resources" / f"{name}.glassbench")
    assert len(design.bumps) == bumps and (design.cap.kind if design.cap else None) == cap
    img, res, ctx = _image(design, assets, 24, 32)
    assert res.counters[1] == 0 and res.counters[2] == 0 and np.all(np.isfinite(img))
    assert ctx.finish.obj_rows[:, 1].sum() >= 1
    closure, overall = closure_trade(design)
    assert (closure is None) == (cap is None) and overall >= design.shape.z_top


def test_a_cork_the_wine_reaches_is_wet_below_the_fill_line(bordeaux):
    """Brimful, the wine stands around and under the cork: below the fill line the cork is
    surrounded by liquid (its capsule outside the neck stays in air), so no ray mismatches."""
    design, assets = bordeaux
    full = dataclasses.replace(design, cap=default_cap("cork"),
                               liquid=dataclasses.replace(design.liquid, fill_value=775.0))
    _, res, ctx = _image(full, assets, 60, 80, 0, 2)
    assert ctx.geometry.fill_height > ctx.cap.z_min
    assert ctx.cap.inside == (True, False)
    assert res.counters[1] == 0 and res.counters[2] == 0


# ------------------------------------------------------------------ plastic caps in shadow
def _stepped_design(liquid=None, light=(0.0, 0.0, -1.0)):
    """A 250 mm bottle with a flat 3 mm shoulder (1 mm rise over 24) at 200 mm under a 28 mm neck, a
    plastic screw cap and one light (intensity 2): a vertical shadow
    ray from the skirt's rim meets the shoulder and the base at (nearly: 2.4 deg) normal incidence."""
    from engine.geometry.section import Section
    from engine.geometry.segments import Line
    from engine.geometry.shape import BottleShape
    from engine.model.design import Camera, Glass, RenderSettings
    segs = (Line((0, 0), (38, 0)), Line((38, 0), (38, 200)), Line((38, 200), (14, 201)), Line((14, 201), (14, 250)))
    shape = BottleShape("round", {"profile": Section(segs, (False, False, False))}, 3.0, 6.0)
    d = Design(shape=shape, glass=Glass(ior=1.5), liquid=liquid, cap=Cap("screw", "plastic", (0.8, 0.2, 0.1)),
               lights=(Light(light, (1.0, 1.0, 1.0), 2.0),),
               camera=Camera(eye=(0, -700, 150), target=(0, 0, 150), fov_y_deg=25),
               render=RenderSettings(width=16, height=16, spp=1, max_depth=64))
    return d


def _stepped(liquid=None, light=(0.0, 0.0, -1.0)):
    """:func:`_stepped_design` compiled in a black environment."""
    black = EnvironmentMap(np.zeros((4, 8, 3), np.float32))
    return RenderContext.from_design(_stepped_design(liquid, light), None, 16, 16, environment=black)


def _unshadowed(ctx, cos=1.0):
    """What the light alone gives a plastic part facing it at ``cos`` without a shadow:
    ``(1 - R_coat) albedo E cos / pi`` (RGB)."""
    mat = ctx.scene.mat_f[-1]
    r, _ = fresnel_dielectric(1.0, mat[MF_COAT_IOR])
    return (1.0 - r) * mat[MF_ALBEDO:MF_ALBEDO + 3] * 2.0 * cos / math.pi


def test_a_plastic_caps_rim_lit_from_below_is_shadowed_by_the_glass_and_the_wine():
    """The skirt's flat rim (14.86..15.14 mm from the axis) faces down; the light is straight
    below. Its shadow ray crosses the flat shoulder (in and out) and the base (in and out), each
    at normal incidence: it passes (1 - 0.04)^4 = 0.849 of the light (it was 1: no shadow rays);
    black wine filled to 100 mm absorbs all of it."""
    ctx = _stepped()
    rim = ctx.cap.z_min
    assert rim > 200.0
    out, _ = trace_rays(ctx, [[15.0, 0.0, rim - 1.0]], [[0.0, 0.0, 1.0]])
    ratio = out[0] / _unshadowed(ctx)
    # what the coat's reflection brings back (it is lit only through the rim) is ~0.2 %
    assert np.allclose(ratio, 0.96 ** 4, atol=5e-3), ratio
    wine = Liquid(ior=1.33, absorption=(50.0, 50.0, 50.0), fill_value=100.0)
    dark, _ = trace_rays(_stepped(wine), [[15.0, 0.0, rim - 1.0]], [[0.0, 0.0, 1.0]])
    assert np.all(dark[0] < 1e-3 * _unshadowed(ctx)), dark


def test_the_inside_of_a_plastic_skirt_is_shadowed_by_the_skirt_across_the_neck():
    """From the 0.3 mm air gap between the neck and the skirt, a ray meets the skirt's inner
    face, lit by a light straight across the neck; the shadow ray passes the neck's glass and
    meets the opposite side of the skirt (opaque): no light there (it had the full light)."""
    ctx = _stepped(light=(-1.0, 0.0, 0.0))
    out, _ = trace_rays(ctx, [[14.15, 0.0, 245.0]], [[1.0, 0.0, 0.0]])
    assert np.all(out[0] < 1e-3 * _unshadowed(ctx)), out
    # the same light on the outside of the skirt's far side, unshadowed: all of it
    lit = _stepped(light=(-1.0, 0.0, 0.0))
    seen, _ = trace_rays(lit, [[-40.0, 0.0, 245.0]], [[1.0, 0.0, 0.0]])
    assert np.all(seen[0] > 0.5 * _unshadowed(ctx))


def test_a_light_edit_relights_a_plastic_cap(bordeaux):
    """Lights shade a closure's diffuse parts too: a job after a light edit of a capped design
    without labels renders anew (it used to keep the previous film, lights shading labels only)
    and equals a full render."""
    from engine.tracer.job import RenderJob
    from engine.tracer.job_options import Replaces
    from engine.tracer.sampling import Sampling

    def job(d, **kw):
        j = RenderJob(d, assets, width=24, height=32, spp=1, threads=1, sampling=Sampling(adaptive=False), **kw).start()
        j.wait()
        assert j.error is None
        return j

    design, assets = bordeaux
    d = dataclasses.replace(design, cap=Cap("screw", "plastic", (0.8, 0.2, 0.1)), labels=())
    first = job(d)
    d2 = dataclasses.replace(d, lights=(Light((0.0, -1.0, 1.0), (1.0, 1.0, 1.0), 3.0),))
    again, full = job(d2, replaces=Replaces(first, {"lights"})), job(d2)
    np.testing.assert_array_equal(again.image(), full.image())
    assert not np.array_equal(again.image(), first.image())


def _rim_hit(d):
    """The surface layer's answer ``(children, r, g, b, bits)`` for a ray straight up onto the
    flat rim of the -x side of ``d``'s plastic skirt (:func:`_stepped_design`), 15 mm from
    the axis, with the kernels' own scratch (as the integrator calls it)."""
    from engine.tracer.kernels.queries import hits
    from engine.tracer.kernels.records import Hit, Ray, Scratch
    from engine.tracer.kernels.surface import interaction, scatter
    ctx = RenderContext.from_design(d, None, 8, 8)
    o, dr = np.array([[-15.0, 0.0, ctx.cap.z_min - 1.0]]), np.array([[0.0, 0.0, 1.0]])
    t, k, part, n = np.zeros(1), np.zeros(1, np.int64), np.zeros(1, np.int64), np.zeros((1, 3))
    hits(ctx.scene.geom, o, dr, np.zeros(1, np.int64), np.full(1, -1, np.int64), np.zeros(1, np.int64), t, k, part, n)
    assert k[0] == ctx.geometry.obj_i.shape[0]          # the cap's part
    tables = ctx.tables()
    it = interaction(tables, Ray(*o[0], *dr[0]), Hit(t[0], int(k[0]), int(part[0]), *n[0]), -1, np.uint64(0))
    assert it.inc == 0  # the ray comes up through the air
    s = scatter(tables, it, 1.0, 1.0, 1.0, np.uint64(1), np.zeros((4, 8)),
                Scratch(np.zeros(16), np.zeros(5), np.zeros((64, 2))))
    return s.nk, s.er, s.eg, s.eb, s.bits


def test_a_label_a_plastic_parts_shadow_ray_crosses_enters_its_record():
    """The rim of a plastic skirt lit by a light below on the other side: its shadow ray crosses
    the neck under the skirt and leaves it at z ~ 221 mm through a label there. The hit reports
    the label's object-mask bit (so a relabel traces the pixel again) and is darker than with the
    label turned away from the shadow ray's path (the integrator ORs the bits into the sample's
    mask)."""
    from engine.model.design import Label
    from engine.tracer.kernels.labels import LABEL_BIT0
    neck_label = Label(z_mm=221.0, angle_deg=0.0, height_mm=10.0, width_mm=20.0, diffuse=0.7)
    d = dataclasses.replace(_stepped_design(light=(1.0, 0.0, -0.6)), labels=(neck_label,))
    nk, r, g, b, bits = _rim_hit(d)
    assert bits == 1 << LABEL_BIT0
    away = dataclasses.replace(d, labels=(dataclasses.replace(neck_label, angle_deg=90.0),))
    nk2, r2, g2, b2, bits2 = _rim_hit(away)
    assert bits2 == 0
    assert r2 > r + 0.05 and nk == nk2 == 1


def test_a_closure_shadows_a_label_under_its_skirt():
    """A label on the neck just under a plastic skirt, lit by a steep light: the label's shadow
    ray meets the skirt's rim (closure parts are opaque to shadow rays; before, it passed through
    a part as through air, so the cap changed nothing there)."""
    from engine.model.design import Label
    black = EnvironmentMap(np.zeros((4, 8, 3), np.float32))
    neck_label = Label(z_mm=232.5, angle_deg=0.0, height_mm=9.0, width_mm=20.0, diffuse=0.7, specular=0.0)
    d = dataclasses.replace(_stepped_design(light=(0.2, 0.0, 1.0)), labels=(neck_label,))
    out = {}
    for name, design in (("capped", d), ("bare", dataclasses.replace(d, cap=None))):
        ctx = RenderContext.from_design(design, None, 8, 8, environment=black)
        out[name], counters = trace_rays(ctx, [[40.0, 0.0, 236.0]], [[-1.0, 0.0, 0.0]])
        assert counters[1] == 0 and counters[2] == 0
    assert np.all(out["bare"][0] > 0.01)
    assert np.all(out["capped"][0] < 1e-3 * out["bare"][0]), out


def test_query_rays_draw_from_the_streams_the_caller_names():
    """``trace_rays``'s ray ``i`` draws from stream ``seed + i``: the same seed repeats a call
    bit for bit, another seed gives a frosted ray other lobes (independent estimates across
    calls), and a call's tail traced alone with the seed moved on is the same tail."""
    frost = dataclasses.replace(tall(3.0, fill=None),
                                bumps=(BumpTile("frost", "frosted", 10.0, 290.0, repeat=1, alpha=0.3),))
    ctx = RenderContext.from_design(frost, None, 8, 8)
    o = np.tile([0.0, -400.0, 150.0], (64, 1))
    d = np.tile([0.0, 1.0, 0.0], (64, 1))
    a, counters = trace_rays(ctx, o, d)
    assert counters.sum() > 0
    b, _ = trace_rays(ctx, o, d, seed=0)
    c, _ = trace_rays(ctx, o, d, seed=64)
    assert np.array_equal(a, b)
    assert np.unique(a[:, 0]).size > 32  # the lobes scatter the 64 copies of one ray
    assert not np.any(np.all(a == c, axis=1))  # no ray of the second call repeats the first's
    tail, _ = trace_rays(ctx, o[32:], d[32:], seed=32)
    assert np.array_equal(tail, a[32:])
    with pytest.raises(ValueError, match="seed"):
        trace_rays(ctx, o, d, seed=-1)
