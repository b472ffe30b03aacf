"""Exceptions raised by the engine. Each names what is wrong in words a designer can act on."""
from __future__ import annotations


class GlassbenchError(Exception):
    """Base class of every error the engine raises on bad input."""


class SectionError(GlassbenchError, ValueError):
    """An invalid vertical section; ``index`` is the offending segment (or ``None``)."""

    def __init__(self, index: int | None, message: str):
        self.index = index
        prefix = f"segment {index}: " if index is not None else ""
        super().__init__(prefix + message)


class WallError(GlassbenchError, ValueError):
    """A wall or base thickness the section cannot carry."""


class ProjectError(GlassbenchError):
    """A project file that cannot be read or written; the message names the problem."""
