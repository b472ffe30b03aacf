"""``glassbench labels``, ``glassbench dieline`` and ``glassbench label PROJECT add|remove``.

Design rule: what the printer and a scripted variant need, over the engine's public API only.
Every number is checked against :mod:`engine.limits` before the project is read, and every
label against ``check_design`` (so on the wall, at most once around, or on a closure it fits
on: ``label add --on cap-top|cap-skirt``) before it is saved, which
is atomic (:func:`engine.files.project.save_project`). Warnings where a label cannot lie flat go
to stderr as ``glassbench COMMAND: warning: label 'NAME': ...``, one a line; errors are the
usual one line and status 2 (:func:`engine.cli.main`). Units: mm, degrees.
"""
from __future__ import annotations

import json
import os
import re
import sys

from .. import limits as L
from ..errors import GlassbenchError, shown
from ..model.design import LABEL_SURFACES
from ..appearance.images import read_image_file
from ..color import hex_to_linear
from ..appearance.report import describe
from ..operations import labels as ops
from ..appearance.presets import DEFAULT_SHEET, SHEET_PRESETS


class LabelCliError(GlassbenchError, ValueError):
    """A labels command-line problem (one line, status 2)."""


def add_parsers(sub) -> None:
    """Add ``labels``, ``dieline`` and ``label`` to the subcommand parsers ``sub``."""
    p = sub.add_parser("labels", help="each label's area, flat die-line, largest strain, warnings")
    p.add_argument("project")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p = sub.add_parser("dieline", help="write a label's flat die-line (SVG, PDF or DXF, 1:1)")
    p.add_argument("project")
    p.add_argument("label", help="the label's name (or its index from 0)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.svg|pdf|dxf")
    p = sub.add_parser("label", help="add or remove a label (saves the project)")
    p.add_argument("project")
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    d, s, t = SHEET_PRESETS[DEFAULT_SHEET]
    add = actions.add_parser("add", help="add a label with IMAGE as its front")
    add.add_argument("image", metavar="IMAGE")
    add.add_argument("--on", choices=LABEL_SURFACES, default="wall",
                     help="where: the bottle's wall (default), or printed on the cap's top or skirt")
    add.add_argument("--z", type=float, default=None,
                     help="height of the centre above the standing plane (mm; on the wall, required), "
                          "or above the skirt's lower edge (cap-skirt; default: mid-skirt)")
    add.add_argument("--x", type=float, default=0.0, help="cap-top: the centre's x from the axis (mm)")
    add.add_argument("--y", type=float, default=0.0, help="cap-top: the centre's y from the axis (mm)")
    add.add_argument("--height", type=float, required=True, help="height along the wall or skirt (mm)")
    add.add_argument("--width", type=float, required=True, help="arc length around the girth (mm)")
    add.add_argument("--angle", type=float, default=None,
                     help="azimuth of the centre, or cap-top: of the reader (deg; default: facing the camera)")
    add.add_argument("--back", default=None, metavar="COLOUR|IMAGE",
                     help="the back: #rrggbb (sRGB), r,g,b (linear 0..1) or an image file")
    add.add_argument("--diffuse", type=float, default=d, help=f"diffuse K (default {d:g})")
    add.add_argument("--specular", type=float, default=s, help=f"specular coat (default {s:g})")
    add.add_argument("--transmission", type=float, default=t, help=f"diffuse transmission (default {t:g})")
    add.add_argument("--name", default=None, help="the label's name (default: from IMAGE)")
    rm = actions.add_parser("remove", help="remove a label")
    rm.add_argument("name", metavar="LABEL")


def _warn(command: str, report) -> None:
    for w in report.warnings:
        print(f"glassbench {command}: warning: label {report.name!r}: {w.message}", file=sys.stderr)


def cmd_labels(args) -> int:
    """``labels PROJECT [--json]``: area (mm^2), die-line, largest strain and warnings."""
    from ..files.project import load_project
    from ..appearance.report import label_report
    design, _ = load_project(args.project)
    reports = [label_report(design, i) for i in range(len(design.labels))]
    for r in reports:
        _warn("labels", r)
    if args.json:
        print(json.dumps({"project": design.name, "labels": [r.to_json() for r in reports]},
                         indent=2, allow_nan=False))
        return 0
    if not reports:
        print(f"{design.name}: no labels")
    for r in reports:
        print(f"{r.name}: {describe(r.flat.figures)}, area {r.area_mm2:.1f} mm2, "
              f"largest strain {100 * r.max_strain:.2f} %, {len(r.warnings)} warning(s)")
    return 0


def find_label(design, key: str) -> int:
    """Index of the label called ``key`` (or numbered ``key`` from 0); ``LabelCliError`` else."""
    try:
        return ops.find_label(design, key)
    except GlassbenchError as exc:
        raise LabelCliError(str(exc).replace("the design has", "the project has")) from None


def cmd_dieline(args) -> int:
    """``dieline PROJECT LABEL -o OUT``: the flat shape with dimensions, 1:1."""
    from ..files.project import load_project
    from ..appearance.report import label_report
    from ..appearance.dieline_files import FORMATS, write_dieline
    if os.path.splitext(args.output)[1].lower() not in FORMATS:
        raise LabelCliError(f"the die-line must end in .svg, .pdf or .dxf, got {shown(args.output, 200)}")
    design, _ = load_project(args.project)
    report = label_report(design, find_label(design, args.label))
    _warn("dieline", report)
    write_dieline(report, args.output, design.name)
    print(f"wrote {args.output}")
    return 0


def parse_colour(text: str):
    """Linear RGB of ``#rrggbb`` (sRGB) or ``r,g,b`` (linear, 0..1), or ``None`` if neither."""
    if re.fullmatch(r"#[0-9a-fA-F]{6}", text):
        return hex_to_linear(text)
    parts = text.split(",")
    if len(parts) == 3:
        try:
            rgb = tuple(float(p) for p in parts)
        except ValueError:
            return None
        for c, v in enumerate(rgb):
            L.check_range(f"--back[{c}]", v, L.LABEL_COLOR_RANGE)
        return rgb
    return None


def cmd_label(args) -> int:
    """``label PROJECT add IMAGE ...`` / ``label PROJECT remove LABEL``: the operations of
    :mod:`engine.operations.labels`, checked and saved."""
    from ..files.project import load_project, save_project
    from ..operations.check import check_design
    if args.action == "remove":
        design, assets = load_project(args.project)
        i = find_label(design, args.name)
        edit = ops.remove_label(design, i)
        save_project(args.project, edit.design, edit.assets_after(assets))
        print(f"removed label {design.labels[i].name!r} from {args.project}")
        return 0
    if args.on == "wall" and args.z is None:
        raise LabelCliError("a label on the wall needs --z (the height of its centre, mm)")
    for flag, value, bounds, unit in (("--z", 0.0 if args.z is None else args.z, (0.0, L.MAX_EXTENT_MM), "mm"),
                                      ("--x", args.x, (-L.MAX_EXTENT_MM, L.MAX_EXTENT_MM), "mm"),
                                      ("--y", args.y, (-L.MAX_EXTENT_MM, L.MAX_EXTENT_MM), "mm"),
                                      ("--height", args.height, L.LABEL_SIZE_RANGE_MM, "mm"),
                                      ("--width", args.width, L.LABEL_SIZE_RANGE_MM, "mm"),
                                      ("--diffuse", args.diffuse, L.LABEL_COEFFICIENT_RANGE, ""),
                                      ("--specular", args.specular, L.LABEL_COEFFICIENT_RANGE, ""),
                                      ("--transmission", args.transmission, L.LABEL_COEFFICIENT_RANGE, "")):
        L.check_range(flag, value, bounds, unit)
    if args.angle is not None:
        L.check_range("--angle", args.angle, (-L.MAX_TURN_DEG, L.MAX_TURN_DEG), "deg")
    front = read_image_file(args.image)
    back = parse_colour(args.back) if args.back is not None else None
    if args.back is not None and back is None:
        back = read_image_file(args.back)
    design, assets = load_project(args.project)
    at = None
    if args.z is not None or args.angle is not None:
        at = (args.z, args.angle if args.angle is not None else ops.camera_azimuth_deg(design.camera))
    edit = ops.add_label(design, assets, front, name=args.name, filename=args.image, back=back, at=at,
                         height_mm=args.height, width_mm=args.width, surface=args.on, cap_xy=(args.x, args.y),
                         coefficients=(args.diffuse, args.specular, args.transmission), exact=True)
    assets = edit.assets_after(assets)
    check_design(edit.design, assets)
    from ..appearance.report import label_report
    report = label_report(edit.design, len(edit.design.labels) - 1)
    _warn("label", report)
    save_project(args.project, edit.design, assets)
    print(f"added label {edit.design.labels[-1].name!r} to {args.project} ({describe(report.flat.figures)})")
    return 0
