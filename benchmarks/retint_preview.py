"""A colour-only edit in the window: how soon the preview is ready, retinted against denoised.

Usage::

    python -m benchmarks.retint_preview [--samples jar,knurled_jar] [--width 715 --height 953]
                                        [--threads 2]

Each bundled sample is rendered as the window renders it (:func:`benchmarks.window_converge.render`:
the window's sampling at its default pane size) until converged; then a designer's colour edit
(:data:`TINT`: the glass turns amber; a liquid, if any, turns from its colour to a blue) starts
the next job as the window starts it, told what changed, so that it takes the old film's
:class:`~engine.tracer.retint.RetintBasis` (:mod:`engine.tracer.retint`). After each wave of the
new job its film is copied (on the job's thread: the time of the copy is taken off the clock),
and after the render both previews the window could show are made from the same copies: the
retinted one (:func:`engine.tracer.denoise.preview_frame` of the job) and the denoised one
(:func:`~engine.tracer.denoise.denoised_frame`, the window's denoiser warm, one thread: what
every edit showed before). Each frame counts as shown when its wave ended plus the time it took
to make (the window makes it on a thread of its own beside the workers). Errors are against the
new job's converged image, which equals a fresh render of the edited design bit for bit (the
retint never touches the film: ``--check-fresh`` checks it, at the cost of a third render). "Ready" is the window's criterion
(:data:`~benchmarks.window_converge.READY_LEVELS` display levels RMS and
:data:`~benchmarks.window_converge.READY_FLIP` mean FLIP, from then on), the converged time
where no frame meets it.

The peer is the denoised preview of the same film in the same run. Writes
``benchmarks/out/retint_preview.csv`` (every frame) and ``retint_preview.png`` (error against
time, per sample, both previews), and prints last ``retint_first_worst=S retint_ready_worst=S
retint_ready_median=S denoised_ready_worst=S denoised_ready_median=S retint_basis_mib=M``.
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import time

import numpy as np

from benchmarks.window_converge import (OUT, READY_FLIP, READY_LEVELS, _warm_denoiser, distance, flip_mean,
                                        render, samples, window_arguments)

#: The edit: absorption (1/mm, RGB) added to the glass's (an amber tint: blue goes first), and
#: the liquid's new absorption (a blue drink), if the design has a liquid.
TINT = (0.004, 0.03, 0.09)
LIQUID_BLUE = (0.06, 0.02, 0.004)


def tinted(design):
    """``design`` after the benchmark's colour edit (:data:`TINT`)."""
    glass = dataclasses.replace(design.glass, absorption=tuple(float(a + t) for a, t in zip(design.glass.absorption, TINT)))
    liquid = None if design.liquid is None else dataclasses.replace(design.liquid, absorption=LIQUID_BLUE)
    return dataclasses.replace(design, glass=glass, liquid=liquid)


class FilmCopy:
    """A job's film, context and retint basis as they were after one wave: what the window's
    frame maker reads (``film``, ``context``, ``retint``, ``drafting``, :meth:`image`,
    :meth:`aa_pixels`)."""

    def __init__(self, job):
        from engine.tracer.film import Film

        src = job.film
        self.film = Film(src.width, src.height, src.depth.shape[2])
        with src.lock:
            for name, value in vars(src).items():
                if isinstance(value, np.ndarray):
                    setattr(self.film, name, value.copy())
        self.context, self.retint, self.drafting = job.context, job.retint, job.drafting

    def image(self):
        return self.film.image()

    def aa_pixels(self):
        from engine.tracer.job import RenderJob

        return RenderJob.aa_pixels(self)


def edit_timeline(design, assets, width, height, threads):
    """``(old job, new job, [(wave end s, FilmCopy)])``: a converged render of ``design``, then
    the render after the colour edit with the window's reuse, its film copied after each wave."""
    from engine.model.changes import Change
    from engine.tracer.job_options import JobObservers, Replaces

    old, _ = render(design, assets, width, height, threads)
    copies, clock = [], {"start": 0.0, "spent": 0.0}

    def on_wave(job, wave):  # (the job's thread: the copy's time is taken off the clock)
        t = time.perf_counter()
        copies.append((t - clock["start"] - clock["spent"], FilmCopy(job)))
        clock["spent"] += time.perf_counter() - t

    clock["start"] = time.perf_counter()
    new, secs = render(tinted(design), assets, width, height, threads,
                       replaces=Replaces(old, Change({"glass", "liquid"})), observers=JobObservers(on_wave=on_wave))
    return old, new, copies, secs - clock["spent"]


def frames(copies, converged, denoiser):
    """Per wave copy ``(wave end s, kind, seconds to make, levels RMS, mean FLIP)`` of both
    previews, ``kind`` "retinted" or "denoised"."""
    from engine.tracer.denoise import denoised_frame, preview_frame

    out = []
    for t, copy in copies:
        for kind, make in (("retinted", lambda c: preview_frame(c, denoiser)),
                           ("denoised", lambda c: denoised_frame(c, denoiser) if c.film.has_centre.all() else None)):
            t0 = time.perf_counter()
            image = make(copy)
            took = time.perf_counter() - t0
            if image is not None:
                out.append((t, kind, took, distance(image, converged)[0], flip_mean(image, converged)))
    return out


def ready(rows, kind, converged_s) -> float:
    """The first time from which every ``kind`` frame shown before convergence meets the
    window's criterion (``converged_s`` if none does)."""
    shown = sorted((t + took, rms, flip) for t, k, took, rms, flip in rows if k == kind and t + took < converged_s)
    when = converged_s
    for t, rms, flip in reversed(shown):
        if rms > READY_LEVELS or flip > READY_FLIP:
            break
        when = t
    return when


def sample_row(name, design, assets, a) -> dict:
    """One sample's figures (printed as they come)."""
    from engine.tracer.job import render_image

    old, new, copies, secs = edit_timeline(design, assets, a.width, a.height, a.threads)
    converged = new.image()
    if a.check_fresh:
        fresh = render_image(tinted(design), assets, width=a.width, height=a.height, threads=a.threads,
                             sampling=new.sampling)
        if not np.array_equal(fresh, converged):
            raise AssertionError(f"{name}: the retinted job's converged image differs from a fresh render")
    if new.retint is None:
        raise AssertionError(f"{name}: the colour edit did not take the retint")
    rows = frames(copies, converged, _warm_denoiser(a.width, a.height))
    first = min((t + took for t, k, took, *_ in rows if k == "retinted"), default=secs)
    row = {"sample": name, "converged_s": secs, "retint_first_s": first,
           "retint_ready_s": ready(rows, "retinted", secs), "denoised_ready_s": ready(rows, "denoised", secs),
           "edit_levels_rms": distance(old.image(), converged)[0], "basis_mib": new.retint.nbytes / 2 ** 20,
           "frames": rows}
    firsts = {k: next(((t + took, rms, flip) for t, kk, took, rms, flip in rows if kk == k), None)
              for k in ("retinted", "denoised")}
    said = ", ".join(f"{k} {v[0]:.2f} s: {v[1]:.1f} levels RMS / FLIP {v[2]:.3f}" for k, v in firsts.items() if v)
    print(f"{name}: the edit moves the image {row['edit_levels_rms']:.1f} levels RMS; converged in {secs:.1f} s; "
          f"ready retinted {row['retint_ready_s']:.2f} s, denoised {row['denoised_ready_s']:.2f} s; "
          f"first frames: {said}; basis {row['basis_mib']:.0f} MiB", flush=True)
    return row


def write_outputs(rows) -> None:
    """``retint_preview.csv`` and ``retint_preview.png`` (module doc)."""
    with open(os.path.join(OUT, "retint_preview.csv"), "w", newline="") as fh:
        out = csv.writer(fh)
        out.writerow(["sample", "wave_end_s", "kind", "make_s", "levels_rms", "flip"])
        for r in rows:
            out.writerows([r["sample"], f"{t:.3f}", k, f"{took:.3f}", f"{e:.3f}", f"{f:.4f}"]
                          for t, k, took, e, f in r["frames"])
    chart(rows, os.path.join(OUT, "retint_preview.png"))


def chart(rows, path) -> None:
    """Error against time after the edit, per sample (one colour), both previews."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    colours = plt.get_cmap("tab10")
    for i, r in enumerate(rows):
        for kind, style in (("retinted", "-"), ("denoised", ":")):
            pts = sorted((t + took, e, f) for t, k, took, e, f in r["frames"] if k == kind)
            if pts:
                t, e, f = zip(*pts)
                label = r["sample"] if kind == "retinted" else None
                axes[0].plot(t, e, style, marker=".", color=colours(i % 10), label=label)
                axes[1].plot(t, f, style, marker=".", color=colours(i % 10))
    for ax, target, what in ((axes[0], READY_LEVELS, "display levels RMS"), (axes[1], READY_FLIP, "mean FLIP")):
        ax.axhline(target, color="k", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("seconds after the colour edit")
        ax.set_ylabel(f"{what} against the converged image")
    axes[0].legend(fontsize=7)
    fig.suptitle("A colour edit: the retinted preview (solid) against the denoised one (dotted) of the same film")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    from engine.files.project import load_project
    from engine.tracer.warmup import warm_up

    ap = window_arguments(argparse.ArgumentParser(description=__doc__.splitlines()[0]))
    ap.add_argument("--check-fresh", action="store_true",
                    help="also render the edited design afresh and check the new job's image equals it bit for bit "
                         "(tests/test_retint.py checks it at a small size)")
    a = ap.parse_args(argv)
    os.makedirs(OUT, exist_ok=True)
    warm_up()
    rows = []
    for path in samples([s for s in a.samples.split(",") if s]):
        design, assets = load_project(path)
        rows.append(sample_row(os.path.basename(path)[:-len(".glassbench")], design, assets, a))
    write_outputs(rows)
    first = max(r["retint_first_s"] for r in rows)
    rr = np.array([r["retint_ready_s"] for r in rows])
    dr = np.array([r["denoised_ready_s"] for r in rows])
    print(f"retint_first_worst={first:.2f} retint_ready_worst={rr.max():.2f} retint_ready_median={np.median(rr):.2f} "
          f"denoised_ready_worst={dr.max():.2f} denoised_ready_median={np.median(dr):.2f} "
          f"retint_basis_mib={max(r['basis_mib'] for r in rows):.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
