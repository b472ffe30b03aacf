"""Is the hip flask reference's bias in its base its flat 0.2-degree facets? (SPEC_outline 8)

Usage::

    python -m benchmarks.facet_bias mitsuba KIND --seed {1,2} --spp N [--chunk C] [--threads T]
    python -m benchmarks.oracle render ../shared/oracle/specs/outline_public_2.json \\
        -o benchmarks/out/facet_bias/glassbench_1.exr --threads 1
    python -m benchmarks.facet_bias glassbench [--sample-base B]   # a second, independent render
    python -m benchmarks.facet_bias report

Design rule: the experiment changes one thing at a time. Mitsuba renders outline_public_2 as
SPEC_outline 8 says its reference was made (``volpathmis``, ``max_depth`` 1024, no Russian
roulette, facets turning at most 0.2 degrees: :mod:`benchmarks.peer_scene`), on the film's rows
:data:`ROWS` only (the thick base, where 94 % of glassbench's squared error against the
reference sits), from two meshes that differ only in how the base's rounding (the round
profile's first arc, 90 degrees from z = 0 to 3.5 mm) is split: in 451 pieces, as the reference's
mesher did (plain ``ceil`` of 450.00000000000006 steps), or in 450 (the peer's fewest), each with
flat facets (``flat*``: the reference's kind of scene) and with the surfaces' exact vertex normals
(``smooth*``: the exact optics up to the facets' positions, 1e-6 of a radius off the surface).
Every kind has the same samples per pixel and the same seeds, in two halves (seeds 1 and 2) so
its own noise is measured, not guessed. If ``flat451`` matches the reference and ``smooth451``
matches glassbench, the reference's bias is its facets.

``mitsuba`` writes ``benchmarks/out/facet_bias/KIND_s{S}.exr`` (the crop, the running mean) and a
``.json`` beside it (samples so far) after every chunk, so a long half can be stopped and used;
``report`` compares kinds whose two halves have the same count, prints the table and, last,
``facet_bias_ref_vs_flat=X facet_bias_ref_vs_smooth=Y`` (rel RMSE in the crop, the 451 meshes).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

from benchmarks.paths import ORACLE_SPECS

NAME = "outline_public_2"
SPEC = str(ORACLE_SPECS / f"{NAME}.json")
#: The film rows rendered and compared (the base: glassbench's error sits in rows 216-239).
ROWS = (200, 256)
#: The rows of the coherent bias (benchmarks/RESULTS.md, stop 49), reported on their own too.
BASE_ROWS = (216, 240)
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out", "facet_bias")
#: The reference's samples per pixel (refs/outline_public_2.json: two halves of 8192).
REFERENCE_SPP = 16384
#: Block size (pixels) of the coherent part: means over BLOCK x BLOCK pixels cut independent
#: pixel noise by BLOCK and keep a bias that is smooth over that many pixels.
BLOCK = 4
#: The meshes: the split rule's slack (benchmarks.peer_scene.SPLIT_SLACK) sets the base rounding's
#: pieces, 451 at 0 (the reference's mesher) and 450 at 1e-9; flat facets or exact vertex normals.
CONVERSIONS = {f"{look}{pieces}": {"max_turn_deg": 0.2, "vertex_normals": look == "smooth", "split_slack": slack}
               for look in ("flat", "smooth") for pieces, slack in ((451, 0.0), (450, 1e-9))}
#: The pairs reported: the experiment's (the reference's mesh), then the 450-piece mesh's.
PAIRS = (("ref", "flat451"), ("ref", "smooth451"), ("flat451", "smooth451"), ("glassbench", "flat451"),
         ("glassbench", "smooth451"), ("ref", "glassbench"), ("flat450", "flat451"), ("smooth450", "smooth451"),
         ("ref", "flat450"), ("ref", "smooth450"), ("glassbench", "smooth450"))


def half_path(kind: str, seed: int) -> str:
    return os.path.join(OUT, f"{kind}_s{seed}.exr")


def cropped_scene(kind: str, folder: str):
    """Mitsuba's scene of :data:`SPEC` with the ``kind`` conversion, its film cropped to :data:`ROWS`."""
    import mitsuba as mi

    from benchmarks.peer_scene import scene_dict

    d, tris = scene_dict(SPEC, folder, conversion=CONVERSIONS[kind])
    film = d["sensor"]["film"]
    film.update({"crop_offset_x": 0, "crop_offset_y": ROWS[0], "crop_width": film["width"],
                 "crop_height": ROWS[1] - ROWS[0]})
    return mi.load_dict(d, parallel=False), tris


def render_half(kind: str, seed: int, spp: int, chunk: int, threads: int) -> str:
    """Render one half (chunks of ``chunk`` spp, chunk ``j`` seeded ``1000 * seed + j``: the two
    every kind sees the same seeds) and keep its running mean on disk after each chunk."""
    import tempfile

    from benchmarks.peer_scene import mitsuba_available, render_chunks

    why = mitsuba_available()
    if why is not None:
        raise SystemExit(f"facet_bias: Mitsuba is not available ({why})")
    import drjit as dr

    from engine.files.images import save_image

    os.makedirs(OUT, exist_ok=True)
    with tempfile.TemporaryDirectory() as folder:
        t0 = time.perf_counter()
        scene, tris = cropped_scene(kind, folder)
        # (after loading: a 15-million-triangle load on a pool of 1 thread waited forever)
        dr.set_thread_count(threads)
        print(f"{kind}: {tris} triangles, loaded in {time.perf_counter() - t0:.1f} s", flush=True)
        chunks = [chunk] * (spp // chunk) + ([spp % chunk] if spp % chunk else [])
        spent = 0.0
        for total, img, secs in render_chunks(scene, chunks, seed0=1000 * seed):
            spent += secs
            save_image(half_path(kind, seed), img.astype(np.float32))  # (Mitsuba's EXR writer hangs on 1 thread)
            with open(half_path(kind, seed)[:-4] + ".json", "w") as fh:
                json.dump({"kind": kind, "seed": seed, "spp": total, "seconds": spent, "threads": threads,
                           "rows": ROWS, "conversion": CONVERSIONS[kind], "triangles": tris}, fh)
            print(f"  {kind} seed {seed}: {total} spp, {spent:.0f} s", flush=True)
    return half_path(kind, seed)


def read_exr(path) -> np.ndarray:
    from engine.tracer.tables.environment import read_radiance_image

    return np.asarray(read_radiance_image(path), dtype=np.float64)


def rel(a, b, ref) -> float:
    """``sqrt(sum (a - b)^2) / sqrt(sum ref^2)``: SPEC 7's rel RMSE, any pair against ``ref``'s size."""
    return float(np.sqrt(np.sum((a - b) ** 2) / np.sum(ref ** 2)))


def halves(kind: str) -> tuple[np.ndarray, np.ndarray, int] | None:
    """The mean of ``kind``'s two halves, their difference (for the noise) and the samples per
    pixel of each; ``None`` unless both halves are there with the same count."""
    metas = [half_path(kind, s)[:-4] + ".json" for s in (1, 2)]
    if not all(os.path.exists(m) for m in metas):
        return None
    meta = [json.load(open(m)) for m in metas]
    if meta[0]["spp"] != meta[1]["spp"]:
        print(f"({kind}: halves of {meta[0]['spp']} and {meta[1]['spp']} spp, left out)")
        return None
    a, b = (read_exr(half_path(kind, s)) for s in (1, 2))
    return 0.5 * (a + b), a - b, meta[0]["spp"]


def glassbench_pair() -> tuple[np.ndarray, np.ndarray | None]:
    """glassbench's crop (the mean of its renders on independent samples) and their difference
    (``None`` with one render)."""
    lo, hi = ROWS
    imgs = [read_exr(os.path.join(OUT, f"glassbench_{k}.exr"))[lo:hi] for k in (1, 2)
            if os.path.exists(os.path.join(OUT, f"glassbench_{k}.exr"))]
    if not imgs:
        raise SystemExit(f"facet_bias: no glassbench render in {OUT} (see the usage)")
    return np.mean(imgs, axis=0), (imgs[0] - imgs[1]) if len(imgs) == 2 else None


def block_means(img) -> np.ndarray:
    h, w = (img.shape[0] // BLOCK) * BLOCK, (img.shape[1] // BLOCK) * BLOCK
    return img[:h, :w].reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, -1).mean(axis=(1, 3))


def lag1(d) -> float:
    """Correlation of a difference image with itself one pixel along x (channels summed): about
    0 for independent pixel noise, positive for a bias that spans pixels."""
    d = d.sum(axis=-1)
    a, b = d[:, :-1].ravel() - d.mean(), d[:, 1:].ravel() - d.mean()
    return float(np.sum(a * b) / math.sqrt(np.sum(a * a) * np.sum(b * b)))


def compare(images: dict, noise: dict, ref) -> dict:
    """Per pair of :data:`PAIRS` present in ``images``: rel RMSE, the excess over both sides' noise
    ``sqrt(rel^2 - n1^2 - n2^2)`` (0 when the noise explains it all), the rel RMSE of BLOCK x BLOCK
    means, the lag-1 correlation of the difference and the signed mean ``sum (2nd - 1st) / sum ref``."""
    out = {}
    for one, two in PAIRS:
        if one not in images or two not in images:
            continue
        x, y = images[one], images[two]
        r = rel(x, y, ref)
        out[f"{one} vs {two}"] = {
            "rel": r, "excess": math.sqrt(max(0.0, r * r - noise[one] ** 2 - noise[two] ** 2)),
            "blocks": rel(block_means(x), block_means(y), block_means(ref)), "lag1": lag1(x - y),
            "signed": float(np.sum(y - x) / np.sum(ref))}
    return out


def report() -> tuple[float, float]:
    """Print the table (whole crop and the base rows) and return (ref vs flat451, ref vs
    smooth451) over the whole crop."""
    from benchmarks.oracle_render import reference_path

    lo, hi = ROWS
    ref = read_exr(reference_path(SPEC))[lo:hi]
    renders = {k: h for k in CONVERSIONS if (h := halves(k)) is not None}
    if "flat451" not in renders or "smooth451" not in renders:
        raise SystemExit(f"facet_bias: flat451 and smooth451 need both halves in {OUT} (see the usage)")
    gb, d_gb = glassbench_pair()
    print(f"{NAME}, rows {lo}-{hi - 1}: Mitsuba " + ", ".join(f"{k} {h[2]} + {h[2]} spp" for k, h in renders.items())
          + f" (seeds 1, 2); glassbench {'2 renders on independent samples' if d_gb is not None else '1 render'}")
    print("noise: |half 1 - half 2| / 2 (SPEC 6); the reference's: flat451's scaled to "
          f"{REFERENCE_SPP} spp (the same renderer and scene); excess: sqrt(rel^2 - both noises^2)")
    figures = {}
    for label, (a, b) in {"all rows": (0, hi - lo), f"rows {BASE_ROWS[0]}-{BASE_ROWS[1] - 1}":
                          (BASE_ROWS[0] - lo, BASE_ROWS[1] - lo)}.items():
        r = ref[a:b]
        images = {"ref": r, "glassbench": gb[a:b], **{k: h[0][a:b] for k, h in renders.items()}}
        noise = {k: rel(h[1][a:b], 0, r) / 2 for k, h in renders.items()}
        noise["glassbench"] = rel(d_gb[a:b], 0, r) / 2 if d_gb is not None else 0.0
        noise["ref"] = noise["flat451"] * math.sqrt(2 * renders["flat451"][2] / REFERENCE_SPP)
        rows = compare(images, noise, r)
        print(f"\n{label}:  {'pair':24s} {'rel RMSE':>9s} {'excess':>8s} {f'{BLOCK}x{BLOCK} means':>11s} "
              f"{'lag-1':>6s} {'signed (2nd - 1st)':>19s}")
        for name, x in rows.items():
            print(f"  {name:33s} {100 * x['rel']:7.3f} % {100 * x['excess']:6.3f} % {100 * x['blocks']:9.3f} % "
                  f"{x['lag1']:6.2f} {100 * x['signed']:+17.3f} %")
        print("  noise: " + ", ".join(f"{k} {100 * v:.3f} %" for k, v in noise.items())
              + ("" if d_gb is not None else " (glassbench: one render, its noise unknown, taken as 0)"))
        figures[label] = rows
    whole = figures["all rows"]
    return whole["ref vs flat451"]["rel"], whole["ref vs smooth451"]["rel"]


def render_glassbench(sample_base: int, threads: int) -> str:
    """glassbench's converged render (the oracle command's defaults) on samples ``sample_base``
    on in each pixel's sequence, written as ``glassbench_2.exr``."""
    from benchmarks.oracle_render import CLI_SAMPLING, CLI_SPP, render_spec
    from engine.files.images import save_image

    img, secs, _ = render_spec(SPEC, CLI_SPP, threads, sampling=CLI_SAMPLING, sample_base=sample_base)
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, "glassbench_2.exr")
    save_image(path, img)
    print(f"glassbench on samples from {sample_base}: {secs:.1f} s, wrote {path}")
    return path


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.facet_bias")
    sub = p.add_subparsers(dest="command", required=True)
    m = sub.add_parser("mitsuba", help="render one half of the crop in Mitsuba")
    m.add_argument("kind", choices=sorted(CONVERSIONS))
    m.add_argument("--seed", type=int, choices=(1, 2), required=True)
    m.add_argument("--spp", type=int, required=True)
    m.add_argument("--chunk", type=int, default=1024)
    m.add_argument("--threads", type=int, default=1)
    g = sub.add_parser("glassbench", help="glassbench's render on other samples (glassbench_2.exr)")
    g.add_argument("--sample-base", type=int, default=1 << 20)
    g.add_argument("--threads", type=int, default=1)
    sub.add_parser("report", help="the table")
    a = p.parse_args(argv)
    if a.command == "mitsuba":
        render_half(a.kind, a.seed, a.spp, a.chunk, a.threads)
    elif a.command == "glassbench":
        render_glassbench(a.sample_base, a.threads)
    else:
        flat, smooth = report()
        print(f"facet_bias_ref_vs_flat={flat:.5f} facet_bias_ref_vs_smooth={smooth:.5f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
