"""A labelled bottle, glassbench against Mitsuba 3: how right is the labels' diffuse shading?

Usage::

    python -m benchmarks.peer_label [--width 120] [--height 160] [--spp 256]

A round glass bottle (r 40 mm, no liquid) in the oracle's studio environment
(``../shared/oracle/env/studio.exr``) with one paper label (plain colour, diffuse K 0.8, no
coat, no transmission, the same colour on both faces, no lights: Mitsuba sees the environment
only). glassbench shades the sheet with its prefiltered irradiance
(:mod:`engine.tracer.kernels.labels`); Mitsuba 3 (``llvm_ad_rgb``, ``volpathmis``) gets the same
glass as the geometry engine's interface mesh and the label as a two-sided diffuse cylindrical
patch 0.05 mm outside the wall, and path-traces it at ``--spp``. Compared over the pixels where
the labelled and unlabelled glassbench images differ inside the bulk of those pixels' box (the
label seen directly, and a thin arc of it reflected in the base): the ratio of mean radiances and the relative RMSE per pixel (Mitsuba's
own noise included). Writes ``benchmarks/out/peer_label.csv`` and ``peer_label.png`` (both
images and their ratio); prints last ``label_peer_mean_ratio=X`` (glassbench over Mitsuba).
Needs Mitsuba (see :mod:`benchmarks.peer`); prints ``label_peer_skipped=REASON`` without it.
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import os
import tempfile
import time

import numpy as np

from benchmarks.paths import SHARED
from benchmarks.peer import _write_ply, mitsuba_available

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "out")
ENV = SHARED / "oracle" / "env" / "studio.exr"
R_MM, TOP_MM = 40.0, 200.0
COLOUR = (0.7, 0.45, 0.25)


def scene(width, height):
    """``(design without label, design with it, assets)``."""
    from engine.model.design import Camera, Design, Environment, Label, LabelSide, RenderSettings
    from tests.label_helpers import cylinder_shape

    lab = Label("paper", LabelSide(None, COLOUR), LabelSide(None, COLOUR), z_mm=100.0, angle_deg=-90.0,
                height_mm=50.0, width_mm=70.0, diffuse=0.8, specular=0.0, transmission=0.0)
    bare = Design(cylinder_shape(R_MM, TOP_MM), camera=Camera(eye=(0.0, -420.0, 130.0), target=(0.0, 0.0, 100.0),
                                                               fov_y_deg=32.0),
                  environment=Environment("file", "studio.exr"), lights=(),
                  render=RenderSettings(width=width, height=height, spp=16))
    return bare, dataclasses.replace(bare, labels=(lab,)), {"studio.exr": str(ENV)}


def label_patch(lab, n=64):
    """The label as a cylindrical grid mesh 0.05 mm outside the wall (vertices, faces)."""
    from types import SimpleNamespace

    r = R_MM + 0.05
    half = lab.width_mm / R_MM / 2.0
    th = math.radians(lab.angle_deg) + np.linspace(-half, half, n)
    z = lab.z_mm + np.linspace(-lab.height_mm / 2, lab.height_mm / 2, n)
    tt, zz = np.meshgrid(th, z)
    v = np.stack([r * np.cos(tt), r * np.sin(tt), zz], -1).reshape(-1, 3)
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1], i[:-1, 1:], i[1:, :-1], i[1:, 1:]
    f = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return SimpleNamespace(vertices=v, faces=f)


def mitsuba_image(design, spp, folder):
    import mitsuba as mi

    from engine.geometry.tessellate import tessellate_interfaces

    cam, g, lab = design.camera, design.glass, design.labels[0]
    rot = mi.ScalarTransform4f([[0, 0, -1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
    d = {"type": "scene", "integrator": {"type": "volpathmis", "max_depth": 256, "rr_depth": 256},
         "sensor": {"type": "perspective", "fov_axis": "y", "fov": float(cam.fov_y_deg),
                    "to_world": mi.ScalarTransform4f().look_at(origin=list(cam.eye), target=list(cam.target),
                                                               up=list(cam.up)),
                    "film": {"type": "hdrfilm", "width": design.render.width, "height": design.render.height,
                             "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                    "sampler": {"type": "independent", "sample_count": spp}},
         "env": {"type": "envmap", "filename": str(ENV), "to_world": rot},
         "glass_medium": {"type": "homogeneous", "albedo": {"type": "rgb", "value": [0.0, 0.0, 0.0]},
                          "sigma_t": {"type": "rgb", "value": list(map(float, g.absorption))}}}
    for name, mesh in tessellate_interfaces(design.shape, None, 0.02).items():
        if name != "glass_air":
            continue
        path = os.path.join(folder, f"{name}.ply")
        _write_ply(path, mesh)
        d[name] = {"type": "ply", "filename": path, "face_normals": True,
                   "bsdf": {"type": "dielectric", "int_ior": float(g.ior), "ext_ior": 1.0},
                   "interior": {"type": "ref", "id": "glass_medium"}}
    path = os.path.join(folder, "label.ply")
    _write_ply(path, label_patch(lab))
    albedo = [lab.diffuse * c for c in lab.front.color]
    d["label"] = {"type": "ply", "filename": path,
                  "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse",
                                                       "reflectance": {"type": "rgb", "value": albedo}}}}
    scene = mi.load_dict(d)
    t0 = time.perf_counter()
    img = np.array(mi.render(scene, spp=spp, seed=1))
    return img, time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--width", type=int, default=120)
    ap.add_argument("--height", type=int, default=160)
    ap.add_argument("--spp", type=int, default=256)
    args = ap.parse_args(argv)
    why = mitsuba_available()
    if why is not None:
        print(f"label_peer_skipped={why}")
        return 0
    from engine.tracer.job import render_image

    bare, labelled, assets = scene(args.width, args.height)
    t0 = time.perf_counter()
    ours = render_image(labelled, assets, threads=2).astype(np.float64)
    t_ours = time.perf_counter() - t0
    without = render_image(bare, assets, threads=2).astype(np.float64)
    with tempfile.TemporaryDirectory() as folder:
        theirs, t_theirs = mitsuba_image(labelled, args.spp, folder)
    changed = np.abs(ours - without).max(axis=2) > 1e-3
    ys, xs = np.nonzero(changed)
    # the label's pixels: the changed pixels' bulk (their 2..98 % box, 2 px inside)
    y0, y1 = np.percentile(ys, 2) + 2, np.percentile(ys, 98) - 2
    x0, x1 = np.percentile(xs, 2) + 2, np.percentile(xs, 98) - 2
    yy, xx = np.mgrid[:args.height, :args.width]
    mask = changed & (yy >= y0) & (yy <= y1) & (xx >= x0) & (xx <= x1)
    a, b = ours[mask], theirs[mask]
    ratio = float(a.mean() / b.mean())
    per_channel = (a.mean(axis=0) / b.mean(axis=0)).tolist()
    rel = float(np.sqrt(np.mean((a - b) ** 2)) / b.mean())
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "peer_label.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["pixels", "glassbench_s", "mitsuba_s", "mitsuba_spp", "mean_ratio", "ratio_r", "ratio_g",
                    "ratio_b", "rel_rmse"])
        w.writerow([int(mask.sum()), t_ours, t_theirs, args.spp, ratio, *per_channel, rel])
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(9, 4))
    ax[0].imshow(np.clip(ours, 0, 1) ** (1 / 2.2))
    ax[0].set_title("glassbench")
    ax[1].imshow(np.clip(theirs, 0, 1) ** (1 / 2.2))
    ax[1].set_title(f"Mitsuba 3, {args.spp} spp")
    im = ax[2].imshow(np.where(mask, ours.mean(2) / np.maximum(theirs.mean(2), 1e-6), np.nan), vmin=0.8, vmax=1.2,
                      cmap="coolwarm")
    ax[2].set_title("ratio on the label")
    fig.colorbar(im, ax=ax[2], fraction=0.05)
    for x in ax:
        x.axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "peer_label.png"), dpi=100)
    print(f"label pixels {int(mask.sum())}; glassbench {t_ours:.2f} s, Mitsuba {t_theirs:.2f} s at {args.spp} spp")
    print(f"per-channel ratio {', '.join(f'{v:.4f}' for v in per_channel)}; rel RMSE {rel:.4f}")
    print(f"wrote {OUT}/peer_label.csv and peer_label.png")
    print(f"label_peer_mean_ratio={ratio:.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
