"""The ``glassbench`` subcommands that need no window: info, export-mesh, new, render here, and
those of :data:`DELEGATED` (batch, turntable, labels, dieline, label, cap, bump, export-cad,
export-scene, share) in the modules that own them.

Design rule: each subcommand is a small function over the engine's public API; ``main``
turns every expected failure (a bad project, a bad DXF, a missing file, a tracer that
refuses) into one line on stderr and exit status 2, never a traceback. No Qt here:
``app.main`` hands subcommands to :func:`main` and only opens a window without one.
"""
from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import sys
from pathlib import Path

from .model.design import Camera, Design, RenderSettings
from . import limits
from .errors import CliError, GlassbenchError, ProjectError, bounded, shown  # noqa: F401 - CliError for callers
from .geometry.shape import BottleShape
from .model.trade import format_table, trade_numbers  # noqa: F401 - also for callers of the CLI

#: Subcommands whose parsers and handlers live with what they do: module (relative to
#: ``engine``) -> its subcommands. Each module offers ``add_parsers(sub)`` and ``cmd_NAME(args)``
#: (dashes in NAME as underscores).
DELEGATED = {".batch.commands": ("batch", "turntable"),
             ".appearance.label_cli": ("labels", "dieline", "label"),
             ".appearance.commands": ("cap", "bump"),
             ".export.commands": ("export-cad", "export-scene", "share")}
SUBCOMMANDS = ("info", "export-mesh", "new", "render") + sum(DELEGATED.values(), ())
EXIT_ERROR = 2


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line on stderr and exit status 2, like every
    other error of the command line (argparse's own prints the whole usage first)."""

    def error(self, message: str):
        self.exit(EXIT_ERROR, f"{self.prog}: error: {bounded(message)} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the subcommands (``glassbench SUBCOMMAND ...``)."""
    p = OneLineParser(prog="glassbench", description="Glass-container workbench.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    info = sub.add_parser("info", help="capacity, glass volume and size of a project")
    info.add_argument("project")
    info.add_argument("--json", action="store_true", help="print one JSON object")
    mesh = sub.add_parser("export-mesh", help="write the bottle as STL/OBJ/PLY/glTF")
    mesh.add_argument("project")
    mesh.add_argument("out")
    mesh.add_argument("--tol", type=float, default=0.05, help="chordal tolerance (mm)")
    new = sub.add_parser("new", help="create a project from a DXF section")
    new.add_argument("--from-dxf", required=True, metavar="FILE.dxf")
    new.add_argument("out", metavar="OUT.glassbench")
    new.add_argument("--wall", type=float, default=3.0, help="wall thickness (mm)")
    new.add_argument("--base", type=float, default=6.0, help="base thickness (mm)")
    new.add_argument("--name", default=None)
    render = sub.add_parser("render", help="render a project to PNG/EXR/TIFF")
    render.add_argument("project")
    render.add_argument("-o", "--output", required=True, metavar="OUT.png|exr|tif")
    render.add_argument("--width", type=int, default=None)
    render.add_argument("--height", type=int, default=None)
    render.add_argument("--spp", type=int, default=None)
    for module in DELEGATED:
        _delegate(module).add_parsers(sub)
    return p


def _delegate(module: str):
    """The module of :data:`DELEGATED` that owns some subcommands (imported on first use)."""
    return importlib.import_module(module, __package__)


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand; returns the exit status (0 ok, 2 error; argparse exits 2 itself)."""
    args = build_parser().parse_args(argv)
    handler = {"info": cmd_info, "export-mesh": cmd_export_mesh, "new": cmd_new,
               "render": cmd_render}.get(args.command)
    if handler is None:
        owner = next(m for m, names in DELEGATED.items() if args.command in names)
        handler = getattr(_delegate(owner), f"cmd_{args.command.replace('-', '_')}")
    try:
        return handler(args)
    except KeyboardInterrupt:
        print(f"glassbench {args.command}: interrupted", file=sys.stderr)
        return 130
    except (GlassbenchError, OSError, ValueError, ArithmeticError) as exc:
        print(f"glassbench {args.command}: error: {one_line(exc)}", file=sys.stderr)
        return EXIT_ERROR
    except Exception as exc:  # why: a command line never shows a traceback (set GLASSBENCH_DEBUG)
        if os.environ.get("GLASSBENCH_DEBUG"):
            raise
        print(f"glassbench {args.command}: internal error: {type(exc).__name__}: {one_line(exc)}",
              file=sys.stderr)
        return EXIT_ERROR


def one_line(exc: BaseException) -> str:
    """The exception's message on one line (OSError: strerror and file name)."""
    if isinstance(exc, OSError) and exc.strerror:
        text = f"{exc.strerror}: {exc.filename}" if exc.filename else exc.strerror
    else:
        text = str(exc) or type(exc).__name__
    return bounded(text)


# ---------------------------------------------------------------------------------- info

def cmd_info(args) -> int:
    """``info PROJECT [--json]``: trade numbers (ml, mm, cm^3, g) as a table or JSON."""
    from .files.project import load_project
    design, _ = load_project(args.project)
    numbers = trade_numbers(design)
    if args.json:
        print(json.dumps(numbers, indent=2, allow_nan=False))
    else:
        print(format_table(numbers))
    return 0


# --------------------------------------------------------------------------- export-mesh

def cmd_export_mesh(args) -> int:
    """``export-mesh PROJECT OUT [--tol MM]``: the glass body as a mesh (format from OUT's suffix)."""
    from .files.project import load_project
    limits.check_range("--tol", args.tol, (limits.MIN_TOL_MM, limits.MAX_TOL_MM), "mm")
    design, _ = load_project(args.project)
    try:
        from .files.mesh_export import export_mesh
    except ImportError as exc:
        raise CliError(f"mesh export is not available in this build ({exc})") from None
    export_mesh(design.shape, args.out, args.tol)
    print(f"wrote {args.out}")
    return 0


# ----------------------------------------------------------------------------------- new

def framing_camera(shape: BottleShape, width: int, height: int, fov_y_deg: float = 28.0) -> Camera:
    """A camera (mm) looking at the bottle from the front (-y), slightly above its middle,
    far enough that the whole bottle fills about 85 % of the frame (``width`` x ``height`` px)."""
    z_top = shape.z_top
    r_max = max_radius(shape)
    t = math.tan(math.radians(fov_y_deg) / 2)
    aspect = width / height
    # Distance so that half the height (plus margin) fits vertically and the radius horizontally.
    dist = max(0.59 * z_top / t, 1.18 * r_max / (t * aspect)) + r_max
    target = (0.0, 0.0, 0.5 * z_top)
    eye = (0.0, -dist, 0.5 * z_top + 0.12 * dist)
    return Camera(eye=eye, target=target, up=(0.0, 0.0, 1.0), fov_y_deg=fov_y_deg)


def max_radius(shape: BottleShape) -> float:
    """Largest distance (mm) of the outer surface from the axis (half the maximum diameter)."""
    from .geometry import capacity
    return 0.5 * float(capacity.max_diameter_mm(shape))


def cmd_new(args) -> int:
    """``new --from-dxf FILE.dxf OUT.glassbench``: a round bottle (wall/base in mm) from a DXF
    section, framed by a camera; refuses to write an invalid design."""
    from .files.dxf_import import section_from_dxf
    from .files.project import SUFFIX, check_design, save_project
    if not args.out.endswith(SUFFIX):
        raise CliError(f"the project file name must end in {SUFFIX}: {shown(args.out, 200)}")
    for flag in ("wall", "base"):
        limits.check_range(f"--{flag}", getattr(args, flag), (0.0, limits.MAX_EXTENT_MM), "mm")
    section = section_from_dxf(args.from_dxf)
    shape = BottleShape("round", (("profile", section),), args.wall, args.base)
    render = RenderSettings(width=360, height=480)
    name = args.name or Path(args.from_dxf).stem
    design = Design(shape=shape, camera=framing_camera(shape, render.width, render.height),
                    render=render, name=name)
    try:
        check_design(design, {})
    except ProjectError as exc:
        raise CliError(f"{args.from_dxf}: {exc}") from None
    save_project(args.out, design, {})
    print(f"wrote {args.out}")
    return 0


# -------------------------------------------------------------------------------- render

def cmd_render(args) -> int:
    """``render PROJECT -o OUT``: hand the project to the tracer's render command."""
    ext = os.path.splitext(args.output)[1].lower()
    if ext not in (".png", ".exr", ".tif", ".tiff"):
        raise CliError(f"the output must end in .png, .exr or .tif, got {shown(args.output, 200)}")
    for name, bounds in (("width", limits.WIDTH_RANGE), ("height", limits.HEIGHT_RANGE),
                         ("spp", limits.SPP_RANGE)):
        v = getattr(args, name)
        if v is not None:
            limits.check_range(f"--{name}", v, bounds, integer=True)
    try:
        from .tracer import cli_render
    except ImportError as exc:
        raise CliError(f"rendering is not available yet: the tracer's cli_render is missing ({exc})") from None
    return render_via_tracer(cli_render, args.project, args.output, args.width, args.height, args.spp)


def render_via_tracer(cli_render, project, output, width, height, spp) -> int:
    """Call the tracer's render command (:func:`engine.tracer.cli_render.render_command`)
    for one project; it loads the project, renders with progress on stderr and saves."""
    fn = getattr(cli_render, "render_command", None) or getattr(cli_render, "render_project", None)
    if fn is None:
        raise CliError("the tracer's cli_render module offers no render_command function")
    status = fn(project, output, width=width, height=height, spp=spp)
    if status in (None, 0):
        print(f"wrote {output}")
        return 0
    return int(status)
