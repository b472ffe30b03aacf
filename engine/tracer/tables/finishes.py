"""Finishes and closures compiled for the kernels: cap render objects and the finish tables.

Design rule: a closure is one revolved render object per part (its closed meridian chain from
:mod:`engine.appearance.closures`, lines and arcs), appended after the bottle's objects with a
material of its own (aluminium as a conductor under a lacquer tint, plastic as a coat over a
diffuse base). A part is opaque: air on both sides of its surface, its materials reflect only,
so its inside is never entered. The cap's tables (:class:`CapTables`) are built and cached by
``(cap, finish, edge)``, the only values they depend on, apart from the bottle's: a cap edit never
rebuilds or re-tessellates the bottle, a bottle edit that leaves the finish alone keeps the cap's
tables, and :func:`scene_with_cap` only concatenates rows (offsetting the cap's segment rows).
A closure material's GGX ``roughness`` becomes a frosted row over its whole part (a glossy,
not mirror-sharp, metal or coat), except that a material at least :data:`MATTE_ROUGHNESS` rough
(cork) loses its coat and is purely diffuse.

:func:`finish_arrays` builds the :class:`~engine.tracer.kernels.records.FinishTables` the
surface layer reads (:mod:`engine.tracer.kernels.surface`, :mod:`engine.tracer.kernels.finish`):
every bump row of the design (the bottle's tiles on the outer wall, and on a punted bottom, the
closure's reliefs on their parts) sorted by object, and, with a plastic part, the environment's
cosine-prefiltered irradiance (:func:`engine.tracer.tables.lighting.irradiance_table`, once per
environment) and the design's distant lights, and always the GGX albedo tables of rough surfaces
(:func:`engine.tracer.tables.ggx_albedo.albedo_tables`, loaded once per process). A design without
bumps or cap gets empty rows: the kernels then never leave the plain path. Units mm.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from ...appearance.closure_parts import cap_material
from ...appearance.closures import finish_of
from ..kernels.records import FinishTables, Geometry, Scene
from ..kernels import intersect as K
from ..kernels import profile as R
from ..kernels.bumps import FROSTED, P_ALPHA, P_COLS, P_V0, P_V1
from ..kernels.labels import LABEL_BIT0
from .ggx_albedo import albedo_tables, conductor_average, dielectric_average
from ..kernels.backdrop import W_COLS
from ..kernels.ground import CAUSTIC_COLS, GRID_COLS, LIGHT_COLS, SKY_COLS
from .lighting import irradiance_table, light_table
from ..kernels.materials import CONDUCTOR, MAT_COLS, MF_ALBEDO, MF_COAT_IOR, MF_K, MF_N, MF_TINT, PLASTIC
from ..kernels.microfacet import MF_FAVG
from .render_objects import AIR, BOTTOM, LIQUID, OUTER_WALL, _chain_bbox, _Tables, cached

#: Objects the kernels' int64 object masks can tell apart (the bits above are the labels').
MAX_OBJECTS = LABEL_BIT0
#: A closure material at least this rough (GGX alpha) is drawn without its coat (cork).
MATTE_ROUGHNESS = 0.3


@dataclass(frozen=True, eq=False)
class CapTables:
    """Render rows of one closure: ``seg`` (n, S_COLS) segment rows numbered from 0,
    ``obj_i``/``obj_f`` one object per part (``O_FIRST`` counted in ``seg``, ``O_MAT`` from 0
    among the cap's own materials), ``mat_i``/``mat_f`` one material per part, ``names`` the
    parts' names, ``z_min``/``z_max`` (mm) the closure's extent, ``inside[i]`` whether part
    ``i`` lies within the bore (a cork: what the liquid may reach), ``roughness[i]`` the GGX
    alpha its surface is drawn with (0: polished)."""

    seg: np.ndarray
    obj_i: np.ndarray
    obj_f: np.ndarray
    mat_i: np.ndarray
    mat_f: np.ndarray
    names: tuple
    z_min: float
    z_max: float
    inside: tuple = ()
    roughness: tuple = ()


def material_row(material):
    """``(kind, mat_f row)`` of a :class:`~engine.appearance.closure_parts.ClosureMaterial`,
    with the mean Fresnel ``F_avg`` of its mirror (tint included) that a rough surface's
    energy compensation reads (:mod:`engine.tracer.kernels.microfacet`)."""
    row = np.zeros(MAT_COLS)
    if material.kind == "conductor":
        row[MF_N:MF_N + 3], row[MF_K:MF_K + 3], row[MF_TINT:MF_TINT + 3] = material.eta, material.k, material.tint
        row[MF_FAVG:MF_FAVG + 3] = [t * conductor_average(n, k)
                                    for n, k, t in zip(material.eta, material.k, material.tint)]
        return CONDUCTOR, row
    row[MF_ALBEDO:MF_ALBEDO + 3] = np.clip(material.tint, 0.0, 1.0)
    row[MF_COAT_IOR] = 1.0 if material.roughness >= MATTE_ROUGHNESS else material.eta[0]
    row[MF_FAVG:MF_FAVG + 3] = dielectric_average(row[MF_COAT_IOR])
    return PLASTIC, row


def build_cap_tables(cap, finish, edge: float) -> CapTables:
    """Compile ``cap`` sized from ``finish`` (:class:`~engine.appearance.closures.Finish`) into
    render rows; ``edge`` is the bottle's edge distance (mm, ``F_EDGE``)."""
    from ...appearance.closure_shapes import closure_parts
    parts = closure_parts(cap, finish, cap_material(cap))
    tab = _Tables()
    mats_i, mats_f = [], []
    for m, part in enumerate(parts):
        first, n, _ = tab.chain(part.chain, 0.0, False)
        pad = 1e-9 * max(finish.z_top, 1.0)
        tab.add(part.name, K.REVOLVED, first, n, 1.0, _chain_bbox(tab.seg[first:first + n], pad),
                O_FRONT_LO=AIR, O_BACK_LO=AIR, O_FRONT_HI=AIR, O_BACK_HI=AIR, O_MAT=m, F_EDGE=edge)
        kind, row = material_row(part.material)
        mi = np.zeros(4, np.int64)
        mi[0] = kind
        mats_i.append(mi)
        mats_f.append(row)
    seg = np.array(tab.seg, float).reshape(-1, R.S_COLS)
    zs = seg[:, [R.S_ZMIN, R.S_ZMAX]]
    return CapTables(np.ascontiguousarray(seg), np.array(tab.obj_i).reshape(-1, K.O_COLS),
                     np.array(tab.obj_f).reshape(-1, K.F_COLS), np.array(mats_i).reshape(-1, 4),
                     np.array(mats_f).reshape(-1, MAT_COLS), tuple(tab.names), float(zs.min()), float(zs.max()),
                     tuple(bool(of[K.F_RMAX] < finish.r_bore) for of in tab.obj_f),
                     tuple(0.0 if p.material.roughness >= MATTE_ROUGHNESS else float(p.material.roughness)
                           for p in parts))


_CACHE: dict = {}
_LOCK = threading.Lock()
_CACHE_SIZE = 8
#: How many times :func:`build_cap_tables` ran (tests check that a bottle edit keeps them).
BUILDS = [0]


def cap_tables_for(design, geom) -> CapTables | None:
    """The cached :class:`CapTables` of ``design``'s cap on its finish (``None`` without a
    cap); ``geom`` is the bottle's :class:`~engine.tracer.tables.render_objects.RenderGeometry`."""
    if design.cap is None:
        return None
    key = (design.cap, finish_of(design), float(geom.obj_f[0, K.F_EDGE]))
    return cached(_CACHE, _LOCK, _CACHE_SIZE, key, _build_counted)


def _build_counted(cap, finish, edge):
    BUILDS[0] += 1
    return build_cap_tables(cap, finish, edge)


def scene_with_cap(scene: Scene, cap: CapTables | None, fill_height: float | None = None) -> Scene:
    """The kernels' scene (:class:`~engine.tracer.kernels.records.Scene`) with the cap's objects and materials appended after the
    bottle's (segment rows and material ids offset); ``scene`` itself without a cap. Below a
    fill height (mm) a part inside the bore is surrounded by liquid (a cork the wine reaches),
    like the inner wall."""
    if cap is None:
        return scene
    (seg, tab, slab_f, slab_i, obj_i, obj_f, plan), media, mat_i, mat_f = scene
    oi = cap.obj_i.copy()
    oi[:, K.O_FIRST] += seg.shape[0]
    oi[:, K.O_MAT] += mat_i.shape[0]
    of = cap.obj_f
    wet = np.array(cap.inside, bool)
    if fill_height is not None and wet.any():
        of = of.copy()
        of[wet, K.F_ZSPLIT] = fill_height
        oi[wet, K.O_FRONT_LO] = LIQUID
        oi[wet, K.O_BACK_LO] = LIQUID
    if obj_i.shape[0] + oi.shape[0] > MAX_OBJECTS:
        raise ValueError(f"too many render objects for the object masks ({MAX_OBJECTS} at most)")
    mf = np.zeros((mat_f.shape[0], MAT_COLS))
    mf[:, :mat_f.shape[1]] = mat_f
    c = np.ascontiguousarray
    return Scene(Geometry(c(np.concatenate([seg, cap.seg])), tab, slab_f, slab_i, c(np.concatenate([obj_i, oi])),
                          c(np.concatenate([obj_f, of])), plan), media, c(np.concatenate([mat_i, cap.mat_i])),
                 c(np.concatenate([mf, cap.mat_f])))


# ----------------------------------------------------------------------------- finish tables
_EMPTY_IRR = np.zeros((2, 2, 3), np.float32)
#: No caustic grids (a design without a diffuse ground or without lights).
NO_CAUSTICS = (np.zeros((0, 1, 1, CAUSTIC_COLS)), np.zeros((0, GRID_COLS)))
#: No sky grid (a design without a diffuse ground: :mod:`engine.tracer.tables.sky`).
NO_SKY = (np.zeros((1, 3)), np.zeros(SKY_COLS))
#: No sweep grid (a design without a backdrop sweep: :mod:`engine.tracer.tables.sweep`).
NO_SWEEP = (np.zeros((1, 3)), np.zeros(W_COLS))


def empty_finish(n_objects: int) -> FinishTables:
    """The finish tables of a plain design: no rows on any object."""
    return FinishTables(np.zeros((n_objects, 2), np.int64), np.zeros(0, np.int64), np.zeros((0, P_COLS)),
                        np.zeros((1, 3), np.float32), _EMPTY_IRR, np.zeros((0, LIGHT_COLS)), *albedo_tables(),
                        *NO_CAUSTICS, *NO_SKY, *NO_SWEEP)


def finish_arrays(design, assets, geom, cap: CapTables | None, scene: Scene, texels) -> FinishTables:
    """The finish tables of ``design`` for the kernels (module doc); ``scene`` is the combined
    scene (bottle and cap objects), ``texels`` the environment's."""
    n_obj = scene.geom.obj_i.shape[0]
    ground = design.stage.is_diffuse_ground  # the lights reach it
    if not design.bumps and cap is None:
        empty = empty_finish(n_obj)
        return empty._replace(lights=light_table(design.lights)) if ground else empty
    from .bump_rows import BOTTLE, bump_tables
    bt = bump_tables(design, assets)
    n_bottle = geom.obj_i.shape[0]
    bottle_objs = [OUTER_WALL]
    if geom.kind == "round" and geom.obj_i[BOTTOM, K.O_KIND] == K.REVOLVED:
        bottle_objs.append(BOTTOM)   # a punt: its outer base continues the wall's v
    per_obj = [[] for _ in range(n_obj)]
    for i, surface in enumerate(bt.surfaces):
        if surface == BOTTLE:
            for o in bottle_objs:
                per_obj[o].append(i)
        elif cap is not None:
            name = surface.split(":", 1)[1]
            if name in cap.names:
                per_obj[n_bottle + cap.names.index(name)].append(i)
    kinds_all, params_all = list(bt.kinds), list(bt.params)
    for j, alpha in enumerate(cap.roughness if cap is not None else ()):
        if alpha > 0.0:   # the part's own gloss: a frosted row over all of it
            row = np.zeros(P_COLS)
            row[P_V0], row[P_V1], row[P_ALPHA] = -np.inf, np.inf, alpha
            per_obj[n_bottle + j].append(len(kinds_all))
            kinds_all.append(FROSTED)
            params_all.append(row)
    order = [i for rows in per_obj for i in rows]
    obj_rows = np.zeros((n_obj, 2), np.int64)
    at = 0
    for o, rows in enumerate(per_obj):
        obj_rows[o] = at, len(rows)
        at += len(rows)
    kinds = np.ascontiguousarray(np.array(kinds_all, np.int64)[order] if order else np.zeros(0, np.int64))
    params = np.ascontiguousarray(np.array(params_all, float).reshape(-1, P_COLS)[order] if order
                                  else np.zeros((0, P_COLS)))
    plastic = bool(np.any(scene.mat_i[:, 0] == PLASTIC))
    irr = irradiance_table(texels) if plastic else _EMPTY_IRR
    lights = light_table(design.lights) if plastic or ground else np.zeros((0, LIGHT_COLS))
    return FinishTables(obj_rows, kinds, params, np.ascontiguousarray(bt.atlas, np.float32), irr, lights,
                        *albedo_tables(), *NO_CAUSTICS, *NO_SKY, *NO_SWEEP)
