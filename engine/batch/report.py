"""What a batch leaves besides its images: a captioned contact sheet and a summary.

Design rule: both are made from the files in the output folder and the job's variants, never
from what happened to be rendered this run, so a resumed batch reports every frame. The
contact sheet (``contact_sheet.png``) shows each variant's views in order, a variant starting
a new row, each thumbnail captioned with variant and view. The summary (``summary.csv`` and
``summary.json``) has one row per variant: the project, the overrides, its trade numbers
(as ``glassbench info``: ml, mm, cm^3, g) and the plant's figures (tip angles, centres of
gravity, weight to capacity, membrane stress: :data:`engine.plant.sheet.SUMMARY_FIGURES`) and
whether the frames are denoised (``denoised``; then each frame row in the JSON names its
``raw_file`` beside it, and the contact sheet, which shows the denoised frames, says so in its
title). All three are written atomically.
"""
from __future__ import annotations

import csv
import io
import json
import os

from ..operations.trade import NUMBER_KEYS, trade_numbers
from ..plant.sheet import SUMMARY_FIGURES, plant_numbers, summary_figures
from ..files.images import display_rgb8, write_bytes
from ..tracer.denoise import raw_path

CONTACT_SHEET = "contact_sheet.png"
SUMMARY_CSV = "summary.csv"
SUMMARY_JSON = "summary.json"
#: Thumbnail box (pixels) and views per row of the contact sheet.
THUMB = 160
COLUMNS = 8


def contact_sheet(job, frames, path: str, title: str = "") -> None:
    """Write the captioned grid of ``frames`` (their files in ``job.output``) to ``path`` (PNG)."""
    from PIL import Image, ImageDraw, ImageFont
    n_views = len(job.views)
    cols = max(1, min(COLUMNS, n_views))
    rows_per_variant = -(-n_views // cols)
    first = frames[0].design.render
    scale = THUMB / max(first.width, first.height)
    tw, th = max(1, round(first.width * scale)), max(1, round(first.height * scale))
    font = ImageFont.load_default(size=12)
    pad, caption, head = 8, 32, 28 if title else 0
    cell_w, cell_h = tw + pad, th + caption
    rows = len(job.variants) * rows_per_variant
    sheet = Image.new("RGB", (pad + cols * cell_w, head + pad + rows * cell_h), (32, 32, 34))
    draw = ImageDraw.Draw(sheet)
    if title:
        draw.text((pad, 8), title, fill=(235, 235, 235), font=font)
    order = {v.name: i for i, v in enumerate(job.variants)}
    views = {v.name: i for i, v in enumerate(job.views)}
    for frame in frames:
        k = views[frame.view.name]
        row = order[frame.variant.name] * rows_per_variant + k // cols
        x, y = pad + (k % cols) * cell_w, head + pad + row * cell_h
        thumb = Image.fromarray(display_rgb8(os.path.join(job.output, frame.relpath)))
        fit = min(tw / thumb.width, th / thumb.height)  # frames of other sizes keep their shape
        w, h = max(1, round(thumb.width * fit)), max(1, round(thumb.height * fit))
        sheet.paste(thumb.resize((w, h), Image.LANCZOS), (x + (tw - w) // 2, y + (th - h) // 2))
        draw.text((x, y + th + 3), _fit(frame.variant.name, tw, font), fill=(235, 235, 235), font=font)
        draw.text((x, y + th + 16), _fit(frame.view.name, tw, font), fill=(160, 160, 165), font=font)
    buf = io.BytesIO()
    sheet.save(buf, format="PNG")
    write_bytes(path, buf.getvalue())


def _fit(text: str, width: int, font) -> str:
    """``text`` cut with an ellipsis to fit ``width`` pixels."""
    while len(text) > 1 and font.getlength(text) > width:
        text = text[:-2] + "\u2026"
    return text


def variant_rows(job, manifest) -> list[dict]:
    """One summary row per variant: names, overrides, trade numbers, frames and render time."""
    by_variant: dict = {}
    for frame in job.frames():
        entry = manifest.frames.get(frame.relpath, {})
        row = {"view": frame.view.name, "file": frame.relpath, "sha256": entry.get("sha256"),
               "seconds": entry.get("seconds"), "worker": entry.get("worker")}
        if job.denoise:  # the file is the denoised estimate; the raw film is beside it
            row["raw_file"] = raw_path(frame.relpath)
        by_variant.setdefault(frame.variant.name, []).append(row)
    rows = []
    for var in job.variants:
        numbers = trade_numbers(var.design)
        d = var.design
        frames = by_variant.get(var.name, [])
        plant = summary_figures(plant_numbers(d, tolerant=True))
        rows.append({"variant": var.name, "project": os.path.basename(var.project),
                     **{k: numbers.get(k) for k in NUMBER_KEYS}, **plant,
                     "glass_absorption_per_mm": list(d.glass.absorption),
                     "liquid_absorption_per_mm": list(d.liquid.absorption) if d.liquid else None,
                     "overrides": var.overrides,
                     "render_seconds": round(sum(f["seconds"] or 0.0 for f in frames), 3),
                     "frames": frames})
    return rows


def write_summary(job, manifest, folder: str) -> tuple[str, str]:
    """Write ``summary.csv`` and ``summary.json`` into ``folder``; returns their paths."""
    rows = variant_rows(job, manifest)
    doc = {"output": job.output, "format": job.format, "alpha": job.alpha, "denoised": job.denoise,
           "views": [v.name for v in job.views], "variants": rows}
    json_path = os.path.join(folder, SUMMARY_JSON)
    write_bytes(json_path, json.dumps(doc, indent=1, allow_nan=False).encode("utf-8"))
    buf = io.StringIO()
    cols = ["variant", "project", *NUMBER_KEYS, *SUMMARY_FIGURES, "glass_absorption_per_mm",
            "liquid_absorption_per_mm",
            "overrides", "frames", "denoised", "render_seconds"]
    writer = csv.DictWriter(buf, fieldnames=cols, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        flat = {k: row[k] for k in cols if k not in ("frames", "denoised")}
        flat["frames"] = len(row["frames"])
        flat["denoised"] = "true" if job.denoise else "false"
        for k in ("glass_absorption_per_mm", "liquid_absorption_per_mm", "overrides"):
            flat[k] = "" if row[k] is None else json.dumps(row[k], separators=(",", ":"))
        for k in (*NUMBER_KEYS, *SUMMARY_FIGURES):
            v = row[k]
            flat[k] = "" if v is None else v if isinstance(v, str) else f"{v:.3f}"
        writer.writerow(flat)
    csv_path = os.path.join(folder, SUMMARY_CSV)
    write_bytes(csv_path, buf.getvalue().encode("utf-8"))
    return csv_path, json_path

