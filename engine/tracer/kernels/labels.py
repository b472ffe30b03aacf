"""Labels at a hit on the outer wall or a closure part, compiled: where the hit falls on which
label, and what the sheet does to the branch there.

Design rule: a label is a decal over a render object, not an object: :func:`label_hit` is
called by the surface layer (:mod:`.surface`) at every hit on an object labels lie on (the outer wall, object 0, and
for prints on the cap a closure part; their bits are ``lab.objects``), and either hands the
hit back (``nk = -1``: no label there, or a clear part of one; the object's own material
follows) or answers for its covered fraction ``alpha``: children written into ``kids`` (coat or
foil mirror branches) and the radiance the lit diffuse sheet sends back at once; the uncovered
fraction ``1 - alpha`` goes to what lies beneath (the surface layer's mask,
:func:`engine.tracer.kernels.surface.scatter`). The label tables are the record ``lab`` of
:func:`engine.tracer.tables.labels.label_arrays` (their columns are the ``D_``, ``L_``, ``LF_``
and ``P_`` layouts below); a design without
labels passes empty tables and costs one length test per hit.

Relief. The caller passes the shading normal the object's relief bends the geometric one to
(bump tiles under the label, :func:`engine.tracer.kernels.finish.shading_frame`): the coat's
mirror child, the irradiance lookups, the lights and an embossed region's bend start from it;
the geometric normal still decides media (a mirror child a bent normal would send into the wall
reflects about the geometric normal; the glass beneath goes through the surface layer's bump
adapter). A frosted
band under a label's uncovered texels is drawn smooth.

Lookup. Each label's place row (``lab.place``) names its surface, its object and the band of
the object's arc length ``v`` it may cover. On the wall the hit's surface coordinates are the
labels' ``(theta, h)`` (:mod:`engine.appearance.surface`): ``theta`` the polar angle in the
bottle frame, ``h`` the arc length along the section (round walls, the segment's own ``v``) or
the height z (swept). On the cap's skirt ``(theta, h)`` is the world polar angle and z, looked
up in the print's decal; on the cap's top ``(s, t)`` is affine in the hit's ``(x, y)``
(:func:`_top_st`). A closure is opaque: a print on it is seen from outside only, gets no light
from behind, and its uncovered fraction is handed back (``rest``) for the closure's material.
Labels are tried from the last (on top) down; the first whose artwork covers the point
(alpha > 0 and not a clear-vinyl region) is the one hit, every label consulted on the way sets
its bit in the returned mask (bit :data:`LABEL_BIT0` + k, labels from 30 on share bit 62), so a
pixel's record says which labels its result depends on. Texels are fetched bilinearly (texel
centres at half-integers), region codes at the nearest texel.

Sheet model (mm, radiance in the environment's units). ``Irr(n)`` is the environment's
cosine-convolved irradiance divided by pi (a lat-long table prefiltered once per
environment, :mod:`engine.tracer.tables.labels`; exactly 1 everywhere in a white furnace), looked up by
normal; it ignores the bottle's own occlusion (a distant-environment approximation).

* seen from outside (the ray in air): a coat reflects ``Rc`` (the label's ``specular`` at
  normal incidence, rising with the dielectric Fresnel term of index 1.5 towards grazing) as a
  mirror child about the shading normal; the rest ``1 - Rc`` reaches the paper, which sends back
  ``colour x (K Irr(n) + T Irr(-n))`` (diffuse reflection of the front colour times ``diffuse``
  K, diffuse transmission T of light from the far side) plus the design's lights;
* seen from inside the glass: the back face (artwork at :func:`engine.appearance.decal.
  back_coordinates`, ``(1 - s, t)``, or the back colour), index-matched to the glass (no coat,
  no Fresnel child): ``back colour x (K Irr(-n) + T Irr(n))`` plus lights; the ray ends there;
* foil (gold, silver): a conductor with the finish's complex IOR; ``gloss`` of the reflection
  is a mirror child, ``1 - gloss`` a rough lobe approximated by ``F(cos) Irr(n)``;
* clear vinyl: the glass shows through, exactly as without a label; with a white underprint the
  region is the printed ink over the underprint (colour x underprint, diffuse);
* varnish: a second coat over the paper's, weighted by its gloss (``Rc += gloss F (1 - Rc)``);
* emboss: the paper with its shading normal bent by the slope of a relief of ``depth_mm`` whose
  height is the region's (bilinear) indicator; slopes per mm use the label's size.

Relabel. Every sheet emission is ``alpha (P c + Q)`` per channel, with ``c`` the face colour
(texel or plain colour) and ``P``, ``Q`` free of it; the integrator sums these terms apart from
the rest of the sample's radiance and adds them last. With record buffers (a job's label
record) each hit's weight, alpha, ``P``, ``Q`` and artwork coordinates are written in order,
and each sample's radiance without them: :func:`replay_samples` then recomputes a sample's
radiance for new artwork colours with the same operations in the same order, bit for bit
equal to tracing it again, as long as the ray tree is the same (alpha, regions, coefficients
and placement unchanged: engine.tracer.job checks).

Lights are directional (``Design.lights``: towards the light, colour x intensity is the
irradiance at normal incidence). Each lit sheet point casts one straight shadow ray per light
towards it (:func:`shadow`): labels on the outer wall block it (times ``1 - alpha``), glass and
liquid attenuate it by the Fresnel transmittance of each interface crossed (``1 - R`` with the
real indices; total internal reflection blocks) and by Beer-Lambert absorption, a closure part
(any material but a dielectric interface) blocks it, and refraction is ignored (the ray goes
straight; caustics are not followed). Label points and plastic closures
(:func:`engine.tracer.kernels.finish.lit_by_lights`) use lights.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .intersect import F_COS, F_SIN, O_KIND, O_MAT, REVOLVED, nearest_hit, object_media
from .materials import (K_SIDE, KD_X, KD_Y, KD_Z, KW_B, KW_G, KW_R, M_KIND, SMOOTH_DIELECTRIC,
                        fresnel_conductor, fresnel_dielectric)
from .revolved import segment_v
from .records import Ray
from .jit import INLINE, JIT
from .sampling import env_lookup

# The label tables are a records.LabelTables (engine.tracer.tables.labels.label_arrays); its
# record buffers (engine.tracer.tables.labels.with_buffers; zero rows: not recording) are the hits
# (float64 (cap, H_COLS), int64 (cap, 2)), their count and overflow flag (int64 (2,)), the
# current sample's radiance without label terms (float64 (3,)), and per sample of the call its
# radiance without label terms (float64 (S, 3)) and its hits' range (int64 (S, 2)).
#: Columns of a recorded hit: branch weight, alpha, the colour factor P and the colour-free term
#: Q of its emission ``alpha (P c + Q)``, the face's artwork coordinates; label row and face.
H_WR, H_WG, H_WB, H_ALPHA, H_P, H_Q, H_S, H_T = 0, 1, 2, 3, 4, 7, 10, 11
H_COLS = 12
H_LABEL, H_FACE = 0, 1
# The layouts of the label tables, owned here and filled by engine.tracer.tables.labels.
#: Columns of a decal row (:func:`engine.tracer.tables.labels.pack_decals`): the footprint in
#: ``(theta, h)``, the grid's node counts and its first node.
D_THETA0, D_THETA1, D_H0, D_H1, D_NT, D_NH, D_OFFSET = range(7)
D_COLS = 7
#: Columns of a label row: coefficients, front and back plain colours (linear RGB), texture rows
#: of front and back (-1: plain), region map row (-1: none), first finish row and count.
(L_DIFFUSE, L_SPECULAR, L_TRANSMISSION, L_FRONT_R, L_FRONT_G, L_FRONT_B, L_BACK_R, L_BACK_G,
 L_BACK_B, L_FRONT_TEX, L_BACK_TEX, L_REGION_MAP, L_REGION0, L_NREGIONS) = range(14)
L_COLS = 14
#: Columns of a finish-region row: kind code (:data:`FINISH_CODES`), relief (mm), gloss,
#: conductor ``n`` and ``k`` per RGB (foils; 0 otherwise), underprint reflectance per RGB.
LF_KIND, LF_DEPTH, LF_GLOSS, LF_N, LF_K, LF_UNDER = 0, 1, 2, 3, 6, 9
LF_COLS = 12
#: Columns of a label's place row: its surface (:data:`WALL`, :data:`CAP_TOP`,
#: :data:`CAP_SKIRT`), the render object it lies on, the band of the object's arc length ``v``
#: it may cover (mm; the whole object for the wall), and for a cap-top print its centre (mm)
#: and the unit direction from its top edge to its bottom edge.
P_SURFACE, P_OBJECT, P_V0, P_V1, P_CX, P_CY, P_BX, P_BY = range(8)
P_COLS = 8
WALL, CAP_TOP, CAP_SKIRT = 0, 1, 2
#: Surface codes of a place row by ``Label.surface``.
SURFACE_CODES = {"wall": WALL, "cap-top": CAP_TOP, "cap-skirt": CAP_SKIRT}
#: Finish kind codes (0: plain paper), and by ``FinishRegion.finish``.
GOLD_FOIL, SILVER_FOIL, CLEAR_VINYL, CLEAR_VINYL_WHITE, EMBOSS, VARNISH = 1, 2, 3, 4, 5, 6
FINISH_CODES = {"gold_foil": GOLD_FOIL, "silver_foil": SILVER_FOIL, "clear_vinyl": CLEAR_VINYL,
                "clear_vinyl_white": CLEAR_VINYL_WHITE, "emboss": EMBOSS, "varnish": VARNISH}
#: Index of the paper's coat and of varnish (engine.appearance.presets.COAT_IOR).
COAT_IOR = 1.5
#: First bit of the labels in a sample's object mask (objects use the bits below).
LABEL_BIT0 = 32
MAX_LABEL_BIT = 62
#: Boundaries a shadow ray may cross before it counts as blocked.
SHADOW_CROSSINGS = 24
AIR = 0


@njit(**INLINE)
def label_bit(k):
    """The object-mask bit of label ``k``."""
    return np.int64(1) << np.int64(min(LABEL_BIT0 + k, MAX_LABEL_BIT))


@njit(**JIT)
def decal_lookup(rows, nodes, k, theta, h):
    """``(s, t)`` of surface point ``(theta, h)`` on label ``k``'s decal, ``(nan, nan)`` off the
    label: the lookup of :mod:`engine.appearance.decal` (module rule there), compiled."""
    t0 = rows[k, D_THETA0]
    nt, nh, first = int(rows[k, D_NT]), int(rows[k, D_NH]), int(rows[k, D_OFFSET])
    fx = ((theta - t0) % (2.0 * math.pi)) / (rows[k, D_THETA1] - t0) * (nt - 1)
    fy = (h - rows[k, D_H0]) / (rows[k, D_H1] - rows[k, D_H0]) * (nh - 1)
    if not (fx >= 0.0 and fx <= nt - 1 and fy >= 0.0 and fy <= nh - 1):
        return math.nan, math.nan
    j, i = min(int(fx), nt - 2), min(int(fy), nh - 2)
    wx, wy = fx - j, fy - i
    n00 = first + i * nt + j
    n10 = n00 + nt
    out_s = out_t = 0.0
    for c in range(2):
        lo = nodes[n00, c] + (nodes[n00 + 1, c] - nodes[n00, c]) * wx
        hi = nodes[n10, c] + (nodes[n10 + 1, c] - nodes[n10, c]) * wx
        v = lo * (1.0 - wy) + hi * wy
        if c == 0:
            out_s = v
        else:
            out_t = v
    if out_s >= 0.0 and out_s <= 1.0 and out_t >= 0.0 and out_t <= 1.0:
        return out_s, out_t
    return math.nan, math.nan


@njit(**JIT)
def texel(lab, m, s, t):
    """Bilinear straight RGBA of texture ``m`` at artwork ``(s, t)`` (edges clamp)."""
    texels, tex_i = lab.texels, lab.tex_i
    first, w, h = tex_i[m, 0], tex_i[m, 1], tex_i[m, 2]
    x = min(max(s * w - 0.5, 0.0), w - 1.0)
    y = min(max(t * h - 0.5, 0.0), h - 1.0)
    x0, y0 = min(int(x), w - 2 if w > 1 else 0), min(int(y), h - 2 if h > 1 else 0)
    x1, y1 = min(x0 + 1, w - 1), min(y0 + 1, h - 1)
    ax, ay = x - x0, y - y0
    a, b = first + y0 * w, first + y1 * w
    r = g = bl = al = 0.0
    for c in range(4):
        v = ((texels[a + x0, c] * (1.0 - ax) + texels[a + x1, c] * ax) * (1.0 - ay)
             + (texels[b + x0, c] * (1.0 - ax) + texels[b + x1, c] * ax) * ay)
        if c == 0:
            r = v
        elif c == 1:
            g = v
        elif c == 2:
            bl = v
        else:
            al = v
    return r, g, bl, al


@njit(**INLINE)
def _code_at(lab, q, s, t):
    """Region code of map ``q`` at the texel containing ``(s, t)``."""
    first, w, h = lab.region_i[q, 0], lab.region_i[q, 1], lab.region_i[q, 2]
    x = min(max(int(s * w), 0), w - 1)
    y = min(max(int(t * h), 0), h - 1)
    return int(lab.codes[first + y * w + x])


@njit(**JIT)
def _indicator(lab, q, code, s, t):
    """Bilinear of ``[region code == code]`` at ``(s, t)`` (texel centres at half-integers)."""
    first, w, h = lab.region_i[q, 0], lab.region_i[q, 1], lab.region_i[q, 2]
    codes = lab.codes
    x = min(max(s * w - 0.5, 0.0), w - 1.0)
    y = min(max(t * h - 0.5, 0.0), h - 1.0)
    x0, y0 = int(x), int(y)
    x1, y1 = min(x0 + 1, w - 1), min(y0 + 1, h - 1)
    ax, ay = x - x0, y - y0
    v00 = 1.0 if codes[first + y0 * w + x0] == code else 0.0
    v01 = 1.0 if codes[first + y0 * w + x1] == code else 0.0
    v10 = 1.0 if codes[first + y1 * w + x0] == code else 0.0
    v11 = 1.0 if codes[first + y1 * w + x1] == code else 0.0
    return (v00 * (1.0 - ax) + v01 * ax) * (1.0 - ay) + (v10 * (1.0 - ax) + v11 * ax) * ay


@njit(**INLINE)
def surface_point(seg, obj_i, obj_f, part, px, py, pz):
    """The labels' ``(theta, h)`` of a point on the outer wall (object 0) on part ``part``."""
    if obj_i[0, O_KIND] == REVOLVED:
        return math.atan2(py, px), segment_v(seg, part, px, py, pz)
    return math.atan2(py, px) - math.atan2(obj_f[0, F_SIN], obj_f[0, F_COS]), pz


@njit(**INLINE)
def label_point(seg, obj_i, obj_f, obj, part, px, py, pz):
    """``(theta, h, v)`` of a point on render object ``obj`` (segment or slab row ``part``):
    on the outer wall (object 0) the labels' ``(theta, h)`` (:func:`surface_point`; ``v = h``);
    on a closure part the world polar angle, ``h = z`` (mm) and the part's arc length ``v``."""
    if obj == 0:
        theta, h = surface_point(seg, obj_i, obj_f, part, px, py, pz)
        return theta, h, h
    return math.atan2(py, px), pz, segment_v(seg, part, px, py, pz)


@njit(**INLINE)
def _top_st(lab, k, px, py):
    """Artwork ``(s, t)`` of the point ``(px, py)`` (mm) under cap-top print ``k`` (affine:
    ``t`` grows along the place row's unit direction ``b``, ``s`` along ``(-b_y, b_x)``, to the
    right of a reader looking down with the print's bottom edge towards them)."""
    pl = lab.place[k]
    x, y = px - pl[P_CX], py - pl[P_CY]
    bx, by = pl[P_BX], pl[P_BY]
    return 0.5 + (-by * x + bx * y) / lab.size[k, 0], 0.5 + (bx * x + by * y) / lab.size[k, 1]


@njit(**JIT)
def find_label(lab, obj, theta, h, v, px, py):
    """``(k, s, t, alpha, code, bits)`` of the label covering the point of object ``obj`` at
    :func:`label_point` ``(theta, h, v)`` (world ``px, py`` for cap-top prints): ``k = -1``
    when none covers it; ``bits`` the mask bits of every label consulted (module rule)."""
    rows, lf, place = lab.rows, lab.f, lab.place
    bits = np.int64(0)
    for k in range(rows.shape[0] - 1, -1, -1):
        if int(place[k, P_OBJECT]) != obj or not (v >= place[k, P_V0] and v <= place[k, P_V1]):
            continue
        if int(place[k, P_SURFACE]) == CAP_TOP:
            s, t = _top_st(lab, k, px, py)
            if not (s >= 0.0 and s <= 1.0 and t >= 0.0 and t <= 1.0):
                continue
        else:
            s, t = decal_lookup(rows, lab.nodes, k, theta, h)
            if not (s == s):
                continue
        bits |= label_bit(k)
        alpha = 1.0
        m = int(lf[k, L_FRONT_TEX])
        if m >= 0:
            alpha = texel(lab, m, s, t)[3]
        code = 0
        q = int(lf[k, L_REGION_MAP])
        if q >= 0:
            code = _code_at(lab, q, s, t)
            if code > 0 and int(lab.finish[int(lf[k, L_REGION0]) + code - 1, LF_KIND]) == CLEAR_VINYL:
                alpha = 0.0
        if alpha > 0.0:
            return k, s, t, min(alpha, 1.0), code, bits
    return -1, 0.0, 0.0, 0.0, 0, bits


@njit(**JIT)
def shadow(sc, lab, ox, oy, oz, lx, ly, lz, medium, last, side, scratch):
    """Transmittance ``(r, g, b, bits)`` of a straight shadow ray through scene ``sc`` from a
    point on object ``last`` (left with ``side``, in ``medium``) along unit ``l`` (module rule:
    labels block by their alpha, interfaces pass ``1 - R``, media absorb, closure parts block;
    refraction ignored). Shared by label sheets and plastic closures."""
    seg, tab, slab_f, slab_i, obj_i, obj_f, _ = sc.geom
    media, mat_i = sc.media, sc.mat_i
    tr = tg = tb = 1.0
    bits = np.int64(0)
    for _ in range(SHADOW_CROSSINGS):
        t, k, part, nx, ny, nz = nearest_hit(sc.geom, Ray(ox, oy, oz, lx, ly, lz), medium, last, side, scratch)
        if k < 0:
            return tr, tg, tb, bits
        if medium != AIR:
            tr *= math.exp(-media[medium, 1] * t)
            tg *= math.exp(-media[medium, 2] * t)
            tb *= math.exp(-media[medium, 3] * t)
        if mat_i[obj_i[k, O_MAT], M_KIND] != SMOOTH_DIELECTRIC:  # a closure part: opaque
            return 0.0, 0.0, 0.0, bits
        ox, oy, oz = ox + t * lx, oy + t * ly, oz + t * lz
        if k == 0:  # wall labels block by their alpha (a closure part, prints and all, stopped the ray above)
            theta, h = surface_point(seg, obj_i, obj_f, part, ox, oy, oz)
            kl, s, tt, alpha, code, b = find_label(lab, 0, theta, h, h, ox, oy)
            bits |= b
            if kl >= 0:
                tr *= 1.0 - alpha
                tg *= 1.0 - alpha
                tb *= 1.0 - alpha
                if alpha >= 1.0:
                    return 0.0, 0.0, 0.0, bits
        front, back = object_media(obj_i, obj_f, k, oz)
        dn = nx * lx + ny * ly + nz * lz
        inc, trn = (front, back) if dn < 0.0 else (back, front)
        refl, cos_t = fresnel_dielectric(abs(dn), media[trn, 0] / media[inc, 0])
        if refl >= 1.0:
            return 0.0, 0.0, 0.0, bits
        tr *= 1.0 - refl
        tg *= 1.0 - refl
        tb *= 1.0 - refl
        medium, last, side = trn, k, (1 if dn >= 0.0 else -1)
    return 0.0, 0.0, 0.0, bits


@njit(**INLINE)
def _lights(sc, lab, obj, px, py, pz, nx, ny, nz, out_in, scratch):
    """Irradiance / pi from the design's lights on the sheet at ``p`` of object ``obj`` with
    outward normal ``n``: ``(front r, g, b, back r, g, b, bits)``; ``out_in`` is the medium on
    the inner side. A print on a closure (``obj > 0``, opaque) is lit from the front only."""
    lights = lab.lights
    fr = fg = fb = br = bg = bb = 0.0
    bits = np.int64(0)
    for i in range(lights.shape[0]):
        lx, ly, lz = lights[i, 0], lights[i, 1], lights[i, 2]
        c = nx * lx + ny * ly + nz * lz
        if c == 0.0 or (c < 0.0 and obj != 0):
            continue
        if c > 0.0:  # the light is on the outer side: the front face is lit
            sr, sg, sb, b = shadow(sc, lab, px, py, pz, lx, ly, lz, AIR, obj, 1, scratch)
        else:
            sr, sg, sb, b = shadow(sc, lab, px, py, pz, lx, ly, lz, out_in, obj, -1, scratch)
        bits |= b
        f = abs(c) / math.pi
        er, eg, eb = lights[i, 3] * sr * f, lights[i, 4] * sg * f, lights[i, 5] * sb * f
        if c > 0.0:
            fr, fg, fb = fr + er, fg + eg, fb + eb
        else:
            br, bg, bb = br + er, bg + eg, bb + eb
    return fr, fg, fb, br, bg, bb, bits


@njit(**INLINE)
def _mirror_kid(kids, c, d, n, g, w):
    """A mirror child of the ray along ``d`` about the unit shading normal ``n`` (facing the
    ray) of weights ``w`` into ``kids[c]``; about the geometric normal ``g`` instead where a bent
    normal would send it into the wall (the branch must leave on the side it came from). All
    four are 3-tuples."""
    dx, dy, dz = d
    nx, ny, nz = n
    gx, gy, gz = g
    wr, wg, wb = w
    d = -(dx * nx + dy * ny + dz * nz)
    rx, ry, rz = dx + 2.0 * d * nx, dy + 2.0 * d * ny, dz + 2.0 * d * nz
    if rx * gx + ry * gy + rz * gz <= 0.0:
        d = -(dx * gx + dy * gy + dz * gz)
        rx, ry, rz = dx + 2.0 * d * gx, dy + 2.0 * d * gy, dz + 2.0 * d * gz
    kids[c, KD_X], kids[c, KD_Y], kids[c, KD_Z] = rx, ry, rz
    kids[c, KW_R], kids[c, KW_G], kids[c, KW_B] = wr, wg, wb
    kids[c, K_SIDE] = 0.0


@njit(**JIT)
def _emboss_normal(lab, k, q, code, depth, s, t, px, py, nx, ny, nz):
    """Shading normal bent by the relief ``depth x indicator`` of region ``code`` (mm) of
    label ``k`` about the unit normal ``n`` (the sheet's, relief of the surface included)."""
    w, h = lab.region_i[q, 1], lab.region_i[q, 2]
    ds, dt = 1.0 / w, 1.0 / h
    gs = (_indicator(lab, q, code, s + ds, t) - _indicator(lab, q, code, s - ds, t)) / (2.0 * ds)
    gt = (_indicator(lab, q, code, s, t + dt) - _indicator(lab, q, code, s, t - dt)) / (2.0 * dt)
    gu = depth * gs / lab.size[k, 0]  # dH / d(arc length around), s grows with azimuth
    gv = depth * gt / lab.size[k, 1]  # dH / d(slant down the wall), t grows downwards
    if int(lab.place[k, P_SURFACE]) == CAP_TOP:  # s and t grow along fixed directions
        bx, by = lab.place[k, P_BX], lab.place[k, P_BY]
        ux, uy, uz, vx, vy, vz = -by, bx, 0.0, bx, by, 0.0
    else:
        rho = math.sqrt(px * px + py * py)
        ex, ey = (px / rho, py / rho) if rho > 0.0 else (1.0, 0.0)
        ux, uy, uz = -ey, ex, 0.0  # around, increasing azimuth
        vx, vy, vz = nz * ex, nz * ey, -(nx * ex + ny * ey)  # down the meridian, tangent
    a = ux * nx + uy * ny + uz * nz
    ux, uy, uz = ux - a * nx, uy - a * ny, uz - a * nz
    hu = math.sqrt(ux * ux + uy * uy + uz * uz)
    if int(lab.place[k, P_SURFACE]) == CAP_TOP:
        a = vx * nx + vy * ny + vz * nz
        vx, vy, vz = vx - a * nx, vy - a * ny, vz - a * nz
    hv = math.sqrt(vx * vx + vy * vy + vz * vz)
    mx, my, mz = nx, ny, nz
    if hu > 0.0:
        mx, my, mz = mx - gu * ux / hu, my - gu * uy / hu, mz - gu * uz / hu
    if hv > 0.0:
        mx, my, mz = mx - gv * vx / hv, my - gv * vy / hv, mz - gv * vz / hv
    m = math.sqrt(mx * mx + my * my + mz * mz)
    return mx / m, my / m, mz / m


@njit(**INLINE)
def _emit(alpha, p, c, q):
    """One channel of a sheet's emission (module rule: the one formula tracing and replay use)."""
    return alpha * (p * c + q)


@njit(**JIT)
def face_colour(lab, k, face, s_face, t):
    """Linear RGB of face ``face`` (0 front, 1 back) of label ``k`` at that face's artwork
    coordinates (the texel, else the plain colour)."""
    lf = lab.f
    m = int(lf[k, L_FRONT_TEX]) if face == 0 else int(lf[k, L_BACK_TEX])
    if m >= 0:
        r, g, b, _ = texel(lab, m, s_face, t)
        return r, g, b
    col = L_FRONT_R if face == 0 else L_BACK_R
    return lf[k, col], lf[k, col + 1], lf[k, col + 2]


@njit(**JIT)
def _record_hit(lab, w, alpha, p, q, s_face, t, k, face):
    """Keep a label hit for a relabel (``lab``'s record buffers): the branch's weight ``w``, the
    texel's ``alpha``, its emission factors ``p`` and ``q`` (RGB 3-tuples; module rule), its
    coordinates ``(s_face, t)`` on label ``k``'s ``face``; an overflow flags the call."""
    wr, wg, wb = w
    pr, pg, pb = p
    qr, qg, qb = q
    hf, hn = lab.hit_f, lab.hit_n
    i = hn[0]
    if i >= hf.shape[0]:
        hn[1] = 1  # overflow: this call's samples cannot be replayed
        return
    hf[i, H_WR], hf[i, H_WG], hf[i, H_WB], hf[i, H_ALPHA] = wr, wg, wb, alpha
    hf[i, H_P], hf[i, H_P + 1], hf[i, H_P + 2] = pr, pg, pb
    hf[i, H_Q], hf[i, H_Q + 1], hf[i, H_Q + 2] = qr, qg, qb
    hf[i, H_S], hf[i, H_T] = s_face, t
    lab.hit_i[i, H_LABEL], lab.hit_i[i, H_FACE] = k, face
    hn[0] = i + 1


@njit(**JIT)
def record_sample(lab, s, h0):
    """After sample ``s`` of a call (recording only): its radiance without label terms and the
    range ``[h0, now)`` of its hits."""
    if lab.hit_f.shape[0] == 0:
        return
    sf = lab.smp_f
    sf[s, 0], sf[s, 1], sf[s, 2] = lab.rest[0], lab.rest[1], lab.rest[2]
    lab.smp_i[s, 0], lab.smp_i[s, 1] = h0, lab.hit_n[0]


@njit(**INLINE)
def finish_radiance(lr, lg, lb, ar, ag, ab):
    """A sample's radiance: the rest plus the label terms, cleaned (non-finite -> 0). A sample
    may be negative where a control variate takes back more than the sample brought (the
    ground's, :mod:`.surface`): only the pixel's mean is a radiance, and the film clamps that."""
    lr += ar
    lg += ag
    lb += ab
    if not (math.isfinite(lr) and math.isfinite(lg) and math.isfinite(lb)):
        lr = lg = lb = 0.0
    return lr, lg, lb


@njit(**JIT)
def replay_samples(lab, s0, count, smp_f, smp_i, hit_f, hit_i, out_sum, out_sumsq):
    """Per-pixel sums (as :func:`~engine.tracer.kernels.tile.render_pixels` writes them) of
    recorded samples ``s0[p] .. s0[p] + count[p] - 1`` with the label tables ``lab`` (module
    rule: the same operations in the same order as tracing them)."""
    for p in range(s0.shape[0]):
        sr = sg = sb = ssq = 0.0
        for s in range(s0[p], s0[p] + count[p]):
            ar = ag = ab = 0.0
            for i in range(smp_i[s, 0], smp_i[s, 1]):
                cr, cg, cb = face_colour(lab, hit_i[i, H_LABEL], hit_i[i, H_FACE], hit_f[i, H_S], hit_f[i, H_T])
                a = hit_f[i, H_ALPHA]
                ar += hit_f[i, H_WR] * _emit(a, hit_f[i, H_P], cr, hit_f[i, H_Q])
                ag += hit_f[i, H_WG] * _emit(a, hit_f[i, H_P + 1], cg, hit_f[i, H_Q + 1])
                ab += hit_f[i, H_WB] * _emit(a, hit_f[i, H_P + 2], cb, hit_f[i, H_Q + 2])
            r, g, b = finish_radiance(smp_f[s, 0], smp_f[s, 1], smp_f[s, 2], ar, ag, ab)
            sr += r
            sg += g
            sb += b
            lum = (r + g + b) / 3.0
            ssq += lum * lum
        out_sum[p, 0] = sr
        out_sum[p, 1] = sg
        out_sum[p, 2] = sb
        out_sumsq[p] = ssq


@njit(**JIT)
def label_hit(tables, it, wr, wg, wb, kids, scratch):
    """What a label does at the surface interaction ``it`` (a :class:`~.records.Interaction`)
    on the object it lies on (module rule): a mask over what lies beneath.

    ``it``'s normal is the object's oriented unit normal (pointing into the air), its shading
    normal ``s`` the one the surface's relief bends it to (``s = n`` without relief), ``w`` the
    branch's weight (recorded for a relabel); ``tables`` a :class:`~.records.Tables`.

    Returns ``(nk, r, g, b, bits, rest, guide)``: ``nk = -1`` when no label covers the point
    (the object's material follows), else the number of children in ``kids`` and the radiance
    (per unit branch weight) the sheet sends back now; ``bits`` the labels consulted
    (object-mask bits, module rule); ``rest`` the uncovered fraction ``1 - alpha`` of the texel,
    which the caller gives what lies beneath (:func:`engine.tracer.kernels.surface.scatter`:
    the glass of the wall, a closure's own material); ``guide`` the albedo the texel shows the
    denoiser (its colour times ``alpha``, plus ``rest`` of white; ``-1`` where no label covers).
    """
    lab, sc, env_p = tables.labels, tables.scene, tables.env
    bx, by, bz = it.sx, it.sy, it.sz
    seg, tab, slab_f, slab_i, obj_i, obj_f, _ = sc.geom
    px, py, pz, nx, ny, nz, dx, dy, dz = it.px, it.py, it.pz, it.nx, it.ny, it.nz, it.dx, it.dy, it.dz
    obj, part, inc, trn = it.obj, it.part, it.inc, it.trn
    theta, h, v = label_point(seg, obj_i, obj_f, obj, part, px, py, pz)
    k, s, t, alpha, code, bits = find_label(lab, obj, theta, h, v, px, py)
    if k < 0 or (obj != 0 and nx * dx + ny * dy + nz * dz >= 0.0):  # a closure: outside only
        return -1, 0.0, 0.0, 0.0, bits, 0.0, (-1.0, -1.0, -1.0)
    lf, irr = lab.f, lab.irr
    scale, rot = env_p[0], env_p[1]
    outside = inc == AIR
    kind, frow = 0, -1
    if code > 0:
        frow = int(lf[k, L_REGION0]) + code - 1
        kind = int(lab.finish[frow, LF_KIND])
    diff, trans = lf[k, L_DIFFUSE], lf[k, L_TRANSMISSION]
    face = 0 if outside else 1
    s_face = s if outside else 1.0 - s  # back_coordinates
    cr, cg, cb = face_colour(lab, k, face, s_face, t)
    # shading normal (outward): the surface's relief, then an embossed region's
    sx, sy, sz = bx, by, bz
    if outside and kind == EMBOSS:
        sx, sy, sz = _emboss_normal(lab, k, int(lf[k, L_REGION_MAP]), code, lab.finish[frow, LF_DEPTH],
                                    s, t, px, py, bx, by, bz)
    # irradiance / pi on the outer (o*) and the inner (i*) side: environment, then lights
    or_, og, ob = env_lookup(irr, scale, rot, sx, sy, sz)
    ir, ig, ib = env_lookup(irr, scale, rot, -sx, -sy, -sz)
    if obj != 0:  # a print on an opaque closure: no light from behind
        ir = ig = ib = 0.0
    if lab.lights.shape[0] > 0:
        fr, fg, fb, br, bg, bb, b = _lights(sc, lab, obj, px, py, pz, sx, sy, sz, trn if outside else inc,
                                            scratch)
        bits |= b
        or_, og, ob, ir, ig, ib = or_ + fr, og + fg, ob + fb, ir + br, ig + bg, ib + bb
    nk = 0
    # emission alpha (P c + Q): P the colour's factor, Q what no colour tints
    pr = pg = pb = qr = qg = qb = 0.0
    if outside:
        cos_i = max(-(dx * sx + dy * sy + dz * sz), 1e-6)
        if kind == GOLD_FOIL or kind == SILVER_FOIL:
            f = lab.finish[frow]
            g = f[LF_GLOSS]
            rr = fresnel_conductor(cos_i, f[LF_N], f[LF_K])
            rg = fresnel_conductor(cos_i, f[LF_N + 1], f[LF_K + 1])
            rb = fresnel_conductor(cos_i, f[LF_N + 2], f[LF_K + 2])
            _mirror_kid(kids, 0, (dx, dy, dz), (sx, sy, sz), (nx, ny, nz),
                        (alpha * g * rr, alpha * g * rg, alpha * g * rb))
            nk = 1
            # the rough part of the foil: a lobe as wide as the hemisphere
            qr, qg, qb = rr * (1.0 - g) * or_, rg * (1.0 - g) * og, rb * (1.0 - g) * ob
        else:
            r0, _ = fresnel_dielectric(1.0, COAT_IOR)
            rf, _ = fresnel_dielectric(cos_i, COAT_IOR)
            rc = min(1.0, lf[k, L_SPECULAR] * rf / r0)
            if kind == VARNISH:
                rc += lab.finish[frow, LF_GLOSS] * rf * (1.0 - rc)
            if rc > 0.0:
                _mirror_kid(kids, 0, (dx, dy, dz), (sx, sy, sz), (nx, ny, nz), (alpha * rc, alpha * rc, alpha * rc))
                nk = 1
            base = 1.0 - rc
            pr = base * (diff * or_ + trans * ir)
            pg = base * (diff * og + trans * ig)
            pb = base * (diff * ob + trans * ib)
            if kind == CLEAR_VINYL_WHITE:  # the ink over the white underprint
                f = lab.finish[frow]
                pr, pg, pb = pr * f[LF_UNDER], pg * f[LF_UNDER + 1], pb * f[LF_UNDER + 2]
    else:  # the back face, seen through the glass: the ray ends on the paper
        pr, pg, pb = diff * ir + trans * or_, diff * ig + trans * og, diff * ib + trans * ob
    er, eg, eb = _emit(alpha, pr, cr, qr), _emit(alpha, pg, cg, qg), _emit(alpha, pb, cb, qb)
    if lab.hit_f.shape[0] > 0:
        _record_hit(lab, (wr, wg, wb), alpha, (pr, pg, pb), (qr, qg, qb), s_face, t, k, face)
    rest = 1.0 - alpha if alpha < 1.0 else 0.0
    return nk, er, eg, eb, bits, rest, (alpha * cr + rest, alpha * cg + rest, alpha * cb + rest)
