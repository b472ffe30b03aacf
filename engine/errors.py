"""Exceptions raised by the engine. Each names what is wrong in words a designer can act on.

Design rule: a message is one line of bounded length. Every engine error passes its message
through :func:`bounded` (longer messages are cut in the middle), and a value echoed in a
message goes through :func:`shown`, so a hostile value (a 100 kB string, a huge number) can
never make an error line longer than :data:`MAX_MESSAGE_CHARS`.
"""
from __future__ import annotations

#: Longest message (characters) any engine error carries.
MAX_MESSAGE_CHARS = 400
#: Longest echo (characters) of a value inside a message.
MAX_SHOWN_CHARS = 60


def shown(value, limit: int = MAX_SHOWN_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters (``...`` marks a cut); never raises."""
    try:
        text = repr(value)
    except Exception:  # why: a repr may refuse (an int of 5,000 digits) or be user code
        text = f"<{type(value).__name__}>"
    if len(text) > limit:
        text = text[:limit - 3] + "..."
    return text


def bounded(message: str, limit: int = MAX_MESSAGE_CHARS) -> str:
    """``message`` on one line and at most ``limit`` characters (cut in the middle)."""
    text = " ".join(str(message).split())
    if len(text) > limit:
        half = (limit - 5) // 2
        text = f"{text[:half]} ... {text[-half:]}"
    return text


class GlassbenchError(Exception):
    """Base class of every error the engine raises on bad input (message: see :func:`bounded`)."""

    def __init__(self, message: str = ""):
        super().__init__(bounded(message))


class CliError(GlassbenchError):
    """A command-line problem to report as one line (exit status 2)."""


class SectionError(GlassbenchError, ValueError):
    """An invalid vertical section; ``index`` is the offending segment (or ``None``)."""

    def __init__(self, index: int | None, message: str):
        self.index = index
        prefix = f"segment {index}: " if index is not None else ""
        super().__init__(prefix + message)


class OutlineError(GlassbenchError, ValueError):
    """An invalid plan outline (SPEC_outline section 2); ``index`` is the offending segment of
    the chain (or ``None`` when the fault is the outline's as a whole, e.g. the origin outside)."""

    def __init__(self, index: int | None, message: str):
        self.index = index
        super().__init__((f"segment {index}: " if index is not None else "") + message)


class WallError(GlassbenchError, ValueError):
    """A wall or base thickness the section cannot carry."""


class ProjectError(GlassbenchError):
    """A project file that cannot be read or written; the message names the problem."""


class DesignError(ProjectError, ValueError):
    """A design value outside its physics or its limits (:mod:`engine.limits`); the message
    names the field. A ``ProjectError``, since a project may not hold it either."""


class NotSupportedError(DesignError):
    """Something the design's kind of bottle cannot do yet (labels, CAD, ... on an outline
    bottle): one line naming the feature and the kind
    (:meth:`engine.geometry.crosssection.CrossSection.require`)."""


class InputFileError(GlassbenchError, ValueError):
    """A file handed to glassbench (an image, a job file) that it will not read: not a regular
    file, or larger than its kind may be (:func:`engine.io.read.read_bounded`)."""
