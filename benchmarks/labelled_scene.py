"""The labelled scene of ``python -m benchmarks.peer``: an oracle bottle with a plain paper label.

(:mod:`benchmarks.peer_label` checks the label's mean radiance against Mitsuba on a cylinder; this
scene charts error against time in the peer benchmark.)

Design rule: the label is what the tracer's paper model must get right against a path tracer
with nothing else in the way, so it is a plain colour (no artwork, whose mapping the label
tests check), Lambertian (``specular = transmission = 0``) and lit by the environment only.
glassbench renders it as a decal on the exact outer wall; Mitsuba gets a thin sheet
:data:`SHEET_GAP_MM` outside the wall's tessellation, following the label's own surface map
(:func:`engine.appearance.frame.label_frame`), with a two-sided diffuse BSDF (front colour
outside, back colour inside). There is no independent reference image for this scene, so both
renderers are measured against Mitsuba at :data:`REFERENCE_SPP` samples per pixel.
Units: mm.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

#: The scene the label goes on (a round bottle; the camera looks at the label).
SCENE = "public_1"
#: Air between Mitsuba's label sheet and the glass (mm): far below a pixel (~0.2 mm here).
SHEET_GAP_MM = 0.02
#: Mitsuba's samples per pixel for the reference image.
REFERENCE_SPP = 2048
#: Linear RGB of the front (cream paper) and back (white paper), and the diffuse K.
FRONT, BACK, DIFFUSE = (0.80, 0.62, 0.36), (0.90, 0.90, 0.90), 0.85


def labelled_design(spec_path):
    """``(design, assets)`` of a SPEC scene with one plain paper label facing its camera: centred
    at 40 % of the bottle's height, 30 % of it tall and a quarter of the girth wide."""
    from benchmarks.oracle_spec import spec_to_design
    from engine.appearance.frame import Placement, label_frame
    from engine.model.design import Label, LabelSide

    design, assets = spec_to_design(spec_path)
    eye = design.camera.eye
    z = 0.4 * design.shape.z_top
    angle = math.degrees(math.atan2(eye[1], eye[0]))
    girth = label_frame(design.shape, Placement(z, angle, 1.0, 1.0)).girth_mm
    label = Label("peer label", LabelSide(None, FRONT), LabelSide(None, BACK), z_mm=z, angle_deg=angle,
                  height_mm=0.3 * design.shape.z_top, width_mm=0.25 * girth, diffuse=DIFFUSE,
                  specular=0.0, transmission=0.0)
    return dataclasses.replace(design, labels=(label,), lights=()), assets


def label_sheet(design, label, n_s: int = 96, n_t: int = 64):
    """Vertices ``(N, 3)`` and faces ``(M, 3)`` of the label's sheet for Mitsuba: the label's
    patch on the wall moved :data:`SHEET_GAP_MM` outwards, faces wound so that their normals
    point out of the glass (the front)."""
    from engine.appearance.frame import Placement, label_frame

    frame = label_frame(design.shape, Placement.of(label))
    s, t = np.meshgrid(np.linspace(0.0, 1.0, n_s), np.linspace(0.0, 1.0, n_t))
    p = frame.points(s, t)
    ds = np.gradient(p, axis=1)
    dt = np.gradient(p, axis=0)
    n = np.cross(dt, ds)  # t runs down, s runs with the azimuth: t x s points outwards
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    radial = np.concatenate([p[..., :2], np.zeros_like(p[..., :1])], axis=-1)
    if np.sum(n * radial) < 0.0:
        n = -n
    v = (p + SHEET_GAP_MM * n).reshape(-1, 3)
    idx = np.arange(n_s * n_t).reshape(n_t, n_s)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([b, c, d], -1).reshape(-1, 3)])
    f0 = v[faces[:, 1]] - v[faces[:, 0]]
    f1 = v[faces[:, 2]] - v[faces[:, 0]]
    fn = np.cross(f0, f1)
    centre = v[faces].mean(axis=1)
    if np.sum(fn[:, :2] * centre[:, :2]) < 0.0:
        faces = faces[:, ::-1]
    return v, np.ascontiguousarray(faces)


def sheet_bsdf(label) -> dict:
    """Mitsuba's two-sided diffuse BSDF of a plain label: front outside, back inside."""
    def diffuse(rgb):
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": [label.diffuse * c for c in rgb]}}
    return {"type": "twosided", "front": diffuse(label.front.color), "back": diffuse(label.back.color)}
