"""Build the sample projects in this folder from code: ``python resources/make_samples.py``.

Design rule: every sample is constructed from a few designer-facing numbers (mm), solved so
that its trade numbers are right (the Bordeaux holds 750 ml at a normal fill point and about
776 ml brimful), validated, checked with :mod:`engine.geometry.capacity`, and saved with
:func:`engine.files.project.save_project`. The ``.glassbench`` files are committed; rerun this
script after changing the format or the shapes. Writes:

* ``bordeaux.glassbench``: 750 ml Bordeaux wine bottle, punted base, circular-arc shoulder,
  green glass, red wine filled to 750 ml.
* ``square.glassbench``: rounded-square spirits bottle with a round neck, rotated 30 deg.
* ``jar.glassbench``: a wide preserve jar, amber syrup.
* ``bordeaux_table.glassbench``: the Bordeaux standing on a white table in a low sun from
  behind, so its shadow and the wine's red caustic fall towards the camera.
* ``bordeaux_profile.dxf``: the Bordeaux section as a DXF (``glassbench new --from-dxf``).
"""
from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from engine.geometry import capacity# noqa: E402
from engine.cli.project import framing_camera  # noqa: E402
from engine.model.design import Camera, Design, Glass, Light, Liquid, RenderSettings, Stage  # noqa: E402
from engine.files.dxf_import import section_to_dxf  # noqa: E402
from engine.files.project import save_project  # noqa: E402
from engine.operations.check import check_design  # noqa: E402
from engine.geometry.section import Section  # noqa: E402
from engine.geometry.segments import Arc, Line  # noqa: E402
from engine.geometry.shape import BottleShape  # noqa: E402

RENDER = RenderSettings(width=360, height=480, spp=16)
#: The Bordeaux's brimful capacity (ml): with its 29 mm neck, 750 ml then stand ~63 mm below
#: the top, a normal fill point for a cork finish.
BRIMFUL_ML = 776.0


def shoulder_to_neck(body_r: float, z_s: float, shoulder_r: float, angle_deg: float,
                     neck_r: float):
    """Convex arc (radius ``shoulder_r``) leaving a vertical body at ``(body_r, z_s)`` and
    turning ``angle_deg`` inwards, then the concave arc that meets the vertical neck of
    radius ``neck_r`` tangentially. Returns the two arcs (mm); the neck starts at the
    second arc's end."""
    a = math.radians(angle_deg)
    c1 = (body_r - shoulder_r, z_s)
    p = (c1[0] + shoulder_r * math.cos(a), c1[1] + shoulder_r * math.sin(a))
    concave_r = (p[0] - neck_r) / (1.0 - math.cos(a))
    if concave_r <= 0:
        raise ValueError("the shoulder turns in past the neck; use a smaller shoulder radius")
    c2 = (p[0] + concave_r * math.cos(a), p[1] + concave_r * math.sin(a))
    return (Arc(c1, shoulder_r, (body_r, z_s), p, "ccw"),
            Arc(c2, concave_r, p, (neck_r, c2[1]), "cw"))


def bordeaux_section(z_s: float, neck_r: float = 14.5, top: float = 300.0) -> Section:
    """Punt (12 mm dome to a ring at r = 28), heel, straight body of radius 37.5 to ``z_s``,
    circular-arc shoulder, neck of radius ``neck_r`` up to ``top`` (mm)."""
    body_r, ring_r, punt_h = 37.5, 28.0, 12.0
    rp = (ring_r ** 2 + punt_h ** 2) / (2 * punt_h)
    punt = Arc((0.0, punt_h - rp), rp, (0.0, punt_h), (ring_r, 0.0), "cw")
    heel_r = body_r - ring_r
    heel = Arc((ring_r, heel_r), heel_r, (ring_r, 0.0), (body_r, heel_r), "ccw")
    body = Line((body_r, heel_r), (body_r, z_s))
    convex, concave = shoulder_to_neck(body_r, z_s, 30.0, 62.0, neck_r)
    neck = Line(concave.p1, (neck_r, top))
    return Section((punt, heel, body, convex, concave, neck))


def solve(fn, target: float, lo: float, hi: float, steps: int = 60) -> float:
    """Bisection for ``fn(x) = target`` with ``fn`` increasing on [lo, hi]."""
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if fn(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def round_shape(section: Section, wall=3.0, base=6.0) -> BottleShape:
    return BottleShape("round", (("profile", section),), wall, base)


def bordeaux() -> Design:
    z_s = solve(lambda z: capacity.brimful_ml(round_shape(bordeaux_section(z))), BRIMFUL_ML, 150.0, 240.0)
    shape = round_shape(bordeaux_section(z_s))
    return Design(shape=shape, glass=Glass(1.52, (0.006, 0.0015, 0.005)),
                  liquid=Liquid(1.34, (0.015, 0.35, 0.28), "volume", 750.0),
                  camera=framing_camera(shape, RENDER.width, RENDER.height), render=RENDER,
                  name="Bordeaux 750 ml", notes="Punted Bordeaux wine bottle, 75 mm x 300 mm.")


def bordeaux_on_table() -> Design:
    """The Bordeaux on a white table under a sun (0.53 degrees) low behind it: the camera
    looks down a little more, so the table in front, where the red caustic falls, is seen."""
    bottle = bordeaux()
    return dataclasses.replace(
        bottle, stage=Stage(kind="table", color=(0.8, 0.8, 0.8)),
        lights=(Light(direction=(0.35, 1.0, 0.75), color=(1.0, 0.96, 0.9), intensity=2.5, angle_deg=0.53),),
        camera=Camera(eye=(0.0, -720.0, 420.0), target=(0.0, -60.0, 120.0), fov_y_deg=30.0),
        name="Bordeaux on a table", notes="The Bordeaux 750 ml on a white table, a low sun behind it.")


def square_profile(body_r: float, z_s: float, angle_deg: float, neck_r: float, top: float) -> Section:
    heel_r = 6.0
    base = Line((0.0, 0.0), (body_r - heel_r, 0.0))
    heel = Arc((body_r - heel_r, heel_r), heel_r, base.p1, (body_r, heel_r), "ccw")
    body = Line((body_r, heel_r), (body_r, z_s))
    convex, concave = shoulder_to_neck(body_r, z_s, 16.0, angle_deg, neck_r)
    return Section((base, heel, body, convex, concave, Line(concave.p1, (neck_r, top))))


def square() -> Design:
    # u: half-width across the flats; v: radius along the diagonal (corner radius ~14 mm).
    # Both shoulders start at z_s and end in the same neck at the same height (u = v there,
    # a round finish): the shoulder rise is (body - neck) cot(angle / 2), so v turns further.
    u_body, v_body, neck_r, top, z_s, u_angle = 32.0, 37.0, 13.0, 240.0, 150.0, 70.0
    half = math.atan((v_body - neck_r) / (u_body - neck_r) * math.tan(math.radians(u_angle) / 2))
    u = square_profile(u_body, z_s, u_angle, neck_r, top)
    v = square_profile(v_body, z_s, math.degrees(2 * half), neck_r, top)
    shape = BottleShape("rounded_square", (("u", u), ("v", v)), 3.0, 7.0, rotation_deg=30.0)
    return Design(shape=shape, glass=Glass(1.52, (0.0, 0.0, 0.0)),
                  liquid=Liquid(1.36, (0.002, 0.012, 0.05), "height", 170.0),
                  camera=framing_camera(shape, RENDER.width, RENDER.height), render=RENDER,
                  name="Square spirits", notes="Rounded-square bottle with a round neck.")


def jar() -> Design:
    body_r, heel_r, z_s, neck_r, top = 45.0, 8.0, 100.0, 39.0, 122.0
    base = Line((0.0, 0.0), (body_r - heel_r, 0.0))
    heel = Arc((body_r - heel_r, heel_r), heel_r, base.p1, (body_r, heel_r), "ccw")
    body = Line((body_r, heel_r), (body_r, z_s))
    convex, concave = shoulder_to_neck(body_r, z_s, 8.0, 60.0, neck_r)
    section = Section((base, heel, body, convex, concave, Line(concave.p1, (neck_r, top))))
    shape = round_shape(section, 3.5, 7.0)
    return Design(shape=shape, glass=Glass(1.52, (0.001, 0.001, 0.0015)),
                  liquid=Liquid(1.45, (0.004, 0.03, 0.12), "height", 90.0),
                  camera=framing_camera(shape, RENDER.width, RENDER.height), render=RENDER,
                  name="Wide jar", notes="Preserve jar with a wide mouth, amber syrup.")


def report(design: Design) -> str:
    shape = design.shape
    brim = capacity.brimful_ml(shape)
    liquid = design.liquid
    if liquid.fill_mode == "volume":
        fill_ml, below = liquid.fill_value, capacity.fill_point_below_top_mm(shape, liquid.fill_value)
    else:
        fill_ml, below = capacity.capacity_ml(shape, liquid.fill_value), shape.z_top - liquid.fill_value
    return (f"{design.name}: brimful {brim:.1f} ml, fill {fill_ml:.1f} ml at {below:.1f} mm below "
            f"the top, height {capacity.height_mm(shape):.1f} mm, max diameter "
            f"{capacity.max_diameter_mm(shape):.1f} mm, glass {capacity.glass_mass_g(shape):.0f} g")


def build_all(folder: Path = HERE) -> dict[str, Design]:
    """Build, check and save every sample into ``folder``; returns them by file name."""
    samples = {"bordeaux.glassbench": bordeaux(), "square.glassbench": square(),
               "jar.glassbench": jar(), "bordeaux_table.glassbench": bordeaux_on_table()}
    for name, design in samples.items():
        check_design(design, {})
        save_project(folder / name, design, {}, keep_backup=False)
        print(report(design))
    section_to_dxf(samples["bordeaux.glassbench"].shape.primary, folder / "bordeaux_profile.dxf")
    return samples


if __name__ == "__main__":
    build_all()
