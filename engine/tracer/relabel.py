"""Relabel: a label edit re-traces only the pixels whose ray trees met what changed.

Design rule: when only labels, lights (without a closure: they light its diffuse parts too) or
label images changed (every other field of the design and the environment the same, the same
size and sampling), a job keeps the previous job's compiled scene (a label edit never rebuilds
geometry, media or environment: :meth:`~engine.tracer.context.RenderContext.with_labels`) and
replays the same waves: a pixel's traced samples are reused from the previous job's per-wave
record when the pixel is clean and the wave asks it for the same samples, and traced again
otherwise. A pixel is dirty when its ray trees (any sample, shadow rays included) consulted a
label whose artwork, finish or coefficients changed (the label bits of the object mask,
:mod:`engine.tracer.kernels.labels`), any label when lights changed, and every pixel whose trees
met the object a label lies on (the outer wall, or a closure part for a print on the cap) before
or after it moved, was added, removed or reordered (the new footprint may cover it). A label
whose edit changes its face colours only (artwork of the same size with the same alpha channel
and region map, everything else equal) leaves every ray tree as it was: its pixels are not
traced but their label terms recomputed from the recorded hits
(:func:`engine.tracer.kernels.labels.replay_samples`). Since samples are seeded by (pixel,
sample) and the film is the same function of the traced results, the image equals a full render
of the new design bit for bit.

:class:`LabelRecorder` keeps, per wave, each pixel's sums and each sample's label hits, only for
designs with labels and at most :data:`MAX_RECORDED_SAMPLES` samples a job, so memory follows the
labels' pixels. :func:`plan_relabel` decides once, from the change the scene announced, whether a
job can relabel its predecessor and which pixels it must trace again.
"""
from __future__ import annotations

import dataclasses
import threading
from dataclasses import dataclass

import numpy as np

from ..appearance.frame import Placement
from ..model.changes import UNSEEN_FIELDS
from ..model.design import LabelSide
from .context import PixelResult
from .kernels.integrator import N_COUNTERS
from .kernels.labels import H_COLS, L_FRONT_TEX, L_REGION_MAP, LABEL_BIT0, MAX_LABEL_BIT, P_OBJECT, replay_samples
from .tables.labels import with_buffers

#: Samples whose label hits one job keeps for relabels (~40 bytes each, plus their hits); the
#: pixels beyond are traced again by a relabel instead of recomputed.
MAX_RECORDED_SAMPLES = 1 << 21
#: Object-mask bits of all labels (engine.tracer.kernels.labels).
_ALL_LABEL_BITS = np.int64(sum(1 << b for b in range(LABEL_BIT0, MAX_LABEL_BIT + 1)))
_NO_SAMPLES = (np.zeros((0, 3)), np.zeros((0, 2), np.int64), np.zeros((0, H_COLS)), np.zeros((0, 2), np.int64))
#: Fields a relabel may see changed; any other visible change means a full render.
RELABEL_FIELDS = frozenset({"labels", "lights", "assets"}) | UNSEEN_FIELDS


@dataclass
class WaveRecord:
    """The traced results of one wave, by pixel index ``row * width + col`` (sorted), and the
    label terms of their samples: pixel ``i``'s samples are ``smp_*[s0[i] : s0[i] + count[i]]``
    (``s0 = -1``: not recorded, the pixel can only be traced again; ``-2``: its samples had no
    label hits, its result does not depend on label colours)."""

    pix: np.ndarray
    first: np.ndarray
    count: np.ndarray
    sums: np.ndarray
    sumsq: np.ndarray
    signature: np.ndarray
    objects: np.ndarray
    depth: np.ndarray
    s0: np.ndarray
    smp_f: np.ndarray = None
    smp_i: np.ndarray = None
    hit_f: np.ndarray = None
    hit_i: np.ndarray = None

    PER_PIXEL = ("pix", "first", "count", "sums", "sumsq", "signature", "objects", "depth", "s0")

    @classmethod
    def join(cls, chunks) -> "WaveRecord":
        if len(chunks) == 1 and (len(chunks[0].pix) < 2 or bool(np.all(np.diff(chunks[0].pix) > 0))):
            return chunks[0]  # a relabel that kept the whole wave: already a record
        s_off = h_off = 0
        s0, smp_f, smp_i, hit_f, hit_i = [], [], [], [], []
        for c in chunks:
            s0.append(np.where(c.s0 >= 0, c.s0 + s_off, c.s0))
            smp_f.append(c.smp_f)
            smp_i.append(c.smp_i + h_off)
            hit_f.append(c.hit_f)
            hit_i.append(c.hit_i)
            s_off += len(c.smp_f)
            h_off += len(c.hit_f)
        parts = {f: np.concatenate([getattr(c, f) for c in chunks]) for f in cls.PER_PIXEL[:-1]}
        parts["s0"] = np.concatenate(s0)
        order = np.argsort(parts["pix"], kind="stable")
        return cls(**{f: a[order] for f, a in parts.items()}, smp_f=np.concatenate(smp_f),
                   smp_i=np.concatenate(smp_i), hit_f=np.concatenate(hit_f), hit_i=np.concatenate(hit_i))

    def subset(self, idx, sums=None, sumsq=None) -> "WaveRecord":
        """Pixels ``idx`` (their samples' arrays shared), optionally with new sums."""
        out = {f: getattr(self, f)[idx] for f in self.PER_PIXEL}
        if sums is not None:
            out["sums"], out["sumsq"] = sums, sumsq
        return WaveRecord(**out, smp_f=self.smp_f, smp_i=self.smp_i, hit_f=self.hit_f, hit_i=self.hit_i)

    def result(self) -> PixelResult:
        return PixelResult(self.sums, self.sumsq, self.signature, self.objects, self.depth,
                           np.zeros(N_COUNTERS, np.int64), len(self.pix))


class LabelRecorder:
    """The per-wave records of one job of ``width`` pixels a row (thread-safe)."""

    def __init__(self, width: int):
        self.width = int(width)
        self.waves = {}
        self._chunks = []
        self._recorded = 0
        self._lock = threading.Lock()

    def add(self, chunk: WaveRecord) -> None:
        """A chunk of the current wave (traced or replayed)."""
        with self._lock:
            self._chunks.append(chunk)

    def end_wave(self, wave: int) -> None:
        """The current wave's chunks become its record."""
        if self._chunks:
            self.waves[wave] = WaveRecord.join(self._chunks)
        self._chunks = []

    def record(self, rows, cols, first, count, res) -> WaveRecord:
        """A traced chunk's record. Only samples of pixels with label hits are kept (``s0 = -2``:
        none, the pixel's result does not depend on label colours; ``-1``: not recorded), and at
        most :data:`MAX_RECORDED_SAMPLES` a job."""
        n = len(cols)
        count = np.broadcast_to(np.asarray(count, np.int64), (n,)).copy()
        s0 = np.full(n, -1, np.int64)
        smp_f, smp_i, hit_f, hit_i = _NO_SAMPLES
        if res.label_record is not None and n:
            smp_f, smp_i, hit_f, hit_i = res.label_record
            starts = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int64)
            hits = np.add.reduceat(smp_i[:, 1] - smp_i[:, 0], starts)
            keep = hits > 0
            kept = int(count[keep].sum())
            with self._lock:
                room = self._recorded + kept <= MAX_RECORDED_SAMPLES
                if room:
                    self._recorded += kept
            if room:
                take = np.repeat(keep, count)
                smp_f, smp_i = smp_f[take], smp_i[take]
                s0 = np.where(keep, np.concatenate([[0], np.cumsum(np.where(keep, count, 0))[:-1]]), -2)
            else:
                s0 = np.where(keep, -1, -2)
                smp_f, smp_i, hit_f, hit_i = _NO_SAMPLES
        return WaveRecord(rows * self.width + cols, np.asarray(first, np.int64), count, res.sums, res.sumsq,
                          res.signature, res.objects, res.depth, s0.astype(np.int64), smp_f, smp_i, hit_f, hit_i)


@dataclass(frozen=True, eq=False)
class RelabelPlan:
    """How a job relabels its predecessor: the predecessor's context with the new labels, the
    ``(H, W)`` masks of pixels to trace again and of pixels whose label terms only are
    recomputed, and the predecessor's records."""

    context: object
    trace: np.ndarray
    recolour: np.ndarray
    records: LabelRecorder


def _label_bit(k: int) -> np.int64:
    return np.int64(1 << min(LABEL_BIT0 + k, MAX_LABEL_BIT))


def _object_bit(labels, k: int) -> np.int64:
    """The object-mask bit of the render object label ``k`` of the tables ``labels`` lies on."""
    return np.int64(1 << int(labels.place[k, P_OBJECT]))


def _placed(label) -> tuple:
    """What fixes where a label lies: its surface and the numbers that place it there."""
    return Placement.of(label), label.surface, label.cap_x_mm, label.cap_y_mm


def _same_asset(a, b) -> bool:
    return a is b or (a is not None and a == b)


def _colour_only(a, b, k, old_assets, new_assets, old_t, new_t) -> bool:
    """Whether label ``k`` changed from ``a`` to ``b`` in its face colours only (artwork of
    the same size with the same alpha, region maps equal, everything else equal): then every ray
    tree is the same and only the label terms change."""
    blank = LabelSide()
    if dataclasses.replace(a, front=blank, back=blank) != dataclasses.replace(b, front=blank, back=blank):
        return False
    for r in a.regions:
        if r.mask_asset is not None and not _same_asset(old_assets.get(r.mask_asset), new_assets.get(r.mask_asset)):
            return False

    def alpha(t):
        m = int(t.f[k, L_FRONT_TEX])
        if m < 0:
            return None
        first, w, h = t.tex_i[m]
        return (int(w), int(h)), t.texels[first:first + w * h, 3]

    def codes(t):
        q = int(t.f[k, L_REGION_MAP])
        if q < 0:
            return None
        first, w, h = t.region_i[q]
        return (int(w), int(h)), t.codes[first:first + w * h]

    for f in (alpha, codes):  # a plain front (no alpha) only matches a plain front
        x, y = f(old_t), f(new_t)
        if (x is None) != (y is None):
            return False
        if x is not None and (x[0] != y[0] or not np.array_equal(x[1], y[1])):
            return False
    return True


def plan_relabel(previous, design, assets, change) -> RelabelPlan | None:
    """The :class:`RelabelPlan` of a job rendering ``design`` with ``assets`` after the finished
    job ``previous`` (same size and sampling, checked by the caller), ``change`` the fields and
    assets that changed since (:class:`engine.model.changes.Change`); ``None`` when it cannot
    relabel (module rule)."""
    old_design = previous.design
    if (previous.records is None or previous.context is None or not design.labels
            or not change.fields <= RELABEL_FIELDS
            or (old_design.lights != design.lights and design.cap is not None)):
        return None  # (lights shade a closure's diffuse parts too: those pixels are not recorded)
    if design.environment.asset is not None and design.environment.asset in change.assets:
        return None
    old_assets, new_assets = previous.assets or {}, assets or {}
    ctx = previous.context.with_labels(design, assets)
    old, new = old_design.labels, design.labels
    old_t, new_t = previous.context.labels, ctx.labels
    bits = colour_bits = np.int64(0)
    if old_design.lights != design.lights:
        bits |= _ALL_LABEL_BITS
    if len(old) != len(new):
        bits |= old_t.objects[0] | new_t.objects[0] | _ALL_LABEL_BITS
    else:
        for k, (a, b) in enumerate(zip(old, new)):
            if a == b and all(n not in change.assets for n in a.asset_names()):
                continue
            if _placed(a) != _placed(b):
                bits |= _object_bit(old_t, k) | _object_bit(new_t, k) | _label_bit(k)
            elif _colour_only(a, b, k, old_assets, new_assets, old_t, new_t):
                colour_bits |= _label_bit(k)
            else:
                bits |= _label_bit(k)
    objects = previous.film.objects
    trace = (objects & bits) != 0
    return RelabelPlan(ctx, trace, ((objects & colour_bits) != 0) & ~trace, previous.records)


def replay(plan: RelabelPlan, film, wave: int, mask, want, width: int, recorder: LabelRecorder):
    """Put the previous job's results of ``wave`` into ``film`` for the pixels of ``mask`` it
    traced with the same samples, as they were (clean pixels) or with their label terms
    recomputed for the new colours (module rule); ``want`` the samples each pixel asks for
    (``None``: the centres). Returns ``(mask of pixels left to trace, cols, rows, result)`` of
    what was put in (``cols`` empty when nothing was)."""
    rec = plan.records.waves.get(wave)
    ys, xs = np.nonzero(mask & ~plan.trace)
    if rec is None or not len(xs):
        return mask, xs[:0], ys[:0], None
    pix = ys * width + xs
    idx = np.minimum(np.searchsorted(rec.pix, pix), len(rec.pix) - 1)
    if want is None:
        first, count = np.zeros(len(xs), np.int64), np.ones(len(xs), np.int64)
    else:
        have = film.aa_count[ys, xs]
        first, count = have + 1, want[ys, xs] - have
    same = (rec.pix[idx] == pix) & (rec.first[idx] == first) & (rec.count[idx] == count)
    same &= ~plan.recolour[ys, xs] | (rec.s0[idx] != -1)  # -2: no label terms to recompute
    idx, rows, cols = idx[same], ys[same], xs[same]
    # every row of the record kept (idx is then 0, 1, ...: both are in pixel order): share
    # its arrays instead of copying them
    part = rec if len(idx) == len(rec.pix) else rec.subset(idx)
    again = np.nonzero(plan.recolour[rows, cols] & (part.s0 >= 0))[0]
    if len(again):
        sums, sumsq = part.sums.copy(), part.sumsq.copy()
        out_s, out_q = np.zeros((len(again), 3)), np.zeros(len(again))
        replay_samples(with_buffers(plan.context.labels), part.s0[again], part.count[again], rec.smp_f, rec.smp_i,
                       rec.hit_f, rec.hit_i, out_s, out_q)
        sums[again], sumsq[again] = out_s, out_q
        part = dataclasses.replace(part, sums=sums, sumsq=sumsq)
    res = part.result()
    if want is None:
        film.add_centre(cols, rows, res)
    else:
        film.add_aa(cols, rows, part.count, res)
    recorder.add(part)
    left = mask.copy()
    left[rows, cols] = False
    return left, cols, rows, res
