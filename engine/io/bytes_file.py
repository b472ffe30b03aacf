"""Bytes held in memory (an embedded asset) as a file, for readers that take only paths.

Design rule: OpenImageIO's Python binding opens files, not buffers, so an embedded image is
written once to a private temporary folder that is removed afterwards, whatever happens.
"""
from __future__ import annotations

import contextlib
import os
import tempfile


@contextlib.contextmanager
def bytes_as_file(data: bytes, suffix: str, stem: str = "asset"):
    """Yield the path of a private temporary file holding ``data`` (name ``stem + suffix``)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, stem + suffix)
        with open(path, "wb") as fh:
            fh.write(data)
        yield path
