"""Final renders, turntables and variant batches, on this machine or a Dask cluster.

Design rule: a batch is planned completely before anything renders. A job file (TOML or JSON)
is read into a :class:`~engine.batch.jobfile.BatchJob` of variants (a project plus checked
overrides) times views (turntable frames or named cameras); every problem is reported as one
:class:`~engine.batch.source.JobError` naming the file and line. Then each frame's inputs are
hashed (:mod:`engine.batch.manifest`), frames already in the output folder with the same hash
are skipped, and the rest run as Dask tasks (:mod:`engine.batch.execute`): one task renders
one whole frame, because the tracer's anti-aliasing decides per pixel from its neighbours, so a
tile could not be rendered without them. The client writes every file, atomically, inside
the output folder only. No Qt here; the window's Final image dialog uses
:class:`~engine.batch.still.FinalRender`.
"""
from __future__ import annotations

from .source import JobError

__all__ = ["JobError"]
