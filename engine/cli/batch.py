"""``glassbench batch`` and ``glassbench turntable``: the batch machinery on the command line.

Design rule: :mod:`engine.cli` owns the program; this module adds two subparsers and their
handlers, so ``cli.py`` gains only a few well-separated lines. A handler reads and checks the
whole job first (:class:`~engine.batch.source.JobError` names the line), then runs it on a
LocalCluster or the ``--scheduler`` given, with a terminal progress bar unless ``--quiet``,
and prints where everything went (for a denoised job, where its raw frames are too). Errors
reach ``engine.cli.main``, which prints one line.
"""
from __future__ import annotations

from ..batch.jobfile import FORMATS, read_job, turntable_job


def add_parsers(sub) -> None:
    """Add the ``batch`` and ``turntable`` subcommands to an argparse subparsers object."""
    batch = sub.add_parser("batch", help="render the variants x views of a job file (TOML/JSON)")
    batch.add_argument("job", metavar="JOB.toml|JOB.json")
    batch.add_argument("-o", "--output", default=None, metavar="DIR",
                       help="output folder (default: the job file's 'output')")
    batch.add_argument("--check", action="store_true",
                       help="read and check the job, print its plan, render nothing")
    _add_cluster_options(batch)
    turn = sub.add_parser("turntable", help="render N frames orbiting the bottle's axis")
    turn.add_argument("project")
    turn.add_argument("--frames", type=int, required=True,
                      help="frames per turn (frame k at 360 k / N degrees)")
    turn.add_argument("-o", "--output", required=True, metavar="DIR", help="writes DIR/frame_0000.EXT ...")
    turn.add_argument("--width", type=int, default=None)
    turn.add_argument("--height", type=int, default=None)
    turn.add_argument("--spp", type=int, default=None, metavar="N",
                      help="samples per edge pixel before the adaptive rounds, not per pixel: smooth pixels take one, "
                             "pixels whose samples still scatter up to 64 x N in all (default: the project's)")
    turn.add_argument("--format", choices=FORMATS, default="png")
    turn.add_argument("--alpha", action="store_true", help="add the bottle's coverage as alpha")
    turn.add_argument("--denoise", action="store_true",
                      help="write each frame denoised (Intel Open Image Denoise, guided by albedo and normal) and "
                           "keep its raw film beside it as frame_NNNN.raw.EXT; each file's description says which")
    _add_cluster_options(turn)


def _add_cluster_options(p) -> None:
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="an existing Dask scheduler (tcp://HOST:8786); default: a LocalCluster here")
    p.add_argument("--workers", type=int, default=None,
                   help="LocalCluster worker processes (default: one per core)")
    p.add_argument("--threads", type=int, default=1, help="tracer threads per frame (default 1)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def cmd_batch(args) -> int:
    """``batch JOB [-o DIR] [--check] [--scheduler ADDRESS]``."""
    job = read_job(args.job, args.output)
    if args.check:
        n = len(job.variants) * len(job.views)
        print(f"{args.job}: {len(job.variants)} variant(s) x {len(job.views)} view(s) = {n} frame(s)"
              f"{', denoised' if job.denoise else ''} -> {job.output}")
        return 0
    return _run(job, args)


def cmd_turntable(args) -> int:
    """``turntable PROJECT --frames N -o DIR [--alpha] [--denoise] [...]``."""
    job = turntable_job(args.project, args.frames, args.output, width=args.width, height=args.height,
                        spp=args.spp, format=args.format, alpha=args.alpha, denoise=args.denoise)
    return _run(job, args)


def _run(job, args) -> int:
    from ..batch.progress import BatchProgress, TerminalProgress
    from ..batch.run import run_batch
    from ..batch.source import JobError
    for name in ("workers", "threads"):
        v = getattr(args, name)
        if v is not None and not 1 <= v <= 1024:
            raise JobError(f"--{name} must be in 1..1024, got {v}")
    progress = BatchProgress() if args.quiet else TerminalProgress()
    report = run_batch(job, scheduler=args.scheduler, workers=args.workers, threads=args.threads,
                       progress=progress)
    print(f"rendered {len(report.rendered)} frame(s), skipped {len(report.skipped)} already done, "
          f"in {report.seconds:.1f} s -> {report.output}")
    if job.denoise:
        print("frames denoised (Intel Open Image Denoise); the raw film of each beside it as NAME.raw.EXT")
    print(f"contact sheet {report.contact_sheet}")
    print(f"summary {report.summary_csv} {report.summary_json}")
    return 0
