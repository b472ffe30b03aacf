"""The Node side of the exports: where the setup script put the packages, and running them.

Design rule: Node packages are files, not Python dependencies: ``scripts/setup.sh`` installs
them into ``web/node_modules`` from the pinned ``web/package.json`` and ``package-lock.json``
(``npm ci``), and this module only finds them (``GLASSBENCH_WEB`` names another folder holding
a ``node_modules``) and runs the two small scripts beside them: ``validate_gltf.mjs`` (the
Khronos glTF validator) and ``check_page.mjs`` (a review page opened in Debian's chromium by
``playwright-core``). A missing package is a one-line :class:`WebError` that says how to install
it, never a traceback.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

from ..errors import GlassbenchError

#: The self-contained <model-viewer> build (UMD: a classic script, which browsers also run from
#: file://, where module scripts are refused), relative to ``node_modules``.
MODEL_VIEWER_JS = "@google/model-viewer/dist/model-viewer-umd.min.js"
#: Debian's chromium, the browser the page is checked in.
CHROMIUM = "/usr/bin/chromium"
#: Longest a validator or browser run may take (s).
NODE_TIMEOUT_S = 180


class WebError(GlassbenchError, OSError):
    """A Node package, node itself or chromium is missing, or a Node script failed."""


def web_dir() -> Path:
    """The folder holding ``package.json``, the scripts and ``node_modules``."""
    return Path(os.environ.get("GLASSBENCH_WEB") or Path(__file__).resolve().parents[2] / "web")


def node_module(relpath: str) -> Path:
    """The file ``relpath`` inside ``node_modules``; ``WebError`` if it is not installed."""
    path = web_dir() / "node_modules" / relpath
    if not path.is_file():
        raise WebError(f"{relpath.split('/dist/')[0]} is not installed in {web_dir()}/node_modules: "
                       "run bash scripts/setup.sh")
    return path


def model_viewer_js() -> Path:
    """The <model-viewer> script the review page copies (:data:`MODEL_VIEWER_JS`)."""
    return node_module(MODEL_VIEWER_JS)


def _node(script: str, *args: str) -> dict:
    node = shutil.which("node")
    if node is None:
        raise WebError("node is not installed: run bash scripts/setup.sh")
    done = subprocess.run([node, str(web_dir() / script), *args], capture_output=True, text=True,
                          timeout=NODE_TIMEOUT_S, cwd=web_dir())
    if done.returncode != 0:
        raise WebError(f"{script} failed: {done.stderr.strip()[-300:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def validate_glb(path) -> dict:
    """The Khronos validator's report on a GLB file: ``errors``, ``warnings``, ``infos``,
    ``hints`` (counts), ``messages`` (the errors' and warnings' entries) and ``info``."""
    node_module("gltf-validator/index.js")
    return _node("validate_gltf.mjs", str(Path(path).resolve()))


def check_page(index_html, screenshot, chromium: str = CHROMIUM) -> dict:
    """Open a review page from disk in headless chromium and report what it did
    (``console_errors``, ``page_errors``, ``failed_requests``, ``loaded``, ``numbers``,
    ``shown``) after writing a full-page screenshot to ``screenshot`` (PNG) and one of the
    viewer alone beside it (``NAME-viewer.png``)."""
    node_module("playwright-core/package.json")
    if not Path(chromium).is_file():
        raise WebError(f"{chromium} is not installed: run bash scripts/setup.sh")
    return _node("check_page.mjs", str(Path(index_html).resolve()), str(Path(screenshot).resolve()),
                 chromium)
