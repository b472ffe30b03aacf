"""The review page: one self-contained folder a brand reviewer opens in a browser, even offline.

Design rule: ``glassbench share`` writes everything the page needs into one folder and fetches
nothing at view time: ``index.html``; ``<model-viewer>``'s self-contained UMD script copied from
``web/node_modules`` (:mod:`engine.export.web`); the scene (:mod:`engine.export.gltf_scene`) as
``scene.glb`` to download and, base64 in ``scene-data.js``, as the page's own copy (a page
opened from a file may not fetch its neighbours, so it hands the viewer a ``blob:`` URL) and
the design's environment as the viewer's sky (a ``data:`` PNG, :func:`skybox_png`: glass that
transmits needs something behind it to show) seen from the design's camera;
``poster.png`` rendered by glassbench's tracer to its noise target (converged,
:class:`engine.tracer.job.RenderJob`; when asked, its denoised estimate, the raw render beside
it as ``poster.raw.png`` and the page saying which it shows); the trade numbers of :func:`engine.operations.trade.
trade_numbers`, in a table whose cells carry each exact value (``data-value``), the plant's
headline figures (:func:`engine.plant.sheet.plant_numbers`: least tip angle, capacity band, membrane
stress), and, whole, the JSON ``glassbench info --json`` prints (in the page and as
``numbers.json``, the plant's under ``"plant"``); each label's
die-line as SVG (:func:`engine.appearance.dieline_files.write_dieline`; labels of one flat
shape share one); and the frames of a
turntable, when one was rendered, as a flip-book (denoised frames said to be so, their raw
frames left out). The folder is built beside the target and
swapped in whole; an existing folder is replaced only if it is a review page (it holds
:data:`MARKER`), never another folder of the user's.
"""
from __future__ import annotations

import base64
import html
import json
import os
import secrets
import shutil
from pathlib import Path

from ..errors import GlassbenchError
from ..operations.trade import INFO_ROWS, trade_numbers
from ..plant.sheet import plant_numbers
from ..tracer.denoise import DENOISED_NOTE, raw_path
from .gltf_scene import scene_glb
from .web import model_viewer_js

#: The file that marks a folder as a review page glassbench wrote (and may replace).
MARKER = ".glassbench-share"
#: The poster's default size (pixels): the design's aspect, at most this tall.
POSTER_HEIGHT = 640
#: The raw render beside a denoised poster (``poster.raw.png``).
RAW_POSTER = raw_path("poster.png")
#: Turntable frames a page takes at most.
MAX_TURNTABLE_FRAMES = 720


class ShareError(GlassbenchError, ValueError):
    """The review page cannot be written where or as asked; says why."""


def poster_size(design, height: int | None = None) -> tuple[int, int]:
    """``(width, height)`` of the poster: the design's aspect, ``height`` (default at most
    :data:`POSTER_HEIGHT`) pixels tall."""
    h = int(height or min(design.render.height, POSTER_HEIGHT))
    return max(1, round(h * design.render.width / design.render.height)), h


def render_poster(design, assets, path, width: int, height: int, progress=None,
                  denoise: bool = False) -> list[str]:
    """Render ``design`` with the tracer to its noise target and save it as PNG at ``path``;
    with ``denoise`` the PNG at ``path`` is the denoised estimate and the raw render goes beside
    it (``poster.raw.png``), each saying which it is (:func:`engine.finals.write_final`).
    Returns the paths written, the raw one first."""
    from ..finals import write_final
    from ..tracer.job import RenderJob
    from ..tracer.job_options import Workers
    job = RenderJob(design, assets, width=width, height=height, workers=Workers(tile=32))
    job.start()
    while not job.wait(0.25):
        if progress:
            progress(job.progress, f"rendering the poster {width}x{height}")
    if job.error is not None:
        raise job.error
    return write_final(job, design, assets, path, denoise=denoise)


def skybox_png(design, assets, width: int = 1024) -> bytes:
    """The design's environment (scale and turn included) as an sRGB equirectangular PNG in
    the viewer's convention (glTF's +Y up; three.js's ``u = atan2(z, x) / 2 pi + 1/2``, top row
    up), so the glass in the page refracts and reflects what the tracer's glass does."""
    import io

    import numpy as np
    from PIL import Image

    from ..color import tonemap_srgb8
    from ..tracer.tables.environment import environment_from_design
    env = environment_from_design(design.environment, assets)
    h = width // 2
    az = ((np.arange(width) + 0.5) / width - 0.5) * 2 * np.pi
    el = (0.5 - (np.arange(h) + 0.5) / h) * np.pi
    az, el = np.meshgrid(az, el)
    gx, gy, gz = np.cos(az) * np.cos(el), np.sin(el), np.sin(az) * np.cos(el)
    d = np.stack([gx, -gz, gy], -1).reshape(-1, 3)  # glTF (x, y, z) -> design (x, -z, y)
    rgb = tonemap_srgb8(env.lookup(d).reshape(h, width, 3))
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb), "RGB").save(buf, "PNG")
    return buf.getvalue()


def glass_film(design) -> list[float]:
    """The viewer's stand-in colour of the glass (linear RGBA): what two walls let through,
    at a fifth coverage."""
    from ..model.tint import transmittance
    return [*transmittance(design.glass.absorption, 2.0 * design.shape.wall_thickness), 0.2]


def camera_attributes(design) -> str:
    """``<model-viewer>`` attributes putting its orbit camera where the design's camera is."""
    import math

    from .gltf_build import to_gltf
    eye, target = to_gltf(design.camera.eye), to_gltf(design.camera.target)
    d = eye - target
    r = float(math.sqrt(d @ d))
    theta, phi = math.atan2(d[0], d[2]), math.acos(max(-1.0, min(1.0, d[1] / r)))
    x, y, z = (float(v) for v in target)
    return (f'camera-orbit="{theta:.6f}rad {phi:.6f}rad {r:.6f}m" '
            f'camera-target="{x:.6f}m {y:.6f}m {z:.6f}m" field-of-view="{design.camera.fov_y_deg:g}deg" '
            f'min-camera-orbit="auto auto {0.2 * r:.6f}m" max-camera-orbit="auto auto {5 * r:.6f}m"')


def turntable_frames(folder) -> list[Path]:
    """The frames ``frame_NNNN.png|jpg`` of a rendered turntable, in order (a denoised
    turntable's raw frames beside them, ``frame_NNNN.raw.png``, are not frames of the
    flip-book); ``ShareError`` if there are none or too many."""
    folder = Path(folder)
    frames = sorted(p for p in folder.glob("frame_*") if p.suffix.lower() in (".png", ".jpg", ".jpeg")
                    and not p.stem.lower().endswith(".raw"))
    if not frames:
        raise ShareError(f"{folder} holds no turntable frames (frame_0000.png ...)")
    if len(frames) > MAX_TURNTABLE_FRAMES:
        raise ShareError(f"{folder} holds {len(frames)} frames; a page takes {MAX_TURNTABLE_FRAMES}")
    return frames


def frames_denoised(frames) -> bool:
    """Whether a turntable's frames say they are denoised estimates (their first frame's
    ``ImageDescription``, as ``glassbench turntable --denoise`` writes it)."""
    from ..files.images import image_description
    try:
        return bool(frames) and image_description(frames[0]).startswith(DENOISED_NOTE.split("{")[0])
    except OSError:
        return False


def dieline_key(design, label) -> tuple:
    """What a label's flat shape depends on: its surface and size, and where it sits on a wall
    (height; also the azimuth on a non-round one). Labels with one key share one die-line."""
    key = (label.surface, label.height_mm, label.width_mm)
    if label.surface == "wall":
        key += (label.z_mm,) if design.shape.xs.revolved else (label.z_mm, label.angle_deg)
    return key


def dieline_files(design, folder: Path) -> list[tuple[str, list[int]]]:
    """Write one die-line per distinct flat shape (:func:`dieline_key`) as
    ``dielines/NNNN.svg``; ``[(name written, [label indices]), ...]``."""
    from ..appearance.dieline_files import write_dieline
    from ..appearance.report import label_report
    groups: dict[tuple, list[int]] = {}
    for k, label in enumerate(design.labels):
        groups.setdefault(dieline_key(design, label), []).append(k)
    out = []
    for g, members in enumerate(groups.values()):
        (folder / "dielines").mkdir(exist_ok=True)
        name = f"dielines/{g:04d}.svg"
        write_dieline(label_report(design, members[0]), folder / name, design.name)
        out.append((name, members))
    return out


def _names(design, members) -> str:
    names = ", ".join(html.escape(design.labels[k].name) for k in members[:3])
    return names + (f" and {len(members) - 3} more" if len(members) > 3 else "")


def _value_text(key: str, value, unit: str) -> str:
    return "\u2013" if value is None else f"{value:.1f} {unit}"


def numbers_table(numbers: dict) -> str:
    """The HTML table of the trade numbers; each value cell carries the exact number."""
    rows = []
    for key, label, unit in INFO_ROWS:
        v = numbers.get(key)
        exact = "null" if v is None else json.dumps(v)
        rows.append(f'<tr><th>{html.escape(label)}</th><td data-key="{key}" data-value="{exact}">'
                    f"{_value_text(key, v, unit)}</td></tr>")
    closure = numbers.get("closure")
    if closure:
        rows.append(f"<tr><th>Closure</th><td>{html.escape(closure['kind'])}, "
                    f"{closure['diameter_mm']:.1f} mm across, {closure['height_mm']:.1f} mm high</td></tr>")
    return "<table class=\"numbers\">" + "".join(rows) + "</table>"


def plant_table(plant: dict | None) -> str:
    """The plant's headline figures as an HTML table (the whole set is in ``numbers.json``)."""
    if not plant:
        return ""
    rows = []
    least = plant.get("least_tip")
    if least:
        rows.append(("Least tip angle", f"{least['deg']:.1f}\u00b0 ({least['state']})"))
    band = plant.get("capacity_band")
    if band:
        rows.append(("Nominal capacity", f"{band['nominal_ml']:.1f} \u00b1 {band['tolerance_ml']:.1f} ml"))
        if band.get("fill_height_min_mm") is not None and band.get("fill_height_max_mm") is not None:
            rows.append(("Fill height within tolerance",
                         f"{band['fill_height_min_mm']:.1f} \u2013 {band['fill_height_max_mm']:.1f} mm"))
    stress = plant.get("stress") or {}
    if stress.get("max_mpa") is not None:
        rows.append((f"Membrane stress at {stress['pressure_mpa']:.2f} MPa", f"{stress['max_mpa']:.2f} MPa"))
    rows += [("Warning", w) for w in plant.get("warnings") or ()]
    body = "".join(f"<tr><th>{html.escape(a)}</th><td>{html.escape(b)}</td></tr>" for a, b in rows)
    return f"<h2>The plant's figures</h2><table class=\"numbers\">{body}</table>"


def poster_caption(denoised: bool) -> str:
    """What the page says under its rendered poster: nothing for the raw render; for a denoised
    one, that it is an estimate, and a link to the raw render beside it."""
    if not denoised:
        return ""
    return ('<p class="caption">A denoised estimate (Intel Open Image Denoise); the raw render: '
            f'<a href="{RAW_POSTER}">{RAW_POSTER}</a></p>')


def page_html(design, numbers: dict, dielines: list, frames: list[str], denoised: bool = False,
              denoised_frames: bool = False) -> str:
    """``index.html`` (see the module rule); ``denoised``: the poster is a denoised estimate,
    ``denoised_frames``: so are the turntable's frames."""
    name = html.escape(design.name)
    data = json.dumps(numbers, indent=2, allow_nan=False).replace("</", "<\\/")
    dl = "".join(f'<li><a href="{d}">{_names(design, members)}</a> (SVG, 1:1)</li>'
                 for d, members in dielines) or "<li>No labels.</li>"
    turn = ""
    if frames:
        note = ('<p class="caption">Denoised frames (Intel Open Image Denoise); the raw frames stay '
                'with the rendered turntable.</p>') if denoised_frames else ""
        turn = (f'<h2>Turntable</h2><img id="turntable" src="{frames[0]}" alt="turntable frame">{note}'
                f'<input id="turn" type="range" min="0" max="{len(frames) - 1}" value="0">'
                f'<script>const frames = {json.dumps(frames)};'
                "document.getElementById('turn').addEventListener('input', (e) => {"
                "document.getElementById('turntable').src = frames[e.target.value]; });</script>")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{name} - glassbench review</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 0; color: #222; background: #f4f3f0; }}
main {{ display: grid; grid-template-columns: minmax(300px, 2fr) minmax(260px, 1fr); gap: 1.5em; padding: 1.5em; }}
model-viewer {{ width: 100%; height: 70vh; background: #fff; border-radius: 8px; }}
h1 {{ margin: 0.6em 1em 0; font-weight: 600; }} h2 {{ font-size: 1.05em; margin: 1.2em 0 0.4em; }}
table.numbers th {{ text-align: left; font-weight: normal; padding-right: 1.5em; color: #555; }}
table.numbers td {{ text-align: right; font-variant-numeric: tabular-nums; }}
img {{ max-width: 100%; border-radius: 6px; }} input[type=range] {{ width: 100%; }}
p.caption {{ font-size: 0.85em; color: #555; margin: 0.3em 0 0; }}
</style>
<script src="model-viewer-umd.min.js"></script>
<script src="scene-data.js"></script>
</head><body>
<h1>{name}</h1>
<main>
<section>
<model-viewer id="viewer" alt="{name}: the bottle in 3D" poster="poster.png" camera-controls
  touch-action="pan-y" interaction-prompt="none" exposure="1" {camera_attributes(design)}></model-viewer>
<p><a href="scene.glb" download>Download the scene (glTF, .glb)</a></p>
{turn}
</section>
<aside>
<h2>Rendered by glassbench</h2><img src="poster.png" alt="{name}, rendered{' (denoised)' if denoised else ''}">
{poster_caption(denoised)}
<h2>Trade numbers</h2>{numbers_table(numbers)}
{plant_table(numbers.get("plant"))}
<h2>Label die-lines</h2><ul>{dl}</ul>
</aside>
</main>
<script type="application/json" id="numbers-json">{data}</script>
<script>
const bytes = Uint8Array.from(atob(window.GLASSBENCH_SCENE_B64), (c) => c.charCodeAt(0));
const viewer = document.getElementById('viewer');
viewer.skyboxImage = window.GLASSBENCH_SKYBOX;
// three.js does not show one transmitting object through another: in the viewer (not in the
// file) the glass is drawn as a tinted film, so the liquid behind it shows.
viewer.addEventListener('load', () => {{
  for (const m of viewer.model.materials) {{
    if (m.name !== 'glass') continue;
    m.setTransmissionFactor(0);
    m.setAlphaMode('BLEND');
    m.pbrMetallicRoughness.setBaseColorFactor({glass_film(design)});
  }}
}});
viewer.src = URL.createObjectURL(new Blob([bytes], {{ type: 'model/gltf-binary' }}));
</script>
</body></html>
"""


def write_share(design, assets, out_dir, tol_mm: float = 0.05, poster_height: int | None = None,
                turntable=None, progress=None, denoise: bool = False) -> Path:
    """Write the review page of ``design`` into the folder ``out_dir`` (see the module rule).

    ``tol_mm`` is the scene's chordal tolerance (mm), ``poster_height`` the poster's height
    (pixels), ``turntable`` a folder of rendered frames or ``None``; with ``denoise`` the poster
    is denoised, the raw render is kept beside it as ``poster.raw.png`` and the page says so
    under the poster, with a link to the raw one. Returns the folder.
    Raises ``ShareError`` for a folder that is not a review page, ``WebError`` without the
    Node packages, and the exports' own errors; nothing is left half written.
    """
    step = progress or (lambda f, m: None)
    out = Path(out_dir).resolve()
    if out.exists() and (not out.is_dir() or (any(out.iterdir()) and not (out / MARKER).exists())):
        raise ShareError(f"{out} exists and is not a glassbench review page; choose a new folder")
    mv = model_viewer_js()
    frames = turntable_frames(turntable) if turntable is not None else []
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.parent / f".{out.name}.{os.getpid()}-{secrets.token_hex(4)}.tmp"
    tmp.mkdir()
    try:
        step(0.02, "trade numbers")
        numbers = {**trade_numbers(design), "plant": plant_numbers(design)}
        step(0.05, "scene")
        glb, _ = scene_glb(design, assets, tol_mm, lambda f, m: step(0.05 + 0.2 * f, m))
        (tmp / "scene.glb").write_bytes(glb)
        sky = skybox_png(design, assets)
        (tmp / "environment.png").write_bytes(sky)
        (tmp / "scene-data.js").write_text(
            "window.GLASSBENCH_SCENE_B64 = \"" + base64.b64encode(glb).decode("ascii") + "\";\n"
            "window.GLASSBENCH_SKYBOX = \"data:image/png;base64," + base64.b64encode(sky).decode("ascii")
            + "\";\n")
        shutil.copyfile(mv, tmp / "model-viewer-umd.min.js")
        (tmp / "numbers.json").write_text(json.dumps(numbers, indent=2, allow_nan=False) + "\n")
        dielines = dieline_files(design, tmp)
        names = []
        for k, f in enumerate(frames):
            (tmp / "turntable").mkdir(exist_ok=True)
            names.append(f"turntable/{k:04d}{f.suffix.lower()}")
            shutil.copyfile(f, tmp / names[-1])
        w, h = poster_size(design, poster_height)
        render_poster(design, assets, tmp / "poster.png", w, h,
                      lambda f, m: step(0.3 + 0.65 * f, m), denoise=denoise)
        page = page_html(design, numbers, dielines, names, denoise, frames_denoised(frames))
        (tmp / "index.html").write_text(page, encoding="utf-8")
        (tmp / MARKER).write_text("written by glassbench share\n")
        _swap_in(tmp, out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    step(1.0, "done")
    return out


def _swap_in(new: Path, out: Path) -> None:
    """Put the finished folder ``new`` at ``out``; an old review page there goes only after."""
    old = None
    if out.exists():
        old = out.parent / f".{out.name}.old-{secrets.token_hex(4)}"
        os.replace(out, old)
    try:
        os.replace(new, out)
    except OSError:
        if old is not None:
            os.replace(old, out)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
