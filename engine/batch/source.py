"""Job files read as plain data that still knows the line of every key.

Design rule: a job file's errors must name the line, so parsing keeps a map from each key path
(``("projects", 0, "variants", 1, "glass_tint")``) to the line it was written on. JSON is parsed
by the standard library's pure-Python scanner with position-recording hooks; TOML is parsed by
``tomllib`` (stdlib) and its lines are found by a small scanner of table headers and ``key =``
lines. A path with no line of its own reports its nearest ancestor's, so an error always names
a line. Syntax errors become :class:`JobError` with the parser's line.
"""
from __future__ import annotations

import bisect
import json
import json.decoder
import json.scanner
import os
import re
import tomllib
from dataclasses import dataclass, field

from ..errors import GlassbenchError, InputFileError
from ..io.read import read_bounded

#: Largest job file read (bytes): a job lists projects and overrides, never image data.
MAX_JOB_BYTES = 4 << 20


class JobError(GlassbenchError):
    """A job file that cannot be run; the message starts with ``FILE:LINE:`` when known."""


@dataclass(frozen=True)
class SourceTree:
    """A parsed job file: ``data`` (dicts, lists, numbers, strings) and the lines of its keys."""

    path: str
    data: object
    lines: dict = field(default_factory=dict)

    def line_of(self, key_path: tuple) -> int | None:
        """Line (1-based) where ``key_path`` or its nearest ancestor was written."""
        p = tuple(key_path)
        while p:
            if p in self.lines:
                return self.lines[p]
            p = p[:-1]
        return None

    def error(self, key_path: tuple, message: str) -> JobError:
        """A :class:`JobError` ``FILE:LINE: message`` for the value at ``key_path``."""
        line = self.line_of(key_path)
        where = f"{self.path}:{line}" if line else self.path
        return JobError(f"{where}: {message}")


def read_source(path: str | os.PathLike) -> SourceTree:
    """Read a ``.toml`` or ``.json`` job file; raises :class:`JobError` (syntax, size, suffix)."""
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
    if ext not in (".toml", ".json"):
        raise JobError(f"{path}: a job file must end in .toml or .json")
    try:
        raw = read_bounded(path, MAX_JOB_BYTES, "job file")
    except InputFileError as exc:
        raise JobError(f"{path}: {exc}; not a job file") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise JobError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    return parse_json(path, text) if ext == ".json" else parse_toml(path, text)


# ------------------------------------------------------------------------------ JSON
def parse_json(path: str, text: str) -> SourceTree:
    """Parse JSON text, recording the line of every object key and list item.

    A key's line is found by bisection in the newlines' offsets (counted once), so the parse
    stays O(n log n) in the text however many keys it holds."""
    newlines = [i for i, ch in enumerate(text) if ch == "\n"] if "\n" in text else []

    def line(pos):
        return bisect.bisect_left(newlines, pos) + 1

    def parse_object(s_and_end, strict, scan_once, object_hook, pairs_hook, memo=None, *rest):
        starts = []

        def tracking(s, idx):
            starts.append(idx)
            return scan_once(s, idx)
        pairs, end = json.decoder.JSONObject(s_and_end, strict, tracking, None, list, memo, *rest)
        out = _Lined()
        for (key, value), at in zip(pairs, starts):
            if key in out:
                raise JobError(f"{path}:{line(at)}: duplicate key {key!r}")
            out[key] = value
            out.item_lines[key] = line(at)
        return out, end

    def parse_array(s_and_end, scan_once, *rest):
        starts = []

        def tracking(s, idx):
            starts.append(idx)
            return scan_once(s, idx)
        values, end = json.decoder.JSONArray(s_and_end, tracking, *rest)
        out = _LinedList(values)
        out.item_lines.update({i: line(at) for i, at in enumerate(starts)})
        return out, end

    def no_constants(name):
        raise ValueError(f"{name} is not a number a job may hold")

    decoder = json.JSONDecoder(parse_constant=no_constants)
    decoder.parse_object = parse_object
    decoder.parse_array = parse_array
    decoder.memo = {}
    decoder.scan_once = json.scanner.py_make_scanner(decoder)
    try:
        tree = decoder.decode(text)
    except json.JSONDecodeError as exc:
        raise JobError(f"{path}:{exc.lineno}: invalid JSON: {exc.msg} (column {exc.colno})") from None
    except (ValueError, RecursionError) as exc:
        raise JobError(f"{path}: invalid JSON: {exc}") from None
    lines: dict = {}
    return SourceTree(path, _plain(tree, (), lines), lines)


class _Lined(dict):
    def __init__(self):
        super().__init__()
        self.item_lines = {}


class _LinedList(list):
    def __init__(self, values):
        super().__init__(values)
        self.item_lines = {}


def _plain(value, key_path, lines):
    """Plain dicts and lists, with the recorded lines moved into ``lines`` by key path."""
    if isinstance(value, dict):
        for k, n in getattr(value, "item_lines", {}).items():
            lines[key_path + (k,)] = n
        return {k: _plain(v, key_path + (k,), lines) for k, v in value.items()}
    if isinstance(value, list):
        for i, n in getattr(value, "item_lines", {}).items():
            lines[key_path + (i,)] = n
        return [_plain(v, key_path + (i,), lines) for i, v in enumerate(value)]
    return value


# ------------------------------------------------------------------------------ TOML
_TOML_LINE = re.compile(r"^\s*(\[\[?)([^\]]+)\]\]?|^\s*([A-Za-z0-9_\-\"'. ]+?)\s*=")
_TOML_STRING = re.compile(r'"(?:[^"\\]|\\.)*"|\'[^\']*\'')
_TOML_ERROR_AT = re.compile(r"\(at line (\d+), column (\d+)\)")


def parse_toml(path: str, text: str) -> SourceTree:
    """Parse TOML with ``tomllib`` and find the line of every table and key."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = _TOML_ERROR_AT.search(msg)
        if m:
            msg = _TOML_ERROR_AT.sub("", msg).strip()
            raise JobError(f"{path}:{m.group(1)}: invalid TOML: {msg} (column {m.group(2)})") from None
        raise JobError(f"{path}: invalid TOML: {msg}") from None
    return SourceTree(path, data, toml_key_lines(text))


def _toml_keys(text: str) -> tuple:
    return tuple(k.strip().strip("\"'") for k in re.findall(r'"[^"]*"|\'[^\']*\'|[^.]+', text))


def toml_key_lines(text: str) -> dict:
    """Map key paths to 1-based lines: ``[table]`` / ``[[array]]`` headers and ``key =`` lines.

    Lines inside a multi-line value (an array spread over lines) are skipped by counting
    brackets outside strings. Keys inside an inline table share the line of their table.
    """
    lines: dict = {}
    arrays: dict = {}  # array-of-tables path -> number of elements so far
    current: tuple = ()
    depth = 0

    def resolve(keys):
        p: tuple = ()
        for k in keys:
            p += (k,)
            if p in arrays:
                p += (arrays[p] - 1,)
        return p

    for number, raw in enumerate(text.splitlines(), start=1):
        code = _TOML_STRING.sub('""', raw).split("#", 1)[0]
        if depth == 0:
            m = _TOML_LINE.match(code)
            if m and m.group(1) == "[[":
                keys = _toml_keys(m.group(2))
                parent = resolve(keys[:-1]) + (keys[-1],)
                arrays[parent] = arrays.get(parent, 0) + 1
                current = parent + (arrays[parent] - 1,)
                lines[current] = number
                lines.setdefault(parent, number)
                continue
            if m and m.group(1) == "[":
                current = resolve(_toml_keys(m.group(2)))
                lines[current] = number
                continue
            if m and m.group(3):
                lines[current + _toml_keys(m.group(3))] = number
                code = code.split("=", 1)[1]
        depth += code.count("[") + code.count("{") - code.count("]") - code.count("}")
        depth = max(depth, 0)
    return lines
