"""Build the finish and closure samples in this folder: ``python resources/make_finish_samples.py``.

Design rule: each sample starts from a shape of :mod:`make_samples` (the same builders, mm) and
adds its finishes through the same functions the command line and the panels use
(:func:`engine.operations.tiles.new_tile` / ``add_image_tile``,
:func:`engine.appearance.closure_shapes.default_cap`), so the samples show what a designer gets.
The camera is framed on the bottle with its closure. Writes:

* ``knurled_jar.glassbench``: the wide jar with a knurled base band and a gold lug cap.
* ``threaded_bottle.glassbench``: a 28 mm beverage bottle with a 28-410 thread and a plastic
  screw cap.
* ``cut_decanter.glassbench``: a clear decanter with facets, a diamond band and shoulder flutes.
* ``frosted_logo.glassbench``: a Bordeaux, frosted (GGX alpha 0.3) on the body, with an
  embossed logo (``logo.png``, drawn here with numpy and written with OpenImageIO).
"""
from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

from make_samples import RENDER, bordeaux, bordeaux_section, jar, round_shape  # noqa: E402

from engine.appearance.closure_shapes import default_cap  # noqa: E402
from engine.operations.tiles import add_image_tile, new_tile  # noqa: E402
from engine.cli.project import framing_camera  # noqa: E402
from engine.files.project import save_project  # noqa: E402
from engine.operations.check import check_design  # noqa: E402
from engine.model.design import Design, Glass, Liquid  # noqa: E402


def logo_png(size: int = 256) -> bytes:
    """An embossing logo as 8-bit grey PNG bytes: a ring around a four-pointed star (white is
    raised), anti-aliased by 4x4 supersampling."""
    import OpenImageIO as oiio
    s = 4 * size
    y, x = (np.mgrid[0:s, 0:s] + 0.5) / s * 2.0 - 1.0
    r = np.hypot(x, y)
    ring = (r > 0.78) & (r < 0.92)
    star = np.abs(x) ** 0.5 + np.abs(y) ** 0.5 < 0.62 ** 0.5 * 1.25
    img = (ring | star).astype(np.float32).reshape(size, 4, size, 4).mean(axis=(1, 3))
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "logo.png")
        out = oiio.ImageOutput.create(path)
        out.open(path, oiio.ImageSpec(size, size, 1, "uint8"))
        out.write_image(np.round(img * 255.0).astype(np.uint8))
        out.close()
        return Path(path).read_bytes()


def framed(design: Design) -> Design:
    """``design`` with the camera framing its shape (the closure adds a few mm on top)."""
    return dataclasses.replace(design, camera=framing_camera(design.shape, RENDER.width, RENDER.height))


def knurled_jar() -> Design:
    d = jar()
    knurl = new_tile(d, "knurl", 1.0, 14.0, name="base knurl", sharpness=0.6)
    return framed(dataclasses.replace(d, bumps=(knurl,), cap=default_cap("lug"),
                                      name="Knurled jar, lug cap",
                                      notes="Wide jar with a knurled base and a gold lug cap."))


def threaded_bottle() -> Design:
    top = 230.0
    shape = round_shape(bordeaux_section(150.0, neck_r=14.0, top=top))
    d = Design(shape=shape, glass=Glass(1.52, (0.002, 0.0008, 0.002)),
               liquid=Liquid(1.34, (0.002, 0.004, 0.03), "height", 170.0), render=RENDER)
    thread = new_tile(d, "thread", top - 17.0, top - 1.0, name="28-410 thread", finish="28-410")
    return framed(dataclasses.replace(d, bumps=(thread,), cap=default_cap("screw"),
                                      name="Threaded bottle, screw cap",
                                      notes="Beverage bottle with a 28-410 finish and a screw cap."))


def cut_decanter() -> Design:
    shape = round_shape(bordeaux_section(150.0, neck_r=16.0, top=250.0), 4.0, 9.0)
    d = Design(shape=shape, glass=Glass(1.52, (0.0, 0.0, 0.0)),
               liquid=Liquid(1.36, (0.003, 0.02, 0.06), "height", 120.0), render=RENDER)
    tiles = (new_tile(d, "facets", 14.0, 70.0, name="facets", repeat=16, depth=1.2),
             new_tile(d, "diamond", 78.0, 128.0, name="diamond band", depth=0.9),
             new_tile(d, "flutes", 160.0, 205.0, name="shoulder flutes", repeat=24, depth=0.8))
    return framed(dataclasses.replace(d, bumps=tiles, name="Cut-glass decanter",
                                      notes="Clear decanter: facets, a diamond band, fluted shoulder."))


def frosted_logo(logo: bytes) -> tuple[Design, dict]:
    d = dataclasses.replace(bordeaux(), glass=Glass(1.52, (0.001, 0.0005, 0.001)))
    frost = new_tile(d, "frosted", 15.0, 180.0, name="frosting", alpha=0.3)
    emblem, asset = add_image_tile(d, {}, "emboss", "logo.png", logo, 80.0, 140.0, name="logo",
                                   width_deg=70.0, depth=0.8, angle_deg=-90.0, width=0.08)
    d = dataclasses.replace(d, bumps=(frost, emblem), name="Frosted Bordeaux with logo",
                            notes="Etched body and an embossed logo facing the camera.")
    return framed(d), {asset: logo}


def build_all(folder: Path = HERE) -> dict[str, Design]:
    """Build, check and save the finish samples into ``folder``; returns them by file name."""
    logo = logo_png()
    (folder / "logo.png").write_bytes(logo)
    frosted, assets = frosted_logo(logo)
    samples = {"knurled_jar.glassbench": (knurled_jar(), {}),
               "threaded_bottle.glassbench": (threaded_bottle(), {}),
               "cut_decanter.glassbench": (cut_decanter(), {}),
               "frosted_logo.glassbench": (frosted, assets)}
    for name, (design, extra) in samples.items():
        check_design(design, extra)
        save_project(folder / name, design, extra, keep_backup=False)
        print(f"{name}: {design.name}, {len(design.bumps)} bump tile(s), cap "
              f"{design.cap.kind if design.cap else 'none'}")
    return {k: v[0] for k, v in samples.items()}


if __name__ == "__main__":
    build_all()
