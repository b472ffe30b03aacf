"""The peer's proof: Mitsuba's scene converges to every public reference, or no ratio is printed.

Usage::

    python -m benchmarks.peer_check [--scenes public_1,...,ground_public_1,thick_jar] [--force]

Design rule: a speed ratio against a peer means something only at the peer's own error against
the same scene. So before :mod:`benchmarks.peer` prints a ratio, Mitsuba's scene
(:mod:`benchmarks.peer_scene`) is rendered at ``CHECK_SPPS`` samples per pixel (one render in
chunks of fresh seeds, its running mean taken at each count: the 4096-spp image costs 4096
samples, not 5440) and compared with each public reference: at 4096 spp it must be within
``LIMIT`` (0.8 %) rel RMSE of every one, else the benchmark prints why and exits non-zero. The
table (spp against rel RMSE per scene) and the slope of log error against log spp are printed:
a scene converging to its reference falls as ``1 / sqrt(spp)`` (slope -0.5) down to the
reference's own noise (``noise_rel_rms`` of ``refs/NAME.json``); the slope of the error above that
noise (subtracted in quadrature) stays near -0.5 where a biased scene's flattens, and a slope
flatter than ``FLATTEST_SLOPE`` (-0.4) on any checked scene refuses the peer too. The result is
cached in ``benchmarks/out/peer_check.json`` under a key hashing the conversion's source
(this module and :mod:`benchmarks.peer_scene`), the conversion settings, Mitsuba's version, the
specs and the references, so an unchanged conversion is not re-rendered (Mitsuba with fixed
seeds renders the same image); ``--force`` (``--check-peer`` in the peer benchmark) renders again.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import sys
import tempfile
import time

import numpy as np

from benchmarks.paths import ORACLE_SPECS

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
CACHE = os.path.join(OUT, "peer_check.json")
#: Samples per pixel of the check; the last is where ``LIMIT`` applies.
CHECK_SPPS = (64, 256, 1024, 4096)
#: Largest rel RMSE (SPEC 7) at 4096 spp against a public reference.
LIMIT = 0.008
#: Flattest slope of log(error above the reference's noise) against log spp still called 1/sqrt(spp).
FLATTEST_SLOPE = -0.4
PUBLIC = ("public_1", "public_2", "public_3", "public_4")
#: Seeds of the check's chunks start here (the benchmark's own renders use 1, 2, ...).
SEED0 = 1000


def spec_path(name: str) -> str:
    """The SPEC file of a scene name: a shared oracle scene, or an extra one of the benchmarks."""
    from benchmarks import thick_jar

    if name == thick_jar.NAME:
        return thick_jar.spec_path()
    return str(ORACLE_SPECS / f"{name}.json")


def reference(name: str) -> tuple[np.ndarray, float]:
    """A scene's reference image and its own noise (``noise_rel_rms`` of its json)."""
    from benchmarks import thick_jar
    from benchmarks.oracle_render import reference_path
    from engine.tracer.tables.environment import read_radiance_image

    if name == thick_jar.NAME:
        thick_jar.ensure_reference()
    path = reference_path(spec_path(name))
    with open(os.path.splitext(path)[0] + ".json") as fh:
        noise = float(json.load(fh)["noise_rel_rms"])
    return np.asarray(read_radiance_image(path), dtype=np.float64), noise


def conversion_key(names, conversion) -> str:
    """Hash of everything the check's answer depends on (see the module doc)."""
    import mitsuba

    from benchmarks import peer_scene
    from benchmarks.oracle_render import reference_path

    h = hashlib.sha256()
    for module in (peer_scene, sys.modules[__name__]):
        with open(module.__file__, "rb") as fh:
            h.update(fh.read())
    h.update(json.dumps([sorted(conversion.items()), CHECK_SPPS, LIMIT, SEED0, mitsuba.__version__]).encode())
    for name in names:
        for path in (spec_path(name), reference_path(spec_path(name))):
            if os.path.exists(path):
                with open(path, "rb") as fh:
                    h.update(hashlib.sha256(fh.read()).digest())
    return h.hexdigest()[:16]


def chunks(spps) -> list[int]:
    """Chunk sizes whose running totals are ``spps``: 64, 192, 768, 3072 for 64..4096."""
    return [b - a for a, b in zip((0, *spps[:-1]), spps)]


def convergence(name: str, conversion=None, spps=CHECK_SPPS) -> dict:
    """``{"spp": [...], "rel_rmse": [...], "seconds": [...], "noise_ref": x, "triangles": n}``:
    Mitsuba's rel RMSE against the scene's reference at each sample count."""
    from benchmarks.oracle_render import rel_rmse
    from benchmarks.peer_scene import load_scene, render_chunks

    ref, noise = reference(name)
    with tempfile.TemporaryDirectory() as folder:
        scene, load_s, tris = load_scene(spec_path(name), folder, conversion=conversion)
        row = {"spp": [], "rel_rmse": [], "seconds": [], "noise_ref": noise, "triangles": tris,
               "load_seconds": load_s}
        for total, img, secs in render_chunks(scene, chunks(spps), seed0=SEED0):
            row["spp"].append(total)
            row["rel_rmse"].append(rel_rmse(img, ref))
            row["seconds"].append(secs)
            print(f"    {name}: {total:5d} spp rel RMSE {100 * row['rel_rmse'][-1]:.2f} % ({secs:.1f} s)", flush=True)
    return row


def slope(spps, errors, floor: float = 0.0) -> float:
    """Least-squares slope of log error against log spp; with ``floor`` the error above it
    (``sqrt(err^2 - floor^2)``, the reference's own noise taken out in quadrature)."""
    e = np.asarray(errors, float)
    above = np.sqrt(np.maximum(e * e - floor * floor, 1e-300))
    return float(np.polyfit(np.log(np.asarray(spps, float)), np.log(above), 1)[0])


def verdict(table: dict, names=PUBLIC, limit: float = LIMIT, at: int = CHECK_SPPS[-1]) -> list[str]:
    """Why Mitsuba's scene is not a valid peer (empty: it is): a scene of ``names`` unchecked,
    or at ``at`` spp further than ``limit`` from its reference; or any scene of the table whose
    error above its reference's noise falls slower than ``spp ** FLATTEST_SLOPE`` (a bias: the
    old 0.005 mm flat-faceted scene's slope was -0.19 on public_1)."""
    why = []
    for name in names:
        row = table.get(name)
        if row is None or at not in row["spp"]:
            why.append(f"{name} was not checked at {at} spp")
            continue
        err = row["rel_rmse"][row["spp"].index(at)]
        if not err <= limit:  # (a NaN fails too)
            why.append(f"{name} at {at} spp is {100 * err:.2f} % rel RMSE from its reference (limit {100 * limit:.1f} %)")
    for name, row in table.items():
        k = slope(row["spp"], row["rel_rmse"], row["noise_ref"])
        if not k <= FLATTEST_SLOPE:
            why.append(f"{name}'s error above its reference's noise falls as spp^{k:.2f}, slower than "
                       f"spp^{FLATTEST_SLOPE}: a bias")
    return why


def format_table(table: dict) -> list[str]:
    """The convergence table: spp against rel RMSE (%) per scene, the references' own noise,
    and the slopes (raw, and of the error above the reference's noise)."""
    rows = list(table.values())
    spps = sorted({s for row in rows for s in row["spp"]})
    lines = [f"  {'spp':>22s}" + "".join(f"{n:>17s}" for n in table)]
    for s in spps:
        cells = [f"{100 * row['rel_rmse'][row['spp'].index(s)]:16.2f}%" if s in row["spp"] else " " * 17
                 for row in rows]
        lines.append(f"  {s:22d}" + "".join(cells))
    lines.append(f"  {'reference noise':>22s}" + "".join(f"{100 * row['noise_ref']:16.2f}%" for row in rows))
    lines.append(f"  {'slope':>22s}" + "".join(f"{slope(row['spp'], row['rel_rmse']):17.2f}" for row in rows))
    lines.append(f"  {'slope above ref. noise':>22s}"
                 + "".join(f"{slope(row['spp'], row['rel_rmse'], row['noise_ref']):17.2f}" for row in rows))
    return lines


def check(names=PUBLIC, force: bool = False, conversion=None) -> dict:
    """The convergence table of ``names`` (rendered, or read from the cache where the key
    matches), printed; :func:`verdict` judges it."""
    from benchmarks.peer_scene import spec_conversion

    overrides, used = conversion, {}
    cache = {}
    if os.path.exists(CACHE):
        with open(CACHE) as fh:
            cache = json.load(fh)
    table = {}
    for name in names:
        conversion = used[name] = spec_conversion(spec_path(name), overrides)
        key = f"{name}@{conversion_key([name], conversion)}"
        if not force and key in cache:
            table[name] = cache[key]["row"]
            print(f"    {name}: the cached check ({key}, {cache[key]['when']})")
            continue
        table[name] = convergence(name, conversion)
        cache[key] = {"row": table[name], "conversion": conversion, "when": time.strftime("%Y-%m-%d %H:%M")}
        os.makedirs(OUT, exist_ok=True)
        with open(CACHE, "w") as fh:
            json.dump(cache, fh, indent=1)
    kinds = {json.dumps(c, sort_keys=True) for c in used.values()}
    said = kinds.pop() if len(kinds) == 1 else "; ".join(f"{n}: {c}" for n, c in used.items())
    print(f"  Mitsuba's scene ({said}) against the references, rel RMSE:")
    for line in format_table(table):
        print(line)
    return table


def time_conversions(name: str, conversions: dict, spp: int = 256, repeats: int = 3) -> dict:
    """Mitsuba's render time of one scene under several conversions (``{label: conversion}``),
    alternating, each the fastest of ``repeats`` (after a compiling render): the peer takes the
    fastest conversion that converges, so its speed is measured, not assumed."""
    import mitsuba as mi

    from benchmarks.peer_scene import load_scene

    with tempfile.TemporaryDirectory() as folder:
        scenes = {}
        for label, conv in conversions.items():
            os.makedirs(os.path.join(folder, label))
            scenes[label] = load_scene(spec_path(name), os.path.join(folder, label), conversion=conv)
            np.array(mi.render(scenes[label][0], spp=spp, seed=1))  # compile
        best = {label: math.inf for label in scenes}
        for _ in range(repeats):
            for label, (scene, _, _) in scenes.items():
                t0 = time.perf_counter()
                np.array(mi.render(scene, spp=spp, seed=2))  # (drjit is lazy: the copy waits for the image)
                best[label] = min(best[label], time.perf_counter() - t0)
        for label, (_, load_s, tris) in scenes.items():
            print(f"    {name} {label}: {tris} triangles, {spp} spp in {best[label]:.2f} s "
                  f"({best[label] / best[next(iter(best))]:.2f} of the first)")
    return best


def main(argv=None) -> int:
    from benchmarks.peer_scene import mitsuba_available

    p = argparse.ArgumentParser(prog="python -m benchmarks.peer_check")
    p.add_argument("--scenes", default=",".join(PUBLIC))
    p.add_argument("--force", action="store_true", help="render again even if the cache matches")
    p.add_argument("--max-turn-deg", type=float, default=None, help="facets' turning (default: the peer's)")
    p.add_argument("--vertex-normals", choices=("yes", "no"), default=None)
    p.add_argument("--time", default=None, metavar="TURN:flat|normals,...",
                   help="time these conversions against each other instead (e.g. 0.2:flat,2:normals)")
    a = p.parse_args(argv)
    why = mitsuba_available()
    if why is not None:
        raise SystemExit(f"benchmarks.peer_check needs Mitsuba 3 with LLVM 19: {why}")
    conversion = {}
    if a.max_turn_deg is not None:
        conversion["max_turn_deg"] = a.max_turn_deg
    if a.vertex_normals is not None:
        conversion["vertex_normals"] = a.vertex_normals == "yes"
    names = a.scenes.split(",")
    public = [n for n in names if n in PUBLIC]  # (the limit is the public references'; any scene's slope counts)
    if a.time:
        convs = {c: {"max_turn_deg": float(c.split(":")[0]), "vertex_normals": c.endswith(":normals")}
                 for c in a.time.split(",")}
        for name in names:
            time_conversions(name, convs)
        return 0
    why = verdict(check(names, a.force, conversion), public)
    for line in why:
        print(f"  not converged: {line}")
    print(f"peer_check={'ok' if not why else 'failed'}")
    return 0 if not why else 1


if __name__ == "__main__":
    raise SystemExit(main())
