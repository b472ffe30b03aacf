"""The stage compiled for the kernels: the ground's render object and material, and the open sky.

Design rule: the ground is one more render object after the bottle's and the closure's: a
horizontal plane region (the square of the stage's half-side) at the stage's height, air on
both sides, with a ``GROUND`` material row (:mod:`engine.tracer.kernels.materials`) that the
surface layer shades (:func:`engine.tracer.kernels.surface.scatter`). A design whose stage is
``none`` gets no object at all, so its images are those of before stages, bit for bit. The one
number of the environment the ground needs, the irradiance of an upward surface under an open
sky (:func:`open_sky_irradiance`), rides in the environment's parameter row. A table or riser
with its backdrop on gets one more object after the ground: the sweep (:func:`sweep_row`, a
``BACKDROP`` material of the same sheet), behind the bottle as the camera sees it, and the
ground's probes then span the whole sky (``MG_WIDE``: the sweep hides sky from it too). A
diffuse ground also gets its sky grid (:func:`stage_sky`, :mod:`engine.tracer.tables.sky`) and, under lights,
their caustic grids (:func:`stage_caustics`). Units mm.
"""
from __future__ import annotations

import math
import threading

import numpy as np

from ...model.design import Stage
from ..kernels import intersect as K
from ..kernels.materials import (BACKDROP, GROUND, MAT_COLS, MG_ALBEDO, MG_ALPHA, MG_BOUND_R, MG_BOUND_Z,
                                 MG_COAT_IOR, MG_MIRROR, MG_SHADOW, MG_WIDE)
from ..kernels.microfacet import MF_FAVG
from ..kernels.outlines import RRECT
from ..kernels.records import Geometry, Scene, Tables
from .ggx_albedo import dielectric_average
from .environment import ArrayCache
from .render_objects import AIR, cached

#: The glossy riser's clear coat (acrylic, black glass).
COAT_IOR = 1.5
#: Polar and azimuthal steps of the open-sky quadrature (:func:`open_sky_irradiance`).
SKY_STEPS = (256, 1024)
#: The backdrop sweep in the bottle's size ``h`` (its height above the stage or its bounding
#: radius, the larger): the curve leaves the floor ``SWEEP_GAP h`` beyond the bottle's bounding
#: radius and rises with radius ``SWEEP_CURVE h`` to the wall, which reaches ``SWEEP_EXTENT h``
#: above the floor and as far to each side (far enough to fill any frame that shows the bottle).
SWEEP_GAP, SWEEP_CURVE, SWEEP_EXTENT = 0.75, 1.0, 40.0
#: Sky integrals kept (maps x turns x sweep facings a session goes through), by the map's
#: identity (each entry keeps its map alive, so no other map can take its id).
_SKY_INTEGRALS = ArrayCache(16)
_SKY_LOCK = threading.Lock()


def material_row(stage: Stage, bound_r: float, bound_z: float) -> np.ndarray:
    """The ``GROUND`` material row of ``stage`` (module rule); ``bound_r``, ``bound_z`` (mm) the
    radius and top of an upright cylinder about the axis holding everything on the stage."""
    row = np.zeros(MAT_COLS)
    row[MG_BOUND_R], row[MG_BOUND_Z] = bound_r, bound_z
    row[MG_ALBEDO:MG_ALBEDO + 3] = stage.color
    if stage.kind == "glossy":
        row[MG_COAT_IOR] = COAT_IOR
        row[MG_ALPHA] = 0.5 * (1.0 - stage.gloss) ** 2  # gloss 1: a sharp coat; 0: GGX alpha 0.5
        row[MF_FAVG:MF_FAVG + 3] = dielectric_average(COAT_IOR)
    row[MG_SHADOW] = 1.0 if stage.kind == "shadow" else 0.0
    row[MG_MIRROR] = 1.0 if stage.kind == "mirror" else 0.0
    return row


def sweep_facing(camera) -> tuple[float, float]:
    """``(cos, sin)``: the unit horizontal direction from the bottle's axis away from ``camera``'s
    eye (a ``Camera``, mm), where its backdrop sweep stands: behind the bottle as the camera sees
    it (from straight above: along the view's horizontal part, else +y)."""
    for x, y in ((-camera.eye[0], -camera.eye[1]),
                 (camera.target[0] - camera.eye[0], camera.target[1] - camera.eye[1])):
        n = math.hypot(x, y)
        if n > 1e-9 * max(1.0, *(abs(v) for v in camera.eye)):
            return x / n, y / n
    return 0.0, 1.0


def sweep_row(stage: Stage, camera, bound_r: float, bound_z: float, edge: float) -> np.ndarray:
    """The ``obj_f`` row of ``stage``'s backdrop sweep (:data:`~..kernels.intersect.SWEEP`'s
    columns) for a bottle within radius ``bound_r`` and below ``bound_z`` (mm), seen by
    ``camera``: facing away from the camera (:func:`sweep_facing`), sized by
    :data:`SWEEP_GAP` and its kin; ``edge`` the objects' edge distance."""
    z = float(stage.z_mm)
    h = max(bound_r, bound_z - z)
    start, radius, extent = bound_r + SWEEP_GAP * h, SWEEP_CURVE * h, SWEEP_EXTENT * h
    of = np.zeros(K.F_COLS)
    of[K.F_COS], of[K.F_SIN] = sweep_facing(camera)
    of[K.F_NSIGN], of[K.F_ZSPLIT], of[K.F_PZ], of[K.F_EDGE] = 1.0, np.inf, z, edge
    of[K.F_SW_START], of[K.F_SW_RADIUS], of[K.F_SW_HALF], of[K.F_SW_TOP] = start, radius, extent, z + extent
    of[K.F_RMAX] = math.hypot(start + radius, extent) * (1 + 1e-9)
    of[K.F_ZMIN], of[K.F_ZMAX] = z - 1e-9 * extent, z + extent * (1 + 1e-9)
    return of


def _air_object(kind: int, mat: int) -> np.ndarray:
    """An ``obj_i`` row of ``kind`` with air on both sides and material ``mat``."""
    oi = np.zeros(K.O_COLS, np.int64)
    oi[K.O_KIND], oi[K.O_XS_IN], oi[K.O_MAT] = kind, -1, mat
    oi[K.O_FRONT_LO] = oi[K.O_BACK_LO] = oi[K.O_FRONT_HI] = oi[K.O_BACK_HI] = AIR
    return oi


def scene_with_stage(scene: Scene, stage: Stage, camera=None) -> Scene:
    """``scene`` with the ground of ``stage`` appended as its last object and material and, when
    the stage draws one, its backdrop sweep after it, facing ``camera`` (a ``Camera``, mm;
    ``scene`` itself for the stage ``none``)."""
    if stage.kind == "none":
        return scene
    (seg, tab, slab_f, slab_i, obj_i, obj_f, plan), media, mat_i, mat_f = scene
    oi = _air_object(K.PLANE, mat_i.shape[0])
    oi[K.O_XS] = RRECT
    of = np.zeros(K.F_COLS)
    half, z = float(stage.half_size_mm), float(stage.z_mm)
    pad = 1e-9 * half
    of[K.F_NSIGN], of[K.F_ZSPLIT], of[K.F_COS] = 1.0, np.inf, 1.0
    of[K.F_RMAX], of[K.F_ZMIN], of[K.F_ZMAX] = math.sqrt(2.0) * half * (1 + 1e-9) + pad, z - pad, z + pad
    of[K.F_PZ], of[K.F_PNZ] = z, 1.0
    of[K.F_OUT0], of[K.F_OUT1], of[K.F_OUT2] = half, half, 0.0
    of[K.F_EDGE] = obj_f[0, K.F_EDGE] if obj_f.shape[0] else 1e-9
    mi = np.zeros((1, mat_i.shape[1]), np.int64)
    mi[0, 0] = GROUND
    mf = np.zeros((mat_f.shape[0], MAT_COLS))
    mf[:, :mat_f.shape[1]] = mat_f
    # the bottle, its threads and closure: objects' boxes are (radius about the axis, z range)
    bound_r = float(obj_f[:, K.F_RMAX].max()) * (1 + 1e-6) + 1e-6
    bound_z = float(obj_f[:, K.F_ZMAX].max()) + 1e-6
    row = material_row(stage, bound_r, bound_z)
    new_i, new_f, new_mi, new_mf = [oi], [of], [mi], [row]
    if stage.draws_backdrop:
        from ...model.design import Camera
        row[MG_WIDE] = 1.0
        sweep = row.copy()
        sweep[MG_WIDE] = 0.0
        new_i.append(_air_object(K.SWEEP, mat_i.shape[0] + 1))
        new_f.append(sweep_row(stage, camera if camera is not None else Camera(), bound_r, bound_z, of[K.F_EDGE]))
        new_mi.append(np.array([[BACKDROP] + [0] * (mat_i.shape[1] - 1)], np.int64))
        new_mf.append(sweep)
    c = np.ascontiguousarray
    return Scene(Geometry(seg, tab, slab_f, slab_i, c(np.vstack([obj_i, *new_i])), c(np.vstack([obj_f, *new_f])), plan),
                 media, c(np.vstack([mat_i, *new_mi])), c(np.vstack([mf, *new_mf])))


def ground_objects(scene: Scene) -> np.ndarray:
    """Indices of the render objects of ``scene`` that are the stage's (its ground and backdrop
    sweep; none without one)."""
    mats = scene.geom.obj_i[:, K.O_MAT]
    return np.nonzero(np.isin(scene.mat_i[mats, 0], (GROUND, BACKDROP)))[0]


def ground_object(scene: Scene) -> int:
    """The render object of ``scene`` that is the stage's ground plane (the sweep follows it)."""
    mats = scene.geom.obj_i[:, K.O_MAT]
    return int(np.nonzero(scene.mat_i[mats, 0] == GROUND)[0][0])


def _cosine_directions(steps) -> np.ndarray:
    """``(n, 3)`` unit directions about +z in a frame's coordinates, a midpoint rule of ``steps``
    = (polar, azimuthal) cells in ``cos^2`` and azimuth: the cosine-weighted hemisphere in equal
    parts (so a mean over them is an irradiance over pi)."""
    nt, nphi = steps
    c2 = (np.arange(nt) + 0.5) / nt
    cos_t, sin_t = np.sqrt(c2), np.sqrt(1.0 - c2)
    phi = (np.arange(nphi) + 0.5) * (2.0 * math.pi / nphi)
    return np.stack([np.outer(sin_t, np.cos(phi)), np.outer(sin_t, np.sin(phi)),
                     np.outer(cos_t, np.ones(nphi))], axis=-1).reshape(-1, 3)


def open_sky_irradiance(environment) -> np.ndarray:
    """``E_up`` (RGB, the environment's radiance units times its scale): the irradiance over pi
    of an upward surface with nothing in the way, ``(1 / pi) int L(w) cos(theta) dw`` over the
    upper hemisphere, by a midpoint rule in ``cos^2`` (so each cell carries equal weight) and
    azimuth of :data:`SKY_STEPS` cells over the environment's own lookup; cached per map, scale
    and turn (the turn does not change it, but the lookup takes it)."""
    def build(_):
        return environment.lookup(_cosine_directions(SKY_STEPS)).mean(axis=0)
    return _SKY_INTEGRALS.get(environment.texels, build, key=(float(environment.scale), float(environment.rotation_deg)))


#: Tilts of the sweep's normal (from up to level, facing the bottle) its open-sky table holds,
#: and the quadrature's polar and azimuthal steps per tilt (:func:`sweep_sky_irradiance`).
SWEEP_TILTS = 33
SWEEP_SKY_STEPS = (64, 256)


def sweep_sky_irradiance(environment, facing, floor=(0.0, 0.0, 0.0)) -> np.ndarray:
    """``(SWEEP_TILTS, 3)``: the irradiance over pi of the sweep's sheet with nothing in the way
    but the floor (the environment above the horizon; below it the open floor's radiance
    ``floor``, RGB: every direction down from the sweep meets the floor or the sweep's own
    foot), at normals tilted from up (row 0) to level facing back along ``facing`` (the sweep's
    ``(cos, sin)``, last row: the wall), evenly in angle; the control variate's mean of
    :func:`engine.tracer.kernels.backdrop.backdrop`. By a midpoint rule in ``cos^2`` and
    azimuth (:data:`SWEEP_SKY_STEPS`), cached per map, scale, turn, facing and floor."""
    fc, fs = (float(x) for x in facing)
    floor = np.asarray(floor, float)

    def build():
        local = _cosine_directions(SWEEP_SKY_STEPS)
        out = np.zeros((SWEEP_TILTS, 3))
        for i, tilt in enumerate(np.linspace(0.0, 0.5 * math.pi, SWEEP_TILTS)):
            n = np.array([-math.sin(tilt) * fc, -math.sin(tilt) * fs, math.cos(tilt)])
            u = np.array([-fs, fc, 0.0])  # level, across the sweep
            d = local @ np.stack([u, np.cross(n, u), n])
            seen = np.where(d[:, 2:3] > 0.0, environment.lookup(d), floor)
            out[i] = seen.mean(axis=0)
        return out
    return _SKY_INTEGRALS.get(environment.texels, lambda _: build(),
                              key=("sweep", float(environment.scale), float(environment.rotation_deg), fc, fs,
                                   *floor.tolist()))


def open_floor(design, e_up) -> np.ndarray:
    """The open floor's radiance (RGB) the backdrop's control variate assumes below its horizon:
    the stage's albedo times the open sky's irradiance ``e_up`` (over pi) and the open light of
    the design's lights above the horizon that do not stand behind the sweep (a light behind it
    leaves the floor in its shadow)."""
    from .lighting import light_table
    from ..kernels.ground import L_B, L_COS, L_DX, L_DY, L_DZ, L_R
    fc, fs = sweep_facing(design.camera)
    e = np.array(e_up, float)
    for row in light_table(design.lights):
        if row[L_DZ] > 0.0 and fc * row[L_DX] + fs * row[L_DY] <= 0.0:
            e += row[L_DZ] * 0.5 * (1.0 + row[L_COS]) / math.pi * row[L_R:L_B + 1]
    return np.asarray(design.stage.color, float) * e


def environment_params(design, environment, factor: float) -> np.ndarray:
    """The kernels' environment row for ``design`` under ``environment``: scale, turn (rad), the
    half-float map's ``factor``, the open sky's irradiance ``E_up`` on a ground (zeros without
    one) and, with a backdrop sweep, the count of its open-sky tilts, their table
    (:func:`sweep_sky_irradiance`, flattened) and the open floor's radiance it assumes
    (:func:`open_floor`): the kernels' ``env_p[6]`` on."""
    sky = open_sky_irradiance(environment) if design.stage.kind != "none" else np.zeros(3)
    row = [float(environment.scale), math.radians(float(environment.rotation_deg)), factor, *sky]
    if design.stage.draws_backdrop:
        floor = open_floor(design, sky)
        table = sweep_sky_irradiance(environment, sweep_facing(design.camera), floor)
        row += [float(len(table)), *table.ravel(), *floor]
    return np.array(row)


#: The last caustic grids built, by what they depend on (a camera or environment edit keeps them).
_CAUSTIC_CACHE: dict = {}
_CAUSTIC_KEEP = 4


def _asset_hashes(assets) -> tuple:
    """The assets' names and the SHA-1 of their bytes, sorted: what a grid's key holds of them."""
    import hashlib
    return tuple(sorted((name, hashlib.sha1(blob).hexdigest()) for name, blob in (assets or {}).items()))


def _facing_key(design):
    """What a grid holds of the camera: where the backdrop sweep faces, if it is drawn."""
    return sweep_facing(design.camera) if design.stage.draws_backdrop else None


def _caustic_key(design, assets) -> tuple:
    """What the caustic grids of ``design`` depend on: everything but the camera (other than
    where the backdrop sweep faces), the render settings and the environment (photons do not
    see the sky), and the label images' bytes."""
    from ...model.design import Camera, Environment, RenderSettings
    import dataclasses
    bare = dataclasses.replace(design, camera=Camera(), render=RenderSettings(), environment=Environment())
    return bare, _asset_hashes(assets), _facing_key(design)


def _with_buffers(tables: Tables) -> Tables:
    """``tables`` with its labels' (empty) record buffers, as the kernels take them."""
    from .labels import with_buffers
    return tables._replace(labels=with_buffers(tables.labels))


def stage_caustics(design, assets, tables: Tables) -> dict:
    """The finish tables' ``caustics`` and ``caustic_grid`` fields for ``design`` on its diffuse
    ground (:func:`engine.tracer.tables.caustics.caustic_grids`, its photons meeting ``tables``),
    from a small cache."""
    from .caustics import caustic_grids
    scene = tables.scene
    hit = cached(_CAUSTIC_CACHE, _SKY_LOCK, _CAUSTIC_KEEP, _caustic_key(design, assets), lambda *_: caustic_grids(
        _with_buffers(tables), int(scene.geom.obj_i[ground_object(scene), K.O_MAT]), float(design.stage.z_mm)))
    return {"caustics": hit[0], "caustic_grid": hit[1]}


#: The last sky grids built, by what they depend on (a camera edit keeps them).
_SKY_GRID_CACHE: dict = {}


def _sky_key(design, assets) -> tuple:
    """What the sky grid of ``design`` depends on: everything but the camera (other than where
    the backdrop sweep faces) and the render settings other than the tree's cut-offs, and the
    assets' bytes."""
    from ...model.design import Camera, RenderSettings
    import dataclasses
    bare = dataclasses.replace(design, camera=Camera(), render=RenderSettings())
    return (bare, int(design.render.max_depth), float(design.render.min_weight), _asset_hashes(assets),
            _facing_key(design))


def stage_sky(design, assets, tables: Tables, cancelled=None) -> dict:
    """The finish tables' ``sky`` and ``sky_grid`` fields for ``design`` on its diffuse ground
    (:func:`engine.tracer.tables.sky.sky_grid`, its probes meeting ``tables``, stopped by
    ``cancelled()``), from a small cache; ``tables.finishes`` must carry no sky grid yet."""
    from .sky import sky_grid
    hit = cached(_SKY_GRID_CACHE, _SKY_LOCK, _CAUSTIC_KEEP, _sky_key(design, assets), lambda *_: sky_grid(
        _with_buffers(tables), ground_object(tables.scene), float(design.stage.z_mm),
        math.sqrt(2.0) * float(design.stage.half_size_mm), int(design.render.max_depth),
        float(design.render.min_weight), cancelled=cancelled))
    return {"sky": hit[0], "sky_grid": hit[1]}


#: The last sweep grids built, by what they depend on (the sky grid's key).
_SWEEP_GRID_CACHE: dict = {}


def stage_sweep(design, assets, tables: Tables, cancelled=None) -> dict:
    """The finish tables' ``sweep`` and ``sweep_grid`` fields for ``design``'s backdrop sweep
    (:func:`engine.tracer.tables.sweep.sweep_grid`, its probes meeting ``tables``, stopped by
    ``cancelled()``), from a small cache; ``tables.finishes`` must carry no sweep or sky grid yet
    (the sky grid is built after it)."""
    from .sweep import sweep_grid
    hit = cached(_SWEEP_GRID_CACHE, _SKY_LOCK, _CAUSTIC_KEEP, _sky_key(design, assets), lambda *_: sweep_grid(
        _with_buffers(tables), int(design.render.max_depth),
        float(design.render.min_weight), cancelled=cancelled))
    return {"sweep": hit[0], "sweep_grid": hit[1]}


def clear_stage_caches() -> None:
    """Forget every caustic and sky grid built (a benchmark timing a design's first render)."""
    with _SKY_LOCK:
        _CAUSTIC_CACHE.clear()
        _SKY_GRID_CACHE.clear()
        _SWEEP_GRID_CACHE.clear()


def stage_grids_ready(design, assets, width: int, height: int) -> bool:
    """Whether a render of ``design`` at ``width x height`` pixels would find its ground's grids
    built (none needed without a diffuse ground; no sky grid for an image too small to pay for
    it, :func:`engine.tracer.tables.sky.sky_grid_pays`): else its first image may come from a
    draft (:class:`engine.tracer.job.RenderJob`)."""
    from .sky import sky_grid_pays
    if not design.stage.is_diffuse_ground:
        return True
    with _SKY_LOCK:
        key = _sky_key(design, assets)
        sky = not sky_grid_pays(width, height) or (
            key in _SKY_GRID_CACHE and (not design.stage.draws_backdrop or key in _SWEEP_GRID_CACHE))
        caustics = not design.lights or _caustic_key(design, assets) in _CAUSTIC_CACHE
    return sky and caustics
