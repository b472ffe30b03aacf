"""Running frames on Dask: a LocalCluster on this machine, or an existing cluster's scheduler.

Design rule: the client plans, Dask schedules, the client writes. Each variant's design and
assets are scattered once with ``broadcast=True`` (one copy per worker, never one per task);
each frame is one task (:func:`engine.batch.task.render_frame`) that names the scattered
payload plus its camera. Results are handed to ``on_result`` on the calling thread as they
finish, in any order. A worker that dies costs only its tasks: Dask reschedules them on the
others; should a payload be lost with every worker that held it, it is scattered again and the
frame resubmitted (at most ``MAX_ATTEMPTS`` times). Anything that stops the loop (an error, a
KeyboardInterrupt from a callback) cancels the frames still queued.
"""
from __future__ import annotations

import contextlib
import logging
import os
import threading
import uuid

from .source import JobError

#: Submissions of one frame before its failure is final (worker deaths Dask retries itself).
MAX_ATTEMPTS = 3
#: Seconds to wait for a cluster to have at least one worker.
WORKER_WAIT_S = 60.0


def default_workers() -> int:
    """Local workers: one per usable core (each renders one frame at a time)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return max(1, cores)


@contextlib.contextmanager
def open_client(scheduler: str | None = None, workers: int | None = None):
    """A Dask client: to ``scheduler`` (``tcp://HOST:PORT``) or to a new LocalCluster.

    The LocalCluster listens on 127.0.0.1 only, without a dashboard, with ``workers``
    single-threaded worker processes (default :func:`default_workers`); it is closed on exit.
    Raises :class:`JobError` when the scheduler cannot be reached or has no workers.
    """
    from distributed import Client, LocalCluster
    cluster = None
    if scheduler:
        if "://" not in scheduler:
            scheduler = f"tcp://{scheduler}"
        try:
            client = Client(scheduler, timeout="15s")
        except (OSError, TimeoutError) as exc:
            raise JobError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
    else:
        n = workers or default_workers()
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None, silence_logs=logging.ERROR)
        client = Client(cluster)
    try:
        try:
            client.wait_for_workers(1, timeout=WORKER_WAIT_S)
        except (TimeoutError, OSError):
            raise JobError(f"the Dask cluster at {client.scheduler.address} has no workers "
                           f"(waited {WORKER_WAIT_S:g} s)") from None
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_frames(client, frames, payload_of, *, alpha: bool, threads: int, on_result,
               on_progress=None, denoise: bool = False) -> None:
    """Render ``frames`` on ``client``'s cluster; call ``on_result(frame, result)`` per frame.

    Parameters
    ----------
    frames : list of engine.batch.jobfile.Frame
    payload_of : callable
        ``payload_of(frame) -> (design, assets)``: the variant data to scatter (one call per
        variant; frames of a variant share the scattered copy).
    alpha, threads, denoise
        Passed to :func:`engine.batch.task.render_frame`.
    on_result : callable
        ``on_result(frame, result_dict)``, on this thread, as each frame finishes.
    on_progress : callable, optional
        ``on_progress(relpath, fraction, tiles)`` from Dask events (on the client's event thread).
    """
    from distributed import as_completed

    from .task import render_frame
    topic = f"glassbench-batch-{uuid.uuid4().hex}"
    if on_progress is not None:
        client.subscribe_topic(topic, lambda event: _deliver(event, on_progress))
    payloads: dict = {}
    lock = threading.Lock()

    def payload(frame):
        key = id(frame.variant)
        with lock:
            if key not in payloads:
                payloads[key] = client.scatter([payload_of(frame)], broadcast=True, hash=False)[0]
            return payloads[key]

    def submit(frame):
        return client.submit(render_frame, payload(frame), frame.design.camera, frame.design.render,
                             alpha, threads, topic, frame.relpath, denoise, pure=False)

    pending = {}
    attempts = {}
    for frame in frames:
        fut = submit(frame)
        pending[fut] = frame
        attempts[frame.relpath] = 1
    queue = as_completed(list(pending))
    try:
        for fut in queue:
            frame = pending.pop(fut)
            try:
                result = fut.result()
            except Exception as exc:
                if _is_lost(exc) and attempts[frame.relpath] < MAX_ATTEMPTS:
                    attempts[frame.relpath] += 1
                    payloads.pop(id(frame.variant), None)
                    again = submit(frame)
                    pending[again] = frame
                    queue.add(again)
                    continue
                raise JobError(f"frame {frame.relpath}: {type(exc).__name__}: {_one_line(exc)}") from None
            finally:
                fut.release()
            on_result(frame, result)
    finally:
        if pending:
            client.cancel(list(pending))
        if on_progress is not None:
            with contextlib.suppress(Exception):
                client.unsubscribe_topic(topic)
        for fut in payloads.values():
            fut.release()


def _deliver(event, on_progress) -> None:
    _, msg = event
    if isinstance(msg, dict):
        on_progress(str(msg.get("frame", "")), float(msg.get("progress", 0.0)), int(msg.get("tiles", 0)))


def _is_lost(exc) -> bool:
    """A failure of the data, not of the frame: its inputs were lost with the workers."""
    from concurrent.futures import CancelledError
    return isinstance(exc, CancelledError) or "lost" in str(exc).lower()


def _one_line(exc) -> str:
    return " ".join((str(exc) or type(exc).__name__).split())[:300]
