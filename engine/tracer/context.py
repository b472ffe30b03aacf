"""The compiled scene of one render: what worker threads hand to the kernels.

Design rule: a :class:`RenderContext` is built once per render from a frozen ``Design``
snapshot (geometry tables from the value cache, media, materials, environment texels, camera)
and is then shared read-only by every worker. :func:`trace_pixels` is the one Python entry to
the tile kernel: it allocates the caller's output buffers and returns per-pixel sums, so tests,
benchmarks and the job all trace through the same code.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from .camera import PinholeCamera
from .tables.environment import EnvironmentMap, environment_from_design, half_texels
from .kernels.integrator import (C_BUDGET, C_CUT_DEPTH, C_CUT_WEIGHT, C_LEAKS, C_MISMATCH, C_NODES,
                                 C_QUERIES, N_COUNTERS)
from .kernels.sampling import C_COLS
from .kernels.tile import render_pixels
from .kernels.ground import NOISY_BIT
from .kernels.records import Cutoffs, FinishTables, Geometry, LabelTables, Pixels, PixelSums, Scene, Tables
from .tables.labels import empty_label_arrays, label_arrays, with_buffers
from .tables.finishes import cap_tables_for, empty_finish, finish_arrays, scene_with_cap
from .tables.render_objects import RenderGeometry, render_geometry_for, scene_arrays, search_tables
from .tables.sky import sky_grid_pays
from .tables.stage import (environment_params, ground_objects, scene_with_stage, stage_caustics, stage_sky,
                           stage_sweep)
from .thread_geometry import scene_with_threads

#: Boundaries one camera sample may visit before what it still holds is closed with the
#: environment (bounds the time of a sample; light trapped by total internal reflection in a
#: thick base is what reaches it).
MAX_NODES = 1 << 14


def scene_tables(design):
    """``(geometry, cap tables, scene)`` of ``design``: the render objects of the bottle
    (cached by shape and fill), its true threads, its closure and the stage's ground, as the
    kernels search them. What a render, the coverage of a final render's alpha and picking all
    intersect."""
    geom = render_geometry_for(design)
    cap = cap_tables_for(design, geom)
    scene = scene_with_cap(scene_with_threads(scene_arrays(geom, design), design), cap, geom.fill_height)
    return geom, cap, scene_with_stage(scene, design.stage, design.camera)


def camera_array(camera: PinholeCamera) -> np.ndarray:
    """The kernels' camera row: eye, forward, right, up', tan(fov/2), width, height."""
    f, r, u, t = camera.basis()
    cam = np.zeros(C_COLS)
    cam[0:3], cam[3:6], cam[6:9], cam[9:12] = camera.eye, f, r, u
    cam[12], cam[13], cam[14] = t, camera.width, camera.height
    return cam


@dataclass(frozen=True, eq=False)
class RenderContext:
    """Everything compiled from one design snapshot for one image size (immutable).

    ``reference_level`` is the environment's mean radiance: the fixed scale the sampling
    policy's thresholds are fractions of (independent of the bottle, so of any edit to it).
    """

    geometry: RenderGeometry
    scene: Scene
    #: the environment's float32 texels (what the label and finish maps are made from)
    texels: np.ndarray
    #: ``(scale, rotation rad, factor, E_up (rgb))``: the environment's scale and turn, the factor
    #: of the kernels' half-float copy of the map (:func:`engine.tracer.tables.environment.half_texels`)
    #: and its open-sky irradiance for a ground, then a backdrop sweep's open-sky table
    #: (:func:`~engine.tracer.tables.stage.environment_params`)
    env_params: np.ndarray
    camera: PinholeCamera
    cam: np.ndarray
    max_depth: int
    min_weight: float
    n_materials: int
    reference_level: float
    environment: EnvironmentMap = field(repr=False, default=None)
    #: the label tables (:func:`engine.tracer.tables.labels.label_arrays`); a label edit replaces only
    #: this field (:meth:`with_labels`)
    labels: LabelTables = field(repr=False, default_factory=empty_label_arrays)
    #: the finish tables (:mod:`engine.tracer.tables.finishes`: relief rows, cap irradiance)
    finish: FinishTables = field(repr=False, default=None)
    #: the closure's render rows (:class:`engine.tracer.tables.finishes.CapTables`) or ``None``
    cap: object = field(repr=False, default=None)
    #: the half-float bit patterns of ``texels`` the kernels look up (:meth:`from_design`)
    lookup_texels: np.ndarray = field(repr=False, default=None)

    @classmethod
    def from_design(cls, design, assets=None, width=None, height=None, environment=None, *, grids=None,
                    cancelled=None) -> "RenderContext":
        """Compile ``design`` for an image of ``width x height`` pixels (default: its render
        settings); ``environment`` replaces the design's (tests: a uniform white one). A diffuse
        ground gets its lights' caustic grids and, where the image pays for it
        (:func:`~engine.tracer.tables.sky.sky_grid_pays`; ``grids`` true: always), its sky grid
        (and a backdrop sweep its sweep grid);
        ``grids`` false makes a draft (the ground probes per hit and shows no caustic).
        ``cancelled()`` true stops the sky grid's build
        (:class:`~engine.tracer.tables.sky.GridCancelled`). Raises the geometry engine's errors
        for an invalid shape."""
        w = int(width or design.render.width)
        h = int(height or design.render.height)
        geom, cap, scene = scene_tables(design)
        env = environment if environment is not None else environment_from_design(design.environment, assets)
        cam = PinholeCamera.from_design(design.camera, w, h)
        tex = np.ascontiguousarray(env.texels, dtype=np.float32)
        finish = finish_arrays(design, assets, geom, cap, scene, tex)
        half, factor = half_texels(tex)
        params = environment_params(design, env, factor)
        level = float(np.mean(tex, dtype=np.float64)) * float(env.scale)
        labels = label_arrays(design, assets, tex, geom.obj_i.shape[0])
        def tables():  # what the stage's photons and probes meet, with the finishes built so far
            return Tables(scene, labels, finish, params, half)

        if grids is not False and finish.lights.shape[0] and design.stage.is_diffuse_ground:
            finish = finish._replace(**stage_caustics(design, assets, tables()))
        if (sky_grid_pays(w, h) if grids is None else grids) and design.stage.is_diffuse_ground:
            if design.stage.draws_backdrop:  # first: the sky grid's probes that meet the sweep read it
                finish = finish._replace(**stage_sweep(design, assets, tables(), cancelled))
            finish = finish._replace(**stage_sky(design, assets, tables(), cancelled))
        return cls(geom, scene, tex, params, cam, camera_array(cam), int(design.render.max_depth),
                   float(design.render.min_weight), int(scene.mat_i.shape[0]), level, env,
                   labels, finish, cap, half)

    def with_labels(self, design, assets=None) -> "RenderContext":
        """This context with the labels (and lights) of ``design``: geometry, media, camera and
        environment are kept as they are (the caller vouches that only labels, lights or label
        assets differ)."""
        return dataclasses.replace(self, labels=label_arrays(design, assets, self.texels,
                                                             self.geometry.obj_i.shape[0]))

    @property
    def ground_objects(self) -> np.int64:
        """Object-mask bits of the stage's ground (none without one)."""
        return np.int64(sum(1 << int(k) for k in ground_objects(self.scene)))

    @property
    def stochastic_objects(self) -> np.int64:
        """Object-mask bits that say a tree's light was estimated by sampling (the ground's
        :data:`~engine.tracer.kernels.ground.NOISY_BIT`: a probe beyond its sky grid, a rough
        coat, a light's penumbra): such a pixel is noisy even where it differs from no
        neighbour. Zero without a ground."""
        return NOISY_BIT if self.ground_objects else np.int64(0)

    def tables(self, labels: LabelTables | None = None) -> Tables:
        """What the kernels' trees read (:class:`~engine.tracer.kernels.records.Tables`): the
        scene, ``labels`` (default: the context's, with empty record buffers), the finishes,
        the environment's row and its lookup texels."""
        return Tables(self.scene, with_buffers(self.labels) if labels is None else labels, self.finish_tables,
                      self.env_params, self.lookup_texels)

    @property
    def finish_tables(self) -> FinishTables:
        """The finish tables (empty ones for a context built without)."""
        return self.finish if self.finish is not None else empty_finish(self.scene.geom.obj_i.shape[0])


@dataclass
class TraceStats:
    """Kernel counters summed over a render (see :mod:`engine.tracer.kernels.integrator`)."""

    rays_cast: int = 0       # intersection queries (ray segments)
    escaped_inside: int = 0  # rays inside glass or liquid that met nothing: a leak
    mismatches: int = 0      # hits whose incident side was not the ray's medium
    cut_depth: int = 0
    cut_weight: int = 0
    cut_budget: int = 0
    boundaries: int = 0

    def add_counters(self, c) -> None:
        """Add a kernel counter array."""
        self.rays_cast += int(c[C_QUERIES])
        self.escaped_inside += int(c[C_LEAKS])
        self.mismatches += int(c[C_MISMATCH])
        self.cut_depth += int(c[C_CUT_DEPTH])
        self.cut_weight += int(c[C_CUT_WEIGHT])
        self.cut_budget += int(c[C_BUDGET])
        self.boundaries += int(c[C_NODES])


@dataclass
class PixelResult:
    """Per-pixel sums of a :func:`trace_pixels` call (arrays of length P)."""

    sums: np.ndarray      # (P, 3) radiance sums over the traced samples
    sumsq: np.ndarray     # (P,) sums of squared per-sample mean-of-RGB radiance
    signature: np.ndarray  # (P,) uint64 dominant-path hash of the first traced sample
    objects: np.ndarray   # (P,) int64 bit mask of the render objects the trees met
    depth: np.ndarray     # (P, n_materials) int64 shallowest depth each material was met (255: never)
    counters: np.ndarray  # (N_COUNTERS,) int64 kernel counters (see kernels.integrator)
    finished: int         # pixels done (fewer than P when cancelled)
    #: with ``record_labels``: ``(smp_f, smp_i, hit_f, hit_i)``, per traced sample (pixels in
    #: order, their samples in order) its radiance without label terms and its hits' range, and
    #: the hits (kernels.labels ``H_*``); ``None`` otherwise
    label_record: tuple | None = None
    #: ``(P, 6)`` sums over the traced samples of the denoiser's guides, albedo RGB and normal
    #: (:func:`~engine.tracer.kernels.integrator.trace_sample`); ``None`` where none were traced
    #: (a relabel's recomputed pixels keep the film's)
    guide: np.ndarray | None = None


def _per_pixel(v, p: int) -> np.ndarray:
    """A scalar or ``(p,)`` array of sample numbers as a fresh ``(p,)`` int64 array (a copy: a
    read-only view would make the kernel compile a second time for its type)."""
    a = np.asarray(v, np.int64)
    return np.full(p, a, np.int64) if a.ndim == 0 else np.array(a.reshape(p))


def trace_pixels(ctx: RenderContext, cols, rows, first, count, cancel=None, record=None,
                 roulette: float = 0.0, record_labels: bool = False) -> PixelResult:
    """Trace samples ``first[p] .. first[p] + count[p] - 1`` of pixels ``(cols[p], rows[p])``.

    Sample 0 is the pixel centre, samples >= 1 the pixel's stratified positions (see
    :mod:`engine.tracer.kernels.sampling`). ``cancel`` is an int array of one element polled
    between pixels; ``record`` an optional ``(rays float32 (N, 6 or 9), count int64 (1,))``
    pair that receives every intersection query (benchmarks): origin and direction, and with
    9 columns the medium, the object left and the side (:func:`nearest_hits`'s arguments);
    ``roulette`` > 0 makes branches lighter than it play Russian roulette (unbiased; for the
    extra samples of noisy pixels);
    ``record_labels`` keeps the label terms of every sample (``PixelResult.label_record``, for
    a relabel; only with labels). Releases the GIL while tracing.
    """
    cols = np.ascontiguousarray(cols, dtype=np.int64)
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    p = len(cols)
    first, count = _per_pixel(first, p), _per_pixel(count, p)
    sums = np.zeros((p, 3))
    sumsq = np.zeros(p)
    sig = np.zeros(p, np.uint64)
    mask = np.zeros(p, np.int64)
    depth = np.full((p, ctx.n_materials), 255, np.int64)
    counters = np.zeros(N_COUNTERS, np.int64)
    guide = np.zeros((p, 6))
    if cancel is None:
        cancel = np.zeros(1, np.int64)
    rec_rays, rec_n = record if record is not None else (np.zeros((0, 6), np.float32), np.zeros(1, np.int64))
    samples = int(count.sum()) if record_labels and ctx.labels.rows.shape[0] > 0 else 0
    hits = None
    cut = Cutoffs(ctx.max_depth, ctx.min_weight, float(roulette), MAX_NODES)
    out = PixelSums(sums, sumsq, sig, mask, depth, counters, guide)
    while True:
        labels = with_buffers(ctx.labels, samples, hits)
        done = render_pixels(ctx.tables(labels), ctx.cam, Pixels(cols, rows, first, count), cut, 0, out, cancel,
                             (rec_rays, rec_n))
        if not samples or not labels.hit_n[1] or done < p:
            break
        # more hits than room: trace the call again with room for all (same seeds, same result)
        hits = 4 * labels.hit_f.shape[0]
        sums[:], sumsq[:], sig[:], mask[:], depth[:], counters[:], guide[:] = 0, 0, 0, 0, 255, 0, 0
    rec = None
    if samples and done == p:
        n = int(labels.hit_n[0])
        rec = (labels.smp_f, labels.smp_i, labels.hit_f[:n].copy(), labels.hit_i[:n].copy())
    return PixelResult(sums, sumsq, sig, mask, depth, counters, int(done), rec, guide)


# --------------------------------------------------------------------------- ray queries
def _geom(where) -> Geometry:
    """The search tables of a :class:`RenderGeometry` or a :class:`Scene`."""
    return where.geom if isinstance(where, Scene) else search_tables(where)


def nearest_hits(geometry, origins, directions, medium=0, last=-1, side=0):
    """Nearest true hits of rays (mm, unit directions) against the render objects of
    ``geometry``: a :class:`RenderGeometry` (the bottle) or a
    :class:`~engine.tracer.kernels.records.Scene` of :func:`scene_tables` (the bottle with its
    threads and closure).

    ``medium`` is the medium each ray travels in, ``last``/``side`` the object it just left and
    the sign of ``d . n`` it left with (``-1``/``0`` for a fresh ray); all broadcast.
    Returns ``(t, object, part, normal)``: distance (inf for a miss), object row (-1), segment
    or slab row, oriented unit normal.
    """
    from .kernels.queries import hits

    o = np.ascontiguousarray(np.asarray(origins, float).reshape(-1, 3))
    d = np.ascontiguousarray(np.asarray(directions, float).reshape(-1, 3))
    n = len(o)
    b = lambda v: np.ascontiguousarray(np.broadcast_to(np.asarray(v, np.int64), (n,)))
    t, k, part, nrm = np.empty(n), np.empty(n, np.int64), np.empty(n, np.int64), np.empty((n, 3))
    hits(_geom(geometry), o, d, b(medium), b(last), b(side), t, k, part, nrm)
    return t, k, part, nrm


def object_normals(geometry: RenderGeometry, objects, parts, points) -> np.ndarray:
    """Oriented unit normals of ``objects[i]`` (on segment/slab row ``parts[i]``) at ``points``."""
    from .kernels.queries import normals

    p = np.ascontiguousarray(np.asarray(points, float).reshape(-1, 3))
    n = len(p)
    out = np.empty((n, 3))
    normals(_geom(geometry), np.ascontiguousarray(np.broadcast_to(np.asarray(objects, np.int64), (n,))),
            np.ascontiguousarray(np.broadcast_to(np.asarray(parts, np.int64), (n,))), p, out)
    return out


def trace_rays(ctx: RenderContext, origins, directions, seed: int = 0):
    """Radiance ``(N, 3)`` of arbitrary rays starting in air (origins in mm, unit directions),
    and the kernel counters. Ray ``i`` draws its random numbers (Russian roulette, rough
    surfaces' lobes) from stream ``seed + i``: two calls with the same ``seed`` repeat each
    other's streams, so estimates meant to be independent (a pixel per call, averaged) give each
    call its own range, e.g. ``seed`` = the rays traced so far."""
    if not 0 <= int(seed) < 2 ** 63:
        raise ValueError(f"seed must be in [0, 2**63), got {seed!r}")
    from .kernels.queries import radiance

    o = np.ascontiguousarray(np.asarray(origins, float).reshape(-1, 3))
    d = np.ascontiguousarray(np.asarray(directions, float).reshape(-1, 3))
    out = np.zeros((len(o), 3))
    counters = np.zeros(N_COUNTERS, np.int64)
    radiance(ctx.tables(), o, d, Cutoffs(ctx.max_depth, ctx.min_weight, 0.0, MAX_NODES), out, counters, int(seed))
    return out, counters
