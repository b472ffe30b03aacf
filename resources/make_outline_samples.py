"""Build the free-plan samples in this folder: ``python resources/make_outline_samples.py``.

Design rule: as :mod:`make_samples`, every sample comes from a few designer-facing numbers (mm)
and is checked and saved; here the plan is a free convex outline (SPEC_outline) scaled by a
*core* profile ``k(z)`` and rounded by a *rounding* profile ``c(z)``. Both profiles share one
shape of shoulder: the core turns in over a convex arc and runs into the axis (the plan
vanishes into the round neck), while the rounding grows from the body's corner radius to the
neck's radius over an S of two equal arcs ending at the same height. Writes:

* ``flacon.glassbench``: a hexagonal perfume flacon, 56 mm across the flats, a heavy 10 mm base,
  110 ml brimful, 100 ml of pale gold perfume, a paper label on the front panel.
* ``hip_flask.glassbench``: a hip flask of four arcs (100 x 36 mm), 212 ml brimful, 200 ml of
  amber spirit.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from resources.make_samples import report, solve  # noqa: E402

from engine.geometry import capacity  # noqa: E402

from engine.appearance.sample import png_bytes, sample_artwork, sample_label  # noqa: E402
from engine.cli.project import framing_camera  # noqa: E402
from engine.files.project import save_project  # noqa: E402
from engine.geometry.plan import flask, hexagon  # noqa: E402
from engine.geometry.section import Section  # noqa: E402
from engine.geometry.segments import Arc, Line  # noqa: E402
from engine.geometry.shape import BottleShape  # noqa: E402
from engine.model.design import Design, Glass, Liquid, RenderSettings  # noqa: E402
from engine.operations.check import check_design  # noqa: E402

RENDER = RenderSettings(width=360, height=480, spp=16)


def core_profile(k: float, z_s: float, shoulder_r: float, angle_deg: float, neck_r: float, top: float):
    """The core ``k`` (mm) from the base to ``z_s``, a convex shoulder arc of ``shoulder_r``
    turning ``angle_deg`` in, a straight shoulder, a concave arc of ``neck_r`` turning back up
    into the axis (the core vanishes: a round neck), then the axis up to ``top``. Returns
    ``(section, z_neck)``, the height where the core is 0."""
    a = math.radians(angle_deg)
    centre = (k - shoulder_r, z_s)
    p = (centre[0] + shoulder_r * math.cos(a), z_s + shoulder_r * math.sin(a))
    run = (p[0] - neck_r * (1.0 - math.cos(a))) / math.sin(a)  # the straight shoulder's length
    if run <= 0.0:
        raise ValueError("the shoulder's arcs overlap; use smaller radii or a steeper angle")
    q = (p[0] - run * math.sin(a), p[1] + run * math.cos(a))
    z_neck = q[1] + neck_r * math.sin(a)
    segs = (Line((0.0, 0.0), (k, 0.0)), Line((k, 0.0), (k, z_s)),
            Arc(centre, shoulder_r, (k, z_s), p, "ccw"), Line(p, q),
            Arc((neck_r, z_neck), neck_r, q, (0.0, z_neck), "cw"), Line((0.0, z_neck), (0.0, top)))
    return Section(segs), z_neck


def rounding_profile(c: float, heel_r: float, z1: float, neck_r: float, z_neck: float, top: float):
    """The rounding ``c`` (mm): a heel arc of ``heel_r`` from the standing plane, ``c`` up to
    ``z1``, an S of two equal arcs out to ``neck_r`` at ``z_neck``, the neck to ``top``."""
    foot = c - heel_r
    heel = Arc((foot, heel_r), heel_r, (foot, 0.0), (c, heel_r), "ccw")
    dr, dz = neck_r - c, z_neck - z1
    turn = 2.0 * math.atan(dr / dz)  # each arc turns this far: rise 2 R sin, run 2 R (1 - cos)
    radius = dz / (2.0 * math.sin(turn))
    mid = (c + 0.5 * dr, z1 + 0.5 * dz)
    first = Arc((c + radius, z1), radius, (c, z1), mid, "cw")
    second = Arc((neck_r - radius, z_neck), radius, mid, (neck_r, z_neck), "ccw")
    return Section((Line((0.0, 0.0), (foot, 0.0)), heel, Line((c, heel_r), (c, z1)), first, second,
                    Line((neck_r, z_neck), (neck_r, top))))


def outline_shape(plan, k, c, z_s, shoulder, neck_r, top, wall, base) -> BottleShape:
    """An outline bottle (see the module rule) with a shoulder ``(convex radius, angle deg,
    concave radius)``; the rounding's S starts 4 mm above ``z_s``."""
    core, z_neck = core_profile(k, z_s, *shoulder, top)
    rounding = rounding_profile(c, min(2.5, 0.8 * c), z_s + 4.0, neck_r, z_neck, top)
    return BottleShape("outline", (("core", core), ("round", rounding)), wall, base, plan=plan)


#: The flacon's label artwork (asset name): the sample artwork, portrait, 7.5 texels per mm.
FLACON_ART = "flacon_label.png"


def flacon() -> tuple[Design, dict]:
    """Hexagonal flacon: flats facing the camera (the plan's vertex at +x, flats along y), a
    24 x 30 mm label on the front panel (its flat is ``k`` = 27.7 mm wide: a plain rectangle)."""
    across_flats, c = 56.0, 4.0
    k = (0.5 * across_flats - c) / math.cos(math.pi / 6)  # flats at k cos 30 + c from the axis

    def bottle(z_s):
        return outline_shape(hexagon(), k, c, z_s, (12.0, 75.0, 8.0), 9.0, z_s + 38.0, 3.5, 10.0)
    shape = bottle(solve(lambda z: capacity.brimful_ml(bottle(z)), 110.0, 30.0, 90.0))  # 100 ml nominal
    body_top = shape.sections[0][1].segments[1].p1[1]
    label = sample_label(FLACON_ART, z_mm=0.5 * (shape.base_thickness + body_top), angle_deg=-90.0,
                         height_mm=30.0, width_mm=24.0)
    design = Design(shape=shape, glass=Glass(1.52, (0.0005, 0.0004, 0.0006)),
                    liquid=Liquid(1.36, (0.002, 0.006, 0.03), "volume", 100.0), labels=(label,),
                    camera=framing_camera(shape, RENDER.width, RENDER.height), render=RENDER,
                    name="Hexagonal flacon",
                    notes="Perfume flacon, 56 mm across the flats, pale gold perfume, a label on the front panel.")
    return design, {FLACON_ART: png_bytes(sample_artwork(1, (225, 180)))}


def hip_flask() -> tuple[Design, dict]:
    """Hip flask: four arcs, 100 mm wide and 36 mm deep, amber spirit."""
    width, depth, c = 100.0, 36.0, 4.0
    plan = flask(width, depth)
    k = 0.5 * width - c  # the plan's reach (its end, along +x) is 1 after normalisation

    def bottle(z_s):
        return outline_shape(plan, k, c, z_s, (8.0, 80.0, 6.0), 11.0, z_s + 38.0, 3.0, 6.0)
    shape = bottle(solve(lambda z: capacity.brimful_ml(bottle(z)), 212.0, 60.0, 140.0))  # 200 ml nominal
    return Design(shape=shape, glass=Glass(1.52, (0.0, 0.0, 0.0)),
                  liquid=Liquid(1.36, (0.003, 0.012, 0.045), "volume", 200.0),
                  camera=framing_camera(shape, RENDER.width, RENDER.height), render=RENDER,
                  name="Hip flask", notes="Hip flask of four arcs, 100 x 36 mm, amber spirit."), {}


def build_all(folder: Path = HERE) -> dict[str, Design]:
    """Build, check and save both samples into ``folder``; returns them by file name."""
    samples = {"flacon.glassbench": flacon(), "hip_flask.glassbench": hip_flask()}
    for name, (design, assets) in samples.items():
        check_design(design, assets)
        save_project(folder / name, design, assets, keep_backup=False)
        print(report(design))
    return {name: design for name, (design, _) in samples.items()}


if __name__ == "__main__":
    build_all(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)
