"""The C libraries' own messages, caught: libpng, libtiff and libjpeg write to the process's
stderr (file descriptor 2) when they meet a damaged image, before glassbench's one-line error.

Design rule: a decoder that may print is run inside :func:`captured_stderr`, which points
descriptor 2 at a private temporary file for the call and hands back what was written there;
the caller folds it into its own error or drops it. One decode at a time holds the redirection
(a lock), and Python's own ``sys.stderr`` is flushed before and after, so nothing written before
is lost. While a decode runs, another thread's output to descriptor 2 is caught with it: decodes
are short, and what they catch is only shown when the decode fails.
"""
from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import threading

_LOCK = threading.Lock()


class Captured:
    """What a decoder wrote to stderr, as text (empty until the ``with`` block ends)."""

    text: str = ""


@contextlib.contextmanager
def captured_stderr():
    """Run the block with descriptor 2 redirected to a temporary file; yields a
    :class:`Captured` whose ``text`` is what was written (last 2 KiB, one line)."""
    out = Captured()
    with _LOCK, tempfile.TemporaryFile() as sink:
        with contextlib.suppress(Exception):
            sys.stderr.flush()
        try:
            saved = os.dup(2)
        except OSError:  # no descriptor 2 (a detached process): nothing can be printed there
            yield out
            return
        try:
            os.dup2(sink.fileno(), 2)
            yield out
        finally:
            with contextlib.suppress(Exception):
                sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0, os.SEEK_END)
            size = sink.tell()
            sink.seek(max(0, size - 2048))
            out.text = " ".join(sink.read().decode("utf-8", "replace").split())
