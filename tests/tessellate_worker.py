"""Tessellates the nastiest known bottles under a memory limit; run by tests/test_tessellate.py.

Not a test module itself (pytest does not collect it): the address-space limit must not touch
the test process. Usage: ``python -m tests.tessellate_worker LIMIT_BYTES``. Prints one line per
bottle and ``OK peak_rss_mb=...`` at the end; a failure (``MemoryError`` included) exits 1.
"""
from __future__ import annotations

import resource
import sys
import time

from engine.geometry.shape import BottleShape
from tests.peak_memory import peak_rss_bytes
from tests.test_offset import stepped_section, torus_foot_section

#: ``(u, ratio, neck, wall)`` of rounded squares from the hypothesis test's strategy whose inner
#: corner (the outer's minus the wall) is ten times sharper than the outer one: their inner
#: walls once split into 2^16 times the rings at 0.1 mm (6.4 GB, 13 minutes for one of them).
SHARP_INNER_CORNERS = ((18.719, 1.3404, 13.119, 3.056), (27.796, 1.3327, 7.153, 3.372),
                       (20.030, 1.3459, 12.066, 1.899))


def stepped_bottle(kind: str, u: float, ratio: float, neck: float, wall: float) -> BottleShape:
    """The hypothesis test's bottle: body radii ``u`` and ``u * ratio`` (mm) to 90 mm, a straight
    shoulder to a ``neck`` radius at 120 mm, a finish to 150 mm; glass ``wall`` mm, base + 2 mm."""
    names = {"rounded_square": ("u", "v"), "oval": ("half_width", "half_depth"), "round": ("profile",)}[kind]
    return BottleShape(kind, {nm: stepped_section(r, 90.0, neck, 120.0, 150.0)
                              for nm, r in zip(names, (u, u * ratio))}, wall, wall + 2.0)


def huge_torus_bottle() -> BottleShape:
    """A 2 m wide round bottle with a 900 mm foot arc: at the finest tolerance its walls need
    millions of triangles, more than a wall may have."""
    return BottleShape("round", {"profile": torus_foot_section(100.0, 900.0, 1900.0)}, 2.0, 4.0)


def peak_rss_mb() -> float:
    """This process's peak resident memory (MiB), see :mod:`tests.peak_memory`."""
    return peak_rss_bytes() / 2**20


def main() -> int:
    limit = int(sys.argv[1])
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    from engine.geometry.tessellate import tessellate_body
    from engine.limits import MIN_TOL_MM

    for args in SHARP_INNER_CORNERS:
        t0 = time.perf_counter()
        mesh = tessellate_body(stepped_bottle("rounded_square", *args), 0.1)
        print(f"sharp inner corner {args}: {len(mesh.faces)} triangles in {time.perf_counter() - t0:.2f} s",
              flush=True)
    t0 = time.perf_counter()
    try:
        tessellate_body(huge_torus_bottle(), MIN_TOL_MM)
    except ValueError as exc:
        print(f"huge bottle at {MIN_TOL_MM} mm refused in {time.perf_counter() - t0:.2f} s: {exc}", flush=True)
    else:
        raise AssertionError("the huge bottle at the finest tolerance was meshed, not refused")
    print(f"OK peak_rss_mb={peak_rss_mb():.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
