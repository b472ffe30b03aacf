"""``glassbench stage``: what the bottle stands on, from the command line.

Design rule: as :mod:`engine.cli.finishes`: the handler loads the project, makes the one change
(merged into the project's stage: what is not given stays), runs the project's own check and
saves atomically (:func:`engine.cli.finishes._save`, the previous file kept as ``.bak``), so a
refused change leaves the file untouched. The kinds, their alias and which fields a kind draws
are :mod:`engine.operations.stage`'s, as for the Stage panel and the batch override. Colours
are typed and shown in sRGB hex; the model keeps them linear (:mod:`engine.color`).
"""
from __future__ import annotations

import argparse

from ..color import linear_to_hex
from ..errors import CliError, shown
from ..limits import check_range
from ..operations.stage import KIND_NAMES, STAGE_USES, set_stage, stage_kind
from .finishes import _save, srgb_hex_to_linear

#: The option that sets each ``Stage`` field (for the messages).
OPTIONS = {"color": "--colour", "gloss": "--gloss", "backdrop": "--backdrop"}
#: What each kind is, in the words ``show`` prints.
KIND_WORDS = {"none": "none (the bottle floats in its environment)", "shadow": "shadow catcher",
              "table": "table", "glossy": "glossy riser", "mirror": "mirror"}


def add_parsers(sub) -> None:
    """Add the ``stage`` subcommand to an argparse subparsers object."""
    p = sub.add_parser("stage", help="set or show what the bottle stands on")
    p.add_argument("project")
    p.add_argument("action", choices=("set", "show"))
    p.add_argument("kind", nargs="?", metavar="KIND", help=f"set: {KIND_NAMES}")
    p.add_argument("--colour", "--color", dest="colour", default=None, metavar="HEX",
                   help="sRGB colour of the table or riser, or the mirror's tint, e.g. '#8c8c8c'")
    p.add_argument("--gloss", type=float, default=None, metavar="G",
                   help="glossy riser: how sharp its clear coat reflects, 0..1 (1: mirror-sharp)")
    p.add_argument("--backdrop", action=argparse.BooleanOptionalAction, default=None,
                   help="table or riser: raise its sheet behind the bottle in a cyclorama sweep "
                        "(--no-backdrop: take it away)")


def describe(stage) -> str:
    """One line naming ``stage``'s kind and the fields that kind draws (colour in sRGB hex and
    linear RGB, as a job file may give it)."""
    uses = STAGE_USES[stage.kind]
    parts = [KIND_WORDS[stage.kind]]
    if "color" in uses:
        linear = ", ".join(f"{c:.4g}" for c in stage.color)
        parts.append(f"colour {linear_to_hex(stage.color)} (linear {linear})")
    if "gloss" in uses:
        parts.append(f"gloss {stage.gloss:g}")
    if "backdrop" in uses and stage.backdrop:
        parts.append("with its backdrop sweep")
    return ", ".join(parts)


def cmd_stage(args) -> int:
    """``stage PROJECT set KIND [--colour HEX] [--gloss G] [--backdrop | --no-backdrop]``,
    ``stage PROJECT show``."""
    from ..files.project import load_project
    design, assets = load_project(args.project)
    given = {"color": args.colour, "gloss": args.gloss, "backdrop": args.backdrop}
    given = {k: v for k, v in given.items() if v is not None}
    if args.action == "show":
        if args.kind is not None or given:
            raise CliError("stage show takes no KIND and no options")
        print(f"stage: {describe(design.stage)}")
        return 0
    if args.kind is None:
        raise CliError(f"stage set needs a KIND: {KIND_NAMES}")
    if stage_kind(args.kind) is None:
        raise CliError(f"stage set KIND: {shown(args.kind)} is not one of {KIND_NAMES}")
    if "color" in given:
        given["color"] = srgb_hex_to_linear(given["color"])
    if "gloss" in given:
        check_range("--gloss", given["gloss"], (0.0, 1.0))
    edit = set_stage(design, typed=OPTIONS, kind=args.kind, **given)
    new = design if edit is None else edit.design
    _save(args.project, new, assets)
    print(f"wrote {args.project}: stage {describe(new.stage)}")
    return 0
