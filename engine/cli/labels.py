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

import dataclasses
import json
import math
import os
import re
import sys

from .. import limits as L
from ..errors import GlassbenchError, shown
from ..model.design import LABEL_SURFACES, Label, LabelSide
from ..appearance.images import image_extension, read_image_file
from ..color import hex_to_linear
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


def describe(fig: dict) -> str:
    """A die-line's figures in words."""
    if fig.get("surface") == "cap-top":
        return (f"rectangle {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm on the cap's top "
                f"(a flat disk {fig['disk_diameter_mm']:.2f} mm across)")
    if fig.get("surface") == "cap-skirt":
        return (f"rectangle {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm on the cap's skirt "
                f"({fig['skirt_girth_mm']:.2f} mm around, {fig['skirt_height_mm']:.2f} mm high)")
    if fig["kind"] == "rectangle":
        return f"rectangle {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm"
    if fig["kind"] == "sector":
        return (f"sector r {fig['r_inner_mm']:.2f}..{fig['r_outer_mm']:.2f} mm, "
                f"{fig['angle_deg']:.2f} deg")
    return f"outline {fig['width_mm']:.2f} x {fig['height_mm']:.2f} mm"


def find_label(design, key: str) -> int:
    """Index of the label called ``key`` (or numbered ``key`` from 0); ``LabelCliError`` else."""
    names = [lab.name for lab in design.labels]
    if key in names:
        return names.index(key)
    if key.isdigit() and int(key) < len(names):
        return int(key)
    have = ", ".join(repr(n) for n in names[:8]) or "none"
    raise LabelCliError(f"the project has no label {shown(key)} (its labels: {have})")


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


def asset_name(name: str, role: str, data, taken) -> str:
    """A plain file name for a label image (``label-NAME-ROLE.ext``), unused in ``taken``."""
    stem = re.sub(r"[^\w\- ]+", "_", name).strip(" _.")[:80] or "label"
    ext = image_extension(data)
    base = f"label-{stem}-{role}"
    out, k = base + ext, 2
    while out in taken:
        out, k = f"{base}-{k}{ext}", k + 1
    return out


def camera_azimuth_deg(camera) -> float:
    """Azimuth (deg, from +x towards +y) of the camera's eye about the z axis: a label there
    faces the camera (the front, -90, for an eye on the axis)."""
    x, y = camera.eye[0], camera.eye[1]
    return math.degrees(math.atan2(y, x)) if math.hypot(x, y) > 1e-9 else -90.0


def cmd_label(args) -> int:
    """``label PROJECT add IMAGE ...`` / ``label PROJECT remove LABEL``; saves the project."""
    from ..files.project import load_project, save_project
    from ..operations.check import check_design
    from ..appearance.cap_surfaces import cap_surface
    if args.action == "remove":
        design, assets = load_project(args.project)
        i = find_label(design, args.name)
        labels = design.labels[:i] + design.labels[i + 1:]
        kept = {n for lab in labels for n in lab.asset_names()} | {design.environment.asset}
        gone = set(design.labels[i].asset_names()) - kept
        save_project(args.project, dataclasses.replace(design, labels=labels),
                     {k: v for k, v in assets.items() if k not in gone})
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
    back_colour = parse_colour(args.back) if args.back is not None else None
    back_data = read_image_file(args.back) if args.back is not None and back_colour is None else None
    design, assets = load_project(args.project)
    names = {lab.name for lab in design.labels}
    name = args.name or os.path.splitext(os.path.basename(args.image))[0] or "label"
    if args.name is None:
        base, k = name, 2
        while name in names:
            name, k = f"{base} {k}", k + 1
    front_asset = asset_name(name, "front", front, assets)
    assets = {**assets, front_asset: front}
    back = LabelSide(color=back_colour or (1.0, 1.0, 1.0))
    if back_data is not None:
        back = LabelSide(asset_name(name, "back", back_data, assets))
        assets[back.asset] = back_data
    angle = args.angle if args.angle is not None else camera_azimuth_deg(design.camera)
    z = args.z
    if z is None:  # wall labels have it; a print on a cap is centred on the skirt, or unused
        z = 0.5 * cap_surface(design, "cap-skirt", f"label {name!r}").height_mm if args.on == "cap-skirt" else 0.0
    label = Label(name, LabelSide(front_asset), back, z, angle, args.height, args.width,
                  args.diffuse, args.specular, args.transmission, surface=args.on, cap_x_mm=args.x,
                  cap_y_mm=args.y)
    new = dataclasses.replace(design, labels=design.labels + (label,))
    check_design(new, assets)
    from ..appearance.report import label_report
    report = label_report(new, len(new.labels) - 1)
    _warn("label", report)
    save_project(args.project, new, assets)
    print(f"added label {name!r} to {args.project} ({describe(report.flat.figures)})")
    return 0
