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
from typing import Mapping

from ..limits import ASSET_NAME, DEFAULT_LIMITS, Limits, check_assets  # noqa: F401 - the archive's bounds
from ..model.design import Design
from ..operations.check import check_design
from ..errors import InputFileError, ProjectError
from ..io.read import read_bounded
from ..io import atomic
from . import jsontext
from .serialize import design_from_document, design_to_dict, document_from_design

SUFFIX = ".glassbench"
PROJECT_MEMBER = "project.json"
ASSET_DIR = "assets/"
GENERATOR = "glassbench 0.1.0"


def save_project(path: str | os.PathLike, design: Design,
                 assets: Mapping[str, bytes] | None = None, keep_backup: bool = True) -> None:
    """Write ``design`` and ``assets`` to ``path`` atomically (:mod:`engine.io.atomic`).

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
        blob = read_bounded(path, limits.archive_bytes, "project")
    except OSError as exc:
        raise ProjectError(f"cannot open {path}: {exc.strerror or exc}") from None
    except InputFileError as exc:
        raise ProjectError(f"{exc}: not a project") from None
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


