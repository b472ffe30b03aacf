"""Prints on the closure: where its flat top and its straight skirt are, and the labels on them.

Design rule: a label whose ``surface`` is ``"cap-top"`` or ``"cap-skirt"`` is drawn by the same
kernels as a label on the wall (artwork, finish regions, lights), on the closure part that
carries that surface. Both surfaces are found in the closure's meridian chains
(:func:`engine.appearance.closures.closure_geometry`, sized from the finish), so a print
follows the cap when the neck changes:

* the **top** is the highest horizontal line of a chain that ends on the axis, walked towards
  it (its outward normal points up): a disk of radius :attr:`CapSurface.radius` at height
  :attr:`CapSurface.z0`; a print there is a flat rectangle, affine in ``(x, y)``;
* the **skirt** is the outermost vertical line of a chain walked upwards (normal pointing
  out) that lies outside the glass: a cylinder of radius :attr:`CapSurface.radius` between
  :attr:`CapSurface.z0` and :attr:`CapSurface.z1`; a print there is a rolled rectangle, like
  a label on a cylindrical wall, its centre's height measured from the lower edge.

Each is also a band ``[v0, v1]`` of the part's arc length ``v`` (mm from the chain's start,
the tracer's ``segment_v``), so the kernels tell the top from the underside and the skirt from
the inside of the shell. :func:`engine.tracer.tables.labels.place_rows` is the kernels' place table of every label (wall
labels included); :func:`surface_decal` the decal of a skirt print. Units mm, degrees.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import DesignError
from ..model.design import Design
from .closure_shapes import chain_lines
from .closures import closure_geometry, finish_of
from .decal import Decal

#: The surfaces of a closure a label may be printed on.
CAP_SURFACES = ("cap-top", "cap-skirt")
_FLAT = 1e-9


@dataclass(frozen=True)
class CapSurface:
    """One printable surface of a closure (mm): ``kind`` ``"cap-top"`` or ``"cap-skirt"``,
    ``part`` the index of the closure part carrying it, ``v0 <= v <= v1`` its band of that
    part's arc length, ``radius`` the top disk's radius or the skirt's, ``z0``/``z1`` the top's
    height (twice) or the skirt's lower and upper edges."""

    kind: str
    part: int
    v0: float
    v1: float
    radius: float
    z0: float
    z1: float

    @property
    def height_mm(self) -> float:
        """The skirt's straight height (0 for the top)."""
        return self.z1 - self.z0


def _top(geom):
    best = None
    for i, part in enumerate(geom.parts):
        for v0, v1, sg in chain_lines(part.chain):
            (r0, z0), (r1, z1) = sg.p0, sg.p1
            if abs(z1 - z0) < _FLAT and abs(r1) < _FLAT and r0 > r1 and (best is None or z0 > best.z0):
                best = CapSurface("cap-top", i, v0, v1, float(r0), float(z0), float(z0))
    return best


def _skirt(geom, r_glass: float):
    best = None
    for i, part in enumerate(geom.parts):
        for v0, v1, sg in chain_lines(part.chain):
            (r0, z0), (r1, z1) = sg.p0, sg.p1
            if abs(r1 - r0) < _FLAT and z1 > z0 and r0 > r_glass and (
                    best is None or (r0, z1 - z0) > (best.radius, best.height_mm)):
                best = CapSurface("cap-skirt", i, v0, v1, float(r0), float(z0), float(z1))
    return best


def cap_surface(design, surface: str, where: str = "the label") -> CapSurface:
    """The :class:`CapSurface` ``surface`` (one of :data:`CAP_SURFACES`) of ``design``'s
    closure. Raises ``DesignError`` (naming ``where``) without a cap, or when the closure has
    no such surface (a crown's flared skirt is not straight)."""
    if design.cap is None:
        raise DesignError(f"{where} is printed on the {_words(surface)} but the design has no cap")
    found = _surfaces(design.shape, design.cap, design.bumps)[CAP_SURFACES.index(surface)]
    if found is None:
        raise DesignError(f"{where} is printed on the {_words(surface)} but a {design.cap.kind} "
                          f"closure has no {'flat top' if surface == 'cap-top' else 'straight skirt'}")
    return found


@lru_cache(maxsize=32)
def _surfaces(shape, cap, bumps):
    design = Design(shape=shape, cap=cap, bumps=bumps)
    geom = closure_geometry(design)
    return _top(geom), _skirt(geom, finish_of(design).r_neck)


def _words(surface: str) -> str:
    return "cap's top" if surface == "cap-top" else "cap's skirt"


def top_corners(label) -> np.ndarray:
    """The four corners ``(4, 2)`` (mm, world x, y) of a cap-top print: top-left, top-right,
    bottom-right, bottom-left as the artwork reads."""
    b = np.array([math.cos(math.radians(label.angle_deg)), math.sin(math.radians(label.angle_deg))])
    right = np.array([-b[1], b[0]])
    c = np.array([label.cap_x_mm, label.cap_y_mm])
    w, h = 0.5 * label.width_mm, 0.5 * label.height_mm
    return np.array([c - w * right - h * b, c + w * right - h * b, c + w * right + h * b, c - w * right + h * b])


def check_cap_label(design, label, where: str = "the label") -> None:
    """Raise ``DesignError`` unless ``label`` (a print on the closure) fits on its surface."""
    surf = cap_surface(design, label.surface, where)
    if label.surface == "cap-top":
        reach = float(np.max(np.hypot(*top_corners(label).T)))
        if reach > surf.radius * (1.0 + 1e-12):
            raise DesignError(
                f"{where} is {label.width_mm:g} x {label.height_mm:g} mm at ({label.cap_x_mm:g}, "
                f"{label.cap_y_mm:g}) mm but the cap's flat top is {2 * surf.radius:.1f} mm across: "
                f"a corner lies {reach - surf.radius:.1f} mm past its edge")
        return
    girth = 2.0 * math.pi * surf.radius
    if label.width_mm > girth * (1.0 + 1e-12):
        raise DesignError(f"{where} is {label.width_mm:g} mm wide but the cap's skirt is "
                          f"{girth:.1f} mm around: a print wraps at most once around")
    lo, hi = label.z_mm - 0.5 * label.height_mm, label.z_mm + 0.5 * label.height_mm
    if lo < -1e-9 or hi > surf.height_mm + 1e-9:
        raise DesignError(f"{where}: its {label.height_mm:g} mm centred {label.z_mm:g} mm above the "
                          f"skirt's lower edge do not fit on the cap's straight skirt "
                          f"({surf.height_mm:.1f} mm high)")


def surface_decal(design, label) -> Decal:
    """The decal of a print on the closure: a skirt print's exact 2 x 2 grid over ``(theta,
    z)`` (``s`` linear in the azimuth, ``t`` in the height); a top print's lookup is affine in
    ``(x, y)`` (:func:`engine.tracer.tables.labels.place_rows`), so its decal is an empty 2 x 2 grid that is never read."""
    zero = np.zeros((2, 2), np.float32)
    if label.surface == "cap-top":
        st = np.zeros((2, 2, 2), np.float32)
        theta0, theta1, h0, h1 = 0.0, 1.0, 0.0, 1.0
    else:
        surf = cap_surface(design, label.surface)
        span = label.width_mm / surf.radius
        theta0 = math.radians(label.angle_deg) - 0.5 * span
        theta1 = theta0 + span
        h0 = surf.z0 + label.z_mm - 0.5 * label.height_mm
        h1 = h0 + label.height_mm
        # node (i, j): i = 0 the lower edge (t = 1), j = 0 the left edge (s = 0)
        st = np.array([[[0.0, 1.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 0.0]]], np.float32)
    for a in (st, zero):
        a.setflags(write=False)
    return Decal(theta0, theta1, h0, h1, st, zero, "rectangle", 0.0)
