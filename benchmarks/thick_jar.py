"""A thick jar of the SPEC family, seen from above: an extra oracle scene, with a Mitsuba reference.

Usage::

    python -m benchmarks.thick_jar [--force]     # write the spec, make the reference if stale

Design rule: the public scenes have 3-4 mm walls; thick glass (a 7 mm wall, a 12 mm base) is
where a Whitted tracer's tree grows deepest (total internal reflection in the base, seen through
the open mouth from above), so accuracy and the peer ratio are measured there too. The scene is
a SPEC file like the shared ones (:data:`SPEC`; written to ``benchmarks/out/oracle/specs/``,
its environment the shared ``calibration.exr``), so glassbench renders it through
:func:`benchmarks.oracle_spec.spec_to_design` and Mitsuba through :mod:`benchmarks.peer_scene`.
It has no reference from the oracle: :func:`ensure_reference` makes one the way SPEC section 6
made the shared ones (Mitsuba 3, ``volpathmis``, facets turning 0.2 degrees, two independent
halves of ``REFERENCE_SPP / 2`` samples, noise estimated from their difference), except that its
facets carry the surfaces' exact vertex normals (the spec's ``render.tessellation.
vertex_normals``, which Mitsuba's renders of it in ``benchmarks.peer`` follow too). Seen through a
7 mm wall and a 12 mm base, flat facets move the checker's edges: Mitsuba with exact vertex
normals at 4096 spp was 1.34 % rel RMSE from the flat-faceted reference at 16384 spp (whose noise
is 0.32 %), and glassbench's converged render (16 samples, adaptive 0.002) 1.41 % from the flat
one but 0.99 % from the one with normals (which holds 0.6 % of noise itself). The flat
reference measured its own facets, not the renderers. It caches the reference in
``benchmarks/out/oracle/refs/thick_jar.exr`` (+ ``.json``: spp, time, noise, and the key: a hash
of the spec, Mitsuba's version and the meshes' bytes, so it is made again only when the scene
Mitsuba renders changes). It is Mitsuba's own image, so Mitsuba converging to it proves only its
noise; glassbench converging to it checks two independent implementations against each other.
Units: mm.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import tempfile
import time

import numpy as np

from benchmarks.paths import SHARED

NAME = "thick_jar"
FOLDER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out", "oracle")
#: Samples per pixel of the reference (two halves with their own seeds).
REFERENCE_SPP = 16384
WALL_MM, BASE_MM = 7.0, 12.0


def _profile() -> list[dict]:
    """A 80 mm wide, 125 mm tall jar: base fillet and shoulder of radius 10 mm (more than the
    wall, SPEC 4.1 rule 6), a concave arc into a vertical neck 56 mm across."""
    c70, s70 = math.cos(math.radians(70.0)), math.sin(math.radians(70.0))
    shoulder_end = [30.0 + 10.0 * c70, 90.0 + 10.0 * s70]
    neck_centre = [30.0 + 18.0 * c70, 90.0 + 18.0 * s70]  # 8 mm from the shoulder's end, outwards
    neck = [neck_centre[0] - 8.0, neck_centre[1]]
    return [{"type": "line", "p0": [0.0, 0.0], "p1": [30.0, 0.0]},
            {"type": "arc", "center": [30.0, 10.0], "radius": 10.0, "p0": [30.0, 0.0], "p1": [40.0, 10.0],
             "direction": "ccw"},
            {"type": "line", "p0": [40.0, 10.0], "p1": [40.0, 90.0]},
            {"type": "arc", "center": [30.0, 90.0], "radius": 10.0, "p0": [40.0, 90.0], "p1": shoulder_end,
             "direction": "ccw"},
            {"type": "arc", "center": neck_centre, "radius": 8.0, "p0": shoulder_end, "p1": neck, "direction": "cw"},
            {"type": "line", "p0": neck, "p1": [neck[0], 125.0]}]


SPEC = {
    "name": NAME,
    "note": "thick-walled jar (7 mm wall, 12 mm base) seen from above through its open mouth, faintly "
            "green glass, empty, calibration environment; made for glassbench's benchmarks, reference by Mitsuba (benchmarks/thick_jar.py)",
    "units": "mm",
    "camera": {"eye": [0.0, -240.0, 440.0], "look_at": [0.0, 0.0, 62.0], "up": [0.0, 0.0, 1.0],
               "fov_y_deg": 22.0, "width": 256, "height": 256},
    # (the calibration map: seen from above, the studio's dark floor leaves the image to a few
    # highlights of its softboxes, which path tracing picks by Fresnel weight; their noise was
    # 1.8 % rel RMS at 16384 spp, 0.3 % against the checkerboard)
    "environment": {"file": "calibration.exr", "scale": 1.0},  # made absolute by spec_path
    "air_ior": 1.0,
    "bottle": {"wall_thickness": WALL_MM, "base_thickness": BASE_MM, "cross_section": {"kind": "round"},
               "profile": _profile(), "glass": {"ior": 1.52, "sigma_a": [0.004, 0.0015, 0.003]}},
    "liquid": None,
    "render": {"spp": REFERENCE_SPP, "max_depth": 1024,
               "tessellation": {"max_turn_deg": 0.2, "max_seg_mm": 1000.0, "n_theta_min": 64,
                                "vertex_normals": True}},
}


def spec_path() -> str:
    """Write the jar's SPEC file (its environment a shared oracle map) and return its path."""
    spec = json.loads(json.dumps(SPEC))
    spec["environment"]["file"] = str(SHARED / "oracle" / "env" / spec["environment"]["file"])
    path = os.path.join(FOLDER, "specs", f"{NAME}.json")
    text = json.dumps(spec, indent=1)
    if not os.path.exists(path) or open(path).read() != text:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as fh:
            fh.write(text)
    return path


def reference_key() -> str:
    """Hash of what the reference shows: the spec, Mitsuba's version and integrator depth, and
    the meshes' bytes (not the converter's source: a comment there changes no image)."""
    import mitsuba

    from benchmarks import peer_scene

    h = hashlib.sha256(json.dumps([SPEC, mitsuba.__version__, peer_scene.MAX_DEPTH, peer_scene.ENV_TO_WORLD]).encode())
    spec = json.loads(json.dumps(SPEC))
    normals = peer_scene.spec_conversion(spec_path())["vertex_normals"]
    for name, arrays in sorted(peer_scene.spec_meshes(spec).items()):
        h.update(name.encode())
        for a in arrays[:3 if normals else 2]:  # (flat facets: the normals are not in the scene)
            h.update(np.ascontiguousarray(a, dtype="<f4" if a.dtype.kind == "f" else "<i4").tobytes())
    return h.hexdigest()[:16]


def reference_paths() -> tuple[str, str]:
    return os.path.join(FOLDER, "refs", f"{NAME}.exr"), os.path.join(FOLDER, "refs", f"{NAME}.json")


def ensure_reference(force: bool = False, spp: int = REFERENCE_SPP, chunk: int = 1024) -> str:
    """The reference EXR's path, rendered first if missing, stale (another key) or ``force``."""
    exr, meta_path = reference_paths()
    key = reference_key()
    if not force and os.path.exists(exr) and os.path.exists(meta_path):
        with open(meta_path) as fh:
            if json.load(fh).get("key") == key:
                return exr
    import mitsuba as mi

    from benchmarks.peer_scene import load_scene, mitsuba_available, render_chunks, spec_conversion

    why = mitsuba_available()
    if why is not None:
        raise RuntimeError(f"the thick jar's reference needs Mitsuba 3 with LLVM 19: {why}")
    print(f"  {NAME}: rendering Mitsuba's reference, {spp} spp in two halves (once; cached in {exr})", flush=True)
    halves, t0 = [], time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        conversion = spec_conversion(spec_path())
        scene, load_s, tris = load_scene(spec_path(), folder)
        for half, seed0 in enumerate((1, 100001)):  # SPEC 6: two independent halves
            img = None
            for total, img, _ in render_chunks(scene, [chunk] * (spp // 2 // chunk), seed0=seed0):
                print(f"    half {half + 1}: {total} spp, {time.perf_counter() - t0:.0f} s", flush=True)
            halves.append(img)
    a, b = halves
    ref = 0.5 * (a + b)
    mask = np.any(ref != 0, axis=-1)
    noise = float(np.sqrt(np.sum((a - b)[mask] ** 2)) / 2 / np.sqrt(np.sum(ref[mask] ** 2)))
    os.makedirs(os.path.dirname(exr), exist_ok=True)
    mi.Bitmap(ref.astype(np.float32)).write(exr)
    meta = {"name": NAME, "spp": spp, "seeds": [1, 100001], "render_seconds": round(time.perf_counter() - t0, 1),
            "setup_seconds": round(load_s, 1), "noise_rel_rms": noise, "triangles": tris, "key": key,
            "conversion": conversion, "variant": "llvm_ad_rgb", "integrator": "volpathmis",
            "mean_rgb": ref.reshape(-1, 3).mean(axis=0).tolist()}
    with open(meta_path, "w") as fh:
        json.dump(meta, fh, indent=1)
    print(f"  {NAME}: reference written ({meta['render_seconds']} s, noise {100 * noise:.2f} %)")
    return exr


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.thick_jar")
    p.add_argument("--force", action="store_true", help="render the reference again")
    p.add_argument("--spp", type=int, default=REFERENCE_SPP)
    a = p.parse_args(argv)
    print(f"spec: {spec_path()}")
    print(f"reference: {ensure_reference(a.force, a.spp)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
