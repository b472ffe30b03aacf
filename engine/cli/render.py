"""``glassbench render PROJECT -o OUT.png|exr|tif [--alpha]``: render a project file headless.

Design rule: loads the project, runs a :class:`engine.tracer.job.RenderJob` with its progress on
stderr, adds the bottle's coverage as alpha when asked (:func:`engine.tracer.picking.coverage`,
as the final-render dialog and ``turntable --alpha`` do) and writes the image through the one
image writer (:func:`engine.files.images.save_image`: EXR linear float32, PNG and TIFF sRGB
8-bit), atomically.
"""
from __future__ import annotations

import os
import sys
import time

from .. import limits
from ..errors import CliError, shown
from ..files.images import IMAGE_SUFFIXES
from ..limits import check_image_size
from ..finals import write_final
from ..tracer.job import RenderJob
from ..tracer.job_options import Workers


class ProgressLine:
    """A percentage on ``stream``: on a terminal one line rewritten whenever its text changes;
    in a log (not a terminal) a new line only each time the work has moved on by a tenth, so
    a CI log or a redirected stderr gets ten lines, not one per poll."""

    def __init__(self, label: str, stream):
        self.label, self.stream = label, stream
        self.live = stream.isatty()
        self.last = None

    def update(self, fraction: float) -> None:
        """Show ``fraction`` (0..1) done."""
        if self.live:
            text = f"{self.label}: {100 * fraction:5.1f} %"
            if text != self.last:
                print(f"\r{text}", end="", file=self.stream, flush=True)
                self.last = text
            return
        tenth = int(10 * fraction + 1e-9)
        if tenth != self.last and tenth > 0:
            print(f"{self.label}: {10 * tenth:3d} %", file=self.stream, flush=True)
            self.last = tenth

    def close(self) -> None:
        """End the terminal's line (a log's lines are ended already)."""
        if self.live and self.last is not None:
            print(file=self.stream)


def add_parsers(sub) -> None:
    """The subparser of ``render``."""
    render = sub.add_parser("render", help="render a project to PNG/EXR/TIFF")
    render.add_argument("project")
    render.add_argument("-o", "--output", required=True, metavar="OUT.png|exr|tif")
    render.add_argument("--width", type=int, default=None)
    render.add_argument("--height", type=int, default=None)
    render.add_argument("--spp", type=int, default=None, metavar="N",
                        help="samples per edge pixel before the adaptive rounds, not per pixel: smooth pixels take one, "
                             "pixels whose samples still scatter up to 64 x N in all (default: the project's)")
    render.add_argument("--alpha", action="store_true",
                        help="add the bottle's coverage (glass and closure) as an alpha channel")
    render.add_argument("--denoise", action="store_true",
                        help="write the denoised image (Intel Open Image Denoise, guided by albedo and normal) and "
                             "keep the raw one beside it as NAME.raw.EXT; each file's description says which it is")


def cmd_render(args) -> int:
    """``render PROJECT -o OUT [--width W] [--height H] [--spp N] [--alpha]``."""
    if os.path.splitext(args.output)[1].lower() not in IMAGE_SUFFIXES:
        raise CliError(f"the output must end in .png, .exr or .tif, got {shown(args.output, 200)}")
    for name, bounds in (("width", limits.WIDTH_RANGE), ("height", limits.HEIGHT_RANGE),
                         ("spp", limits.SPP_RANGE)):
        v = getattr(args, name)
        if v is not None:
            limits.check_range(f"--{name}", v, bounds, integer=True)
    render_command(args.project, args.output, args.width, args.height, args.spp, alpha=args.alpha,
                   denoise=args.denoise)
    if args.denoise:
        from ..tracer.denoise import raw_path
        print(f"wrote {args.output} (denoised) and {raw_path(args.output)} (raw)")
    else:
        print(f"wrote {args.output}")
    return 0


def render_command(project_path, out_path, width=None, height=None, spp=None, threads=None,
                   progress=True, alpha=False, denoise=False) -> int:
    """Render a ``.glassbench`` project to ``out_path``; returns the exit status (0 = written).

    ``width``, ``height`` (pixels) and ``spp`` override the project's render settings; ``alpha``
    adds the coverage as alpha; ``denoise`` writes the denoised image to ``out_path`` and the raw
    one beside it (:func:`engine.tracer.denoise.raw_path`). With ``progress`` a percentage line is updated on stderr; the
    time taken is printed on stdout. Raises ``engine.errors.ProjectError`` for an unreadable
    project and ``ValueError`` for a bad output name; a failing render re-raises the worker's
    exception.
    """
    from ..files.project import load_project

    if os.path.splitext(os.fspath(out_path))[1].lower() not in IMAGE_SUFFIXES:
        raise ValueError(f"the output must end in .png, .exr or .tif, got {out_path!r}")
    design, assets = load_project(project_path)
    # The overrides combine with the project's own size: check what will really be rendered.
    check_image_size(width or design.render.width, height or design.render.height,
                     spp or design.render.spp, where="image ")
    t0 = time.perf_counter()
    job = RenderJob(design, assets, width=width, height=height, spp=spp, threads=threads,
                    workers=Workers(tile=64))
    job.start()
    report = ProgressLine(f"rendering {job.width}x{job.height} at {job.spp} spp", sys.stderr) if progress else None
    while not job.wait(0.25):
        if report:
            report.update(job.progress)
    if report:
        report.close()
    if job.error is not None:
        raise job.error
    secs = time.perf_counter() - t0
    write_final(job, design, assets, out_path, alpha=alpha, denoise=denoise)
    print(f"rendered {job.width}x{job.height}, {job.spp} spp, in {secs:.2f} s")
    return 0
