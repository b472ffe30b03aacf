"""Rebuilds the wireframe off the GUI thread, always from the newest shape.

Design rule: ``request(shape)`` costs the GUI thread almost nothing: it stores the shape as the
one pending request and wakes the worker. The worker takes the newest pending shape (older ones
are simply overwritten, so a fast drag never queues stale work), tessellates it, and emits the
lines through a queued signal. A result whose serial is older than the newest request already
shown is dropped. ``shutdown`` stops and joins the worker thread.
"""
from __future__ import annotations

import threading
import time

from PySide6.QtCore import QObject, Signal

from app import engine_bridge


class WireframeController(QObject):
    """Background wireframe builder.

    Signals
    -------
    meshReady(object, object)
        ``(points (N, 3), edges (M, 2))`` for the newest shape, on the GUI thread.
    failed(str)
        The tessellator refused the shape (the message says why).
    """

    meshReady = Signal(object, object)
    failed = Signal(str)
    _built = Signal(int, object, object, float)
    _error = Signal(int, str)

    def __init__(self, parent=None, tol_mm: float = 0.5):
        super().__init__(parent)
        self.tol_mm = tol_mm
        self._cond = threading.Condition()
        self._pending = None
        self._serial = 0
        self._shown_serial = 0
        self._busy = False
        self._stop = False
        self._thread: threading.Thread | None = None
        self.requested_at: dict[int, float] = {}
        self.latencies_s: list[float] = []
        self._built.connect(self._on_built)
        self._error.connect(self._on_error)

    def request(self, shape):
        """Ask for the wireframe of ``shape`` (replaces any request not yet started)."""
        with self._cond:
            self._serial += 1
            self._pending = (self._serial, shape)
            self.requested_at[self._serial] = time.perf_counter()
            if self._thread is None:
                self._thread = threading.Thread(target=self._work, name="wireframe", daemon=True)
                self._thread.start()
            self._cond.notify()

    def is_idle(self) -> bool:
        with self._cond:
            return self._pending is None and not self._busy and self._shown_serial == self._serial

    def _work(self):
        while True:
            with self._cond:
                while self._pending is None and not self._stop:
                    self._cond.wait()
                if self._stop:
                    return
                serial, shape = self._pending
                self._pending = None
                self._busy = True
            try:
                points, edges = engine_bridge.wireframe_lines(shape, self.tol_mm)
                self._built.emit(serial, points, edges, time.perf_counter())
            except Exception as exc:  # why: a shape the tessellator refuses must not kill the thread
                self._error.emit(serial, f"Wireframe: {exc}")
            finally:
                with self._cond:
                    self._busy = False

    def _on_built(self, serial, points, edges, _built_at):
        if serial < self._shown_serial:
            return
        self._shown_serial = serial
        self.meshReady.emit(points, edges)
        start = self.requested_at.pop(serial, None)
        if start is not None:
            self.latencies_s.append(time.perf_counter() - start)
        for old in [s for s in self.requested_at if s < serial]:
            del self.requested_at[old]

    def _on_error(self, serial, message):
        self._shown_serial = max(self._shown_serial, serial)
        self.failed.emit(message)

    def shutdown(self, timeout: float = 30.0):
        """Stop the worker thread and wait for it."""
        with self._cond:
            self._stop = True
            self._cond.notify_all()
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None
