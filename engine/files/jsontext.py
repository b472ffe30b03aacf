"""Strict, bounded reading of ``project.json`` text: UTF-8, finite numbers, bounded nesting,
each key once per object.

Design rule: every scan of untrusted text is linear in its length whatever the bytes, so no
file can hang the loader. The nesting depth is measured before the parser runs, without any
backtracking pattern: quotes, backslashes and brackets are located with vectorised numpy
operations on the raw UTF-8 bytes (a multi-byte character never contains an ASCII byte), a quote
is escaped when an odd run of backslashes precedes it, and a bracket counts only outside
strings. Errors are :class:`engine.errors.ProjectError` naming ``project.json``.
"""
from __future__ import annotations

import json

import numpy as np

from ..errors import ProjectError

MEMBER = "project.json"
_QUOTE, _BACKSLASH = 0x22, 0x5C
#: +1 for an opening bracket ([ {), -1 for a closing one (] }), 0 for any other byte.
_STEP = np.zeros(256, dtype=np.int8)
_STEP[[0x5B, 0x7B]], _STEP[[0x5D, 0x7D]] = 1, -1


def nesting_depth(raw: bytes) -> int:
    """Deepest bracket nesting of the JSON text ``raw`` (UTF-8 bytes), outside strings.

    Linear time and memory in ``len(raw)``. For text that is not valid JSON (an unterminated
    string, a stray backslash) the figure is some depth and the parser then reports the error.
    """
    b = np.frombuffer(raw, dtype=np.uint8)
    quotes = np.flatnonzero(b == _QUOTE).astype(np.int32)  # positions fit: json_bytes < 2**31
    after = (quotes > 0) & (b[quotes - 1] == _BACKSLASH)   # only these can be escaped
    if after.any():
        slashes = np.flatnonzero(b == _BACKSLASH).astype(np.int32)
        new_run = np.diff(slashes, prepend=-2) != 1
        run_start = slashes[new_run][np.cumsum(new_run, dtype=np.int32) - 1]
        cand = quotes[after]
        k = np.searchsorted(slashes, cand - 1)  # cand - 1 is a backslash: found exactly
        escaped = np.zeros(len(quotes), dtype=bool)
        escaped[np.flatnonzero(after)] = (cand - run_start[k]) % 2 == 1  # an odd run escapes
        quotes = quotes[~escaped]
    steps = _STEP[b]
    brackets = np.flatnonzero(steps).astype(np.int32)
    brackets = brackets[np.searchsorted(quotes, brackets) % 2 == 0]  # outside strings
    if not len(brackets):
        return 0
    return int(max(np.max(np.cumsum(steps[brackets], dtype=np.int64)), 0))


def parse_json(raw: bytes, max_depth: int) -> object:
    """Decode UTF-8 JSON strictly: no NaN/Infinity, nesting at most ``max_depth``.

    Raises ``ProjectError`` naming the problem (with the byte offset of bad UTF-8).
    """
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ProjectError(f"{MEMBER} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    if nesting_depth(raw) > max_depth:
        raise ProjectError(f"{MEMBER} is nested deeper than {max_depth} levels")

    def no_constants(name):
        raise ProjectError(f"{MEMBER} contains {name}; only finite numbers are allowed")

    def unique_keys(pairs):
        # why: JSON leaves duplicate names undefined; Python keeps the last, another reader the
        # first, so a file saying format_version 1 then 7 would mean two things. Refuse it.
        out = dict(pairs)
        if len(out) != len(pairs):
            seen = set()
            dup = next(k for k, _ in pairs if k in seen or seen.add(k))
            raise ProjectError(f"{MEMBER} names {dup!r} twice in one object; a key may appear once")
        return out
    try:
        return json.loads(text, parse_constant=no_constants, object_pairs_hook=unique_keys)
    except ProjectError:
        raise
    except (ValueError, RecursionError) as exc:
        raise ProjectError(f"{MEMBER} is not valid JSON: {str(exc)[:200]}") from None
