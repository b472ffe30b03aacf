"""The ``.glassbench`` project file: a zip archive of ``project.json`` plus ``assets/NAME``.

Design rule: loading is all-or-nothing and trusts nothing. Every problem with a file (not a
zip, hostile member names, bombs, wrong JSON types, NaN, unknown versions, invalid geometry)
becomes one :class:`engine.errors.ProjectError` naming it; nothing is half-loaded. Saving is
atomic: a temporary file in the same folder, fsync, ``os.replace``; the previous file is
kept as ``NAME.glassbench.bak``.

``project.json`` (format 1, current)::

    {"format_version": 1, "generator": "glassbench 0.1.0",
     "design": {... engine.files.serialize.design_to_dict ...}}

Older formats (format 0, the prototype layout documented in :mod:`engine.files.serialize`) are
migrated step by step to the current one before the design is read.
"""
from __future__ import annotations

import io
import json
import os
import re
import shutil
import stat
import struct
import tempfile
import zipfile
import zlib
from dataclasses import dataclass
from typing import Mapping

from ..model.design import Design
from ..errors import GlassbenchError, ProjectError
from .serialize import design_from_document, document_from_design

SUFFIX = ".glassbench"
PROJECT_MEMBER = "project.json"
ASSET_DIR = "assets/"
GENERATOR = "glassbench 0.1.0"
#: Asset names: plain file names (spaces and non-ASCII letters allowed) of at most 128
#: characters: no folder separators, colons or control characters, no leading dot.
ASSET_NAME = re.compile(r"^[^/\\:.\x00-\x1f\x7f][^/\\:\x00-\x1f\x7f]{0,127}\Z")


@dataclass(frozen=True)
class Limits:
    """Size limits for reading a project (bytes unless named otherwise)."""

    archive_bytes: int = 1 << 30
    members: int = 256
    json_bytes: int = 16 << 20
    asset_bytes: int = 256 << 20
    total_bytes: int = 1 << 30
    json_depth: int = 64


DEFAULT_LIMITS = Limits()


def save_project(path: str | os.PathLike, design: Design,
                 assets: Mapping[str, bytes] | None = None, keep_backup: bool = True) -> None:
    """Write ``design`` and ``assets`` to ``path`` atomically.

    With ``keep_backup`` the file it replaces is kept as ``path.bak`` (``NAME.glassbench.bak``).

    Raises ``ProjectError`` for a design that :func:`load_project` would refuse (NaN, invalid
    geometry, a missing or badly named asset, sizes over :data:`DEFAULT_LIMITS`) or a failed
    write; on failure the previous file is untouched.
    """
    path = os.fspath(path)
    assets = dict(assets or {})
    if len(assets) >= DEFAULT_LIMITS.members:
        raise ProjectError(f"a project holds at most {DEFAULT_LIMITS.members - 1} assets")
    for name, data in assets.items():
        if not isinstance(name, str) or not ASSET_NAME.match(name):
            raise ProjectError(f"asset name {name!r} is not a plain file name")
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise ProjectError(f"asset {name!r} must be bytes, got {type(data).__name__}")
        if len(data) > DEFAULT_LIMITS.asset_bytes:
            raise ProjectError(f"asset {name!r} is larger than {DEFAULT_LIMITS.asset_bytes} bytes")
    doc = document_from_design(design, GENERATOR)
    # Never write a file that cannot be opened again.
    check_design(design, assets)
    try:
        payload = json.dumps(doc, indent=1, allow_nan=False, ensure_ascii=False).encode("utf-8")
    except ValueError as exc:  # NaN (caught earlier, kept as a guard) or lone surrogates
        raise ProjectError(f"cannot write the project: {exc}") from None
    folder = os.path.dirname(os.path.abspath(path))
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=".glassbench-", suffix=".tmp", dir=folder)
        with os.fdopen(fd, "wb") as fh:
            with zipfile.ZipFile(fh, "w", compression=zipfile.ZIP_DEFLATED) as zf:
                zf.writestr(_member(PROJECT_MEMBER), payload)
                for name in sorted(assets):
                    zf.writestr(_member(ASSET_DIR + name), bytes(assets[name]))
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, _file_mode(path))
        if keep_backup and os.path.exists(path):
            _keep_backup(path)
        os.replace(tmp, path)
        _fsync_folder(folder)
    except OSError as exc:
        raise ProjectError(f"cannot write {path}: {exc.strerror or exc}") from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)


def _member(name: str) -> zipfile.ZipInfo:
    # A fixed time stamp makes saving the same project twice give the same bytes.
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_DEFLATED
    info.external_attr = 0o644 << 16
    return info


def _file_mode(path: str) -> int:
    """Permission bits for the saved file: the old file's, else the umask's default."""
    try:
        return stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        mask = os.umask(0)  # why: the only portable way to read the umask is to set it
        os.umask(mask)
        return 0o666 & ~mask


def _keep_backup(path: str) -> None:
    # Copy rather than move, so ``path`` exists at every instant of the save.
    bak = path + ".bak"
    fd, tmp = tempfile.mkstemp(prefix=".glassbench-bak-", dir=os.path.dirname(os.path.abspath(path)))
    try:
        with os.fdopen(fd, "wb") as out, open(path, "rb") as src:
            shutil.copyfileobj(src, out)
            out.flush()
            os.fsync(out.fileno())
        os.replace(tmp, bak)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _fsync_folder(folder: str) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # why: some platforms cannot open folders; the data itself is synced
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


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
            blob = fh.read(limits.archive_bytes + 1)
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
_CHUNK = 1 << 16


def _read_members(blob: bytes, limits: Limits) -> dict[str, bytes]:
    """Check every member of the archive, then read them with streaming size caps."""
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
            if declared_total > limits.total_bytes:
                raise ProjectError(f"the archive declares more than {limits.total_bytes} bytes in all")
            files.append((info, name, cap))
        out: dict[str, bytes] = {}
        total = 0
        for info, name, cap in files:
            data = _read_capped(zf, info, name, cap)
            total += len(data)
            if total > limits.total_bytes:
                raise ProjectError(f"the archive unpacks to more than {limits.total_bytes} bytes")
            out[name] = data
    return out


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


def _read_capped(zf: zipfile.ZipFile, info: zipfile.ZipInfo, name: str, cap: int) -> bytes:
    # Stream: never trust the declared size, stop as soon as the cap is passed (zip bombs).
    buf = bytearray()
    try:
        with zf.open(info) as fh:
            while True:
                chunk = fh.read(_CHUNK)
                if not chunk:
                    break
                buf += chunk
                if len(buf) > cap:
                    raise ProjectError(f"member {name!r} unpacks to more than {cap} bytes")
    except ProjectError:
        raise
    except _ZIP_ERRORS as exc:
        raise ProjectError(f"member {name!r} is damaged: {exc}") from None
    if len(buf) != info.file_size:
        raise ProjectError(f"member {name!r} unpacks to {len(buf)} bytes, "
                           f"not the {info.file_size} it declares")
    return bytes(buf)


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
    """Decode UTF-8 JSON strictly: no NaN/Infinity, bounded nesting; ``ProjectError`` otherwise."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ProjectError(f"{PROJECT_MEMBER} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    if _nesting_depth(text) > limits.json_depth:
        raise ProjectError(f"{PROJECT_MEMBER} is nested deeper than {limits.json_depth} levels")

    def no_constants(name):
        raise ProjectError(f"{PROJECT_MEMBER} contains {name}; only finite numbers are allowed")
    try:
        return json.loads(text, parse_constant=no_constants)
    except ProjectError:
        raise
    except (ValueError, RecursionError) as exc:
        raise ProjectError(f"{PROJECT_MEMBER} is not valid JSON: {str(exc)[:200]}") from None


_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)


def _nesting_depth(text: str) -> int:
    """Bracket depth of a JSON text, outside strings; stops recursion bombs before parsing."""
    depth = best = 0
    for m in re.finditer(r"[\[\]{}]", _JSON_STRING.sub("", text)):
        depth += 1 if m.group() in "[{" else -1
        best = max(best, depth)
    return best


def check_design(design: Design, assets: Mapping[str, bytes]) -> None:
    """Check what the value types cannot: sane ranges, asset references and the geometry.

    Raises ``ProjectError``; ``SectionError`` / ``WallError`` from validation are wrapped
    with their message kept.
    """
    r = design.render
    for name, value, lo, hi in (("render.width", r.width, 1, 16384),
                                ("render.height", r.height, 1, 16384),
                                ("render.spp", r.spp, 1, 1 << 20),
                                ("render.max_depth", r.max_depth, 1, 100_000)):
        if not lo <= value <= hi:
            raise ProjectError(f"design.{name} = {value} is outside {lo}..{hi}")
    media = [("glass", design.glass)] + ([("liquid", design.liquid)] if design.liquid else [])
    for name, medium in media:
        if not 1.0 <= medium.ior <= 5.0:
            raise ProjectError(f"design.{name}.ior = {medium.ior} is not a refractive index (1..5)")
        if any(a < 0 for a in medium.absorption):
            raise ProjectError(f"design.{name}.absorption must not be negative")
    if design.liquid is not None and design.liquid.fill_mode not in ("height", "volume"):
        raise ProjectError(f"design.liquid.fill_mode must be 'height' or 'volume', "
                           f"got {design.liquid.fill_mode[:40]!r}")
    env = design.environment
    if env.kind not in ("studio", "file"):
        raise ProjectError(f"design.environment.kind must be 'studio' or 'file', got {env.kind[:40]!r}")
    refs = [("environment", env.asset)] + [(f"labels[{i}]", lab.asset) for i, lab in enumerate(design.labels)]
    for where, name in refs:
        if name is not None and name not in assets:
            raise ProjectError(f"design.{where} names asset {name[:80]!r}, which the project lacks")
    if env.scale < 0:
        raise ProjectError(f"design.environment.scale = {env.scale} must not be negative")
    if env.kind == "file" and env.asset is None:
        raise ProjectError("design.environment.kind is 'file' but no asset is named")
    validate_design_shape(design)


def validate_design_shape(design: Design) -> None:
    """Run :func:`engine.geometry.validate.validate_shape` (when available), wrapping its errors."""
    try:
        from ..geometry import validate
    except ImportError:  # why: validation is written in parallel; load what we can until then
        return
    fn = getattr(validate, "validate_shape", None)
    if fn is None:
        return
    try:
        fn(design.shape)
    except GlassbenchError as exc:
        raise ProjectError(f"invalid bottle shape: {exc}") from None
    except (ValueError, ArithmeticError) as exc:
        raise ProjectError(f"invalid bottle shape: {exc}") from None


