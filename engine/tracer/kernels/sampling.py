"""Camera rays, sample positions, seeds and the environment lookup, compiled.

Design rule: everything random is a pure function of integers (counter-based hashing), so a
sample, and every branch of its tree, can be replayed from (pixel, sample, branch) alone and
the image never depends on threads or tile order. Sample 0 of a pixel is its centre; samples
``k >= 1`` are the points ``k - 1`` of the two-dimensional Sobol sequence, Owen-scrambled per
pixel (:func:`pixel_offset`), so every power-of-two prefix of them is a (0, m, 2)-net: the
first four anti-aliasing samples of a pixel fall one in each quarter, the first sixteen one in
each cell of its 4 x 4 grid, and edge pixels converge faster than with independent samples.
A rough surface's lobe is a pixel's integral too: its two uniforms come from another such net
over the same samples (:func:`padded_sobol2`, seeded by the node's place in the tree), so a
frosted pixel's samples spread over the lobe as its positions spread over the pixel (measured
on the frosted sample: 0.06-0.56 of the variance of independent lobes at 256 samples, and the
window's image 1.47 -> 1.22 display levels RMS at its own size in the same time). Branches of
Russian roulette and the ground's probes keep their own streams.
Camera and environment follow ../shared/oracle/SPEC.md sections 2 and 3 exactly.
"""
from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic, overload

from .jit import INLINE, JIT

_M32 = np.uint64(0xFFFFFFFF)
# camera array columns: eye (3), forward (3), right (3), up (3), tan(fov/2), width, height
C_EYE, C_F, C_R, C_U, C_TAN, C_W, C_H = 0, 3, 6, 9, 12, 13, 14
C_COLS = 15


@njit(**JIT)
def mix64(x):
    """SplitMix64 finaliser: a bijective, well-mixed hash of a uint64."""
    z = np.uint64(x) + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(**JIT)
def branch_seed(parent, child):
    """Seed of child ``child`` (0, 1, ...) of a branch seeded ``parent``."""
    return mix64(parent ^ mix64(np.uint64(child) + np.uint64(0x632BE59BD9B4E019)))


@njit(**JIT)
def uniform01(seed, k):
    """The ``k``-th uniform number in [0, 1) of a branch's stream (53 bits)."""
    return float(mix64(seed ^ mix64(np.uint64(k) + np.uint64(0xD1B54A32D192ED03))) >> np.uint64(11)) * (2.0 ** -53)


@njit(**INLINE)
def _reverse32(x):
    """The 32 low bits of ``x`` (uint64) in reverse order."""
    x = ((x >> np.uint64(1)) & np.uint64(0x55555555)) | ((x & np.uint64(0x55555555)) << np.uint64(1))
    x = ((x >> np.uint64(2)) & np.uint64(0x33333333)) | ((x & np.uint64(0x33333333)) << np.uint64(2))
    x = ((x >> np.uint64(4)) & np.uint64(0x0F0F0F0F)) | ((x & np.uint64(0x0F0F0F0F)) << np.uint64(4))
    x = ((x >> np.uint64(8)) & np.uint64(0x00FF00FF)) | ((x & np.uint64(0x00FF00FF)) << np.uint64(8))
    return ((x >> np.uint64(16)) | (x << np.uint64(16))) & _M32


@njit(**INLINE)
def _nested_hash(x, seed):
    """A 32-bit hash in which output bit ``j`` depends only on input bits ``0..j`` and the seed
    (an addition, then products with even constants, whose bit ``j`` sees only lower bits):
    applied to a bit-reversed fraction it flips each binary digit according to the digits
    above it, which is Owen's nested scrambling (Laine and Karras 2011; these constants from
    Burley, "Practical hash-based Owen scrambling", JCGT 2020)."""
    x = (x + seed) & _M32
    x ^= (x * np.uint64(0x6C50B47C)) & _M32
    x ^= (x * np.uint64(0xB82F1E52)) & _M32
    x ^= (x * np.uint64(0xC7AFE638)) & _M32
    x ^= (x * np.uint64(0x8D22F6E6)) & _M32
    return x


@njit(**INLINE)
def _sobol2(i):
    """The second coordinate of Sobol point ``i`` (primitive polynomial ``x + 1``: direction
    numbers ``v_1 = 1/2``, ``v_{j+1} = v_j xor v_j / 2``), as a 32-bit fraction."""
    y = np.uint64(0)
    v = np.uint64(0x80000000)
    while i != np.uint64(0):
        if i & np.uint64(1):
            y ^= v
        v ^= v >> np.uint64(1)
        i >>= np.uint64(1)
    return y


@njit(**JIT)
def pixel_offset(pixel, k):
    """Sub-pixel position in [0, 1)^2 of sample ``k`` of pixel index ``row * width + col``.

    ``k = 0`` is the centre. ``k >= 1`` is Sobol point ``k - 1`` with each coordinate
    Owen-scrambled by seeds hashed from the pixel: the first coordinate of point ``i`` is
    ``i`` bit-reversed (van der Corput), so its reversed form is ``i`` itself; the scramble
    hashes the reversed digits and reverses back. Every prefix of ``2^m`` anti-aliasing
    samples keeps one point in each of ``2^m`` equal strata of every elementary shape, and
    each point alone is uniform on the square. Indices wrap at ``2^32``."""
    if k == 0:
        return 0.5, 0.5
    h = mix64(np.uint64(pixel) ^ np.uint64(0x5851F42D4C957F2D))
    i = np.uint64(k - 1) & _M32
    x = _reverse32(_nested_hash(i, h & _M32))
    y = _reverse32(_nested_hash(_reverse32(_sobol2(i)), h >> np.uint64(32)))
    return (float(x) + 0.5) * (2.0 ** -32), (float(y) + 0.5) * (2.0 ** -32)


@njit(**INLINE)
def padded_sobol2(i, seed):
    """Point ``i`` (0, 1, ...) in [0, 1)^2 of a 2-D net padded to a pixel's samples: the Sobol
    points of :func:`pixel_offset`, Owen-scrambled by seeds hashed from ``seed`` (uint64), at
    an index shuffled by a nested scramble of its bits (Burley 2020, "Practical hash-based Owen
    scrambling", section 4). The shuffle maps each aligned block of ``2^m`` indices onto an
    aligned block, so the first ``2^m`` samples, and each half of a doubling round, are nets in
    these two dimensions as in the pixel's; and each point alone is uniform and independent of
    the pixel's position (its own seeds), so an estimate from them is unbiased."""
    h = mix64(np.uint64(seed) ^ np.uint64(0xA0761D6478BD642F))
    j = _reverse32(_nested_hash(_reverse32(np.uint64(i) & _M32), h & _M32))
    g = mix64(h)
    x = _reverse32(_nested_hash(j, g & _M32))
    y = _reverse32(_nested_hash(_reverse32(_sobol2(j)), g >> np.uint64(32)))
    return (float(x) + 0.5) * (2.0 ** -32), (float(y) + 0.5) * (2.0 ** -32)


@njit(**JIT)
def pixel_offsets_batch(pixels, ks, out):
    """:func:`pixel_offset` of ``(pixels[i], ks[i])`` into ``out[i]`` (for Python callers)."""
    for j in range(pixels.shape[0]):
        out[j, 0], out[j, 1] = pixel_offset(pixels[j], ks[j])


@njit(**JIT)
def camera_ray(cam, x, y):
    """Unit direction of the primary ray through image point ``(x, y)`` (pixels, y down)."""
    t = cam[C_TAN]
    w, h = cam[C_W], cam[C_H]
    sx = (2.0 * x / w - 1.0) * t * w / h
    sy = (1.0 - 2.0 * y / h) * t
    dx = cam[C_F] + sx * cam[C_R] + sy * cam[C_U]
    dy = cam[C_F + 1] + sx * cam[C_R + 1] + sy * cam[C_U + 1]
    dz = cam[C_F + 2] + sx * cam[C_R + 2] + sy * cam[C_U + 2]
    n = math.sqrt(dx * dx + dy * dy + dz * dz)
    return dx / n, dy / n, dz / n


#: ``atan(t) ~ t P(t^2)`` on ``[0, 1]``: P's coefficients, a least-squares fit at Chebyshev
#: nodes reweighted towards equal ripple (Lawson), odd terms up to ``t^23``; the largest error
#: is 2.2e-11 rad (``tests/test_camera_env.py`` checks against libm). One lookup of the
#: environment needs two arc tangents; libm's ``atan2`` and ``acos`` cost 34 ns a pair, this
#: 10 ns (a public_4 frame is about 3 % faster, measured in one process against the old kernels).
_ATAN = (0.9999999994302649, -0.3333332704094423, 0.19999793543932795, -0.142825514242857,
         0.11083671264661088, -0.08941118911292048, 0.0714307547948753, -0.05251456605734459,
         0.032232571611663596, -0.014721216536282895, 0.004293645423580093, -0.0005876996121446029)
_A0, _A1, _A2, _A3, _A4, _A5, _A6, _A7, _A8, _A9, _A10, _A11 = _ATAN


@njit(**INLINE)
def atan2_poly(y, x):
    """``atan2(y, x)`` (rad, in ``[-pi, pi]``) to within 2.2e-11 rad, without libm: the ratio of
    the smaller to the larger magnitude through :data:`_ATAN` (Estrin's scheme, so the
    polynomial is a short chain), then the octant. ``atan2(0, 0)`` is 0."""
    ax, ay = abs(x), abs(y)
    big, small = max(ax, ay), min(ax, ay)
    t = small / big if big > 0.0 else 0.0
    s = t * t
    s2 = s * s
    s4 = s2 * s2
    p = ((_A0 + _A1 * s) + (_A2 + _A3 * s) * s2
         + ((_A4 + _A5 * s) + (_A6 + _A7 * s) * s2) * s4
         + ((_A8 + _A9 * s) + (_A10 + _A11 * s) * s2) * (s4 * s4))
    a = t * p
    if ay > ax:
        a = 0.5 * math.pi - a
    if x < 0.0:
        a = math.pi - a
    return -a if y < 0.0 else a


@intrinsic
def _half_to_float(typingctx, bits):
    """The IEEE half-precision number whose bit pattern is the uint16 ``bits``, as float32
    (one ``vcvtph2ps`` on an x86-64 with F16C; numba has no float16 type of its own)."""
    def codegen(context, builder, signature, args):
        return builder.fpext(builder.bitcast(args[0], ir.HalfType()), ir.FloatType())
    return types.float32(types.uint16), codegen


def texel(tex, j, i, c):
    """Channel ``c`` of texel ``(j, i)``: float32 texels as they are, uint16 ones read as the
    bit patterns of half floats (:func:`engine.tracer.tables.environment.half_texels`)."""
    v = tex[j, i, c]
    return float(np.uint16(v).view(np.float16)) if tex.dtype == np.uint16 else float(v)


@overload(texel, inline="always")
def _texel(tex, j, i, c):
    if tex.dtype == types.uint16:
        return lambda tex, j, i, c: _half_to_float(tex[j, i, c])
    return lambda tex, j, i, c: tex[j, i, c]


@njit(**JIT)
def env_lookup(tex, scale, rot, dx, dy, dz):
    """Radiance ``(r, g, b)`` arriving along unit direction ``d`` (SPEC 3, bilinear, u wraps,
    rows clamped), times ``scale``; the map is turned by ``rot`` rad about +z. ``tex`` is
    ``(H, W, 3)`` float32 texels or the half-float bit patterns of
    :func:`engine.tracer.tables.environment.half_texels` (the render's map: half the memory traffic)."""
    h, w = tex.shape[0], tex.shape[1]
    u = (atan2_poly(dy, dx) - rot) * (0.5 / math.pi)
    u -= math.floor(u)
    v = atan2_poly(math.sqrt(dx * dx + dy * dy), dz) * (1.0 / math.pi)  # acos(dz), even at the poles
    x = u * w - 0.5  # in [-0.5, w - 0.5]: one wrap (no division)
    if x < 0.0:
        x += w
    y = v * (h - 1)
    i0 = int(x)
    fx = x - i0
    if i0 > w - 1:
        i0 = w - 1
    i1 = i0 + 1 if i0 + 1 < w else 0
    j0 = int(y)
    if j0 > h - 2:
        j0 = h - 2
    fy = y - j0
    j1 = j0 + 1
    w00 = (1.0 - fx) * (1.0 - fy)
    w01 = fx * (1.0 - fy)
    w10 = (1.0 - fx) * fy
    w11 = fx * fy
    r = (texel(tex, j0, i0, 0) * w00 + texel(tex, j0, i1, 0) * w01 + texel(tex, j1, i0, 0) * w10
         + texel(tex, j1, i1, 0) * w11) * scale
    g = (texel(tex, j0, i0, 1) * w00 + texel(tex, j0, i1, 1) * w01 + texel(tex, j1, i0, 1) * w10
         + texel(tex, j1, i1, 1) * w11) * scale
    b = (texel(tex, j0, i0, 2) * w00 + texel(tex, j0, i1, 2) * w01 + texel(tex, j1, i0, 2) * w10
         + texel(tex, j1, i1, 2) * w11) * scale
    return r, g, b
