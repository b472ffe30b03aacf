"""Reading a file a user names, in bounded memory and time.

Design rule: every file glassbench reads on a user's word (artwork, relief and environment
images, job files) is read by :func:`read_bounded`: only a regular file (a link is followed to
what it names, so a link to ``/dev/zero``, a pipe or a device is refused at once, before a byte
is read) and never more than its kind's limit plus one byte, so a file that lies about its size
or grows while read still cannot take more memory than the limit. Sizes in bytes.
"""
from __future__ import annotations

import os
import stat

from ..errors import InputFileError, shown

#: Bytes read at a time past a file's stated size.
CHUNK_BYTES = 1 << 20


def read_bounded(path, max_bytes: int, what: str = "file") -> bytes:
    """The bytes of ``path`` if it is a regular file of at most ``max_bytes`` bytes.

    Raises :class:`engine.errors.InputFileError` naming ``what`` and the file for anything
    else (``OSError`` when it cannot be opened at all).
    """
    path = os.fspath(path)
    name = shown(os.path.basename(path) or path, 120)
    if not stat.S_ISREG(os.stat(path).st_mode):
        raise InputFileError(f"{what} {name} is not a regular file (a device, pipe or folder)")
    with open(path, "rb") as fh:
        st = os.fstat(fh.fileno())
        if not stat.S_ISREG(st.st_mode):  # swapped since the check
            raise InputFileError(f"{what} {name} is not a regular file")
        if st.st_size > max_bytes:
            raise InputFileError(f"{what} {name} is {st.st_size} bytes, larger than {max_bytes}")
        # why the size and then chunks: read(n) allocates n bytes at once, and a file may grow
        # while it is read; what it holds past the limit is never read
        parts, total = [fh.read(st.st_size + 1)], 0
        total = len(parts[0])
        while total <= max_bytes and len(parts[-1]):
            parts.append(fh.read(min(CHUNK_BYTES, max_bytes + 1 - total)))
            total += len(parts[-1])
    if total > max_bytes:
        raise InputFileError(f"{what} {name} is larger than {max_bytes} bytes")
    return b"".join(parts)
