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


def _frame_queries(design, size=24):
    """The recorded queries of a small frame: origins, unit directions (float64), medium, object
    left, side left."""
    from engine.tracer.context import RenderContext, trace_pixels

    ctx = RenderContext.from_design(design, None, size, size)
    ys, xs = np.mgrid[0:size, 0:size]
    rec = (np.zeros((200_000, 9), np.float32), np.zeros(1, np.int64))
    trace_pixels(ctx, xs.ravel(), ys.ravel(), 1, 1, record=rec)
    rays = rec[0][:rec[1][0]]
    o, d = rays[:, :3].astype(float), rays[:, 3:6].astype(float)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return ctx.geometry, (o, d, *(np.ascontiguousarray(rays[:, c].astype(np.int64)) for c in (6, 7, 8)))


@pytest.mark.parametrize("square", [False, True])
def test_embree_search_answers_the_tracers_queries_as_the_exact_search_does(square):
    """The complete Embree + refinement search (triangle -> part, bracket, acceptance, fallback)
    on a frame's own queries, round and rounded square: the same answer as the analytic search
    for nearly every query, never an earlier one (an earlier accepted crossing would be one the
    exact search missed, or a false root of the refinement: a root outside its part's box was
    one, before the part's box was asked), and a later one only where the mesh hides a crossing."""
    from benchmarks.embree_kernel import EmbreeSearch, triangle_parts
    from benchmarks.tracer import embree_scene, load_scene
    from engine.tracer.context import nearest_hits
    from tests.test_tracer import simple_design

    design = load_scene("square")[0] if square else simple_design(40.0)
    geometry, queries = _frame_queries(design)
    assert len(queries[0]) > 1000 and set(np.unique(queries[2])) > {0}  # queries inside glass too
    t_ex, k_ex, _, _ = nearest_hits(geometry, *queries)
    _, _, mesh = embree_scene(design, 0.02, with_mesh=True)
    obj, part = triangle_parts(geometry, *mesh, 0.02)
    assert np.all(obj >= 0)  # every triangle names its part
    search = EmbreeSearch(geometry, *mesh, tnear=0.05, bracket=0.05, tol=0.02)
    try:
        t, k, _, fell = search.hits(*queries)
    finally:
        search.close()
    with np.errstate(invalid="ignore"):  # inf - inf where both miss
        same = (k == k_ex) & ((np.abs(t - t_ex) <= 1e-6 * np.maximum(1.0, np.abs(t_ex))) | (t == t_ex))
    assert same.mean() > 0.995
    assert not np.any(~same & (t < t_ex * (1 - 1e-6)))
    assert fell.mean() < 0.1


def test_per_surface_search_with_nothing_meshed_is_the_exact_search():
    from benchmarks.embree_kernel import EmbreeSearch
    from benchmarks.tracer import embree_scene
    from engine.tracer.context import nearest_hits
    from tests.test_tracer import simple_design

    design = simple_design(40.0)
    geometry, queries = _frame_queries(design, 16)
    _, _, mesh = embree_scene(design, 0.05, with_mesh=True)
    g = geometry
    none = EmbreeSearch(g, *mesh, tol=0.05, masks=(np.zeros(len(g.seg), bool), np.zeros(len(g.slab_f), bool),
                                                   np.zeros(len(g.obj_i), bool)))
    every = EmbreeSearch(g, *mesh, tol=0.05, masks=(np.ones(len(g.seg), bool), np.ones(len(g.slab_f), bool),
                                                    np.ones(len(g.obj_i), bool)))
    try:
        assert none.triangles == 0 and every.triangles == len(mesh[1])
        t_ex, k_ex, j_ex, _ = nearest_hits(geometry, *queries)
        t, k, j, fell = none.hits(*queries)
        assert np.array_equal(t, t_ex) and np.array_equal(k, k_ex) and not fell.any()
        t, k, j, fell = every.hits(*queries)
        assert np.mean(k == k_ex) > 0.99  # everything meshed: Embree answers
    finally:
        none.close()
        every.close()
