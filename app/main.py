"""The ``glassbench`` console script: subcommands, or the window, or a headless preview.

Design rule: this is the only place that decides between the command line and the GUI.
``glassbench info|export-mesh|new|render ...`` goes to :mod:`engine.cli` without importing
Qt; ``glassbench [PROJECT]`` and ``glassbench --screenshot OUT.png [PROJECT]`` open the window
(``app.startup.run``, imported only then). On Linux without a display (no ``DISPLAY`` or
``WAYLAND_DISPLAY``) and without ``--screenshot``, the project (default: the Bordeaux sample)
is rendered to a PNG with the tracer instead, and its path printed. Errors are one line on
stderr and exit status 2.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

RESOURCES = Path(__file__).resolve().parent.parent / "resources"
SAMPLE_PROJECT = RESOURCES / "bordeaux.glassbench"


def has_display() -> bool:
    """Whether a window can be shown (always true off Linux)."""
    if not sys.platform.startswith("linux"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _gui_parser() -> argparse.ArgumentParser:
    from engine.cli import SUBCOMMANDS, OneLineParser
    p = OneLineParser(
        prog="glassbench",
        description="Glass-container workbench. Without a command, opens the window.",
        epilog=f"commands: {', '.join(SUBCOMMANDS)} (glassbench COMMAND --help)")
    p.add_argument("project", nargs="?", help="a .glassbench project to open")
    p.add_argument("--screenshot", metavar="OUT.png",
                   help="open the window, save a screenshot of it and quit")
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``glassbench`` console script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    from engine import cli
    if argv and argv[0] in cli.SUBCOMMANDS:
        return cli.main(argv)
    args = _gui_parser().parse_args(argv)
    try:
        if args.project is not None and not os.path.isfile(args.project):
            raise cli.CliError(f"no such project file: {args.project}")
        if not has_display():
            if args.screenshot is None:
                return headless_preview(args.project)
            # A screenshot needs no screen: let Qt draw off-screen.
            os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
        from app.startup import run  # why here: Qt is loaded only to open a window
        result = run(args.project, args.screenshot)
        return 0 if result is None else int(result)
    except (cli.GlassbenchError, OSError, ValueError, ImportError) as exc:
        print(f"glassbench: error: {cli.one_line(exc)}", file=sys.stderr)
        return cli.EXIT_ERROR
    except KeyboardInterrupt:
        return 130
    except Exception as exc:  # why: the console script never shows a traceback
        if os.environ.get("GLASSBENCH_DEBUG"):
            raise
        print(f"glassbench: internal error: {type(exc).__name__}: {cli.one_line(exc)}",
              file=sys.stderr)
        return cli.EXIT_ERROR


def headless_preview(project: str | None) -> int:
    """Render ``project`` (default: the Bordeaux sample) to a PNG in the temp folder."""
    from engine import cli
    path = project or str(SAMPLE_PROJECT)
    if not os.path.isfile(path):
        raise cli.CliError(f"no display, and the sample project {path} is missing")
    out = os.path.join(tempfile.gettempdir(), f"glassbench-{Path(path).stem}.png")
    print(f"glassbench: no display; rendering {path} to {out}", file=sys.stderr)
    status = cli.main(["render", path, "-o", out])
    if status == 0:
        print(out)
    return status


if __name__ == "__main__":
    sys.exit(main())
