"""``glassbench cap`` and ``glassbench bump``: closures and bump tiles from the command line.

Design rule: :mod:`engine.cli` owns the program; this module adds two subparsers and their
handlers. Each handler loads the project, makes the one change (a tile through
:mod:`engine.operations.tiles`, the operations the bump-tiles panel calls too), runs the project's own check
(:func:`engine.operations.check.check_design`) and saves atomically (the previous file kept as
``.bak``), so a refused change leaves the file untouched. Errors reach ``engine.cli.main``,
which prints one line and exits with status 2.
"""
from __future__ import annotations

from ..color import hex_to_linear
from ..errors import shown
from ..io.read import read_bounded
from ..limits import MAX_ARTWORK_BYTES, BUMP_REPEAT_RANGE, GGX_ALPHA_RANGE, MAX_BUMP_DEPTH_MM, MAX_EXTENT_MM, check_range
from ..model.design import BUMP_KINDS, BUMP_SURFACES, CAP_KINDS, CAP_MATERIALS, THREAD_GEOMETRY

CAP_CHOICES = CAP_KINDS + ("none",)
#: Relief maps by their command-line name (``--map``).
MAP_MODES = {"height": "height_map", "colour-code": "colour_code", "normal-gl": "normal_gl",
             "normal-dx": "normal_dx", "emboss": "emboss"}


def add_parsers(sub) -> None:
    """Add the ``cap`` and ``bump`` subcommands to an argparse subparsers object."""
    cap = sub.add_parser("cap", help="put a closure on the finish (or take it off)")
    cap.add_argument("project")
    cap.add_argument("action", choices=("set",))
    cap.add_argument("kind", choices=CAP_CHOICES, metavar="KIND", help=", ".join(CAP_CHOICES))
    cap.add_argument("--colour", "--color", dest="colour", default=None, metavar="HEX",
                     help="sRGB colour, e.g. '#c8a040' (metal: the lacquer's tint)")
    cap.add_argument("--material", choices=CAP_MATERIALS, default=None)
    cap.add_argument("--height", type=float, default=None, help="cap height (cork: length), mm")
    cap.add_argument("--count", type=int, default=None, help="knurl ridges, crown flutes or lugs")
    cap.add_argument("--no-capsule", action="store_true", help="a cork without its capsule")
    bump = sub.add_parser("bump", help="add, list or remove bump tiles")
    bump.add_argument("project")
    bump.add_argument("action", choices=("add", "list", "remove"))
    bump.add_argument("what", nargs="?", metavar="KIND|INDEX",
                      help="add: knurl, stipple, thread, flutes, facets, diamond, frosted or "
                           "image:FILE; remove: the tile's index (see list)")
    for flag, unit in (("--z0", "mm"), ("--z1", "mm"), ("--depth", "mm"), ("--alpha", "GGX"),
                       ("--angle", "deg"), ("--width-deg", "deg"), ("--pitch", "mm")):
        bump.add_argument(flag, type=float, default=None, help=unit)
    bump.add_argument("--repeat", type=int, default=None, help="repeats around the girth")
    bump.add_argument("--finish", default=None, help="thread standard, e.g. 28-400")
    bump.add_argument("--map", choices=tuple(MAP_MODES), default="height",
                      help="how an image's texels are read (default: height)")
    bump.add_argument("--inverted", action="store_true", help="press in instead of raise")
    bump.add_argument("--geometry", choices=THREAD_GEOMETRY, default=None,
                      help="thread: drawn as relief, as true glass, or auto (true when the ridge "
                           "is large against the wall; default)")
    bump.add_argument("--on", choices=BUMP_SURFACES, default="bottle",
                      help="the glass (heights above the standing plane) or the cap's straight "
                           "skirt (heights above its lower edge)")
    bump.add_argument("--name", default=None)


def srgb_hex_to_linear(text: str) -> tuple[float, float, float]:
    """``'#RRGGBB'`` (or ``RRGGBB``) in sRGB to linear RGB in 0..1; ``ValueError`` otherwise."""
    rgb = hex_to_linear(text)
    if rgb is None:
        raise ValueError(f"--colour {shown(text)} is not a colour like '#c8a040'")
    return rgb


def _save(path, design, assets) -> None:
    from ..files.project import save_project
    from ..operations.check import check_design
    check_design(design, assets)
    save_project(path, design, assets)


def cmd_cap(args) -> int:
    """``cap PROJECT set KIND [--colour HEX] [--material M] [--height MM] [--count N]``."""
    from ..appearance.closures import closure_trade
    from ..files.project import load_project
    from ..operations.closure import set_cap
    design, assets = load_project(args.project)
    changes = {"material": args.material, "height": args.height, "count": args.count,
               "capsule": False if args.no_capsule else None,
               "color": None if args.colour is None else srgb_hex_to_linear(args.colour)}
    edit = set_cap(design, args.kind, **changes)
    new = design if edit is None else edit.design
    _save(args.project, new, assets)
    if new.cap is None:
        print(f"wrote {args.project}: no closure")
        return 0
    info, overall = closure_trade(new)
    print(f"wrote {args.project}: {info['kind']} closure {info['diameter_mm']:.1f} mm across, "
          f"{info['height_mm']:.1f} mm high; overall height {overall:.1f} mm")
    return 0


def cmd_bump(args) -> int:
    """``bump PROJECT add KIND --z0 MM --z1 MM [...]`` (a thread: ``--geometry
    auto|relief|true``), ``bump PROJECT list`` (a thread's line says how it is drawn and why),
    ``bump PROJECT remove INDEX``."""
    from ..errors import CliError
    from ..files.project import load_project
    design, assets = load_project(args.project)
    if args.action == "list":
        from ..appearance.bands import thread_drawings
        for i, (t, drawing) in enumerate(zip(design.bumps, thread_drawings(design))):
            where = "" if t.on == "bottle" else (" on the cap" if design.cap is not None else
                                                 " on the cap (no cap: not drawn)")
            how = f"; drawn as {drawing.reason}" if drawing is not None else ""
            print(f"{i}: {t.name} ({t.kind}) z {t.z0:g}..{t.z1:g} mm{where}, x{t.repeat}, "
                  f"depth {t.depth:g} mm{how}")
        return 0
    from ..operations import tiles
    if args.action == "remove":
        try:
            index = int(args.what)
        except (TypeError, ValueError):
            raise CliError(f"bump remove needs a tile index, got {shown(args.what)}") from None
        if not 0 <= index < len(design.bumps):
            raise CliError(f"the project has no bump tile {index} (it has {len(design.bumps)})")
        edit = tiles.remove_tile(design, index)
        _save(args.project, edit.design, edit.assets_after(assets))
        print(f"wrote {args.project}: {len(edit.design.bumps)} bump tile(s)")
        return 0
    edit = _add_tile(args, design, assets, CliError)
    _save(args.project, edit.design, edit.assets_after(assets))
    tile = edit.design.bumps[-1]
    where = " above the lower edge of the cap's skirt" if tile.on == "cap" else ""
    print(f"wrote {args.project}: added {tile.name} ({tile.kind}) on z {tile.z0:g}..{tile.z1:g} mm{where}")
    return 0


def _add_tile(args, design, assets, CliError):
    """The :func:`engine.operations.tiles.add_tile` edit the arguments ask for."""
    from ..operations.tiles import add_tile
    what = args.what or ""
    if args.z0 is None or args.z1 is None:
        raise CliError("bump add needs the band's heights: --z0 MM --z1 MM")
    ext = (-MAX_EXTENT_MM, MAX_EXTENT_MM)
    check_range("--z0", args.z0, ext, "mm")
    check_range("--z1", args.z1, ext, "mm")
    for flag, value, bounds in (("--depth", args.depth, (0.0, MAX_BUMP_DEPTH_MM)),
                                ("--alpha", args.alpha, GGX_ALPHA_RANGE)):
        if value is not None:
            check_range(flag, value, bounds)
    if args.repeat is not None:
        check_range("--repeat", args.repeat, BUMP_REPEAT_RANGE, integer=True)
    given = dict(repeat=args.repeat, depth=args.depth, alpha=args.alpha, angle_deg=args.angle,
                 width_deg=args.width_deg, pitch=args.pitch, name=args.name,
                 inverted=True if args.inverted else None, on=args.on)
    given = {k: v for k, v in given.items() if v is not None}
    if what.startswith("image:"):
        path = what[len("image:"):]
        data = read_bounded(path, MAX_ARTWORK_BYTES, "relief image")
        return add_tile(design, assets, MAP_MODES[args.map], args.z0, args.z1, image=data,
                        filename=path, **given)
    procedural = tuple(k for k in BUMP_KINDS if k not in MAP_MODES.values())
    if what not in procedural:
        raise CliError(f"bump add KIND: {shown(what)} is not one of {', '.join(procedural)} "
                       f"or image:FILE")
    if args.finish is not None:
        given["finish"] = args.finish
    if args.geometry is not None:
        if what != "thread":
            raise CliError(f"--geometry is for threads only, not {shown(what)}")
        given["geometry"] = args.geometry
    return add_tile(design, assets, what, args.z0, args.z1, **given)
