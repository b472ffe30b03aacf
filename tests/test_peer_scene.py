"""The peer's scene conversion (benchmarks.peer_scene): SPEC section 6's mesh, checked cheaply.

Where it can fail: the facet rule (0.2 degrees of turning), the vertices and normals on the exact
surfaces (against the engine's own surface evaluation, an independent implementation), closed
solids, the references' own triangle count. No Mitsuba needed.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from benchmarks.paths import ORACLE_SPECS
from benchmarks.peer_scene import Piece, bottle_rings, facet_turn_deg, spec_meshes


def spec(name, max_turn_deg=None):
    s = json.load(open(ORACLE_SPECS / f"{name}.json"))
    if max_turn_deg is not None:
        s["render"]["tessellation"]["max_turn_deg"] = max_turn_deg
    return s


def closed(parts) -> bool:
    """Every edge of the welded union of ``(vertices, faces)`` parts in two faces, opposite ways."""
    v = np.concatenate([p[0] for p in parts])
    offsets = np.cumsum([0] + [len(p[0]) for p in parts[:-1]])
    f = np.concatenate([p[1] + o for p, o in zip(parts, offsets)])
    _, inv = np.unique(v, axis=0, return_inverse=True)
    f = inv.reshape(-1)[f]
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    directed = np.unique(e, axis=0, return_counts=True)[1]
    undirected = np.unique(np.sort(e, axis=1), axis=0, return_counts=True)[1]
    return bool(np.all(directed == 1) and np.all(undirected == 2))


def test_profile_samples_turn_at_most_the_spec_angle_and_no_more_are_taken():
    """SPEC 6: arcs and ellipse arcs split every 0.2 degrees of tangent turning (the fewest
    samples that do it); public_4 has both, convex and concave."""
    for seg in spec("public_4")["bottle"]["profile"][1:]:
        pc = Piece.from_spec(seg)
        t = pc.samples(math.radians(0.2), 1000.0)
        psi = np.unwrap(pc.tangent_angle(t))
        steps = np.degrees(np.abs(np.diff(psi)))
        total = np.degrees(abs(psi[-1] - psi[0]))
        assert steps.max() <= 0.2 + 1e-9, seg["type"]
        assert len(steps) == max(1, math.ceil(total / 0.2 - 1e-9)), seg["type"]
        r, z, _, _ = pc.at(np.array([0.0, 1.0]))
        assert np.allclose([r[0], z[0], r[1], z[1]], [*seg["p0"], *seg["p1"]], atol=1e-9)


def test_round_facets_turn_at_most_the_spec_angle():
    """Neighbouring faces of every mesh of a round bottle with a liquid (ellipse, concave arcs)
    turn by at most max_turn_deg, but at the creases: the rim's two edges and the inner base's.
    (Two triangles across a vertical edge lie in neighbouring bands' halves, so they also see a
    sliver of the turning along the profile: 1e-5 of it at 2 degrees, 1.5e-6 at 0.2.)"""
    meshes = spec_meshes(spec("public_4", max_turn_deg=2.0))
    turn, creases = zip(*(facet_turn_deg(v, f) for v, f, _ in meshes.values()))
    assert 1.99 < max(turn) <= 2.0 * (1 + 2e-5)
    assert dict(zip(meshes, creases)) == {"glass_air": 2 * 180, "glass_liquid": 180, "liquid_air": 0}


def test_the_public_1_conversion_has_the_references_triangle_count():
    """refs/public_1.json: 1800 points per ring, 6,328,800 triangles (SPEC 6's own mesh)."""
    rings = bottle_rings(spec("public_1"))
    assert rings["outer"].xy.shape[1] == 1800
    ref = json.load(open(ORACLE_SPECS.parent / "refs" / "public_1.json"))["info"]
    assert 2 * 1800 * (len(rings["outer"].z) + len(rings["inner"].z)) == ref["triangles"]


def assert_rings_on_exact_surfaces(s) -> dict:
    """Every wall vertex of the spec ``s`` lies on the engine's exact surface (to 1e-9 mm) and
    carries its exact unit normal (to 1e-9); returns the rings."""
    from benchmarks.oracle_spec import shape_from_spec
    from engine.geometry.body import BottleBody

    body = BottleBody(shape_from_spec(s["bottle"]))
    rings = bottle_rings(s)
    for part in ("outer", "inner"):
        rg = rings[part]
        p = np.concatenate([rg.xy, np.broadcast_to(rg.z[:, None, None], rg.xy.shape[:2] + (1,))], -1)
        g, grad = body.wall_implicit(part, p)
        assert np.abs(g).max() < 1e-9, part
        exact = grad / np.linalg.norm(grad, axis=-1, keepdims=True)
        # the engine's gradient grows out of the glass's outline / the cavity: away from the axis both
        assert np.abs(rg.n - exact).max() < 1e-9, part
    return rings


@pytest.mark.parametrize("name", ["public_3", "public_4"])
def test_vertices_and_normals_are_the_exact_surfaces(name):
    """Every wall vertex lies on the engine's exact surface (to 1e-9 mm) and carries its exact
    unit normal (to 1e-9): a rounded square turned 55 degrees flaring into a round neck, and
    offset ellipse arcs; the glass and the liquid are closed solids."""
    s = spec(name, max_turn_deg=3.0)
    assert_rings_on_exact_surfaces(s)
    m = spec_meshes(s)
    assert closed([m["glass_air"][:2], m["glass_liquid"][:2]])
    v, f, _ = m["glass_liquid"]
    assert closed([(v, f[:, ::-1]), m["liquid_air"][:2]])
