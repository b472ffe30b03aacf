"""How long the window's preview takes to converge on every bundled sample, and whether it is honest.

Usage::

    python -m benchmarks.window_converge [--samples bordeaux,jar] [--width 715 --height 953]
                                         [--threads 2] [--check-scale 0.167] [--no-check]

Each ``resources/*.glassbench`` is rendered as the window renders it (:class:`RenderJob` at the
window's default pane size, 715 x 953, with the window's noise criterion,
:data:`app.engine_bridge.WINDOW_NOISE`, on ``--threads`` workers): seconds to converge, rays
(intersection queries) and rays per pixel. "Converged" must be honest: at ``--check-scale`` of
that size each sample's converged image is compared, in display levels (0..255 after the tone
map), with a reference of the same design rendered with a noise target of half a display level
and 4 x the samples, drawn from another part of each pixel's sample sequence
(``RenderJob(_bench=BenchHooks(sample_base=...))``: a reference that shared the render's first
samples would agree with it where both stopped at the same count, whatever their error). A design on a diffuse
ground builds its grids (the sky's and the lights' caustics, :mod:`engine.tracer.tables.sky`)
within the time, as the window's first render of it does. The RMS and the 99th percentile of
the difference are printed (targets 1.5 and 10 levels), with the reference's own noise (the RMS
of its difference from a second independent reference, over sqrt 2), which the difference
includes, and the render's own error (the two in quadrature's difference). At the window's own
size (where a smooth pixel keeps its noiseless centre, so the error is the anti-aliased pixels'),
a second render on independent samples gives the render's own error there
(:func:`own_error`: RMS and 99th percentile, against the same targets), and that render's image
after each wave gives the error a designer sees on the way (:func:`progress_errors`): the first
time it is within 3 and within 1.5 levels RMS is printed per sample, the curves are the chart's
third panel and ``window_progress.csv``. The split policy's
per-pixel tolerance (levels), which it widens while its estimate of the image's error allows
(:func:`engine.tracer.adaptive.split_tolerance`), is printed with each sample. Writes
``benchmarks/out/window_converge.csv`` and ``window_converge.png`` (seconds and rays per pixel
per sample against the targets) and prints last
``window_converge_worst=S window_converge_median=M`` (seconds over the samples; targets: worst
<= 15 s, median <= 5 s on 2 cores). A render still running after ``--limit`` seconds
(:data:`LIMIT_S`) is cancelled and its sample reported not converged: it counts as ``inf`` in
the figure line, so the benchmark ends on every sample and says which did not converge.
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import glob
import os
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
#: The window's default preview pane in device pixels (a 1600 x 1000 screen, the default layout).
WINDOW_SIZE = (715, 953)
#: The honesty check's reference: noise target in display units, sample factor.
REFERENCE_NOISE = 0.5 / 255.0
REFERENCE_SPP_FACTOR = 4
#: Where the references' anti-aliasing samples start in each pixel's sequence (the render's at 1).
REFERENCE_BASES = (1 << 20, 2 << 20)
TARGET_WORST_S, TARGET_MEDIAN_S = 15.0, 5.0
TARGET_RMS_LEVELS, TARGET_P99_LEVELS = 1.5, 10.0
#: Errors (display levels RMS at the window's size) whose first time the benchmark reports: what
#: a designer sees while the preview refines (3: a coarse grain; 1.5: the honesty target).
PROGRESS_BOUNDS = (3.0, 1.5)
#: "Ready" (issue 42): the denoised preview within this many display levels RMS and this mean
#: FLIP of the converged image; the window's denoiser quality.
READY_LEVELS, READY_FLIP = 3.0, 0.02
#: Bytes a colour-only edit would need per leaf of the ray trees to re-weigh them without tracing
#: (RGB weight and the lengths in glass and liquid, float32): issue 42's item 4.
KEPT_LEAF_BYTES = 20


def samples(names=None) -> list[str]:
    """Paths of the bundled samples (all, or those ``names``)."""
    paths = sorted(glob.glob(os.path.join(REPO, "resources", "*.glassbench")))
    if names:
        want = set(names)
        paths = [p for p in paths if os.path.basename(p)[:-len(".glassbench")] in want]
    return paths


#: Wall seconds one render may take before it is cancelled (``--limit``): the benchmark ends on
#: every sample, and a sample that does not converge in time is reported as such.
LIMIT_S = 900.0


class NotConverged(Exception):
    """A render of the benchmark did not converge within its limit (seconds) and was cancelled."""

    def __init__(self, seconds: float, size: str = ""):
        super().__init__(f"{size} render not converged within {seconds:.0f} s".lstrip())
        self.seconds, self.size = seconds, size


def set_limit(seconds: float) -> None:
    """Set :data:`LIMIT_S` (``--limit``)."""
    global LIMIT_S
    LIMIT_S = float(seconds)


def _watch(job, wave):
    """An observer of every wave, as the window's (a watched render traces its sketch)."""


def _watched():
    """Observers of a render timed as the window renders: its waves watched."""
    from engine.tracer.job_options import JobObservers
    return JobObservers(on_wave=_watch)


def window_sampling(**changes):
    """The window's sampling (:data:`app.engine_bridge.WINDOW_NOISE`) with ``changes`` (fields of
    :class:`engine.tracer.sampling.Sampling`: another policy, target, ...)."""
    from app.engine_bridge import WINDOW_NOISE

    return dataclasses.replace(WINDOW_NOISE, **changes)


def render(design, assets, width, height, threads, sampling=None, **kw):
    """``(job, wall seconds)`` of one render at ``sampling`` (``None``: the window's), ``kw``
    the job's other options; raises :class:`NotConverged` (the job cancelled) past
    :data:`LIMIT_S`."""
    from engine.tracer.job import RenderJob

    t0 = time.perf_counter()
    job = RenderJob(design, assets, width=width, height=height, threads=threads,
                    sampling=window_sampling() if sampling is None else sampling, **kw).start()
    if not job.wait(LIMIT_S):
        job.cancel()
        job.wait()
        raise NotConverged(LIMIT_S, f"{width}x{height}")
    if job.error is not None:
        raise job.error
    return job, time.perf_counter() - t0


def levels(image) -> np.ndarray:
    """Display levels (float, 0..255) of a linear image: the window's tone map before rounding."""
    from engine.color import srgb_encode

    return srgb_encode(image) * 255.0


def reference(design, assets, width, height, threads, base=REFERENCE_BASES[0]) -> np.ndarray:
    """The honesty check's reference image (module doc): the classic policy (each pixel's own
    sample scatter, which assumes nothing of stratification) with a noise target of half a
    display level and 4 x the samples, its anti-aliasing samples from sample ``base`` of each
    pixel's sequence on."""
    from engine.tracer.job_options import BenchHooks

    classic = window_sampling(noise_target=REFERENCE_NOISE, policy="classic")
    ref, _ = render(design, assets, width, height, threads, classic, spp=REFERENCE_SPP_FACTOR * design.render.spp,
                    _bench=BenchHooks(sample_base=base))
    return ref.image()


def reference_noise(design, assets, width, height, threads, ref) -> float:
    """The display levels RMS of the reference ``ref``'s own error: its difference from a second
    reference on other samples (:data:`REFERENCE_BASES`), over sqrt 2."""
    other = reference(design, assets, width, height, threads, base=REFERENCE_BASES[1])
    return distance(ref, other, scale=1.0 / np.sqrt(2.0))[0]


def honesty(design, assets, width, height, threads, ref, policy) -> tuple[float, float]:
    """``(RMS, 99th percentile)`` in display levels of a converged render by ``policy`` against
    the reference image ``ref`` (module doc), at ``width x height``."""
    job, _ = render(design, assets, width, height, threads, window_sampling(policy=policy))
    return distance(job.image(), ref)


def distance(image, other, scale: float = 1.0) -> tuple[float, float]:
    """``(RMS, 99th percentile)`` in display levels of ``scale x`` the difference of two linear
    images once tone-mapped."""
    diff = np.abs(levels(image) - levels(other)) * scale
    return float(np.sqrt(np.mean(diff ** 2))), float(np.percentile(diff, 99))


def own_error(design, assets, width, height, threads, image, policy) -> tuple[float, float, list]:
    """``(RMS, 99th percentile, progress)`` in display levels of the error of ``image`` (a
    converged render by ``policy`` at ``width x height``, the window's size) estimated from a
    second render on independent samples (``BenchHooks.sample_base``): their difference over
    sqrt 2. The check at the window's own size, where smooth pixels keep their noiseless
    centre: the reference check runs at a fraction of it, where nearly every pixel of a relief
    sample is an edge. Both renders are unbiased estimates of the same pixel integrals (the same tree cut),
    so this is their distance from a noiseless reference at that size.

    ``progress``: what a designer sees while waiting, ``[(seconds, levels RMS), ...]`` after
    each wave of the second render (:func:`progress_errors`)."""
    from engine.tracer.job_options import BenchHooks, JobObservers
    from engine.tracer.tables.stage import clear_stage_caches

    seen = []  # (seconds from the start less the measuring so far, levels RMS from image)
    clock = {"start": 0.0, "spent": 0.0}

    def snapshot(job, wave):  # (on the job's thread between waves: the job waits for it)
        t = time.perf_counter()
        seen.append((t - clock["start"] - clock["spent"], distance(job.image(), image)[0]))
        clock["spent"] += time.perf_counter() - t

    clear_stage_caches()  # (its time, as the first render's, includes the ground's grids: the same grids)
    clock["start"] = time.perf_counter()
    other, _ = render(design, assets, width, height, threads, window_sampling(policy=policy),
                      _bench=BenchHooks(sample_base=REFERENCE_BASES[0]), observers=JobObservers(on_wave=snapshot))
    rms, p99 = distance(image, other.image(), scale=1.0 / np.sqrt(2.0))
    return rms, p99, progress_errors(seen, rms)


def flip_mean(image, other) -> float:
    """NVIDIA FLIP's mean error (``flip-evaluator``) between two linear images as displayed:
    both tone-mapped by the window's encoding and compared as sRGB (LDR)."""
    import flip_evaluator

    a = np.clip(levels(other) / 255.0, 0.0, 1.0).astype(np.float32)
    b = np.clip(levels(image) / 255.0, 0.0, 1.0).astype(np.float32)
    return float(flip_evaluator.evaluate(a, b, "LDR", applyMagma=False)[1])


_DENOISERS: dict = {}


def _warm_denoiser(width, height):
    """The window's preview denoiser, made once per run and warmed on a frame of the size: OIDN
    loads its library and builds its filter for a size once, as the window does at its first
    denoised frame."""
    from engine.tracer.denoise import Denoiser

    if (width, height) not in _DENOISERS:
        den = Denoiser()
        den(np.full((height, width, 3), 0.5, np.float32), np.full((height, width, 3), 0.5, np.float32),
            np.zeros((height, width, 3), np.float32))
        _DENOISERS[(width, height)] = den
    return _DENOISERS[(width, height)]


def denoised_progress(design, assets, width, height, threads, policy, converged) -> dict:
    """What the window shows on the way to ``converged`` (its converged image at ``width x
    height``), from a second render as the window runs it: the denoiser (one thread, the
    window's quality) on a thread of its own beside the workers, asked for each wave's film from
    wave 1 (the first at full resolution) and skipping frames it cannot keep up with.

    Returns ``{"first_s", "converged_s", "frames": [(seconds shown, wave, levels RMS, mean FLIP,
    raw levels RMS, raw FLIP)], "ready_s"}``: ``first_s`` when the first image covers the frame
    (wave 0's block preview), ``ready_s`` the first time from which every denoised frame shown is
    within :data:`READY_LEVELS` RMS and :data:`READY_FLIP` mean FLIP of ``converged`` (the
    converged time if none is)."""
    from app.render_controller import WORKER_NICE
    from engine.tracer.denoise import FrameDenoiser
    from engine.tracer.job_options import JobObservers, Workers
    from engine.tracer.tables.stage import clear_stage_caches

    clock = {"start": 0.0, "first": None}
    shown = []

    def deliver(key, image, samples):
        t = time.perf_counter() - clock["start"]
        wave, raw = key
        shown.append((t, wave, image, raw))

    # the window's denoiser (its threads, its quality), warm as the window's is after its first frame
    watcher = FrameDenoiser(deliver, denoiser=_warm_denoiser(width, height), nice=WORKER_NICE)

    def on_wave(job, wave):  # (on the job's thread: as cheap as the window's signal)
        if wave == 0 and clock["first"] is None:
            clock["first"] = time.perf_counter() - clock["start"]
        elif wave >= 1 or job.sketched:  # (wave 0 again: a pass of the sketch)
            watcher.request((wave, job.image()), job)

    clear_stage_caches()
    clock["start"] = time.perf_counter()
    try:
        job, secs = render(design, assets, width, height, threads, window_sampling(policy=policy),
                           observers=JobObservers(on_wave=on_wave),
                           workers=Workers(nice=WORKER_NICE))  # (the window's workers: niced as its denoiser)
    finally:
        watcher.close(120)
    frames, regions, by_region = [], failure_regions(job), []
    for t, wave, image, raw in shown:
        if t >= secs:
            continue  # converged first: the window shows the raw film then
        frames.append((t, wave, distance(image, converged)[0], flip_mean(image, converged),
                       distance(raw, converged)[0], flip_mean(raw, converged)))
        by_region.append(region_errors(image, raw, converged, regions))
    ready = secs
    for t, wave, rms, flip, _, _ in reversed(frames):
        if rms > READY_LEVELS or flip > READY_FLIP:
            break
        ready = t
    first = clock["first"] if clock["first"] is not None else secs
    return {"first_s": first, "converged_s": secs, "frames": frames, "ready_s": ready, "regions": by_region}


#: Where a denoiser fails, as regions of the converged film (:func:`failure_regions`).
REGIONS = ("label_edges", "relief_edges", "silhouette", "ground", "thick_glass", "fireflies")


def _neighbour_differs(a, differs) -> np.ndarray:
    """Pixels (``(H, W)``) where ``differs(a, neighbour)`` holds for one of the 4 neighbours."""
    out = np.zeros(a.shape[:2], bool)
    for axis in (0, 1):
        d = differs(np.take(a, range(1, a.shape[axis]), axis), np.take(a, range(a.shape[axis] - 1), axis))
        lo = [slice(None)] * 2
        hi = [slice(None)] * 2
        lo[axis], hi[axis] = slice(1, None), slice(None, -1)
        out[tuple(lo)] |= d
        out[tuple(hi)] |= d
    return out


def bottle_mask(job) -> np.ndarray:
    """Pixels ``(H, W)`` whose ray trees met the bottle's own surfaces (its glass, liquid and
    walls; not the stage, the label or the cap alone): the pixels of glass issue 41 compares
    samples by."""
    return (job.film.objects & ((1 << len(job.context.geometry.names)) - 1)) != 0


def failure_regions(job) -> dict:
    """Masks ``(H, W)`` of the places issue 42 names, from a converged window render ``job``:
    ``label_edges`` (the albedo guide steps by > 0.1: label text, die-cut edges, seen directly or
    through the glass), ``relief_edges`` (the first hit's normal turns by > 15 deg to a neighbour
    on the bottle: knurling, cut facets, threads), ``silhouette`` (bottle next to background),
    ``ground`` (pixels that see the stage's ground and no bottle: caustic, soft shadow),
    ``thick_glass`` (pixels at half the sample cap or more: light circling in a thick base, total
    internal reflection). ``fireflies`` is per frame (:func:`region_errors`)."""
    film, ctx = job.film, job.context
    albedo, normal = film.guides()
    ground = int(ctx.ground_objects)
    bottle = bottle_mask(job)
    grey = albedo.mean(axis=2)
    label = _neighbour_differs(grey, lambda a, b: np.abs(a - b) > 0.1)
    unit = normal / np.maximum(np.linalg.norm(normal, axis=2, keepdims=True), 1e-9)
    turned = _neighbour_differs(unit, lambda a, b: (a * b).sum(axis=-1) < np.cos(np.radians(15.0)))
    silhouette = _neighbour_differs(bottle, lambda a, b: a != b)
    counts = film.samples()
    return {"label_edges": label & bottle, "relief_edges": turned & bottle & ~silhouette,
            "silhouette": silhouette, "ground": ((film.objects & ground) != 0) & ~bottle,
            "thick_glass": bottle & (counts >= max(2, counts.max() // 2))}


def region_errors(image, raw, converged, regions) -> dict:
    """``{region: (pixels, levels RMS of image, of raw)}`` against ``converged`` in each of
    ``regions`` and in ``fireflies`` (pixels where ``raw`` is brighter than ``converged`` by
    more than 64 display levels: single samples of a small bright light)."""
    a, r, c = levels(image).mean(axis=2), levels(raw).mean(axis=2), levels(converged).mean(axis=2)
    masks = dict(regions, fireflies=(r - c) > 64.0)
    out = {}
    for name in REGIONS:
        m = masks[name]
        n = int(np.count_nonzero(m))
        out[name] = (n, float(np.sqrt(np.mean((a[m] - c[m]) ** 2))) if n else 0.0,
                     float(np.sqrt(np.mean((r[m] - c[m]) ** 2))) if n else 0.0)
    return out


def progress_errors(seen, final_rms: float) -> list:
    """``[(seconds, levels RMS)]``: the error of a render's image after each wave, from ``seen``,
    its distance after each wave (seconds, levels RMS) from an independent converged image whose
    own error is ``final_rms`` levels RMS: the two errors are independent, so the image's own is
    the distance's square less the other's (a distance below that is noise: 0)."""
    return [(t, float(np.sqrt(max(d * d - final_rms * final_rms, 0.0)))) for t, d in seen]


def time_within(progress, bound: float) -> float | None:
    """The first time (s) in ``progress`` (:func:`progress_errors`) from which the error stays
    within ``bound`` levels RMS, or None if its last point is above it."""
    t_in = None
    for t, e in progress:
        if e <= bound:
            if t_in is None:
                t_in = t
        else:
            t_in = None
    return t_in


def chart(rows, path) -> None:
    """Seconds and rays per pixel per sample, with the targets."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    first = rows[0]["policy"]
    rows = [r for r in rows if r["policy"] == first]
    names = [r["sample"] for r in rows]
    with_progress = any(r.get("progress") for r in rows)
    fig, axes = plt.subplots(1, 3 if with_progress else 2, figsize=(16.5 if with_progress else 11, 4))
    axes[0].bar(names, [r["seconds"] for r in rows], color="#4a7ab0")
    axes[0].axhline(TARGET_WORST_S, color="#b03030", ls="--", lw=1, label=f"worst target {TARGET_WORST_S:g} s")
    axes[0].axhline(TARGET_MEDIAN_S, color="#d08020", ls=":", lw=1, label=f"median target {TARGET_MEDIAN_S:g} s")
    axes[0].set_ylabel("seconds to converge (2 cores)")
    axes[0].legend(fontsize=8)
    axes[1].bar(names, [r["rays_per_pixel"] for r in rows], color="#60a060")
    axes[1].set_ylabel("rays per pixel")
    for ax in axes[:2]:
        ax.tick_params(axis="x", rotation=45, labelsize=8)
    if with_progress:  # the error a designer sees against the time waited, per sample
        ax = axes[2]
        for r in rows:
            pts = [(t, e) for t, e in r.get("progress", ()) if t > 0 and e > 0]
            if pts:
                ax.loglog(*zip(*pts), marker=".", lw=1, label=r["sample"])
        ax.axhline(TARGET_RMS_LEVELS, color="#b03030", ls="--", lw=1)
        ax.axvline(TARGET_WORST_S, color="#b03030", ls="--", lw=1)
        ax.axvline(TARGET_MEDIAN_S, color="#d08020", ls=":", lw=1)
        ax.set_xlabel("seconds since the edit")
        ax.set_ylabel("error, display levels RMS")
        ax.set_title("the preview on the way (second render on other samples)", fontsize=9)
        ax.legend(fontsize=6, ncol=2)
    fig.suptitle(f"The window's preview, {rows[0]['width']} x {rows[0]['height']}, converged by its criterion")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def ready_chart(rows, path) -> None:
    """Per sample: seconds to the first image, to a ready denoised preview and to convergence
    (log scale), against the targets (0.5 s, 3 s)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [r["sample"] for r in rows]
    x = np.arange(len(rows))
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for k, (key, label) in enumerate((("first_s", "first image"), ("ready_s", "denoised preview ready"),
                                      ("seconds", "converged (raw)"))):
        ax.bar(x + (k - 1) * 0.27, [r[key] for r in rows], 0.27, label=label)
    ax.axhline(0.5, ls=":", c="k", lw=0.8)
    ax.axhline(3.0, ls="--", c="k", lw=0.8)
    ax.set_yscale("log")
    ax.set_xticks(x, names, rotation=30, ha="right")
    ax.set_ylabel("seconds (2 threads, 715 x 953)")
    ax.set_title("The window after an edit: first image (target 0.5 s), ready (3 s), converged")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def window_arguments(ap):
    """``ap`` (an ``argparse.ArgumentParser``) with the options every window benchmark takes:
    ``--samples``, ``--width``, ``--height`` (the window's pane) and ``--threads``."""
    ap.add_argument("--samples", default="", help="comma-separated sample names (default: all)")
    ap.add_argument("--width", type=int, default=WINDOW_SIZE[0])
    ap.add_argument("--height", type=int, default=WINDOW_SIZE[1])
    ap.add_argument("--threads", type=int, default=2)
    return ap


def main(argv=None) -> int:
    from engine.files.project import load_project

    ap = window_arguments(argparse.ArgumentParser(description=__doc__.splitlines()[0]))
    ap.add_argument("--check-scale", type=float, default=1.0 / 6.0,
                    help="size of the honesty check as a fraction of the render's")
    ap.add_argument("--no-check", action="store_true", help="skip the honesty check")
    ap.add_argument("--no-denoise", action="store_true", help="skip the denoised preview's timeline")
    ap.add_argument("--limit", type=float, default=None,
                    help=f"seconds a render may take before the sample is reported not converged (default {LIMIT_S:g})")
    ap.add_argument("--policies", default="split,classic",
                    help="sampling policies to render (the first is the figure line's; the others its peers)")
    a = ap.parse_args(argv)
    if a.limit is not None:
        set_limit(a.limit)
    os.makedirs(OUT, exist_ok=True)
    from engine.tracer.warmup import warm_up
    warm_up()  # (the window warms its kernels at launch: no sample's time should carry a compile)
    policies = [p for p in a.policies.split(",") if p]
    rows, unconverged = [], []
    for path in samples([s for s in a.samples.split(",") if s]):
        name = os.path.basename(path)[:-len(".glassbench")]
        design, assets = load_project(path)
        try:
            rows += sample_rows(a, name, design, assets, policies)
        except NotConverged as exc:  # (its rows so far are dropped: a sample is whole or out)
            unconverged.append(name)
            print(f"{name}: a {exc}: cancelled; its converged and ready times are unknown "
                  "(inf in the figure line)", flush=True)
    if not rows:
        print(f"no sample converged within {LIMIT_S:.0f} s")
        return 1
    write_outputs(rows, policies)
    print_summary(rows, policies, unconverged)
    return 0


def sample_rows(a, name, design, assets, policies) -> list[dict]:
    """One row per policy of the sample ``name`` (its renders, honesty check and denoised
    timeline, printed as they come); raises :class:`NotConverged` when a render runs out of
    time."""
    from engine.tracer.tables.stage import clear_stage_caches

    rows = []
    w, h = max(8, round(a.width * a.check_scale)), max(8, round(a.height * a.check_scale))
    ref = None if a.no_check else reference(design, assets, w, h, a.threads)
    ref_noise = None if a.no_check else reference_noise(design, assets, w, h, a.threads, ref)
    for policy in policies:  # (each policy's render and check back to back: the machine is shared)
        clear_stage_caches()  # (the time includes the ground's grids, as a design's first render does)
        job, secs = render(design, assets, a.width, a.height, a.threads, window_sampling(policy=policy),
                           observers=_watched())
        rays = job.stats.rays_cast
        # a colour-only edit could re-weigh a kept tree instead of tracing it again: each leaf
        # (a segment leaving for the environment or cut) would keep its RGB weight without
        # absorption and its length in glass and in liquid (5 float32)
        leaves = rays - job.stats.boundaries + job.stats.cut_depth
        row = {"sample": name, "policy": policy, "width": a.width, "height": a.height, "seconds": secs,
               "rays": rays, "rays_per_pixel": rays / (a.width * a.height),
               "tree_leaves": leaves, "kept_tree_gib": leaves * KEPT_LEAF_BYTES / 2 ** 30,
               "samples_per_pixel": float(job.sample_counts().mean()),
               # the display-only sketch's passes (engine.tracer.sketch), inside ``seconds``
               "sketch_s": float(sum(t for _, t in job.sketch_log)),
               # issue 41 compares samples by their time per pixel of glass (the flacon fills
               # twice the square's share of the frame)
               "glass_pixels": int(bottle_mask(job).sum()),
               # the per-pixel tolerance the split policy settled at (display levels)
               "tolerance_levels": None if job.tolerance is None else job.tolerance * 255.0}
        if ref is not None:
            row["check_size"] = f"{w}x{h}"
            row["rms_levels"], row["p99_levels"] = honesty(design, assets, w, h, a.threads, ref, policy)
            row["reference_noise_levels"] = ref_noise
            # the render's own error: the difference less the reference's noise (independent)
            row["own_rms_levels"] = float(np.sqrt(max(row["rms_levels"] ** 2 - ref_noise ** 2, 0.0)))
            row["full_rms_levels"], row["full_p99_levels"], progress = own_error(
                design, assets, a.width, a.height, a.threads, job.image(), policy)
            row["progress"] = progress
            for bound in PROGRESS_BOUNDS:
                row[f"within_{bound:g}_levels_s"] = time_within(progress, bound)
        rows.append(row)
        if policy == policies[0] and not a.no_denoise:
            dp = denoised_progress(design, assets, a.width, a.height, a.threads, policy, job.image())
            row["first_s"], row["ready_s"], row["denoised_frames"] = dp["first_s"], dp["ready_s"], dp["frames"]
            print(f"{name}: first image {dp['first_s']:.2f} s, denoised preview ready {dp['ready_s']:.2f} s "
                  f"(its render converged in {dp['converged_s']:.1f} s); frames shown (s: levels RMS / FLIP, "
                  "raw film then): " + ", ".join(f"{t:.1f}: {e:.1f}/{f:.3f} ({re_:.1f}/{rf:.3f})"
                                                 for t, _, e, f, re_, rf in dp["frames"]), flush=True)
            row["regions"] = dp["regions"]
            if dp["regions"]:  # where the denoiser fails: its first frame's error by region
                print(f"{name}: first denoised frame by region (pixels: levels RMS denoised / raw): " + ", ".join(
                    f"{k} {n}: {e:.1f}/{re_:.1f}" for k, (n, e, re_) in dp["regions"][0].items() if n), flush=True)
        check = (f", against the reference at {row['check_size']}: {row['rms_levels']:.2f} levels RMS, "
                 f"p99 {row['p99_levels']:.1f} (the reference's own noise {ref_noise:.2f}, "
                 f"the render's own {row['own_rms_levels']:.2f}); its own error at "
                 f"{a.width}x{a.height}: {row['full_rms_levels']:.2f} levels RMS, p99 {row['full_p99_levels']:.1f}"
                 if "rms_levels" in row else "")
        settled = ("" if row["tolerance_levels"] is None
                   else f", tolerance {row['tolerance_levels']:.0f} levels")
        if "progress" in row:
            check += "; on the way " + ", ".join(
                f"within {b:g} levels after " + ("(never)" if row[f"within_{b:g}_levels_s"] is None
                                                 else f"{row[f'within_{b:g}_levels_s']:.1f} s")
                for b in PROGRESS_BOUNDS)
        row["seconds_per_kilopixel_of_glass"] = secs / max(row["glass_pixels"], 1) * 1000.0
        print(f"{name} [{policy}]: {secs:.1f} s, {rays / 1e6:.1f} M rays, {row['rays_per_pixel']:.0f} rays/pixel, "
              f"{row['glass_pixels']:,} pixels of glass ({row['seconds_per_kilopixel_of_glass']:.2f} s per "
              f"thousand), {row['samples_per_pixel']:.1f} samples/pixel{settled}, its sketch {row['sketch_s']:.1f} s, a kept tree for colour edits "
              f"{row['kept_tree_gib']:.2f} GiB{check}", flush=True)
    return rows


def write_outputs(rows, policies) -> None:
    """The CSV files and charts of the converged samples' ``rows`` (module doc)."""
    with open(os.path.join(OUT, "window_converge.csv"), "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=sorted({k for r in rows for k in r if k not in ("progress", "regions")}),
                                extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    with open(os.path.join(OUT, "window_progress.csv"), "w", newline="") as fh:
        out = csv.writer(fh)
        out.writerow(["sample", "policy", "seconds", "levels_rms"])
        for r in rows:
            out.writerows([r["sample"], r["policy"], f"{t:.3f}", f"{e:.4f}"] for t, e in r.get("progress", ()))
    chart(rows, os.path.join(OUT, "window_converge.png"))
    denoised = [r for r in rows if "ready_s" in r]
    if denoised:
        with open(os.path.join(OUT, "window_denoise.csv"), "w", newline="") as fh:
            out = csv.writer(fh)
            out.writerow(["sample", "seconds", "wave", "levels_rms", "flip", "raw_levels_rms", "raw_flip"])
            for r in denoised:
                out.writerows([r["sample"], f"{t:.3f}", w, f"{e:.3f}", f"{f:.4f}", f"{re_:.3f}", f"{rf:.4f}"]
                              for t, w, e, f, re_, rf in r["denoised_frames"])
        ready_chart(denoised, os.path.join(OUT, "window_ready.png"))
        with open(os.path.join(OUT, "window_denoise_regions.csv"), "w", newline="") as fh:
            out = csv.writer(fh)
            out.writerow(["sample", "seconds", "region", "pixels", "levels_rms", "raw_levels_rms"])
            for r in denoised:
                for (t, *_), regions in zip(r["denoised_frames"], r["regions"]):
                    out.writerows([r["sample"], f"{t:.3f}", k, n, f"{e:.3f}", f"{re_:.3f}"]
                                  for k, (n, e, re_) in regions.items())


def print_summary(rows, policies, unconverged) -> None:
    """The peers' ratios, the honesty check and last the figure line; a sample in
    ``unconverged`` counts as infinitely slow to converge and to be ready (its first image is
    not in the worst)."""
    denoised = [r for r in rows if "ready_s" in r]
    for policy in policies[1:]:
        ratio = [r["seconds"] / q["seconds"] for r in rows if r["policy"] == policy
                 for q in rows if q["policy"] == policies[0] and q["sample"] == r["sample"]]
        rays = [r["rays"] / q["rays"] for r in rows if r["policy"] == policy
                for q in rows if q["policy"] == policies[0] and q["sample"] == r["sample"]]
        print(f"against the {policy} policy (same run): {min(ratio):.1f}-{max(ratio):.1f}x the time, "
              f"{min(rays):.1f}-{max(rays):.1f}x the rays")
    rows = [r for r in rows if r["policy"] == policies[0]]
    times = np.array([r["seconds"] for r in rows] + [np.inf] * len(unconverged))
    if "rms_levels" in rows[0]:
        print(f"honesty ({policies[0]}): worst RMS {max(r['rms_levels'] for r in rows):.2f} levels "
              f"(target {TARGET_RMS_LEVELS}), worst p99 {max(r['p99_levels'] for r in rows):.1f} "
              f"(target {TARGET_P99_LEVELS:g}); at the window's size worst RMS "
              f"{max(r['full_rms_levels'] for r in rows):.2f}, worst p99 {max(r['full_p99_levels'] for r in rows):.1f}")
    if denoised:
        first = np.array([r["first_s"] for r in denoised])
        ready = np.array([r["ready_s"] for r in denoised] + [np.inf] * len(unconverged))
        if unconverged:
            print(f"not converged within {LIMIT_S:.0f} s: {', '.join(unconverged)} (inf below; the first image's "
                  f"worst is over the {len(denoised)} others)")
        print(f"window_first_worst={first.max():.2f} window_ready_worst={ready.max():.2f} "
              f"window_ready_median={float(np.median(ready)):.2f} window_converge_worst={times.max():.1f} "
              f"window_converge_median={float(np.median(times)):.1f}")
    else:
        print(f"window_converge_worst={times.max():.1f} window_converge_median={float(np.median(times)):.1f}")


if __name__ == "__main__":
    raise SystemExit(main())
