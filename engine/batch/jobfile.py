"""The batch job: variants times views at one size, read from a TOML or JSON job file.

Design rule: :func:`read_job` checks everything before anything renders: keys and types,
projects (loaded and validated), every override, every camera, names that become file names.
The result is a :class:`BatchJob` whose :meth:`BatchJob.frames` are complete, frozen render
inputs. Relative paths start at the job file's folder. A job file::

    output = "review"            # folder for images, contact sheet, summary and manifest
    width = 240                  # pixels; width, height and spp default to each project's
    height = 320
    spp = 8
    format = "png"               # png | exr | tif
    alpha = false                # add the bottle's silhouette coverage as alpha
    denoise = false              # true: VIEW.EXT denoised (OIDN), the raw film as VIEW.raw.EXT
    turntable = 8                # views frame_0000 ... orbiting the axis (optional)

    [cameras.front]              # named views (optional): eye and target in mm
    eye = [0, -700, 220]
    target = [0, 0, 150]

    [[projects]]
    file = "bordeaux.glassbench"
      [[projects.variants]]      # no variants: the project as it is
      name = "amber"
      glass_tint = [0.002, 0.006, 0.02]
      fill_ml = 700

Images go to ``OUTPUT/VARIANT/VIEW.EXT`` (the turntable command: ``OUTPUT/frame_0000.EXT``);
with ``denoise = true`` that file is the denoised estimate and the raw film goes beside it as
``VIEW.raw.EXT``, each file's description saying which it is.
"""
from __future__ import annotations

import dataclasses
import os
import re
from dataclasses import dataclass, field

from ..errors import GlassbenchError
from ..model.design import Design
from . import overrides as ov
from .source import JobError, SourceTree, read_source
from .views import View, job_views, turntable_views

FORMATS = ("png", "exr", "tif")
#: Names that become file and folder names: no separators, no leading dot, at most 64 chars.
SAFE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}\Z")
TOP_KEYS = ("output", "width", "height", "spp", "format", "alpha", "denoise", "turntable", "cameras",
            "projects")
LIMITS = {"width": 16384, "height": 16384, "spp": 1 << 20, "turntable": 3600}
#: Variants one job may hold (over all its projects), and frames (variants times views): a job
#: past them is refused before any project is loaded or any override applied, so ``--check``
#: answers at once whatever the file asks.
MAX_VARIANTS = 1000
MAX_FRAMES = 20000


@dataclass(frozen=True, eq=False)
class Variant:
    """A project with overrides applied: ``design`` and ``assets`` (name -> bytes) are final."""

    name: str
    project: str
    design: Design
    assets: dict
    overrides: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Frame:
    """One image to make: ``design`` carries the view's camera and the batch's size and spp."""

    variant: Variant
    view: View
    relpath: str
    design: Design


@dataclass(frozen=True, eq=False)
class BatchJob:
    """Variants x views at one size; ``output`` is the absolute folder everything goes to.
    With ``denoise`` each frame's file is the denoised estimate and its raw film is kept beside
    it (:func:`engine.tracer.denoise.raw_path`)."""

    output: str
    variants: tuple
    views: tuple
    width: int | None = None
    height: int | None = None
    spp: int | None = None
    format: str = "png"
    alpha: bool = False
    flat: bool = False
    denoise: bool = False

    def frames(self) -> list[Frame]:
        """Every frame, variant-major, with its path relative to ``output`` (POSIX ``/``)."""
        out = []
        for var in self.variants:
            r = var.design.render
            render = dataclasses.replace(r, width=self.width or r.width, height=self.height or r.height,
                                         spp=self.spp or r.spp)
            for view in self.views:
                design = dataclasses.replace(var.design, camera=view.camera_for(var.design.camera),
                                             render=render)
                name = f"{view.name}.{self.format}"
                out.append(Frame(var, view, name if self.flat else f"{var.name}/{name}", design))
        return out


def read_job(path: str | os.PathLike, output: str | None = None) -> BatchJob:
    """Read and check a job file; ``output`` (a folder) replaces the file's ``output``.

    The file's ``output`` is relative to the job file's folder, ``output`` to the current one.

    Raises :class:`JobError` ``FILE:LINE: message`` for the first problem found.
    """
    tree = read_source(path)
    data = tree.data
    if not isinstance(data, dict):
        raise tree.error((), "a job file holds a table of settings")
    for key in data:
        if key not in TOP_KEYS:
            raise tree.error((key,), f"unknown setting {key!r} (known: {', '.join(TOP_KEYS)})")
    base = os.path.dirname(os.path.abspath(os.fspath(path)))
    out = os.path.abspath(output) if output else data.get("output")  # -o is relative to the cwd
    if not isinstance(out, str) or not out:
        raise tree.error(("output",), "name the output folder (output = \"folder\", "
                                      "or -o on the command line)")
    sizes = {k: _whole(tree, data, k) for k in ("width", "height", "spp", "turntable")}
    fmt = data.get("format", "png")
    if fmt not in FORMATS:
        raise tree.error(("format",), f"format must be one of {', '.join(FORMATS)}, got {fmt!r}")
    alpha, denoise = _flag(tree, data, "alpha"), _flag(tree, data, "denoise")
    views = job_views(tree, data, sizes["turntable"],
                      lambda where, name: _check_name(tree, where, name, "camera"))
    count = _variant_count(tree, data)
    if count * len(views) > MAX_FRAMES:
        raise tree.error(("projects",), f"{count} variants times {len(views)} views is {count * len(views)} "
                                        f"frames; a job may render at most {MAX_FRAMES} (split it)")
    variants = _variants(tree, data, base)
    return BatchJob(os.path.abspath(os.path.join(base, out)), variants, views, sizes["width"],
                    sizes["height"], sizes["spp"], fmt, alpha, denoise=denoise)


def _flag(tree, data, key) -> bool:
    v = data.get(key, False)
    if not isinstance(v, bool):
        raise tree.error((key,), f"{key} must be true or false, got {v!r}")
    return v


def _whole(tree, data, key):
    v = data.get(key)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= LIMITS[key]:
        raise tree.error((key,), f"{key} must be a whole number in 1..{LIMITS[key]}, got {v!r}")
    return v


def _variant_count(tree: SourceTree, data: dict) -> int:
    """How many variants the job's projects ask for (a project without any is one), counted
    before anything is loaded; :class:`JobError` past :data:`MAX_VARIANTS`."""
    projects = data.get("projects")
    if not isinstance(projects, list):
        return 1
    count = 0
    for proj in projects:
        tables = proj.get("variants", [{}]) if isinstance(proj, dict) else [{}]
        count += len(tables) if isinstance(tables, list) else 1
        if count > MAX_VARIANTS:
            raise tree.error(("projects",), f"more than {MAX_VARIANTS} variants in one job (split it)")
    return count


def _variants(tree: SourceTree, data: dict, base: str) -> tuple:
    from ..files.project import load_project
    projects = data.get("projects")
    if not isinstance(projects, list) or not projects:
        raise tree.error(("projects",), "list at least one project ([[projects]] with file = \"...\")")
    loaded, variants, names = {}, [], set()
    for i, proj in enumerate(projects):
        where = ("projects", i)
        if not isinstance(proj, dict) or not isinstance(proj.get("file"), str):
            raise tree.error(where, "each project needs file = \"NAME.glassbench\"")
        for key in proj:
            if key not in ("file", "variants"):
                raise tree.error(where + (key,), f"unknown project setting {key!r} (known: file, variants)")
        file = os.path.join(base, proj["file"])
        if file not in loaded:
            try:
                loaded[file] = load_project(file)
            except (GlassbenchError, OSError) as exc:
                detail = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
                raise tree.error(where + ("file",), f"cannot load {proj['file']}: {detail}") from None
        design, assets = loaded[file]
        tables = proj.get("variants", [{}])
        if not isinstance(tables, list) or not tables:
            raise tree.error(where + ("variants",), "variants must be a list of tables")
        stem = os.path.splitext(os.path.basename(file))[0]
        for j, table in enumerate(tables):
            vwhere = where + ("variants", j)
            if not isinstance(table, dict):
                raise tree.error(vwhere, "each variant is a table of overrides")
            table = dict(table)
            name = table.pop("name", stem if len(tables) == 1 else f"{stem}-{j + 1}")
            _check_name(tree, vwhere + ("name",), name, "variant")
            if name in names:
                raise tree.error(vwhere + ("name",), f"two variants are named {name!r}")
            names.add(name)
            d, a = ov.apply_overrides(design, assets, table, tree, vwhere, base)
            ov.check_variant_design(d, a, tree, vwhere)
            variants.append(Variant(name, file, d, a, table))
    return tuple(variants)


def _check_name(tree, where, name, what):
    if not isinstance(name, str) or not SAFE_NAME.match(name):
        raise tree.error(where, f"{what} name {name!r} must be letters, digits, '_', '-', '.' or '+' "
                                f"(at most 64, not starting with '.'): it becomes a file name")


def turntable_job(project: str, frames: int, output: str, *, width=None, height=None, spp=None,
                  format: str = "png", alpha: bool = False, denoise: bool = False) -> BatchJob:
    """The ``glassbench turntable`` job: one project, ``frames`` views, ``OUTPUT/frame_0000.EXT``
    (with ``denoise``, denoised, and the raw film beside each as ``frame_0000.raw.EXT``)."""
    from ..files.project import load_project
    if format not in FORMATS:
        raise JobError(f"--format must be one of {', '.join(FORMATS)}, got {format!r}")
    for key, v in (("frames", frames), ("width", width), ("height", height), ("spp", spp)):
        limit = LIMITS.get(key, LIMITS["turntable"])
        if v is not None and not 1 <= v <= limit:
            raise JobError(f"--{key} must be in 1..{limit}, got {v}")
    design, assets = load_project(project)
    stem = os.path.splitext(os.path.basename(project))[0]
    name = stem if SAFE_NAME.match(stem) else "project"
    variant = Variant(name, os.path.abspath(project), design, dict(assets))
    return BatchJob(os.path.abspath(output), (variant,), turntable_views(frames), width, height, spp,
                    format, alpha, flat=True, denoise=bool(denoise))
