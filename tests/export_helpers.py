"""Designs where the export methods are pushed to their limits (issue 28), built from the
bundled samples: each is a valid design the engine accepts (check_design passes)."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from engine.geometry.section import Section
from engine.geometry.segments import Arc, EllipseArc, Line
from engine.model.design import Cap, Label, LabelSide

RESOURCES = Path(__file__).resolve().parents[1] / "resources"
SAMPLES = sorted(RESOURCES.glob("*.glassbench"))


def load(name: str):
    from engine.files.project import load_project
    return load_project(RESOURCES / name)


def with_profile(design, segments, smooth=None, **shape_changes):
    """``design`` with its round profile replaced by ``segments``."""
    section = Section(tuple(segments), smooth)
    shape = dataclasses.replace(design.shape, sections=(("profile", section),), **shape_changes)
    return dataclasses.replace(design, shape=shape)


def thin_wall():
    """The Bordeaux sample with a 0.5 mm wall (base 2 mm)."""
    d, a = load("bordeaux.glassbench")
    shape = dataclasses.replace(d.shape, wall_thickness=0.5, base_thickness=2.0)
    return dataclasses.replace(d, shape=shape), a


def tangent_punt():
    """A punt that meets the standing ring tangentially: an S of two arcs of one radius, level
    on the axis and level again at the ring, where the heel arc leaves level too."""
    d, a = load("bordeaux.glassbench")
    segs = list(d.shape.primary.segments)
    h, ring = 12.0, segs[1].p0[0]
    radius = (ring ** 2 + h ** 2) / (4 * h)
    mid = (0.5 * ring, 0.5 * h)
    punt = [Arc((0.0, h - radius), radius, (0.0, h), mid, "cw"),
            Arc((ring, radius), radius, mid, (ring, 0.0), "ccw")]
    return with_profile(d, punt + segs[1:], (True,) * len(segs)), a


def ellipse_1_20():
    """A concave shoulder that is an ellipse arc with a 1 : 20 axis ratio (20 mm across, 1 mm up)."""
    d, a = load("jar.glassbench")
    r_body, z_sh, r_neck = 40.0, 100.0, 20.0
    segs = [Line((0.0, 0.0), (r_body, 0.0)), Line((r_body, 0.0), (r_body, z_sh)),
            EllipseArc((r_body, z_sh + 1.0), r_body - r_neck, 1.0, (r_body, z_sh), (r_neck, z_sh + 1.0), "cw"),
            Line((r_neck, z_sh + 1.0), (r_neck, 130.0))]
    d = with_profile(d, segs, (False, False, True), wall_thickness=3.0, base_thickness=6.0)
    return dataclasses.replace(d, liquid=dataclasses.replace(d.liquid, fill_mode="height", fill_value=90.0)), a


def seam_label():
    """The labelled sample with its label centred on the 180 degree seam of the azimuth."""
    d, a = load("labelled.glassbench")
    return dataclasses.replace(d, labels=(dataclasses.replace(d.labels[0], angle_deg=180.0),)), a


def no_liquid():
    d, a = load("knurled_jar.glassbench")
    return dataclasses.replace(d, liquid=None), a


def no_labels():
    d, a = load("labelled.glassbench")
    return dataclasses.replace(d, labels=()), a


def km_finish():
    """The Bordeaux sample whose neck below the finish is an arc of 1 km radius (leaving the
    shoulder vertically, meeting the finish at a 0.002 degree corner), with a screw cap on it."""
    d, a = load("bordeaux.glassbench")
    segs = list(d.shape.primary.segments)
    (r0, z0), z_top = segs[-1].p0, segs[-1].p1[1]
    big, z1 = 1e6, z0 + 30.0  # mm
    phi = math.asin((z1 - z0) / big)
    top = (r0 - big + big * math.cos(phi), z1)
    segs[-1:] = [Arc((r0 - big, z0), big, (r0, z0), top, "ccw"), Line(top, (top[0], z_top))]
    smooth = d.shape.primary.smooth + (False,)
    d = with_profile(d, segs, smooth, wall_per_segment=None)
    return dataclasses.replace(d, cap=Cap("screw", "plastic", (0.9, 0.1, 0.1))), a


def many_labels(n: int = 4096):
    """The Bordeaux sample with ``n`` small plain labels in a grid on its body (the list limit)."""
    d, a = load("bordeaux.glassbench")
    cols = 64
    labels = tuple(Label(name=f"l{k}", front=LabelSide(None, (0.9, 0.2 + 0.6 * (k % 7) / 6, 0.3)),
                         z_mm=20.0 + 2.5 * (k // cols), angle_deg=-180.0 + 360.0 * (k % cols) / cols,
                         height_mm=2.0, width_mm=3.0)
                   for k in range(n))
    return dataclasses.replace(d, labels=labels), a


EDGE_CASES = {"thin_wall": thin_wall, "tangent_punt": tangent_punt, "ellipse_1_20": ellipse_1_20,
              "seam_label": seam_label, "no_liquid": no_liquid, "no_labels": no_labels,
              "km_finish": km_finish}


def cap_prints():
    """The threaded sample's screw cap with a print on its flat top and one round its skirt."""
    from engine.appearance.cap_surfaces import cap_surface
    d, a = load("threaded_bottle.glassbench")
    skirt = cap_surface(d, "cap-skirt")
    labels = (Label(name="top print", front=LabelSide(None, (0.8, 0.1, 0.1)), surface="cap-top",
                    width_mm=10.0, height_mm=6.0, angle_deg=-90.0),
              Label(name="skirt print", front=LabelSide(None, (0.1, 0.1, 0.8)), surface="cap-skirt",
                    z_mm=0.5 * skirt.height_mm, width_mm=20.0, height_mm=8.0, angle_deg=-90.0))
    return dataclasses.replace(d, labels=labels), a


def bspline_face_points(solid, per_side: int = 11):
    """Points on every B-spline face of ``solid``: a grid over each face's parameters at cell
    centres of ``per_side`` cells, away from the interpolation nodes (``j / 2^k``)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_SurfaceType as T
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    pts = []
    it = TopExp_Explorer(solid, TopAbs_ShapeEnum.TopAbs_FACE)
    while it.More():
        s = BRepAdaptor_Surface(TopoDS.Face(it.Current()))
        if s.GetType() == T.GeomAbs_BSplineSurface:
            f = (np.arange(per_side) + 0.5) / per_side
            u0, u1, v0, v1 = (s.FirstUParameter(), s.LastUParameter(), s.FirstVParameter(),
                              s.LastVParameter())
            for u in u0 + (u1 - u0) * f:
                for v in v0 + (v1 - v0) * f:
                    p = s.Value(u, v)
                    pts.append((p.X(), p.Y(), p.Z()))
        it.Next()
    return np.array(pts)


def wall_distance(shape, pts) -> np.ndarray:
    """Distance (mm) of each world point ``(n, 3)`` from the nearer exact wall of ``shape``, by
    the wall's implicit function to first order (``|g| / |grad g|``)."""
    from engine.geometry.body import BottleBody
    body = BottleBody(shape)
    dist = np.full(len(pts), np.inf)
    for part in ("outer", "inner"):
        lo, hi = body.wall_range(part)
        on = (pts[:, 2] >= lo - 1e-9) & (pts[:, 2] <= hi + 1e-9)
        g, grad = body.wall_implicit(part, pts[on])
        dist[on] = np.minimum(dist[on], np.abs(g) / np.linalg.norm(grad, axis=-1))
    return dist
