"""``glassbench export-cad / export-scene / share / drawing``: handing the design on, from the
command line.

Design rule: each subcommand loads the project, checks its own options against
:mod:`engine.limits` (tolerances, poster height), calls the one engine function the window
calls too (:func:`engine.export.cad.export_cad`, :func:`engine.export.gltf_scene.export_scene`,
:func:`engine.export.share.write_share`, :func:`engine.export.drawing.write_drawing`) and prints what it wrote and what was checked: the
solids read back with their volumes against ``glassbench info``'s, the scene's counts, the
page's folder. Errors are the engine's one-line errors (``engine.cli.main`` prints them, exit
status 2); OpenCascade is imported only by ``export-cad``.
"""
from __future__ import annotations

import sys

from .. import limits
from ..errors import CliError

#: Default chordal tolerance (mm) of the scene's meshes.
SCENE_TOL_MM = 0.05


def add_parsers(sub) -> None:
    """Add ``export-cad``, ``export-scene``, ``share`` and ``drawing`` to an argparse subparsers
    object."""
    cad = sub.add_parser("export-cad", help="write glass, liquid and closure as CAD solids (STEP/IGES/BREP)")
    cad.add_argument("project")
    cad.add_argument("out", metavar="OUT.step|.iges|.brep")
    cad.add_argument("--tol", type=float, default=None,
                     help="largest distance of a fitted B-spline from the exact surface, mm (default 0.001)")
    cad.add_argument("--no-liquid", action="store_true", help="leave the liquid out")
    scene = sub.add_parser("export-scene", help="write the complete glTF 2.0 scene (.glb)")
    scene.add_argument("project")
    scene.add_argument("out", metavar="OUT.glb")
    scene.add_argument("--tol", type=float, default=SCENE_TOL_MM, help="chordal tolerance of the meshes, mm")
    share = sub.add_parser("share", help="write a self-contained review page folder")
    share.add_argument("project")
    share.add_argument("-o", "--output", required=True, metavar="DIR")
    share.add_argument("--tol", type=float, default=SCENE_TOL_MM, help="chordal tolerance of the scene, mm")
    share.add_argument("--poster-height", type=int, default=None,
                       help="poster height in pixels (default: the design's, at most 640)")
    share.add_argument("--turntable", default=None, metavar="DIR",
                       help="a rendered turntable (glassbench turntable -o DIR) to include")
    share.add_argument("--denoise", action="store_true",
                       help="denoise the poster (Intel Open Image Denoise) and keep the raw one beside it as "
                            "poster.raw.png; the page says which it shows")
    drawing = sub.add_parser("drawing", help="write the glass plant's drawing (PDF, SVG or DXF)")
    drawing.add_argument("project")
    drawing.add_argument("out", nargs="?", default=None, metavar="OUT.pdf|.svg|.dxf")
    drawing.add_argument("-o", "--output", default=None, metavar="OUT.pdf|.svg|.dxf",
                         help="the file to write (or give it after PROJECT)")
    drawing.add_argument("--sheet", choices=("A3", "A4"), default="A3", help="paper, landscape (default A3)")
    drawing.add_argument("--scale", default=None, metavar="1:N",
                         help="the drawing's scale (default: the largest of 2:1, 1:1, 1:2, 1:5, 1:10, 1:20 that fits)")


def _load(path):
    from ..files.project import load_project
    return load_project(path)


def _progress(fraction: float, message: str) -> None:
    print(f"\r{100 * fraction:5.1f} % {message:<48.48}", end="", file=sys.stderr, flush=True)


def cmd_export_cad(args) -> int:
    """``export-cad PROJECT OUT [--tol MM] [--no-liquid]``."""
    try:
        from ..export.cad import DEFAULT_TOL_MM, export_cad
    except ImportError as exc:
        raise CliError(f"CAD export needs OpenCascade (cadquery-ocp): {exc}") from None
    tol = DEFAULT_TOL_MM if args.tol is None else args.tol
    limits.check_range("--tol", tol, (1e-6, 1.0), "mm")
    design, _ = _load(args.project)
    report = export_cad(design, args.out, tol, liquid=not args.no_liquid)
    for body in report["bodies"]:
        line = f"  {body['name']}: valid, closed, {body['volume_mm3'] / 1000.0:.6f} cm3"
        if body["relative_error"] is not None:
            line += f" (info {body['expected_mm3'] / 1000.0:.6f} cm3, relative {body['relative_error']:.1e})"
        if body["deviation_mm"]:
            line += f", B-spline within {body['deviation_mm']:.1e} mm"
        print(line)
    print(f"wrote {args.out}")
    return 0


def cmd_export_scene(args) -> int:
    """``export-scene PROJECT OUT.glb [--tol MM]``."""
    from ..export.gltf_scene import export_scene
    limits.check_range("--tol", args.tol, (limits.MIN_TOL_MM, limits.MAX_TOL_MM), "mm")
    design, assets = _load(args.project)
    stats = export_scene(design, assets, args.out, args.tol)
    print(f"  {stats.meshes} meshes ({stats.labels} labels, front and back), {stats.textures} "
          f"textures, {stats.vertices:,} vertices at {args.tol:g} mm")
    print(f"wrote {args.out}")
    return 0


def cmd_share(args) -> int:
    """``share PROJECT -o DIR [--tol MM] [--poster-height PX] [--turntable DIR] [--denoise]``."""
    from ..export.share import write_share
    limits.check_range("--tol", args.tol, (limits.MIN_TOL_MM, limits.MAX_TOL_MM), "mm")
    if args.poster_height is not None:
        limits.check_range("--poster-height", args.poster_height, limits.HEIGHT_RANGE, integer=True)
    design, assets = _load(args.project)
    out = write_share(design, assets, args.output, args.tol, args.poster_height, args.turntable,
                      progress=_progress if sys.stderr.isatty() else None, denoise=args.denoise)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    if args.denoise:
        print(f"  poster.png denoised, the raw render beside it as {out / 'poster.raw.png'}")
    print(f"wrote {out / 'index.html'}")
    return 0


def cmd_drawing(args) -> int:
    """``drawing PROJECT -o OUT.pdf|.svg|.dxf [--sheet A3|A4] [--scale 1:N]`` (or ``OUT`` after
    ``PROJECT``)."""
    from ..export.drawing import write_drawing
    if (args.out is None) == (args.output is None):
        raise CliError("give the file to write once: drawing PROJECT -o OUT.pdf (or .svg, .dxf)")
    out = args.output or args.out
    design, _ = _load(args.project)
    report = write_drawing(design, out, sheet=args.sheet, scale=args.scale)
    print(f"  {report['sheet']} landscape at {report['scale']}: {', '.join(report['views'])}; "
          f"{len(report['dimensions'])} dimensions")
    print(f"wrote {out}")
    return 0
