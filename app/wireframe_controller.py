"""Slow derived data computed off the GUI thread, always from the newest request.

Design rule: ``request(value)`` costs the GUI thread almost nothing: it stores the value as the
one pending request and wakes the worker. The worker takes the newest pending value (older ones
are simply overwritten, so a fast drag never queues stale work), computes, and emits the result
through a queued signal. A result older than one already shown is dropped. ``shutdown`` stops
and joins the worker thread. :class:`WireframeController` builds the 3D wireframe this way;
:class:`DerivedController` the trade and plant numbers and inner walls (a :class:`Derived`).
"""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass

from PySide6.QtCore import QObject, Signal

from app import engine_bridge
from engine.model.design import Design


class LatestOnlyWorker(QObject):
    """Runs ``compute(value)`` on one worker thread for the newest requested value.

    Signals
    -------
    resultReady(object)
        The result for the newest value, on the GUI thread.
    failed(str)
        ``compute`` raised (the message says why); the worker keeps going.
    """

    resultReady = Signal(object)
    failed = Signal(str)
    _built = Signal(int, object, float)
    _error = Signal(int, str)
    thread_name = "latest-only-worker"

    def __init__(self, parent=None):
        super().__init__(parent)
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
        """Ask for the result for ``shape`` (replaces any request not yet started)."""
        with self._cond:
            self._serial += 1
            self._pending = (self._serial, shape)
            self.requested_at[self._serial] = time.perf_counter()
            if self._thread is None:
                self._thread = threading.Thread(target=self._work, name=self.thread_name, daemon=True)
                self._thread.start()
            self._cond.notify()

    def is_idle(self) -> bool:
        """Whether no work is queued or running and the newest result is shown; a stopped
        worker (:meth:`shutdown`) is idle once its last computation ended (nothing more comes)."""
        with self._cond:
            if self._stop:
                return not self._busy
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
                result = self.compute(shape)
                self._built.emit(serial, result, time.perf_counter())
            except Exception as exc:  # why: a value the engine refuses must not kill the thread
                self._error.emit(serial, f"{self.what}: {exc}")
            finally:
                with self._cond:
                    self._busy = False

    what = "Worker"

    def compute(self, value):
        """The result for ``value`` (runs on the worker thread; override)."""
        raise NotImplementedError

    def _on_built(self, serial, result, _built_at):
        if serial < self._shown_serial:
            return
        self._shown_serial = serial
        self.resultReady.emit(result)
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


class WireframeController(LatestOnlyWorker):
    """Background wireframe builder of a design (the glass and its closure):
    ``meshReady(points (N, 3), edges (M, 2))``."""

    meshReady = Signal(object, object)
    thread_name = "wireframe"
    what = "Wireframe"

    def __init__(self, parent=None, tol_mm: float = 0.5):
        super().__init__(parent)
        self.tol_mm = tol_mm
        self.resultReady.connect(lambda r: self.meshReady.emit(*r))

    def compute(self, design):
        return engine_bridge.design_wireframe(design, self.tol_mm)


@dataclass(frozen=True)
class Derived:
    """What :class:`DerivedController` computes for one design.

    Attributes
    ----------
    design
        The design the rest was computed for.
    numbers
        Its trade numbers (:func:`app.engine_bridge.trade_numbers`; ml, mm, cm^3, g).
    inner
        Inner wall per section name (:func:`app.engine_bridge.inner_sections`).
    warnings
        What the design cannot be made or filled with, in words.
    plant
        The plant's numbers (:func:`app.engine_bridge.plant_numbers`), ``None`` when none
        could be computed.
    """

    design: Design
    numbers: dict
    inner: dict
    warnings: tuple[str, ...]
    plant: dict | None


class DerivedController(LatestOnlyWorker):
    """Trade numbers, plant numbers, inner walls and warnings of a Design:
    ``resultReady(Derived)``."""

    thread_name = "derived-numbers"
    what = "Trade numbers"

    def compute(self, design) -> Derived:
        numbers = engine_bridge.trade_numbers(design)
        warnings = engine_bridge.design_warnings(design, numbers.get("fill_height_mm"))
        return Derived(design, numbers, engine_bridge.inner_sections(design.shape), tuple(warnings),
                       engine_bridge.plant_numbers(design))
