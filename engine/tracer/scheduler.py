"""Waves of pixels cut into tile tasks on worker threads: the loop of an image-tile integrator.

Design rule: the scheduler knows pixels, tiles, how many samples each pixel of a wave asks for
and the worker threads, and nothing of what a sample is (pbrt's ``ImageTileIntegrator``: the
per-ray work is handed in as ``run_batch``). A wave's tiles with work become tasks: tiles with few
samples (a preview's) batched into tasks of at least :data:`MIN_TASK_SAMPLES`, and in a wave of
unequal work (anti-aliasing) a tile holding more than ``1 / (BALANCE x threads)`` of the wave's
samples cut into quarters, heaviest first. Each worker pulls the wave's tasks in order from a
shared counter; the wave ends at a barrier. Which worker traces which pixel never changes an
image: samples are seeded by (pixel, sample).
"""
from __future__ import annotations

import itertools
import random

import numpy as np

#: An anti-aliasing wave is cut into tasks of at most about 1 / (BALANCE x threads) of its
#: samples (:meth:`TileScheduler.balanced`).
BALANCE = 4
#: A task traces at least this many samples (tiles are batched until it does): below it the
#: Python around a tile's kernel call (~50 us) is more than its samples cost (a preview
#: wave's tile holds 4-16 of them).
MIN_TASK_SAMPLES = 512


class TileScheduler:
    """Tiles of ``tile x tile`` pixels of a ``width x height`` image, run on ``threads`` workers.

    ``shuffle_seed`` orders the tiles at random (tests: the image must not depend on it).
    """

    def __init__(self, width: int, height: int, tile: int, threads: int, shuffle_seed=None):
        self.width, self.height, self.tile, self.threads = int(width), int(height), int(tile), int(threads)
        t = self.tile
        self.tiles = [(x, y, min(x + t, self.width), min(y + t, self.height))
                      for y in range(0, self.height, t) for x in range(0, self.width, t)]
        if shuffle_seed is not None:
            random.Random(shuffle_seed).shuffle(self.tiles)

    def tasks(self, work: np.ndarray, balance: bool) -> list:
        """The wave's tasks (lists of tiles) for ``work``, the samples each pixel asks for ``(H,
        W)``: tiles without work dropped, heavy ones split when ``balance``, light ones batched."""
        t = self.tile
        # samples per tile in one pass over the image, not one per tile
        per_tile = np.add.reduceat(np.add.reduceat(work, np.arange(0, self.height, t), 0),
                                   np.arange(0, self.width, t), 1)
        weighted = [(tl, int(per_tile[tl[1] // t, tl[0] // t])) for tl in self.tiles]
        weighted = [(tl, w) for tl, w in weighted if w > 0]
        if balance:
            weighted = self.balanced(weighted, work)
        return batches([tl for tl, _ in weighted], [w for _, w in weighted])

    def balanced(self, weighted, work):
        """``(tile, samples)`` of the busy tiles ``weighted``, one holding more than ``1 / (BALANCE
        x threads)`` of the wave's samples cut into quarters (down to 8 px), heaviest first
        (longest-processing-time order). Such a wave's samples crowd into a few tiles, and the
        wave ends at a barrier: one worker's last big tile would keep the others idle."""
        share = float(sum(w for _, w in weighted)) / (BALANCE * self.threads)
        out, stack = [], list(weighted)
        while stack:
            (x0, y0, x1, y1), w = stack.pop()
            if w == 0:
                continue
            if w > share and x1 - x0 > 8 and y1 - y0 > 8:
                xm, ym = (x0 + x1) // 2, (y0 + y1) // 2
                for q in ((x0, y0, xm, ym), (xm, y0, x1, ym), (x0, ym, xm, y1), (xm, ym, x1, y1)):
                    stack.append((q, int(work[q[1]:q[3], q[0]:q[2]].sum())))
            else:
                out.append((-w, (x0, y0, x1, y1)))
        return [(tl, -w) for w, tl in sorted(out)]

    def run(self, pool, tasks: list, mask: np.ndarray, run_batch, cancelled, cancel) -> None:
        """Run ``run_batch(parts)`` for every task on the pool's workers, ``parts`` the task's
        tiles with pixels in ``mask`` as ``((x0, y0, x1, y1), rows, cols)``; returns when all
        are done. One pulling loop per worker over the ordered tasks, not one future per tile (a
        wave of small tiles spent its first milliseconds submitting them, holding the GIL that a
        starting worker needs). ``cancelled()`` is polled between tasks; a failing task calls
        ``cancel()`` (the others stop at their next task or pixel) and its exception is raised
        here."""
        order = itertools.count()  # (its next() is atomic under the GIL)

        def parts_of(batch):
            parts = []
            for x0, y0, x1, y1 in batch:
                ys, xs = np.nonzero(mask[y0:y1, x0:x1])
                if len(xs):
                    parts.append(((x0, y0, x1, y1), ys + y0, xs + x0))
            return parts

        def pull():
            try:
                while not cancelled():
                    i = next(order)
                    if i >= len(tasks):
                        return
                    parts = parts_of(tasks[i])
                    if parts and not cancelled():
                        run_batch(parts)
            except BaseException:
                cancel()  # the other workers stop at their next task
                raise

        futures = [pool.submit(pull) for _ in range(min(self.threads, len(tasks)))]
        first_error = None
        for f in futures:
            exc = f.exception()
            if exc is not None and first_error is None:
                first_error = exc
                cancel()
        if first_error is not None:
            raise first_error


def batches(tiles, samples) -> list:
    """Consecutive ``tiles`` (``(x0, y0, x1, y1)``, holding ``samples[i]`` samples each) grouped
    into lists of at least :data:`MIN_TASK_SAMPLES` samples (the last may hold less); order
    kept, so a wave's heaviest tiles still go first."""
    out, batch, total = [], [], 0
    for tl, n in zip(tiles, samples):
        batch.append(tl)
        total += n
        if total >= MIN_TASK_SAMPLES:
            out.append(batch)
            batch, total = [], 0
    if batch:
        out.append(batch)
    return out
