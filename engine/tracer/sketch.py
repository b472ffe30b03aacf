"""The sketch: display-only samples that make the window's first full frame readable.

Design rule: a render's film starts with one sample at each pixel's centre, which is exact on
smooth glass but aliased wherever a pixel holds an edge, and a denoiser cannot undo aliasing
(it removes noise). On heavy designs (thick glass, relief) that centre wave also takes seconds,
a whole Fresnel tree per pixel. So before the centres a window render traces the *sketch*: a
few samples at stratified positions in every pixel, each a cheap path rather than a tree
(branches lighter than :data:`SKETCH_ROULETTE` play Russian roulette: unbiased), from a part of
each pixel's sample sequence the film never uses (:data:`SKETCH_BASE`). Their noise is what
the guided denoiser removes well. The sketch never enters the film: the adaptive rounds, a
relabel's records, "converged" and the raw image never see it. Only the preview pools it
(:meth:`Sketch.pooled`): where the film has anti-aliasing samples the sketch's join them
(both are unbiased estimates of the same pixel), where it holds a centre that the rounds will
refine the centre counts as one sample more, a smooth pixel keeps its centre.

Measured at the window's 715 x 953 on 2 threads (each pass's image denoised by OIDN with its
guides, against each sample's converged window image, display levels RMS / mean FLIP): 4
samples at roulette 0.2 cost about one centre wave and give the frosted logo 2.04 / 0.019 in
1.5 s (its centres, denoised: 3.1 / 0.015 after 2.1 s), the threaded bottle 2.14 / 0.017 in
1.9 s, the square 3.31 / 0.022 in 2.7 s, the knurled jar 5.44 / 0.040 in 5.3 s (its centres:
7.1 / 0.035 after 5.8 s). Pure paths (roulette 1) were cheaper and worse for the same time
(the square 4.44 / 0.029 in 1.8 s at 4 samples), whole trees at one sample dearer for the same
error (the knurled jar 6.86 / 0.041 in 5.2 s).
"""
from __future__ import annotations

import threading

import numpy as np

from .film import guide_images

#: Where the sketch's samples start in each pixel's sequence: far beyond the film's (at most
#: ``SPLIT_FACTOR x spp``) and the benchmarks' independent references (``1 << 20``, ``2 << 20``),
#: aligned to a power of two so its first samples form a scrambled net over the pixel.
SKETCH_BASE = 1 << 24
#: Branches lighter than this play Russian roulette in the sketch (a sample then costs about
#: a path through the glass instead of its whole tree; module doc for the measurements).
SKETCH_ROULETTE = 0.2
#: Samples per pixel after each pass of the sketch: one for the first full frame, then the
#: rest of a 2 x 2 net.
SKETCH_PASSES = (1, 4)
#: Seconds the sketch's passes may take in all: a pass after the first runs only if, at the
#: pace of the one before, the sketch stays within this. Every second of the sketch delays the
#: film's own waves. Measured at the window's size with both passes everywhere
#: (``benchmarks.window_converge``, first image / ready / converged against the run before
#: the sketch): the frosted logo ready 2.5 s (5.0) and the threaded bottle 2.9 s (6.6), both
#: from the second pass's frame (first passes 0.4-0.5 s); the hip flask 9.4 s (18.0) and the
#: jar 12.4 s (14.9), from the film's first waves pooled with the sketch; but the square 16.5 s
#: (13.0), the cut decanter 56.7 s (52.1), the flacon 69.2 s (61.4) and the knurled jar 88.7 s
#: (81.1), whose "ready" a later wave decides, each delayed by the second pass's whole cost
#: (2-5 s). With this budget the frosted logo and the threaded bottle keep both passes (ready
#: 2.6 and 2.9 s), the heavier designs one (0.7-1.8 s; ready within the machine's noise of the
#: run before the sketch, the hip flask 12.9 s). A display-only choice: that it depends on the
#: machine's pace changes no pixel of the image.
SKETCH_BUDGET_S = 2.2


def next_pass_fits(spent: float, last_seconds: float, last_samples: int, samples: int) -> bool:
    """Whether a pass of ``samples`` more samples per pixel keeps the sketch within
    :data:`SKETCH_BUDGET_S`, ``spent`` seconds so far, the last pass having taken
    ``last_seconds`` for ``last_samples`` (its pace per sample, the same for the next)."""
    return spent + last_seconds * samples / max(last_samples, 1) <= SKETCH_BUDGET_S
#: A render sketches only where its block preview's trees took at least this many rays per
#: pixel (intersection queries; at the window's 715 x 953 on 2 threads, its centre wave's
#: seconds in brackets): the Bordeaux 4.4 (0.65 s) and the labelled bottle 3.8 (0.8 s) trace
#: their centres first; the frosted logo 5.5 (1.0 s), the threaded bottle 8.5 (1.75 s), the jar
#: 17.8 (2.5 s), the knurled jar 27 (5.3 s) sketch. Rays, not seconds: the preview's few pixels
#: take too little time to time (its batches' fixed costs were 20x its tracing on the
#: Bordeaux), and a choice that is a function of the design does not change with the load.
SKETCH_RAYS = 5.0


class Sketch:
    """The sketch's per-pixel sums of one render: radiance ``(H, W, 3)``, samples ``(H, W)``
    and the denoiser's guides ``(H, W, 6)`` (albedo and normal, summed over samples, as the
    film keeps them). Changed only under its lock."""

    def __init__(self, width: int, height: int):
        h, w = int(height), int(width)
        self.lock = threading.Lock()
        self.sums = np.zeros((h, w, 3))
        self.n = np.zeros((h, w), np.int64)
        self.guide = np.zeros((h, w, 6))

    def add(self, cols, rows, count, result) -> None:
        """Add ``count`` samples (an int or one per pixel) of distinct pixels ``(cols[p],
        rows[p])`` from a :class:`~engine.tracer.context.PixelResult`."""
        rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
        with self.lock:
            self.sums[rows, cols] += result.sums
            self.n[rows, cols] += count
            if result.guide is not None:
                self.guide[rows, cols] += result.guide

    @property
    def samples(self) -> int:
        """The fewest sketch samples any pixel has (0 before the first pass ends)."""
        with self.lock:
            return int(self.n.min()) if self.n.size else 0

    def pooled(self, film, sampled=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(colour, albedo, normal)``, float32 ``(H, W, 3)`` each: what the preview's denoiser
        reads, the film's samples and the sketch's pooled per pixel (module doc). ``sampled``
        (``(H, W)`` bool or ``None``): the pixels the rounds will anti-alias (the job's
        :meth:`~engine.tracer.job.RenderJob.aa_pixels`, once every centre is traced); a pixel
        outside it with a centre keeps its centre. A pixel with neither samples nor a centre
        shows the block preview."""
        with self.lock:
            s_sum, s_n, s_guide = self.sums.copy(), self.n.copy(), self.guide.copy()
        with film.lock:
            centre, has_centre = film.centre.copy(), film.has_centre.copy()
            aa_sum, aa_n = film.aa_sum.copy(), film.aa_count.copy()
            preview = film.preview.copy()
            g_sum, g_n = film.guide_sum.copy(), film.guide_n.copy()
        centre_only = has_centre & (aa_n == 0)
        # a smooth pixel keeps its centre; before every centre is traced none is known smooth
        smooth = centre_only & ~sampled if sampled is not None else np.zeros_like(centre_only)
        probe = centre_only & ~smooth  # (its centre counts as one sample of a pixel to refine)
        total = s_sum + aa_sum + np.where(probe[..., None], centre, 0.0)
        count = (s_n + aa_n + probe).astype(np.float64)
        colour = np.where(count[..., None] > 0, total / np.maximum(count, 1.0)[..., None], preview)
        colour = np.where(smooth[..., None], centre, colour)
        colour = np.nan_to_num(colour, nan=0.0, posinf=0.0, neginf=0.0)
        return (np.clip(colour, 0.0, 3.4e38).astype(np.float32), *guide_images(g_sum + s_guide, g_n + s_n))
