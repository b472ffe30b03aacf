"""The label tables of one render: every label of a design as the flat arrays the kernels read.

Design rule: :func:`label_arrays` is the one place a design's labels become the tuple the
kernels take (:class:`engine.tracer.kernels.records.LabelTables`; the labels kernel owns the
``D_``, ``L_``, ``LF_`` and ``P_`` column layouts this module fills and never redefines): the decals (each
label's exact map sampled on a grid, :mod:`engine.appearance.decal`, packed by
:func:`pack_decals`), the label rows and artwork of :func:`compile_labels`, each label's size in
mm (for emboss slopes), the environment's diffuse irradiance table
(:func:`engine.tracer.tables.lighting.irradiance_table`, computed once per environment and cached), the
directional lights, each label's place row (the surface and render object it lies on,
:func:`place_rows`) and the bit mask of the objects labels lie on. A design without labels gets
:func:`empty_label_arrays`: zero-row tables of the same types, so the kernels compile once and
pay one length test per hit. Only the objects' numbering comes from the compiled scene, so a
label edit rebuilds only this tuple.

:func:`compile_labels` turns ``Design.labels`` and the project's assets into a
:class:`CompiledLabels` of contiguous numpy arrays, the way :mod:`engine.tracer.tables.render_objects`
compiles geometry: the kernels index rows and never see a Python object. Geometry (the decals)
and appearance (images, region maps, finishes, coefficients) come from separate caches keyed by
value, so an artwork, finish or coefficient edit recompiles in the time it takes to copy the
arrays and never rebuilds a decal, and a label that moves never decodes an image again. Rows
follow ``Design.labels`` (overlap order: a later row is on top). Images shared by several faces
are stored once. A texel of texture ``m`` at ``(x, y)`` (``x`` from the left of the artwork,
``y`` from its top) is ``texels[tex_i[m, 0] + y * tex_i[m, 1] + x]``, straight linear RGBA; a
region code of map ``q`` is ``codes[region_i[q, 0] + y * region_i[q, 1] + x]``, 0 for plain
paper and ``c`` for finish row ``label_f[k, L_REGION0] + c - 1``. The artwork texel under
``(s, t)`` is ``x = s W``, ``y = t H`` (texel centres at half-integers).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ... import limits as L
from ...appearance.cap_surfaces import cap_surface, surface_decal
from ...appearance.decal import label_decal
from ...appearance.images import ArtworkError, asset_image, probe_image
from ...appearance.presets import FOIL_OPTICS, WHITE_UNDERPRINT
from ...appearance.regions import region_map
from ..kernels.labels import (D_COLS, FINISH_CODES, H_COLS, L_BACK_B, L_BACK_R, L_BACK_TEX, L_COLS, L_DIFFUSE,
                              L_FRONT_B, L_FRONT_R, L_FRONT_TEX, L_NREGIONS, L_REGION0, L_REGION_MAP,
                              L_SPECULAR, L_TRANSMISSION, LF_COLS, LF_DEPTH, LF_GLOSS, LF_K, LF_KIND, LF_N,
                              LF_UNDER, P_BX, P_BY, P_COLS, P_CX, P_CY, P_OBJECT, P_SURFACE, P_V0, P_V1,
                              SURFACE_CODES)
from ..kernels.records import LabelTables
from ..kernels.ground import LIGHT_COLS
from .lighting import irradiance_table, light_table


@dataclass(frozen=True, eq=False)
class CompiledLabels:
    """The kernels' label tables (module rule); every array contiguous and read-only."""

    decal_rows: np.ndarray   # (n, D_COLS) float64, pack_decals
    decal_nodes: np.ndarray  # (N, 2) float32 (s, t)
    label_f: np.ndarray      # (n, L_COLS) float64
    texels: np.ndarray       # (T, 4) float32 straight linear RGBA
    tex_i: np.ndarray        # (m, 3) int64: first texel, width, height
    codes: np.ndarray        # (R,) uint8 region codes
    region_i: np.ndarray     # (q, 3) int64: first code, width, height
    finishes: np.ndarray     # (F, LF_COLS) float64

    @property
    def count(self) -> int:
        return len(self.label_f)


def _finish_row(region) -> np.ndarray:
    row = np.zeros(LF_COLS)
    row[LF_KIND], row[LF_DEPTH], row[LF_GLOSS] = FINISH_CODES[region.finish], region.depth_mm, region.gloss
    if region.finish in FOIL_OPTICS:
        n, k = FOIL_OPTICS[region.finish]
        row[LF_N:LF_N + 3], row[LF_K:LF_K + 3] = n, k
    if region.finish == "clear_vinyl_white":
        row[LF_UNDER:LF_UNDER + 3] = WHITE_UNDERPRINT
    return row


def check_artwork_budget(design, assets) -> None:
    """``ArtworkError`` when the label images of ``design`` together have more texels than
    :data:`engine.limits.MAX_DESIGN_ARTWORK_TEXELS` (from their headers: nothing decoded)."""
    names = dict.fromkeys(n for lab in design.labels for n in lab.asset_names())
    total = 0
    for name in names:
        if name not in assets:
            raise ArtworkError(f"label image {name!r} is not in the project")
        info = probe_image(assets[name], f"label image {name!r}")
        total += info.width * info.height
    if total > L.MAX_DESIGN_ARTWORK_TEXELS:
        raise ArtworkError(f"the labels' images have {total} texels together "
                           f"(limit {L.MAX_DESIGN_ARTWORK_TEXELS})")


def compile_labels(design, assets) -> CompiledLabels:
    """The :class:`CompiledLabels` of ``design`` with ``assets`` (name -> bytes).

    Raises :class:`engine.appearance.images.ArtworkError` for a bad or missing image; the labels
    must lie on their surfaces (a design that passed ``check_design`` does).
    """
    check_artwork_budget(design, assets)
    rows, nodes = pack_decals([label_decal(design.shape, lab) if lab.surface == "wall"
                               else surface_decal(design, lab) for lab in design.labels])
    label_f = np.zeros((len(design.labels), L_COLS))
    textures: dict[str, int] = {}
    images, maps, finishes = [], [], []
    for k, lab in enumerate(design.labels):
        f = label_f[k]
        f[L_DIFFUSE], f[L_SPECULAR], f[L_TRANSMISSION] = lab.diffuse, lab.specular, lab.transmission
        f[L_FRONT_R:L_FRONT_B + 1], f[L_BACK_R:L_BACK_B + 1] = lab.front.color, lab.back.color
        for col, side in ((L_FRONT_TEX, lab.front), (L_BACK_TEX, lab.back)):
            if side.asset is None:
                f[col] = -1
                continue
            if side.asset not in textures:
                textures[side.asset] = len(images)
                images.append(asset_image(assets, side.asset))
            f[col] = textures[side.asset]
        f[L_REGION_MAP], f[L_REGION0], f[L_NREGIONS] = -1, len(finishes), len(lab.regions)
        if lab.regions:
            f[L_REGION_MAP] = len(maps)
            maps.append(region_map(lab, assets))
            finishes.extend(_finish_row(r) for r in lab.regions)
    texels, tex_i = _pack([im.reshape(-1, 4) for im in images], images, np.float32, (0, 4))
    codes, region_i = _pack([m.reshape(-1) for m in maps], maps, np.uint8, (0,))
    out = CompiledLabels(rows.reshape(-1, D_COLS), nodes, label_f, texels, tex_i, codes, region_i,
                         np.array(finishes).reshape(-1, LF_COLS))
    for a in out.__dict__.values():
        a.setflags(write=False)
    return out


def _pack(flat_parts, originals, dtype, empty_shape):
    index = np.zeros((len(originals), 3), np.int64)
    offset = 0
    for m, a in enumerate(originals):
        index[m] = (offset, a.shape[1], a.shape[0])
        offset += a.shape[0] * a.shape[1]
    data = np.concatenate(flat_parts) if flat_parts else np.zeros(empty_shape, dtype)
    return np.ascontiguousarray(data, dtype=dtype), index


def pack_decals(decals):
    """Decals as two flat arrays for the kernels: ``rows`` float64 ``(n, D_COLS)`` (columns
    ``D_THETA0 .. D_OFFSET``; ``D_NT``/``D_NH`` node counts, ``D_OFFSET`` the first node) and
    ``nodes`` float32 ``(N, 2)``; node ``(i, j)`` of decal ``k`` is ``nodes[offset + i * nt + j]``."""
    rows = np.zeros((len(decals), D_COLS))
    parts, offset = [], 0
    for k, d in enumerate(decals):
        nh, nt = d.shape
        rows[k] = (d.theta0, d.theta1, d.h0, d.h1, nt, nh, offset)
        parts.append(d.st.reshape(-1, 2))
        offset += nh * nt
    nodes = np.concatenate(parts) if parts else np.zeros((0, 2), np.float32)
    return rows, np.ascontiguousarray(nodes, dtype=np.float32)


def place_rows(design, first_cap_object: int) -> tuple[np.ndarray, int]:
    """``(rows (n, P_COLS), objects)``: each label's place row (module rule; a wall label lies
    on object 0 over all of it) and the bit mask of the render objects labels lie on; the
    closure's parts are objects ``first_cap_object + part``."""
    rows = np.zeros((len(design.labels), P_COLS))
    objects = 0
    for k, label in enumerate(design.labels):
        row = rows[k]
        row[P_SURFACE] = SURFACE_CODES[label.surface]
        row[P_V0], row[P_V1] = -np.inf, np.inf
        if label.surface != "wall":
            surf = cap_surface(design, label.surface)
            row[P_OBJECT] = first_cap_object + surf.part
            row[P_V0], row[P_V1] = surf.v0, surf.v1
            a = math.radians(label.angle_deg)
            row[P_CX], row[P_CY], row[P_BX], row[P_BY] = label.cap_x_mm, label.cap_y_mm, math.cos(a), math.sin(a)
        objects |= 1 << int(row[P_OBJECT])
    rows.setflags(write=False)
    return rows, objects


#: The record buffers of a call that does not record (never written: the kernels test the
#: hit table's length first), shared by every call.
_NO_RECORD = (np.zeros((0, H_COLS)), np.zeros((0, 2), np.int64), np.zeros(2, np.int64), np.zeros(3),
              np.zeros((0, 3)), np.zeros((0, 2), np.int64))


def _tables(cl, size, irr, lights, place, objects) -> LabelTables:
    return LabelTables(cl.decal_rows, cl.decal_nodes, cl.label_f, cl.texels, cl.tex_i, cl.codes, cl.region_i,
                       cl.finishes, size, irr, lights, place, np.array([objects], np.int64), *_NO_RECORD)


class _Empty:
    decal_rows = np.zeros((0, D_COLS))
    decal_nodes = np.zeros((0, 2), np.float32)
    label_f = np.zeros((0, L_COLS))
    texels = np.zeros((0, 4), np.float32)
    tex_i = np.zeros((0, 3), np.int64)
    codes = np.zeros(0, np.uint8)
    region_i = np.zeros((0, 3), np.int64)
    finishes = np.zeros((0, LF_COLS))


def empty_label_arrays() -> LabelTables:
    """The tables of a design without labels (same types, read-only flags included, as
    :func:`label_arrays`, so the kernels are compiled once for both)."""
    irr = np.zeros((2, 2, 3), np.float32)
    for a in (irr,) + tuple(v for k, v in vars(_Empty).items() if isinstance(v, np.ndarray)):
        a.setflags(write=False)
    place = np.zeros((0, P_COLS))
    place.setflags(write=False)  # as place_rows gives it (numba types read-only arrays apart)
    return _tables(_Empty, np.zeros((0, 2)), irr, np.zeros((0, LIGHT_COLS)), place, 0)


def label_arrays(design, assets, env_texels, first_cap_object: int = 0) -> LabelTables:
    """The kernels' label tables of ``design`` (module rule); ``env_texels`` the environment's
    unscaled texels, ``first_cap_object`` the render object of the closure's first part (the
    bottle's object count; prints on the closure lie on those objects). Raises
    :class:`engine.appearance.images.ArtworkError` for a bad image."""
    if not design.labels:
        return empty_label_arrays()
    cl = compile_labels(design, assets or {})
    size = np.array([[lab.width_mm, lab.height_mm] for lab in design.labels], float)
    place, objects = place_rows(design, first_cap_object)
    return _tables(cl, size, irradiance_table(env_texels), light_table(design.lights), place, objects)


#: Hits a recording call makes room for per sample at first (it retries with more on overflow).
HITS_PER_SAMPLE = 2


def with_buffers(labels: LabelTables, samples: int = 0, hits: int | None = None) -> LabelTables:
    """``labels`` with the record buffers the kernels append hits to (the fields ``hit_f ..
    smp_i`` of :class:`~engine.tracer.kernels.records.LabelTables`): for ``samples`` samples and
    ``hits`` hits (default :data:`HITS_PER_SAMPLE` a sample), or none (``samples = 0``: not
    recording)."""
    if samples <= 0:
        return labels._replace(**dict(zip(_BUFFERS, _NO_RECORD)))
    cap = HITS_PER_SAMPLE * samples + 64 if hits is None else int(hits)
    return labels._replace(hit_f=np.zeros((cap, H_COLS)), hit_i=np.zeros((cap, 2), np.int64),
                           hit_n=np.zeros(2, np.int64), rest=np.zeros(3), smp_f=np.zeros((samples, 3)),
                           smp_i=np.zeros((samples, 2), np.int64))


_BUFFERS = ("hit_f", "hit_i", "hit_n", "rest", "smp_f", "smp_i")
