"""The batch manifest: which frames are done, keyed by a content hash of their inputs.

Design rule: a frame is skipped on a re-run only if the manifest holds the same input hash for
its file and the file on disk still has the recorded SHA-256, so a changed override, project,
asset, size or format renders again, and a damaged or deleted image is made anew. The input
hash covers everything a pixel depends on: the frame's design as the project file stores it
(camera and render settings included), the SHA-256 of every asset, the format, alpha, denoise,
and the renderer version. A denoised frame's raw image beside it (``NAME.raw.EXT``) is
checked the same way: its SHA-256 is recorded with the frame's. ``manifest.json`` in the output folder is rewritten atomically after every
finished frame, so an interrupted batch keeps all it finished.
"""
from __future__ import annotations

import hashlib
import json
import os

from ..files.images import write_bytes

MANIFEST_NAME = "manifest.json"
MANIFEST_VERSION = 1
#: Part of every input hash: bump it when the tracer changes what a pixel becomes.
RENDERER = "glassbench 0.1.0 tracer"


def asset_digests(assets) -> dict:
    """SHA-256 (hex) of each asset's bytes, by name (computed once per variant, not per frame)."""
    return {name: hashlib.sha256(bytes(data)).hexdigest() for name, data in sorted(assets.items())}


def frame_hash(design, digests: dict, fmt: str, alpha: bool, denoise: bool = False) -> str:
    """SHA-256 (hex) of one frame's inputs: design, asset digests (:func:`asset_digests`),
    format, alpha, denoise and renderer. ``denoise`` enters the hashed document only when true,
    so a frame without it hashes as it did before the option existed (manifests stay valid)."""
    from ..files.serialize import design_to_dict
    doc = {"renderer": RENDERER, "format": fmt, "alpha": bool(alpha),
           "design": design_to_dict(design), "assets": digests}
    if denoise:
        doc["denoise"] = True
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def file_sha256(path: str) -> str | None:
    """SHA-256 (hex) of a file's bytes, ``None`` if it cannot be read."""
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
    except OSError:
        return None
    return h.hexdigest()


class Manifest:
    """``OUTPUT/manifest.json``: ``{"version": 1, "frames": {relpath: {"inputs", "sha256", ...}}}``.

    An unreadable or foreign manifest is treated as empty (everything renders again) and is
    replaced on the first finished frame; it is never a reason to stop.
    """

    def __init__(self, folder: str):
        self.folder = folder
        self.path = os.path.join(folder, MANIFEST_NAME)
        self.frames: dict = {}
        try:
            with open(self.path, encoding="utf-8") as fh:
                doc = json.load(fh)
            if (isinstance(doc, dict) and doc.get("version") == MANIFEST_VERSION
                    and isinstance(doc.get("frames"), dict)):
                self.frames = {k: v for k, v in doc["frames"].items() if isinstance(v, dict)}
        except (OSError, ValueError):
            self.frames = {}

    def is_done(self, relpath: str, inputs: str) -> bool:
        """Whether ``relpath`` was made from ``inputs`` and is still on disk unchanged, and so
        is every file recorded beside it."""
        entry = self.frames.get(relpath)
        if not entry or entry.get("inputs") != inputs:
            return False
        files = {relpath: entry.get("sha256")}
        beside = entry.get("beside")
        if beside is not None and not isinstance(beside, dict):
            return False
        files.update(beside or {})
        return all(file_sha256(os.path.join(self.folder, p)) == sha for p, sha in files.items())

    def record(self, relpath: str, inputs: str, beside=(), **info) -> None:
        """Note a finished frame (its file, and the files ``beside`` it, relative paths, must
        already be in place) and save the manifest."""
        sha = file_sha256(os.path.join(self.folder, relpath))
        entry = {"inputs": inputs, "sha256": sha, **info}
        if beside:
            entry["beside"] = {p: file_sha256(os.path.join(self.folder, p)) for p in beside}
        self.frames[relpath] = entry
        self.save()

    def save(self) -> None:
        doc = {"version": MANIFEST_VERSION, "frames": dict(sorted(self.frames.items()))}
        write_bytes(self.path, json.dumps(doc, indent=1).encode("utf-8"))
