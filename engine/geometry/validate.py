"""Section and wall validation: each error names the offending segment in designer's words.

Design rule: validation never repairs anything; it raises ``SectionError(index, msg)`` for a
section that is not a bottle profile and ``WallError`` for thicknesses the section cannot carry.
Tolerances: 1e-6 mm for points and 1e-6 rad for tangency (SPEC 4.1).

What a valid section is (SPEC 4.1, extended by the punt):

* ``segments[0]`` starts on the axis (r = 0). The **base part** runs from there to the
  **standing ring**, where the section first reaches z = 0: a joint, or the lowest point of an
  arc / ellipse arc, which is then split there (:func:`engine.geometry.offset.split_at_ring`).
  - *Flat base* (SPEC): the base part is one horizontal ``Line`` from ``(0, 0)`` to ``(r_base, 0)``.
  - *Punt* (round bottles only): the section starts at ``(0, h_punt)``, ``h_punt > 0``, leaving the
    axis horizontally (tangent within 1e-6 rad of +r); along the base part r rises strictly and z
    never rises (it descends to the ring at z = 0); the base stays at z >= 0 and the wall never
    crosses it. The inner base is then the base part offset by ``base_thickness``.
* The **wall part** (ring -> mouth): z rises strictly along every segment (no overhangs, no
  horizontal parts), r > 0, and the last segment is a vertical line going up (the finish).
* Joints are continuous (1e-6 mm); where ``smooth[i]`` asks for tangency between segments
  ``i`` and ``i + 1`` the tangents agree to 1e-6 rad; arcs have their end points on their
  circle / ellipse and are not degenerate (no zero length).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..errors import SectionError, WallError
from .offset import BodyProfile, build_body_profile, is_flat_base, locate, radius_at, split_at_ring
from .segments import Arc, EllipseArc, Line, POINT_TOL_MM

ANGLE_TOL_RAD = 1e-6
#: Points per base segment where the punt and the wall are held against each other.
BASE_SAMPLES = 1025
#: How far (mm) a wall point may lie below the base's polyline through those points before it
#: crosses the punt: above the chords' sag (under 1e-5 mm for any base a bottle can have at
#: 1025 points), far below anything a designer draws.
BASE_CROSS_TOL_MM = 1e-3


def _angle_inside(seg, angles) -> bool:
    """Whether an arc's parameter angle passes strictly through any of ``angles`` (rad)."""
    a0, sw = seg.angle0, seg.sweep
    for a in angles:
        d = ((a - a0) * math.copysign(1.0, sw)) % (2 * math.pi)
        if 1e-9 < d < abs(sw) - 1e-9:
            return True
    return False


def _check_segment(i: int, seg) -> None:
    """Degenerate segments and arc end points off their curve."""
    if seg.length < POINT_TOL_MM:
        raise SectionError(i, f"degenerate {seg.kind}: length {seg.length:.3g} mm")
    if isinstance(seg, Arc):
        for name, p in (("start", seg.p0), ("end", seg.p1)):
            off = abs(math.hypot(p[0] - seg.center[0], p[1] - seg.center[1]) - seg.radius)
            if off > POINT_TOL_MM:
                raise SectionError(i, f"arc {name} point {p} is {off:.3g} mm off its circle")
    elif isinstance(seg, EllipseArc):
        for name, p in (("start", seg.p0), ("end", seg.p1)):
            er, ez = (p[0] - seg.center[0]) / seg.radius_r, (p[1] - seg.center[1]) / seg.radius_z
            off = abs(math.hypot(er, ez) - 1.0) * min(seg.radius_r, seg.radius_z)
            if off > POINT_TOL_MM:
                raise SectionError(i, f"ellipse arc {name} point {p} is about {off:.3g} mm off its ellipse")


def r_min(seg) -> float:
    """Smallest r (mm) on a segment (exact)."""
    r = min(seg.p0[0], seg.p1[0])
    if isinstance(seg, Arc) and _angle_inside(seg, [math.pi]):
        r = seg.center[0] - seg.radius
    if isinstance(seg, EllipseArc) and _angle_inside(seg, [math.pi]):
        r = seg.center[0] - seg.radius_r
    return r


def r_max(seg) -> float:
    """Largest r (mm) on a segment (exact)."""
    r = max(seg.p0[0], seg.p1[0])
    if isinstance(seg, (Arc, EllipseArc)) and _angle_inside(seg, [0.0]):
        r = seg.center[0] + (seg.radius if isinstance(seg, Arc) else seg.radius_r)
    return r


def _monotone(seg, axis: int) -> bool:
    """Whether r (axis 0) or z (axis 1) is monotone along the segment (exact for arcs)."""
    if isinstance(seg, Line):
        return True
    turning = [0.0, math.pi] if axis == 0 else [math.pi / 2, -math.pi / 2]
    return not _angle_inside(seg, turning)


def validate_section(section, may_reach_axis: bool = False) -> None:
    """Check one section against the rules of the module docstring.

    Parameters
    ----------
    section : Section
        The section (mm).
    may_reach_axis : bool
        Let the wall touch the axis (``r >= 0``): an outline bottle's core, which vanishes
        into its round neck.

    Raises
    ------
    SectionError
        With ``index`` the offending segment (``None`` for the section as a whole) and a
        message a designer can act on. Returns ``None`` when the section is valid.
    """
    segs = section.segments
    if len(segs) < 2:
        raise SectionError(None, "a section needs at least a base and a finish segment")
    if abs(segs[0].p0[0]) > POINT_TOL_MM:
        raise SectionError(0, f"the section must start on the axis (r = 0), starts at r = {segs[0].p0[0]:g} mm")
    for i, seg in enumerate(segs):
        _check_segment(i, seg)
        if r_min(seg) < -POINT_TOL_MM:  # why first: a crossing also breaks tangents and joints
            raise SectionError(i, f"the section crosses the axis (it reaches r = {r_min(seg):.4g} mm; "
                                  f"every point must stay at r >= 0)")
    for i in range(len(segs) - 1):
        a, b = segs[i].p1, segs[i + 1].p0
        gap = math.hypot(a[0] - b[0], a[1] - b[1])
        if gap > POINT_TOL_MM:
            raise SectionError(i + 1, f"does not start where segment {i} ends (gap {gap:.3g} mm)")
        if section.smooth[i]:
            ta, tb = segs[i].tangent(1.0), segs[i + 1].tangent(0.0)
            turn = math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(np.dot(ta, tb)))
            if abs(turn) > ANGLE_TOL_RAD:
                raise SectionError(i + 1, f"the joint between segments {i} and {i + 1} is set "
                                          f"smooth but the tangent turns {math.degrees(turn):.4g} deg there")
    base, wall, k = split_at_ring(section)
    _check_base(section, base, wall, k)
    for i, seg in enumerate(wall, start=k):
        if not (seg.p1[1] > seg.p0[1] + POINT_TOL_MM) or not _monotone(seg, 1):
            raise SectionError(i, "the wall must rise: z has to increase strictly along it "
                                  "(no overhang or horizontal part)")
        if r_min(seg) <= POINT_TOL_MM and not may_reach_axis:
            raise SectionError(i, "the wall touches or crosses the axis (r must stay > 0)")
    last = segs[-1]
    if not isinstance(last, Line) or abs(last.p1[0] - last.p0[0]) > POINT_TOL_MM:
        raise SectionError(len(segs) - 1, "the last segment must be a vertical line (the finish)")


def _check_base(section, base, wall, k: int) -> None:
    """The base part: the SPEC flat base, or a punt descending from the axis to the ring."""
    segs = section.segments
    if is_flat_base(section):
        if segs[0].p1[0] <= POINT_TOL_MM:
            raise SectionError(0, "the flat base needs a positive radius")
        return
    if segs[0].p0[1] <= POINT_TOL_MM:
        raise SectionError(0, "the base must be a horizontal line at z = 0 (flat base) or start "
                              "above z = 0 on the axis and descend (punt)")
    t0 = segs[0].tangent(0.0)
    if abs(math.atan2(t0[1], t0[0])) > ANGLE_TOL_RAD:
        raise SectionError(0, "a punt must leave the axis horizontally (else it has a cone tip)")
    for i, seg in enumerate(base):
        if not (seg.p1[0] > seg.p0[0]) or not _monotone(seg, 0):
            raise SectionError(i, "along the base r must increase strictly from the axis to the ring")
        if seg.p1[1] > seg.p0[1] + POINT_TOL_MM or not _monotone(seg, 1):
            raise SectionError(i, "a punt must descend from the axis to the standing ring (z may not rise)")
    base_r = np.concatenate([s.point(np.linspace(0, 1, BASE_SAMPLES))[:, 0] for s in base])
    base_z = np.concatenate([s.point(np.linspace(0, 1, BASE_SAMPLES))[:, 1] for s in base])
    inside = (base_z >= wall[0].p0[1]) & (base_z <= wall[-1].p1[1])
    r_wall = radius_at(wall, base_z[inside])
    crossing = r_wall < base_r[inside] - POINT_TOL_MM
    if np.any(crossing):
        j = int(np.min(locate(wall, base_z[inside][crossing])[0]))
        raise SectionError(k + j, "the wall crosses the punt (self-intersection)")
    # why the other way too: a fine zigzag of the wall can reach into the punt between the base's
    # samples; its tips are the wall's joints (and its arcs' samples), each held against the base
    # height at its radius (the base is a function of r: r rises strictly along it)
    for j, seg in enumerate(wall):
        p = seg.point(np.linspace(0.0, 1.0, 33))
        below = p[:, 0] < base_r[-1]
        if np.any(below):
            z_base = np.interp(p[below, 0], base_r, base_z)
            if np.any(p[below, 1] < z_base - BASE_CROSS_TOL_MM):
                raise SectionError(k + j, "the wall crosses the punt (self-intersection)")


def _named(name: str, exc: SectionError) -> SectionError:
    msg = str(exc)
    if exc.index is not None:
        msg = msg.split(": ", 1)[1]
    return SectionError(exc.index, f"{name} section: {msg}")


def _sample_heights(chains, z_lo: float, z_hi: float) -> np.ndarray:
    """Heights (mm) to check a cross-section at: every joint, 33 per segment and a dense grid."""
    zs = [np.linspace(z_lo, z_hi, 401)]
    for chain in chains:
        for s in chain:
            zs.append(s.point(np.linspace(0.0, 1.0, 33))[:, 1])
    z = np.unique(np.concatenate(zs))
    return z[(z >= z_lo) & (z <= z_hi)]


def validate_shape(shape) -> BodyProfile:
    """Raise ``SectionError`` / ``WallError`` unless ``shape`` builds a valid glass body.

    Checks every section (:func:`validate_section`, errors prefixed with the section name), the
    thicknesses, for non-round bottles equal ``z_top``, a flat base, a round finish (the sections
    converge: ``u = v``, ``half_width = half_depth = corner`` or ``a = b`` at the mouth) and a
    valid outer and inner cross-section at every height; then builds the inner walls and checks
    that each is thinner than the radius of curvature of convex parts, stays off the axis and rises.
    Returns the :class:`~engine.geometry.offset.BodyProfile` it built (use :func:`body_profile`
    for the cached one).
    """
    kind, xs = shape.cross_section, shape.xs
    for name, sec in shape.sections:
        try:
            validate_section(sec, may_reach_axis=name in xs.vanishing)
        except SectionError as exc:
            raise _named(name, exc) from None
    w, bt = shape.wall_thickness, shape.base_thickness
    if not (w > 0 and math.isfinite(w)):
        raise WallError(f"the wall thickness must be a positive number of mm, got {w:g}")
    if kind != "outline":  # (an outline bottle's wall is the plan offset: SPEC_outline 5)
        _check_convex_radii(shape)  # why before the base: a thicker base cannot cure this one
    if not (bt >= w and math.isfinite(bt)):
        raise WallError(f"the base ({bt:g} mm) must be at least as thick as the wall ({w:g} mm)")
    if not math.isfinite(shape.rotation_deg):
        raise SectionError(None, f"the rotation must be a finite number of degrees, got {shape.rotation_deg}")
    if bt >= shape.z_top:
        raise WallError(f"the base ({bt:g} mm) is as thick as the bottle is high ({shape.z_top:g} mm)")
    if shape.wall_per_segment is not None:
        if not xs.revolved:
            raise WallError("a wall thickness per segment is only supported on round bottles")
        if any(not (x > 0 and math.isfinite(x)) for x in shape.wall_per_segment):
            raise WallError("every per-segment wall thickness must be a positive number of mm")
    if kind == "outline":
        return _check_outline(shape)
    if not xs.revolved:
        _check_non_round_outer(shape)
    return _check_walls(shape)


def _check_outline(shape) -> BodyProfile:
    """An outline bottle (SPEC_outline 3 and 5): flat bases, both profiles ending at the mouth,
    the rounding positive everywhere, and at every height of the cavity an inner section with a
    1 mm disc and every piece of the outline (:meth:`engine.geometry.plan.PlanOutline.
    inner_reason`). Heights are sampled as for the other kinds (every joint, and densely)."""
    for name, sec in shape.sections:
        if not is_flat_base(sec):
            raise SectionError(0, f"{name} profile: an outline bottle stands on a flat base")
        if abs(sec.z_top - shape.z_top) > POINT_TOL_MM:
            raise SectionError(len(sec) - 1, f"{name} profile ends at z = {sec.z_top:g} mm, "
                                             f"not at the mouth z = {shape.z_top:g} mm")
    round_wall = split_at_ring(shape.section("round"))[1]
    for i, seg in enumerate(round_wall, start=1):
        if r_min(seg) <= POINT_TOL_MM:
            raise SectionError(i, "round profile: the rounding must stay above 0 mm")
    prof = build_body_profile(shape)
    core, rnd = (sp.inner_wall for sp in prof.sections)
    z = _sample_heights([core, rnd], prof.z_ib, prof.z_top)
    k = radius_at(core, np.clip(z, core[0].p0[1], core[-1].p1[1]))
    t = radius_at(rnd, np.clip(z, rnd[0].p0[1], rnd[-1].p1[1]))
    for zj, kj, tj in zip(z, k, t):
        reason = shape.plan.inner_reason(float(kj), float(tj))
        if reason is not None:
            raise WallError(f"the cavity at z = {zj:.4g} mm (core {kj:.4g} mm, rounding less the wall "
                            f"{tj:.4g} mm): {reason}")
    return prof


def _check_non_round_outer(shape) -> None:
    z_top = shape.z_top
    for name, sec in shape.sections:
        if not is_flat_base(sec):
            raise SectionError(0, f"{name} section: a punt is only supported on round bottles")
        if abs(sec.z_top - z_top) > POINT_TOL_MM:
            raise SectionError(len(sec) - 1, f"{name} section ends at z = {sec.z_top:g} mm, "
                                             f"not at the mouth z = {z_top:g} mm")
    walls = [sec.segments[1:] for _, sec in shape.sections]
    if not shape.xs.is_circle([sec.r_top for _, sec in shape.sections]):
        raise SectionError(len(shape.primary) - 1, "the sections must meet in a round finish "
                                                   "(equal radii at the mouth)")
    _check_cross_sections(shape.xs, walls, 0.0, z_top, "outer")


def _check_cross_sections(xs, chains, z_lo, z_hi, which, err=SectionError) -> None:
    z = _sample_heights(chains, z_lo, z_hi)
    radii = [radius_at(c, np.clip(z, c[0].p0[1], c[-1].p1[1])) for c in chains]
    bad, rule = xs.invalid(radii)
    if np.any(bad):
        j = int(np.argmax(bad))
        vals = ", ".join(f"{r[j]:.4g}" for r in radii)
        where = f"{which} cross-section invalid at z = {z[j]:.4g} mm: needs {rule} (radii {vals} mm)"
        if err is SectionError:
            raise SectionError(int(locate(chains[0], z[j])[0]) + 1, where)
        raise WallError(where)


def _check_convex_radii(shape) -> None:
    """The wall thinner than the radius of curvature of every convex part of every section."""
    for name, sec in shape.sections:
        _, wall, k = split_at_ring(sec)
        walls = shape.wall_per_segment or [shape.wall_thickness] * len(wall)
        if len(walls) != len(wall):
            raise WallError(f"{len(walls)} wall thicknesses given for {len(wall)} wall segments")
        for i, w, seg in zip(range(k, len(sec)), walls, wall):
            if not isinstance(seg, Line) and seg.direction == "ccw":
                kappa = float(np.max(seg.curvature(np.linspace(0.0, 1.0, 513))))
                if isinstance(seg, EllipseArc):
                    for s in (0.0, math.pi / 2, math.pi, -math.pi / 2):
                        if _angle_inside(seg, [s]):
                            a, b = seg.radius_r, seg.radius_z
                            kappa = max(kappa, a * b / (a * a * math.sin(s) ** 2 + b * b * math.cos(s) ** 2) ** 1.5)
                if w * kappa >= 1.0 - 1e-12:
                    what = "arc" if isinstance(seg, Arc) else "ellipse arc (at its tightest)"
                    raise WallError(f"{name} section, segment {i}: a {w:g} mm wall does not fit inside "
                                    f"the {1 / kappa:.4g} mm radius of this convex {what}; the wall "
                                    f"must be thinner than {1 / kappa:.4g} mm here")


def _check_walls(shape) -> BodyProfile:
    """Inner walls off the axis, rising and valid (the convex radii were checked before).
    Returns the body profile it had to build for that."""
    prof = build_body_profile(shape)
    for sp, (name, sec) in zip(prof.sections, shape.sections):
        outer, k = sp.outer_wall, split_at_ring(sec)[2]
        # All inner segments at once (one locate call): the check stays linear in the segments.
        p = np.stack([seg.point(np.linspace(0.0, 1.0, 65)) for seg in sp.inner_wall])
        at_axis = np.min(p[..., 0], axis=1) <= POINT_TOL_MM
        falls = np.any(np.diff(p[..., 1], axis=1) < -1e-12, axis=1)
        if np.any(at_axis | falls):
            m = int(np.argmax(at_axis | falls))
            z0 = np.clip(p[m, :1, 1], outer[0].p0[1], outer[-1].p1[1])
            j = k + max(int(locate(outer, z0)[0][0]), 0)
            if at_axis[m]:
                raise WallError(f"{name} section, segment {j}: the wall is thicker than the radius "
                                f"there (the inner wall reaches the axis)")
            raise WallError(f"{name} section, segment {j}: the inner wall does not rise "
                            f"(wall too thick for this part of the section)")
        if sp.inner_wall[0].p0[1] >= shape.z_top - POINT_TOL_MM:
            raise WallError(f"{name} section: the inner base reaches the mouth")
    if not prof.xs.revolved:
        _check_cross_sections(prof.xs, [sp.inner_wall for sp in prof.sections],
                              prof.z_ib, prof.z_top, "inner", WallError)
    return prof


@lru_cache(maxsize=64)
def body_profile(shape) -> BodyProfile:
    """The validated, cached :class:`~engine.geometry.offset.BodyProfile` of ``shape``.

    Raises ``SectionError`` / ``WallError`` (from :func:`validate_shape`) when the shape is not a
    valid bottle; a valid shape's profile is built once, by the validation itself, and kept
    (shapes are hashable values).
    """
    return validate_shape(shape)
