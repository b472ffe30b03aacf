"""The design a new window starts from: the bundled Bordeaux sample, or one built here.

Design rule: ``glassbench`` with no argument opens ``resources/bordeaux.glassbench`` when it is
present and readable; otherwise (a fresh checkout, or a broken resource) it opens a Bordeaux-like
round bottle constructed in code so that the window always has something valid to show.
"""
from __future__ import annotations

import math
from pathlib import Path

from engine.model.design import Design, Liquid, RenderSettings
from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc, Line
from engine.geometry.shape import BottleShape

RESOURCES = Path(__file__).resolve().parent.parent / "resources"
SAMPLE_PROJECT = RESOURCES / "bordeaux.glassbench"


def bordeaux_section(body_r: float = 37.0, neck_r: float = 14.0, shoulder_z: float = 190.0,
                     top_z: float = 300.0) -> Section:
    """A round wine-bottle profile (mm): rounded heel, straight body, S-shoulder, neck.

    The shoulder is a convex quarter-ellipse part (60 degrees of it) followed by a concave arc
    that meets the vertical neck tangentially, so every joint above the base is smooth.
    """
    heel = 6.0
    base = Line((0.0, 0.0), (body_r - heel, 0.0))
    heel_arc = Arc((body_r - heel, heel), heel, (body_r - heel, 0.0), (body_r, heel), "ccw")
    body = Line((body_r, heel), (body_r, shoulder_z))
    a, b, s1 = 15.0, 40.0, math.radians(60.0)
    centre = (body_r - a, shoulder_z)
    p_shoulder = (centre[0] + a * math.cos(s1), centre[1] + b * math.sin(s1))
    shoulder = EllipseArc(centre, a, b, (body_r, shoulder_z), p_shoulder, "ccw")
    # Concave arc: centre on the outward normal of the shoulder end, tangent to the neck.
    tr, tz = -a * math.sin(s1), b * math.cos(s1)
    norm = math.hypot(tr, tz)
    nr, nz = tz / norm, -tr / norm
    radius = (p_shoulder[0] - neck_r) / (1.0 - nr)
    c2 = (p_shoulder[0] + radius * nr, p_shoulder[1] + radius * nz)
    neck_base = (c2[0] - radius, c2[1])
    waist = Arc(c2, radius, p_shoulder, neck_base, "cw")
    neck = Line(neck_base, (neck_r, top_z))
    return Section((base, heel_arc, body, shoulder, waist, neck))


def built_in_design() -> Design:
    """The Bordeaux-like sample built in code (valid by construction)."""
    shape = BottleShape("round", (("profile", bordeaux_section()),), 3.0, 6.0)
    return Design(shape=shape, liquid=Liquid(fill_mode="height", fill_value=230.0),
                  render=RenderSettings(width=240, height=320, spp=8), name="Bordeaux")


def sample_design():
    """``(design, assets, path_or_None)`` for a new window."""
    from app import engine_bridge
    from engine.errors import GlassbenchError
    if SAMPLE_PROJECT.is_file():
        try:
            design, assets = engine_bridge.load_project(str(SAMPLE_PROJECT))
            return design, dict(assets), None
        except (GlassbenchError, OSError, ValueError):
            pass
    return built_in_design(), {}, None


def square_section_pair(u: float = 30.0, v: float = 36.0, top_z: float = 200.0):
    """Two straight-walled sections for a rounded-square bottle: ``u`` (faces) and ``v``
    (diagonal) radii in mm, with a heel arc and a short neck."""
    def one(r):
        heel = 4.0
        return Section((Line((0.0, 0.0), (r - heel, 0.0)),
                        Arc((r - heel, heel), heel, (r - heel, 0.0), (r, heel), "ccw"),
                        Line((r, heel), (r, top_z))))
    return one(u), one(v)
