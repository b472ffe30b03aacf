"""Progress of a batch: what it tells while it runs, and the terminal bar that shows it.

Design rule: :func:`engine.batch.run.run_batch` reports to a :class:`BatchProgress`, whose
methods do nothing; the command line passes :class:`TerminalProgress`, a ``rich`` bar on stderr
with frames and tiles done, elapsed time and time left. ``frame_progress`` arrives from Dask's
event thread, the other calls from the batch's own thread; the bar's state is guarded by a
lock. The fraction done counts a running frame by its tracer progress, so the time left moves
while long frames render.
"""
from __future__ import annotations

import threading


class BatchProgress:
    """Receives a batch's progress; this base class ignores it (quiet runs, tests subclass)."""

    def start(self, total: int, skipped: int) -> None:
        """``total`` frames will render; ``skipped`` were already done (manifest)."""

    def frame_progress(self, relpath: str, fraction: float, tiles: int) -> None:
        """A running frame is ``fraction`` done after ``tiles`` tiles (any thread)."""

    def frame_done(self, relpath: str, seconds: float, worker: str) -> None:
        """A frame's file is written (``seconds`` of rendering on ``worker``)."""

    def finish(self) -> None:
        """The batch ended (finished, failed or interrupted)."""


class TerminalProgress(BatchProgress):
    """A ``rich`` progress bar on stderr: frames, tiles, elapsed and remaining time."""

    def __init__(self, description: str = "rendering", console=None):
        self.description = description
        self.console = console  # a rich Console (default: one on stderr)
        self.lock = threading.Lock()
        self.partial: dict = {}
        self.tiles: dict = {}
        self.done = 0
        self.bar = None
        self.task = None

    def start(self, total: int, skipped: int) -> None:
        from rich.console import Console
        from rich.progress import (BarColumn, Progress, TextColumn, TimeElapsedColumn,
                                   TimeRemainingColumn)
        console = self.console or Console(stderr=True)
        if skipped:
            console.print(f"{skipped} frame(s) already done (manifest): skipped")
        self.total = total
        self.bar = Progress(TextColumn("{task.description}"), BarColumn(),
                            TextColumn("{task.fields[frames]}/{task.total:.0f} frames"),
                            TextColumn("{task.fields[tiles]} tiles"), TimeElapsedColumn(),
                            TextColumn("left"), TimeRemainingColumn(), console=console,
                            refresh_per_second=4)
        self.task = self.bar.add_task(self.description, total=max(total, 1), frames=0, tiles=0)
        self.bar.start()

    def frame_progress(self, relpath: str, fraction: float, tiles: int) -> None:
        with self.lock:
            if relpath in self.partial and self.partial[relpath] is None:
                return  # a late event of a finished frame
            self.partial[relpath] = min(max(fraction, 0.0), 0.999)
            self.tiles[relpath] = tiles
            self._update()

    def frame_done(self, relpath: str, seconds: float, worker: str) -> None:
        with self.lock:
            self.partial[relpath] = None  # finished: later events of it are ignored
            self.done += 1
            self._update()

    def _update(self) -> None:
        if self.bar is None:
            return
        running = sum(v for v in self.partial.values() if v is not None)
        self.bar.update(self.task, completed=self.done + running, frames=self.done,
                        tiles=sum(self.tiles.values()))

    def finish(self) -> None:
        if self.bar is not None:
            self.bar.stop()
            self.bar = None
