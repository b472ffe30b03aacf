"""Retint: a colour-only edit's preview from the last converged film, before the new one exists.

Design rule: when only the glass's or the liquid's absorption changed (the tint, the liquid's
colour; every other field of the design, the assets and the sampling the same), every ray tree
of the new render has the old one's geometry, and each leaf's value changes by the factor
``exp(-delta_sigma * length)`` of its lengths in the media. Keeping those lengths per sample
would cost 0.01-1.7 GiB at the window's size (``benchmarks.window_converge``: "a kept tree for
colour edits"); the new render's own samples carry the same information for free: a pixel's
centre sample (sample 0: the same ray, the same tree) is traced again by the new job's first
waves, so each pixel gives a pair (old centre, new centre). The preview maps the old
*converged* image through a line fitted per pixel and channel to the pairs of its 3 x 3
neighbourhood (:func:`retinted`, :func:`local_fit`): exact where the change is one factor
across the neighbourhood (the body, the liquid, label text seen through the glass), the
neighbourhood's new mean where the old channel was dark, and it keeps the old render's
anti-aliasing (the fit is applied to the old pixel's mean, not to its centre). Before the
centres are all traced, a pixel takes the line of one of the preview wave's blocks around it,
the one whose old centre looks most like its own (same dominant path, nearest colour): the old
film says which neighbour shares a pixel's path, so the line follows the silhouette instead of
the blocks.

Honesty: the retinted image is a biased estimate, shown and labelled as one (the window's
"retinted preview") and never fed back: the new job renders every wave as a full render
does, its film, rounds and "converged" never see the old one, and the preview frame blends
each pixel to the new film's raw value as the new film's own error falls
(:func:`engine.tracer.denoise.raw_weight`). Memory: two float32 images, a signature and a flag per
pixel (33 bytes a pixel: 22 MB at the window's size), whatever the scene.
:func:`retint_basis` decides once, from the change the scene announced, whether a job can
retint its predecessor's film; edits in a row (a colour picker dragged) chain on the same
basis while the jobs between them are still running.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..color import srgb_encode
from ..model.changes import UNSEEN_FIELDS
from .adaptive import preview_block

#: Design fields a retint may see changed (the absorption of glass and liquid only: the
#: rest of those fields is compared, :func:`colour_only`).
RETINT_FIELDS = frozenset({"glass", "liquid"}) | UNSEEN_FIELDS
#: Radiance below which a centre counts as black when old brightnesses are compared (log
#: radiance), as a fraction of the design's reference level (the environment's mean radiance).
BLACK_LEVEL = 1e-3
#: The local fit's regulariser's scale (:func:`local_fit`), as a fraction of the reference level:
#: old values varying less than this give their neighbourhood's new mean, not a factor.
FIT_SCALE = 1e-2
#: Fewest traced neighbours (of 9) a pixel's own fit needs; below, its preview block's line.
MIN_FIT = 4
#: A retinted pixel's error (display levels), as ``ERROR_FLOOR + ERROR_SLOPE x`` the fit's scatter
#: on the display: calibrated on the edge pixels of the jar and the knurled jar after the benchmark's
#: edit (179 x 238; the scatter predicted 0-1 / 2-4 / 4-8 / 8-16 / over 16 levels, the error was
#: 1.8-2.1 / 5.0-6.0 / 5.9-6.6 / 7.7-8.9 / 17-18 levels RMS); and the error of a pixel that takes
#: its preview block's line. The raw film's own error must fall below it before the preview
#: shows the raw value (:func:`~engine.tracer.denoise.raw_weight`, from the estimate's error to three times it).
ERROR_FLOOR, ERROR_SLOPE, BLOCK_ERROR_LEVELS = 2.5, 0.75, 8.0


@dataclass(frozen=True, eq=False)
class RetintBasis:
    """What a retint keeps of a converged film: its image, its centre samples, their
    dominant paths' signatures and which pixels it anti-aliased (``edges``; all ``(H, W, ...)``
    at the render's size), the preview wave's block edge ``block`` (px) and the design's
    reference ``level`` (the environment's mean radiance)."""

    design: object
    image: np.ndarray
    centre: np.ndarray
    signature: np.ndarray
    edges: np.ndarray
    block: int
    level: float

    @property
    def floor(self) -> float:
        """Radiance that counts as black (:data:`BLACK_LEVEL`)."""
        return BLACK_LEVEL * self.level

    @property
    def eps(self) -> float:
        """The local fit's regulariser, radiance squared (:data:`FIT_SCALE`)."""
        return (FIT_SCALE * self.level) ** 2

    @property
    def nbytes(self) -> int:
        return self.image.nbytes + self.centre.nbytes + self.signature.nbytes + self.edges.nbytes


def _absorption_free(design):
    """``design`` with the glass's and the liquid's absorption set to zero (what a retint
    may not see changed is what remains)."""
    glass = dataclasses.replace(design.glass, absorption=(0.0, 0.0, 0.0))
    liquid = None if design.liquid is None else dataclasses.replace(design.liquid, absorption=(0.0, 0.0, 0.0))
    return glass, liquid


def colour_only(old, new, change) -> bool:
    """Whether designs ``old`` -> ``new`` differ only in the glass's or the liquid's absorption
    (``change``: the :class:`~engine.model.changes.Change` the scene announced between them;
    no asset may have changed)."""
    if "assets" in change or not change.fields <= RETINT_FIELDS:
        return False
    return _absorption_free(old) == _absorption_free(new)


def basis_of_film(design, film, image, level: float) -> RetintBasis:
    """The basis of ``film`` (a finished job's, of ``design``; ``image`` its estimate) whose
    environment has mean radiance ``level``."""
    with film.lock:
        centre = film.centre.astype(np.float32)
        signature = film.signature.copy()
        edges = film.aa_count > 0
    return RetintBasis(design, np.asarray(image, np.float32), centre, signature, edges,
                       preview_block(film.width, film.height), max(float(level), 1e-6))


def retint_basis(previous, design, change):
    """The :class:`RetintBasis` a job of ``design`` may take over from job ``previous``
    (finished at the same size and sampling, or itself a retint still running: its basis),
    ``change`` what changed since; ``None`` when the edit is not colour-only."""
    if not colour_only(previous.design, design, change):
        return None
    if previous.done and previous.error is None and not previous.cancelled:
        if previous.context is None:  # (a kept film without a scene: nothing to compare with)
            return None
        return basis_of_film(previous.design, previous.film, previous.image(), previous.context.reference_level)
    basis = getattr(previous, "retint", None)
    if basis is not None and colour_only(basis.design, design, change):
        return basis  # edits in a row: the last converged film is still the best one known
    return None


def _box3(a) -> np.ndarray:
    """The sum of ``a`` ``(H, W, ...)`` over each cell's 3 x 3 neighbourhood (edges repeated)."""
    pad = [(1, 1), (1, 1)] + [(0, 0)] * (a.ndim - 2)
    p = np.pad(a, pad, mode="edge")
    h, w = a.shape[:2]
    out = np.zeros(a.shape, np.float32)
    for dy in range(3):
        for dx in range(3):
            out += p[dy:dy + h, dx:dx + w]
    return out


def local_fit(old, new, weight, eps: float):
    """Per cell and channel, the line ``new ~ alpha * old + beta`` fitted by least squares over
    the cell's 3 x 3 neighbourhood of ``weight``-ed cells (``old``, ``new`` ``(H, W, 3)``,
    ``weight`` ``(H, W)`` 0/1: the cells that hold both), ``eps`` (radiance squared) pulling
    ``alpha`` toward 0 where the old values hardly vary (a guided filter's regulariser: a dark
    or flat neighbourhood gives its new mean). Returns ``(alpha, beta, count, residual)``, the
    last the mean squared distance of the neighbourhood's new values from the line."""
    w = weight.astype(np.float32)[..., None]
    n = _box3(w)
    m = np.maximum(n, 1.0)
    mo, mn = _box3(w * old) / m, _box3(w * new) / m
    var = np.maximum(_box3(w * old * old) / m - mo * mo, 0.0)
    cov = _box3(w * old * new) / m - mo * mn
    alpha = cov / (var + eps)
    var_new = np.maximum(_box3(w * new * new) / m - mn * mn, 0.0)
    residual = np.maximum(var_new - 2.0 * alpha * cov + alpha * alpha * var, 0.0)
    return alpha, mn - alpha * mo, n[..., 0], residual


#: The 3 x 3 blocks a pixel's line may come from, its own first.
_OFFSETS = np.array([(0, 0), (0, -1), (0, 1), (-1, 0), (-1, -1), (-1, 1), (1, 0), (1, -1), (1, 1)])


def _block_fit(basis, new, has):
    """Each pixel's ``(alpha, beta)`` from one of the 3 x 3 preview blocks around it (module
    rule): each block's line passes through its centre's pair with the slope fitted over the 3 x
    3 blocks' centres, and a pixel takes the line of the block whose old centre has its old
    signature and the nearest old brightness (log of the mean of the channels). (Through the block's own pair rather
    than the fitted one: after the preview wave the jar and the knurled jar at 179 x 238 show
    FLIP 0.032 / 0.039 instead of 0.051 / 0.050; neither is ready then. Brightness alone, not
    the three channels, picks the block: 0.3 levels RMS worse there, a third of the time.)"""
    b, (h, w) = basis.block, has.shape
    ys = np.minimum(np.arange(0, h, b) + b // 2, h - 1)[:, None]
    xs = np.minimum(np.arange(0, w, b) + b // 2, w - 1)[None, :]
    traced = has[ys, xs]
    g_old, g_new = basis.centre[ys, xs], new[ys, xs]
    alpha, _, _, _ = local_fit(g_old, g_new, traced, basis.eps)
    beta = g_new - alpha * g_old  # (the line through the block's own pair: its centre exact)
    g_key = np.log(g_old.mean(axis=2) + basis.floor)
    g_sig = basis.signature[ys, xs]
    p_key = np.log(basis.centre.mean(axis=2) + basis.floor)
    by, bx = np.arange(h) // b, np.arange(w) // b
    best = np.full((h, w), np.inf, np.float32)
    choice = np.zeros((h, w), np.int8)
    for k, (dy, dx) in enumerate(_OFFSETS):
        qy = np.clip(by + dy, 0, len(ys) - 1)[:, None]
        qx = np.clip(bx + dx, 0, xs.shape[1] - 1)[None, :]
        cost = np.abs(g_key[qy, qx] - p_key) + np.where(g_sig[qy, qx] == basis.signature, 0.0, 8.0)
        cost[~traced[qy, qx]] = np.inf
        take = cost < best
        best[take], choice[take] = cost[take], k
    qy = np.clip(by[:, None] + _OFFSETS[choice, 0], 0, len(ys) - 1)
    qx = np.clip(bx[None, :] + _OFFSETS[choice, 1], 0, xs.shape[1] - 1)
    return alpha[qy, qx], beta[qy, qx]


def retinted(basis: RetintBasis, film):
    """``(estimate, error)``: the retinted estimate ``(H, W, 3)`` float32 linear radiance of
    ``film`` (the new job's, as it is now) from ``basis`` (module rule) and its own error
    ``(H, W)`` in display levels, from the fit's scatter (:func:`local_fit`'s residual) as the
    display shows it (:data:`ERROR_FLOOR`, :data:`ERROR_SLOPE`; :data:`BLOCK_ERROR_LEVELS` where
    a pixel takes a preview block's line); ``None`` before any centre is traced.

    Each pixel's new value is ``alpha * old + beta`` of its old converged value, the line
    fitted (:func:`local_fit`) to the pairs (old centre, new centre) of its 3 x 3 neighbourhood:
    where the colour change is a factor it is that factor, where the old channel is dark it is
    the neighbourhood's new mean. Applied to the old *converged* value, it carries over the
    old render's anti-aliasing. Measured on edge pixels after the new centres, at 179 x 238
    with the benchmark's amber edit (display levels RMS; the old image 58 / 51 / 29): the jar
    6.1, the knurled jar 8.2, Bordeaux 2.5, against 16.1 / 18.2 / 10.4 for the centre's ratio
    and 13.7 / 14.3 / 10.2 for the neighbourhood's ratio (a dark channel's ratio is noise); a
    5 x 5 fit is worse (7.5 / 8.3 / 4.0)."""
    with film.lock:
        has = film.has_centre.copy()
        new = np.maximum(film.centre.astype(np.float32), 0.0)
    if not has.any():
        return None
    if np.count_nonzero(has) < has.size // 4:  # the preview wave's blocks alone: their lines
        alpha, beta = _block_fit(basis, new, has)
        return np.maximum(alpha * basis.image + beta, 0.0), np.full(has.shape, BLOCK_ERROR_LEVELS)
    alpha, beta, count, residual = local_fit(basis.centre, new, has, basis.eps)
    few = count < MIN_FIT
    if few.any():  # (where a pixel's neighbours are not traced yet)
        block_a, block_b = _block_fit(basis, new, has)
        alpha, beta = np.where(few[..., None], block_a, alpha), np.where(few[..., None], block_b, beta)
    estimate = np.maximum(alpha * basis.image + beta, 0.0)
    lum, spread = estimate.mean(axis=2), np.sqrt(residual.mean(axis=2))
    error = 127.5 * (srgb_encode(lum + spread) - srgb_encode(np.maximum(lum - spread, 0.0)))
    error = np.where(few, BLOCK_ERROR_LEVELS, ERROR_FLOOR + ERROR_SLOPE * error)
    return estimate, error
