"""One door from the window to the engine: every engine call the GUI makes goes through here.

Design rule: the GUI never imports engine modules that may still be missing directly. Each
function here imports its engine module lazily and, where the module has not landed yet, falls
back to a small stand-in so the window still opens (the stand-ins never pretend to be exact:
trade numbers become ``None`` and the preview says the tracer is missing). Nothing here imports
Qt, so controllers can call it from worker threads.
"""
from __future__ import annotations

import contextlib
import importlib
import math
from typing import Callable

import numpy as np

from engine.design import Design
from engine.errors import GlassbenchError, ProjectError, SectionError
from engine.shape import BottleShape


def _module(name: str):
    """The engine module ``name`` or ``None`` when it has not been written yet."""
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as exc:
        if exc.name and name.startswith(exc.name):
            return None
        raise


# ----------------------------------------------------------------------------- scene
class _StandInScene:
    """Observable holder of a Design, used only until :mod:`engine.scene` exists."""

    def __init__(self, design: Design, assets: dict | None = None):
        self._design = design
        self.assets = dict(assets or {})
        self._observers: list[Callable] = []
        self._pending: set[str] | None = None

    @property
    def design(self) -> Design:
        return self._design

    def snapshot(self) -> Design:
        return self._design

    def subscribe(self, callback):
        self._observers.append(callback)
        return lambda: self._observers.remove(callback) if callback in self._observers else None

    def _notify(self, changed):
        if not changed:
            return
        if self._pending is not None:
            self._pending |= set(changed)
            return
        for cb in list(self._observers):
            cb(frozenset(changed), self)

    def replace(self, **changes):
        import dataclasses
        changed = {k for k, v in changes.items() if getattr(self._design, k) != v}
        if changed:
            self._design = dataclasses.replace(self._design, **{k: changes[k] for k in changed})
        self._notify(changed)

    def set_design(self, design: Design):
        import dataclasses
        changed = {f.name for f in dataclasses.fields(Design)
                   if getattr(self._design, f.name) != getattr(design, f.name)}
        self._design = design
        self._notify(changed)

    def set_asset(self, name, data):
        self.assets[name] = data
        self._notify({"assets"})

    @contextlib.contextmanager
    def batch(self):
        outer = self._pending is not None
        if not outer:
            self._pending = set()
        try:
            yield self
        finally:
            if not outer:
                changed, self._pending = self._pending, None
                self._notify(changed)


def make_scene(design: Design, assets: dict | None = None):
    """A scene holding ``design`` (the engine's Scene once it exists)."""
    mod = _module("engine.scene")
    if mod is None:
        return _StandInScene(design, assets)
    scene = mod.Scene(design)
    for name, data in (assets or {}).items():
        scene.set_asset(name, data)
    return scene


def scene_assets(scene) -> dict:
    """The scene's embedded assets as a plain dict (name -> bytes)."""
    assets = getattr(scene, "assets", {})
    return dict(assets() if callable(assets) else assets)


# ------------------------------------------------------------------------ validation
def validate_shape(shape: BottleShape) -> None:
    """Raise a :class:`GlassbenchError` naming the problem when ``shape`` is not a valid bottle."""
    mod = _module("engine.validate")
    if mod is not None:
        mod.validate_shape(shape)
        return
    # Stand-in: the chain rules of SPEC 4.1 that matter most while editing.
    for name, sec in shape.sections:
        segs = sec.segments
        for i in range(1, len(segs)):
            if math.dist(segs[i - 1].p1, segs[i].p0) > 1e-6:
                raise SectionError(i, f"{name}: does not start where segment {i - 1} ends")
            if segs[i].p1[1] <= segs[i].p0[1]:
                raise SectionError(i, f"{name}: height must increase along the wall")
            if min(segs[i].p0[0], segs[i].p1[0]) <= 0:
                raise SectionError(i, f"{name}: radius must stay positive")


def inner_sections(shape: BottleShape) -> dict:
    """Inner wall per section name (a sequence of segments), or ``{}`` when unavailable."""
    mod = _module("engine.offset")
    if mod is None:
        return {}
    out = {}
    for name, sec in shape.sections:
        with contextlib.suppress(GlassbenchError, ValueError, AttributeError, TypeError):
            inner = mod.inner_section(sec, shape.wall_thickness, shape.base_thickness)
            out[name] = getattr(inner, "segments", inner)
    return out


# ----------------------------------------------------------------------- trade numbers
def trade_numbers(design: Design) -> dict:
    """Brimful and fill capacity (ml), fill height (mm), fill point below the top (mm),
    glass volume (cm^3) and mass (g); a value is ``None`` where it cannot be computed."""
    mod = _module("engine.capacity")
    keys = ("brimful_ml", "fill_ml", "fill_height_mm", "fill_point_mm", "glass_cm3", "glass_g")
    out = dict.fromkeys(keys)
    if mod is None:
        return out
    shape, liquid = design.shape, design.liquid

    def attempt(key, fn, *args):
        with contextlib.suppress(GlassbenchError, ValueError, ArithmeticError, TypeError):
            out[key] = float(fn(*args))

    attempt("brimful_ml", mod.brimful_ml, shape)
    attempt("glass_cm3", mod.glass_volume_cm3, shape)
    attempt("glass_g", mod.glass_mass_g, shape, design.glass.density_g_cm3)
    if liquid is not None:
        if liquid.fill_mode == "volume":
            attempt("fill_height_mm", mod.fill_height_for_volume, shape, liquid.fill_value)
        else:
            out["fill_height_mm"] = float(liquid.fill_value)
        if out["fill_height_mm"] is not None:
            attempt("fill_ml", mod.capacity_ml, shape, out["fill_height_mm"])
            out["fill_point_mm"] = shape.z_top - out["fill_height_mm"]
    return out


def fill_height_mm(design: Design) -> float | None:
    """Height (mm) of the liquid surface above z = 0, or ``None`` without a liquid."""
    liquid = design.liquid
    if liquid is None:
        return None
    if liquid.fill_mode == "height":
        return float(liquid.fill_value)
    return trade_numbers(design)["fill_height_mm"]


# ------------------------------------------------------------------------------ files
def load_project(path: str):
    """``(Design, assets)`` from a ``.glassbench`` file; raises :class:`ProjectError`."""
    mod = _module("engine.project")
    if mod is None:
        raise ProjectError("project files cannot be read yet (engine.project is missing)")
    return mod.load_project(path)


def save_project(path: str, design: Design, assets: dict) -> None:
    """Write ``design`` and ``assets`` to ``path`` atomically; raises :class:`ProjectError`."""
    mod = _module("engine.project")
    if mod is None:
        raise ProjectError("project files cannot be written yet (engine.project is missing)")
    mod.save_project(path, design, assets)


def import_dxf(path: str, current: Design) -> Design:
    """A design whose shape comes from the DXF file at ``path``; raises on a bad file."""
    mod = _module("engine.dxf_import")
    if mod is None:
        raise ProjectError("DXF import is not available yet (engine.dxf_import is missing)")
    for name in ("section_from_dxf", "import_dxf_shape", "import_dxf", "read_dxf"):
        fn = getattr(mod, name, None)
        if fn is not None:
            break
    else:
        raise ProjectError("engine.dxf_import offers no import function")
    result = fn(path)
    import dataclasses
    if isinstance(result, Design):
        return result
    if isinstance(result, BottleShape):
        return dataclasses.replace(current, shape=result)
    # A Section or a list of segments: a round bottle with that profile.
    from engine.section import Section
    section = result if isinstance(result, Section) else Section(tuple(result))
    shape = BottleShape("round", (("profile", section),), current.shape.wall_thickness,
                        current.shape.base_thickness)
    return dataclasses.replace(current, shape=shape)


def export_mesh(shape: BottleShape, path: str) -> None:
    """Write the bottle's mesh to ``path`` (format from the suffix)."""
    mod = _module("engine.mesh_export")
    if mod is None:
        raise ProjectError("mesh export is not available yet (engine.mesh_export is missing)")
    mod.export_mesh(shape, path)


# ---------------------------------------------------------------------------- meshes
def _section_polyline(section, samples_per_segment: int = 12) -> np.ndarray:
    pts = [np.atleast_2d(seg.point(np.linspace(0.0, 1.0, samples_per_segment)))
           for seg in section.segments]
    return np.concatenate(pts, axis=0)


def wireframe_lines(shape: BottleShape, tol_mm: float = 0.5):
    """``(points (N,3), lines (M,2) index pairs)`` outlining the outer surface of ``shape``.

    Uses :func:`engine.tessellate.tessellate_body` when present (edges of its triangles);
    otherwise revolves the first section: enough to see the form while geometry lands.
    """
    mod = _module("engine.tessellate")
    if mod is not None:
        mesh = mod.tessellate_body(shape, tol_mm)
        faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
        edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
        edges = np.unique(np.sort(edges, axis=1), axis=0)
        return np.asarray(mesh.vertices, dtype=float), edges
    rz = _section_polyline(shape.primary)
    n_theta = 48
    theta = np.linspace(0.0, 2 * math.pi, n_theta, endpoint=False)
    pts = np.stack([np.outer(np.cos(theta), rz[:, 0]), np.outer(np.sin(theta), rz[:, 0]),
                    np.broadcast_to(rz[:, 1], (n_theta, len(rz)))], axis=-1).reshape(-1, 3)
    idx = np.arange(n_theta * len(rz)).reshape(n_theta, len(rz))
    meridians = np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], axis=1)
    rings = np.stack([idx.ravel(), np.roll(idx, -1, axis=0).ravel()], axis=1)
    return pts, np.concatenate([meridians, rings[:: max(1, len(rz) // 12)]])


# ---------------------------------------------------------------------------- tracer
def tracer_job_class():
    """The engine's ``RenderJob`` class, or ``None`` while the tracer has not landed."""
    mod = _module("engine.tracer.job")
    return None if mod is None else mod.RenderJob


def tonemap_srgb8(image: np.ndarray) -> np.ndarray:
    """Linear RGB float image -> sRGB uint8 (the tracer's tone map when present)."""
    mod = _module("engine.tracer.job")
    if mod is not None and hasattr(mod, "tonemap_srgb8"):
        return np.asarray(mod.tonemap_srgb8(image))
    x = np.clip(np.nan_to_num(np.asarray(image, dtype=float)[..., :3]), 0.0, 1.0)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (srgb * 255 + 0.5).astype(np.uint8)
