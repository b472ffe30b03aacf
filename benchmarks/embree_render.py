"""Renders with Embree + refinement inside the tracer's kernels: the peer benchmark's mesh method.

The engine finds every hit with its analytic search (:func:`engine.tracer.kernels.intersect.
nearest_hit`); ``benchmarks.tracer`` measured, on a frame's own queries, the search an Embree
tracer would run instead (:class:`benchmarks.embree_kernel.EmbreeSearch`). To chart that method
as images (time and error against the references, beside the analytic one and Mitsuba 3) this
module renders a SPEC scene with the engine's own integrator, job and film, its nearest-hit
search swapped for :func:`embree_nearest_hit`: Embree 4's hit on the geometry engine's mesh at
a tolerance, the triangle's part refined onto its exact root within a bracket, the tracer's
acceptance rules, the analytic search where that yields nothing.

How, without touching the engine: it runs in a process of its own (``python -m
benchmarks.embree_render``, which :func:`render` starts) whose kernel cache is a directory of
its own (:func:`cache_dir`; the kernels compiled there call this search, the engine's cache
never sees them; the first run compiles them all, some minutes).
Before anything is compiled it rebinds ``nearest_hit`` in the integrator and label kernels, and
each :class:`~engine.tracer.context.RenderContext` gets two rows appended to its offset table
``tab`` (no segment row points past its own rows): the Embree scene's handle and the addresses
of its triangle -> (object, part) tables, then ``tnear``, the bracket and a marker. The cast and
the refinement are :mod:`benchmarks.embree_kernel`'s (:func:`~benchmarks.embree_kernel.cast1`
calls Embree by name, so the compiled kernels stay cacheable; its ray-hit record lives on the
calling thread's stack).

Units: mm. Benchmarks only.
"""
from __future__ import annotations

import argparse
import dataclasses
import glob
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from benchmarks.embree_kernel import cast1, refine_hit
from engine.tracer.kernels.intersect import nearest_hit
from engine.tracer.kernels.records import Hit
from engine.tracer.kernels.jit import JIT

#: the marker in the appended row that says the table carries an Embree scene
MARKER = 271828.0
#: where the kernels compiled with this search are cached (never the engine's cache)
CACHE_ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out", "kernels-embree")


def cache_dir() -> str:
    """The parent of the engine's kernel cache for this process (``GLASSBENCH_KERNEL_CACHE``,
    under which the engine keys a folder by its kernels' sources): keyed here by this module's
    and :mod:`benchmarks.embree_kernel`'s sources, which the compiled kernels also hold."""
    import hashlib

    h = hashlib.sha256()
    for name in ("embree_render.py", "embree_kernel.py"):
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), name), "rb") as fh:
            h.update(fh.read())
    return os.path.join(CACHE_ROOT, h.hexdigest()[:16])


@intrinsic
def _int64s_at(typingctx, address):
    """An int64* from an address."""
    sig = types.CPointer(types.int64)(address)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], ir.IntType(64).as_pointer())

    return sig, codegen


@njit(**JIT)
def embree_nearest_hit(geom, ray, medium, last, side, scratch):
    """:func:`~engine.tracer.kernels.intersect.nearest_hit`'s contract by Embree + refinement
    (module doc); the analytic search itself where ``tab`` carries no Embree scene."""
    seg, tab, slab_f, slab_i, obj_i, obj_f, plan = geom
    ox, oy, oz, dx, dy, dz = ray
    roots, crit, stack = scratch
    n_tab = tab.shape[0]
    if n_tab < 3 or tab[n_tab - 1, 2] != MARKER:
        return nearest_hit(geom, ray, medium, last, side, scratch)
    # pointers, not arrays: these kernels run without numba's reference counting
    tri_obj = _int64s_at(np.uintp(tab[n_tab - 2, 1]))
    tri_part = _int64s_at(np.uintp(tab[n_tab - 2, 2]))
    tnear, bracket = tab[n_tab - 1, 0], tab[n_tab - 1, 1]
    te, p = cast1(np.uintp(tab[n_tab - 2, 0]), ox, oy, oz, dx, dy, dz, tnear, np.inf)
    if p < 0:
        if medium == 0:  # in air a miss is a miss; elsewhere the mesh let the ray through
            return Hit(np.inf, -1, -1, 0.0, 0.0, 0.0)
    else:
        t, k, j, nx, ny, nz = refine_hit(tri_obj[p], tri_part[p], te, seg, tab, slab_f, slab_i, obj_i, obj_f, ox, oy,
                                         oz, dx, dy, dz, medium, last, side, bracket, np.inf, roots, crit, stack, plan)
        if k >= 0:
            return Hit(t, k, j, nx, ny, nz)
    return nearest_hit(geom, ray, medium, last, side, scratch)


class _MeshedContexts:
    """Appends the Embree rows to every render context this process builds. The mesh, its
    triangle tables and its Embree scene are built once per geometry (as the engine keeps its
    render geometry between jobs) and kept as long as the process; ``build_s`` sums their
    builds (s)."""

    def __init__(self, tol, tnear, bracket):
        self.tol, self.tnear, self.bracket = tol, tnear, bracket
        self.meshes = {}
        self.build_s = 0.0

    def __call__(self, ctx, design):
        from benchmarks.embree_kernel import Embree4Scene, triangle_parts
        from benchmarks.tracer import embree_scene
        from engine.model.fill import fill_height_of

        key = (repr(design.shape), fill_height_of(design))
        if key not in self.meshes:
            start = time.perf_counter()
            _, _, (v, f) = embree_scene(design, self.tol, with_mesh=True)
            tri_obj, tri_part = triangle_parts(ctx.geometry, v, f, self.tol)
            scene = Embree4Scene(v, f)
            rows = np.array([[float(scene.handle), float(tri_obj.ctypes.data), float(tri_part.ctypes.data), len(f)],
                             [self.tnear, self.bracket, MARKER, 0.0]])
            self.meshes[key] = (scene, tri_obj, tri_part, rows)
            self.build_s += time.perf_counter() - start
        rows = self.meshes[key][3]
        tab = np.ascontiguousarray(np.vstack([ctx.scene.geom.tab, rows]))
        return dataclasses.replace(ctx, scene=ctx.scene._replace(geom=ctx.scene.geom._replace(tab=tab)))


def install(tol, tnear, bracket):
    """Swap the search in this process (before any kernel is compiled or loaded); returns the
    hook that records the mesh builds' time."""
    if os.path.abspath(os.environ.get("GLASSBENCH_KERNEL_CACHE", "")) != cache_dir():
        raise RuntimeError(f"run with GLASSBENCH_KERNEL_CACHE={cache_dir()}: these kernels must not enter the "
                           "engine's cache")
    from engine.tracer import context
    from engine.tracer.kernels import integrator, labels

    integrator.nearest_hit = embree_nearest_hit
    labels.nearest_hit = embree_nearest_hit
    hook = _MeshedContexts(tol, tnear, bracket)
    plain = context.RenderContext.from_design.__func__

    def from_design(cls, design, *args, **kw):
        return hook(plain(cls, design, *args, **kw), design)

    context.RenderContext.from_design = classmethod(from_design)
    return hook


def render(spec_path, settings, tol, tnear, bracket, threads=2, timeout=3600):
    """Render a SPEC scene at each of ``settings`` (``(label, spp, target, cut)`` as
    :data:`benchmarks.peer.SETTINGS`) with Embree + refinement at mesh tolerance ``tol`` (mm),
    in a process of its own; returns ``[(label, seconds, image, waves, build_s)]`` (``waves``
    the progressive ``(seconds, image, samples)`` list of :func:`benchmarks.oracle_render.
    render_spec`; ``build_s`` the mesh's build, once before the first setting, not in
    ``seconds``)."""
    import pickle

    import shutil

    here = cache_dir()
    for old in glob.glob(os.path.join(CACHE_ROOT, "*")):  # caches of earlier versions of these modules
        if os.path.abspath(old) != here:
            shutil.rmtree(old, ignore_errors=True)
    env = dict(os.environ, GLASSBENCH_KERNEL_CACHE=here)
    with tempfile.TemporaryDirectory() as tmp:
        job = os.path.join(tmp, "job.pkl")
        out = os.path.join(tmp, "out.pkl")
        with open(job, "wb") as fh:
            pickle.dump((spec_path, list(settings), tol, tnear, bracket, threads), fh)
        subprocess.run([sys.executable, "-m", "benchmarks.embree_render", job, out], env=env, check=True,
                       timeout=timeout, cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        with open(out, "rb") as fh:
            return pickle.load(fh)


def main(argv=None) -> int:
    """The child process of :func:`render` (its own pickles in, its own pickles out)."""
    import pickle

    p = argparse.ArgumentParser(prog="python -m benchmarks.embree_render")
    p.add_argument("job")
    p.add_argument("out")
    a = p.parse_args(argv)
    with open(a.job, "rb") as fh:
        spec_path, settings, tol, tnear, bracket, threads = pickle.load(fh)
    hook = install(tol, tnear, bracket)
    from benchmarks.oracle_render import render_setting, render_spec, setting_sampling
    from benchmarks.oracle_spec import spec_to_design

    scene = spec_to_design(spec_path)
    # kernels loaded, environment decoded, mesh built (as the engine's geometry, once)
    render_spec(spec_path, 1, threads, sampling=setting_sampling(None), scene=scene)
    results = []
    for setting in settings:
        waves = []
        img, secs, _ = render_setting(spec_path, setting, threads, scene=scene, progress=waves)
        results.append((setting[0], secs, img, waves, hook.build_s))
    with open(a.out, "wb") as fh:
        pickle.dump(results, fh)
    return 0


if __name__ == "__main__":
    sys.exit(main())
