"""Camera (SPEC 2), sample seeding and the environment lookup (SPEC 3)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from engine.tracer.camera import PinholeCamera, pixel_offsets
from engine.model.design import Camera, Environment
from engine.tracer.tables.environment import EnvironmentMap, environment_from_design, studio_texels


def _cam(w=40, h=20):
    return PinholeCamera.from_design(Camera(eye=(0, -100, 0), target=(0, 0, 0), up=(0, 0, 1), fov_y_deg=30), w, h)


def test_image_centre_looks_forward_and_pixel_0_0_is_top_left():
    cam = _cam()
    _, d = cam.rays(np.array([20.0, 0.0, 40.0]), np.array([10.0, 0.0, 20.0]))
    assert np.allclose(d[0], [0, 1, 0])
    # Top-left corner: left (-x when looking along +y with z up) and up.
    assert d[1, 0] < 0 and d[1, 2] > 0
    # Bottom-right corner: right and down.
    assert d[2, 0] > 0 and d[2, 2] < 0


def test_vertical_field_of_view_is_the_full_angle():
    cam = _cam(40, 20)
    _, d = cam.rays(np.array([20.0, 20.0]), np.array([0.0, 20.0]))
    assert abs(math.degrees(math.acos(np.dot(d[0], d[1]))) - 30.0) < 1e-9
    # Horizontal extent follows the aspect ratio: sx = t * w / h at the right edge.
    _, d = cam.rays(np.array([40.0]), np.array([10.0]))
    assert abs(d[0, 0] / d[0, 1] - math.tan(math.radians(15)) * 2) < 1e-12


def test_sample_positions_are_a_pure_function_of_pixel_and_index():
    a = pixel_offsets(np.arange(1000), np.full(1000, 3))
    b = pixel_offsets(np.arange(1000)[::-1], np.full(1000, 3))[::-1]
    assert np.array_equal(a, b)
    assert np.all((a >= 0) & (a < 1))
    assert len(np.unique(a[:, 0])) == 1000  # pixels are decorrelated
    assert np.array_equal(pixel_offsets([5, 6], [0, 0]), [[0.5, 0.5], [0.5, 0.5]])  # sample 0: the centre


@pytest.mark.parametrize("m", [1, 2, 3, 4, 6])
def test_every_power_of_two_prefix_of_a_pixels_samples_is_a_net(m):
    """Samples 1..2^m of every pixel: one in each of the 2^m strata of every elementary shape
    (2^a x 2^(m-a) cells), as a (0, m, 2)-net in base 2 has; and over many pixels each sample
    is uniform on the square (the scramble is per pixel)."""
    n, pixels = 2 ** m, np.arange(300) * 7919
    s = pixel_offsets(np.repeat(pixels, n), np.tile(np.arange(1, n + 1), len(pixels))).reshape(len(pixels), n, 2)
    for a in range(m + 1):
        cells = np.floor(s[..., 0] * 2 ** a).astype(int) * 2 ** (m - a) + np.floor(s[..., 1] * 2 ** (m - a)).astype(int)
        assert all(len(set(c)) == n for c in cells), f"{2 ** a} x {2 ** (m - a)} strata"
    first = s[:, 0]
    assert abs(first.mean() - 0.5) < 0.05 and abs(first.std() - (1 / 12) ** 0.5) < 0.03


def _spec_lookup(tex, d):
    """SPEC 3 written out scalar by scalar, as an independent check."""
    h, w = tex.shape[:2]
    phi = math.atan2(d[1], d[0])
    u = (phi / (2 * math.pi)) % 1.0
    v = math.acos(max(-1.0, min(1.0, d[2]))) / math.pi
    x = (u * w - 0.5) % w
    y = v * (h - 1)
    i0 = math.floor(x)
    i1 = (i0 + 1) % w
    j0 = min(math.floor(y), h - 2)
    j1 = j0 + 1
    fx, fy = x - i0, y - j0
    return ((tex[j0, i0] * (1 - fx) + tex[j0, i1] * fx) * (1 - fy)
            + (tex[j1, i0] * (1 - fx) + tex[j1, i1] * fx) * fy)


def test_environment_lookup_matches_the_spec_formula():
    rng = np.random.default_rng(1)
    tex = rng.random((9, 16, 3)).astype(np.float32)
    env = EnvironmentMap(tex)
    d = rng.normal(size=(300, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d[:3] = [[0, 0, 1], [0, 0, -1], [1, -1e-12, 0]]  # poles and the u = 0 seam
    d[:3] /= np.linalg.norm(d[:3], axis=1, keepdims=True)
    got = env.lookup(d)
    want = np.array([_spec_lookup(tex.astype(float), di) for di in d])
    assert np.allclose(got, want, atol=1e-6)


def test_texel_centres_return_the_texel_and_poles_are_rows_0_and_last():
    tex = np.zeros((5, 8, 3), np.float32)
    tex[2, 3] = [1, 2, 3]
    tex[0, :] = 7
    tex[4, :] = 9
    env = EnvironmentMap(tex)
    u, v = (3 + 0.5) / 8, 2 / 4
    phi, theta = u * 2 * math.pi, v * math.pi
    d = np.array([[math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)],
                  [0, 0, 1], [0, 0, -1]])
    out = env.lookup(d)
    assert np.allclose(out[0], [1, 2, 3], atol=1e-6)
    assert np.allclose(out[1], 7) and np.allclose(out[2], 9)


def test_scale_and_rotation_turn_the_map_about_z():
    rng = np.random.default_rng(2)
    tex = rng.random((6, 12, 3)).astype(np.float32)
    d = rng.normal(size=(50, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    a = math.radians(40)
    turned = np.stack([math.cos(a) * d[:, 0] - math.sin(a) * d[:, 1],
                       math.sin(a) * d[:, 0] + math.cos(a) * d[:, 1], d[:, 2]], 1)
    base = EnvironmentMap(tex).lookup(d)
    rot = EnvironmentMap(tex, scale=2.5, rotation_deg=40).lookup(turned)
    assert np.allclose(rot, 2.5 * base, atol=1e-9)


def test_studio_and_file_environments(tmp_path):
    import OpenImageIO as oiio

    studio = environment_from_design(Environment(kind="studio"))
    up, down = studio.lookup(np.array([[0, 0, 1.0], [0, 0, -1.0]]))
    assert np.all(studio.texels >= 0) and np.all(np.isfinite(studio.texels))
    assert up.mean() > 3 * down.mean()  # bright ceiling over a dark floor
    assert studio_texels().max() >= 6.0  # the key light
    img = np.full((4, 8, 3), 0.25, np.float32)
    path = tmp_path / "e.exr"
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(8, 4, 3, oiio.FLOAT))
    out.write_image(img)
    out.close()
    for item in (path.read_bytes(), str(path)):
        env = environment_from_design(Environment(kind="file", asset="e.exr", scale=2.0), {"e.exr": item})
        assert np.allclose(env.lookup(np.array([[1.0, 0, 0]])), 0.5)
    with pytest.raises(ValueError):
        environment_from_design(Environment(kind="file", asset="missing.exr"), {})


def test_kernel_arc_tangent_is_within_its_stated_error_everywhere():
    """The environment kernel's polynomial ``atan2`` against libm: every octant, both axes, the
    seams at +-pi, tiny and huge ratios; its bound (2.2e-11 rad) moves a lookup by 4e-9 texel."""
    from engine.tracer.kernels.sampling import atan2_poly

    rng = np.random.default_rng(5)
    pts = list(rng.normal(size=(20000, 2)))
    pts += [(y * s, x * s2) for y, x in [(0.0, 1.0), (1.0, 0.0), (1.0, 1.0), (1e-300, 1.0), (1.0, 1e-300),
                                        (1e-12, 1.0), (1.0, 1e-12), (0.41421356, 1.0)]
            for s in (1.0, -1.0) for s2 in (1.0, -1.0)]
    err = max(abs(atan2_poly(y, x) - math.atan2(y, x)) for y, x in pts if not (y == 0.0 and x < 0.0))
    assert err < 2.5e-11
    assert atan2_poly(0.0, 0.0) == 0.0
    # the negative x axis is the seam: either side of it is the same azimuth, u = 1/2
    assert abs(abs(atan2_poly(0.0, -1.0)) - math.pi) < 1e-15


def test_kernel_environment_lookup_matches_the_spec_formula():
    """The compiled lookup every render uses, against SPEC 3 written out with libm, on a map
    with a steep checker (so an angle error would show), at the poles and the seam."""
    from engine.tracer.kernels.sampling import env_lookup

    rng = np.random.default_rng(6)
    tex = (rng.random((64, 128, 3)) * 10).astype(np.float32)
    d = rng.normal(size=(3000, 3))
    d[:4] = [[0, 0, 1], [0, 0, -1], [-1, 1e-13, 0], [-1, -1e-13, 0]]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    got = np.array([env_lookup(tex, 1.0, 0.0, *di) for di in d])
    want = np.array([_spec_lookup(tex.astype(float), di) for di in d])
    assert np.max(np.abs(got - want)) < 1e-7


def test_half_texels_keep_eleven_bits_and_scale_a_bright_map_by_a_power_of_two():
    """The kernels' copy of a map: every texel within 2**-11 of its value (normal half floats;
    the faintest within 2**-25 absolute); a map brighter than a half float holds is divided by a
    power of two (exact) that ``factor`` gives back; non-finite texels are cleaned first."""
    from engine.tracer.tables.environment import HALF_MAX, half_texels

    rng = np.random.default_rng(7)
    tex = (10.0 ** rng.uniform(-9, 4, size=(32, 64, 3))).astype(np.float32)
    bits, factor = half_texels(tex)
    back = bits.view(np.float16).astype(np.float64) * factor
    assert factor == 1.0 and bits.dtype == np.uint16 and not bits.flags.writeable
    assert np.all(np.abs(back - tex) <= 2.0 ** -11 * tex + 2.0 ** -25)
    assert np.abs(back - tex).max() > 0.0  # (it does round)
    bright = tex.copy()
    bright[3, 5] = (1e9, 5e4, 1.0)  # a sun: MAX_TEXEL
    bits, factor = half_texels(bright)
    back = bits.view(np.float16).astype(np.float64) * factor
    assert factor == 2.0 ** math.ceil(math.log2(1e9 / HALF_MAX)) and np.all(np.isfinite(back))
    assert np.all(np.abs(back - bright) <= 2.0 ** -11 * bright + 2.0 ** -25 * factor)
    bad = tex.copy()
    bad[0, 0] = (np.inf, np.nan, -1.0)
    bits, factor = half_texels(bad)
    assert np.all(np.isfinite(bits.view(np.float16))) and factor > 1.0  # +inf became MAX_TEXEL


def test_half_texels_of_a_shared_map_are_made_once():
    """The studio (read-only, shared) is converted once, whatever the number of renders; a
    writable array, which may change, is converted each time."""
    from engine.tracer.tables.environment import half_texels

    studio = studio_texels()
    assert half_texels(studio)[0] is half_texels(studio)[0]
    mine = np.array(studio)
    first = half_texels(mine)[0]
    mine[0, 0] = 5.0
    assert half_texels(mine)[0] is not first and half_texels(mine)[0][0, 0, 0] == np.float16(5.0).view(np.uint16)


def test_kernel_lookup_of_half_texels_is_the_float32_lookup_within_their_rounding():
    """The render's lookup (half floats) against the float32 one and SPEC 3, seam and poles
    included: bilinear weights are positive, so a lookup moves by at most 2**-11 of itself."""
    from engine.tracer.tables.environment import half_texels
    from engine.tracer.kernels.sampling import env_lookup

    rng = np.random.default_rng(8)
    tex = (rng.random((64, 128, 3)) * 10).astype(np.float32)
    bits, factor = half_texels(tex)
    d = rng.normal(size=(3000, 3))
    d[:4] = [[0, 0, 1], [0, 0, -1], [-1, 1e-13, 0], [-1, -1e-13, 0]]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    half = np.array([env_lookup(bits, 2.0 * factor, 0.0, *di) for di in d])
    full = np.array([env_lookup(tex, 2.0, 0.0, *di) for di in d])
    assert np.all(np.abs(half - full) <= 2.0 ** -11 * full + 1e-12)
    rounded = bits.view(np.float16).astype(np.float64) * factor  # SPEC 3 on the rounded texels
    want = 2.0 * np.array([_spec_lookup(rounded, di) for di in d])
    assert np.max(np.abs(half - want)) < 1e-6


def test_a_render_sees_a_bright_map_at_its_brightness():
    """A map beyond half-float range (factor > 1) reaches the image at its true radiance: a
    camera ray that meets no bottle returns the map's value in its direction."""
    from engine.tracer.context import RenderContext, trace_rays
    from tests.test_tracer import simple_design

    tex = np.full((8, 16, 3), 2.0e6, np.float32)
    tex[:, :, 1] = 3.0
    ctx = RenderContext.from_design(simple_design(None), None, 8, 8, environment=EnvironmentMap(tex, 0.5))
    assert ctx.env_params[2] > 1.0
    rad, _ = trace_rays(ctx, [[0.0, -500.0, 900.0]], [[0.0, 0.0, 1.0]])
    assert np.allclose(rad[0], [1.0e6, 1.5, 1.0e6], rtol=2.0 ** -11)


def test_without_half_float_conversion_the_kernels_read_float32(monkeypatch):
    """A CPU that cannot convert half floats in one instruction gets the float32 texels."""
    from engine.tracer.tables import environment as E

    monkeypatch.setattr(E, "_converts_halves", lambda: False)
    tex = studio_texels()
    got, factor = E.half_texels(tex)
    assert got.dtype == np.float32 and factor == 1.0 and np.array_equal(got, tex)


@pytest.mark.parametrize("m", [2, 4, 6])
def test_a_rough_surfaces_padded_net_is_a_net_in_every_aligned_block_and_apart_from_the_pixels(m):
    """A rough surface's two lobe uniforms over a pixel's samples (:func:`padded_sobol2`): each
    aligned block of ``2^m`` sample indices (the first ``2^m``, and the second half of a
    doubling round) is a (0, m, 2)-net whatever the node's seed; over many seeds each point is
    uniform; and the shuffled index pairs them with the pixel's positions without correlation."""
    from engine.tracer.kernels.sampling import padded_sobol2
    n = 2 ** m
    seeds = [np.uint64(s * 0x9E3779B97F4A7C15 % 2 ** 64) for s in range(1, 201)]
    for start in (0, n, 5 * n):
        for seed in seeds[:40]:
            s = np.array([padded_sobol2(i, seed) for i in range(start, start + n)])
            for a in range(m + 1):
                cells = np.floor(s[:, 0] * 2 ** a).astype(int) * 2 ** (m - a) + np.floor(s[:, 1] * 2 ** (m - a)).astype(int)
                assert len(set(cells)) == n, f"{2 ** a} x {2 ** (m - a)} strata, block at {start}"
    first = np.array([padded_sobol2(3, seed) for seed in seeds])
    assert abs(first[:, 0].mean() - 0.5) < 0.05 and abs(first[:, 1].std() - (1 / 12) ** 0.5) < 0.03
    # against the pixel's own positions (sample k >= 1 is index k - 1): no correlation
    lobes = np.array([padded_sobol2(i, seeds[7]) for i in range(256)])
    pos = pixel_offsets(np.full(256, 4242), np.arange(1, 257))
    assert abs(np.corrcoef(lobes[:, 0], pos[:, 0])[0, 1]) < 0.2
    assert not np.allclose(np.sort(lobes[:, 0]), np.sort(pos[:, 0]))  # (another scramble)
