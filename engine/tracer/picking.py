"""What the camera sees at an image point: coverage for alpha, the wall point under the cursor.

Design rule: one ray caster, the tracer's exact search (:func:`engine.tracer.context.
nearest_hits` over :func:`~engine.tracer.context.scene_tables`: the bottle, its true threads and
its closure), so what a final render's alpha covers and where a label dropped on the preview
lands are what the render shows, to the last digit, with no mesh and no march. Rays are the
camera's own (:class:`engine.tracer.camera.PinholeCamera`, SPEC section 2: pixel ``(i, j)``
spans ``[i, i + 1] x [j, j + 1]``). Units mm and pixels.
"""
from __future__ import annotations

import math

import numpy as np

from .camera import PinholeCamera
from .context import nearest_hits, scene_tables
from .tables.stage import ground_objects

#: Rays cast per call of the search (bounds the memory of print-size coverage).
CHUNK_RAYS = 1 << 20
#: The render object of the bottle's outer wall (engine.tracer.tables.render_objects).
OUTER_WALL = 0


def camera_hits(design, width: int, height: int, xs, ys, scene=None):
    """``(t, object, points)`` of the camera rays through image points ``(xs, ys)`` (pixels,
    float, of a ``width x height`` image): distance (inf for a miss), render object (-1) and the
    world point (mm) of each first hit. ``scene`` is a scene tuple of ``design`` to reuse."""
    if scene is None:
        scene = scene_tables(design)[2]
    cam = PinholeCamera.from_design(design.camera, width, height)
    o, d = cam.rays(np.asarray(xs, float).ravel(), np.asarray(ys, float).ravel())
    t, k, _, _ = nearest_hits(scene, o, d)
    with np.errstate(invalid="ignore"):
        points = o + np.where(np.isfinite(t), t, 0.0)[:, None] * d
    return t, k, points


def _pixel_parts(design, width: int, height: int, grid: int, env=None):
    """Per pixel of a ``width x height`` image, from ``grid x grid`` fixed points: the share the
    bottle covers, the share the stage's ground covers and, with ``env`` (an environment map),
    the mean radiance it shows along the camera rays that miss the bottle, ``(H, W, 3)`` (what a
    shadow catcher shows where nothing is in the way, the sky above the horizon included)."""
    scene = scene_tables(design)[2]
    ground = ground_objects(scene)
    sub = (np.arange(grid) + 0.5) / grid
    dx, dy = (a.ravel() for a in np.meshgrid(sub, sub))
    bottle = np.zeros((height, width), np.float32)
    on_ground = np.zeros((height, width), np.float32)
    bg = np.zeros((height, width, 3)) if env is not None else None
    cam = PinholeCamera.from_design(design.camera, width, height)
    rows_per_chunk = max(1, CHUNK_RAYS // (width * len(dx)))
    cols = np.arange(width, dtype=float)
    for r0 in range(0, height, rows_per_chunk):
        rows = np.arange(r0, min(height, r0 + rows_per_chunk), dtype=float)
        shape = (len(rows), width, len(dx))
        x = np.broadcast_to(cols[None, :, None] + dx, shape)
        y = np.broadcast_to(rows[:, None, None] + dy, shape)
        _, k, _ = camera_hits(design, width, height, x, y, scene)
        g = np.isin(k, ground)
        band = slice(r0, r0 + len(rows))
        bottle[band] = ((k >= 0) & ~g).reshape(shape).mean(axis=2)
        on_ground[band] = g.reshape(shape).mean(axis=2)
        if env is not None:
            _, d = cam.rays(x.ravel(), y.ravel())
            behind = (k < 0) | g
            seen = np.where(behind[:, None], env.lookup(d), 0.0).reshape(*shape, 3).sum(axis=2)
            n = behind.reshape(shape).sum(axis=2)[..., None]
            bg[band] = np.divide(seen, n, out=np.zeros_like(seen), where=n > 0)
    return bottle, on_ground, bg


def coverage(design, width: int, height: int, grid: int = 4) -> np.ndarray:
    """Fraction of each pixel the bottle (glass, threads, closure) covers, ``(height, width)``
    float32 in [0, 1], from ``grid x grid`` fixed points per pixel: alpha is geometric coverage,
    not transparency (a cut-out of glass keeps the colour the tracer computed, the studio seen
    through it included), deterministic and independent of the render's samples."""
    return _pixel_parts(design, width, height, grid)[0]


def cutout(design, assets, rgb, grid: int = 4):
    """``(colour, alpha)`` of a final render ``rgb`` ``(H, W, 3)`` (linear) to composite over
    another background: alpha is the bottle's :func:`coverage`, and on a shadow catcher also
    the shadow. There the ground shows the environment's background ``b`` darkened to ``c``;
    the shadow's alpha over the part of the pixel the bottle leaves is ``1 - min(c / b)`` (the
    most darkened channel) and the colour is what, laid over ``b`` with the pixel's alpha,
    gives back ``c`` exactly (a coloured shadow keeps its colour, no channel goes negative). A caustic
    brighter than the background has alpha 0 there: straight alpha cannot add light.
    ``colour`` is unassociated (:func:`engine.files.images.save_image` multiplies for EXR)."""
    h, w = rgb.shape[:2]
    return cut_out(rgb, cutout_parts(design, assets, w, h, grid))


def cutout_parts(design, assets, width: int, height: int, grid: int = 4) -> tuple:
    """What :func:`cutout` traces for an image of ``width x height``: ``(bottle coverage, the
    background seen on a shadow catcher or None)``; one pair serves any image of the design
    (the raw render and its denoised estimate)."""
    if design.stage.kind != "shadow":
        return coverage(design, width, height, grid), None
    from .tables.environment import environment_from_design
    bottle, _, bg = _pixel_parts(design, width, height, grid, environment_from_design(design.environment, assets))
    return bottle, bg


def cut_out(rgb, parts) -> tuple:
    """:func:`cutout` of ``rgb`` from its :func:`cutout_parts`."""
    bottle, bg = parts
    if bg is None:
        return rgb, bottle
    rgb = np.asarray(rgb, float)
    kept = np.divide(rgb, bg, out=np.ones_like(rgb), where=bg > 0.0).min(axis=2)
    shade = np.clip(1.0 - kept, 0.0, 1.0)
    alpha = bottle + (1.0 - bottle) * shade  # the bottle's share, and the shadow's depth over the rest
    with np.errstate(invalid="ignore", divide="ignore"):
        colour = (rgb - (1.0 - alpha)[..., None] * bg) / alpha[..., None]
    colour = np.where(alpha[..., None] > 1e-6, np.maximum(colour, 0.0), 0.0)
    return colour.astype(np.float32), np.clip(alpha, 0.0, 1.0).astype(np.float32)


def wall_point(design, u: float, v: float):
    """``(z_mm, angle_deg)`` where the camera ray through image point ``(u, v)`` (0..1 of the
    design's image width and height, y down) first meets the bottle's outer wall, or ``None``
    when it meets something else first (the closure, the base, the rim) or nothing: where a
    label dropped there goes. ``angle_deg`` is the world polar angle of the point."""
    w, h = design.render.width, design.render.height
    t, k, p = camera_hits(design, w, h, [u * w], [v * h])
    if k[0] != OUTER_WALL or not math.isfinite(t[0]):
        return None
    x, y, z = p[0]
    return float(z), float(math.degrees(math.atan2(y, x)))
