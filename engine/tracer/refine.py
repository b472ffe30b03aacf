"""Refine Embree's mesh hits onto the true surfaces, with their exact oriented normals.

Design rule: the render mesh (:mod:`engine.tracer.geometry`) only *finds* which surface a ray
meets and roughly where (Embree's BVH over a coarse tessellation, float32). Each hit is then
moved onto the exact surface along the ray:

* round walls and punted bases (surfaces of revolution): the exact analytic roots of
  :func:`engine.intersect.revolved_hits` on the segment of the :class:`BodyProfile` chain that
  owns the hit height and its neighbours (a joint may put the true hit on either side); the
  root nearest the mesh hit wins;
* other walls (rounded square / rectangle, oval): safeguarded Newton steps along the ray on
  :meth:`engine.geometry.body.BottleBody.wall_implicit` from the mesh hit (steps clamped to the window);
* flat parts (flat bases, rim, free surface): planes, intersected exactly.

A refined root further than the *window* from the mesh hit (or behind the ray's start, or a
Newton run that does not converge) is no hit at all: the true surface is not crossed there (a
silhouette the chords cut, or a sliver of mesh off the true surface), and the caller lets the
ray pass the mesh unchanged. Units: mm; ``t`` is the distance along unit directions.
"""
from __future__ import annotations

import numpy as np

from ..intersect import revolved_hits, revolved_normals
from ..intersect.revolved import in_sweep
from ..geometry.segments import Arc, EllipseArc
from ..geometry.offset import locate

OUTER_WALL, BOTTOM, INNER_WALL, INNER_BASE, RIM, FREE_SURFACE = range(6)
#: Newton iterations on non-round walls (quadratic convergence from within the tolerance).
NEWTON_STEPS = 12
#: Newton steps polishing an arc hit from the mesh (quadratic: 1e-2 -> 1e-4 -> 1e-8 -> 1e-16).
POLISH_STEPS = 4
#: Plain Newton steps on non-round walls before the bracketed solver takes over.
FAST_STEPS = 3
#: Distance (mm) from the true surface a polished arc hit must be within (else: the quartic).
POLISH_TOL_MM = 1e-11
#: Heights (mm) this near a wall joint also try the segments on both sides.
JOINT_MARGIN_MM = 0.5
#: |g| (mm) under which a Newton iterate is on the surface.
NEWTON_TOL_MM = 1e-11


def _plane(o, d, z0):
    """Distances to the plane ``z = z0`` (inf where the ray runs parallel to it)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (z0 - o[:, 2]) / d[:, 2]
    return np.where(np.isfinite(t), t, np.inf)


def _conic_polish(o, d, t_mesh, seg):
    """Roots of ``seg`` (Arc / EllipseArc) revolved, by Newton from the mesh hit on its exact
    implicit ``((rho - cr)/a)^2 + ((z - cz)/b)^2 - 1`` (the torus / spheroid that
    :func:`revolved_hits` solves as a quartic), kept where it converges inside the arc's sweep;
    ``nan`` elsewhere (the caller then solves the quartic)."""
    a, b = (seg.radius, seg.radius) if isinstance(seg, Arc) else (seg.radius_r, seg.radius_z)
    cr, cz = seg.center
    t = t_mesh.copy()
    for _ in range(POLISH_STEPS):
        p = o + t[:, None] * d
        rho = np.maximum(np.hypot(p[:, 0], p[:, 1]), 1e-300)
        u, v = (rho - cr) / a, (p[:, 2] - cz) / b
        f = u * u + v * v - 1.0
        df = 2.0 * (u / a * (p[:, 0] * d[:, 0] + p[:, 1] * d[:, 1]) / rho + v / b * d[:, 2])
        with np.errstate(divide="ignore", invalid="ignore"):
            t = t - f / df
    p = o + t[:, None] * d
    rho = np.hypot(p[:, 0], p[:, 1])
    u, v = (rho - cr) / a, (p[:, 2] - cz) / b
    ok = np.isfinite(t) & (np.abs(u * u + v * v - 1.0) * (0.5 * min(a, b)) <= POLISH_TOL_MM)  # ~ distance
    ok &= in_sweep(np.arctan2(v, u), seg.angle0, seg.sweep)
    return np.where(ok, t, np.nan)


def _revolved(o, d, t_mesh, chain, candidates, window):
    """Nearest analytic root to ``t_mesh`` over each ray's candidate segments of ``chain``.

    ``candidates`` (N, k) int holds segment indices (-1: none). Lines are solved in closed form
    (cones); circle and ellipse arcs are first polished by Newton on their exact implicit
    (:func:`_conic_polish`); only rays that found nothing that way get every root of their
    arcs from :func:`revolved_hits` (the quartic). Returns ``(t, seg)`` with ``t = nan`` where
    no root lies within ``window`` of the mesh hit.
    """
    best = np.full(len(o), np.nan)
    gap = np.full(len(o), np.inf)
    seg = np.full(len(o), -1, dtype=np.int64)

    def take(i, sel, hits):
        dist = np.abs(hits - t_mesh[sel, None])
        dist = np.where(np.isfinite(dist) & (hits > 0), dist, np.inf)
        k = np.argmin(dist, axis=1)
        dk = dist[np.arange(len(sel)), k]
        better = (dk < gap[sel]) & (dk <= window[sel])
        upd = sel[better]
        gap[upd] = dk[better]
        best[upd] = hits[better, k[better]]
        seg[upd] = i

    arcs = []
    for i in np.unique(candidates[candidates >= 0]):
        sel = np.nonzero(np.any(candidates == i, axis=1))[0]
        if isinstance(chain[i], (Arc, EllipseArc)):
            take(i, sel, _conic_polish(o[sel], d[sel], t_mesh[sel], chain[i])[:, None])
            arcs.append((i, sel))
        else:
            take(i, sel, revolved_hits(o[sel], d[sel], chain[i]))
    for i, sel in arcs:  # the quartic, only where no candidate gave a root near the mesh hit
        sel = sel[np.isnan(best[sel])]
        if len(sel):
            take(i, sel, revolved_hits(o[sel], d[sel], chain[i]))
    return best, seg


def _revolved_normals(points, chain, seg, sign):
    n = np.empty_like(points)
    for i in np.unique(seg):
        m = seg == i
        n[m] = sign * revolved_normals(points[m], chain[i])
    return n


def _wall_candidates(chain, z, margin):
    """Segment holding each height, (N, 1); with its neighbours, (N, 3), -1 past the ends, for
    heights within ``margin`` (mm) of a joint (the true hit may lie across it)."""
    lo, hi = sorted((chain[0].p0[1], chain[-1].p1[1]))
    idx, _ = locate(chain, np.clip(z, lo, hi))
    idx = np.where(idx < 0, 0, idx)
    joints = np.array([s.p1[1] for s in chain[:-1]])
    near = np.zeros(len(z), dtype=bool)
    if len(joints):
        near = np.min(np.abs(z[:, None] - joints[None, :]), axis=1) <= margin
    cand = np.stack([np.where(near, idx - 1, -1), idx, np.where(near, idx + 1, -1)], axis=1)
    return np.where((cand >= 0) & (cand < len(chain)), cand, -1)


def _newton(body, part, o, d, t_mesh, window, tol):
    """Newton along the ray from the mesh hit; the rays where plain steps do not land on the
    surface within :data:`FAST_STEPS` go to :func:`_safe_newton`. Returns ``(t, grad)``."""
    t = t_mesh.copy()
    z_lo, z_hi = body.wall_range(part)
    for _ in range(FAST_STEPS):
        g, grad = body.wall_implicit(part, o + t[:, None] * d)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = t - g / np.einsum("ij,ij->i", grad, d)
    g, grad = body.wall_implicit(part, o + np.where(np.isfinite(t), t, 0.0)[:, None] * d)
    z = o[:, 2] + t * d[:, 2]
    ok = (np.isfinite(t) & (np.abs(g) <= NEWTON_TOL_MM) & (np.abs(t - t_mesh) <= 0.5 * window)
          & (z >= z_lo) & (z <= z_hi))
    bad = np.nonzero(~ok)[0]
    if len(bad):
        t[bad], grad[bad] = _safe_newton(body, part, o[bad], d[bad], t_mesh[bad], window[bad], tol)
    return t, grad


def _first_crossing(body, part, o, d, window, tol):
    """The first sign change of ``g`` along the ray after ``t = 0`` (steps from ``tol / 100``
    doubling up to ``window``), then the safeguarded solve inside it. Returns ``(t, grad)``."""
    f = lambda t: body.wall_implicit(part, o + t[:, None] * d)[0]
    t0 = np.full(len(o), 1e-9)
    f0 = f(t0)
    lo, hi = t0.copy(), np.full(len(o), np.nan)
    step = 0.01 * tol
    prev = t0.copy()
    while step <= 2.0 * np.max(window):
        tt = np.minimum(step, window)
        new = np.isnan(hi) & (np.sign(f(tt)) != np.sign(f0))
        lo, hi = np.where(new, prev, lo), np.where(new, tt, hi)
        prev = np.where(np.isnan(hi), tt, prev)
        step *= 2.0
    found = np.isfinite(hi)
    mid = np.where(found, 0.5 * (lo + np.where(found, hi, lo)), 0.0)
    half = np.where(found, 0.5 * (np.where(found, hi, lo) - lo), 0.0)
    t, grad = _safe_newton(body, part, o, d, mid, half, max(np.max(half), 1e-12))
    return np.where(found, t, np.nan), grad


def _safe_newton(body, part, o, d, t_mesh, window, tol):
    """Safeguarded Newton along the ray on the wall's implicit function ``f(t) = g(o + t d)``.

    A sign change of ``f`` is bracketed first, stepping out from the mesh hit both ways by
    ``tol/2, tol, 2 tol, ...`` up to ``window`` (the crossing nearest the mesh hit); then
    Newton steps, replaced by bisection whenever they would leave the bracket (``rtsafe``).
    Returns ``(t, grad)``; ``t`` is nan where no crossing lies in the window.
    """
    f = lambda t: body.wall_implicit(part, o + t[:, None] * d)
    # g is clamped to the wall's heights: search only where the ray is within them
    z_lo, z_hi = body.wall_range(part)
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (z_lo - o[:, 2]) / d[:, 2], (z_hi - o[:, 2]) / d[:, 2]
    flat = ~np.isfinite(ta) | ~np.isfinite(tb)
    t_min = np.where(flat, -np.inf, np.minimum(ta, tb))
    t_max = np.where(flat, np.inf, np.maximum(ta, tb))
    t_mesh = np.clip(t_mesh, t_min, t_max)
    f0 = f(t_mesh)[0]
    lo, hi = t_mesh.copy(), t_mesh.copy()
    found = f0 == 0.0
    flo = np.where(found, 0.0, f0)
    step = 0.5 * tol
    while not np.all(found) and step <= 2.0 * np.max(window):
        for sgn in (1.0, -1.0):
            tt = np.clip(t_mesh + sgn * np.minimum(step, window), t_min, t_max)
            ft = f(tt)[0]
            new = ~found & (np.sign(ft) != np.sign(f0))
            lo = np.where(new, np.minimum(tt, t_mesh), lo)
            hi = np.where(new, np.maximum(tt, t_mesh), hi)
            found |= new
        step *= 2.0
    flo = f(lo)[0]
    t = 0.5 * (lo + hi)
    for _ in range(NEWTON_STEPS * 5):
        g, grad = f(t)
        done = (np.abs(g) <= NEWTON_TOL_MM) | (hi - lo <= 1e-13 * np.maximum(1.0, np.abs(t)))
        if np.all(done | ~found):
            break
        left = np.sign(g) == np.sign(flo)
        lo, hi = np.where(left, t, lo), np.where(left, hi, t)
        flo = np.where(left, g, flo)
        with np.errstate(divide="ignore", invalid="ignore"):
            tn = t - g / np.einsum("ij,ij->i", grad, d)
        inside = np.isfinite(tn) & (tn > lo) & (tn < hi)
        t = np.where(done, t, np.where(inside, tn, 0.5 * (lo + hi)))
    g, grad = f(t)
    return np.where(found, t, np.nan), grad


#: Surfaces that share an edge: near it the mesh may report one where the true ray meets the other.
NEIGHBOURS = {OUTER_WALL: (RIM, BOTTOM), BOTTOM: (OUTER_WALL,), INNER_WALL: (RIM, INNER_BASE, FREE_SURFACE),
              INNER_BASE: (INNER_WALL, FREE_SURFACE), RIM: (OUTER_WALL, INNER_WALL),
              FREE_SURFACE: (INNER_WALL, INNER_BASE)}


def refine(geom, o, d, t_mesh, surface):
    """Exact hits near mesh hits: on the mesh's surface, else on a neighbouring one.

    Returns ``(t, n, surface)`` as :func:`refine_on` does, with the surface id of the true hit
    (a mesh hit near an edge, say wall / rim, may belong to the neighbouring surface).
    """
    t, n = refine_on(geom, o, d, t_mesh, surface)
    surface = surface.copy()
    for sid, others in NEIGHBOURS.items():
        m = np.nonzero((surface == sid) & ~np.isfinite(t))[0]
        for other in others:
            if not len(m) or (other == FREE_SURFACE and geom.fill_height is None):
                continue
            t2, n2 = refine_on(geom, o[m], d[m], t_mesh[m], np.full(len(m), other, np.int8))
            ok = np.isfinite(t2)
            t[m[ok]], n[m[ok]], surface[m[ok]] = t2[ok], n2[ok], other
            m = m[~ok]
    return t, n, surface


def _inside(body, part, p, slack=1e-9):
    return body.wall_implicit(part, p)[0] <= slack


def refine_on(geom, o, d, t_mesh, surface, forward=False, window_mm=None):
    """Exact hit distances and oriented unit normals (module table of ``geometry``).

    Parameters
    ----------
    geom : RenderGeometry
    o, d : ndarray (N, 3) float64
        Ray origins (mm) and unit directions.
    t_mesh : ndarray (N,)
        Embree's distances to the mesh (mm).
    surface : ndarray (N,) int8
        Surface id of the hit triangle.
    forward : bool
        Find the first crossing after ``t = 0`` instead of the one nearest ``t_mesh`` (rays
        that saw no mesh at all; ``t_mesh`` is then 0).
    window_mm : float, optional
        How far (mm) from ``t_mesh`` a root may lie; ``geom.window_mm`` by default.

    Returns
    -------
    t : ndarray (N,)
        Exact distance (mm) to the true surface; ``nan`` where the true surface is not crossed
        near the mesh hit (the caller lets the ray pass).
    n : ndarray (N, 3)
        Unit normals oriented as the surface table says (meaningless where ``t`` is nan).
    """
    body, prof = geom.body, geom.body.profile
    t = np.full(len(o), np.nan)
    n = np.zeros((len(o), 3))
    window = np.full(len(o), geom.window_mm if window_mm is None else float(window_mm))
    sec = prof.sections[0]
    flat = {RIM: (prof.z_top, 1.0)}
    if geom.fill_height is not None:
        flat[FREE_SURFACE] = (geom.fill_height, 1.0)
    if not prof.punt:
        flat[BOTTOM] = (0.0, -1.0)
        flat[INNER_BASE] = (sec.inner_base[0].p0[1], 1.0)
    for sid, (z0, nz) in flat.items():
        m = surface == sid
        if np.any(m):
            tp = _plane(o[m], d[m], z0)
            tp = np.where(np.abs(tp - t_mesh[m]) <= window[m], tp, np.nan)
            p = o[m] + np.where(np.isfinite(tp), tp, 0.0)[:, None] * d[m]
            p[:, 2] = z0
            inside = _inside(body, "outer" if sid in (RIM, BOTTOM) else "inner", p)
            if sid == RIM:
                inside &= ~_inside(body, "inner", p, -1e-9)
            t[m] = np.where(inside, tp, np.nan)
            n[m, 2] = nz
    walls = ((OUTER_WALL, "outer", sec.outer_wall, 1.0), (INNER_WALL, "inner", sec.inner_wall, -1.0))
    for sid, part, chain, sign in walls:
        m = np.nonzero(surface == sid)[0]
        if not len(m):
            continue
        if body.kind == "round":
            z = o[m, 2] + t_mesh[m] * d[m, 2]
            cand = _wall_candidates(chain, z, JOINT_MARGIN_MM)
            tm, seg = _revolved(o[m], d[m], t_mesh[m], chain, cand, window[m])
            miss = np.nonzero(~np.isfinite(tm))[0]  # the owning segment had no root: try both sides
            if len(miss):
                c2 = _wall_candidates(chain, z[miss], np.inf)
                tm[miss], seg[miss] = _revolved(o[m][miss], d[m][miss], t_mesh[m][miss], chain, c2, window[m][miss])
            good = np.isfinite(tm)
            p = o[m[good]] + tm[good, None] * d[m[good]]
            n[m[good]] = _revolved_normals(p, chain, seg[good], sign)
        else:
            if forward:  # the first crossing ahead, not the one nearest a mesh hit
                tm, grad = _first_crossing(body, part, o[m], d[m], window[m], geom.tol_mm)
            else:
                tm, grad = _newton(body, part, o[m], d[m], t_mesh[m], window[m], geom.tol_mm)
            z_lo, z_hi = body.wall_range(part)
            z = o[m, 2] + tm * d[m, 2]
            tm = np.where((z >= z_lo - 1e-9) & (z <= z_hi + 1e-9), tm, np.nan)
            n[m] = sign * grad / np.linalg.norm(grad, axis=1, keepdims=True)
        t[m] = tm
    if prof.punt:
        for sid, chain, sign in ((BOTTOM, sec.outer_base, 1.0), (INNER_BASE, sec.inner_base, -1.0)):
            m = np.nonzero(surface == sid)[0]
            if not len(m):
                continue
            cand = np.broadcast_to(np.arange(len(chain)), (len(m), len(chain)))
            tm, seg = _revolved(o[m], d[m], t_mesh[m], chain, cand, window[m])
            good = np.isfinite(tm)
            p = o[m[good]] + tm[good, None] * d[m[good]]
            n[m[good]] = _revolved_normals(p, chain, seg[good], sign)
            t[m] = tm
    t[~(t > 0)] = np.nan
    return t, n


def exact_normals(geom, points, surface):
    """Oriented unit normals (module table) at ``points`` (N, 3) mm on the walls and flat parts
    (punted bases excepted: there the owning segment comes from :func:`refine`)."""
    body, sec = geom.body, geom.body.profile.sections[0]
    n = np.zeros_like(points)
    n[:, 2] = np.where(surface == BOTTOM, -1.0, 1.0)
    for sid, part, chain, sign in ((OUTER_WALL, "outer", sec.outer_wall, 1.0),
                                   (INNER_WALL, "inner", sec.inner_wall, -1.0)):
        m = surface == sid
        if not np.any(m):
            continue
        if body.kind == "round":
            seg = _wall_candidates(chain, points[m, 2], 0.0)[:, 1]
            n[m] = _revolved_normals(points[m], chain, seg, sign)
        else:
            _, grad = body.wall_implicit(part, points[m])
            n[m] = sign * grad / np.linalg.norm(grad, axis=1, keepdims=True)
    return n
