"""The window's calls into the engine that need a translation or a worker thread.

Design rule: the window and its controllers reach the engine's numbers, meshes, files and
exports through these functions, which turn engine results into what the GUI shows (a dict of trade numbers with ``None`` where a
number cannot be computed, wireframe edges, a design from a DXF file). Nothing here imports Qt,
so controllers call it from worker threads. It is not the only door: panels import the
engine's model values and named operations directly (``engine.operations``), which is the rule
there, since an edit is an engine operation the panel applies.
"""
from __future__ import annotations

import contextlib
import dataclasses

import numpy as np

from engine.geometry import offset, tessellate

from engine.files import dxf_import, mesh_export, project
from engine.io import atomic
from engine.model import advice, fill, orbit
from engine.operations import trade
from engine.plant import sheet as plant_sheet
from engine.model.design import Design
from engine.errors import GlassbenchError
from engine.model.scene import ALL_CHANGES, Scene  # noqa: F401 - for the window
from engine.model.changes import UNSEEN_FIELDS  # noqa: F401 - for the window

#: Design fields the derived numbers (trade, plant, inner walls, warnings) are computed from:
#: labels and the closure weigh in the plant's stability.
DERIVED_FROM = frozenset({"shape", "liquid", "glass", "cap", "labels", "plant"})
from engine.geometry.section import Section
from engine.geometry.shape import BottleShape
from engine.tracer import job as tracer_job
from engine.tracer.sampling import Sampling


# ----------------------------------------------------------------------------- scene
def make_scene(design: Design, assets: dict | None = None) -> Scene:
    """A scene holding ``design`` and its ``assets`` (name -> bytes)."""
    return Scene(design, assets)


def scene_assets(scene) -> dict:
    """The scene's embedded assets as a plain dict (name -> bytes)."""
    return dict(scene.assets)


# ------------------------------------------------------------------------ validation
def fitted_liquid(design: Design):
    """The design's liquid moved inside its cavity if a shape edit left it outside
    (:func:`engine.model.fill.fitted_liquid`); unchanged when the shape itself is invalid."""
    try:
        return fill.fitted_liquid(design.shape, design.liquid)
    except (GlassbenchError, ValueError, ArithmeticError):
        return design.liquid


def inner_sections(shape: BottleShape) -> dict:
    """Inner wall per section name (a tuple of segments); a section whose inner wall cannot be
    built is left out (validation reports why)."""
    out = {}
    walls = shape.wall_per_segment if shape.wall_per_segment is not None else shape.wall_thickness
    for k, (name, sec) in enumerate(shape.sections):
        with contextlib.suppress(GlassbenchError, ValueError):
            out[name] = offset.inner_section(sec, walls if k == 0 else shape.wall_thickness,
                                             shape.base_thickness)
    return out


# ----------------------------------------------------------------------- trade numbers
def trade_numbers(design: Design) -> dict:
    """The design's trade numbers (:func:`engine.operations.trade.trade_numbers`: ml, mm, cm^3, g),
    with ``None`` where one cannot be computed for the design being edited."""
    return trade.trade_numbers(design, tolerant=True)


# ----------------------------------------------------------------------- plant numbers
def plant_numbers(design: Design) -> dict | None:
    """The plant's numbers of the design (:func:`engine.plant.sheet.plant_numbers`, tolerant: a
    part that cannot be computed is ``None``), or ``None`` when none can be given for the design
    being edited."""
    try:
        return plant_sheet.plant_numbers(design, tolerant=True)
    except (GlassbenchError, ValueError, ArithmeticError):
        return None


# ----------------------------------------------------------------------------- camera
def orbited(start, d_azimuth_deg: float, d_elevation_deg: float):
    """``start`` (a Camera) turned by a drag of the given degrees (:mod:`engine.model.orbit`)."""
    return orbit.orbited(start, d_azimuth_deg, d_elevation_deg)


def design_warnings(design: Design, fill_height_mm: float | None = None) -> list[str]:
    """What the design cannot be made or filled with, in words (:mod:`engine.model.advice`);
    nothing for a shape the engine refuses (validation speaks then)."""
    try:
        return advice.design_warnings(design, fill_height_mm)
    except (GlassbenchError, ValueError, ArithmeticError):
        return []


# ------------------------------------------------------------------------------ files
def load_project(path: str):
    """``(Design, assets)`` from a ``.glassbench`` file; raises :class:`ProjectError`."""
    return project.load_project(path)


def save_project(path: str, design: Design, assets: dict, keep_backup: bool = True) -> None:
    """Write ``design`` and ``assets`` to ``path`` atomically (keeping ``path.bak`` unless told
    not to); raises :class:`ProjectError`."""
    project.save_project(path, design, assets, keep_backup=keep_backup)


def replace_file_atomically(path: str, suffix: str = ""):
    """Context manager yielding a temporary path; on success it replaces ``path`` whole
    (:func:`engine.io.atomic.replacing`): for image exports."""
    return atomic.replacing(path, suffix=suffix)


def import_dxf(path: str, current: Design) -> Design:
    """``current`` with its shape taken from the section in the DXF file at ``path``.

    A round bottle keeps its wall and base; for a non-round bottle the DXF section replaces
    every section (equal sections: the designer then edits the others). An outline bottle keeps
    its plan, wall, base and the rounding at its widest core, and the section becomes its front
    view (:func:`engine.geometry.outline_from_section.outline_from_section`, as ``glassbench new
    --from-dxf SECTION.dxf --plan PLAN.dxf``). Raises on a bad file or an unfitting section.
    """
    section: Section = dxf_import.section_from_dxf(path)
    shape = current.shape
    if shape.cross_section == "outline":  # its core and rounding are two sections: the rule makes both
        from engine.geometry.outline_from_section import outline_from_section
        from engine.geometry.plan_widths import widest_core
        rounding = widest_core(shape).c
        return dataclasses.replace(current, shape=outline_from_section(
            section, shape.plan, shape.wall_thickness, shape.base_thickness, rounding))
    sections = tuple((name, section) for name, _ in shape.sections)
    return dataclasses.replace(current, shape=dataclasses.replace(shape, sections=sections, wall_per_segment=None))


def export_mesh(shape: BottleShape, path: str) -> None:
    """Write the bottle's glass mesh to ``path`` (STL/OBJ/PLY/glTF from the suffix)."""
    mesh_export.export_mesh(shape, path)


# ---------------------------------------------------------------------------- meshes
#: Mesh parts the wireframe shows: the outside of the glass (the inner wall would double
#: every line and hide the form).
WIREFRAME_PARTS = ("outer", "base_outer", "rim")


def wireframe_lines(shape: BottleShape, tol_mm: float = 0.5):
    """``(points (N, 3), edges (M, 2) index pairs)``: rings and meridians of the outer glass
    surface of ``shape`` tessellated to ``tol_mm`` (coarse: this is a view, not an export).

    The triangles' diagonals are left out: a diagonal joins two rings at different polar angles,
    a meridian at (nearly) the same angle, a ring edge stays at one height.
    """
    mesh = tessellate.tessellate_body(shape, tol_mm)
    wanted = [i for i, name in enumerate(mesh.part_names) if name in WIREFRAME_PARTS]
    faces = np.asarray(mesh.faces, dtype=np.int64)[np.isin(mesh.part, wanted)]
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    v = np.asarray(mesh.vertices, dtype=float)
    flat = np.abs(v[edges[:, 0], 2] - v[edges[:, 1], 2]) < 1e-9
    theta = np.arctan2(v[:, 1], v[:, 0])
    turn = np.abs((theta[edges[:, 0]] - theta[edges[:, 1]] + np.pi) % (2 * np.pi) - np.pi)
    step = float(np.median(turn[flat])) if flat.any() else np.pi
    return v, edges[flat | (turn < 0.3 * step)]


def design_wireframe(design, tol_mm: float = 0.5):
    """``(points (N, 3), edges (M, 2))`` of what the 3D view draws: the glass's outside
    (:func:`wireframe_lines`) and the closure's rings and meridians, if it has one."""
    from engine.appearance.closures import closure_outline

    points, edges = wireframe_lines(design.shape, tol_mm)
    cap_points, cap_edges = closure_outline(design)
    if not len(cap_points):
        return points, edges
    return np.concatenate([points, cap_points]), np.concatenate([edges, cap_edges + len(points)])


# ---------------------------------------------------------------------------- tracer
def warm_up_tracer():
    """Load (or compile) the tracer's kernels on a background thread; returns the thread."""
    from engine.tracer.warmup import warm_up_async

    return warm_up_async()


def tracer_job_class():
    """The class that renders a Design progressively (``engine.tracer.job.RenderJob``)."""
    return tracer_job.RenderJob


#: How the window's renders decide a pixel has enough samples: its noise below a fraction of a
#: display level once tone-mapped (what the screen can show), not in linear radiance.
WINDOW_NOISE = Sampling(noise_space="display", noise_target=tracer_job.adaptive.DISPLAY_NOISE, sketch=True)


# ---------------------------------------------------------------------------- labels
def surface_point(design: Design, u: float, v: float):
    """``(z_mm, angle_deg)`` where the camera ray through image point ``(u, v)`` (0..1 of the
    image's width and height, y down) first meets the bottle's outer wall, or ``None``: the
    tracer's own exact search (:func:`engine.tracer.picking.wall_point`)."""
    from engine.tracer.picking import wall_point
    try:
        return wall_point(design, u, v)
    except (GlassbenchError, ValueError, ArithmeticError):
        return None  # a design the tracer cannot build: the caller places the label itself


# ----------------------------------------------------------------------------- exports
def export_cad(design: Design, path: str, tol_mm: float, liquid: bool, progress=None) -> dict:
    """Write the design's solids (STEP/IGES/BREP) and read them back; the check's report."""
    from engine.export.cad import export_cad as write
    return write(design, path, tol_mm, liquid=liquid, progress=progress)


def export_scene(design: Design, assets: dict, path: str, tol_mm: float, progress=None):
    """Write the design's glTF scene (.glb); its counts."""
    from engine.export.gltf_scene import export_scene as write
    return write(design, assets, path, tol_mm, progress)


def export_drawing(design: Design, path: str, sheet: str = "A3", progress=None) -> dict:
    """Write the design's drawing sheet (PDF, SVG or DXF from the suffix of ``path``) on paper
    size ``sheet`` (``"A4"``, ``"A3"``); what :func:`engine.export.drawing.write_drawing`
    reports."""
    from engine.export.drawing import write_drawing as write
    if progress is not None:
        progress(0.0, "Drawing")
    report = write(design, path, sheet=sheet)
    if progress is not None:
        progress(1.0, "Written")
    return report


def export_review_page(design: Design, assets: dict, folder: str, tol_mm: float,
                       poster_height: int | None, turntable: str | None, progress=None,
                       denoise: bool = False):
    """Write the review page folder (with ``denoise``, the poster denoised and the raw one
    beside it); the folder."""
    from engine.export.share import write_share
    return write_share(design, assets, folder, tol_mm, poster_height, turntable, progress, denoise=denoise)
