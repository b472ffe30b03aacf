"""One batch from plan to report: skip what is done, render the rest, write, summarise.

Design rule: every path written is ``job.output`` joined with a checked relative name and is
refused if, once symbolic links are resolved, it would land outside the output folder. Frames
are written atomically by the client the moment each arrives (a denoised frame with its raw
film beside it, ``NAME.raw.EXT``: :func:`engine.finals.save_final`), and the manifest is updated
right after, so an interruption at any point loses at most the frames still rendering; a re-run
renders only frames whose input hash is not in the manifest (or whose file changed). The
contact sheet and summary are made last, from the output folder, covering every frame.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

from .execute import open_client, run_frames
from .manifest import Manifest, asset_digests, frame_hash
from .progress import BatchProgress
from .report import CONTACT_SHEET, contact_sheet, write_summary
from .source import JobError
from ..finals import save_final
from ..tracer.denoise import raw_path


@dataclass
class BatchReport:
    """What a batch did: frames rendered now and skipped (relative paths), files, seconds."""

    output: str
    rendered: list = field(default_factory=list)
    skipped: list = field(default_factory=list)
    contact_sheet: str | None = None
    summary_csv: str | None = None
    summary_json: str | None = None
    seconds: float = 0.0


def inside(folder: str, relpath: str) -> str:
    """``folder/relpath``, refused (:class:`JobError`) if it resolves outside ``folder``."""
    root = os.path.realpath(folder)
    target = os.path.realpath(os.path.join(root, relpath))
    if os.path.isabs(relpath) or os.path.commonpath([root, target]) != root or target == root:
        raise JobError(f"refusing to write {relpath!r}: it is not inside the output folder {folder}")
    return target


def run_batch(job, *, client=None, scheduler: str | None = None, workers: int | None = None,
              threads: int = 1, progress: BatchProgress | None = None) -> BatchReport:
    """Render ``job`` (a :class:`~engine.batch.jobfile.BatchJob`) and write its outputs.

    Parameters
    ----------
    client : distributed.Client, optional
        Use this client; otherwise one is opened (see :func:`engine.batch.execute.open_client`)
        with ``scheduler`` and ``workers``, only if some frame needs rendering.
    threads : int
        Tracer threads per frame.
    progress : BatchProgress, optional
        Receives the progress (default: nothing is shown).
    """
    t0 = time.perf_counter()
    progress = progress or BatchProgress()
    if os.path.exists(job.output) and not os.path.isdir(job.output):
        raise JobError(f"the output {job.output} exists and is not a folder")
    os.makedirs(job.output, exist_ok=True)
    frames = job.frames()
    targets = {f.relpath: inside(job.output, f.relpath) for f in frames}
    # a denoised frame keeps its raw film beside it, NAME.raw.EXT (checked the same way)
    raws = {f.relpath: raw_path(f.relpath) for f in frames} if job.denoise else {}
    for rel in raws.values():
        if rel in targets:
            raise JobError(f"the raw image of a denoised frame would be {rel!r}, another frame's name; "
                           "rename that view")
        inside(job.output, rel)
    digests = {id(v): asset_digests(v.assets) for v in job.variants}
    inputs = {f.relpath: frame_hash(f.design, digests[id(f.variant)], job.format, job.alpha, job.denoise)
              for f in frames}
    manifest = Manifest(job.output)
    todo = [f for f in frames if not manifest.is_done(f.relpath, inputs[f.relpath])]
    waiting = {f.relpath for f in todo}
    report = BatchReport(job.output, skipped=[f.relpath for f in frames if f.relpath not in waiting])
    for f in todo:
        os.makedirs(os.path.dirname(targets[f.relpath]), exist_ok=True)
        for rel in (f.relpath, raws.get(f.relpath)):
            if rel:  # again: a folder made just now must not be a link out
                inside(job.output, rel)

    def on_result(frame, result):
        save_final(targets[frame.relpath], result["images"])
        beside = (raws[frame.relpath],) if job.denoise else ()
        manifest.record(frame.relpath, inputs[frame.relpath], beside, variant=frame.variant.name,
                        view=frame.view.name, seconds=round(result["seconds"], 4),
                        worker=result["worker"])
        report.rendered.append(frame.relpath)
        progress.frame_done(frame.relpath, result["seconds"], result["worker"])

    progress.start(len(todo), len(report.skipped))
    try:
        if todo:
            def payload_of(frame):
                return frame.variant.design, frame.variant.assets
            kw = dict(alpha=job.alpha, denoise=job.denoise, threads=threads, on_result=on_result,
                      on_progress=progress.frame_progress)
            if client is not None:
                run_frames(client, todo, payload_of, **kw)
            else:
                with open_client(scheduler, workers) as own:
                    run_frames(own, todo, payload_of, **kw)
    finally:
        progress.finish()
    first = frames[0].design.render
    title = (f"{len(job.variants)} variant(s) x {len(job.views)} view(s), "
             f"{first.width}x{first.height} px, {first.spp} spp" + (", denoised" if job.denoise else ""))
    report.contact_sheet = inside(job.output, CONTACT_SHEET)
    contact_sheet(job, frames, report.contact_sheet, title)
    report.summary_csv, report.summary_json = write_summary(job, manifest, job.output)
    report.seconds = time.perf_counter() - t0
    return report
