"""Every label of a design as flat arrays for the tracer's kernels.

Design rule: :func:`compile_labels` turns ``Design.labels`` and the project's assets into a
:class:`CompiledLabels` of contiguous numpy arrays with named columns, the way
:mod:`engine.tracer.render_objects` compiles geometry: the kernels index rows and never see a
Python object. Geometry (the decals) and appearance (images, region maps, finishes,
coefficients) come from separate caches keyed by value, so an artwork, finish or coefficient
edit recompiles in the time it takes to copy the arrays and never rebuilds a decal, and a label
that moves never decodes an image again. Rows follow ``Design.labels`` (overlap order: a later
row is on top). Images shared by several faces are stored once.

Label row ``label_f[k]`` (float64, columns ``L_*``): coefficients, the two plain colours
(linear RGB), the texture rows of front and back (-1: the plain colour), the region map row
(-1: none) and the first finish row and count of its regions. A texel of texture ``m`` at
``(x, y)`` (``x`` from the left of the artwork, ``y`` from its top) is
``texels[tex_i[m, 0] + y * tex_i[m, 1] + x]``, straight linear RGBA; a region code of map ``q``
is ``codes[region_i[q, 0] + y * region_i[q, 1] + x]``, 0 for plain paper and ``c`` for finish row
``label_f[k, L_REGION0] + c - 1``. The artwork texel under ``(s, t)`` is ``x = s W``, ``y = t H``
(texel centres at half-integers).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import limits as L
from .cap_surfaces import surface_decal
from .decal import D_COLS, label_decal, pack_decals
from .images import ArtworkError, asset_image, probe_image
from .presets import FINISH_CODES, FOIL_OPTICS, WHITE_UNDERPRINT
from .regions import region_map

(L_DIFFUSE, L_SPECULAR, L_TRANSMISSION, L_FRONT_R, L_FRONT_G, L_FRONT_B, L_BACK_R, L_BACK_G,
 L_BACK_B, L_FRONT_TEX, L_BACK_TEX, L_REGION_MAP, L_REGION0, L_NREGIONS) = range(14)
L_COLS = 14
#: Finish rows: kind code (:data:`engine.appearance.presets.FINISH_CODES`), relief (mm),
#: gloss, conductor ``n`` and ``k`` per RGB (foils; 0 otherwise), underprint reflectance per RGB.
F_KIND, F_DEPTH, F_GLOSS = 0, 1, 2
F_N, F_K, F_UNDER = 3, 6, 9
F_COLS = 12


@dataclass(frozen=True, eq=False)
class CompiledLabels:
    """The kernels' label tables (module rule); every array contiguous and read-only."""

    decal_rows: np.ndarray   # (n, D_COLS) float64, engine.appearance.decal.pack_decals
    decal_nodes: np.ndarray  # (N, 2) float32 (s, t)
    label_f: np.ndarray      # (n, L_COLS) float64
    texels: np.ndarray       # (T, 4) float32 straight linear RGBA
    tex_i: np.ndarray        # (m, 3) int64: first texel, width, height
    codes: np.ndarray        # (R,) uint8 region codes
    region_i: np.ndarray     # (q, 3) int64: first code, width, height
    finishes: np.ndarray     # (F, F_COLS) float64

    @property
    def count(self) -> int:
        return len(self.label_f)


def _finish_row(region) -> np.ndarray:
    row = np.zeros(F_COLS)
    row[F_KIND], row[F_DEPTH], row[F_GLOSS] = FINISH_CODES[region.finish], region.depth_mm, region.gloss
    if region.finish in FOIL_OPTICS:
        n, k = FOIL_OPTICS[region.finish]
        row[F_N:F_N + 3], row[F_K:F_K + 3] = n, k
    if region.finish == "clear_vinyl_white":
        row[F_UNDER:F_UNDER + 3] = WHITE_UNDERPRINT
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
                         np.array(finishes).reshape(-1, F_COLS))
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
