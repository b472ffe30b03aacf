"""The benchmarks' per-ray Embree 4 binding (benchmarks.embree_kernel) against embreex."""
import numpy as np
import pytest

from benchmarks.embree_kernel import Embree4Scene


def test_one_triangle_is_hit_at_its_distance_and_missed_beside_it():
    scene = Embree4Scene([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    try:
        t, prim = scene.cast([[0.2, 0.2, 2.0], [2.0, 2.0, 2.0], [0.2, 0.2, -1.0]],
                             [[0, 0, -1], [0, 0, -1], [0, 0, -1]])
    finally:
        scene.close()
    assert t[0] == pytest.approx(2.0, abs=1e-6) and prim[0] == 0
    assert np.isinf(t[1]) and np.isinf(t[2])  # beside it, and behind the ray's start


def test_bad_meshes_are_refused():
    with pytest.raises(ValueError):
        Embree4Scene([[0, 0, 0], [1, 0, 0]], [[0, 1, 2]])
    with pytest.raises(ValueError):
        Embree4Scene(np.zeros((3, 2)), [[0, 1, 2]])


def test_it_finds_what_embreex_finds_on_a_bottle():
    from embreex.mesh_construction import TriangleMesh
    from embreex.rtcore_scene import EmbreeScene

    from engine.geometry.tessellate import tessellate_body
    from tests.test_tracer import simple_design

    mesh = tessellate_body(simple_design(40.0).shape, 0.2)
    v, f = mesh.vertices.astype(np.float32), mesh.faces.astype(np.int32)
    rng = np.random.default_rng(3)
    lo, hi = v.min(axis=0), v.max(axis=0)
    o = np.column_stack([rng.uniform(lo[0], hi[0], 2000), np.full(2000, lo[1] - 100.0), rng.uniform(lo[2], hi[2], 2000)])
    aim = np.column_stack([rng.uniform(1.4 * lo[0], 1.4 * hi[0], 2000), np.zeros(2000),
                           rng.uniform(lo[2] - 10, hi[2] + 10, 2000)])
    d = aim - o
    o, d = o.astype(np.float32), (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    ref = EmbreeScene()
    TriangleMesh(ref, v, f)
    want = ref.run(o, d, output=1)
    scene = Embree4Scene(v, f)
    try:
        t, prim = scene.cast(o, d)
    finally:
        scene.close()
    hit = want["geomID"] != -1
    assert 0.2 < hit.mean() < 0.9  # rays both meet and miss the bottle
    assert np.array_equal(np.isfinite(t), hit)
    assert np.allclose(t[hit], want["tfar"][hit], rtol=1e-5) and np.array_equal(prim[hit], want["primID"][hit])


def test_refinement_lands_on_the_exact_hits_of_the_tracers_own_queries():
    """The recorded queries of a frame (each with its medium and the object it leaves), Embree's
    hit past a hair, then the exact root of the analytic answer's part near it: the tracer's
    own hits, to the last digits, for most queries."""
    from benchmarks.embree_kernel import refine_onto_parts
    from benchmarks.tracer import embree_scene
    from engine.tracer.context import RenderContext, nearest_hits, trace_pixels
    from tests.test_tracer import simple_design

    design = simple_design(40.0)
    ctx = RenderContext.from_design(design, None, 24, 24)
    ys, xs = np.mgrid[0:24, 0:24]
    rec = (np.zeros((200_000, 9), np.float32), np.zeros(1, np.int64))
    trace_pixels(ctx, xs.ravel(), ys.ravel(), 1, 1, record=rec)
    rays = rec[0][:rec[1][0]]
    assert len(rays) > 1000 and set(np.unique(rays[:, 6])) > {0.0}  # queries inside glass too
    o, d = rays[:, :3].astype(float), rays[:, 3:6].astype(float)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    medium, last, side = (np.ascontiguousarray(rays[:, c].astype(np.int64)) for c in (6, 7, 8))
    t, k, part, _ = nearest_hits(ctx.geometry, o, d, medium, last, side)
    _, _, mesh = embree_scene(design, with_mesh=True)
    scene = Embree4Scene(*mesh)
    try:
        t_mesh = scene.cast(rays[:, :3], rays[:, 3:6], tnear=0.05)[0]
    finally:
        scene.close()
    found = refine_onto_parts(ctx.geometry, o, d, t_mesh, k, part, 0.05)
    hit, got = np.isfinite(t), np.isfinite(found)
    assert not np.any(got & ~hit)
    same = np.abs(found[hit] - t[hit]) <= 1e-9 * np.maximum(1.0, t[hit])
    assert same.mean() > 0.8  # 89 % measured; an Embree tracer would query the rest again
    assert np.array_equal(same, got[hit])  # a root found is the tracer's own
