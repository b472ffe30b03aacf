"""The ``glassbench`` subcommands that need no window, one module of this package per group
(:data:`DELEGATED`): ``project`` (info, export-mesh, new), ``render``, ``batch`` (batch,
turntable), ``labels`` (labels, dieline, label), ``finishes`` (cap, bump), ``stage``, ``export``
(export-cad, export-scene, share, drawing).

Design rule: each subcommand is a small function over the engine's public API; ``main``
turns every expected failure (a bad project, a bad DXF, a missing file, a tracer that
refuses) into one line on stderr and exit status 2, never a traceback. No Qt here:
``app.main`` hands subcommands to :func:`main` and only opens a window without one.
"""
from __future__ import annotations

import argparse
import importlib
import os
import sys

from ..errors import CliError, GlassbenchError, bounded  # noqa: F401 - CliError for callers

#: Subcommands whose parsers and handlers live with what they do: module (relative to
#: ``engine``) -> its subcommands. Each module offers ``add_parsers(sub)`` and ``cmd_NAME(args)``.
DELEGATED = {".project": ("info", "export-mesh", "new"),
             ".render": ("render",),
             ".batch": ("batch", "turntable"),
             ".labels": ("labels", "dieline", "label"),
             ".finishes": ("cap", "bump"),
             ".stage": ("stage",),
             ".export": ("export-cad", "export-scene", "share", "drawing")}
SUBCOMMANDS = sum(DELEGATED.values(), ())
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
    for module in DELEGATED:
        _delegate(module).add_parsers(sub)
    return p


def _delegate(module: str):
    """The module of :data:`DELEGATED` that owns some subcommands (imported on first use)."""
    return importlib.import_module(module, __package__)


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand; returns the exit status (0 ok, 2 error; argparse exits 2 itself)."""
    args = build_parser().parse_args(argv)
    owner = next(m for m, names in DELEGATED.items() if args.command in names)
    handler = getattr(_delegate(owner), "cmd_" + args.command.replace("-", "_"))
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
