"""Compiled per-ray kernels of the tracer (numba, ``nogil=True, cache=True``).

Design rule: everything a ray does between leaving the camera and reaching the film runs
here, in compiled code that releases the GIL, so worker threads scale with cores. Kernels see
the scene only as the flat arrays of :mod:`engine.tracer.tables.render_objects` and keep no state:
scratch space comes from the caller, so memory per worker is fixed by the tree depth, never by
the scene. Layers, as in pbrt: ``roots`` / ``revolved`` / ``swept`` / ``helix`` (exact
intersectors per surface kind; the ground plane and the backdrop sweep are in ``intersect``)
-> ``intersect`` (nearest hit over the render objects, the surface-interaction record of
``records``) -> ``surface`` (what a hit does to a branch: the ``materials``, with ``labels``,
``finish`` and ``bumps`` over them; ``ground``, ``backdrop``, ``sky`` and ``caustics`` for the
stage) -> ``integrator`` (the reflection/refraction tree of one camera sample) -> ``tile``
(samples of many pixels into ``film`` buffers).
"""
import hashlib as _hashlib
import os as _os
from pathlib import Path as _Path

import numba as _numba


def _cache_dir() -> str:
    """A numba cache folder keyed by the hash of every kernel source file.

    Numba keys its on-disk cache by the defining file alone, so an edit to one kernel would
    leave stale machine code of its callers in other files; a folder per source hash never
    mixes versions. ``GLASSBENCH_KERNEL_CACHE`` overrides the parent folder.
    """
    here = _Path(__file__).resolve().parent
    h = _hashlib.sha256()
    for p in sorted(here.glob("*.py")):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    h.update(_numba.__version__.encode())
    base = _os.environ.get("GLASSBENCH_KERNEL_CACHE") or _os.path.join(
        _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache"),
        "glassbench", "kernels")
    return _os.path.join(base, h.hexdigest()[:16])


CACHE_DIR = _cache_dir()
_numba.config.CACHE_DIR = CACHE_DIR
