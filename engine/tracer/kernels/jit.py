"""How every kernel is compiled: the options numba is given, in one place.

Design rule: each kernel is decorated ``@njit(**JIT)`` (or ``JIT_NRT`` where it allocates, or
``INLINE`` for small helpers); nothing else in the package passes numba options. ``cache=True``
keeps the machine code on disk in the folder :mod:`engine.tracer.kernels` keys by the hash of
every kernel source, so an edit to any kernel recompiles all of them once.
"""
from __future__ import annotations

#: Options of every kernel. ``_nrt=False`` compiles it without numba's reference counting:
#: with it, each call of a (non-inlined) kernel that is passed arrays increments and decrements
#: their reference counts atomically, on counts that every worker thread shares (the scene's
#: tables), once per ray segment and more. Without it, frames are bit for bit the same and
#: 1.1-2x faster (``python -m benchmarks.tracer``: frame over raw Embree 3.24 -> 2.11 on
#: public_1, 6.5 -> 3.9 on the Bordeaux, 7.1 -> 6.2 on public_4, 1 thread). Such a kernel can
#: take arrays and views of them but not allocate one; the few that allocate their scratch
#: (``tile.make_work``, its caller ``tile.render_pixels``, the batch queries, the albedo
#: quadrature of ``microfacet``) use
#: :data:`JIT_NRT`. ``_nrt`` is numba's own option (``numba.core.options``), not public API:
#: a numba that drops it fails loudly at the first compile, in every test.
JIT = dict(nogil=True, cache=True, fastmath=False, error_model="numpy", _nrt=False)
JIT_NRT = dict(JIT, _nrt=True)
#: Small helpers are inlined at numba's IR level: a cached callee is linked as machine code,
#: so LLVM cannot inline it, and a call passing arrays costs ~30 ns (measured; 5 ns inlined).
INLINE = dict(JIT, inline="always")
