"""The ``.glassbench`` project file: a zip archive of ``project.json`` plus ``assets/NAME``.

Design rule: loading is all-or-nothing and trusts nothing. Every problem with a file (not a
zip, hostile member names, bombs, wrong JSON types, NaN, unknown versions, invalid geometry)
becomes one :class:`engine.errors.ProjectError` naming it; nothing is half-loaded. Saving is
atomic: a temporary file in the same folder, fsync, ``os.replace``; the previous file is
kept as ``NAME.glassbench.bak``.

``project.json`` (format 2, current)::

    {"format_version": 2, "generator": "glassbench 0.1.0",
     "design": {... engine.files.serialize.design_to_dict ...}}

Older formats (format 1 with placeholder labels, bump tiles and cap: :mod:`engine.files.migrate_labels`,
:mod:`engine.files.migrate_finishes`; format 0 the prototype layout, documented in
:mod:`engine.files.serialize`) are migrated step by step to the current one before the design
is read.
"""
from __future__ import annotations

import io
import json
import os
import re
import stat
import struct
import zipfile
import zlib
from dataclasses import dataclass
from typing import Mapping

from ..appearance.finish_check import check_finishes
from ..appearance.placement import check_label_placement
from ..geometry.validate import body_profile
from ..model.check import check_values
from ..model.design import Design
from ..model.fill import check_fill
from ..errors import GlassbenchError, ProjectError, shown
from . import atomic, jsontext
from .serialize import design_from_document, design_to_dict, document_from_design

SUFFIX = ".glassbench"
PROJECT_MEMBER = "project.json"
ASSET_DIR = "assets/"
GENERATOR = "glassbench 0.1.0"
#: Asset names: plain file names (spaces and non-ASCII letters allowed) of at most 128
#: characters: no folder separators, colons or control characters, no leading dot.
ASSET_NAME = re.compile(r"^[^/\\:.\x00-\x1f\x7f][^/\\:\x00-\x1f\x7f]{0,127}\Z")


@dataclass(frozen=True)
class Limits:
    """Size limits of a project archive (bytes unless named otherwise), applied when it is
    written and when it is read; the design's own limits are in :mod:`engine.limits`.

    ``archive_bytes`` the file; ``members`` entries in it; ``json_bytes`` ``project.json``;
    ``asset_bytes`` one asset; ``total_bytes`` everything unpacked; ``json_depth`` nesting of
    ``project.json``; ``unpack_ratio``: beyond ``json_bytes``, the members may unpack to at most
    this many times the archive's size (a small file cannot claim much memory).
    """

    archive_bytes: int = 512 << 20
    members: int = 256
    json_bytes: int = 16 << 20
    asset_bytes: int = 256 << 20
    total_bytes: int = 512 << 20
    json_depth: int = 64
    unpack_ratio: int = 100


DEFAULT_LIMITS = Limits()


def save_project(path: str | os.PathLike, design: Design,
                 assets: Mapping[str, bytes] | None = None, keep_backup: bool = True) -> None:
    """Write ``design`` and ``assets`` to ``path`` atomically (:mod:`engine.files.atomic`).

    With ``keep_backup`` the file it replaces is kept as ``path.bak`` (``NAME.glassbench.bak``)
    with that file's permission bits; a symbolic link at ``path`` is followed and stays a link;
    temporaries left by killed saves of the same file are removed.

    Raises ``ProjectError`` for a design that :func:`load_project` would refuse (the same
    :func:`check_design`, the same limits, and the written ``project.json`` is read back through
    the loader's own path before anything touches the disk) or a failed write; on failure the
    previous file is untouched.
    """
    assets = dict(assets or {})
    limits = DEFAULT_LIMITS
    check_design(design, assets)
    payload = _project_json(design, limits)
    if len(payload) + sum(len(d) for d in assets.values()) > limits.total_bytes:
        raise ProjectError(f"the project would unpack to more than {limits.total_bytes} bytes")
    try:
        with atomic.replacing(path, backup=keep_backup) as tmp:
            with open(tmp, "wb") as fh, zipfile.ZipFile(fh, "w", compression=zipfile.ZIP_DEFLATED) as zf:
                zf.writestr(_member(PROJECT_MEMBER), payload)
                for name in sorted(assets):
                    zf.writestr(_member(ASSET_DIR + name), bytes(assets[name]))
    except OSError as exc:
        raise ProjectError(f"cannot write {os.fspath(path)}: {exc.strerror or exc}") from None


def _project_json(design: Design, limits: Limits) -> bytes:
    """``project.json`` for ``design``, proven to read back as ``design`` by the loader's path."""
    doc = document_from_design(design, GENERATOR)
    try:
        payload = json.dumps(doc, indent=1, allow_nan=False, ensure_ascii=False).encode("utf-8")
    except (ValueError, UnicodeEncodeError) as exc:  # NaN (caught earlier) or lone surrogates
        raise ProjectError(f"cannot write the project: {exc}") from None
    if len(payload) > limits.json_bytes:
        raise ProjectError(f"{PROJECT_MEMBER} would be {len(payload)} bytes (limit {limits.json_bytes})")
    # Never write a file that cannot be opened again: read it back as the loader does.
    if design_to_dict(design_from_document(parse_json(payload, limits))) != doc["design"]:
        raise ProjectError("the design does not survive being written (a value cannot be stored exactly)")
    return payload


def _member(name: str) -> zipfile.ZipInfo:
    # A fixed time stamp makes saving the same project twice give the same bytes.
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    return info


def load_project(path: str | os.PathLike, limits: Limits = DEFAULT_LIMITS
                 ) -> tuple[Design, dict[str, bytes]]:
    """Read a project: returns ``(design, assets)``; raises ``ProjectError`` for any problem.

    The design's geometry is validated (:func:`engine.geometry.validate.validate_shape`) and an
    environment or label naming a missing asset is rejected.
    """
    path = os.fspath(path)
    try:
        size = os.path.getsize(path)
    except OSError as exc:
        raise ProjectError(f"cannot open {path}: {exc.strerror or exc}") from None
    if size > limits.archive_bytes:
        raise ProjectError(f"{path} is {size} bytes, larger than any project should be")
    try:
        with open(path, "rb") as fh:
            blob = fh.read(size + 1)  # not archive_bytes: read(n) allocates n bytes at once
    except OSError as exc:
        raise ProjectError(f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        return load_project_bytes(blob, limits)
    except ProjectError as exc:
        raise ProjectError(f"{os.path.basename(path)}: {exc}") from None


def load_project_bytes(blob: bytes, limits: Limits = DEFAULT_LIMITS
                       ) -> tuple[Design, dict[str, bytes]]:
    """Like :func:`load_project` for the archive's bytes in memory."""
    members = _read_members(blob, limits)
    text = members.pop(PROJECT_MEMBER, None)
    if text is None:
        raise ProjectError(f"not a glassbench project: the archive has no {PROJECT_MEMBER}")
    design = design_from_document(parse_json(text, limits))
    assets = {name[len(ASSET_DIR):]: data for name, data in members.items()}
    check_design(design, assets)
    return design, assets


# Everything the standard zip reader may raise on a damaged or hostile archive.
_ZIP_ERRORS = (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, OSError, ValueError,
               NotImplementedError, RuntimeError, struct.error, IndexError, KeyError,
               OverflowError, TypeError, UnicodeDecodeError)


def _read_members(blob: bytes, limits: Limits) -> dict[str, bytes]:
    """Check every member's name and declared size, then read each one once, no further than
    it declares (so memory stays within the declared total, itself bounded)."""
    _check_declared_directory(blob, limits)
    try:
        zf = zipfile.ZipFile(io.BytesIO(blob))
        infos = zf.infolist()
    except _ZIP_ERRORS as exc:
        raise ProjectError(f"not a glassbench project (not a readable zip archive: {exc})") from None
    with zf:
        if len(infos) > limits.members:
            raise ProjectError(f"the archive has {len(infos)} members (limit {limits.members})")
        seen: set[str] = set()
        files = []
        declared_total = 0
        for info in infos:
            name = _checked_member_name(info)
            if name in seen:
                raise ProjectError(f"the archive holds {name!r} twice")
            seen.add(name)
            if name.endswith("/"):
                continue
            if info.flag_bits & 0x1:
                raise ProjectError(f"member {name!r} is encrypted")
            if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
                raise ProjectError(f"member {name!r} uses an unsupported compression method")
            cap = limits.json_bytes if name == PROJECT_MEMBER else limits.asset_bytes
            if info.file_size > cap:
                raise ProjectError(f"member {name!r} declares {info.file_size} bytes (limit {cap})")
            declared_total += info.file_size
            if declared_total > _unpack_budget(len(blob), limits):
                raise ProjectError(f"the archive of {len(blob)} bytes declares more than "
                                   f"{_unpack_budget(len(blob), limits)} bytes in all")
            files.append((info, name))
        return {name: _read_member(zf, info, name) for info, name in files}


def _unpack_budget(archive_size: int, limits: Limits) -> int:
    """Most bytes the members of an archive of ``archive_size`` bytes may unpack to."""
    return min(limits.total_bytes, limits.json_bytes + limits.unpack_ratio * archive_size)


def _check_declared_directory(blob: bytes, limits: Limits) -> None:
    """Refuse an archive whose end record declares too many members or too big a directory,
    before the zip reader spends time and memory parsing it."""
    # The end-of-central-directory record sits in the last 22 + 65535 (comment) bytes.
    at = blob.rfind(b"PK\x05\x06", max(0, len(blob) - 22 - 0xFFFF))
    if at < 0 or at + 22 > len(blob):
        return  # not a zip: the reader will say so
    entries, dir_size = struct.unpack_from("<HI", blob, at + 10)
    if entries == 0xFFFF or dir_size == 0xFFFFFFFF:
        raise ProjectError("ZIP64 archives are not glassbench projects (far too large)")
    if entries > limits.members:
        raise ProjectError(f"the archive has {entries} members (limit {limits.members})")
    if dir_size > limits.members * 4096:
        raise ProjectError(f"the archive's directory is {dir_size} bytes, larger than any project's")


def _read_member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, name: str) -> bytes:
    """The member's bytes, read in one piece and never past its declared size (+1 byte, to
    catch a member that lies about its size: a zip bomb)."""
    try:
        with zf.open(info) as fh:
            data = fh.read(info.file_size + 1)
    except _ZIP_ERRORS as exc:
        raise ProjectError(f"member {name!r} is damaged: {exc}") from None
    if len(data) > info.file_size:
        raise ProjectError(f"member {name!r} unpacks to more than the {info.file_size} bytes it declares")
    if len(data) < info.file_size:
        raise ProjectError(f"member {name!r} unpacks to {len(data)} bytes, "
                           f"not the {info.file_size} it declares")
    return data


def _checked_member_name(info: zipfile.ZipInfo) -> str:
    """The member's name if it is one a project may hold; ``ProjectError`` otherwise."""
    raw = info.orig_filename
    shown = repr(raw[:80])
    if "\x00" in raw or raw != info.filename:
        raise ProjectError(f"member name {shown} contains a NUL character")
    if "\\" in raw:
        raise ProjectError(f"member name {shown} contains a backslash")
    if raw.startswith("/") or re.match(r"^[A-Za-z]:", raw):
        raise ProjectError(f"member name {shown} is an absolute path")
    if ".." in raw.split("/"):
        raise ProjectError(f"member name {shown} escapes the project folder")
    if stat.S_ISLNK(info.external_attr >> 16):
        raise ProjectError(f"member {shown} is a symbolic link")
    if raw in (PROJECT_MEMBER, ASSET_DIR):
        return raw
    if raw.startswith(ASSET_DIR) and ASSET_NAME.match(raw[len(ASSET_DIR):]):
        return raw
    raise ProjectError(f"unexpected member {shown} in the archive")


def parse_json(raw: bytes, limits: Limits = DEFAULT_LIMITS) -> object:
    """Decode UTF-8 JSON strictly: no NaN/Infinity, nesting at most ``limits.json_depth``
    (:func:`engine.files.jsontext.parse_json`, linear in the text); ``ProjectError`` otherwise."""
    return jsontext.parse_json(raw, limits.json_depth)


def check_design(design: Design, assets: Mapping[str, bytes]) -> None:
    """Check what the value types cannot: ranges, sizes, asset references, geometry, fill level.

    The same check runs before a project is written and after it is read. In order: the
    values (:func:`engine.model.check.check_values`, the limits of :mod:`engine.limits`), the
    assets (:func:`check_assets`) and those named by the environment and labels, the geometry
    (:func:`engine.geometry.validate.validate_shape`), the liquid level
    (:func:`engine.model.fill.check_fill`), the labels on the wall
    (:func:`engine.appearance.placement.check_label_placement`; artwork images are checked
    when they are imported and decoded, :mod:`engine.appearance.images`), the relief images
    and the closure's fit (:func:`engine.appearance.finish_check.check_finishes`). Raises
    ``ProjectError`` (a ``DesignError`` for a value); ``SectionError`` / ``WallError`` from
    validation are wrapped with their message kept.
    """
    check_values(design)
    check_assets(assets)
    refs = [("environment", design.environment.asset)] + [
        (f"labels[{i}]", name) for i, lab in enumerate(design.labels) for name in lab.asset_names()]
    for where, name in refs:
        if name is not None and name not in assets:
            raise ProjectError(f"design.{where} names asset {shown(name)}, which the project lacks")
    validate_design_shape(design)
    check_fill(design.shape, design.liquid)
    check_label_placement(design)
    check_finishes(design, assets)


def check_assets(assets: Mapping[str, bytes], limits: Limits = DEFAULT_LIMITS) -> None:
    """Raise ``ProjectError`` unless ``assets`` could be stored: at most ``limits.members - 1``
    of them, plain file names (:data:`ASSET_NAME`), bytes of at most ``limits.asset_bytes``."""
    if len(assets) >= limits.members:
        raise ProjectError(f"a project holds at most {limits.members - 1} assets")
    for name, data in assets.items():
        if not isinstance(name, str) or not ASSET_NAME.match(name):
            raise ProjectError(f"asset name {shown(name)} is not a plain file name")
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise ProjectError(f"asset {shown(name)} must be bytes, got {type(data).__name__}")
        if len(data) > limits.asset_bytes:
            raise ProjectError(f"asset {shown(name)} is larger than {limits.asset_bytes} bytes")


def validate_design_shape(design: Design) -> None:
    """Run :func:`engine.geometry.validate.validate_shape` (through the cached
    :func:`~engine.geometry.validate.body_profile`), wrapping its errors in ``ProjectError``."""
    try:
        body_profile(design.shape)  # validates; the profile is kept for the fill check
    except GlassbenchError as exc:
        raise ProjectError(f"invalid bottle shape: {exc}") from None
    except (ValueError, ArithmeticError) as exc:
        raise ProjectError(f"invalid bottle shape: {exc}") from None
