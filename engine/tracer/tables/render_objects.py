"""Render objects: a design's surfaces compiled into the flat tables the kernels read.

Design rule: the tracer owns no geometry of its own. Every surface comes from the geometry
engine's exact curves (:func:`engine.geometry.validate.body_profile`) and becomes one *render
object*: an exact intersector (a revolved chain of segments, a swept non-round wall cut into
slabs, or a flat region of a plane), the medium on each side of its oriented normal, and a
material. A cap, a label or a mesh is one more row, not one more ``if``. Tables (columns named
in :mod:`engine.tracer.kernels.revolved` ``S_*`` and :mod:`~engine.tracer.kernels.intersect`
``O_*`` / ``F_*``):

=============  =====================  ================================  ================
object         intersector            oriented normal points to          front | back
=============  =====================  ================================  ================
outer wall     revolved / swept       away from the glass                air | glass
bottom         plane z=0 / revolved   away from the glass (down)         air | glass
inner wall     revolved / swept       into the cavity                    liquid below the
                                                                         fill, else air | glass
inner base     plane / revolved       into the cavity (up)               liquid or air | glass
rim            plane z=z_top, annulus up                                 air | glass
free surface   plane z=fill, region   up                                 air | liquid
closure part   revolved (closed       away from the part's material      air | air (opaque:
               meridian chain)                                           reflects only)
=============  =====================  ================================  ================

Closure parts come after the bottle's objects, from their own cached tables
(:mod:`engine.tracer.tables.finishes`).

The geometry tables depend only on ``(shape, fill height)`` and are cached by value, so camera,
colour or IOR edits never rebuild them; media and materials are rebuilt from the design (a few
numbers). There is no liquid object without liquid and no mesh at all: the surfaces are exact.
Units: mm; media absorption in 1/mm.
"""
from __future__ import annotations

import math
import threading
import dataclasses
from dataclasses import dataclass

import numpy as np

from ...geometry.offset import radius_at
from ...geometry.validate import body_profile
from ...model.fill import fill_height_of
from ...geometry.segments import Arc, Line, OffsetEllipseArc
from ...intersect.revolved import segment_bounds
from ..kernels.records import Geometry, Scene
from ..kernels import intersect as K
from ..kernels import profile as R
from ..kernels.materials import MAT_COLS, SMOOTH_DIELECTRIC
from ..kernels.outlines import CIRCLE, OUTLINE, OVAL, RRECT, RSQUARE
from ..kernels.plans import PL_COLS
from .plans import plan_table
from ..kernels.swept import SL_COLS, ruled_coefficients

AIR, GLASS, LIQUID = 0, 1, 2
OBJECT_NAMES = ("outer wall", "bottom", "inner wall", "inner base", "rim", "free surface")
OUTER_WALL, BOTTOM, INNER_WALL, INNER_BASE, RIM, FREE_SURFACE = range(6)
#: Band contraction on a swept wall stops at this fraction of the bottle's size (or earlier, on a
#: band proven monotone: kernels.bands), then the exact surface is solved: only a pair of
#: crossings closer than that can be missed (a graze a few nanometres deep at bottle scale).
SWEPT_LEAF = 1e-4
#: Hits nearer than this fraction of the bottle's size to a ray's start must agree with the
#: ray's medium (a ray leaving an edge onto the neighbouring surface).
EDGE_FRACTION = 1e-7
#: The kernels' integer for each cross-section (by its ``name``): the one table from the geometry's
#: :class:`~engine.geometry.crosssection.CrossSection` objects to the compiled code.
_XS = {"rounded_square": RSQUARE, "rounded_rect": RRECT, "oval": OVAL, "round": CIRCLE, "outline": OUTLINE}


@dataclass(frozen=True, eq=False)
class RenderGeometry:
    """Geometry tables of one bottle (+ liquid): see the module table.

    ``seg`` (n, S_COLS) float64 segments; ``tab`` (k, 4) the offset arcs' monotone tables of
    ``(r, z, parameter, band)`` rows; ``slab_f`` (m, SL_COLS) ``(z0, z1, rmax, ruled, ruled
    slab's outline coefficients)`` (:mod:`~engine.tracer.kernels.swept`) and ``slab_i``
    (m, 3) segment rows per section of the swept walls' slabs; ``obj_i`` / ``obj_f`` the
    objects without their media (filled per design); ``scale_mm`` the bottle's size;
    ``fill_height`` (mm) or ``None``; ``kind`` the cross-section; ``plan`` a free plan
    outline's pieces (:mod:`~engine.tracer.kernels.plans`; one unused row for the fixed kinds).
    """

    seg: np.ndarray
    tab: np.ndarray
    slab_f: np.ndarray
    slab_i: np.ndarray
    obj_i: np.ndarray
    obj_f: np.ndarray
    names: tuple
    scale_mm: float
    fill_height: float | None
    kind: str
    z_top: float
    z_ib: float
    plan: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros((1, PL_COLS)))


# ----------------------------------------------------------------------------- segments
def _inside_angle(a0, sweep, targets):
    """The angle ``a0 + f sweep`` (0 < f < 1) congruent to one of ``targets``, or nan."""
    for c in targets:
        f = ((c - a0) * math.copysign(1.0, sweep)) % (2 * math.pi) / abs(sweep)
        if 1e-12 < f < 1 - 1e-12:
            return a0 + f * sweep
    return math.nan


#: Rows of an offset arc's monotone table (plus its extreme): the bands' radius ranges are at
#: worst one table step too wide, which the contraction then removes.
TABLE_ROWS = 64


def _offset_table(sg, wall: bool):
    """``(r, z, parameter, band)`` rows of an offset ellipse arc, sorted by z (wall) or r
    (base), its extreme in the other coordinate included, so that both coordinates are
    monotone between consecutive rows: the two rows bound the curve between them (a
    conservative box). ``band`` is the piece from this row to the next one: see
    :func:`_piece_band` (0 on the last row)."""
    base = sg.base
    targets = (0.0, math.pi) if wall else (0.5 * math.pi, -0.5 * math.pi)
    split = _inside_angle(base.angle0, base.sweep, targets)
    t = np.linspace(0.0, 1.0, TABLE_ROWS + 1)
    if math.isfinite(split):
        t = np.unique(np.append(t, (split - base.angle0) / base.sweep))
    pts = np.asarray(sg.point(t), float).reshape(-1, 2)
    rows = np.column_stack([pts, t])
    key = 1 if wall else 0
    rows = rows[np.argsort(rows[:, key], kind="stable")]
    band = [_piece_band(sg, rows[k], rows[k + 1]) for k in range(len(rows) - 1)] + [0.0]
    return np.column_stack([rows, band])


def _piece_band(sg, row0, row1) -> float:
    """Signed width (mm) of the band beside the chord of one table piece that holds the piece.

    With the chord from ``P0 = row0[:2]`` to ``P1`` and its unit normal ``n = (e_z, -e_r)``
    (``e`` the chord's direction), every point ``Q`` of the curve between the rows has
    ``n . (Q - P0)`` between 0 and the band: the piece turns by less than a half turn without
    inflection (the offset is regular), so it lies in the triangle of its chord and its end
    tangents, whose apex is this far from the chord. The kernels then know on which side of
    the curve a point of the piece's box lies without solving the curve, unless it is inside
    the band (:func:`engine.tracer.kernels.revolved.offset_roots`). ``inf`` where that does not
    hold (the kernels then always solve the curve)."""
    p0, p1 = np.asarray(row0[:2], float), np.asarray(row1[:2], float)
    e = p1 - p0
    length = float(np.hypot(*e))
    if not length > 0.0:
        return math.inf
    e /= length
    nrm = np.array([e[1], -e[0]])
    ts = np.linspace(row0[2], row1[2], 9)
    # regular (no cusp) and without inflection: the curvature keeps one sign, 1 - w k > 0
    k_base = np.asarray(sg.base.curvature(ts), float)
    if np.any(1.0 - sg.w * k_base <= 0.0):
        return math.inf
    d0 = np.asarray(sg.tangent(row0[2]), float).ravel()
    d1 = np.asarray(sg.tangent(row1[2]), float).ravel()
    cross = d0[0] * d1[1] - d0[1] * d1[0]
    if not (abs(cross) > 1e-15 and float(np.dot(d0, d1)) > 0.0):
        return math.inf
    # apex: p0 + alpha d0 = p1 + beta d1
    alpha = ((p1[0] - p0[0]) * d1[1] - (p1[1] - p0[1]) * d1[0]) / cross
    apex = p0 + alpha * d0
    h = float(np.dot(nrm, apex - p0))
    # the sampled curve must lie inside (a check of the geometry above, not the bound itself)
    q = np.asarray(sg.point(ts), float).reshape(-1, 2)
    v = (q - p0) @ nrm
    tol = 1e-9 * (1.0 + float(np.abs(q).max()))
    if np.any(v * math.copysign(1.0, h) < -tol) or np.any(np.abs(v) > abs(h) + tol):
        return math.inf
    return h


def _segment_row(sg, v0, wall: bool, tables=None):
    """One row of the segment table for a section segment (``wall``: part of a z-rising wall).
    An offset arc's table rows are appended to ``tables``."""
    row = np.full(R.S_COLS, np.nan)
    row[R.S_R0], row[R.S_Z0] = sg.p0
    row[R.S_R1], row[R.S_Z1] = sg.p1
    row[R.S_V0], row[R.S_LEN] = v0, sg.length
    row[R.S_AXIS] = 1.0 if wall else 0.0
    rmin, rmax, zmin, zmax = segment_bounds(sg)
    pad = 1e-9 * (abs(rmax) + abs(zmax) + abs(zmin) + 1.0)
    if isinstance(sg, OffsetEllipseArc):  # sampled bounds: widen by a hair more
        pad = 1e-7 * (abs(rmax) + abs(zmax) + abs(zmin) + 1.0)
    row[R.S_RMIN], row[R.S_RMAX] = max(rmin - pad, 0.0), rmax + pad
    row[R.S_ZMIN], row[R.S_ZMAX] = zmin - pad, zmax + pad
    if isinstance(sg, Line):
        row[R.S_KIND] = R.LINE
        return row
    base = sg.base if isinstance(sg, OffsetEllipseArc) else sg
    if isinstance(base, Arc):
        ar = az = base.radius
    else:
        ar, az = base.radius_r, base.radius_z
    row[R.S_CR], row[R.S_CZ] = base.center
    row[R.S_AR], row[R.S_AZ] = ar, az
    row[R.S_A0], row[R.S_SWEEP] = base.angle0, base.sweep
    row[R.S_DIR] = 1.0 if base.direction == "ccw" else -1.0
    row[R.S_HALF] = 1.0 if math.cos(base.angle0 + 0.5 * base.sweep) >= 0.0 else -1.0
    if isinstance(sg, OffsetEllipseArc):
        row[R.S_KIND] = R.OFFSET
        row[R.S_W] = sg.w
        targets = (0.0, math.pi) if wall else (0.5 * math.pi, -0.5 * math.pi)
        row[R.S_SPLIT] = _inside_angle(base.angle0, base.sweep, targets)
        rows = _offset_table(sg, wall)
        row[R.S_TAB0] = sum(len(x) for x in tables)
        row[R.S_TABN] = len(rows)
        tables.append(rows)
    else:
        row[R.S_KIND] = R.ARC if isinstance(sg, Arc) else R.ELLIPSE
        row[R.S_SIDE] = _arc_side(row)
    return row


def _arc_side(row) -> float:
    """The side of its chord an arc row lies on (``S_SIDE``: +1 or -1), or 0 when the chord is
    too short against the arc (a full or nearly full ellipse): the kernels then test the angle."""
    r0, z0, r1, z1 = row[R.S_R0], row[R.S_Z0], row[R.S_R1], row[R.S_Z1]
    mid = row[R.S_A0] + 0.5 * row[R.S_SWEEP]
    mr, mz = row[R.S_CR] + row[R.S_AR] * math.cos(mid), row[R.S_CZ] + row[R.S_AZ] * math.sin(mid)
    cross = (r1 - r0) * (mz - z0) - (z1 - z0) * (mr - r0)
    size = row[R.S_AR] + row[R.S_AZ]
    if math.hypot(r1 - r0, z1 - z0) < 1e-6 * size or abs(cross) < 1e-9 * size * size:
        return 0.0
    return math.copysign(1.0, cross)


class _Tables:
    """Accumulates segment rows, slabs and objects while a geometry is compiled."""

    def __init__(self):
        self.seg, self.slab_f, self.slab_i, self.obj_i, self.obj_f, self.names = [], [], [], [], [], []
        self.tables = []

    def chain(self, chain, v0, wall):
        first = len(self.seg)
        for sg in chain:
            self.seg.append(_segment_row(sg, v0, wall, self.tables))
            v0 += sg.length
        return first, len(chain), v0

    def add(self, name, kind, first=0, count=0, nsign=1.0, bbox=(0.0, 0.0, 0.0), **f):
        oi = np.zeros(K.O_COLS, np.int64)
        oi[K.O_KIND], oi[K.O_FIRST], oi[K.O_COUNT] = kind, first, count
        oi[K.O_XS_IN] = -1
        of = np.zeros(K.F_COLS)
        of[K.F_NSIGN] = nsign
        of[K.F_ZSPLIT] = np.inf
        of[K.F_COS] = 1.0
        of[K.F_RMAX], of[K.F_ZMIN], of[K.F_ZMAX] = bbox
        for key, val in f.items():
            if key.startswith("O_"):
                oi[getattr(K, key)] = val
            else:
                of[getattr(K, key)] = val
        self.obj_i.append(oi)
        self.obj_f.append(of)
        self.names.append(name)


def _chain_bbox(rows, pad):
    r = np.array(rows)
    return (float(r[:, R.S_RMAX].max()) + pad, float(r[:, R.S_ZMIN].min()) - pad,
            float(r[:, R.S_ZMAX].max()) + pad)


def _outline(xs, radii):
    """``(outline kind, p0, p1, p2)`` of the flat face of cross-section ``xs`` with section radii
    ``radii``: its canonical section (a rounded square is drawn as the rounded rectangle it is)."""
    flat, params = xs.canonical(radii)
    return (_XS[flat.name], *params, *(0.0,) * (3 - len(params)))


def _plane(tab, name, z, nz, xs, outer, inner=None, rot=(1.0, 0.0), scale=1.0, media=None):
    """A flat object at height ``z`` (normal ``(0, 0, nz)``): inside the outline of section
    radii ``outer`` and outside that of ``inner`` (if given); ``media`` = ``(front, back)``."""
    kind, p0, p1, p2 = _outline(xs, outer)
    front, back = media
    extra = dict(O_FRONT_LO=front, O_BACK_LO=back, O_FRONT_HI=front, O_BACK_HI=back)
    if inner is not None:
        xi, q0, q1, q2 = _outline(xs, inner)
        extra.update(O_XS_IN=xi, F_IN0=q0, F_IN1=q1, F_IN2=q2)
    pad = 1e-9 * scale
    tab.add(name, K.PLANE, bbox=(xs.reach_bound(outer) * (1 + 1e-9) + pad, z - pad, z + pad),
            F_PZ=z, F_PNZ=nz, O_XS=kind, F_OUT0=p0, F_OUT1=p1, F_OUT2=p2, F_COS=rot[0], F_SIN=rot[1],
            **extra)


def _dome_radius(chain, h):
    """Radius (mm) where a punt's inner base (rising in r, falling in z) is at height ``h``,
    0 when the whole dome is below it."""
    if h >= chain[0].p0[1]:
        return 0.0
    for sg in chain:
        if min(sg.p0[1], sg.p1[1]) <= h <= max(sg.p0[1], sg.p1[1]):
            lo, hi = 0.0, 1.0
            for _ in range(80):  # z falls along the segment
                mid = 0.5 * (lo + hi)
                if float(sg.point(mid)[1]) > h:
                    lo = mid
                else:
                    hi = mid
            return float(sg.point(0.5 * (lo + hi))[0])
    return float(chain[-1].p1[0])


def _slabs(tab, chains, xs, scale):
    """Cut the walls ``chains`` (one z-rising chain per section) at every joint height: one
    slab per height interval, ``(z0, z1, rmax)`` and the segment row of each section there."""
    firsts = [tab.chain(c, 0.0, True)[0] for c in chains]
    z_lo, z_hi = chains[0][0].p0[1], chains[0][-1].p1[1]
    cuts = sorted({z_lo, z_hi, *(sg.p1[1] for c in chains for sg in c[:-1])})
    cuts = [z for z in cuts if z_lo <= z <= z_hi]
    first = len(tab.slab_f)
    pad = 1e-9 * scale
    rmax_all = 0.0
    for za, zb in zip(cuts[:-1], cuts[1:]):
        if zb - za <= 1e-12 * scale:
            continue
        zm = 0.5 * (za + zb)
        rows, rmaxes = [], []
        for c, f in zip(chains, firsts):
            i = next(j for j, sg in enumerate(c) if sg.p0[1] <= zm <= sg.p1[1])
            rows.append(f + i)
            rmaxes.append(tab.seg[f + i][R.S_RMAX])
        rmax = xs.reach_bound(rmaxes) * (1 + 1e-9) + pad  # each section at its largest in the slab
        rmax_all = max(rmax_all, rmax)
        ruled = _XS[xs.name] in (RSQUARE, RRECT, OUTLINE) and all(tab.seg[r][R.S_KIND] == R.LINE for r in rows)
        coeffs = ruled_coefficients(_XS[xs.name], [tab.seg[r] for r in rows]) if ruled else (0.0,) * (SL_COLS - 4)
        tab.slab_f.append((za - pad, zb + pad, rmax, 1.0 if ruled else 0.0, *coeffs))
        tab.slab_i.append(rows + [rows[0]] * (3 - len(rows)))
    return first, len(tab.slab_f) - first, (rmax_all, z_lo - pad, z_hi + pad)


def build_render_geometry(shape, fill_height: float | None) -> RenderGeometry:
    """Compile ``shape`` with liquid up to ``fill_height`` (mm; ``None`` or at or below the
    inner base: empty) into render-object tables. Raises ``SectionError`` / ``WallError`` for an
    invalid shape (through :func:`body_profile`)."""
    prof = body_profile(shape)
    kind, xs = shape.cross_section, prof.xs
    secs = prof.sections
    r_max = max(max(sg.p0[0], sg.p1[0]) for sp in secs for sg in sp.outer_wall)
    scale = max(prof.z_top, r_max)
    if fill_height is not None and not fill_height > prof.z_ib:
        fill_height = None
    if fill_height is not None:
        fill_height = float(min(fill_height, prof.z_top - 1e-9 * scale))
    tab = _Tables()
    pad = 1e-9 * scale
    edge = EDGE_FRACTION * scale
    wet = LIQUID if fill_height is not None else AIR
    split = fill_height if fill_height is not None else np.inf
    a = math.radians(prof.rotation_deg) if not xs.revolved else 0.0
    rot = (math.cos(a), math.sin(a))
    common = dict(F_EDGE=edge, F_COS=rot[0], F_SIN=rot[1])
    media_outer = dict(O_FRONT_LO=AIR, O_BACK_LO=GLASS, O_FRONT_HI=AIR, O_BACK_HI=GLASS)
    media_inner = dict(O_FRONT_LO=wet, O_BACK_LO=GLASS, O_FRONT_HI=AIR, O_BACK_HI=GLASS, F_ZSPLIT=split)
    base_len = sum(sg.length for sg in secs[0].outer_base)
    if xs.revolved:
        sp = secs[0]
        first, n, _ = tab.chain(sp.outer_wall, base_len, True)
        tab.add("outer wall", K.REVOLVED, first, n, 1.0, _chain_bbox(tab.seg[first:], pad), O_ZSORT=1,
                **media_outer, **common)
        if prof.punt:
            first, n, _ = tab.chain(sp.outer_base, 0.0, False)
            tab.add("bottom", K.REVOLVED, first, n, 1.0, _chain_bbox(tab.seg[first:first + n], pad),
                    **media_outer, **common)
        else:
            _plane(tab, "bottom", 0.0, -1.0, xs, [sp.outer_wall[0].p0[0]], scale=scale, media=(AIR, GLASS))
        ib_len = sum(sg.length for sg in sp.inner_base)
        first, n, _ = tab.chain(sp.inner_wall, ib_len, True)
        tab.add("inner wall", K.REVOLVED, first, n, -1.0, _chain_bbox(tab.seg[first:first + n], pad),
                O_ZSORT=1, **media_inner, **common)
        if prof.punt:
            first, n, _ = tab.chain(sp.inner_base, 0.0, False)
            # a dome may rise above the liquid: wet below the fill, dry above, like the wall
            tab.add("inner base", K.REVOLVED, first, n, -1.0, _chain_bbox(tab.seg[first:first + n], pad),
                    **media_inner, **common)
        else:
            _plane(tab, "inner base", prof.z_ib, 1.0, xs, [sp.inner_wall[0].p0[0]], scale=scale,
                   media=(wet, GLASS))
    else:
        first, n, bbox = _slabs(tab, [sp.outer_wall for sp in secs], xs, scale)
        tab.add("outer wall", K.SWEPT, first, n, 1.0, bbox, O_XS=_XS[xs.name], O_NSEC=len(secs), O_ZSORT=1,
                F_LEAF=SWEPT_LEAF * scale, **media_outer, **common)
        _plane(tab, "bottom", 0.0, -1.0, xs, [sp.outer_wall[0].p0[0] for sp in secs], rot=rot, scale=scale,
               media=(AIR, GLASS))
        first, n, bbox = _slabs(tab, [sp.inner_wall for sp in secs], xs, scale)
        tab.add("inner wall", K.SWEPT, first, n, -1.0, bbox, O_XS=_XS[xs.name], O_NSEC=len(secs), O_ZSORT=1,
                F_LEAF=SWEPT_LEAF * scale, **media_inner, **common)
        _plane(tab, "inner base", prof.z_ib, 1.0, xs, [sp.inner_wall[0].p0[0] for sp in secs], rot=rot,
               scale=scale, media=(wet, GLASS))
    _plane(tab, "rim", prof.z_top, 1.0, xs, [sp.r_top for sp in secs], [sp.r_in_top for sp in secs],
           rot=rot, scale=scale, media=(AIR, GLASS))
    if fill_height is not None:
        radii = [float(radius_at(sp.inner_wall, fill_height)) for sp in secs]
        dome = [_dome_radius(secs[0].inner_base, fill_height)] if prof.punt else None
        if dome is not None and dome[0] <= 0.0:
            dome = None
        _plane(tab, "free surface", fill_height, 1.0, xs, radii, dome, rot=rot, scale=scale, media=(AIR, LIQUID))
    for of in tab.obj_f:
        of[K.F_EDGE] = edge
    seg = np.ascontiguousarray(np.array(tab.seg, float).reshape(-1, R.S_COLS))
    table = np.ascontiguousarray(np.concatenate(tab.tables) if tab.tables else np.zeros((1, 4)))
    slab_f = np.ascontiguousarray(np.array(tab.slab_f, float).reshape(-1, SL_COLS))
    slab_i = np.ascontiguousarray(np.array(tab.slab_i, np.int64).reshape(-1, 3))
    plan = plan_table(xs.plan.to_dicts()) if hasattr(xs, "plan") else np.zeros((1, PL_COLS))
    return RenderGeometry(seg, table, slab_f, slab_i, np.ascontiguousarray(np.array(tab.obj_i)),
                          np.ascontiguousarray(np.array(tab.obj_f)), tuple(tab.names), float(scale),
                          fill_height, kind, float(prof.z_top), float(prof.z_ib), plan)


_CACHE: dict = {}
_CACHE_LOCK = threading.Lock()
_CACHE_SIZE = 8


def cached(cache: dict, lock, size: int, key, build):
    """``cache[key]``, built by ``build(*key)`` on a miss (outside the lock: builds of different
    keys run at once), keeping the ``size`` newest keys; thread-safe."""
    with lock:
        hit = cache.get(key)
    if hit is not None:
        return hit
    value = build(*key)
    with lock:
        cache[key] = value
        while len(cache) > size:
            cache.pop(next(iter(cache)))
    return value


def render_geometry_for(design) -> RenderGeometry:
    """The cached :class:`RenderGeometry` of a design's ``(shape, fill height)`` (thread-safe)."""
    return cached(_CACHE, _CACHE_LOCK, _CACHE_SIZE, (design.shape, fill_height_of(design)), build_render_geometry)


def media_table(design) -> np.ndarray:
    """``(3, 4)`` float64 rows ``(ior, sigma_r, sigma_g, sigma_b)`` for air, glass, liquid."""
    g, liq = design.glass, design.liquid
    rows = [(1.0, 0.0, 0.0, 0.0), (float(g.ior), *map(float, g.absorption))]
    rows.append((float(liq.ior), *map(float, liq.absorption)) if liq is not None else (1.0, 0.0, 0.0, 0.0))
    return np.array(rows, float)


def material_tables(design):
    """``(mat_i, mat_f)`` of the bottle: one material, the smooth dielectric interface (a
    closure's materials follow it, :mod:`engine.tracer.tables.finishes`)."""
    mat_i = np.zeros((1, 4), np.int64)
    mat_i[0, 0] = SMOOTH_DIELECTRIC
    return mat_i, np.zeros((1, MAT_COLS))


def search_tables(geom: RenderGeometry) -> Geometry:
    """The geometry's tables as the kernels' :class:`~engine.tracer.kernels.records.Geometry`."""
    return Geometry(geom.seg, geom.tab, geom.slab_f, geom.slab_i, geom.obj_i, geom.obj_f, geom.plan)


def scene_arrays(geom: RenderGeometry, design) -> Scene:
    """The record the kernels take (:class:`~engine.tracer.kernels.records.Scene`): the
    geometry's tables, the design's media and materials."""
    mat_i, mat_f = material_tables(design)
    return Scene(search_tables(geom), media_table(design), mat_i, mat_f)
