"""The stage's ground as a surface: its material, the sky's light on it and the lights'.

Design rule: the ground is Lambertian (optionally under a clear coat, or a tinted mirror, or a
shadow catcher), so its light is an integral over the sky above it, through the glass and the
liquid where the bottle stands in the way: the caustic and the coloured shadow are that light.

*The environment's light* is estimated with a control variate whose mean is known exactly: the
environment's irradiance ``E_up`` of an upward surface with nothing in the way (``env_p[3:6]``,
computed once per environment). Where nothing is in the way, what arrives along a direction is
the environment itself, so only the directions towards the upright cylinder that holds the
bottle and its closure (``MG_BOUND_*``) can differ: a hit sends back ``albedo (E_up - F
L_env(w))`` at once and one child along a direction ``w`` drawn cosine-distributed within the
azimuth and elevation that cylinder spans from the hit (a share ``F`` of the cosine-weighted
sky), with weight ``albedo F``, whose subtree brings back what really arrives along ``w``. Open
ground is exact and noise-free, and every sample of ground near the bottle probes the bottle.
Where a backdrop sweep stands on the ground (``MG_WIDE``) it hides sky too, so the window is
the whole sky (:func:`probe_window`), still controlled.

Within the *sky grid* (:mod:`engine.tracer.tables.sky`: polar cells about the bottle's axis out
to many times its radius) that estimate is made once per design, not per sample: each cell
holds the sky's irradiance at its centre, from many stratified probes of the same control
variate, and a hit reads it bilinearly (:func:`sky_irradiance`) and sends no probe. The ground
is then noise-free wherever the lights' shadow rays agree, and its pixels need no more samples
than any other; only the ground beyond the grid, a rough coat and a light's penumbra are
sampled per hit, and set :data:`NOISY_BIT` in the object mask so the sampler knows.

*A design light's light* (a disc in the sky, :data:`L_COS`) arrives straight, where one shadow
ray towards a point of its disc meets nothing (:func:`light_on_ground`), or through the bottle:
that part, the light's caustic and coloured shadow, cannot be found from the ground (a point
light is met along one direction only), so it is traced from the light
(:mod:`.caustics`) into a grid of irradiance that the ground looks up, on the side of the
shadow's edge the shadow ray found (:func:`caustic_irradiance`).

A shadow catcher is the same ground with the albedo ``L_env(d) / (E_up + E_lights)`` of the
background ``d`` shows there over the open ground's irradiance, so where nothing is in the way
it shows the environment itself, and where something is, the share of light that still arrives.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .finish import FROST_STREAM
from .intersect import nearest_hit
from .records import Ray
from .jit import INLINE, JIT
from .materials import (K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, MG_ALBEDO, MG_ALPHA, MG_BOUND_R, MG_BOUND_Z,
                        MG_COAT_IOR, MG_MIRROR, MG_SHADOW, MG_WIDE, coat)
from .microfacet import rough_mirror
from .sampling import env_lookup, uniform01

AIR = 0
#: Streams of a branch's seed the ground's direction draws from (frosting uses 7 and 8), then
#: two per light for its disc.
GROUND_STREAM = 9
LIGHT_STREAM = 11
#: Columns of a light row (:func:`engine.tracer.tables.lighting.light_table`): unit direction towards
#: the light, colour x intensity (irradiance on a surface facing it), cosine of its half angle.
L_DX, L_DY, L_DZ, L_R, L_G, L_B, L_COS = range(7)
LIGHT_COLS = 7
#: Columns of a caustic grid row: the grid's corner (mm), its cell (mm), columns and rows used.
G_X0, G_Y0, G_CELL, G_NX, G_NY = range(5)
GRID_COLS = 5
#: Channels of a caustic grid cell: irradiance over pi (rgb) of the light that came through the
#: bottle landing in the light's shadow, and in the open; the share of the cell in the shadow.
C_IN, C_OUT, C_SHADOW = 0, 3, 6
CAUSTIC_COLS = 7
#: Shadow shares below this are taken as none (the division by it would only amplify noise).
MIN_SHARE = 1e-3
#: Columns of the sky grid's row (:mod:`engine.tracer.tables.sky`): the width of the rings
#: inside radius ``S_R1`` (mm, the bottle's bounding radius), that radius, the outer rings'
#: growth (each ``1 + S_GROW`` times as far out as the last), rings inside ``S_R1`` and in all,
#: sectors of a ring outside (inner rings have fewer: :func:`ring_cells`), and the outermost
#: ring's outer radius (mm). Zero rings: no grid.
S_DR, S_R1, S_GROW, S_NIN, S_NRING, S_NSEC, S_RMAX = range(7)
SKY_COLS = 7
#: Sectors of the innermost rings at least.
MIN_SECTORS = 8
#: Object-mask bit a ground hit sets when its light was sampled (a probe, a rough coat's
#: direction, a light's penumbra): the pixel is noisy wherever it is (objects use the bits
#: below it, labels those from :data:`engine.tracer.kernels.labels.LABEL_BIT0` = 32 up).
NOISY_BIT = np.int64(1) << np.int64(31)
#: Points on a light disc's rim a ground hit sends shadow rays to: where all agree, the whole
#: disc is seen or hidden and its light is exact; else the hit is in the penumbra.
RIM_POINTS = 4


@njit(**INLINE)
def light_frame(x, y, z):
    """Two unit vectors ``(u, v)`` completing unit ``(x, y, z)`` to a frame (``u`` horizontal
    unless ``(x, y, z)`` is vertical)."""
    h = math.sqrt(x * x + y * y)
    if h < 1e-12:
        return 1.0, 0.0, 0.0, 0.0, 1.0, 0.0
    ux, uy, uz = -y / h, x / h, 0.0
    return ux, uy, uz, y * uz - z * uy, z * ux - x * uz, x * uy - y * ux


@njit(**INLINE)
def in_disc(light, u1, u2):
    """A unit direction towards ``light`` (a light row) drawn uniformly in its disc (solid
    angle) from uniforms ``u1, u2``; its centre for a point light."""
    lx, ly, lz, c = light[L_DX], light[L_DY], light[L_DZ], light[L_COS]
    if c >= 1.0:
        return lx, ly, lz
    ux, uy, uz, vx, vy, vz = light_frame(lx, ly, lz)
    ct = 1.0 - u1 * (1.0 - c)
    st = math.sqrt(max(0.0, 1.0 - ct * ct))
    phi = 2.0 * math.pi * u2
    a, b = st * math.cos(phi), st * math.sin(phi)
    return ct * lx + a * ux + b * vx, ct * ly + a * uy + b * vy, ct * lz + a * uz + b * vz


@njit(**INLINE)
def caustic_irradiance(fin, q, px, py, shadowed):
    """Irradiance over pi ``(r, g, b)`` at ground point ``(px, py)`` (mm) of light ``q``'s light
    that came through the bottle, for a point in its shadow (``shadowed``) or not: the grid's
    light of that side over that side's share of the ground, bilinear (module rule of
    :mod:`engine.tracer.tables.caustics`); zero outside the grid."""
    g, cs = fin.caustic_grid, fin.caustics
    if q >= g.shape[0] or g[q, G_CELL] <= 0.0:
        return 0.0, 0.0, 0.0
    cell = g[q, G_CELL]
    fx = (px - g[q, G_X0]) / cell - 0.5  # cell centres at half-integers
    fy = (py - g[q, G_Y0]) / cell - 0.5
    nx, ny = int(g[q, G_NX]), int(g[q, G_NY])
    if not (fx > -1.0 and fy > -1.0 and fx < nx and fy < ny):
        return 0.0, 0.0, 0.0
    i0, j0 = int(math.floor(fx)), int(math.floor(fy))
    tx, ty = fx - i0, fy - j0
    c0 = C_IN if shadowed else C_OUT
    r = gr = b = share = 0.0
    for dj in range(2):
        j = j0 + dj
        if j < 0 or j >= ny:
            continue
        wy = ty if dj else 1.0 - ty
        for di in range(2):
            i = i0 + di
            if i < 0 or i >= nx:
                continue
            w = wy * (tx if di else 1.0 - tx)
            r += w * cs[q, j, i, c0]
            gr += w * cs[q, j, i, c0 + 1]
            b += w * cs[q, j, i, c0 + 2]
            share += w * cs[q, j, i, C_SHADOW]
    if not shadowed:
        share = 1.0 - share
    if share < MIN_SHARE:
        return 0.0, 0.0, 0.0
    return r / share, gr / share, b / share


@njit(**INLINE)
def sky_ring(row, rho):
    """The ring coordinate of radius ``rho`` (mm) in sky grid ``row``: ring ``i`` spans
    ``[i, i + 1)`` (uniform rings inside ``S_R1``, geometric beyond; continuous at ``S_R1``)."""
    if rho <= row[S_R1]:
        return rho / row[S_DR]
    return row[S_NIN] + math.log(rho / row[S_R1]) / math.log1p(row[S_GROW])


@njit(**INLINE)
def ring_sectors(row, i):
    """Sectors of ring ``i`` of sky grid ``row``: the outer rings' count, and inside ``S_R1`` in
    proportion to the ring's radius (cells about as wide as they are deep), at least
    :data:`MIN_SECTORS`."""
    nsec, n_in = int(row[S_NSEC]), int(row[S_NIN])
    if i >= n_in:
        return nsec
    return min(nsec, max(MIN_SECTORS, int(math.ceil(nsec * (i + 0.5) / n_in))))


@njit(**INLINE)
def ring_cells(row, i):
    """``(first, count)``: the index of ring ``i``'s first cell in the grid's cell list (rings
    in order, sectors by rising angle) and its sectors."""
    n_in = int(row[S_NIN])
    first = 0
    for k in range(min(i, n_in)):
        first += ring_sectors(row, k)
    if i > n_in:
        first += (i - n_in) * int(row[S_NSEC])
    return first, ring_sectors(row, i)


@njit(**INLINE)
def _ring_value(sky, row, i, phi):
    """The sky grid's value on ring ``i`` at angle ``phi`` (radians, in [0, 2 pi)), linear
    between its sectors' centres."""
    first, ns = ring_cells(row, i)
    g = phi / (2.0 * math.pi) * ns - 0.5
    j = math.floor(g)
    t = g - j
    j0 = int(j) % ns
    j1 = (j0 + 1) % ns
    a, b = sky[first + j0], sky[first + j1]
    return (1.0 - t) * a[0] + t * b[0], (1.0 - t) * a[1] + t * b[1], (1.0 - t) * a[2] + t * b[2]


@njit(**INLINE)
def sky_irradiance(fin, px, py):
    """``(r, g, b, inside)``: the sky's irradiance over pi at ground point ``(px, py)`` (mm) from
    the sky grid (linear along each ring between its cells' centres, then between the two rings
    whose centres bracket the point), and whether the point lies within the grid (else zeros:
    the caller probes)."""
    row, sky = fin.sky_grid, fin.sky
    nring = int(row[S_NRING])
    if nring <= 0:
        return 0.0, 0.0, 0.0, False
    rho = math.sqrt(px * px + py * py)
    if rho >= row[S_RMAX]:
        return 0.0, 0.0, 0.0, False
    f = sky_ring(row, rho) - 0.5
    if f <= 0.0:
        i0, tf = 0, 0.0
    elif f >= nring - 1:
        i0, tf = nring - 1, 0.0
    else:
        i0 = int(math.floor(f))
        tf = f - i0
    i1 = min(i0 + 1, nring - 1)
    phi = (math.atan2(py, px) / (2.0 * math.pi)) % 1.0 * (2.0 * math.pi)
    r0, g0, b0 = _ring_value(sky, row, i0, phi)
    r1, g1, b1 = _ring_value(sky, row, i1, phi)
    return (1.0 - tf) * r0 + tf * r1, (1.0 - tf) * g0 + tf * g1, (1.0 - tf) * b0 + tf * b1, True


@njit(**INLINE)
def cylinder_window(px, py, pz, rho, bound_r, bound_z):
    """``(half azimuth, s_max, share, azimuth)`` of the window the bottle's bounding cylinder
    (radius ``bound_r``, top ``bound_z``, mm) spans from ground point ``p`` at ``rho > bound_r``
    from the axis (mm): its half width and centre in azimuth (radians), ``cos^2`` of its lowest
    zenith angle's complement (``s`` runs over ``[0, s_max]``), and its share of the
    cosine-weighted sky. The ground's probe and the sky grid's draw directions in it."""
    half_az = math.asin(bound_r / rho)
    s_max = math.sin(math.atan2(bound_z - pz, rho - bound_r)) ** 2
    return half_az, s_max, s_max * half_az / math.pi, math.atan2(-py, -px)


@njit(**INLINE)
def probe_window(mat_f, mat, px, py, pz):
    """``(half azimuth, s_max, share, azimuth, controlled)``: where ground material ``mat``'s
    probe from ground point ``p`` (mm) draws its directions (:func:`cylinder_window`'s
    columns) and whether the open sky's light along them is taken off (the control variate).
    Beside the bottle: the window of its bounding cylinder, or the whole sky where a backdrop
    stands on the ground (it hides sky there too), controlled both; under the cylinder: the
    whole sky, uncontrolled (what comes through the base is scrambled by refraction: the sky
    along a direction says little about it, and subtracting it only adds the sky's variance,
    measured as dark specks seen through the liquid)."""
    rho, bound_r = math.sqrt(px * px + py * py), mat_f[mat, MG_BOUND_R]
    if rho <= bound_r:
        return math.pi, 1.0, 1.0, math.pi, False
    if mat_f[mat, MG_WIDE] > 0.5:
        return math.pi, 1.0, 1.0, math.pi, True
    half_az, s_max, share, phi0 = cylinder_window(px, py, pz, rho, bound_r, mat_f[mat, MG_BOUND_Z])
    return half_az, s_max, share, phi0, True


@njit(**INLINE)
def open_light(lights):
    """Irradiance over pi ``(r, g, b)`` of ``lights`` on an upward surface with nothing in the
    way (the mean over each disc of its cosine: ``l_z (1 + cos half angle) / 2``)."""
    er = eg = eb = 0.0
    for q in range(lights.shape[0]):
        c = max(0.0, lights[q, L_DZ]) * 0.5 * (1.0 + lights[q, L_COS]) / math.pi
        er, eg, eb = er + c * lights[q, L_R], eg + c * lights[q, L_G], eb + c * lights[q, L_B]
    return er, eg, eb


@njit(**INLINE)
def _blocked(sc, k, px, py, pz, lx, ly, lz, scratch):
    """Whether the light along unit ``l`` is hidden from ground object ``k`` at ``p`` (mm)."""
    return lz <= 0.0 or nearest_hit(sc.geom, Ray(px, py, pz, lx, ly, lz), AIR, k, 1, scratch)[1] >= 0


@njit(**INLINE)
def _rim_agrees(sc, k, px, py, pz, light, scratch):
    """``(agree, hidden)``: whether shadow rays to :data:`RIM_POINTS` points of ``light``'s disc
    rim all find the same, and whether that is hidden."""
    lx, ly, lz, c = light[L_DX], light[L_DY], light[L_DZ], light[L_COS]
    ux, uy, uz, vx, vy, vz = light_frame(lx, ly, lz)
    st = math.sqrt(max(0.0, 1.0 - c * c))
    first = True
    for m in range(RIM_POINTS):
        a = 2.0 * math.pi * m / RIM_POINTS
        ca, sa = st * math.cos(a), st * math.sin(a)
        h = _blocked(sc, k, px, py, pz, c * lx + ca * ux + sa * vx, c * ly + ca * uy + sa * vy,
                     c * lz + ca * uz + sa * vz, scratch)
        if m == 0:
            first = h
        elif h != first:
            return False, first
    return True, first


@njit(**JIT)
def light_on_ground(sc, fin, k, px, py, pz, bseed, scratch):
    """``(r, g, b, sampled)``: irradiance over pi of the design's lights on ground object ``k``
    at ``p`` (mm), each light's straight light plus its caustic grid (module rule), and whether
    any of it was sampled. A point light's straight light is one shadow ray's; a disc's is exact
    (its mean cosine, ``l_z (1 + cos half angle) / 2``) or none where shadow rays to its rim
    agree, else one shadow ray's towards a point drawn in the disc (the penumbra)."""
    lights = fin.lights
    er = eg = eb = 0.0
    sampled = False
    for q in range(lights.shape[0]):
        light = lights[q]
        if light[L_COS] >= 1.0:
            agree, shadowed = True, _blocked(sc, k, px, py, pz, light[L_DX], light[L_DY], light[L_DZ], scratch)
            cos_in = light[L_DZ]
        else:
            agree, shadowed = _rim_agrees(sc, k, px, py, pz, light, scratch)
            cos_in = light[L_DZ] * 0.5 * (1.0 + light[L_COS])
        if not agree:
            sampled = True
            u1, u2 = uniform01(bseed, LIGHT_STREAM + 2 * q), uniform01(bseed, LIGHT_STREAM + 2 * q + 1)
            lx, ly, lz = in_disc(light, u1, u2)
            shadowed = _blocked(sc, k, px, py, pz, lx, ly, lz, scratch)
            cos_in = lz
        if not shadowed and cos_in > 0.0:
            er += cos_in / math.pi * light[L_R]
            eg += cos_in / math.pi * light[L_G]
            eb += cos_in / math.pi * light[L_B]
        cr, cg, cb = caustic_irradiance(fin, q, px, py, shadowed)
        er, eg, eb = er + cr, eg + cg, eb + cb
    return er, eg, eb, sampled


@njit(**JIT)
def ground(tables, it, bseed, kids, scratch):
    """The stage's ground at interaction ``it`` (module rule), reading ``tables`` (a
    :class:`~.records.Tables`): ``(children, r, g, b, bits)``,
    the radiance factors sent back at once (times the branch's weight; negative where the
    control variate takes back what the child will bring) and the object-mask bits consulted
    (:data:`NOISY_BIT` where its light was sampled). Black from below."""
    sc, fin, env_p, tex = tables.scene, tables.finishes, tables.env, tables.texels
    mat_f, mat = sc.mat_f, it.mat
    bits = np.int64(0)
    if it.dz >= 0.0:  # its lower side absorbs (a ray from below the stage ends there)
        return 0, 0.0, 0.0, 0.0, bits
    scale, rot = env_p[0] * env_p[2], env_p[1]
    ar, ag, ab = mat_f[mat, MG_ALBEDO], mat_f[mat, MG_ALBEDO + 1], mat_f[mat, MG_ALBEDO + 2]
    if mat_f[mat, MG_MIRROR] > 0.5:  # a tinted mirror: one branch
        kids[0, KD_X], kids[0, KD_Y], kids[0, KD_Z] = it.dx, it.dy, -it.dz
        kids[0, KW_R], kids[0, KW_G], kids[0, KW_B] = ar, ag, ab
        kids[0, K_SIDE] = 0.0
        return 1, 0.0, 0.0, 0.0, bits
    if mat_f[mat, MG_SHADOW] > 0.5:  # the background seen here, over what open ground receives
        br, bg, bb = env_lookup(tex, scale, rot, it.dx, it.dy, it.dz)
        lr, lg, lb = open_light(fin.lights)
        er_, eg_, eb_ = env_p[3] + lr, env_p[4] + lg, env_p[5] + lb
        ar = br / er_ if er_ > 0.0 else 1.0
        ag = bg / eg_ if eg_ > 0.0 else 1.0
        ab = bb / eb_ if eb_ > 0.0 else 1.0
    nk, base = 0, 1.0
    ior = mat_f[mat, MG_COAT_IOR]
    if ior > 0.0:  # a clear coat: its mirror branch, and what reaches the base
        cos_i = -it.dz
        base = coat(ior, it.dx, it.dy, it.dz, 0.0, 0.0, 1.0, cos_i, 1.0, kids, 0)
        if mat_f[mat, MG_ALPHA] > 0.0:
            bits |= NOISY_BIT
            rough_mirror(fin.mirror_albedo, fin.mirror_avg, mat_f[mat, MG_ALPHA], (it.dx, it.dy, it.dz),
                         (0.0, 0.0, 1.0), uniform01(bseed, FROST_STREAM), uniform01(bseed, FROST_STREAM + 1), kids,
                         mat_f, mat, ior)
        nk = 1
    ar, ag, ab = base * ar, base * ag, base * ab
    er, eg, eb, gridded = sky_irradiance(fin, it.px, it.py)
    if gridded:  # the sky grid's estimate, made once per design (module rule)
        if fin.lights.shape[0] > 0:
            dr, dg, db, sampled = light_on_ground(sc, fin, it.obj, it.px, it.py, it.pz, bseed, scratch)
            er, eg, eb = er + dr, eg + dg, eb + db
            if sampled:
                bits |= NOISY_BIT
        return nk, ar * er, ag * eg, ab * eb, bits
    bits |= NOISY_BIT
    # the diffuse base: a cosine-distributed direction in the probe's window, less the open sky's
    # light along it (module rule). s = cos(theta)^2 is uniform under the cosine measure.
    u1, u2 = uniform01(bseed, GROUND_STREAM), uniform01(bseed, GROUND_STREAM + 1)
    half_az, s_max, share, phi0, controlled = probe_window(mat_f, mat, it.px, it.py, it.pz)
    s, phi = u1 * s_max, phi0 + (2.0 * u2 - 1.0) * half_az
    r = math.sqrt(max(0.0, 1.0 - s))
    wx, wy, wz = r * math.cos(phi), r * math.sin(phi), math.sqrt(s)
    kids[nk, KD_X], kids[nk, KD_Y], kids[nk, KD_Z] = wx, wy, wz
    kids[nk, KW_R], kids[nk, KW_G], kids[nk, KW_B] = ar * share, ag * share, ab * share
    kids[nk, K_SIDE] = 0.0
    er = eg = eb = 0.0
    if controlled:
        lr, lg, lb = env_lookup(tex, scale, rot, wx, wy, wz)
        er, eg, eb = env_p[3] - share * lr, env_p[4] - share * lg, env_p[5] - share * lb
    if fin.lights.shape[0] > 0:
        dr, dg, db, _ = light_on_ground(sc, fin, it.obj, it.px, it.py, it.pz, bseed, scratch)
        er, eg, eb = er + dr, eg + dg, eb + db
    return nk + 1, ar * er, ag * eg, ab * eb, bits
