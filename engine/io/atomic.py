"""Atomic file replacement: every file glassbench writes appears whole or not at all.

Design rule: a file is written to a temporary file in the target's own folder, synced, given
the old file's permission bits, then renamed over the target (``os.replace``), so a full disk or
a killed process leaves the previous file intact. A symbolic link is followed: the file it
points to is replaced and the link stays a link. The temporary's name says whose it is,
``.NAME.HOST.PID-XXXXXXXX.tmp[.ext]`` (the extension kept for writers that pick a format from
the name), so a later write of the same file removes what a killed writer left behind: a
temporary whose process, on this host, no longer runs. With ``backup`` the replaced file is
kept as ``NAME.bak`` with its own permission bits. Cleaning up never hides the error that made
the write fail.
"""
from __future__ import annotations

import contextlib
import os
import re
import secrets
import shutil
import socket
import stat
import time
from typing import Iterator

#: Characters of the target's name kept in a temporary's name (file names stop at 255 bytes).
_NAME_CHARS = 100
#: This machine's name as it appears in temporaries' names (letters, digits, dashes).
HOST = re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname())[:32] or "host"
#: Temporaries of the old naming (``.glassbench-XXXX.tmp``) carry no process id: they are
#: removed once they are this old (seconds), when no save can still be writing them.
LEGACY_TEMP_AGE_S = 3600.0
_LEGACY = re.compile(r"^\.glassbench-(bak-)?[A-Za-z0-9_]{6,}(\.tmp)?\Z")


def resolve_target(path: str | os.PathLike) -> str:
    """The file a write of ``path`` replaces: symbolic links followed, made absolute."""
    return os.path.realpath(os.fspath(path))


def temp_name(target: str, suffix: str = "") -> str:
    """A fresh temporary path beside ``target`` naming this host and process (see the module rule)."""
    folder, base = os.path.split(target)
    token = secrets.token_hex(4)
    return os.path.join(folder, f".{base[:_NAME_CHARS]}.{HOST}.{os.getpid()}-{token}.tmp{suffix}")


def _temp_pattern(target: str) -> re.Pattern:
    """Temporaries of ``target`` written on this host (group 1: the writer's process id); another
    host's (a shared network folder) are never touched: its processes cannot be asked after."""
    base = os.path.basename(target)[:_NAME_CHARS]
    return re.compile(r"^\." + re.escape(base) + r"\." + re.escape(HOST)
                      + r"\.(\d+)-[0-9a-f]{8}\.tmp(\.[^./]*)?\Z")


def _process_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True  # why: another thread of this process may be writing it right now
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True  # someone else's live process (or no way to tell): leave it
    return True


def remove_stale_temporaries(target: str) -> list[str]:
    """Remove the temporaries of ``target`` (and of its ``.bak``) left by processes that no
    longer run, and old-style glassbench temporaries older than :data:`LEGACY_TEMP_AGE_S`.

    Returns the removed paths. Never raises: a folder that cannot be listed is left alone.
    """
    folder = os.path.dirname(target)
    patterns = (_temp_pattern(target), _temp_pattern(target + ".bak"))
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    now = time.time()
    for name in names:
        path = os.path.join(folder, name)
        if _is_stale(name, path, patterns, now):
            with contextlib.suppress(OSError):
                os.unlink(path)
                removed.append(path)
    return removed


def _is_stale(name: str, path: str, patterns, now: float) -> bool:
    for pattern in patterns:
        match = pattern.match(name)
        if match is not None:
            return not _process_alive(int(match.group(1)))
    if _LEGACY.match(name):
        try:
            return now - os.lstat(path).st_mtime > LEGACY_TEMP_AGE_S
        except OSError:
            return False
    return False


def file_mode(target: str) -> int:
    """Permission bits for a new version of ``target``: the old file's, else the umask's default."""
    try:
        return stat.S_IMODE(os.stat(target).st_mode)
    except OSError:
        mask = os.umask(0)  # why: the only portable way to read the umask is to set it
        os.umask(mask)
        return 0o666 & ~mask


def fsync_folder(folder: str) -> None:
    """Make a rename in ``folder`` durable (where the platform allows opening folders)."""
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


def _fsync_file(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _unlink_quietly(path: str | None) -> None:
    if path is not None:
        with contextlib.suppress(OSError):  # why: the write's own error is the one to report
            os.unlink(path)


def keep_backup(target: str) -> None:
    """Copy ``target`` to ``target.bak`` atomically, with ``target``'s permission bits.

    A copy rather than a rename, so ``target`` exists at every instant of a save.
    """
    bak = target + ".bak"
    tmp = temp_name(bak)
    try:
        with open(target, "rb") as src, open(tmp, "xb") as out:
            shutil.copyfileobj(src, out)
            out.flush()
            os.fsync(out.fileno())
        os.chmod(tmp, stat.S_IMODE(os.stat(target).st_mode))
        os.replace(tmp, bak)
        tmp = None
    finally:
        _unlink_quietly(tmp)


@contextlib.contextmanager
def replacing(path: str | os.PathLike, *, suffix: str = "", backup: bool = False) -> Iterator[str]:
    """Context manager: yields a temporary path to write; on a clean exit it replaces ``path``.

    Parameters
    ----------
    path : str or PathLike
        The file to (re)place; a symbolic link is followed.
    suffix : str
        Appended to the temporary's name, for writers that choose a format by extension.
    backup : bool
        Keep the file being replaced as ``path.bak`` (with its permission bits).

    Raises
    ------
    OSError
        The write, sync or rename failed; the previous file is untouched and the temporary
        removed (a failure to remove it is not reported over the original error).
    """
    target = resolve_target(path)
    folder = os.path.dirname(target)
    remove_stale_temporaries(target)
    tmp = temp_name(target, suffix)
    os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    try:
        yield tmp
        _fsync_file(tmp)
        os.chmod(tmp, file_mode(target))
        if backup and os.path.exists(target):
            keep_backup(target)
        os.replace(tmp, target)
        tmp = None
        fsync_folder(folder)
    finally:
        _unlink_quietly(tmp)
