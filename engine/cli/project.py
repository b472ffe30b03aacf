"""``glassbench info | export-mesh | new``: a project's trade numbers, its glass as a mesh, a
project from a DXF section (round, or an outline bottle with a DXF plan).

Design rule: small functions over the engine's public API (:mod:`engine.cli` rule); units mm.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from .. import limits
from ..errors import CliError, GlassbenchError, shown
from ..geometry.outline_from_section import DEFAULT_ROUND_MM
from ..geometry.shape import BottleShape
from ..model.design import Camera, Design, RenderSettings
from ..operations.trade import format_table, trade_numbers


#: ``glassbench new --help``: the rule that makes an outline bottle of a section and a plan.
NEW_HELP = (
    "Without --plan: a round bottle revolved from SECTION.dxf. With --plan: an outline bottle "
    "whose front view is SECTION.dxf and whose body's plan is PLAN.dxf. Draw both in one frame: "
    "the plan's x is the front view's x and its origin the bottle's axis, and the plan's reach "
    "along +x equals the section's widest radius (within 1 percent). At every height the bottle "
    "reaches the section's radius along +x; the plan's corners are rounded by --round where the "
    "body is widest, the rounding changing linearly with the radius to the mouth's radius at the "
    "mouth, where the plan has shrunk to nothing and the neck is round. The section may not be "
    "narrower than its mouth below it; a punt is stood on a flat base (outline bottles have one).")


def add_parsers(sub) -> None:
    """The subparsers of ``info``, ``export-mesh`` and ``new``."""
    info = sub.add_parser("info", help="capacity, glass volume, size, stability and stress of a project")
    info.add_argument("project")
    info.add_argument("--json", action="store_true", help="print one JSON object")
    mesh = sub.add_parser("export-mesh", help="write the bottle as STL/OBJ/PLY/glTF")
    mesh.add_argument("project")
    mesh.add_argument("out")
    mesh.add_argument("--tol", type=float, default=0.05, help="chordal tolerance (mm)")
    new = sub.add_parser("new", help="create a project from a DXF section (and a DXF plan outline)",
                         description=NEW_HELP)
    new.add_argument("--from-dxf", required=True, metavar="SECTION.dxf",
                     help="the right half of the bottle's front view (x: radius, y: height; mm)")
    new.add_argument("out", metavar="OUT.glassbench")
    new.add_argument("--plan", default=None, metavar="PLAN.dxf",
                     help="the body's plan (top view) at its widest section, axis at the origin: "
                          "one closed convex loop of lines and arcs (mm); makes an outline bottle")
    new.add_argument("--round", type=float, default=None, metavar="MM",
                     help=f"with --plan: the rounding of the plan's corners where the body is widest "
                          f"(mm, default {DEFAULT_ROUND_MM:g})")
    new.add_argument("--wall", type=float, default=3.0, help="wall thickness (mm)")
    new.add_argument("--base", type=float, default=6.0, help="base thickness (mm)")
    new.add_argument("--name", default=None)


def cmd_info(args) -> int:
    """``info PROJECT [--json]``: trade numbers (ml, mm, cm^3, g) and the plant's (stability,
    capacity band, tolerances, membrane stress: :func:`engine.plant.sheet.plant_numbers`) as a
    table or JSON (the plant's under ``"plant"``)."""
    from ..files.project import load_project
    from ..plant.sheet import format_plant, plant_numbers
    design, _ = load_project(args.project)
    numbers = trade_numbers(design)
    plant = plant_numbers(design)
    if args.json:
        print(json.dumps({**numbers, "plant": plant}, indent=2, allow_nan=False))
    else:
        print(format_table(numbers))
        print(format_plant(plant))
    return 0


# --------------------------------------------------------------------------- export-mesh

def cmd_export_mesh(args) -> int:
    """``export-mesh PROJECT OUT [--tol MM]``: the glass body as a mesh (format from OUT's suffix)."""
    from ..files.project import load_project
    limits.check_range("--tol", args.tol, (limits.MIN_TOL_MM, limits.MAX_TOL_MM), "mm")
    design, _ = load_project(args.project)
    try:
        from ..files.mesh_export import export_mesh
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
    from ..geometry import capacity
    return 0.5 * float(capacity.max_diameter_mm(shape))


def cmd_new(args) -> int:
    """``new --from-dxf SECTION.dxf [--plan PLAN.dxf [--round MM]] OUT.glassbench``: a round bottle
    (wall/base in mm) from a DXF section, or with ``--plan`` an outline bottle of that section and
    a DXF plan outline (:data:`NEW_HELP`, :mod:`engine.geometry.outline_from_section`), framed by a
    camera; refuses, naming the file, to write an invalid design."""
    from ..files.dxf_import import section_from_dxf
    from ..files.project import SUFFIX, save_project
    from ..operations.check import check_design
    if not args.out.endswith(SUFFIX):
        raise CliError(f"the project file name must end in {SUFFIX}: {shown(args.out, 200)}")
    for flag in ("wall", "base"):
        limits.check_range(f"--{flag}", getattr(args, flag), (0.0, limits.MAX_EXTENT_MM), "mm")
    if args.round is not None and args.plan is None:
        raise CliError("--round rounds a plan outline's corners: give the plan with --plan PLAN.dxf")
    section = section_from_dxf(args.from_dxf)
    source = args.from_dxf
    if args.plan is None:
        shape = BottleShape("round", (("profile", section),), args.wall, args.base)
    else:
        source = f"{args.from_dxf} with plan {args.plan}"
        shape = _outline_shape(section, args, source)
    render = RenderSettings(width=360, height=480)
    name = args.name or Path(args.from_dxf).stem
    try:  # (the framing measures the bottle, so an invalid one fails there first)
        design = Design(shape=shape, camera=framing_camera(shape, render.width, render.height),
                        render=render, name=name)
        check_design(design, {})
    except GlassbenchError as exc:
        raise CliError(f"{source}: {exc}") from None
    save_project(args.out, design, {})
    print(f"wrote {args.out}")
    return 0


def _outline_shape(section, args, source: str) -> BottleShape:
    """The outline bottle of ``section`` and the plan in ``args.plan`` (``--round`` mm); errors
    name both files (``source``)."""
    from ..files.dxf_plan import plan_from_dxf
    from ..geometry.outline_from_section import outline_from_section, size_mismatch
    rounding = DEFAULT_ROUND_MM if args.round is None else args.round
    limits.check_range("--round", rounding, (0.0, limits.MAX_EXTENT_MM), "mm")
    plan = plan_from_dxf(args.plan)
    mismatch = size_mismatch(section, plan)
    if mismatch:
        raise CliError(f"{source}: {mismatch}")
    try:
        return outline_from_section(section, plan, args.wall, args.base, rounding)
    except GlassbenchError as exc:
        raise CliError(f"{source}: {exc}") from None
