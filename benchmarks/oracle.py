"""Oracle scenes (``/work/shared/oracle/SPEC.md``) as glassbench projects: the command line.

Usage::

    python -m benchmarks.oracle convert SPEC.json OUT.glassbench
    python -m benchmarks.oracle render SPEC.json -o OUT.exr [--spp N]

Design rule: ``convert`` writes the scene of :func:`benchmarks.oracle_spec.spec_to_design` (the
one SPEC mapping, re-exported here) as a checked project; ``render`` hands its arguments to
:mod:`benchmarks.oracle_render`. Dependencies run one way: this module imports both, neither
imports it.
"""
from __future__ import annotations

import argparse
import sys

from benchmarks.oracle_spec import DEFAULT_SPP, MAX_DEPTH, shape_from_spec, spec_to_design
from engine.errors import GlassbenchError

__all__ = ["DEFAULT_SPP", "MAX_DEPTH", "convert", "main", "shape_from_spec", "spec_to_design"]


def convert(spec_path: str, out_path: str, spp: int = DEFAULT_SPP) -> None:
    """Write the SPEC scene at ``spec_path`` as a checked ``.glassbench`` project."""
    from engine.files.project import check_design, save_project
    design, assets = spec_to_design(spec_path, spp)
    check_design(design, assets)
    save_project(out_path, design, assets)


def main(argv: list[str] | None = None) -> int:
    """``convert`` / ``render`` entry point; errors are one line on stderr, status 2."""
    argv = list(sys.argv[1:] if argv is None else argv)
    p = argparse.ArgumentParser(prog="python -m benchmarks.oracle")
    sub = p.add_subparsers(dest="command", required=True)
    c = sub.add_parser("convert", help="SPEC.json -> .glassbench project")
    c.add_argument("spec")
    c.add_argument("out")
    c.add_argument("--spp", type=int, default=DEFAULT_SPP)
    sub.add_parser("render", help="render a SPEC scene (benchmarks.oracle_render)", add_help=False)
    if argv[:1] == ["render"]:
        try:
            from benchmarks import oracle_render
        except ImportError as exc:
            print(f"oracle render: error: benchmarks.oracle_render is not available ({exc})",
                  file=sys.stderr)
            return 2
        result = oracle_render.main(argv[1:])
        return 0 if result is None else int(result)
    args = p.parse_args(argv)
    try:
        convert(args.spec, args.out, args.spp)
    except (GlassbenchError, OSError, ValueError) as exc:
        print(f"oracle convert: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
