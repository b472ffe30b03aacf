"""Build ``labelled.glassbench`` from ``bordeaux.glassbench``: ``python resources/make_labelled.py``.

The Bordeaux sample with the sample wine label of :mod:`engine.appearance.sample` (artwork
drawn with numpy and embedded as PNG, a gold-foil chroma region, a cream back). Rerun after
changing the Bordeaux sample or the format.
"""
from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from engine.appearance.sample import labelled  # noqa: E402
from engine.files.project import load_project, save_project  # noqa: E402


def main() -> None:
    design, assets = load_project(HERE / "bordeaux.glassbench")
    design, assets = labelled(design, assets)
    design = design.__class__(**{**design.__dict__, "name": "Bordeaux, labelled"})
    save_project(HERE / "labelled.glassbench", design, assets, keep_backup=False)
    print("wrote", HERE / "labelled.glassbench")


if __name__ == "__main__":
    main()
