"""Plan outlines (engine.geometry.plan, SPEC_outline): reading and refusals, the derived quantities
of P, exact outer and inner sections, areas, the signed distance and its derivatives, polylines and
presets. Every reference is computed here without the module: closed forms, dense sampling of the
outline straight from its dictionaries (with Richardson extrapolation), half-plane clipping, brute
force distances."""
import json
import math
from pathlib import Path

import mpmath
import numpy as np
import pytest

from engine.errors import MAX_MESSAGE_CHARS, OutlineError
from engine.geometry import crosssection as cs
from engine.geometry import plan as pl

SPECS = Path("/work/shared/oracle/specs")


def public_outline(n):
    path = SPECS / f"outline_public_{n}.json"
    return json.loads(path.read_text())["bottle"]["cross_section"]["outline"]


def d_shape():
    """A circle cut by a chord: two line-arc sharp corners (30 deg each)."""
    a0, a1 = math.radians(-60), math.radians(240)
    p0, p1 = [math.cos(a0), math.sin(a0)], [math.cos(a1), math.sin(a1)]
    return pl.PlanOutline.from_dicts([{"type": "arc", "center": [0, 0], "radius": 1, "p0": p0, "p1": p1, "ccw": True},
                                      {"type": "line", "p0": p1, "p1": p0}])


def rectangle(a, b, corner=0.0):
    """Half-width ``a``, half-depth ``b``, corners rounded with ``corner`` (dictionaries)."""
    if corner == 0:
        pts = [[a, -b], [a, b], [-a, b], [-a, -b]]
        return [{"type": "line", "p0": pts[i], "p1": pts[(i + 1) % 4]} for i in range(4)]
    out = []
    for j, (sx, sy) in enumerate([(1, -1), (1, 1), (-1, 1), (-1, -1)]):
        c = [sx * (a - corner), sy * (b - corner)]
        t0 = math.pi / 2 * (j - 1)  # the normal angle where this corner's arc starts
        p0 = [c[0] + corner * math.cos(t0), c[1] + corner * math.sin(t0)]
        p1 = [c[0] + corner * math.cos(t0 + math.pi / 2), c[1] + corner * math.sin(t0 + math.pi / 2)]
        out.append({"type": "arc", "center": c, "radius": corner, "p0": p0, "p1": p1, "ccw": True})
    return [x for i, arc in enumerate(out) for x in (arc, {"type": "line", "p0": arc["p1"], "p1": out[(i + 1) % 4]["p0"]})]


SHAPES = {"hexagon": lambda: pl.hexagon(), "flask": lambda: pl.flask(100, 30), "shield": lambda: pl.shield(),
          "d_shape": d_shape, "rounded_rect": lambda: pl.PlanOutline.from_dicts(rectangle(2.0, 1.0, 0.3)),
          "triangle": lambda: pl.triangle(), "rounded_pentagon": lambda: pl.regular_polygon(5, 0.3, 10.0)}


# --------------------------------------------------------------------------- independent references
def dense(dicts, n):
    """``n`` points per segment (per radian of an arc turning more) on the chain, straight from
    the dictionaries; shape ``(N, 2)``."""
    out = []
    for d in dicts:
        if d["type"] == "line":
            s = np.linspace(0.0, 1.0, n, endpoint=False)
            p0, p1 = np.array(d["p0"], float), np.array(d["p1"], float)
            out.append(p0 + s[:, None] * (p1 - p0))
        else:
            c = np.array(d["center"], float)
            a0 = math.atan2(d["p0"][1] - c[1], d["p0"][0] - c[0])
            sweep = (math.atan2(d["p1"][1] - c[1], d["p1"][0] - c[0]) - a0) % (2 * math.pi)
            a = a0 + np.linspace(0.0, 1.0, int(n * max(1.0, sweep)), endpoint=False) * sweep
            out.append(c + d["radius"] * np.stack([np.cos(a), np.sin(a)], axis=-1))
    return np.concatenate(out)


def shoelace(p):
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def richardson(f, n):
    """``(4 f(2n) - f(n)) / 3``: removes the ``1/n^2`` error of an inscribed polygon."""
    return (4 * f(2 * n) - f(n)) / 3


def brute_sd(poly, qx, qy):
    """Signed distance from points to the convex ccw polygon ``poly`` (segments, not vertices)."""
    q = np.stack([np.ravel(qx), np.ravel(qy)], axis=-1)[:, None, :]
    a, b = poly[None, :, :], np.roll(poly, -1, axis=0)[None, :, :]
    ab = b - a
    s = np.clip(np.sum((q - a) * ab, axis=-1) / np.sum(ab * ab, axis=-1), 0.0, 1.0)
    dist = np.min(np.linalg.norm(q - (a + s[..., None] * ab), axis=-1), axis=1)
    cross = ab[..., 0] * (q[..., 1] - a[..., 1]) - ab[..., 1] * (q[..., 0] - a[..., 0])
    inside = np.all(cross >= 0, axis=1)
    return np.where(inside, -dist, dist).reshape(np.shape(qx))


def ref_support(dicts, psi):
    """``h(psi)`` as the hull of the joints and arcs, from the dictionaries."""
    ux, uy = np.cos(psi), np.sin(psi)
    h = np.full(np.shape(psi), -np.inf)
    for d in dicts:
        h = np.maximum(h, d["p0"][0] * ux + d["p0"][1] * uy)
        if d["type"] == "arc":
            c = d["center"]
            a0 = math.atan2(d["p0"][1] - c[1], d["p0"][0] - c[0])
            sweep = (math.atan2(d["p1"][1] - c[1], d["p1"][0] - c[0]) - a0) % (2 * math.pi)
            on = (psi - a0) % (2 * math.pi) <= sweep
            h = np.where(on, np.maximum(h, c[0] * ux + c[1] * uy + d["radius"]), h)
    return h


def clipped_area(dicts, k, t, n):
    """Area of ``{x : x . u <= k h(u) + t}`` over ``n`` even directions plus every line normal and
    arc end of the outline: the half-plane intersection, clipped one plane at a time."""
    psi = list(np.linspace(0.0, 2 * math.pi, n, endpoint=False))
    for d in dicts:
        if d["type"] == "line":
            e = np.subtract(d["p1"], d["p0"])
            psi.append(math.atan2(-e[0], e[1]))
        else:
            psi += [math.atan2(d[p][1] - d["center"][1], d[p][0] - d["center"][0]) for p in ("p0", "p1")]
    psi = np.array(psi)
    hs = k * ref_support(dicts, psi) + t
    poly = np.array([[-1e3, -1e3], [1e3, -1e3], [1e3, 1e3], [-1e3, 1e3]])
    for a, h in zip(psi, hs):
        u = np.array([math.cos(a), math.sin(a)])
        f = poly @ u - h
        nxt = np.roll(poly, -1, axis=0)
        fn = np.roll(f, -1)
        keep = [poly[f <= 0]]
        cross = (f <= 0) != (fn <= 0)
        w = (f / (f - np.where(cross, fn, f - 1)))[cross][:, None]
        pts = poly[cross] + w * (nxt[cross] - poly[cross])
        # interleave kept vertices and crossing points in polygon order
        order = np.concatenate([np.nonzero(f <= 0)[0] * 2.0, np.nonzero(cross)[0] * 2.0 + 1])
        poly = np.concatenate(keep + [pts])[np.argsort(order, kind="stable")]
    return shoelace(poly)


def turning(poly):
    """Turn (rad) at each vertex of a closed polygon."""
    e = np.roll(poly, -1, axis=0) - poly
    e0, e1 = np.roll(e, 1, axis=0), e
    return np.arctan2(e0[:, 0] * e1[:, 1] - e0[:, 1] * e1[:, 0], np.sum(e0 * e1, axis=1))


# --------------------------------------------------------------------------- reading
def test_public_outlines_load_and_normalise():
    hexagon = pl.PlanOutline.from_dicts(public_outline(1))
    assert hexagon.scale == 1.0
    assert_same(hexagon, pl.hexagon())
    assert len(hexagon.corners) == 6 and all(c.alpha == pytest.approx(math.pi / 3, abs=1e-12) for c in hexagon.corners)
    flask = pl.PlanOutline.from_dicts(public_outline(2))
    assert flask.scale == pytest.approx(50.0, rel=1e-14) and flask.corners == ()
    assert max(math.hypot(*p) for p in dense(flask.to_dicts(), 2000)) == pytest.approx(1.0, abs=1e-12)
    assert_same(flask, pl.flask(100.0, 30.0))
    # the file's units come back with the scale
    again = flask.to_dicts(flask.scale)
    for a, b in zip(again, public_outline(2)):
        np.testing.assert_allclose(a["p0"], b["p0"], atol=1e-12)
        assert a.get("radius", 0) == pytest.approx(b.get("radius", 0), rel=1e-14)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_round_trip_is_exact_and_hashable(name):
    o = SHAPES[name]()
    back = pl.PlanOutline.from_dicts(o.to_dicts())
    assert back == o and hash(back) == hash(o) and back.segments == o.segments
    assert len({o, back}) == 1
    with pytest.raises(AttributeError):
        o.scale = 2.0


def test_scale_does_not_change_the_normalised_outline():
    items = public_outline(2)
    tiny = [{k: (np.multiply(v, 1e-3).tolist() if k != "type" and k != "ccw" else v) for k, v in d.items()} for d in items]
    huge = [{k: (np.multiply(v, 1e3).tolist() if k != "type" and k != "ccw" else v) for k, v in d.items()} for d in items]
    a, b = pl.PlanOutline.from_dicts(tiny), pl.PlanOutline.from_dicts(huge)
    assert a.scale == pytest.approx(0.05) and b.scale == pytest.approx(5e4)
    for sa, sb in zip(a.to_dicts(), b.to_dicts()):
        for key in ("center", "p0", "p1"):
            np.testing.assert_allclose(sa[key], sb[key], rtol=0, atol=1e-12)
        assert sa["radius"] == pytest.approx(sb["radius"], abs=1e-12)


def assert_same(a, b, atol=1e-14):
    """Two outlines with the same segments to ``atol`` (normalised units)."""
    assert [s.kind for s in a.segments] == [s.kind for s in b.segments]
    for da, db in zip(a.to_dicts(), b.to_dicts()):
        for key in ("center", "p0", "p1", "radius"):
            if key in da:
                np.testing.assert_allclose(da[key], db[key], rtol=0, atol=atol)


def refusal(items):
    with pytest.raises(OutlineError) as info:
        pl.PlanOutline.from_dicts(items)
    msg = str(info.value)
    assert "\n" not in msg and len(msg) <= MAX_MESSAGE_CHARS
    return info.value


def square_lines(r=1.0):
    pts = [[r, -r], [r, r], [-r, r], [-r, -r]]
    return [{"type": "line", "p0": pts[i], "p1": pts[(i + 1) % 4]} for i in range(4)]


def test_refusals_name_the_segment_and_the_rule():
    items = square_lines()
    items[2] = {"type": "line", "p0": [-1, 1.01], "p1": [-1, -1]}
    err = refusal(items)
    assert err.index == 2 and "closed" in str(err)
    # a clockwise arc
    arc = {"type": "arc", "center": [0, 0], "radius": 1, "p0": [1, 0], "p1": [-1, 0], "ccw": False}
    err = refusal([arc, {"type": "line", "p0": [-1, 0], "p1": [1, 0]}])
    assert err.index == 0 and "clockwise" in str(err)
    # the same square walked clockwise turns right at every joint
    cw = [{"type": "line", "p0": d["p1"], "p1": d["p0"]} for d in reversed(square_lines())]
    err = refusal(cw)
    assert "turns right" in str(err) and "counter-clockwise" in str(err)
    # a dent: a right turn in an otherwise ccw chain
    dent = [[1, -1], [1, 1], [0, 0.5], [-1, 1], [-1, -1]]
    err = refusal([{"type": "line", "p0": dent[i], "p1": dent[(i + 1) % 5]} for i in range(5)])
    assert err.index == 2 and "turns right" in str(err) and "not convex" in str(err)
    # the origin outside, and on the boundary
    shifted = [{"type": "line", "p0": [p[0] + 3, p[1]], "p1": [q[0] + 3, q[1]]} for p, q in
               ((d["p0"], d["p1"]) for d in square_lines())]
    assert "strictly inside" in str(refusal(shifted))
    edge = [{"type": "line", "p0": [p[0] + 1, p[1]], "p1": [q[0] + 1, q[1]]} for p, q in
            ((d["p0"], d["p1"]) for d in square_lines())]
    assert "on the boundary" in str(refusal(edge))
    # an arc end off its circle, a 180 deg reversal, a chain that winds twice
    bad = [dict(arc, ccw=True, p1=[-1, 0.01]), {"type": "line", "p0": [-1, 0.01], "p1": [1, 0]}]
    assert refusal(bad).index == 0
    spike = [{"type": "line", "p0": [1, 0], "p1": [-1, 0]}, {"type": "line", "p0": [-1, 0], "p1": [1, 0]}]
    assert "back on itself" in str(refusal(spike))
    star = [[math.cos(a), math.sin(a)] for a in np.arange(5) * 4 * math.pi / 5]
    assert "not 360" in str(refusal([{"type": "line", "p0": star[i], "p1": star[(i + 1) % 5]} for i in range(5)]))


@pytest.mark.parametrize("items,words", [
    (None, "list of segments"), ("line", "list of segments"), ([], "2 to 256"),
    ([{"type": "line", "p0": [1, 0], "p1": [0, 1]}] * 10 ** 6, "2 to 256"),
    ([{"type": "line", "p0": [float("nan"), 0], "p1": [0, 1]}] * 3, "finite"),
    ([{"type": "line", "p0": [float("inf"), 0], "p1": [0, 1]}] * 3, "finite"),
    ([{"type": "line", "p0": ["1", 0], "p1": [0, 1]}] * 3, "must be a number"),
    ([{"type": "line", "p0": [True, 0], "p1": [0, 1]}] * 3, "must be a number"),
    ([{"type": "line", "p0": [10 ** 400, 0], "p1": [0, 1]}] * 3, "finite"),
    ([{"type": "line", "p0": [1, 0, 0], "p1": [0, 1]}] * 3, "two numbers"),
    ([{"type": "line", "p0": [1, 0]}] * 3, "lacks p1"),
    ([{"type": "arc", "center": [0, 0], "p0": [1, 0], "p1": [0, 1]}] * 3, "lacks radius"),
    ([{"type": "arc", "center": [0, 0], "radius": -1, "p0": [1, 0], "p1": [0, 1]}] * 3, "positive"),
    ([{"type": "arc", "center": [0, 0], "radius": 1, "p0": [1, 0], "p1": [0, 1], "ccw": "yes"}] * 3, "clockwise"),
    ([{"type": "spline", "p0": [1, 0], "p1": [0, 1]}] * 3, "unknown segment type"),
    ([{"type": "line", "p0": [1, 0], "p1": [0, 1], "bulge": 1}] * 3, "unknown field"),
    ([{"type": "line", "p0": [1, 0], "p1": [1, 0]}, {"type": "line", "p0": [1, 0], "p1": [1, 0]}], "coincide"),
    ([{"type": "line", "p0": [0, 0], "p1": [0, 0]}] * 3, "no usable size"),
    ([["line", [1, 0], [0, 1]]] * 3, "must be an object"),
])
def test_hostile_input_gets_one_clear_line(items, words):
    err = refusal(items)
    assert words in str(err)


def test_sharp_and_tiny_features_are_accepted():
    # a corner turning by 179.9 deg (a needle tip) and one turning by 0.1 deg (179.9 deg inside)
    tip = math.tan(math.radians(0.05))
    needle = [[1, 0], [-1, 2 * tip], [-1, -2 * tip]]
    o = pl.PlanOutline.from_dicts([{"type": "line", "p0": needle[i], "p1": needle[(i + 1) % 3]} for i in range(3)])
    assert max(c.alpha for c in o.corners) == pytest.approx(math.radians(179.9), abs=1e-9)
    blunt = [[1, -1], [1, 1], [0, 1 + math.tan(math.radians(0.1))], [-1, 1], [-1, -1]]
    o = pl.PlanOutline.from_dicts([{"type": "line", "p0": blunt[i], "p1": blunt[(i + 1) % 5]} for i in range(5)])
    assert min(c.alpha for c in o.corners) == pytest.approx(math.radians(0.2), rel=1e-6)
    # a 100 mm square with one corner rounded by a 0.01 mm arc
    items = rectangle(50.0, 50.0, 0.01)
    o = pl.PlanOutline.from_dicts(items)
    assert sum(s.kind == "arc" for s in o.segments) == 4 and o.corners == ()
    assert o.segments[0].radius * o.scale == pytest.approx(0.01, rel=1e-12)


# --------------------------------------------------------------------------- derived quantities of P
@pytest.mark.parametrize("n", [3, 4, 5, 6, 8, 12, 40])
def test_regular_polygon_closed_forms(n):
    o = pl.regular_polygon(n, rotation_deg=17.0)
    assert o.area == pytest.approx(n / 2 * math.sin(2 * math.pi / n), rel=1e-14)
    assert o.perimeter == pytest.approx(2 * n * math.sin(math.pi / n), rel=1e-14)
    assert o.inradius == pytest.approx(math.cos(math.pi / n), abs=1e-13)
    assert [c.alpha for c in o.corners] == pytest.approx([2 * math.pi / n] * n, abs=1e-12)
    r = 0.25
    rounded = pl.regular_polygon(n, corner_radius=r)
    # the polygon of circumradius 1 - r grown by r: Steiner
    a, l = (1 - r) ** 2 * n / 2 * math.sin(2 * math.pi / n), (1 - r) * 2 * n * math.sin(math.pi / n)
    assert rounded.area == pytest.approx(a + l * r + math.pi * r * r, rel=1e-13)
    assert rounded.perimeter == pytest.approx(l + 2 * math.pi * r, rel=1e-13)
    assert rounded.inradius == pytest.approx((1 - r) * math.cos(math.pi / n) + r, abs=1e-13)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_area_perimeter_against_dense_sampling(name):
    o = SHAPES[name]()
    dicts = o.to_dicts()
    area = richardson(lambda n: shoelace(dense(dicts, n)), 4000)
    length = richardson(lambda n: float(np.sum(np.linalg.norm(np.diff(dense(dicts, n), axis=0, append=dense(dicts, n)[:1]), axis=1))), 4000)
    assert o.area == pytest.approx(area, rel=1e-11)
    assert o.perimeter == pytest.approx(length, rel=1e-11)


def test_flask_area_against_mpmath():
    o = pl.flask(100.0, 30.0)
    mpmath.mp.dps = 30
    # the flask is symmetric in both axes: 4 * the integral of its upper boundary y(x) over x >= 0
    a, e, side, b = mpmath.mpf(43.75), mpmath.mpf(6.25), mpmath.mpf(120), mpmath.mpf(15)
    tx = a * side / mpmath.sqrt(a ** 2 + (side - b) ** 2)

    def y(x):
        if x <= tx:
            return mpmath.sqrt(side ** 2 - x ** 2) - (side - b)
        return mpmath.sqrt(e ** 2 - (x - a) ** 2)
    area = 4 * mpmath.quad(y, [0, tx, a + e])
    assert o.area * o.scale ** 2 == pytest.approx(float(area), rel=1e-13)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_support_against_brute_force(name):
    o = SHAPES[name]()
    pts = dense(o.to_dicts(), 8000)
    psi = np.linspace(-3 * math.pi, 3 * math.pi, 301)
    brute = np.max(pts @ np.stack([np.cos(psi), np.sin(psi)]), axis=0)
    np.testing.assert_allclose(o.support(psi), brute, atol=1e-8)
    assert np.all(o.support(psi) >= brute - 1e-15)


def test_inradius_of_rectangles_flask_and_shield():
    o = pl.PlanOutline.from_dicts(rectangle(2.0, 1.0))
    assert o.inradius == pytest.approx(1.0 / math.hypot(2.0, 1.0), abs=1e-14)
    assert pl.flask(100.0, 30.0).inradius == pytest.approx(15.0 / 50.0, abs=1e-14)
    assert d_shape().inradius == pytest.approx((1 + math.sin(math.pi / 3)) / 2, abs=1e-13)
    # the shield: a grid search of -sd computed by brute force around the module's centre
    sh = pl.shield()
    cx, cy = sh.incenter
    gx, gy = np.meshgrid(cx + np.linspace(-2e-3, 2e-3, 9), cy + np.linspace(-2e-3, 2e-3, 9))
    poly = dense(sh.to_dicts(), 5000)
    best = -np.min(brute_sd(poly, gx, gy))
    assert -float(brute_sd(poly, np.array([cx]), np.array([cy]))[0]) == pytest.approx(sh.inradius, abs=1e-8)
    assert sh.inradius >= best - 1e-8


@pytest.mark.parametrize("pieces", [2, 3, 4])
def test_a_circular_plan_is_its_own_incircle(pieces):
    """Arcs about one centre: the largest disc's centre is every arc's centre, where no arc's
    nearest direction is defined (the polish once divided by its zero contacts there)."""
    ends = [(math.cos(2 * math.pi * i / pieces), math.sin(2 * math.pi * i / pieces)) for i in range(pieces + 1)]
    o = pl.PlanOutline.from_dicts([{"type": "arc", "center": [0.0, 0.0], "radius": 1.0, "p0": list(a),
                                    "p1": list(b), "ccw": True} for a, b in zip(ends, ends[1:])])
    assert o.inradius == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(o.incenter, (0.0, 0.0), atol=1e-9)


# --------------------------------------------------------------------------- sections
def test_rounded_square_is_the_spec_special_case():
    sq = pl.square()
    for p, q in [(10.0, 5.0), (20.0, 0.5), (1e-3, 12.0), (0.0, 7.0)]:
        u = p + q
        expect = float(cs.area("rounded_rect", (u, u, q)))
        assert sq.outer_area(math.sqrt(2) * p, q) == pytest.approx(expect, rel=1e-13)
        assert float(sq.outer_area(math.sqrt(2) * p, q)) == pytest.approx(4 * u * u - (4 - math.pi) * q * q, rel=1e-13)
        ring = pl.sample_pieces(sq.outer_pieces(math.sqrt(2) * p, q), max_turn_deg=0.05)
        on_rect = cs.signed_distance("rounded_rect", (u, u, q), ring[:, 0], ring[:, 1])[0]
        np.testing.assert_allclose(on_rect, 0.0, atol=1e-12)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_outer_area_and_girth_against_the_sampled_boundary(name):
    o = SHAPES[name]()
    k, c = 30.0, 4.0
    pieces = o.outer_pieces(k, c)
    area = richardson(lambda n: shoelace(pl.sample_pieces(pieces, max_turn_deg=360.0 / n)), 3000)
    assert float(o.outer_area(k, c)) == pytest.approx(area, rel=1e-10)
    ring = pl.sample_pieces(pieces, max_turn_deg=0.01)
    girth = float(np.sum(np.linalg.norm(np.roll(ring, -1, axis=0) - ring, axis=1)))
    assert float(o.girth(k, c)) == pytest.approx(girth, rel=1e-8)
    # every sampled point is at distance c from k P (brute force)
    poly = k * dense(o.to_dicts(), 4000)
    pick = ring[:: max(1, len(ring) // 300)]
    np.testing.assert_allclose(brute_sd(poly, pick[:, 0], pick[:, 1]), c, atol=2e-5)


def test_flask_grown_and_shrunk_is_a_flask():
    o = pl.flask(100.0, 30.0)
    k = o.scale  # 50: the flask itself
    for c in (0.5, 3.0, 10.0):
        grown = pl.flask(100 + 2 * c, 30 + 2 * c, 6.25 + c)
        assert float(o.outer_area(k, c)) == pytest.approx(grown.area * grown.scale ** 2, rel=1e-13)
        assert float(o.girth(k, c)) == pytest.approx(grown.perimeter * grown.scale, rel=1e-13)
    for s in (0.5, 3.0, 6.0):
        shrunk = pl.flask(100 - 2 * s, 30 - 2 * s, 6.25 - s)
        assert float(o.inner_area(k, -s)) == pytest.approx(shrunk.area * shrunk.scale ** 2, rel=1e-12)
        assert float(o.inner_girth(k, -s)) == pytest.approx(shrunk.perimeter * shrunk.scale, rel=1e-12)


@pytest.mark.parametrize("n", [3, 4, 6, 8])
def test_inner_parallel_polygon_closed_form(n):
    o = pl.regular_polygon(n, rotation_deg=5.0)
    k = 40.0
    s = np.linspace(0.1, 0.95 * k * math.cos(math.pi / n), 7)
    tan_sum = n * math.tan(math.pi / n)  # every exterior angle is 2 pi / n
    np.testing.assert_allclose(o.inner_area(k, -s), k * k * o.area - k * o.perimeter * s + s * s * tan_sum, rtol=1e-12)
    np.testing.assert_allclose(o.inner_girth(k, -s), k * o.perimeter - 2 * s * tan_sum, rtol=1e-12)
    # the sharp inner corners are k V + t (n_in + n_out) / (1 + n_in . n_out)
    t = -float(s[3])
    corners = [p.p0 for p in o.inner_pieces(k, t)]
    for c, w in zip(o.corners, corners):
        f = t / (1 + np.dot(c.n_in, c.n_out))
        np.testing.assert_allclose(w, k * np.array(c.vertex) + f * (np.add(c.n_in, c.n_out)), atol=1e-12)


@pytest.mark.parametrize("name", ["shield", "d_shape", "rounded_rect", "hexagon", "rounded_pentagon"])
@pytest.mark.parametrize("t", [-2.5, -0.7, 0.0, 1.5])
def test_inner_area_against_half_plane_clipping(name, t):
    o = SHAPES[name]()
    k = 25.0
    ref = richardson(lambda n: clipped_area(o.to_dicts(), k, t, n), 1500)
    assert float(o.inner_area(k, t)) == pytest.approx(ref, rel=1e-7)
    pieces = o.inner_pieces(k, t)
    ring = pl.sample_pieces(pieces, max_turn_deg=0.01)
    assert shoelace(ring) == pytest.approx(float(o.inner_area(k, t)), rel=1e-7)
    girth = float(np.sum(np.linalg.norm(np.roll(ring, -1, axis=0) - ring, axis=1)))
    assert float(o.inner_girth(k, t)) == pytest.approx(girth, rel=1e-7)


@pytest.mark.parametrize("name", ["shield", "d_shape", "rounded_rect", "triangle"])
def test_inner_pieces_are_a_closed_chain_at_distance_t(name):
    o = SHAPES[name]()
    k, t = 25.0, -2.0
    pieces = o.inner_pieces(k, t)
    for a, b in zip(pieces, pieces[1:] + pieces[:1]):
        np.testing.assert_allclose(a.p1, b.p0, atol=1e-12)
    assert all(p.length > 0 for p in pieces)
    poly = k * dense(o.to_dicts(), 4000)
    ring = pl.sample_pieces(pieces, max_turn_deg=0.5)
    pick = ring[:: max(1, len(ring) // 300)]
    np.testing.assert_allclose(brute_sd(poly, pick[:, 0], pick[:, 1]), t, atol=2e-5)
    # the sharp inner corners stay sharp: the polyline turns there by the corner's angle
    turns = turning(ring)
    assert np.sum(turns > math.radians(1)) == len(o.corners)
    assert np.sum(turns) == pytest.approx(2 * math.pi, abs=1e-9)


def test_inner_area_is_vectorised_and_marks_the_invalid():
    o = pl.PlanOutline.from_dicts(rectangle(2.0, 1.0, 0.1))
    k = 40.0
    rho = o.segments[0].radius
    t = np.array([3.0, 0.0, -0.5 * k * rho, -1.5 * k * rho, -k * 2.0])
    a = o.inner_area(k, t)
    for ti, ai in zip(t[:3], a[:3]):
        assert ai == pytest.approx(float(o.inner_area(k, float(ti))), rel=1e-15)
    assert math.isnan(a[3]) and a[4] == 0.0
    assert "vanishes" in o.inner_reason(k, float(t[3]))
    with pytest.raises(OutlineError):
        o.inner_pieces(k, float(t[3]))
    kk, tt = np.meshgrid(np.linspace(10, 50, 5), np.linspace(-1.0, 2.0, 4))
    grid = o.inner_area(kk, tt)
    assert grid.shape == kk.shape
    np.testing.assert_allclose(grid, [[float(o.inner_area(x, y)) for x, y in zip(r1, r2)] for r1, r2 in zip(kk, tt)],
                               rtol=1e-14)


def test_inner_reason_margin_and_regular_polygons():
    hexagon = pl.hexagon()
    k = 20.0
    edge = 1.0 - hexagon.inradius * k
    assert hexagon.inner_reason(k, edge) is None
    assert "no cavity margin" in hexagon.inner_reason(k, edge - 1e-3)
    assert hexagon.inner_reason(0.0, 1.0) is None and "no cavity margin" in hexagon.inner_reason(0.0, 0.9)
    for n in (3, 4, 5, 7):  # the margin rule is the only one a regular polygon can break
        o = pl.regular_polygon(n)
        assert o.inner_reason(k, 1.0 - o.inradius * k) is None


def test_k_zero_is_the_disc():
    o = pl.shield()
    (piece,) = o.outer_pieces(0.0, 7.0)
    assert piece.radius == 7.0 and piece.theta1 - piece.theta0 == pytest.approx(2 * math.pi)
    assert float(o.outer_area(0.0, 7.0)) == pytest.approx(math.pi * 49)
    assert o.inner_pieces(0.0, 2.0)[0].radius == 2.0
    assert float(o.inner_area(0.0, -1.0)) == 0.0
    with pytest.raises(OutlineError):
        o.inner_pieces(0.0, -1.0)
    sd = o.signed_distance(np.array([3.0, 0.0]), np.array([4.0, -9.0]), 0.0, 7.0)[0]
    np.testing.assert_allclose(sd, [-2.0, 2.0], atol=1e-14)


# --------------------------------------------------------------------------- signed distance
@pytest.mark.parametrize("name", sorted(SHAPES))
def test_signed_distance_against_brute_force(name):
    o = SHAPES[name]()
    k, c = 30.0, 2.5
    rng = np.random.default_rng(7)
    q = rng.uniform(-45.0, 45.0, size=(200, 2))
    sd, gx, gy, (d_k, d_c) = o.signed_distance(q[:, 0], q[:, 1], k, c)
    poly = k * dense(o.to_dicts(), 3000)
    np.testing.assert_allclose(sd, brute_sd(poly, q[:, 0], q[:, 1]) - c, atol=5e-6)
    np.testing.assert_allclose(np.hypot(gx, gy), 1.0, atol=1e-14)
    assert np.all(d_c == -1.0)
    h = 1e-6
    fx = (o.signed_distance(q[:, 0] + h, q[:, 1], k, c)[0] - o.signed_distance(q[:, 0] - h, q[:, 1], k, c)[0]) / (2 * h)
    fy = (o.signed_distance(q[:, 0], q[:, 1] + h, k, c)[0] - o.signed_distance(q[:, 0], q[:, 1] - h, k, c)[0]) / (2 * h)
    fk = (o.signed_distance(q[:, 0], q[:, 1], k + h, c)[0] - o.signed_distance(q[:, 0], q[:, 1], k - h, c)[0]) / (2 * h)
    fc = (o.signed_distance(q[:, 0], q[:, 1], k, c + h)[0] - o.signed_distance(q[:, 0], q[:, 1], k, c - h)[0]) / (2 * h)
    smooth = np.abs(fx - gx) < 1e-3  # a point on the medial axis has no derivative
    assert smooth.mean() > 0.97
    np.testing.assert_allclose(fy[smooth], gy[smooth], atol=1e-6)
    np.testing.assert_allclose(fk[smooth], d_k[smooth], atol=1e-6)
    np.testing.assert_allclose(fc, -1.0, atol=1e-8)
    # d_k is minus the support in the gradient direction
    np.testing.assert_allclose(d_k, -o.support(np.arctan2(gy, gx)), atol=1e-12)


def test_signed_distance_on_the_boundary_and_its_normal():
    o = pl.shield()
    k, c = 20.0, 1.5
    ring = o.polyline(k, c)
    sd, gx, gy, _ = o.signed_distance(ring[:, 0], ring[:, 1], k, c)
    np.testing.assert_allclose(sd, 0.0, atol=1e-12)
    step = 1e-3
    assert np.all(o.signed_distance(ring[:, 0] + step * gx, ring[:, 1] + step * gy, k, c)[0] > 0)
    assert np.all(o.signed_distance(ring[:, 0] - step * gx, ring[:, 1] - step * gy, k, c)[0] < 0)


# --------------------------------------------------------------------------- polylines
@pytest.mark.parametrize("name", ["shield", "hexagon", "flask"])
def test_polyline_facets(name):
    o = SHAPES[name]()
    ring = o.polyline(30.0, 2.0, max_turn_deg=0.2)
    turns = turning(ring)
    assert np.max(np.abs(turns)) <= math.radians(0.2) + 1e-12
    assert np.sum(turns) == pytest.approx(2 * math.pi, abs=1e-9)
    # a flat face is one facet wide: a line piece's start vertex is followed by its end
    for p in o.outer_pieces(30.0, 2.0):
        if p.kind == "line":
            i = int(np.argmin(np.linalg.norm(ring - p.p0, axis=1)))
            np.testing.assert_allclose(ring[i], p.p0, atol=1e-12)
            np.testing.assert_allclose(ring[(i + 1) % len(ring)], p.p1, atol=1e-9)
    # every vertex is on the boundary; with chord_tol_mm no facet's midpoint is farther inside
    def sagitta(poly):
        mid = (poly + np.roll(poly, -1, axis=0)) / 2
        return o.signed_distance(mid[:, 0], mid[:, 1], 30.0, 2.0)[0]

    plain = sagitta(ring).min()
    for tol in (1e-2, 1e-5):
        fine = o.polyline(30.0, 2.0, chord_tol_mm=tol)
        np.testing.assert_allclose(o.signed_distance(fine[:, 0], fine[:, 1], 30.0, 2.0)[0], 0.0, atol=1e-12)
        sag = sagitta(fine)
        assert sag.min() >= -tol and sag.max() <= 1e-12
        assert (len(fine) > len(ring)) == (plain < -tol)  # only a tighter tolerance adds facets


# --------------------------------------------------------------------------- presets and builders
def test_presets_and_builders_agree():
    assert pl.square() == pl.regular_polygon(4, rotation_deg=45.0)  # the same arithmetic: bit for bit
    np.testing.assert_allclose(sorted(abs(np.array(s.p0)).max() for s in pl.square().segments), [math.sqrt(0.5)] * 4)
    one_side = pl.hexagon().to_dicts()[:1]
    assert_same(pl.n_fold(one_side, 6), pl.hexagon())
    # a rounded triangle from one arc: n_fold bridges the copies with lines
    arc = pl.triangle(0.3).segments[1]
    assert_same(pl.n_fold([arc], 3), pl.triangle(0.3))
    # the right half of a hexagon, mirrored: same shape (the top and bottom sides split at the axis)
    h = math.sqrt(3) / 2
    half = [{"type": "line", "p0": [0, -h], "p1": [0.5, -h]}, {"type": "line", "p0": [0.5, -h], "p1": [1, 0]},
            {"type": "line", "p0": [1, 0], "p1": [0.5, h]}, {"type": "line", "p0": [0.5, h], "p1": [0, h]}]
    m = pl.mirrored(half)
    assert len(m.segments) == 8 and len(m.corners) == 6
    psi = np.linspace(0, 2 * math.pi, 97)
    np.testing.assert_allclose(m.support(psi), pl.hexagon().support(psi), atol=1e-15)
    assert m.area == pytest.approx(pl.hexagon().area, rel=1e-15)
    # the shield is mirror symmetric with a sharp point below and two square shoulders above
    sh = pl.shield()
    assert len(sh.corners) == 3 and min(c.vertex[1] for c in sh.corners) == pytest.approx(-0.6 / sh.scale)
    np.testing.assert_allclose(sh.support(math.pi - psi), sh.support(psi), atol=1e-14)
    for bad in (lambda: pl.regular_polygon(2), lambda: pl.regular_polygon(5, 1.0), lambda: pl.flask(30, 40),
                lambda: pl.flask(100, 30, 20), lambda: pl.shield(1.0, 0.4, 0.5), lambda: pl.n_fold(one_side, 0)):
        with pytest.raises(OutlineError):
            bad()


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_the_distance_alone_is_the_signed_distance_bit_for_bit(name):
    """PlanOutline.distance (the thickness search's) is signed_distance's value without its
    gradient: equal bit for bit, at points far off, on the axis, on a fan's centre (where its
    own direction is undefined), NaN (never the largest candidate), scalars and empty arrays."""
    o = SHAPES[name]()
    rng = np.random.default_rng(43)
    x, y = rng.uniform(-45.0, 45.0, size=(2, 300, 4))
    k, c = rng.uniform(0.0, 30.0, size=(300, 1)), np.array([-2.0, 0.0, 0.5, 4.0])
    x[0, 0], x[1, :], y[1, :], k[2] = np.nan, 0.0, 0.0, 0.0
    cx, cy = o.segments[0].p0
    x[3, :], y[3, :], k[3] = 10.0 * cx, 10.0 * cy, 10.0  # exactly on a joint (a corner fan's centre)
    for args in ((x, y, k, c), (1.5, -2.0, 7.0, 0.25), (np.empty(0), np.empty(0), 1.0, 0.0)):
        sd = o.signed_distance(*args)[0]
        got = o.distance(*args)
        assert np.shape(got) == np.shape(sd)
        np.testing.assert_array_equal(got, sd)
    assert o.distance(np.nan, 0.0, 1.0, 0.0) == o.signed_distance(np.nan, 0.0, 1.0, 0.0)[0] == -np.inf
