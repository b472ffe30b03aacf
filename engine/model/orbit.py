"""The camera as a designer turns it: an orbit about the target, in degrees and millimetres.

Design rule: the design stores its camera as eye, target and up (SPEC section 2); panels and
views show and change it as an orbit (azimuth, elevation, distance about the target), which is
how a designer turns a bottle. These functions convert exactly between the two for a +z up
vector, and turn a drag (degrees of azimuth and elevation since the drag began) into a camera.
No Qt here: the widgets only turn mouse motion into degrees.
"""
from __future__ import annotations

import dataclasses
import math

from .design import Camera

#: Elevation limit (degrees): at +-90 the view direction would be parallel to the up vector.
MAX_ELEVATION_DEG = 89.0


def camera_to_orbit(cam: Camera) -> tuple[float, float, float]:
    """``(azimuth_deg, elevation_deg, distance_mm)`` of the eye about the target.

    Azimuth 0 looks along +y (the eye on -y); positive azimuth turns the eye towards +x.
    """
    d = [e - t for e, t in zip(cam.eye, cam.target)]
    dist = math.sqrt(sum(v * v for v in d)) or 1.0
    return (math.degrees(math.atan2(d[0], -d[1])),
            math.degrees(math.asin(max(-1.0, min(1.0, d[2] / dist)))), dist)


def orbit_to_camera(cam: Camera, azimuth_deg: float, elevation_deg: float, distance: float,
                    target_z: float | None = None) -> Camera:
    """``cam`` with its eye placed on the orbit (degrees, mm) about its target, up = +z.

    ``target_z`` (mm) moves the target up or down the bottle's axis first.
    """
    tx, ty, tz = cam.target
    tz = tz if target_z is None else float(target_z)
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    eye = (tx + distance * math.cos(el) * math.sin(az), ty - distance * math.cos(el) * math.cos(az),
           tz + distance * math.sin(el))
    return dataclasses.replace(cam, eye=eye, target=(tx, ty, tz), up=(0.0, 0.0, 1.0))


def orbited(start: Camera, d_azimuth_deg: float, d_elevation_deg: float) -> Camera:
    """The camera a drag has turned ``start`` to: azimuth and elevation changed by the given
    degrees, distance and target kept, the elevation held within +-:data:`MAX_ELEVATION_DEG`."""
    az, el, dist = camera_to_orbit(start)
    el = max(-MAX_ELEVATION_DEG, min(MAX_ELEVATION_DEG, el + d_elevation_deg))
    return orbit_to_camera(start, az + d_azimuth_deg, el, dist)
