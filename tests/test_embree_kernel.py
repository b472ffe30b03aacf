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
