"""The meridian chains of each closure kind, built from the finish they sit on.

Design rule: one function per kind turns a :class:`~engine.appearance.closures.Finish` (mm)
and the :class:`~engine.model.design.Cap` into :class:`~engine.appearance.closure_parts.ClosurePart`
s; each part is a closed polyline from the axis back to the axis, material on the left, whose
corners are rounded by circular arcs (:func:`filleted_chain`). Sizes scale with the neck: the
skirt's inside clears the thread (or the neck) by a small gap (at least 0.3 mm of air around a
glass cylinder, :data:`~engine.appearance.closure_parts.SKIRT_GAP_MM`), the shell is as thick as the
material makes it (plastic 1.4 mm, aluminium 0.25-0.3 mm), and a skirt never reaches below the
foot of the straight finish. Standard heights when ``cap.height`` is 0: screw cap ``0.8 r + 2``,
crown 6 mm for a 26 mm finish (21 flutes), cork 44 mm under a 50 mm capsule, roll-on (ROPP)
twice its diameter (30 x 60 for a 30 mm finish), lug cap ``0.2 r + 5.5``.
"""
from __future__ import annotations

import math

from ..geometry.segments import Arc, Line
from ..model.design import BumpTile, Cap
from .closure_parts import CORK, GAP_MM, GOLD_LACQUER, SKIRT_GAP_MM, ClosurePart, PartRelief, cap_material

#: The closure each kind gets when it is first chosen (material and colour of the trade).
DEFAULT_CAPS = {"screw": Cap("screw", "plastic", (0.9, 0.9, 0.88)),
                "crown": Cap("crown", "metal", GOLD_LACQUER),
                "cork": Cap("cork", "metal", (0.30, 0.015, 0.03)),
                "ropp": Cap("ropp", "metal", (1.0, 1.0, 1.0)),
                "lug": Cap("lug", "metal", GOLD_LACQUER)}


def default_cap(kind: str) -> Cap:
    """A closure of ``kind`` in its trade's usual material and colour, standard sizes."""
    return DEFAULT_CAPS[kind]


def filleted_chain(points, radii) -> tuple:
    """Segments of the polyline ``points`` ((r, z) mm) with corner ``i`` rounded by an arc of
    radius ``radii[i]`` (0: a sharp corner; shrunk to fit the neighbouring edges). Left turns
    become ``ccw`` (convex) arcs, right turns ``cw`` (concave)."""
    pts = [tuple(map(float, p)) for p in points]
    corners = [(pts[0], pts[0], None)]
    for i in range(1, len(pts) - 1):
        (ar, az), (br, bz), (cr, cz) = pts[i - 1], pts[i], pts[i + 1]
        l1, l2 = math.hypot(br - ar, bz - az), math.hypot(cr - br, cz - bz)
        d1, d2 = ((br - ar) / l1, (bz - az) / l1), ((cr - br) / l2, (cz - bz) / l2)
        cross = d1[0] * d2[1] - d1[1] * d2[0]
        turn = math.atan2(abs(cross), d1[0] * d2[0] + d1[1] * d2[1])
        rc = radii[i] if i < len(radii) else 0.0
        if rc <= 0.0 or turn < 1e-9:
            corners.append((pts[i], pts[i], None))
            continue
        tan_len = min(rc * math.tan(turn / 2.0), 0.45 * l1, 0.45 * l2)
        rc = tan_len / math.tan(turn / 2.0)
        t1 = (br - d1[0] * tan_len, bz - d1[1] * tan_len)
        t2 = (br + d2[0] * tan_len, bz + d2[1] * tan_len)
        side = 1.0 if cross > 0.0 else -1.0
        centre = (t1[0] - side * d1[1] * rc, t1[1] + side * d1[0] * rc)
        corners.append((t1, t2, Arc(centre, rc, t1, t2, "ccw" if cross > 0.0 else "cw")))
    corners.append((pts[-1], pts[-1], None))
    segs = []
    for (_, start, _), (end, _, arc) in zip(corners[:-1], corners[1:]):
        segs.append(Line(start, end))
        if arc is not None:
            segs.append(arc)
    return tuple(segs)


def chain_lines(chain):
    """``(v0, v1, line)`` of every straight segment of a chain, ``v`` the arc length (mm) from
    the chain's start, as the tracer measures it on a closure part."""
    v = 0.0
    for sg in chain:
        if isinstance(sg, Line):
            yield v, v + sg.length, sg
        v += sg.length


def line_v(chain, a, b) -> tuple[float, float]:
    """Arc length ``v`` (mm from the chain's start) at the two ends of the straight part of
    ``chain`` lying on the line from ``a`` to ``b`` (the filleted remains of that edge)."""
    for v0, v1, sg in chain_lines(chain):
        if _on_line(sg.p0, a, b) and _on_line(sg.p1, a, b):
            return v0, v1
    raise ValueError("no straight part of the chain lies on that edge")


def _on_line(p, a, b) -> bool:
    ux, uz = b[0] - a[0], b[1] - a[1]
    return abs((p[0] - a[0]) * uz - (p[1] - a[1]) * ux) <= 1e-7 * (math.hypot(ux, uz) + 1.0)


def _skirt_v(chain, bottom, top, z0, z1):
    """``v`` band of heights ``z0..z1`` on the vertical outer skirt from ``bottom`` to ``top``."""
    v_lo, _ = line_v(chain, bottom, top)
    return v_lo + (z0 - bottom[1]), v_lo + (z1 - bottom[1])


def _shell(ri, t, zu, ztop, zb, top_round):
    """Points of a cap shell: underside at ``zu`` (axis to ``ri``), skirt down to ``zb``, out
    by ``t``, up to ``ztop`` and back to the axis; and their corner radii."""
    ro = ri + t
    pts = [(0.0, zu), (ri, zu), (ri, zb), (ro, zb), (ro, ztop), (0.0, ztop)]
    return pts, [0.0, 0.0, 0.4 * t, 0.4 * t, top_round, 0.0]


def closure_parts(cap: Cap, f, material) -> tuple[ClosurePart, ...]:
    """The parts of ``cap`` on finish ``f`` (see the module rule for the sizes)."""
    return _KINDS[cap.kind](cap, f, material)


def _screw(cap, f, mat):
    plastic = cap.material == "plastic"
    t, tt = (1.4, 1.8) if plastic else (0.3, 0.3)
    ri = f.r_neck + f.thread_depth + 0.3
    zu = f.z_top + GAP_MM
    ztop = zu + tt
    zb = max(ztop - (cap.height or 0.8 * ri + 2.0), f.z_start + GAP_MM)
    pts, radii = _shell(ri, t, zu, ztop, zb, 1.0 if plastic else 0.6)
    chain = filleted_chain(pts, radii)
    ro = ri + t
    reliefs = ()
    if ztop - 2.0 > zb + 1.0:
        v0, v1 = _skirt_v(chain, pts[3], pts[4], zb + 1.0, ztop - 2.0)
        count = cap.count or max(12, round(2 * math.pi * ro / 1.0))
        knurl = BumpTile("skirt knurl", "knurl", repeat=count, depth=0.3 if plastic else 0.12,
                         width=1.0, sharpness=0.6)
        reliefs = (PartRelief(knurl, v0, v1, ro),)
    return (ClosurePart("shell", chain, mat, reliefs),)


def _crown(cap, f, mat):
    t, scale = 0.3, min(max(2.0 * f.r_neck / 26.0, 0.7), 1.5)
    ri = f.r_neck + f.thread_depth + 0.25
    flare = 2.6 * scale
    zu = f.z_top + GAP_MM
    ztop = zu + t
    zb = max(ztop - (cap.height or 6.0 * scale), f.z_start + GAP_MM)
    dr, dz = flare, zb - zu
    length = math.hypot(dr, dz)
    nr, nz = -dz / length * t, dr / length * t          # the flare's outer side, t away

    def offset_at(z):
        return ri + nr + (z - zu - nz) * dr / dz
    pts = [(0.0, zu), (ri, zu), (ri + flare, zb), (offset_at(zb), zb), (offset_at(ztop), ztop),
           (0.0, ztop)]
    chain = filleted_chain(pts, [0.0, 0.0, 0.1, 0.1, 1.2 * scale, 0.0])
    v0, v1 = line_v(chain, pts[3], pts[4])
    flutes = BumpTile("crown flutes", "flutes", repeat=cap.count or 21, depth=0.6 * scale, width=1.0)
    mid = 0.5 * (pts[3][0] + pts[4][0])
    return (ClosurePart("shell", chain, mat, (PartRelief(flutes, v0 + 0.3, v1 - 0.2, mid),)),)


def _cork(cap, f, mat):
    rc = f.r_bore - SKIRT_GAP_MM
    zc1 = f.z_top - 0.5
    zc0 = max(zc1 - (cap.height or 44.0), f.z_bore + 0.5)
    parts = [ClosurePart("cork", filleted_chain([(0.0, zc0), (rc, zc0), (rc, zc1), (0.0, zc1)],
                                                [0.0, 1.0, 1.0, 0.0]), CORK)]
    if cap.capsule:
        t = 0.25
        ri = f.r_neck + f.thread_depth + SKIRT_GAP_MM
        zu = f.z_top + GAP_MM
        zb = max(zu + t - 50.0, f.z_start + GAP_MM)
        pts, radii = _shell(ri, t, zu, zu + t, zb, 0.8)
        parts.append(ClosurePart("capsule", filleted_chain(pts, radii), mat))
    return tuple(parts)


def _ropp(cap, f, mat):
    t = 0.25
    ri = f.r_neck + f.thread_depth + SKIRT_GAP_MM
    ro = ri + t
    zu = f.z_top + GAP_MM
    ztop = zu + t
    height = cap.height or 4.0 * ro
    zb = max(ztop - height, f.z_start + GAP_MM)
    pts, radii = _shell(ri, t, zu, ztop, zb, 1.2)
    chain = filleted_chain(pts, radii)
    reliefs = []
    if ztop - zb > 12.0:
        knurl = BumpTile("knurl band", "knurl", repeat=cap.count or max(24, round(2 * math.pi * ro / 1.6)),
                         depth=0.12, width=1.0, sharpness=0.5)
        reliefs.append(PartRelief(knurl, *_skirt_v(chain, pts[3], pts[4], ztop - 9.0, ztop - 2.0), ro))
        zp = zb + 0.18 * (ztop - zb)
        bridges = BumpTile("pilfer band", "stipple", repeat=12, depth=0.15, width=0.85, pitch=1.2,
                           inverted=True)
        reliefs.append(PartRelief(bridges, *_skirt_v(chain, pts[3], pts[4], zp - 0.6, zp + 0.6), ro))
    if f.thread is not None:  # the roll-on shell takes the shape of the glass thread
        th = f.thread
        reliefs.append(PartRelief(th, *_skirt_v(chain, pts[3], pts[4], th.z0, th.z1), ro))
    return (ClosurePart("shell", chain, mat, tuple(reliefs)),)


def _lug(cap, f, mat):
    t = 0.25
    ri = f.r_neck + max(f.thread_depth, 0.8) + 0.2
    ro = ri + t
    zu = f.z_top + GAP_MM
    ztop = zu + t
    zb = max(ztop - (cap.height or 0.2 * ri + 5.5), f.z_start + GAP_MM)
    rp, dip = f.r_bore - 2.5, 0.8
    if rp > 4.0:  # a recessed centre panel, inside the bore
        under = [(0.0, zu - dip), (rp, zu - dip), (rp + 1.2, zu)]
        over = [(rp + 1.2, ztop), (rp, ztop - dip), (0.0, ztop - dip)]
    else:
        under, over = [(0.0, zu)], [(0.0, ztop)]
    pts = under + [(ri, zu), (ri, zb), (ro, zb), (ro, ztop)] + over
    n_u = len(under)
    radii = [0.0] + [0.4] * (n_u - 1) + [0.0, 0.1, 0.1, 0.8] + [0.4] * (len(over) - 1) + [0.0]
    chain = filleted_chain(pts, radii)
    band = min(3.0, 0.6 * (ztop - zb))
    lugs = BumpTile("lugs", "stipple", repeat=cap.count or 4, depth=0.6, width=0.1, pitch=band,
                    inverted=True)
    v0, v1 = _skirt_v(chain, (ro, zb), (ro, ztop), zb + 0.4, zb + 0.4 + band)
    return (ClosurePart("shell", chain, mat, (PartRelief(lugs, v0, v1, ro),)),)


_KINDS = {"screw": _screw, "crown": _crown, "cork": _cork, "ropp": _ropp, "lug": _lug}

__all__ = ["closure_parts", "default_cap", "filleted_chain", "line_v", "cap_material"]
