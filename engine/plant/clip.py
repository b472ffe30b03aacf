"""Exact half-plane clips of horizontal cross-sections: what a tilted liquid keeps of each.

Design rule: every function here gives, per row, the area (mm^2), the first moment along the
cut's normal ``u`` (mm^3) and the cut's length (mm) of a section where ``p . u >= d``, in closed
form: a disc's circular segment, an ellipse as the unit disc's segment mapped, and any section
bounded by lines and circular arcs (a rounded rectangle, an outline's section of either sign of
its rounding) by Green's theorem along its pieces, each arc's integrals over the angles it keeps.
The cut's length is the area's derivative in ``d`` (a Newton step's slope). :func:`outline_events`
gives the cut's offsets at which an outline's clipped area changes formula (a joint or a tangency
crosses the cut): a quadrature over height that splits there integrates smooth pieces only.
No Qt; float64; mm.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np


def segment(rho, d):
    """Area (mm^2), first moment along u (mm^3) and the cut's length (mm) of the disk of radius
    ``rho`` where ``p.u >= d``."""
    x = np.clip(d / np.where(rho > 0, rho, 1.0), -1.0, 1.0)
    h2 = np.maximum(rho * rho - d * d, 0.0)
    h = np.sqrt(h2)
    area = rho * rho * np.arccos(x) - np.where(np.abs(d) < rho, d * h, 0.0)
    return area, (2.0 / 3.0) * h2 * h, 2.0 * h


def edges(xa, ea, xb, eb, d):
    """Per row, the sums over straight edges ``(xa, ea) -> (xb, eb)`` (counter-clockwise along
    the outline, mm) of the kept parts' Green integrals where ``xi >= d``: ``(xi - d) d eta``
    (area), ``(xi - d)^2 / 2 d eta`` (first moment about the cut) and the signed ``eta`` of the
    points where an edge crosses the cut (leaving: +, entering: -)."""
    f, f1 = xa - d[:, None], xb - d[:, None]
    de = eb - ea
    with np.errstate(divide="ignore", invalid="ignore"):  # the kept part: f0 + t (f1 - f0) >= 0
        tc = np.clip(f / (f - f1), 0.0, 1.0)
    ta = np.where(f >= 0, 0.0, np.where(f1 >= 0, tc, 1.0))
    tb = np.where(f1 >= 0, 1.0, np.where(f >= 0, tc, 0.0))
    fa, fb = f + ta * (f1 - f), f + tb * (f1 - f)
    dt = np.maximum(tb - ta, 0.0)  # an edge wholly cut away keeps nothing
    area = np.sum(de * dt * 0.5 * (fa + fb), axis=1)
    m2 = np.sum(de * dt * (fa * fa + fa * fb + fb * fb) / 6.0, axis=1)  # int f^2/2, f linear
    crossing = (f >= 0) != (f1 >= 0)
    chord = np.sum(np.where(crossing, (ea + tc * de) * np.where(f >= 0, 1.0, -1.0), 0.0), axis=1)
    return area, m2, chord


def arcs(cxi, ceta, r, t0, d, sweep=0.5 * math.pi):
    """The sums of :func:`edges` over arcs of radius ``r`` (mm) about ``(cxi, ceta)``,
    running counter-clockwise from the angle ``t0`` (rad) through ``t0 + sweep`` (``0 <= sweep
    <= 2 pi``; quarter arcs by default); every array ``(rows, arcs)``, ``d`` per row. On the arc
    ``xi = cxi + r cos t``, ``d eta = r cos t dt``: the integrals are closed forms over the
    angles where ``cos t >= k = (d - cxi) / r``, the interval ``[-beta, beta]`` (mod 2 pi),
    ``beta = acos k``; with ``t0`` in ``[-pi, pi)`` the arc ends before ``3 pi``, so the
    interval and its copy one turn on meet every arc."""
    K = cxi - d[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(r > 0, -K / np.where(r > 0, r, 1.0), np.where(K >= 0, -2.0, 2.0))
    beta = np.arccos(np.clip(k, -1.0, 1.0))
    t0 = np.mod(t0 + math.pi, 2 * math.pi) - math.pi       # in [-pi, pi): one turn is enough
    t1 = t0 + sweep
    full = (k <= -1.0) | (k >= 1.0)
    ends = np.where(full, 0.0, r * np.sin(beta))  # the cut's ends on the arc: eta - ceta = +-r sin(beta)
    rr, Kr = r * r, K * r

    def F(t):
        s, c = np.sin(t), np.cos(t)
        a = Kr * s + rr * (0.5 * t + 0.5 * s * c)
        m = 0.5 * r * (K * K * s + Kr * (t + s * c) + rr * (s - s * s * s / 3.0))  # why not s**3: pow, 100x slower
        return a, m
    area = m2 = chord = 0.0
    for shift in (0.0, 2 * math.pi):
        if shift and np.all(shift - beta >= t1):
            break  # no arc reaches the interval's copy one turn on: nothing to add
        lo = np.maximum(t0, shift - beta)
        hi = np.minimum(t1, shift + beta)
        hi = np.maximum(hi, lo)
        (a1, m1), (a0, m0) = F(hi), F(lo)
        area, m2 = area + a1 - a0, m2 + m1 - m0
        # the cut's ends on the arc: leaving at +beta, entering at -beta (inside the arc's span)
        for at, sign in ((shift + beta, 1.0), (shift - beta, -1.0)):
            inside = (at >= t0) & (at < t1) & ~full
            chord = chord + np.where(inside, sign * ceta + ends, 0.0)
    return np.sum(area, axis=1), np.sum(m2, axis=1), np.sum(chord, axis=1)


def rounded_rect(a, b, r, psi: float, d):
    """Area (mm^2), first moment along ``u`` (mm^3) and the cut's length (mm) where ``p . u >= d``
    of the rounded rectangles of half-width ``a``, half-depth ``b`` and corner radius ``r``
    (arrays per row, mm), ``u`` at the angle ``psi``: four sides and four quarter arcs, exact."""
    c, s = math.cos(psi), math.sin(psi)
    A, B = a - r, b - r
    # the sides, counter-clockwise: right, top, left, bottom
    x0 = np.column_stack([a, A, -a, -A]); y0 = np.column_stack([-B, b, B, -b])
    x1 = np.column_stack([a, -A, -a, A]); y1 = np.column_stack([B, b, -B, -b])
    la, lm, lc = edges(x0 * c + y0 * s, -x0 * s + y0 * c, x1 * c + y1 * s, -x1 * s + y1 * c, d)
    cx = np.column_stack([A, -A, -A, A]); cy = np.column_stack([B, B, -B, -B])
    t0 = np.array([0.0, 0.5, 1.0, 1.5]) * math.pi - psi
    aa, am, ac = arcs(cx * c + cy * s, -cx * s + cy * c, r[:, None] + 0 * cx,
                            np.broadcast_to(t0, cx.shape), d)
    area = la + aa
    return area, lm + am + d * area, np.abs(lc + ac)


def oval(a, b, psi: float, d):
    """Area, first moment along ``u`` and the cut's length of the ellipses of half axes ``a``,
    ``b`` (mm) where ``p . u >= d``: the ellipse is the unit disc mapped by ``diag(a, b)``, so it
    is the unit disc's segment at ``d / w``, ``w = |(a cos psi, b sin psi)|``, scaled (exact)."""
    w = np.hypot(a * math.cos(psi), b * math.sin(psi))
    area, m, chord = segment(np.ones_like(w), d / w)
    return a * b * area, a * b * w * m, chord * a * b / w


def outline(plan, k, r, psi: float, d):
    """Area (mm^2), first moment along ``u`` (mm^3) and the cut's length (mm) where ``p . u >= d``
    of the outline sections ``{q : sd(q, k P) <= r}`` (arrays per row, mm; ``r`` of either sign),
    ``u`` at the angle ``psi``: Green's theorem along each section's lines and arcs, exact."""
    c, s = math.cos(psi), math.sin(psi)
    area, m, chord = (np.zeros(np.shape(k)) for _ in range(3))
    for rows in (r >= 0, r < 0):  # why apart: the two signs have different lists of pieces
        if not rows.any():
            continue
        n, dd = int(rows.sum()), d[rows]
        pieces = plan.section_pieces(k[rows], r[rows])

        def cols(kind, i):  # (rows, pieces of that kind): a flask has no lines
            return np.array([np.broadcast_to(p[i], n) for p in pieces if p[0] == kind]).reshape(-1, n).T
        ax, ay, bx, by = (cols("line", i) for i in range(1, 5))
        la, lm, lc = edges(ax * c + ay * s, -ax * s + ay * c, bx * c + by * s, -bx * s + by * c, dd)
        cx, cy, rho, a0, a1 = (cols("arc", i) for i in range(1, 6))
        aa, am, ac = arcs(cx * c + cy * s, -cx * s + cy * c, rho, a0 - psi, dd, a1 - a0)
        area[rows], m[rows], chord[rows] = la + aa, lm + am + dd * (la + aa), np.abs(lc + ac)
    return area, m, chord


def outline_events(plan, k, r, grown: bool, psi: float, d):
    """``(rows, events)``: per row, how far (mm) beyond the cut ``p . u = d`` each place lies where
    the clipped area of the outline section ``{q : sd(q, k P) <= r}`` (``k``, ``r``, ``d`` arrays
    per row; ``grown``: the pieces of ``r >= 0``, as :meth:`~engine.geometry.plan.PlanOutline.section_pieces`)
    changes formula as ``d`` passes it: each piece's start (a joint) and each arc's points whose
    normal is ``+-u`` (where the cut touches it; NaN where the arc's span does not hold that
    normal). A root in height of a column is where a quadrature should split.

    A grown section's pieces are linear in ``(k, r)`` and keep their angles, so its columns are
    ``k A + r B - d`` with ``A``, ``B`` found once per plan and direction (:func:`_grown_events`):
    no pieces are built per call (the tilted liquid's event search asks again and again)."""
    k, r, d = (np.asarray(v, float) for v in (k, r, d))
    if grown:
        a, b, ra, rb, tangent, held = _grown_events(plan, psi)
        kk, rr = k[:, None], r[:, None]
        return np.where(~tangent | (held & (kk * ra + rr * rb > 0)), kk * a + rr * b - d[:, None], np.nan)
    n = np.shape(k)[0]
    cols = [np.where(held & (rho > 0), off - d, np.nan) if rho is not None else off - d
            for off, rho, held in _event_columns(plan.section_pieces(k, r, False), psi)]
    return np.column_stack([np.broadcast_to(c, n) for c in cols])


def _event_columns(pieces, psi: float):
    """Per event of ``pieces`` (in :func:`outline_events`' order): its offset along ``u`` (mm,
    the cut at 0), and for an arc's touching point the arc's radius (mm; it must be > 0) and
    whether the arc's span holds that normal (else ``None``, ``True``)."""
    ux, uy = math.cos(psi), math.sin(psi)
    for p in pieces:
        if p[0] == "line":
            yield p[1] * ux + p[2] * uy, None, True
            continue
        _, cx, cy, rho, a0, a1 = p
        centre = cx * ux + cy * uy
        yield centre + rho * (np.cos(a0) * ux + np.sin(a0) * uy), None, True
        for sign, at in ((1.0, psi), (-1.0, psi + math.pi)):
            yield centre + sign * rho, rho, (at - a0) % (2 * math.pi) <= a1 - a0


@lru_cache(maxsize=64)
def _grown_events(plan, psi: float):
    """``(A, B, RA, RB, tangent, held)`` per column of :func:`outline_events` on grown sections:
    the offset is ``k A + r B`` (mm); a touching point (``tangent``) counts where its arc's span
    holds the normal (``held``, fixed: a grown piece keeps its angles) and its radius
    ``k RA + r RB`` is > 0. Read off the pieces at ``(k, r) = (1, 0)`` and ``(0, 1)``."""
    cols = list(_event_columns(plan.section_pieces(np.array([1.0, 0.0]), np.array([0.0, 1.0]), True), psi))
    off = np.array([np.broadcast_to(c[0], 2) for c in cols]).T
    rho = np.array([np.broadcast_to(c[1] if c[1] is not None else 0.0, 2) for c in cols]).T
    tangent = np.array([c[1] is not None for c in cols])
    held = np.array([bool(c[2]) for c in cols])
    return off[0], off[1], rho[0], rho[1], tangent, held
