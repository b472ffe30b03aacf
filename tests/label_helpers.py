"""Bottles and images the label tests share: a cylinder, a cone, a rounded-square prism, a
section with a sharp corner, and image files written through OpenImageIO."""
from __future__ import annotations

import os

import numpy as np

from engine.geometry.section import Section
from engine.geometry.segments import Line
from engine.geometry.shape import BottleShape
from engine.model.design import Design

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BORDEAUX = os.path.join(REPO, "resources", "bordeaux.glassbench")
SQUARE = os.path.join(REPO, "resources", "square.glassbench")


def cylinder_shape(r: float = 40.0, top: float = 200.0) -> BottleShape:
    sec = Section((Line((0, 0), (r, 0)), Line((r, 0), (r, top))))
    return BottleShape("round", (("profile", sec),), 3.0, 6.0)


def cone_shape() -> BottleShape:
    """A flat base, 60 mm of cylinder (r 40), a cone narrowing to r 20 at z = 160, a neck."""
    sec = Section((Line((0, 0), (40, 0)), Line((40, 0), (40, 60)), Line((40, 60), (20, 160)),
                   Line((20, 160), (20, 200))), (False, False, False))
    return BottleShape("round", (("profile", sec),), 3.0, 6.0)


def prism_shape(u: float = 30.0, v: float = 36.0, body: float = 150.0, wall: float = 3.0) -> BottleShape:
    """A rounded-square prism (straight walls to ``body`` mm), then a straight shoulder into a
    round neck of radius 20 at 170 mm, up to 200 mm (sharp joints)."""
    def sec(r):
        return Section((Line((0, 0), (r, 0)), Line((r, 0), (r, body)), Line((r, body), (20.0, body + 20)),
                        Line((20.0, body + 20), (20.0, 200.0))), (False, False, False))
    return BottleShape("rounded_square", (("u", sec(u)), ("v", sec(v))), wall, 6.0, rotation_deg=20.0)


def design_with(shape, *labels) -> Design:
    return Design(shape, labels=tuple(labels))


def write_image(path, pixels, fmt=None, unassociated=True) -> bytes:
    """Write ``pixels`` (H, W, C) with OpenImageIO (type from the array, or ``fmt``); bytes."""
    import OpenImageIO as oiio
    path = str(path)
    h, w, c = pixels.shape
    fmt = fmt or {np.dtype(np.uint8): oiio.UINT8, np.dtype(np.uint16): oiio.UINT16,
                  np.dtype(np.float32): oiio.FLOAT}[pixels.dtype]
    spec = oiio.ImageSpec(w, h, c, fmt)
    if c in (2, 4):
        spec.alpha_channel = c - 1
        if unassociated:
            spec.attribute("oiio:UnassociatedAlpha", 1)
    out = oiio.ImageOutput.create(path)
    assert out is not None and out.open(path, spec), oiio.geterror()
    assert out.write_image(pixels), out.geterror()
    out.close()
    with open(path, "rb") as fh:
        return fh.read()


def artwork(tmp_path, name="art.png", size=(64, 96), colour=(200, 30, 30)) -> bytes:
    """An opaque 8-bit PNG of ``size`` (height, width) texels in ``colour`` (sRGB 0..255)."""
    px = np.empty(size + (3,), np.uint8)
    px[...] = colour
    return write_image(tmp_path / name, px)
