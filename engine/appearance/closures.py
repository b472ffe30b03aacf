"""Closures as render-ready geometry: meridian chains with a material each, sized from the finish.

Design rule: a :class:`~engine.model.design.Cap` holds only the designer's choices (kind,
material, colour, skirt height, count); everything with a size is derived here from the
*finish* of the design's shape (:func:`finish_of`: the neck's outer radius and the mouth's
height, the bore, the thread on it), so an edit of the neck moves and resizes the cap and a
cap edit never touches the bottle. A closure is one or more :class:`ClosurePart`: a closed
meridian chain of :mod:`engine.geometry.segments` in the (r, z) plane (mm), from the axis back
to the axis, walked like a bottle section (material on the left: the outward normal is
``(T_z, -T_r)``), so the tracer renders each part as one revolved object. Reliefs on a part
(knurl, flutes, lugs) are bump bands in the chain's own arc length ``v``.

Parts never touch the glass: every face that rests on the bottle keeps :data:`GAP_MM` of air,
so the tracer never meets coincident surfaces. Units mm; metals as complex indices at 652,
564 and 443 nm (the R, G, B rows).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

from ..geometry.chain import radius_at
from ..geometry.validate import body_profile
from ..model.design import BumpTile, Design
from .closure_parts import ClosurePart, cap_material
from .closure_shapes import closure_parts


@dataclass(frozen=True)
class ClosureGeometry:
    """A closure's parts and extent (mm): ``z_min..z_max`` and the largest radius ``r_max``."""

    kind: str
    parts: tuple[ClosurePart, ...]
    z_min: float
    z_max: float
    r_max: float

    @property
    def height_mm(self) -> float:
        """Vertical extent of the whole closure (all its parts), mm."""
        return self.z_max - self.z_min

    @property
    def diameter_mm(self) -> float:
        """Largest diameter of the closure, mm."""
        return 2.0 * self.r_max


@dataclass(frozen=True)
class Finish:
    """The top of the bottle a closure sits on (mm): ``r_neck`` outer radius at the mouth,
    ``z_top`` the mouth, ``z_start`` the foot of the straight finish (the last segment),
    ``r_bore`` the inner radius at the mouth and ``z_bore`` the lowest height down to which
    the bore stays within 0.5 mm of it, ``thread`` the deepest thread on the finish (its
    tile or ``None``) and ``thread_depth`` its depth."""

    r_neck: float
    z_top: float
    z_start: float
    r_bore: float
    z_bore: float
    thread: BumpTile | None
    thread_depth: float


def finish_of(design: Design) -> Finish:
    """The :class:`Finish` of ``design``'s shape (validated: raises like
    :func:`engine.geometry.validate.body_profile` for an invalid shape). Cached by (shape,
    bumps), the values it depends on: every render context asks for it."""
    return _finish(design.shape, design.bumps)


@lru_cache(maxsize=64)
def _finish(shape, bumps) -> Finish:
    import numpy as np
    prof = body_profile(shape)
    sp = prof.sections[0]
    last = sp.outer_wall[-1]
    z_top, z_start = float(prof.z_top), float(last.p0[1])
    r_bore = float(sp.r_in_top)
    inner = sp.inner_wall
    zs = np.array([z_top - 0.5 * k for k in range(int(max(z_top - inner[0].p0[1], 0.0) / 0.5))])
    z_bore = z_top
    if len(zs):  # the bore: down from the mouth while the inner radius stays within 0.5 mm
        wide = np.asarray(radius_at(inner, zs), float) > r_bore + 0.5
        stop = int(np.argmax(wide)) if wide.any() else len(zs)
        z_bore = float(zs[stop - 1]) if stop > 0 else z_top
    threads = [t for t in bumps if t.kind == "thread" and t.on == "bottle" and t.z1 > z_start and t.z0 < z_top]
    deepest = max(threads, key=lambda t: t.depth, default=None)
    return Finish(float(sp.r_top), z_top, z_start, r_bore, z_bore, deepest,
                  deepest.depth if deepest is not None else 0.0)



def closure_geometry(design: Design) -> ClosureGeometry | None:
    """The design's closure as :class:`ClosureGeometry` (``None`` without a cap), sized from
    :func:`finish_of`. Cached by (shape, cap, bumps): the values it depends on."""
    if design.cap is None:
        return None
    return _closure(design.shape, design.cap, design.bumps)


@lru_cache(maxsize=32)
def _closure(shape, cap, bumps) -> ClosureGeometry:
    finish = finish_of(Design(shape=shape, bumps=bumps))
    parts = closure_parts(cap, finish, cap_material(cap))
    pts = [p for part in parts for sg in part.chain for p in _samples(sg)]
    return ClosureGeometry(cap.kind, parts, min(z for _, z in pts), max(z for _, z in pts),
                           max(r for r, _ in pts))


def _samples(seg, n: int = 9):
    return [tuple(map(float, seg.point(t))) for t in (i / (n - 1) for i in range(n))]


def closure_trade(design: Design) -> tuple[dict | None, float]:
    """``(closure, overall_height_mm)`` for ``glassbench info``: ``closure`` is ``None`` or
    ``{"kind", "diameter_mm", "height_mm"}`` (the closure's largest diameter and its own
    vertical extent); the overall height is the bottle's with the closure on it."""
    geom = closure_geometry(design)
    top = float(design.shape.z_top)
    if geom is None:
        return None, top
    info = {"kind": geom.kind, "diameter_mm": round(geom.diameter_mm, 3),
            "height_mm": round(geom.height_mm, 3)}
    return info, round(max(top, geom.z_max), 3)


def closure_outline(design: Design, meridians: int = 16, ring_steps: int = 96):
    """``(points (N, 3), edges (M, 2))`` of the closure's outline for the wireframe: a ring at
    every joint of every chain and ``meridians`` meridians; empty arrays without a cap."""
    import numpy as np
    geom = closure_geometry(design)
    if geom is None:
        return np.zeros((0, 3)), np.zeros((0, 2), np.int64)
    pts, edges = [], []

    def add_polyline(xyz, closed):
        base = len(pts)
        pts.extend(xyz)
        n = len(xyz)
        edges.extend((base + i, base + (i + 1) % n) for i in range(n if closed else n - 1))

    ang = np.linspace(0.0, 2 * np.pi, ring_steps, endpoint=False)
    for part in geom.parts:
        rz = [p for sg in part.chain for p in _samples(sg)]
        for r, z in {sg.p0 for sg in part.chain} | {part.chain[-1].p1}:
            if r > 1e-9:
                add_polyline([(r * math.cos(a), r * math.sin(a), z) for a in ang], True)
        for a in np.linspace(0.0, 2 * np.pi, meridians, endpoint=False):
            add_polyline([(r * math.cos(a), r * math.sin(a), z) for r, z in rz], False)
    return np.asarray(pts, float), np.asarray(edges, np.int64)
