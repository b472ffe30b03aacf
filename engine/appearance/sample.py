"""The labelled sample: artwork drawn with numpy, a wine label with a gold-foil chroma region.

Design rule: the sample project ``resources/labelled.glassbench`` (``python
resources/make_labelled.py``), the relabel benchmark and the label render tests all build
their labels here, so they show the same thing. The artwork is asymmetric on purpose (a block
at its top left, a bar at its right), so orientation errors show; its gold region is the
texels of exactly :data:`GOLD_KEY` (sRGB), keyed with a small tolerance.
"""
from __future__ import annotations

import dataclasses
import os
import tempfile

import numpy as np

from ..model.design import FinishRegion, Label, LabelSide

#: The sRGB colour (0..255) the artwork paints where the gold foil goes.
GOLD_KEY = (212, 175, 55)
#: Artwork size in texels (height, width): about 3 texels per mm on the sample's label.
ART_SIZE = (192, 288)


def png_bytes(pixels: np.ndarray) -> bytes:
    """``pixels`` (H, W, 3 or 4) uint8 sRGB as PNG bytes (written through OpenImageIO)."""
    import OpenImageIO as oiio
    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, oiio.UINT8)
    if c == 4:
        spec.alpha_channel = 3
        spec.attribute("oiio:UnassociatedAlpha", 1)
    fd, path = tempfile.mkstemp(suffix=".png")
    os.close(fd)
    try:
        out = oiio.ImageOutput.create(path)
        if out is None or not out.open(path, spec) or not out.write_image(np.ascontiguousarray(pixels)):
            raise OSError(f"cannot write a PNG: {oiio.geterror()}")
        out.close()
        with open(path, "rb") as fh:
            return fh.read()
    finally:
        os.unlink(path)


def sample_artwork(variant: int = 0, size=ART_SIZE) -> np.ndarray:
    """The sample label's front, ``(H, W, 3)`` uint8 sRGB: a cream sheet, a coloured block at
    the top left (deep red for variant 0, navy for 1, green for 2 ...), a dark bar down the
    right side, and a gold band (:data:`GOLD_KEY`) across the lower third."""
    h, w = size
    px = np.empty((h, w, 3), np.uint8)
    px[...] = (236, 228, 206)
    block = [(140, 20, 30), (25, 35, 95), (30, 110, 50), (90, 40, 120)][variant % 4]
    px[h // 10:h * 4 // 10, w // 12:w * 5 // 12] = block
    px[h // 10:h * 9 // 10, w * 10 // 12:w * 11 // 12] = (40, 30, 30)
    px[h * 6 // 10:h * 8 // 10, w // 12:w * 9 // 12] = GOLD_KEY
    return px


def gold_region() -> FinishRegion:
    """The gold-foil region of the sample artwork (a chroma key on :data:`GOLD_KEY`)."""
    return FinishRegion("gold foil", "gold_foil", "chroma", (tuple(c / 255.0 for c in GOLD_KEY),), 0.05,
                        gloss=0.9)


def sample_label(asset: str = "label_front.png", **changes) -> Label:
    """The sample's label on the Bordeaux body (mm): centred 95 mm up, facing the camera, 70 mm
    tall and 100 mm around, with the gold region and a plain cream back."""
    lab = Label("front label", LabelSide(asset), LabelSide(None, (0.8, 0.78, 0.72)), z_mm=95.0,
                angle_deg=-90.0, height_mm=70.0, width_mm=100.0, diffuse=0.85, specular=0.05,
                transmission=0.1, regions=(gold_region(),))
    return dataclasses.replace(lab, **changes)


def labelled(design, assets, variant: int = 0, asset: str = "label_front.png", **changes):
    """``(design, assets)`` with the sample label (artwork ``variant``) added."""
    out = dict(assets or {})
    out[asset] = png_bytes(sample_artwork(variant))
    return dataclasses.replace(design, labels=tuple(design.labels) + (sample_label(asset, **changes),)), out
