"""Membrane stresses in a round bottle's wall under an internal (proof) pressure.

Design rule: the wall is a thin shell of revolution whose middle surface is the outer section
offset inward by half the wall (``P - t/2 n``, exact for lines and arcs, and the curvature of an
ellipse arc's offset is ``k / (1 - t/2 k)``). At a point of the middle surface with radius ``r``
from the axis, outward normal ``n`` (``n_r = sin(phi)``, ``phi`` the normal's angle to the axis)
and meridional curvature ``k1`` (signed, positive where the meridian bulges outward), the two
principal radii are ``r1 = 1 / k1`` and ``r2 = r / sin(phi)``. A closed (capped) bottle under
pressure ``p`` is in equilibrium with the membrane forces (N/mm)

    N_phi   = p r2 / 2                 (the axial force on the part above a parallel circle)
    N_theta = r2 (p - k1 N_phi)        (Laplace: N_phi / r1 + N_theta / r2 = p)

and the stresses are ``N / t`` (MPa for p in MPa, lengths in mm). A cylinder gives
``p r / t`` (hoop) and ``p r / (2t)`` (meridional), a sphere ``p R / (2t)`` both ways.

Membrane theory holds only away from where the wall must bend; there a point gets no number,
only the reason (:data:`REASONS`): the base (a plate) and the heel (within the bending length
``L = 2.4 sqrt(r2 t)`` of the standing ring), the finish (within ``L`` of the mouth, where the
closure loads the rim), a corner (a joint where the meridian turns by more than
:data:`CORNER_DEG`) or a change of curvature (a joint where ``r2 k1 / 2`` jumps by more than
:data:`CURVATURE_JUMP`, which changes ``N_theta`` by as much of ``p r2``) within ``L`` of it, a
nearly flat wall (``r2`` over :data:`FLAT_FACTOR` times the body's radius), a wall too thick
for a thin shell (``t`` over :data:`THICK_RATIO` of the smaller principal radius), and any
point of a non-round plan (its flat sides carry pressure by bending).

An outline bottle (:mod:`engine.geometry.plan`) is no shell of revolution either: a flat panel
of its plan has no plan curvature (an infinite radius: ``N_theta = p R`` has no finite value,
the panel bends), and where two arcs of different radii meet the hoop force ``p R`` would jump,
which only bending can carry; the meridional force is not ``p r2 / 2`` off a circle. So every
point is marked, as on a rounded square, and its reason quotes the plan's radii of curvature
of the middle surface at that height (each arc's ``k rho + c - t/2``, each corner's ``c - t/2``)
and whether it has flat panels. Its points follow the meridian through the plan's farthest
point (distance ``k + c`` from the axis), their arc length summed along those points.
"""
from __future__ import annotations

import math

import numpy as np

from ..geometry.chain import radius_at
from ..geometry.validate import body_profile

#: Points per segment of the profile (plus its ends).
POINTS_PER_SEGMENT = 24
#: Bending length factor: the edge disturbance of a shell decays over about ``pi / beta``,
#: ``beta = (3 (1 - nu^2))^(1/4) / sqrt(r2 t)`` = 1.29 / sqrt(r2 t) for glass (nu = 0.22): 2.4.
BENDING_FACTOR = 2.4
#: A joint where the meridian turns by more than this (deg) is a corner.
CORNER_DEG = 1.0
#: A joint where ``r2 k1 / 2`` jumps by more than this is a change of curvature.
CURVATURE_JUMP = 0.1
#: A wall whose ``r2`` is more than this times the body's largest radius is nearly flat.
FLAT_FACTOR = 5.0
#: A thin shell: the wall at most this fraction of its smaller principal radius (R/t >= 10).
THICK_RATIO = 0.1

REASONS = {
    "plan": "non-round plan: the flat sides bend between the corners",
    "base": "base: a plate in bending, not a membrane",
    "heel": "heel: bending near the standing ring",
    "finish": "finish: the closure loads the rim",
    "corner": "sharp corner: bending at the joint",
    "curvature": "change of curvature: bending at the joint",
    "flat": "nearly flat wall: carries pressure by bending",
    "thick": "wall too thick for membrane theory (R/t < 10)",
    "outline": "outline plan: not a shell of revolution; its flat panels and the joints of its "
               "arcs carry pressure by bending (each point quotes the plan's radii there)",
}


def _walls(shape) -> list[float]:
    """The wall thickness (mm) of each outer-wall segment of the first section."""
    segs = body_profile(shape).sections[0].outer_wall
    if shape.wall_per_segment is None:
        return [shape.wall_thickness] * len(segs)
    # outer_wall[i] is (part of) section segment k + i, k = first wall segment
    k = len(shape.primary.segments) - len(segs)
    return [shape.wall_per_segment[min(k + i, len(shape.wall_per_segment) - 1)] for i in range(len(segs))]


def _sample(segs, walls):
    """Per point: arc length from the ring (mm), outer point, unit tangent, signed curvature,
    wall (mm) and segment index, along ``segs`` from the ring to the mouth."""
    rows = []
    s0 = 0.0
    for i, (seg, t) in enumerate(zip(segs, walls)):
        u = np.linspace(0.0, 1.0, POINTS_PER_SEGMENT + 1)
        p, tan, k = seg.point(u), seg.tangent(u), np.asarray(seg.curvature(u), float)
        for j in range(len(u)):
            rows.append((s0 + u[j] * seg.length, p[j], tan[j], float(k[j]), t, i))
        s0 += seg.length
    return rows


def _joint_zones(segs, walls):
    """``(s, reason)`` of each joint of ``segs`` where the wall must bend (a corner or a jump
    in curvature), by arc length from the ring (mm)."""
    zones = []
    s = 0.0
    for i in range(len(segs) - 1):
        s += segs[i].length
        a, b = segs[i], segs[i + 1]
        ta, tb = a.tangent(1.0), b.tangent(0.0)
        turn = math.degrees(abs(math.atan2(ta[0] * tb[1] - ta[1] * tb[0], ta[0] * tb[0] + ta[1] * tb[1])))
        if turn > CORNER_DEG:
            zones.append((s, "corner"))
            continue
        r = b.p0[0]
        sin_phi = max(float(tb[1]), 1e-12)
        r2 = r / sin_phi
        ka, kb = float(np.asarray(a.curvature(1.0))), float(np.asarray(b.curvature(0.0)))
        if abs(r2 * (ka - kb)) / 2.0 > CURVATURE_JUMP:
            zones.append((s, "curvature"))
    return zones


def membrane_stresses(shape, pressure_mpa: float) -> dict:
    """Hoop and meridional membrane stresses (MPa) along the outer profile at ``pressure_mpa``.

    Returns the ``stress`` dict of :func:`engine.plant.sheet.plant_numbers`: the points from
    the axis (the base) to the mouth, each with its arc length ``s_mm`` from the axis, height and
    radius of the outer surface (mm), wall ``t_mm``, the two stresses (``None`` where membrane
    theory does not hold) and the reason; the largest stress that holds and where.
    """
    shape.xs.require("stress")
    prof = body_profile(shape)
    if getattr(shape.xs, "plan", None) is not None:  # why: an outline's first section is a scale
        return _summary(_outline_points(shape, prof), pressure_mpa, REASONS["outline"])
    sp = prof.sections[0]
    base_len = sum(s.length for s in sp.outer_base)
    points = []
    s = 0.0
    for seg in sp.outer_base:  # the base: named, not computed
        for u in np.linspace(0.0, 1.0, 5):
            r, z = (float(v) for v in seg.point(u))
            points.append({"s_mm": s + u * seg.length, "z_mm": z, "r_mm": r,
                           "t_mm": shape.base_thickness, "hoop_mpa": None, "meridional_mpa": None,
                           "reason": REASONS["base"]})
        s += seg.length
    segs, walls = sp.outer_wall, _walls(shape)
    zones = _joint_zones(segs, walls)
    total = sum(x.length for x in segs)
    r_body = max(float(np.max(x.point(np.linspace(0, 1, 65))[:, 0])) for x in segs)
    non_round = not shape.xs.revolved
    for s_w, p, tan, k, t, _ in _sample(segs, walls):
        n_r = float(tan[1])  # the outward normal (the tangent turned clockwise) leans out by this
        r_mid = float(p[0]) - 0.5 * t * n_r
        k_mid = k / (1.0 - 0.5 * t * k)
        row = {"s_mm": base_len + s_w, "z_mm": float(p[1]), "r_mm": float(p[0]), "t_mm": t,
               "hoop_mpa": None, "meridional_mpa": None, "reason": None}
        reason = _why_not(s_w, total, t, r_mid, n_r, k_mid, r_body, zones, non_round)
        if reason is None:
            r2 = r_mid / n_r
            n_phi = pressure_mpa * r2 / 2.0
            n_theta = r2 * (pressure_mpa - k_mid * n_phi)
            row["hoop_mpa"], row["meridional_mpa"] = n_theta / t, n_phi / t
        else:
            row["reason"] = REASONS[reason]
        points.append(row)
    return _summary(points, pressure_mpa, REASONS["plan"] if non_round else None)


def _why_not(s, total, t, r_mid, n_r, k_mid, r_body, zones, non_round) -> str | None:
    """The key of :data:`REASONS` why membrane theory does not hold at this point, or ``None``."""
    if non_round:
        return "plan"
    if n_r <= 0.0 or r_mid <= 0.0:
        return "flat"
    r2 = r_mid / n_r
    if r2 > FLAT_FACTOR * r_body:
        return "flat"
    bend = BENDING_FACTOR * math.sqrt(r2 * t)
    if s < bend:
        return "heel"
    if total - s < bend:
        return "finish"
    for s_j, why in zones:
        if abs(s - s_j) < bend:
            return why
    smaller = min(r2, 1.0 / abs(k_mid)) if k_mid != 0.0 else r2
    if t > THICK_RATIO * smaller:
        return "thick"
    return None


def _outline_points(shape, prof) -> list[dict]:
    """The points of an outline bottle (module rule): the base from the axis to the standing
    ring, then the outer wall at :data:`POINTS_PER_SEGMENT` heights a piece between the joints
    of its core and rounding, each marked with its plan's reason."""
    walls = [sp.outer_wall for sp in prof.sections]
    joints = np.unique([p[1] for w in walls for s in w for p in (s.p0, s.p1)])
    u = np.linspace(0.0, 1.0, POINTS_PER_SEGMENT + 1)[:-1]
    z = np.append((joints[:-1, None] + (joints[1:] - joints[:-1])[:, None] * u).ravel(), joints[-1])
    k, c = (radius_at(w, np.clip(z, w[0].p0[1], w[-1].p1[1])) for w in walls)
    t = shape.wall_thickness
    ring = float(k[0] + c[0])
    points = [{"s_mm": f * ring, "z_mm": 0.0, "r_mm": f * ring, "t_mm": shape.base_thickness,
               "hoop_mpa": None, "meridional_mpa": None, "reason": REASONS["base"]}
              for f in (0.0, 0.25, 0.5, 0.75, 1.0)]
    r = k + c
    s = ring + np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(r), np.diff(z)))])
    for i in range(len(z)):
        points.append({"s_mm": float(s[i]), "z_mm": float(z[i]), "r_mm": float(r[i]), "t_mm": t,
                       "hoop_mpa": None, "meridional_mpa": None,
                       "reason": _plan_reason(shape.plan, float(k[i]), float(c[i]) - 0.5 * t)})
    return points


def _plan_reason(plan, k: float, c_mid: float) -> str:
    """Why membrane theory does not hold on an outline's middle surface at core ``k`` and
    rounding ``c_mid`` (mm), with its plan's radii of curvature (mm)."""
    if k <= 1e-9:
        return (f"outline plan, round here (radius {c_mid:.1f} mm) but joined to a non-round "
                "body: not a shell of revolution")
    radii = [k * s.radius + c_mid for s in plan.segments if s.kind == "arc"]
    radii += [c_mid] * len(plan.corners) if c_mid > 0 else []
    flats = any(s.kind == "line" for s in plan.segments)
    what = ("flat panels (no plan curvature) bend between the corners" if flats else
            "the plan radius jumps where its arcs meet: the wall bends there")
    sharp = "; sharp corners" if plan.corners and c_mid <= 0 else ""
    lo, hi = (f"{min(radii):.1f}", f"{max(radii):.1f}") if radii else ("", "")
    curved = "" if not radii else f"; curved parts of plan radius {lo} mm" if lo == hi else \
        f"; curved parts of plan radii {lo}\u2013{hi} mm"
    return f"outline plan: {what}{curved}{sharp}"


def _summary(points, pressure_mpa, plan_note: str | None) -> dict:
    """The stress dict of ``points``; ``plan_note`` the reason every point of a non-round plan
    has (``None``: a round one)."""
    valid = [p for p in points if p["hoop_mpa"] is not None]
    out = {"pressure_mpa": float(pressure_mpa), "max_hoop_mpa": None, "max_meridional_mpa": None,
           "max_mpa": None, "max_at_z_mm": None, "max_kind": None, "points": points,
           "note": plan_note or
           "membrane theory; bending zones (base, heel, finish, joints) marked, not computed"}
    if not valid:
        if plan_note is None:
            out["note"] = "no point of the wall is a membrane (every point is in a bending zone)"
        return out
    out["max_hoop_mpa"] = max(abs(p["hoop_mpa"]) for p in valid)
    out["max_meridional_mpa"] = max(abs(p["meridional_mpa"]) for p in valid)
    top = max(valid, key=lambda p: max(abs(p["hoop_mpa"]), abs(p["meridional_mpa"])))
    hoop = abs(top["hoop_mpa"]) >= abs(top["meridional_mpa"])
    out["max_mpa"] = abs(top["hoop_mpa"]) if hoop else abs(top["meridional_mpa"])
    out["max_kind"] = "hoop" if hoop else "meridional"
    out["max_at_z_mm"] = top["z_mm"]
    return out
