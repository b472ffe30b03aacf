"""Relief and roughness of surface finishes, compiled: bump tiles, relief maps, GGX microfacets.

Design rule: a finish bends the *shading* normal only; these scalar functions (no allocation,
no state) compute the relief's height field and its derivatives analytically, so a tile
magnified 100x stays smooth and every normal is continuous across tile seams and the 360 deg
wrap (ridges, groove bottoms and facet edges are rounded by smooth minima and smooth triangle
waves, never by a kink). One row ``p`` (float64, ``P_COLS``) describes one tile; kinds and
columns are the constants below, filled by :mod:`engine.tracer.tables.bump_rows`.

Conventions (units mm):

* ``u`` is arc length around the girth *at the tile's reference radius* ``R = p[P_RADIUS]``:
  ``u = theta R``, ``theta`` the polar angle (rad, counter-clockwise seen from above);
  :func:`surface_slope` takes ``theta`` and the point's true radius and does the conversion.
  On an outline bottle's wall ``theta`` is the girth fraction ``2 pi l / L`` and the radius
  ``L / 2 pi`` (arc length ``l`` of the perimeter ``L``: :func:`.finish._girth_frame`), so the
  tile runs along the outline's arc length.
* ``v`` is arc length along the section from its start on the axis, rising with it (round
  bottles and closures: the tracer's ``si[I_V]``), or the height z on a non-round wall.
* ``h`` is the relief's displacement along the geometric normal, out of the glass; slopes are
  ``(dh/du, dh/dv)``, dimensionless, and the shading normal is ``n - dh/du t_u - dh/dv t_v``.
* A band ``[p[P_V0], p[P_V1]]`` in ``v`` carries the tile; it fades in and out over
  ``p[P_FADE]`` mm (quintic, so the normal stays continuous at the band's ends).

GGX (Walter et al. 2007): microfacet normals ``m`` are sampled with density
``D(m) (m . n)`` from two uniform numbers the caller draws from the branch's own stream.
"""
from __future__ import annotations

import math

from numba import njit

from .jit import INLINE, JIT

KNURL, STIPPLE, FLUTES, FACETS, DIAMOND, THREAD, FROSTED, MAP = range(8)
KIND_NAMES = ("knurl", "stipple", "flutes", "facets", "diamond", "thread", "frosted", "map")
(P_V0, P_V1, P_FADE, P_RADIUS, P_REPEAT, P_DEPTH, P_PHASE, P_PITCH, P_A, P_B, P_C, P_D, P_ALPHA,
 P_TEX0, P_TEXW, P_TEXH, P_SPAN, P_MODE, P_START) = range(19)
P_COLS = 19
#: Relief-map texel layouts (``p[P_MODE]``): normalised height and its derivatives per unit of
#: the map's own coordinates ``(H, dH/dfu, dH/dfv)``; or slopes as drawn ``(0, dh/du, dh/dv)``.
MAP_HEIGHT, MAP_SLOPE = 0, 1
TWO_PI = 2.0 * math.pi
_MAX_SLOPE = 1e6


# ----------------------------------------------------------------------------- smooth pieces
@njit(**INLINE)
def _ramp(t):
    """Quintic 0 -> 1 on [0, 1] (C2) and its derivative."""
    if t <= 0.0:
        return 0.0, 0.0
    if t >= 1.0:
        return 1.0, 0.0
    return t * t * t * (t * (6.0 * t - 15.0) + 10.0), 30.0 * t * t * (t - 1.0) * (t - 1.0)


@njit(**INLINE)
def _window(x, lo, hi, fade):
    """``(w, dw/dx)``: 1 inside ``[lo, hi]``, fading to 0 at both ends over ``fade``."""
    if x < lo or x > hi:
        return 0.0, 0.0
    if fade <= 0.0:
        return 1.0, 0.0
    a, da = _ramp((x - lo) / fade)
    b, db = _ramp((hi - x) / fade)
    return a * b, (da * b - a * db) / fade


@njit(**INLINE)
def _smin(a, b, k):
    """Polynomial smooth minimum (C1) of ``a`` and ``b`` over width ``k``: ``(value, d/da)``;
    ``d/db = 1 - d/da``."""
    if k <= 0.0:
        return (a, 1.0) if a <= b else (b, 0.0)
    h = min(1.0, max(0.0, 0.5 + 0.5 * (b - a) / k))
    return b + (a - b) * h - k * h * (1.0 - h), h


@njit(**INLINE)
def _ridge(x, k):
    """Smooth triangle wave of period 1 in [-1, 1], ``+1`` at whole ``x``: ``asin(k cos 2 pi x)
    / asin(k)`` (``k`` in (0, 1): near 1 nearly sharp) and its derivative."""
    c, s = math.cos(TWO_PI * x), math.sin(TWO_PI * x)
    norm = math.asin(k)
    return math.asin(k * c) / norm, -TWO_PI * k * s / (math.sqrt(1.0 - k * k * c * c) * norm)


@njit(**INLINE)
def _bell(x, w):
    """``cos^2(pi x / w)`` on ``|x| < w / 2``, else 0 (C1), and its derivative."""
    if w <= 0.0 or abs(x) >= 0.5 * w:
        return 0.0, 0.0
    c, s = math.cos(math.pi * x / w), math.sin(math.pi * x / w)
    return c * c, -2.0 * math.pi / w * c * s


# ------------------------------------------------------------------------- procedural tiles
@njit(**INLINE)
def thread_profile(uu, v, circ, n, pitch, start, flank_low, flank_high, turns, runout):
    """The screw thread's ridge as factors ``(e, de/dtau, prof, dprof/ds)``: its height is
    ``depth e prof``. ``uu`` (mm) is arc length around the girth of circumference ``circ``
    from the thread's phase, ``v`` (mm) along the section; ``n`` starts of ``pitch`` (mm),
    the first ridge centred at ``v = start``. ``prof`` is the ridge across (a bell of the
    flank half-widths, fractions of the pitch, in the helical phase ``s``), ``e`` fades each
    start in and out over ``runout`` turns at the ends of its ``turns`` (``tau``). One
    function for the relief and the true helical geometry (:mod:`.helix`): both draw the
    same thread."""
    uw = uu - circ * math.floor(uu / circ)
    s = (v - start) / pitch - n * uw / circ
    k = math.floor(s + 0.5)
    x = s - k
    prof, dprof = _bell(x, 2.0 * (flank_high if x >= 0.0 else flank_low))
    tau = (k + n * uw / circ) / n        # turns along this start's helix
    e, de = _window(tau, 0.0, turns, runout)
    return e, de, prof, dprof


@njit(**JIT)
def _relief(kind, p, u, v):
    """``(h, dh/du, dh/dv)`` of procedural tile ``p`` at ``(u, v)`` (module conventions)."""
    R = p[P_RADIUS]
    n = p[P_REPEAT]
    w, dw = _window(v, p[P_V0], p[P_V1], p[P_FADE])
    if (w == 0.0 and dw == 0.0) or kind == FROSTED or not (R > 0.0 and n >= 1.0):
        return 0.0, 0.0, 0.0
    pu = TWO_PI * R / n                      # one period around, mm
    pv = p[P_PITCH] if p[P_PITCH] > 0.0 else pu
    depth = p[P_DEPTH]
    uu = u - p[P_PHASE] * R
    a = uu / pu
    b = (v - p[P_V0]) / pv
    if kind == KNURL:
        k = min(max(p[P_B], 1e-3), 0.999)
        if p[P_A] >= 0.5:                    # straight: vertical ridges
            g, dg = _ridge(a, k)
            f, fa, fb = 0.5 * (g - 1.0), 0.5 * dg, 0.0
        else:                                # diamond: grooves at +-45 deg, pyramids between
            g1, d1 = _ridge(a + b, k)
            g2, d2 = _ridge(a - b, k)
            m, wm = _smin(g1, g2, 1.05 - k)
            f, fa, fb = 0.5 * (m - 1.0), 0.5 * (wm * d1 + (1.0 - wm) * d2), 0.5 * (wm * d1 - (1.0 - wm) * d2)
        return depth * w * f, depth * w * fa / pu, depth * (dw * f + w * fb / pv)
    if kind == STIPPLE:
        row = math.floor(b)
        xa = a + p[P_C] * row
        xa -= math.floor(xa) + 0.5
        ca, da = _bell(xa, p[P_A])
        cb, db = _bell(b - row - 0.5, p[P_B])
        f = ca * cb
        return depth * w * f, depth * w * da * cb / pu, depth * (dw * f + w * ca * db / pv)
    if kind == FLUTES:
        c, dc = _bell(a - math.floor(a) - 0.5, p[P_A])
        return -depth * w * c, -depth * w * dc / pu, -depth * dw * c
    if kind == FACETS:                       # planes at distance R - |depth| from the axis
        sgn = 1.0 if depth >= 0.0 else -1.0
        d = max(R - abs(depth), 1e-9 * R)
        step = TWO_PI / n
        phi = (a - math.floor(a) - 0.5) * step
        g = d / math.cos(phi) - R
        dg = d * math.sin(phi) / (math.cos(phi) ** 2)
        phn = phi - step if phi > 0.0 else phi + step
        cn = math.cos(phn)
        gn, dgn = (d / cn - R, d * math.sin(phn) / (cn * cn)) if cn > 0.05 else (1e300, 0.0)
        m, wm = _smin(g, gn, p[P_B])
        h0, w0 = _smin(m, 0.0, p[P_B])
        dh = w0 * (wm * dg + (1.0 - wm) * dgn)
        return sgn * w * h0, sgn * w * dh / R, sgn * dw * h0
    if kind == DIAMOND:                      # crossing V grooves, flat land between
        sgn = 1.0 if depth >= 0.0 else -1.0
        dm, hw, e = abs(depth), max(p[P_A], 1e-6), max(p[P_C], 1e-9)
        x1 = a + b - math.floor(a + b + 0.5)
        x2 = a - b - math.floor(a - b + 0.5)
        q1, q2 = math.sqrt(x1 * x1 + e * e), math.sqrt(x2 * x2 + e * e)
        g1, g2 = dm * ((q1 - e) / hw - 1.0), dm * ((q2 - e) / hw - 1.0)
        s1, s2 = dm * x1 / (q1 * hw), dm * x2 / (q2 * hw)
        m, wm = _smin(g1, g2, p[P_B])
        h0, w0 = _smin(m, 0.0, p[P_B])
        ha = w0 * (wm * s1 + (1.0 - wm) * s2)
        hb = w0 * (wm * s1 - (1.0 - wm) * s2)
        return sgn * w * h0, sgn * w * ha / pu, sgn * (dw * h0 + w * hb / pv)
    if kind == THREAD:                       # helical ridges: n starts, pitch P, right-handed
        circ = TWO_PI * R
        pitch = p[P_PITCH] if p[P_PITCH] > 0.0 else pu
        e, de, prof, dprof = thread_profile(uu, v, circ, n, pitch, p[P_START], p[P_B], p[P_C], p[P_A], p[P_D])
        hh = depth * e * prof
        hu = depth * (de / circ * prof - e * dprof * n / circ)
        return w * hh, w * hu, depth * w * e * dprof / pitch + dw * hh
    return 0.0, 0.0, 0.0


@njit(**JIT)
def bump_height(kind, p, u, v):
    """Height (mm, out of the glass) of procedural tile ``p`` at ``(u, v)``."""
    return _relief(kind, p, u, v)[0]


@njit(**JIT)
def bump_slope(kind, p, u, v):
    """``(dh/du, dh/dv)`` of procedural tile ``p`` at ``(u, v)`` (module conventions);
    ``(0, 0)`` outside its band and for ``FROSTED`` (roughness, not relief)."""
    _, hu, hv = _relief(kind, p, u, v)
    return hu, hv


# ------------------------------------------------------------------------------ relief maps
@njit(**JIT)
def map_texel(atlas, p, fu, fv, wrap):
    """Bilinear lookup of the 3 channels of tile ``p``'s map at map coordinates ``(fu, fv)``
    in [0, 1] (texel centres at ``(i + 0.5) / W``): seamless wrap in ``u`` when ``wrap``, else
    clamped, always clamped in ``v``. ``atlas`` rows ``p[P_TEX0] + j W + i``, float32."""
    off, wd, ht = int(p[P_TEX0]), int(p[P_TEXW]), int(p[P_TEXH])
    x = fu * wd - 0.5
    if wrap:
        x -= wd * math.floor(x / wd)
        i0 = min(int(x), wd - 1)
        i1 = (i0 + 1) % wd
    else:
        x = min(max(x, 0.0), wd - 1.0)
        i0 = min(int(x), wd - 2)
        i1 = i0 + 1
    fx = x - i0
    y = min(max(fv * ht - 0.5, 0.0), ht - 1.0)
    j0 = min(int(y), ht - 2)
    fy = y - j0
    r00, r01 = off + j0 * wd + i0, off + j0 * wd + i1
    w00, w01, w10, w11 = (1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy
    a, b, c, d = atlas[r00], atlas[r01], atlas[r00 + wd], atlas[r01 + wd]
    return (w00 * a[0] + w01 * b[0] + w10 * c[0] + w11 * d[0],
            w00 * a[1] + w01 * b[1] + w10 * c[1] + w11 * d[1],
            w00 * a[2] + w01 * b[2] + w10 * c[2] + w11 * d[2])


@njit(**JIT)
def map_relief(atlas, p, u, v):
    """``(h, dh/du, dh/dv)`` of relief-map tile ``p``: ``p[P_REPEAT]`` copies around, each
    spanning ``p[P_SPAN]`` rad centred on ``p[P_PHASE] + k 2 pi / n`` (a span of a whole period
    or more tiles seamlessly), the map's rows from ``v0`` (row 0) up to ``v1``."""
    v0, v1 = p[P_V0], p[P_V1]
    if v < v0 or v > v1:
        return 0.0, 0.0, 0.0
    R, n = p[P_RADIUS], p[P_REPEAT]
    period = TWO_PI / n
    a = (u / R - p[P_PHASE]) / period
    wrap = p[P_SPAN] >= period * (1.0 - 1e-12)
    if wrap:
        fu = a - math.floor(a)
        span_mm = period * R
    else:
        fu = (a - math.floor(a + 0.5)) * period / p[P_SPAN] + 0.5
        if fu < 0.0 or fu > 1.0:
            return 0.0, 0.0, 0.0
        span_mm = p[P_SPAN] * R
    c0, c1, c2 = map_texel(atlas, p, fu, (v - v0) / (v1 - v0), wrap)
    d = p[P_DEPTH]
    if p[P_MODE] == MAP_SLOPE:
        return 0.0, d * c1, d * c2
    return d * c0, d * c1 / span_mm, d * c2 / (v1 - v0)


@njit(**JIT)
def map_slope(atlas, p, u, v):
    """``(dh/du, dh/dv)`` of relief-map tile ``p`` at ``(u, v)`` (see :func:`map_relief`)."""
    _, hu, hv = map_relief(atlas, p, u, v)
    return hu, hv


@njit(**JIT)
def surface_slope(kind, p, atlas, theta, v, rho):
    """Slopes ``(dh/ds_u, dh/dv)`` per mm of the true surface at polar angle ``theta`` (rad),
    section coordinate ``v`` (mm) and radius ``rho`` (mm) from the axis: what to hand to
    :func:`perturb_normal` with ``t_u = dp/dtheta / rho``. ``(0, 0)`` outside the band."""
    if v < p[P_V0] or v > p[P_V1]:
        return 0.0, 0.0
    R = p[P_RADIUS]
    if kind == MAP:
        hu, hv = map_slope(atlas, p, theta * R, v)
    else:
        hu, hv = bump_slope(kind, p, theta * R, v)
    if rho > 0.0:
        hu *= R / rho
    return hu, hv


@njit(**JIT)
def relief_grid(kind, p, atlas, us, vs, out):
    """``out[i] = (h, dh/du, dh/dv)`` at ``(us[i], vs[i])`` for any kind (previews, meshes)."""
    for i in range(us.shape[0]):
        if kind == MAP:
            h, hu, hv = map_relief(atlas, p, us[i], vs[i])
        else:
            h, hu, hv = _relief(kind, p, us[i], vs[i])
        out[i, 0], out[i, 1], out[i, 2] = h, hu, hv


# ------------------------------------------------------------------------ shading normals
@njit(**JIT)
def onb(nx, ny, nz):
    """Two unit tangents ``(b1, b2)`` completing unit ``n`` to a right-handed orthonormal
    basis (Duff et al. 2017: branch-free, no singularity)."""
    sign = math.copysign(1.0, nz)
    a = -1.0 / (sign + nz)
    b = nx * ny * a
    return (1.0 + sign * nx * nx * a, sign * b, -sign * nx), (b, sign + ny * ny * a, -ny)


@njit(**JIT)
def perturb_normal(nx, ny, nz, tux, tuy, tuz, tvx, tvy, tvz, dh_du, dh_dv):
    """Unit shading normal ``n - dh/du t_u - dh/dv t_v`` of a relief on a surface with unit
    geometric normal ``n`` (the side ``h`` is measured to) and unit tangents ``t_u``, ``t_v``
    along increasing ``u`` and ``v``; the tangents are made orthogonal to ``n`` first. Slopes
    are clamped to 1e6; a degenerate or non-finite result returns ``n``."""
    su = min(max(dh_du, -_MAX_SLOPE), _MAX_SLOPE)
    sv = min(max(dh_dv, -_MAX_SLOPE), _MAX_SLOPE)
    d = tux * nx + tuy * ny + tuz * nz
    ax, ay, az = tux - d * nx, tuy - d * ny, tuz - d * nz
    la = math.sqrt(ax * ax + ay * ay + az * az)
    if not la > 1e-12:
        (ax, ay, az), _ = onb(nx, ny, nz)
        la = 1.0
    ax, ay, az = ax / la, ay / la, az / la
    d, e = tvx * nx + tvy * ny + tvz * nz, tvx * ax + tvy * ay + tvz * az
    bx, by, bz = tvx - d * nx - e * ax, tvy - d * ny - e * ay, tvz - d * nz - e * az
    lb = math.sqrt(bx * bx + by * by + bz * bz)
    if not lb > 1e-12:   # t_v along n or t_u: take the tangent across t_u
        bx, by, bz = ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax
        lb = 1.0
    bx, by, bz = bx / lb, by / lb, bz / lb
    sx, sy, sz = nx - su * ax - sv * bx, ny - su * ay - sv * by, nz - su * az - sv * bz
    ls = math.sqrt(sx * sx + sy * sy + sz * sz)
    if not (ls > 0.0 and math.isfinite(ls)):
        return nx, ny, nz
    return sx / ls, sy / ls, sz / ls


@njit(**JIT)
def consistent_normal(sx, sy, sz, nx, ny, nz, dx, dy, dz):
    """Shading normal ``s`` bent towards the geometric normal ``n`` just enough that the ray
    direction ``d`` meets both from the same side (``d . s`` has the sign of ``d . n``, with at
    least 1 % of its size): a bump can then never make a ray cross to the wrong medium."""
    dn = dx * nx + dy * ny + dz * nz
    ds = dx * sx + dy * sy + dz * sz
    if dn == 0.0:
        return nx, ny, nz
    c = 0.01 * dn
    if (dn > 0.0 and ds >= c) or (dn < 0.0 and ds <= c):
        return sx, sy, sz
    t = (c - ds) / dn
    bx, by, bz = sx + t * nx, sy + t * ny, sz + t * nz
    lb = math.sqrt(bx * bx + by * by + bz * bz)
    if not (lb > 0.0 and math.isfinite(lb)):
        return nx, ny, nz
    return bx / lb, by / lb, bz / lb


# ---------------------------------------------------------------------------------- GGX
@njit(**JIT)
def ggx_d(alpha, cos_m):
    """GGX normal distribution ``D(m)`` (1/sr) for ``cos_m = m . n``; 0 below the surface."""
    if cos_m <= 0.0:
        return 0.0
    a2 = alpha * alpha
    t = cos_m * cos_m * (a2 - 1.0) + 1.0
    return a2 / (math.pi * t * t)


@njit(**JIT)
def ggx_sample(alpha, nx, ny, nz, u1, u2):
    """Microfacet normal about unit ``n`` with density ``D(m) (m . n)`` (per solid angle),
    from two uniforms in [0, 1); ``u1`` is clamped below 1 so the result is always finite."""
    u1 = min(max(u1, 0.0), 1.0 - 2.0 ** -53)
    t2 = alpha * alpha * u1 / (1.0 - u1)
    cos_t = 1.0 / math.sqrt(1.0 + t2)
    sin_t = math.sqrt(t2 / (1.0 + t2))
    phi = TWO_PI * u2
    lx, ly = sin_t * math.cos(phi), sin_t * math.sin(phi)
    (b1x, b1y, b1z), (b2x, b2y, b2z) = onb(nx, ny, nz)
    mx = lx * b1x + ly * b2x + cos_t * nx
    my = lx * b1y + ly * b2y + cos_t * ny
    mz = lx * b1z + ly * b2z + cos_t * nz
    lm = math.sqrt(mx * mx + my * my + mz * mz)
    return mx / lm, my / lm, mz / lm


@njit(**JIT)
def ggx_pdf(alpha, nx, ny, nz, mx, my, mz):
    """Density (1/sr) with which :func:`ggx_sample` returns ``m``: ``D(m) (m . n)``."""
    c = mx * nx + my * ny + mz * nz
    return ggx_d(alpha, c) * max(c, 0.0)


@njit(**JIT)
def ggx_g1(alpha, cos_vn, cos_vm):
    """Smith masking of one direction ``w`` for GGX: ``cos_vn = w . n``, ``cos_vm = w . m``
    (0 when ``w`` sees the microfacet from behind); finite at grazing ``cos_vn = 0``."""
    if cos_vn * cos_vm <= 0.0:
        return 0.0
    c = abs(cos_vn)
    return 2.0 * c / (c + math.sqrt(alpha * alpha + (1.0 - alpha * alpha) * c * c))


@njit(**JIT)
def ggx_eval(alpha, n, wi, wo, m):
    """``(D, G, weight)`` for a branch through microfacet ``m`` from ``w_i`` to ``w_o`` about the
    normal ``n`` (unit 3-tuples, ``w_i`` and ``w_o`` pointing away from the surface; ``w_o``
    reflected or refracted about ``m``). ``weight``
    is ``|w_i . m| G / (|w_i . n| |m . n|)``: times the Fresnel factor of the branch it is the
    branch's throughput when ``m`` came from :func:`ggx_sample` (Walter et al. eq. 41)."""
    nx, ny, nz = n
    ix, iy, iz = wi
    ox, oy, oz = wo
    mx, my, mz = m
    cn = mx * nx + my * ny + mz * nz
    in_ = ix * nx + iy * ny + iz * nz
    im = ix * mx + iy * my + iz * mz
    on = ox * nx + oy * ny + oz * nz
    om = ox * mx + oy * my + oz * mz
    d = ggx_d(alpha, cn)
    g = ggx_g1(alpha, in_, im) * ggx_g1(alpha, on, om)
    if abs(in_) < 1e-12 or cn < 1e-12:
        return d, g, 0.0
    return d, g, abs(im) * g / (abs(in_) * cn)
